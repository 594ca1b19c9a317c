//! `[robust]` (`docs/motions.md` 4.11): the uncertainty a robust plan must hold over, as ranges
//! of numeric experiment keys named as sweeps name them (`"payload.mass"`, `"robot.E"`,
//! `"robot.L[2]"`), the quantile minimised and the fresh draws of the check; the models of the
//! sample (Eq. U2) and of the draws, each the file's experiment with the keys set by the study's
//! key setter ([`flexstar_study::patch::case_document`]) and read by the experiment loader.

use std::path::{Path, PathBuf};

use serde::Serialize;

use flexstar_model::{Experiment, ModelError};
use flexstar_study::key::{self, Key};
use flexstar_study::patch::{case_document, get_dotted, number};
use flexstar_study::spec::{Levels, Vary};

/// Fresh models of the check by default (`[robust] draws`).
pub const DEFAULT_DRAWS: usize = 20;
/// Most fresh models.
pub const MAX_DRAWS: usize = 1000;
/// Most keys whose corners are all candidates of the sample (`2^6` modal analyses); beyond, the
/// one-at-a-time ends.
pub const MAX_CORNER_KEYS: usize = 6;

/// One uncertain key: its range `[lo, hi]` and the file's own (nominal) value, in the key's
/// units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Range {
    /// The key as written (`payload.mass`, `robot.L[2]`).
    pub key: String,
    pub lo: f64,
    pub hi: f64,
    pub nominal: f64,
}

/// `[robust]` as read and checked.
#[derive(Debug, Clone, Serialize)]
pub struct Uncertainty {
    pub ranges: Vec<Range>,
    /// The robust plan's duration (`t_move` of the section).
    pub t_move: RobustDuration,
    /// In (0, 1]: 1 minimises the worst sample (Eq. U1).
    pub quantile: f64,
    /// Fresh models of the check.
    pub draws: usize,
    pub seed: u64,
    /// The model the fresh draws are run on (`[robust] check`).
    pub check: CheckModel,
    /// The file's experiment as a TOML document (its trajectory the stand-in quintic).
    #[serde(skip)]
    doc: toml::Table,
    #[serde(skip)]
    file: PathBuf,
}

/// An error of `[robust]` under `robust.<key>` in `file`.
fn bad(file: &Path, key: &str, reason: impl Into<String>) -> ModelError {
    ModelError::invalid(format!("robust.{key}"), reason).in_file(file)
}

impl Uncertainty {
    /// Read `[robust]` (`section`, taken out of the file) against the file's experiment document
    /// `doc` (with its stand-in trajectory): every check of 4.11's refusals, before any work.
    pub fn read(section: toml::Table, doc: &toml::Table, file: &Path) -> Result<Uncertainty, ModelError> {
        let mut u = Uncertainty {
            ranges: Vec::new(),
            t_move: RobustDuration::Plan,
            quantile: 1.0,
            draws: DEFAULT_DRAWS,
            seed: 1,
            check: CheckModel::Amm,
            doc: doc.clone(),
            file: file.to_path_buf(),
        };
        let mut entries = Vec::new();
        flatten(&section, "", &mut entries);
        for (name, value) in entries {
            match name.as_str() {
                "quantile" => u.quantile = read_quantile(&value, file)?,
                "t_move" => u.t_move = read_duration(&value, file)?,
                "draws" => u.draws = read_count(&value, file, "draws", 1, MAX_DRAWS)?,
                "seed" => u.seed = read_count(&value, file, "seed", 0, usize::MAX)? as u64,
                "check" => u.check = read_check(&value, file)?,
                "fit" => {
                    for (key, range) in crate::fit_uncertainty::ranges(&value, file)? {
                        u.ranges.push(u.read_range(&key, &range)?);
                    }
                }
                _ => u.ranges.push(u.read_range(&name, &value)?),
            }
        }
        if let Some(twice) = u
            .ranges
            .iter()
            .enumerate()
            .find(|(k, r)| u.ranges[..*k].iter().any(|o| o.key == r.key))
        {
            return Err(bad(
                file,
                &format!("\"{}\"", twice.1.key),
                "is given twice (as a range and by the fit, or twice by the fit): keep one",
            ));
        }
        if u.ranges.is_empty() {
            return Err(bad(
                file,
                "",
                "names no uncertain key: give at least one \"key\" = [lo, hi]",
            ));
        }
        Ok(u)
    }

    /// One `"key" = [lo, hi]` entry: two finite numbers with `lo < hi`, a key the experiment
    /// format takes with a number at both ends, a range holding the file's own value.
    fn read_range(&self, name: &str, value: &toml::Value) -> Result<Range, ModelError> {
        let quoted = format!("\"{name}\"");
        let err = |why: String| bad(&self.file, &quoted, why);
        let pair = value.as_array().filter(|a| a.len() == 2);
        let (lo, hi) = match pair.map(|a| (number(&a[0]), number(&a[1]))) {
            Some((Some(lo), Some(hi))) => (lo, hi),
            _ => return Err(err(format!("a range is [lo, hi], two numbers; got {value}"))),
        };
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(err(format!("[{lo}, {hi}]: need finite lo < hi")));
        }
        let key = Key::parse(name).map_err(err)?;
        for end in [lo, hi] {
            self.model(&[name.to_string()], &[end]).map_err(|e| {
                err(format!(
                    "the experiment refuses {name} = {end}: {}",
                    flexstar_study::spec::parse_reason(&e.to_string())
                ))
            })?;
        }
        let nominal = self.nominal(&key).map_err(err)?;
        if !(lo <= nominal && nominal <= hi) {
            return Err(err(format!(
                "the range [{lo}, {hi}] excludes the experiment's own value {nominal}: a robust plan holds around its model"
            )));
        }
        Ok(Range {
            key: name.to_string(),
            lo,
            hi,
            nominal,
        })
    }

    /// The file's own value at `key`: its number, one entry of a list key (defaults included,
    /// [`key::number_at`]), or the common default of a list key the file does not set.
    fn nominal(&self, k: &Key) -> Result<f64, String> {
        if let Some(v) = key::number_at(&self.doc, k) {
            return Ok(v);
        }
        if let Some(v) = get_dotted(&self.doc, &k.path) {
            return Err(format!("{} is a {}, not a number", k.text(), v.type_str()));
        }
        let list = key::numbers_at(&self.doc, &k.path).ok();
        match list.filter(|l| l.windows(2).all(|w| w[0] == w[1])) {
            Some(l) if !l.is_empty() => Ok(l[0]),
            _ => Err(format!(
                "the file does not set {}: give its value, so that the range can be checked to hold it",
                k.text()
            )),
        }
    }

    /// The keys, in file order.
    pub fn keys(&self) -> Vec<String> {
        self.ranges.iter().map(|r| r.key.clone()).collect()
    }

    /// The nominal values.
    pub fn nominal_values(&self) -> Vec<f64> {
        self.ranges.iter().map(|r| r.nominal).collect()
    }

    /// The file's experiment with `values[j]` at `keys[j]` (the study's key setter, then the
    /// experiment loader).
    pub fn model(&self, keys: &[String], values: &[f64]) -> Result<Experiment, ModelError> {
        let values: Vec<toml::Value> = values.iter().map(|v| toml::Value::Float(*v)).collect();
        let doc = case_document(&self.doc, keys, &values).map_err(|e| ModelError::invalid("robust", e))?;
        let text = toml::to_string(&doc).map_err(|e| ModelError::invalid("robust", e.to_string()))?;
        Experiment::from_toml_str(&text, &self.file)
    }

    /// The model at one value per uncertain key.
    pub fn model_at(&self, values: &[f64]) -> Result<Experiment, ModelError> {
        self.model(&self.keys(), values)
    }

    /// The candidates of the sample (Eq. U2): every corner of the box, or beyond
    /// [`MAX_CORNER_KEYS`] keys each key's two ends with the others nominal.
    pub fn candidates(&self) -> Vec<Vec<f64>> {
        let n = self.ranges.len();
        if n <= MAX_CORNER_KEYS {
            return (0..1usize << n)
                .map(|mask| {
                    let pick = |(j, r): (usize, &Range)| if mask >> j & 1 == 1 { r.hi } else { r.lo };
                    self.ranges.iter().enumerate().map(pick).collect()
                })
                .collect();
        }
        let mut out = Vec::new();
        for j in 0..n {
            for end in [self.ranges[j].lo, self.ranges[j].hi] {
                let mut v = self.nominal_values();
                v[j] = end;
                out.push(v);
            }
        }
        out
    }

    /// The fresh models of the check: `draws` points drawn uniformly and independently in the
    /// box (the study's seeded Monte Carlo, [`flexstar_study::sample::random_draws`]).
    pub fn fresh_draws(&self) -> Vec<Vec<f64>> {
        let vary: Vec<Vary> = self
            .ranges
            .iter()
            .map(|r| Vary {
                key: r.key.clone(),
                levels: Levels::Uniform { lo: r.lo, hi: r.hi },
            })
            .collect();
        flexstar_study::sample::random_draws(&vary, self.draws, self.seed)
            .into_iter()
            .map(|row| row.iter().map(|v| number(v).unwrap_or(f64::NAN)).collect())
            .collect()
    }

    /// `count` values of range `j` from `lo` to `hi`, evenly spaced, with the nominal value
    /// added where it is not one of them (the robustness curves' abscissae).
    pub fn sweep(&self, j: usize, count: usize) -> Vec<f64> {
        let r = &self.ranges[j];
        let mut v: Vec<f64> = (0..count)
            .map(|k| r.lo + (r.hi - r.lo) * k as f64 / (count - 1).max(1) as f64)
            .collect();
        if !v.iter().any(|x| (x - r.nominal).abs() <= 1e-12 * (r.hi - r.lo)) {
            v.push(r.nominal);
            v.sort_by(f64::total_cmp);
        }
        v
    }
}

/// The entries of `[robust]` as dotted names: a quoted key (`"payload.mass"`) stays whole, a
/// bare dotted key (`payload.mass = ...`, a nested table in TOML) is joined back.
fn flatten(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in table {
        let name = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(t) => flatten(t, &name, out),
            _ => out.push((name, v.clone())),
        }
    }
}

/// The robust plan's duration, `[robust] t_move` (`docs/motions.md` 4.11, "The robust plan's
/// time"): the plan's own `t_move` (default), the ZVD-shaped quintic's (the plan's `t_move` plus
/// the ZVD's penalty: the same time as the shaper it competes with), or seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RobustDuration {
    Plan,
    Zvd,
    Seconds(f64),
}

fn read_duration(v: &toml::Value, file: &Path) -> Result<RobustDuration, ModelError> {
    match (v.as_str(), number(v)) {
        (Some("zvd"), _) => Ok(RobustDuration::Zvd),
        (Some("plan"), _) => Ok(RobustDuration::Plan),
        (None, Some(t)) if t.is_finite() && t > 0.0 => Ok(RobustDuration::Seconds(t)),
        _ => Err(bad(
            file,
            "t_move",
            format!("is the robust plan's duration: seconds (> 0), \"plan\" ([plan] t_move) or \"zvd\" (the ZVD-shaped quintic's); got {v}"),
        )),
    }
}

/// The model of the fresh draws' check, `[robust] check` (`docs/motions.md` 4.11, "The check's
/// model"): the accurate AMM at the N and step of the plan's searches (default: the draws cost
/// what a plan may take), or the FEM (the independent model, about four times the cost per run).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckModel {
    Amm,
    Fem,
}

fn read_check(v: &toml::Value, file: &Path) -> Result<CheckModel, ModelError> {
    match v.as_str() {
        Some("amm") => Ok(CheckModel::Amm),
        Some("fem") => Ok(CheckModel::Fem),
        _ => Err(bad(
            file,
            "check",
            format!("is the model of the fresh draws: \"amm\" (the accurate AMM, default) or \"fem\"; got {v}"),
        )),
    }
}

fn read_quantile(v: &toml::Value, file: &Path) -> Result<f64, ModelError> {
    match number(v) {
        Some(q) if q > 0.0 && q <= 1.0 => Ok(q),
        _ => Err(bad(
            file,
            "quantile",
            format!("must be in (0, 1] (1: the worst sample), got {v}"),
        )),
    }
}

fn read_count(v: &toml::Value, file: &Path, name: &str, lo: usize, hi: usize) -> Result<usize, ModelError> {
    match v.as_integer() {
        Some(n) if n >= lo as i64 && (n as u64) <= hi as u64 => Ok(n as usize),
        _ => Err(bad(file, name, format!("must be a whole number from {lo}, got {v}"))),
    }
}
