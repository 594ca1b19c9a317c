//! Study files (TOML): a base experiment, the solvers, and the keys to vary.
//!
//! ```toml
//! name = "sleeve-study"
//! base = "case3.toml"              # an experiment, path relative to the study file
//! solvers = ["amm"]                # any of "amm", "fem" (default ["amm"])
//! [[vary]]
//! key = "robot.Lp"                 # any experiment key, or scale.duration
//! values = [0.02, 0.03, 0.04]
//! [[vary]]
//! key = "robot.Jp"
//! linspace = [1e-4, 4e-4, 4]       # n points from a to b; or logspace = [a, b, n] (geometric)
//! # sampling = "grid" (default, full factorial) or "lhs" with samples = 200 and seed = 1
//! # fem_reference = "defaults" (the case's [fem] settings) or "refined" (docs/validation.md section 8)
//! ```
//! Unknown keys are rejected; every error names the study file, the key and the reason.

use std::path::{Path, PathBuf};

use flexstar_model::{Experiment, ModelError};
use serde::Deserialize;

use crate::error::StudyError;
use crate::hash::hex64;
use crate::key::{self, Key};
use crate::patch::{self, SCALE_DURATION};

/// Largest number of cases a study may expand to.
pub const MAX_CASES: usize = 100_000_000;

/// A solver run on every case: the workspace's one solver choice.
pub use flexstar_solve::Solver;

/// The FEM settings a study's `fem` solver runs with (study key `fem_reference`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FemReference {
    /// The case's own `[fem]` settings (the default).
    #[default]
    Defaults,
    /// The refined reference that `flexstar verify` judges the accurate model against:
    /// four times the elements and an eighth of the step
    /// ([`flexstar_solve::reference_fem`]; `docs/validation.md` section 8).
    Refined,
}

/// The levels of one varied key.
#[derive(Debug, Clone, PartialEq)]
pub enum Levels {
    /// Listed values, any TOML type (numbers, strings such as mode families, arrays).
    Values(Vec<toml::Value>),
    /// `linspace = [a, b, n]`: n equally spaced points from a to b (integers when a and b are
    /// integers and every point is one).
    Linspace { a: f64, b: f64, n: usize, integer: bool },
    /// `logspace = [a, b, n]`: n geometrically spaced points from a to b (both > 0).
    Logspace { a: f64, b: f64, n: usize },
    /// `normal = [mean, sd]`: drawn from a normal distribution (sampled studies only).
    Normal { mean: f64, sd: f64 },
    /// `uniform = [lo, hi]`: drawn uniformly from `[lo, hi]` (sampled studies only).
    Uniform { lo: f64, hi: f64 },
}

impl Levels {
    /// A distribution to draw from, rather than levels to list: only a sampled study takes it.
    pub fn is_distribution(&self) -> bool {
        matches!(self, Levels::Normal { .. } | Levels::Uniform { .. })
    }
}

/// One `[[vary]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// Dotted experiment key (`robot.Lp`, `trajectory.to.Gx`, ...) or [`SCALE_DURATION`].
    pub key: String,
    pub levels: Levels,
}

/// How the cases are drawn from the levels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampling {
    /// Full factorial: every combination of levels, the first key varying slowest.
    Grid,
    /// Latin hypercube: `samples` points; each key's range (linspace/logspace bounds, uniform or
    /// log-uniform; or its list of values; a distribution's probability) is cut into `samples`
    /// equal strata, each used once.
    Lhs { samples: usize, seed: u64 },
    /// Monte Carlo: `samples` points, each key drawn independently from its range or
    /// distribution (a tolerance study as a production line sees it).
    Random { samples: usize, seed: u64 },
}

/// A validated study.
#[derive(Debug, Clone)]
pub struct Study {
    /// The study file.
    pub file: PathBuf,
    /// Name; results go to `<out>/<name>/`.
    pub name: String,
    pub description: String,
    /// The base experiment file (resolved against the study file's folder).
    pub base_file: PathBuf,
    /// The base experiment as a TOML document, patched per case.
    pub base: toml::Table,
    /// The base experiment, validated.
    pub base_experiment: Experiment,
    pub solvers: Vec<Solver>,
    pub vary: Vec<Vary>,
    /// Keys set by formulas of the others (`[[tie]]`), in evaluation order.
    pub ties: Vec<crate::tie::Tie>,
    pub sampling: Sampling,
    /// The settings of the `fem` solver's runs.
    pub fem_reference: FemReference,
    /// FNV-1a hash of the study file, the base file and every file a case reads (bytes):
    /// shards and resumed tables must carry the same one.
    pub hash: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    name: String,
    #[serde(default)]
    description: String,
    base: PathBuf,
    #[serde(default = "default_solvers")]
    solvers: Vec<String>,
    vary: Vec<VaryFile>,
    #[serde(default)]
    tie: Vec<TieFile>,
    sampling: Option<String>,
    samples: Option<usize>,
    seed: Option<u64>,
    fem_reference: Option<String>,
}

fn default_solvers() -> Vec<String> {
    vec!["amm".into()]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TieFile {
    key: String,
    formula: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VaryFile {
    key: String,
    values: Option<Vec<toml::Value>>,
    linspace: Option<Vec<toml::Value>>,
    logspace: Option<Vec<toml::Value>>,
    normal: Option<Vec<toml::Value>>,
    uniform: Option<Vec<toml::Value>>,
    /// Draw each beam of a whole beam key on its own: the key becomes three columns `key[1..3]`.
    #[serde(default)]
    per_beam: bool,
}

impl Study {
    /// Read, parse and validate a study file and its base experiment; every `[[vary]]` key is
    /// checked against the experiment format ([`Study::check_keys`]).
    pub fn load(path: &Path) -> Result<Study, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|source| StudyError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        let raw: StudyFile = toml::from_str(&text).map_err(|e| StudyError::Parse {
            file: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let name = check_name(path, &raw.name)?;
        let base_file = path.parent().unwrap_or(Path::new("")).join(&raw.base);
        let base_text = std::fs::read_to_string(&base_file).map_err(|source| StudyError::Base {
            study: path.to_path_buf(),
            source: ModelError::Read {
                file: base_file.clone(),
                source,
            },
        })?;
        let base_experiment = Experiment::from_toml_str(&base_text, &base_file).map_err(|source| StudyError::Base {
            study: path.to_path_buf(),
            source,
        })?;
        let base: toml::Table = base_text.parse().map_err(|e: toml::de::Error| StudyError::Base {
            study: path.to_path_buf(),
            source: ModelError::Parse {
                file: base_file.clone(),
                message: e.to_string(),
            },
        })?;
        let vary_list: Vec<Vary> = raw
            .vary
            .into_iter()
            .map(|v| vary(path, v))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .flatten()
            .collect();
        let ties = ties(path, raw.tie, &vary_list, &base)?;
        let study = Study {
            file: path.to_path_buf(),
            name,
            description: raw.description,
            base_file,
            base,
            base_experiment,
            solvers: solvers(path, &raw.solvers)?,
            vary: vary_list,
            ties,
            sampling: sampling(path, raw.sampling.as_deref(), raw.samples, raw.seed)?,
            fem_reference: fem_reference(path, raw.fem_reference.as_deref())?,
            hash: String::new(),
        };
        study.check_shape()?;
        study.check_keys()?;
        let hash = study.fingerprint(&text, &base_text);
        Ok(Study { hash, ..study })
    }

    /// The varied keys in the study's order (the columns after `run_id`).
    pub fn keys(&self) -> Vec<String> {
        self.vary.iter().map(|v| v.key.clone()).collect()
    }

    /// At least one key, no key twice (nor a whole key and one of its beams), no side of the base
    /// with the in-radius it replaces, and not more than [`MAX_CASES`] cases.
    fn check_shape(&self) -> Result<(), StudyError> {
        if self.vary.is_empty() {
            return Err(StudyError::invalid(
                &self.file,
                "vary",
                "a study needs at least one [[vary]] entry",
            ));
        }
        let parsed: Vec<Key> = self
            .vary
            .iter()
            .map(|v| Key::parse(&v.key).map_err(|e| self.vary_error(&v.key, e)))
            .collect::<Result<_, _>>()?;
        let tied: Vec<Key> = self.ties.iter().filter_map(|t| Key::parse(&t.key).ok()).collect();
        let sides = parsed
            .iter()
            .chain(&tied)
            .find(|k| k.path == "base.sides")
            .map(Key::text);
        for (i, v) in self.vary.iter().enumerate() {
            if self.vary[..i].iter().any(|w| w.key == v.key) {
                return Err(self.vary_error(&v.key, "the key is varied twice"));
            }
            if let Some(w) = parsed[..i].iter().find(|w| w.overlaps(&parsed[i])) {
                return Err(self.vary_error(
                    &v.key,
                    format!("{} is also varied: vary the whole key or its beams, not both", w.text()),
                ));
            }
            if let (Some(side), "robot.d" | "derived.d_share") = (&sides, v.key.as_str()) {
                return Err(self.vary_error(
                    &v.key,
                    format!(
                        "{side} gives the base by its sides, which replace robot.d: vary derived.dev.sides[i] \
                         (a factor on the sides of the base that robot.d or derived.d_share makes) instead"
                    ),
                ));
            }
            if v.levels.is_distribution() && self.sampling == Sampling::Grid {
                return Err(self.vary_error(
                    &v.key,
                    "a distribution is drawn from, not listed: set sampling = \"random\" (independent draws) \
                     or \"lhs\" (stratified), with samples",
                ));
            }
        }
        let count = match self.sampling {
            Sampling::Lhs { samples, .. } | Sampling::Random { samples, .. } => Some(samples),
            Sampling::Grid => self
                .vary
                .iter()
                .try_fold(1usize, |acc, v| acc.checked_mul(v.grid_values().len())),
        };
        match count {
            Some(c) if c <= MAX_CASES => Ok(()),
            _ => Err(StudyError::invalid(
                &self.file,
                "vary",
                format!("the study expands to more than {MAX_CASES} cases"),
            )),
        }
    }

    /// Check every `[[vary]]` key once, before any run: each probe value of the key (every listed
    /// value; the bounds of a range) is patched alone into the base experiment and parsed by the
    /// experiment loader. A key the loader does not know, or a value of the wrong type, is an
    /// error naming the study file and the key; a value the loader parses but refuses (out of
    /// range, infeasible motion) is not: those cases become rows with their reason.
    pub fn check_keys(&self) -> Result<(), StudyError> {
        for v in &self.vary {
            for value in v.probe_values() {
                let doc = patch::case_document(&self.base, std::slice::from_ref(&v.key), std::slice::from_ref(&value))
                    .map_err(|reason| self.vary_error(&v.key, reason))?;
                let text = toml::to_string(&doc).map_err(|e| self.vary_error(&v.key, e.to_string()))?;
                if let Err(ModelError::Parse { message, .. }) = Experiment::from_toml_str(&text, &self.base_file) {
                    return Err(self.vary_error(
                        &v.key,
                        format!(
                            "not accepted by the experiment format of {} with value {}: {}",
                            self.base_file.display(),
                            patch::value_text(&value),
                            parse_reason(&message)
                        ),
                    ));
                }
            }
        }
        for t in &self.ties {
            // a tied key must be a numeric key of the experiment format: patch a number and parse
            let doc = patch::case_document(&self.base, std::slice::from_ref(&t.key), &[toml::Value::Float(1.0)])
                .map_err(|reason| self.vary_error(&t.key, reason))?;
            let text = toml::to_string(&doc).map_err(|e| self.vary_error(&t.key, e.to_string()))?;
            if let Err(ModelError::Parse { message, .. }) = Experiment::from_toml_str(&text, &self.base_file) {
                return Err(self.vary_error(
                    &t.key,
                    format!(
                        "a tied key must be a numeric key of the experiment format: {}",
                        parse_reason(&message)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The study's hash: FNV-1a of the study file, the base file and the contents of every file
    /// a case reads (the base's forces table, and those a varied key names), in path order. A
    /// study without such files keeps the hash of the two texts alone.
    fn fingerprint(&self, text: &str, base_text: &str) -> String {
        let mut files: std::collections::BTreeSet<PathBuf> = self.base_experiment.input_files().into_iter().collect();
        for v in &self.vary {
            for value in v.probe_values() {
                if let Ok(exp) = self.experiment_with(std::slice::from_ref(&v.key), std::slice::from_ref(&value)) {
                    files.extend(exp.input_files());
                }
            }
        }
        let mut bytes = format!("{text}\0{base_text}").into_bytes();
        for f in files {
            bytes.push(0);
            // an unreadable file fails its cases; its absence is part of the fingerprint
            bytes.extend(std::fs::read(&f).unwrap_or_default());
        }
        hex64(&bytes)
    }

    fn vary_error(&self, key: &str, reason: impl Into<String>) -> StudyError {
        StudyError::VaryKey {
            file: self.file.clone(),
            key: key.to_string(),
            reason: reason.into(),
        }
    }

    /// The experiment of one case: the base document with the case's values patched in, parsed
    /// and validated by the experiment loader. Errors (a bad value, an infeasible motion) are
    /// returned as text for the case's `status`.
    pub fn experiment(&self, values: &[toml::Value]) -> Result<Experiment, String> {
        self.experiment_with(&self.keys(), values)
    }

    /// The experiment file of one case as TOML text: the base document with the case's values
    /// and ties (what [`Study::experiment`] loads; `examples/case_toml.rs` writes it, to rerun
    /// a case with `flexstar run`). Paths in it are relative to the base file's folder.
    pub fn case_toml(&self, values: &[toml::Value]) -> Result<String, String> {
        self.case_text(&self.keys(), values)
    }

    fn case_text(&self, keys: &[String], values: &[toml::Value]) -> Result<String, String> {
        let mut doc = patch::case_document(&self.base, keys, values)?;
        if keys.len() == self.vary.len() {
            crate::tie::apply(&mut doc, &self.ties)?;
        }
        toml::to_string(&doc).map_err(|e| e.to_string())
    }

    fn experiment_with(&self, keys: &[String], values: &[toml::Value]) -> Result<Experiment, String> {
        let text = self.case_text(keys, values)?;
        let exp = Experiment::from_toml_str(&text, &self.base_file).map_err(|e| e.to_string())?;
        flexstar_shaping::shape_loaded(exp).map_err(|e| e.to_string())
    }
}

/// The line of a TOML parse message that says why (the message also quotes the patched document).
pub fn parse_reason(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('|') && !l.starts_with("-->") && !l.starts_with("TOML parse error"))
        .filter(|l| !l.chars().next().is_some_and(|c| c.is_ascii_digit()))
        .collect::<Vec<_>>()
        .join(" ")
}

fn fem_reference(file: &Path, value: Option<&str>) -> Result<FemReference, StudyError> {
    match value {
        None | Some("defaults") => Ok(FemReference::Defaults),
        Some("refined") => Ok(FemReference::Refined),
        Some(other) => Err(StudyError::invalid(
            file,
            "fem_reference",
            format!("unknown value {other:?}: expected \"defaults\" or \"refined\""),
        )),
    }
}

fn check_name(file: &Path, name: &str) -> Result<String, StudyError> {
    let ok = !name.is_empty()
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.');
    if ok {
        Ok(name.to_string())
    } else {
        Err(StudyError::invalid(
            file,
            "name",
            format!("must be a non-empty file name of letters, digits, '-', '_', '.', got {name:?}"),
        ))
    }
}

fn solvers(file: &Path, names: &[String]) -> Result<Vec<Solver>, StudyError> {
    if names.is_empty() {
        return Err(StudyError::invalid(
            file,
            "solvers",
            "name at least one solver: \"amm\", \"fem\"",
        ));
    }
    let mut out = Vec::new();
    for n in names {
        let s = match n.as_str() {
            "amm" => Solver::Amm,
            "fem" => Solver::Fem,
            other => {
                return Err(StudyError::invalid(
                    file,
                    "solvers",
                    format!("unknown solver `{other}`: expected \"amm\" or \"fem\""),
                ))
            }
        };
        if out.contains(&s) {
            return Err(StudyError::invalid(file, "solvers", format!("`{n}` is listed twice")));
        }
        out.push(s);
    }
    Ok(out)
}

fn sampling(
    file: &Path,
    kind: Option<&str>,
    samples: Option<usize>,
    seed: Option<u64>,
) -> Result<Sampling, StudyError> {
    match kind.unwrap_or("grid") {
        "grid" => {
            if samples.is_some() || seed.is_some() {
                return Err(StudyError::invalid(
                    file,
                    if samples.is_some() { "samples" } else { "seed" },
                    "used with sampling = \"lhs\" or \"random\" only",
                ));
            }
            Ok(Sampling::Grid)
        }
        "lhs" => match samples {
            Some(n) if n >= 1 => Ok(Sampling::Lhs {
                samples: n,
                seed: seed.unwrap_or(1),
            }),
            _ => Err(StudyError::invalid(
                file,
                "samples",
                "sampling = \"lhs\" needs samples >= 1",
            )),
        },
        "random" => match samples {
            Some(n) if n >= 1 => Ok(Sampling::Random {
                samples: n,
                seed: seed.unwrap_or(1),
            }),
            _ => Err(StudyError::invalid(
                file,
                "samples",
                "sampling = \"random\" needs samples >= 1",
            )),
        },
        other => Err(StudyError::invalid(
            file,
            "sampling",
            format!("unknown sampling `{other}`: expected \"grid\", \"lhs\" or \"random\""),
        )),
    }
}

/// One `[[vary]]` entry: one key, or with `per_beam = true` the three beams of a whole beam key
/// (`robot.L[1]`, `robot.L[2]`, `robot.L[3]`, each with the entry's levels: three columns of a
/// grid or a hypercube, three independent draws).
fn vary(file: &Path, v: VaryFile) -> Result<Vec<Vary>, StudyError> {
    let name = v.key.clone();
    let err = move |reason: String| StudyError::VaryKey {
        file: file.to_path_buf(),
        key: name.clone(),
        reason,
    };
    let key_ok = !v.key.is_empty() && v.key.split('.').all(|p| !p.is_empty()) && v.key.contains('.');
    if !key_ok {
        return Err(err(
            "a key is a dotted experiment key such as robot.Lp or time.t_end, or scale.duration".into(),
        ));
    }
    let parsed = Key::parse(&v.key).map_err(&err)?;
    if v.key.starts_with("scale.") && v.key != SCALE_DURATION {
        return Err(err(format!("the only scale key is {SCALE_DURATION}")));
    }
    if v.key.starts_with("derived.") && !crate::derived::is_derived(&v.key) {
        return Err(err(format!(
            "unknown derived key; the derived keys are {} (derived.dev.* with an optional index [i])",
            crate::derived::DERIVED.join(", ")
        )));
    }
    if v.per_beam && (parsed.index.is_some() || !key::per_beam_allowed(&parsed.path)) {
        return Err(err(if parsed.index.is_some() {
            "per_beam = true draws each beam of a whole key: give the key without an index".into()
        } else {
            format!(
                "per_beam = true takes a beam key of [robot] ({}) or a derived deviation derived.dev.*; \
                 vary the entries of other list keys one by one ({}[2])",
                key::BEAM_KEYS.join(", "),
                v.key
            )
        }));
    }
    let per_beam = v.per_beam;
    let one = one_vary(v, err)?;
    if !per_beam {
        return Ok(vec![one]);
    }
    Ok((1..=3)
        .map(|i| Vary {
            key: parsed.at(i).text(),
            levels: one.levels.clone(),
        })
        .collect())
}

/// The levels of one `[[vary]]` entry, checked.
fn one_vary(v: VaryFile, err: impl Fn(String) -> StudyError) -> Result<Vary, StudyError> {
    let given = [
        v.values.is_some(),
        v.linspace.is_some(),
        v.logspace.is_some(),
        v.normal.is_some(),
        v.uniform.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(err(
            "give exactly one of values, linspace, logspace, normal or uniform".into()
        ));
    }
    if let Some(p) = &v.normal {
        let [mean, sd] = pair(p).map_err(|m| err(format!("normal = [mean, sd]: {m}")))?;
        if sd <= 0.0 {
            return Err(err(format!("normal = [mean, sd] needs sd > 0, got sd = {sd}")));
        }
        return Ok(Vary {
            key: v.key,
            levels: Levels::Normal { mean, sd },
        });
    }
    if let Some(p) = &v.uniform {
        let [lo, hi] = pair(p).map_err(|m| err(format!("uniform = [lo, hi]: {m}")))?;
        if lo >= hi {
            return Err(err(format!(
                "uniform = [lo, hi] needs lo < hi, got lo = {lo}, hi = {hi}"
            )));
        }
        return Ok(Vary {
            key: v.key,
            levels: Levels::Uniform { lo, hi },
        });
    }
    let levels = match (v.values, v.linspace, v.logspace) {
        (Some(values), None, None) => {
            if values.is_empty() {
                return Err(err("empty range: `values` lists no value".into()));
            }
            Levels::Values(values)
        }
        (None, Some(r), None) => {
            let (a, b, n) = range(&r).map_err(|m| err(format!("linspace = [a, b, n]: {m}")))?;
            let integer = r[0].is_integer() && r[1].is_integer();
            Levels::Linspace { a, b, n, integer }
        }
        (None, None, Some(r)) => {
            let (a, b, n) = range(&r).map_err(|m| err(format!("logspace = [a, b, n]: {m}")))?;
            if a <= 0.0 || b <= 0.0 {
                return Err(err(format!(
                    "logspace = [a, b, n] needs a > 0 and b > 0, got a = {a}, b = {b}"
                )));
            }
            Levels::Logspace { a, b, n }
        }
        _ => return Err(err("give exactly one of values, linspace or logspace".into())),
    };
    Ok(Vary { key: v.key, levels })
}

/// Two finite numbers.
fn pair(r: &[toml::Value]) -> Result<[f64; 2], String> {
    let num = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    match r {
        [a, b] => match (num(a), num(b)) {
            (Some(a), Some(b)) if a.is_finite() && b.is_finite() => Ok([a, b]),
            _ => Err("two finite numbers expected".into()),
        },
        _ => Err(format!("two entries expected, got {}", r.len())),
    }
}

/// The `[[tie]]` entries, parsed and ordered (`crate::tie`); the key syntax as for `[[vary]]`.
fn ties(file: &Path, raw: Vec<TieFile>, vary: &[Vary], base: &toml::Table) -> Result<Vec<crate::tie::Tie>, StudyError> {
    let err = |key: &str, reason: String| StudyError::VaryKey {
        file: file.to_path_buf(),
        key: key.to_string(),
        reason,
    };
    let mut ties = Vec::with_capacity(raw.len());
    for t in raw {
        if !(t.key.contains('.') && t.key.split('.').all(|p| !p.is_empty())) || t.key.starts_with("scale.") {
            return Err(err(
                &t.key,
                "a tied key is a dotted experiment key such as robot.Jp".into(),
            ));
        }
        ties.push(crate::tie::Tie::new(&t.key, &t.formula).map_err(|m| err(&t.key, m))?);
    }
    let varied: Vec<String> = vary.iter().map(|v| v.key.clone()).collect();
    crate::tie::ordered(ties, &varied, base).map_err(|(key, reason)| err(&key, reason))
}

fn range(r: &[toml::Value]) -> Result<(f64, f64, usize), String> {
    if r.len() != 3 {
        return Err(format!("three entries expected, got {}", r.len()));
    }
    let num = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    let (Some(a), Some(b)) = (num(&r[0]), num(&r[1])) else {
        return Err("a and b must be numbers".into());
    };
    if !a.is_finite() || !b.is_finite() {
        return Err(format!("a and b must be finite, got {a}, {b}"));
    }
    match r[2].as_integer() {
        Some(n) if n >= 1 => Ok((a, b, n as usize)),
        Some(n) => Err(format!("empty range: n = {n}, need n >= 1")),
        None => Err(format!("n must be a whole number, got {}", r[2])),
    }
}
