//! `configs/thresholds.toml`: what `flexstar verify` (and the CI regression test) demands of the
//! regenerated Table I: the verdicts and most accurate family per case (the paper's text,
//! sections 8-9, as read in `docs/paper-defects.md`), and every mean EVP inside a recorded band
//! (provenance written beside the band in the file). The file is built into the binary
//! ([`Thresholds::builtin`]); `--thresholds` reads another.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use flexstar_model::ModeFamily;
use serde::Deserialize;

use crate::behaviour::Behaviour;
use crate::table::{TableI, TableRow};

/// Expectations for one case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseThresholds {
    /// Actual behaviour of G expected from the FEM.
    pub behaviour: Behaviour,
    /// Families whose boundary conditions at G can represent the behaviour.
    pub correct: Vec<ModeFamily>,
    /// Families that cannot.
    pub incorrect: Vec<ModeFamily>,
    /// The most accurate family (smallest mean EVP).
    pub most_accurate: ModeFamily,
    /// A family allowed to take the first place instead when its mean EVP is within
    /// `tie_points` of the expected one (case 1: pinned-free and free-free).
    #[serde(default)]
    pub tie_with: Option<ModeFamily>,
    #[serde(default)]
    pub tie_points: f64,
    /// Band `[low, high]` of the mean EVP [%] per family.
    #[serde(default)]
    pub evp: HashMap<ModeFamily, [f64; 2]>,
}

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Modes per beam of the verified runs.
    pub modes: usize,
    /// Further N for the convergence columns of the table (not checked).
    #[serde(default)]
    pub n_study: Vec<usize>,
    /// Hard upper bounds on flexstar's accurate model (`docs/validation.md` section 4), every case.
    #[serde(default)]
    pub accurate: Option<AccurateBounds>,
    /// Per case name.
    pub case: BTreeMap<String, CaseThresholds>,
}

/// `[accurate]`: upper bounds on the accurate model's EVP against the FEM [%] in every case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccurateBounds {
    /// Label of the run (Table I column), `enriched`.
    pub label: String,
    /// Largest mean EVP over A, B, C, G [%].
    pub mean_max: f64,
    /// Largest EVP at any single point [%].
    pub point_max: f64,
    /// Largest factor between the run's own error estimate and its mean EVP, either way
    /// (target: within a factor of 2, `docs/amm.md` section 9).
    pub estimate_ratio_max: Option<f64>,
}

/// Errors reading the thresholds file.
#[derive(Debug, thiserror::Error)]
pub enum ThresholdsError {
    #[error("{file}: {reason}")]
    Read { file: String, reason: String },
}

/// `configs/thresholds.toml` as built into the binary.
pub const BUILTIN_THRESHOLDS: &str = include_str!("../../../configs/thresholds.toml");

/// One check of the thresholds, passed or not.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Check {
    pub case: String,
    /// What is checked, e.g. `behaviour of G` or `mean EVP of free-free [%]`.
    pub what: String,
    /// The value found.
    pub value: String,
    /// What it must be.
    pub bound: String,
    pub ok: bool,
}

impl std::fmt::Display for Check {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {}: {} = {} (required: {})",
            if self.ok { "PASS" } else { "FAIL" },
            self.case,
            self.what,
            self.value,
            self.bound
        )
    }
}

impl Thresholds {
    /// The thresholds built into the binary (`configs/thresholds.toml` of the source tree).
    pub fn builtin() -> Result<Self, ThresholdsError> {
        Self::parse(BUILTIN_THRESHOLDS, "configs/thresholds.toml (built in)")
    }

    /// Read a thresholds file.
    pub fn load(path: &Path) -> Result<Self, ThresholdsError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ThresholdsError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        Self::parse(&text, &file)
    }

    /// Parse thresholds text; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<Self, ThresholdsError> {
        let file = file.to_string();
        let t: Thresholds = toml::from_str(text).map_err(|e| ThresholdsError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        for (name, c) in &t.case {
            for (f, band) in &c.evp {
                if !band[0].is_finite() || !band[1].is_finite() || band[0] > band[1] {
                    return Err(ThresholdsError::Read {
                        file: file.clone(),
                        reason: format!("case.{name}.evp.{f}: need low <= high, got {band:?}"),
                    });
                }
            }
        }
        Ok(t)
    }

    /// Every check, passed or failed, in the order of the file.
    pub fn check(&self, table: &TableI) -> Vec<Check> {
        let mut out = Vec::new();
        for (name, exp) in &self.case {
            let mut c = CaseChecks {
                case: name,
                out: &mut out,
            };
            let Some(row) = table.rows.iter().find(|r| &r.case == name) else {
                c.push("case".into(), "not run".into(), "in the table".into(), false);
                continue;
            };
            check_verdicts(&mut c, exp, row);
            check_most_accurate(&mut c, exp, row);
            check_bands(&mut c, exp, row);
            if let Some(acc) = &self.accurate {
                check_accurate(&mut c, acc, row);
            }
        }
        out
    }
}

/// The checks of one case, collected in the order they are made.
struct CaseChecks<'a> {
    case: &'a str,
    out: &'a mut Vec<Check>,
}

impl CaseChecks<'_> {
    fn push(&mut self, what: String, value: String, bound: String, ok: bool) {
        self.out.push(Check {
            case: self.case.to_string(),
            what,
            value,
            bound,
            ok,
        });
    }
}

/// The behaviour of G and the verdict of every family the thresholds name.
fn check_verdicts(c: &mut CaseChecks, exp: &CaseThresholds, row: &TableRow) {
    c.push(
        "behaviour of G".into(),
        row.behaviour.name().into(),
        exp.behaviour.name().into(),
        row.behaviour == exp.behaviour,
    );
    for (families, want) in [(&exp.correct, true), (&exp.incorrect, false)] {
        for f in families {
            let value = row.family(*f).map(|e| verdict(e.correct)).unwrap_or("not run");
            c.push(
                format!("verdict of {f}"),
                value.into(),
                verdict(want).into(),
                value == verdict(want),
            );
        }
    }
}

/// The most accurate family, or a tie with the expected one within the allowed EVP points.
fn check_most_accurate(c: &mut CaseChecks, exp: &CaseThresholds, row: &TableRow) {
    let mean = |f: ModeFamily| row.family(f).and_then(|e| e.evp.mean);
    let best = row.most_accurate_family();
    let value = match best {
        Some(b) => format!("{b} ({})", fmt(mean(b))),
        None => "none (no run has an EVP)".into(),
    };
    let ok = match best {
        Some(b) if b == exp.most_accurate => true,
        Some(b) if Some(b) == exp.tie_with => {
            matches!((mean(b), mean(exp.most_accurate)), (Some(a), Some(e)) if (a - e).abs() <= exp.tie_points)
        }
        _ => false,
    };
    let bound = match exp.tie_with {
        Some(t) => format!(
            "{} ({}), or {t} within {} EVP points of it",
            exp.most_accurate,
            fmt(mean(exp.most_accurate)),
            exp.tie_points
        ),
        None => exp.most_accurate.to_string(),
    };
    c.push("most accurate family".into(), value, bound, ok);
}

/// Every family's mean EVP inside its band.
fn check_bands(c: &mut CaseChecks, exp: &CaseThresholds, row: &TableRow) {
    let mean = |f: ModeFamily| row.family(f).and_then(|e| e.evp.mean);
    let mut bands: Vec<_> = exp.evp.iter().collect();
    bands.sort_by_key(|(f, _)| ModeFamily::ALL.iter().position(|g| g == *f));
    for (f, band) in bands {
        let v = mean(*f);
        c.push(
            format!("mean EVP of {f}"),
            fmt(v),
            format!("[{}, {}] %", band[0], band[1]),
            matches!(v, Some(v) if v >= band[0] && v <= band[1]),
        );
    }
}

/// The accurate model's mean and largest point EVP, and its error estimate against its EVP.
fn check_accurate(c: &mut CaseChecks, acc: &AccurateBounds, row: &TableRow) {
    let run = row.run(&acc.label);
    let mean = run.and_then(|e| e.evp.mean);
    c.push(
        format!("mean EVP of the accurate model ({})", acc.label),
        fmt(mean),
        format!("<= {} %", acc.mean_max),
        matches!(mean, Some(v) if v <= acc.mean_max),
    );
    let worst = run.map(|e| e.evp.points.iter().flatten().fold(0.0f64, |a, b| a.max(*b)));
    c.push(
        format!("largest point EVP of the accurate model ({})", acc.label),
        fmt(worst),
        format!("<= {} %", acc.point_max),
        matches!(worst, Some(v) if v <= acc.point_max),
    );
    if let Some(max) = acc.estimate_ratio_max {
        let estimate = run.and_then(|e| e.error_estimate);
        // the true error is the EVP against the refined reference FEM where verify ran one
        // (docs/validation.md section 8), else against the FEM of the table
        let reference = run.and_then(|e| e.evp_reference.as_ref());
        let truth = reference.map_or(mean, |r| r.mean);
        let against = if reference.is_some() {
            " against the refined FEM"
        } else {
            ""
        };
        let ratio = match (estimate, truth) {
            (Some(e), Some(m)) if e > 0.0 && m > 0.0 => Some(e / m),
            _ => None,
        };
        c.push(
            format!(
                "error estimate / mean EVP{against} of the accurate model ({})",
                acc.label
            ),
            match (estimate, ratio) {
                (Some(e), Some(r)) => format!("{e:.2} % / {} = {r:.2}", fmt(truth)),
                _ => "n/a".into(),
            },
            format!("in [1/{max}, {max}]"),
            matches!(ratio, Some(r) if r <= max && r >= 1.0 / max),
        );
    }
}

fn verdict(correct: bool) -> &'static str {
    if correct {
        "correct"
    } else {
        "incorrect"
    }
}

fn fmt(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2} %")).unwrap_or_else(|| "n/a".into())
}
