//! The `[plan]` and `[limits]` sections of a planning experiment (`docs/motions.md` 4.1, 4.8) and
//! how a plan file becomes an experiment: the sections are taken out, `[trajectory]` and
//! `[shaper]` are refused (the planner makes the motions itself), and the plain quintic of the
//! plan stands in as the trajectory, so that every other section is read and checked exactly as
//! `flexstar run` reads it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use flexstar_model::{Experiment, ModelError, Pose};

use crate::PlanError;

/// What the planner minimises (`[plan] objective`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Objective {
    /// The residual vibration of G after a move of the given `t_move` (default).
    Residual,
    /// The shortest move whose residual peak at G is at most `residual_max`.
    Time,
}

/// Which motions the planner searches (`[plan] shape`, `docs/motions.md` 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Shape {
    /// Interior poses on the segment from `from` to `to`: a timing law, one number per point.
    Timing,
    /// Interior poses anywhere near the quintic's path: three numbers per point.
    Path,
}

impl Shape {
    /// The key's word in a plan file (`"timing"`, `"path"`).
    pub fn word(self) -> &'static str {
        match self {
            Shape::Timing => "timing",
            Shape::Path => "path",
        }
    }
}

/// `[plan]`: a rest-to-rest move from `from` at `t0` to `to` (`docs/motions.md` 4.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanSection {
    /// Start pose (G [m] in the fixed frame, theta [rad]).
    pub from: Pose,
    /// End pose.
    pub to: Pose,
    /// Start of the move [s] (default 0).
    #[serde(default)]
    pub t0: f64,
    /// Duration of the move [s]; exclusive with `objective = "time"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_move: Option<f64>,
    /// `"residual"` (default) or `"time"`.
    #[serde(default = "default_objective")]
    pub objective: Objective,
    /// `objective = "time"`: the largest residual peak of |dG| after the move [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_max: Option<f64>,
    /// `"path"` (default) or `"timing"` (`docs/motions.md` 4.10, "The default shape").
    #[serde(default = "default_shape")]
    pub shape: Shape,
    /// Interior via points (default 12 for timing, 4 for path).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<usize>,
    /// Wall-clock budget of the optimiser [s] (default 8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget_s: Option<f64>,
    /// Smoothness weight `w_s` >= 0 (default [`DEFAULT_SMOOTHNESS`]): the slider jerk's departure
    /// from the plain quintic's joins the objective (`docs/motions.md` 4.10, Eq. S1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothness: Option<f64>,
    /// The planned motion's peak `|s_i''|`, `|s_i'''|` and `|Fa_i|` stay within this factor
    /// (>= 1) of the plain quintic's at the same duration (default [`DEFAULT_PEAK_FACTOR`]);
    /// `"off"` lifts it (`docs/motions.md` 4.10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_factor: Option<PeakFactor>,
    /// Progress along the path never goes backwards (default true; `docs/motions.md` 4.10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monotone: Option<bool>,
    /// Weight `w_t` >= 0 of the tips' residual in the objective (default 0: G only;
    /// `docs/motions.md` 4.10, Eq. S2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_weight: Option<f64>,
}

/// The default of `[plan] peak_factor` (`docs/motions.md` 4.10).
pub const DEFAULT_PEAK_FACTOR: f64 = 1.5;
/// The default of `[plan] smoothness` (`docs/motions.md` 4.10).
pub const DEFAULT_SMOOTHNESS: f64 = 0.0;

/// `[plan] peak_factor`: a number >= 1, or the word `"off"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PeakFactor {
    /// The factor on the plain quintic's peaks (dimensionless).
    Factor(f64),
    /// `"off"` (any other word is refused by [`PlanSection::validate`]).
    Word(String),
}

fn default_objective() -> Objective {
    Objective::Residual
}

fn default_shape() -> Shape {
    Shape::Path
}

/// `[limits]`: bounds the planned motion keeps (each optional).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Largest slider speed `|s_i'|` [m/s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_max: Option<f64>,
    /// Largest slider acceleration `|s_i''|` [m/s^2].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a_max: Option<f64>,
    /// Largest slider jerk `|s_i'''|` [m/s^3] (`docs/motions.md` 4.10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub j_max: Option<f64>,
    /// Largest driving force `|Fa_i|` [N] (Eq. 33, the accurate AMM's).
    #[serde(rename = "Fa_max", default, skip_serializing_if = "Option::is_none")]
    pub fa_max: Option<f64>,
}

impl PlanSection {
    /// Interior via points: `points`, else 12 (timing) or 4 (path); `docs/motions.md` 4.9 says
    /// why 12 for timing, 4.10 ("The default shape") how 4 for path was measured.
    pub fn interior_points(&self) -> usize {
        self.points.unwrap_or(match self.shape {
            Shape::Timing => 12,
            Shape::Path => 4,
        })
    }

    /// The optimiser's wall-clock budget [s].
    pub fn budget(&self) -> f64 {
        self.budget_s.unwrap_or(8.0)
    }

    /// The factor on the plain quintic's peaks; `None` when lifted (`"off"`).
    pub fn peak_factor(&self) -> Option<f64> {
        match &self.peak_factor {
            None => Some(DEFAULT_PEAK_FACTOR),
            Some(PeakFactor::Factor(f)) => Some(*f),
            Some(PeakFactor::Word(_)) => None,
        }
    }

    /// The smoothness weight `w_s` (dimensionless).
    pub fn smoothness(&self) -> f64 {
        self.smoothness.unwrap_or(DEFAULT_SMOOTHNESS)
    }

    /// The tips' weight `w_t` (dimensionless).
    pub fn tip_weight(&self) -> f64 {
        self.tip_weight.unwrap_or(0.0)
    }

    /// Must the progress along the path be monotone?
    pub fn monotone(&self) -> bool {
        self.monotone.unwrap_or(true)
    }

    /// The checks that need no robot (`docs/motions.md` 4.8): finite poses, `t0 >= 0`, exactly
    /// one of `t_move` and `objective = "time"` (with `residual_max > 0`), `points` 1..=20.
    pub fn validate(&self) -> Result<(), ModelError> {
        for (key, p) in [("plan.from", self.from), ("plan.to", self.to)] {
            if ![p.gx, p.gy, p.theta].iter().all(|v| v.is_finite()) {
                return Err(ModelError::invalid(key, "Gx, Gy and theta must be finite"));
            }
        }
        if !(self.t0.is_finite() && self.t0 >= 0.0) {
            return Err(ModelError::invalid("plan.t0", format!("must be >= 0, got {}", self.t0)));
        }
        self.validate_objective()?;
        let m = self.interior_points();
        if !(1..=20).contains(&m) {
            return Err(ModelError::invalid("plan.points", format!("must be 1 to 20, got {m}")));
        }
        if let Some(b) = self.budget_s.filter(|b| !(b.is_finite() && *b > 0.0)) {
            return Err(ModelError::invalid(
                "plan.budget_s",
                format!("must be positive, got {b}"),
            ));
        }
        self.validate_smooth()?;
        if self.from == self.to {
            return Err(ModelError::invalid("plan.to", "the move has no extent: to equals from"));
        }
        Ok(())
    }

    /// `peak_factor` a finite number >= 1 or `"off"`; `smoothness`, `tip_weight` finite and >= 0.
    fn validate_smooth(&self) -> Result<(), ModelError> {
        match &self.peak_factor {
            Some(PeakFactor::Factor(f)) if !(f.is_finite() && *f >= 1.0) => {
                return Err(ModelError::invalid(
                    "plan.peak_factor",
                    format!(
                        "must be a finite number >= 1 (the plain quintic, the planner's start, has factor 1) or \"off\", got {f}"
                    ),
                ))
            }
            Some(PeakFactor::Word(w)) if w != "off" => {
                return Err(ModelError::invalid(
                    "plan.peak_factor",
                    format!("must be a number >= 1 or \"off\", got \"{w}\""),
                ))
            }
            _ => {}
        }
        for (key, v) in [
            ("plan.smoothness", self.smoothness),
            ("plan.tip_weight", self.tip_weight),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(ModelError::invalid(key, format!("must be finite and >= 0, got {v}")));
            }
        }
        Ok(())
    }

    fn validate_objective(&self) -> Result<(), ModelError> {
        match (self.objective, self.t_move, self.residual_max) {
            (Objective::Residual, Some(t), None) if t.is_finite() && t > 0.0 => Ok(()),
            (Objective::Residual, Some(t), None) => Err(ModelError::invalid(
                "plan.t_move",
                format!("must be a positive duration [s], got {t}"),
            )),
            (Objective::Residual, None, _) => Err(ModelError::invalid(
                "plan.t_move",
                "missing: give t_move [s], or objective = \"time\" with residual_max [m]",
            )),
            (Objective::Residual, Some(_), Some(_)) => Err(ModelError::invalid(
                "plan.residual_max",
                "applies to objective = \"time\" only (the residual objective minimises the residual)",
            )),
            (Objective::Time, Some(_), _) => Err(ModelError::invalid(
                "plan.t_move",
                "objective = \"time\" chooses the duration: give residual_max, not t_move",
            )),
            (Objective::Time, None, Some(r)) if r.is_finite() && r > 0.0 => Ok(()),
            (Objective::Time, None, r) => Err(ModelError::invalid(
                "plan.residual_max",
                format!(
                    "objective = \"time\" needs residual_max [m] > 0, got {}",
                    r.map_or("none".to_string(), |r| r.to_string())
                ),
            )),
        }
    }
}

impl Limits {
    /// Every given limit positive and finite.
    pub fn validate(&self) -> Result<(), ModelError> {
        for (key, v) in [
            ("limits.v_max", self.v_max),
            ("limits.a_max", self.a_max),
            ("limits.j_max", self.j_max),
            ("limits.Fa_max", self.fa_max),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(ModelError::invalid(
                    key,
                    format!("must be positive and finite, got {v}"),
                ));
            }
        }
        Ok(())
    }

    /// Is any limit given?
    pub fn any(&self) -> bool {
        self.v_max.is_some() || self.a_max.is_some() || self.j_max.is_some() || self.fa_max.is_some()
    }
}

/// A planning experiment as read: the experiment (its trajectory the plain quintic of the plan,
/// of duration `t_move`, or of a provisional 1 s for `objective = "time"`), the plan and the
/// limits, and the TOML table the file held (for `plan.toml`).
#[derive(Debug, Clone)]
pub struct PlanConfig {
    pub exp: Experiment,
    pub plan: PlanSection,
    pub limits: Limits,
    /// The file's table without `[plan]`, `[limits]` and `[robust]`.
    pub table: toml::Table,
    /// `[robust]`: the uncertainty a robust plan holds over (`docs/motions.md` 4.11).
    pub robust: Option<crate::uncertainty::Uncertainty>,
    /// `[plan] points` or a `via` cycle (`docs/motions.md` 4.12): the moves and dwells; then
    /// `plan` holds the first move and `exp` runs the plain quintic cycle.
    pub cycle: Option<crate::cycle::Cycle>,
}

/// Read and check a plan file: TOML syntax, the two sections (unknown keys refused), no
/// `[trajectory]` or `[shaper]`, then the rest as an experiment. Errors name the file and key.
pub fn read_plan_config(path: &Path) -> Result<PlanConfig, PlanError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    plan_config_from_str(&text, path)
}

/// [`read_plan_config`] from text (`path` names the file in messages and anchors relative files).
pub fn plan_config_from_str(text: &str, path: &Path) -> Result<PlanConfig, PlanError> {
    let in_file = |e: ModelError| PlanError::from(e.in_file(path));
    let mut table: toml::Table = toml::from_str(text).map_err(|e| ModelError::Parse {
        file: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    let cycle = crate::cycle::take_cycle(&mut table, path)?;
    for (key, why) in [
        (
            "trajectory",
            "a plan makes its motions itself: give [plan] instead of [trajectory]",
        ),
        (
            "shaper",
            "a plan compares with the ZVD-shaped quintic itself: remove [shaper]",
        ),
    ] {
        if table.contains_key(key) {
            return Err(in_file(ModelError::invalid(key, why)));
        }
    }
    let plan: PlanSection = section(&mut table, "plan", path)?.ok_or_else(|| {
        in_file(ModelError::invalid(
            "plan",
            "missing: a plan file needs a [plan] section",
        ))
    })?;
    let limits: Limits = section(&mut table, "limits", path)?.unwrap_or_default();
    let robust: Option<toml::Table> = section(&mut table, "robust", path)?;
    plan.validate().map_err(in_file)?;
    limits.validate().map_err(in_file)?;
    let t_move = plan.t_move.unwrap_or(1.0);
    let mut with_motion = table.clone();
    let motion = match &cycle {
        Some(c) => c.plain_trajectory(),
        None => quintic_table(&plan, t_move),
    };
    with_motion.insert("trajectory".into(), motion);
    let rebuilt = toml::to_string(&with_motion).map_err(|e| ModelError::Parse {
        file: path.to_path_buf(),
        message: e.to_string(),
    })?;
    // the stand-in quintic's keys are the plan's (`trajectory.to` is `plan.to`)
    let exp = Experiment::from_toml_str(&rebuilt, path).map_err(|e| match e {
        ModelError::Invalid { file, key, reason } if cycle.is_some() && key == "trajectory.points" => {
            let (key, reason) = crate::cycle::via_error_key(&reason);
            ModelError::Invalid { file, key, reason }
        }
        ModelError::Invalid { file, key, reason } if key.starts_with("trajectory") => ModelError::Invalid {
            file,
            key: key.replacen("trajectory", "plan", 1),
            reason,
        },
        other => other,
    })?;
    let robust = match robust {
        Some(_) if cycle.is_some() => {
            return Err(in_file(ModelError::invalid(
                "robust",
                "a robust plan is not designed for cycles (docs/motions.md 4.12): remove [robust] or plan one move",
            )))
        }
        Some(r) => Some(read_robust(r, &plan, &with_motion, path)?),
        None => None,
    };
    if let Some(c) = &cycle {
        c.check_t_end(exp.time.t_end).map_err(in_file)?;
    }
    Ok(PlanConfig {
        exp,
        plan,
        limits,
        table,
        robust,
        cycle,
    })
}

/// `[robust]` against the file's experiment document (`docs/motions.md` 4.11); refused with
/// `objective = "time"` (a robust time search is not designed).
fn read_robust(
    section: toml::Table,
    plan: &PlanSection,
    doc: &toml::Table,
    path: &Path,
) -> Result<crate::uncertainty::Uncertainty, PlanError> {
    if plan.objective == Objective::Time {
        return Err(ModelError::invalid(
            "robust",
            "applies to the residual objective only (t_move given); objective = \"time\" is not robust",
        )
        .in_file(path)
        .into());
    }
    Ok(crate::uncertainty::Uncertainty::read(section, doc, path)?)
}

/// Take the table `key` out of `table` and deserialize it (errors name the section).
fn section<T: serde::de::DeserializeOwned>(
    table: &mut toml::Table,
    key: &str,
    path: &Path,
) -> Result<Option<T>, PlanError> {
    let Some(value) = table.remove(key) else {
        return Ok(None);
    };
    value.try_into().map(Some).map_err(|e: toml::de::Error| {
        PlanError::from(ModelError::Parse {
            file: path.to_path_buf(),
            message: format!("[{key}]: {}", e.message().trim_end()),
        })
    })
}

/// The `[trajectory]` table of the plain quintic of the plan over `t_move` [s].
pub fn quintic_table(plan: &PlanSection, t_move: f64) -> toml::Value {
    let pose = |p: Pose| {
        toml::Value::Table(toml::Table::from_iter([
            ("Gx".to_string(), toml::Value::Float(p.gx)),
            ("Gy".to_string(), toml::Value::Float(p.gy)),
            ("theta".to_string(), toml::Value::Float(p.theta)),
        ]))
    };
    toml::Value::Table(toml::Table::from_iter([
        ("kind".to_string(), toml::Value::String("quintic".into())),
        ("from".to_string(), pose(plan.from)),
        ("to".to_string(), pose(plan.to)),
        ("t0".to_string(), toml::Value::Float(plan.t0)),
        ("t1".to_string(), toml::Value::Float(plan.t0 + t_move)),
    ]))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str =
        "name = \"t\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n[plan]\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\n\
                        to = { Gx = 0.03, Gy = -0.02, theta = 0.2 }\nt_move = 0.42\n";

    fn read(extra: &str) -> Result<PlanConfig, PlanError> {
        plan_config_from_str(&format!("{HEAD}{extra}"), Path::new("smooth.toml"))
    }

    fn refused(extra: &str, key: &str) {
        match read(extra) {
            Err(PlanError::Input(e)) => {
                let msg = e.to_string();
                assert!(msg.contains("smooth.toml") && msg.contains(key), "{extra}: {msg}");
            }
            other => panic!("{extra}: not refused with {key}: {other:?}"),
        }
    }

    /// The keys of `docs/motions.md` 4.10 as read: defaults, a number, `"off"`, an integer factor.
    #[test]
    fn smooth_keys_read_with_their_defaults() {
        let c = read("").unwrap();
        assert_eq!(c.plan.peak_factor(), Some(DEFAULT_PEAK_FACTOR));
        assert!(c.plan.monotone() && c.plan.smoothness() == 0.0 && c.plan.tip_weight() == 0.0);
        assert_eq!(c.limits.j_max, None);
        let c = read(
            "peak_factor = \"off\"\nmonotone = false\nsmoothness = 0.5\ntip_weight = 2.0\n[limits]\nj_max = 80.0\n",
        )
        .unwrap();
        assert_eq!(c.plan.peak_factor(), None);
        assert!(!c.plan.monotone() && c.plan.smoothness() == 0.5 && c.plan.tip_weight() == 2.0);
        assert_eq!(c.limits.j_max, Some(80.0));
        assert_eq!(read("peak_factor = 2\n").unwrap().plan.peak_factor(), Some(2.0));
    }

    /// `[robust]` as read (`docs/motions.md` 4.11): quoted and bare dotted keys, an indexed
    /// key, the nominal value taken from the file or the paper's default list, the defaults.
    #[test]
    fn robust_ranges_read_with_their_nominal_values() {
        let c = read("[payload]\nmass = 0.25\n[robust]\n\"payload.mass\" = [0.0, 0.5]\nrobot.E = [180e9, 220e9]\n\"robot.L[2]\" = [0.49, 0.51]\n")
            .unwrap();
        let u = c.robust.expect("[robust]");
        let mut got: Vec<(String, f64, f64, f64)> = u
            .ranges
            .iter()
            .map(|r| (r.key.clone(), r.lo, r.hi, r.nominal))
            .collect();
        got.sort_by(|a, b| a.0.cmp(&b.0));
        assert_eq!(
            got,
            vec![
                ("payload.mass".to_string(), 0.0, 0.5, 0.25),
                ("robot.E".to_string(), 180e9, 220e9, 200e9),
                ("robot.L[2]".to_string(), 0.49, 0.51, 0.5),
            ]
        );
        assert_eq!((u.quantile, u.draws, u.seed), (1.0, 20, 1));
        // a model at given values carries them (the study's setter, then the loader)
        let ends: Vec<f64> = u.ranges.iter().map(|r| r.hi).collect();
        let m = u.model_at(&ends).unwrap();
        assert_eq!(m.payload.mass, 0.5);
        let draws = u.fresh_draws();
        assert_eq!(draws.len(), 20);
        assert!(draws
            .iter()
            .all(|d| d.iter().zip(&u.ranges).all(|(v, r)| *v >= r.lo && *v <= r.hi)));
        assert_eq!(u.candidates().len(), 8);
    }

    /// `[robust] fit = "fit.json"` (`docs/motions.md` 4.11): each fitted parameter's range is the
    /// shadow of the fit's joint 95 % region, `estimate -+ sqrt(chi2_2(0.95)) se` with
    /// `chi2_2(0.95) = 5.9915` (tables) and `se` the wider of the two standard errors, cut to the
    /// fit's box; a fit that is no calibration and a key given twice are refused.
    #[test]
    fn robust_ranges_from_a_fit_are_its_confidence_region_s_shadow() {
        let dir = std::env::temp_dir().join(format!("flexstar-robust-fit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fit = |calibrated: bool| {
            format!(
                "{{\"calibrated\": {calibrated}, \"reason\": \"converged\", \"parameters\": [\
                 {{\"key\": \"payload.mass\", \"estimate\": 0.25, \"lo\": 0.21, \"hi\": 1.0, \
                 \"standard_error\": 0.01, \"standard_error_correlated\": 0.02}},\
                 {{\"key\": \"robot.E\", \"estimate\": 2e11, \"lo\": 1.5e11, \"hi\": 2.5e11, \
                 \"standard_error\": 1e9, \"standard_error_correlated\": null}}]}}"
            )
        };
        std::fs::write(dir.join("fit.json"), fit(true)).unwrap();
        std::fs::write(dir.join("bad.json"), fit(false)).unwrap();
        let plan = |robust: &str| {
            plan_config_from_str(
                &format!("{HEAD}[payload]\nmass = 0.25\n[robust]\n{robust}"),
                &dir.join("plan.toml"),
            )
        };
        let u = plan("fit = \"fit.json\"\n").unwrap().robust.unwrap();
        let k = 5.9915f64.sqrt();
        // the mass's lower end, 0.25 - 0.049, is cut to the fit's box at 0.21
        let want = [
            ("payload.mass", 0.21, 0.25 + k * 0.02),
            ("robot.E", 2e11 - k * 1e9, 2e11 + k * 1e9),
        ];
        for (r, (key, lo, hi)) in u.ranges.iter().zip(want) {
            assert_eq!(r.key, key);
            assert!(
                (r.lo / lo - 1.0).abs() < 1e-5 && (r.hi / hi - 1.0).abs() < 1e-5,
                "{r:?} vs [{lo}, {hi}]"
            );
        }
        for (robust, why) in [
            ("fit = \"bad.json\"\n", "no calibration"),
            ("fit = \"none.json\"\n", "none.json"),
            ("fit = \"fit.json\"\n\"payload.mass\" = [0.0, 0.5]\n", "twice"),
        ] {
            let msg = match plan(robust) {
                Err(PlanError::Input(e)) => e.to_string(),
                other => panic!("{robust}: {other:?}"),
            };
            assert!(
                msg.contains("plan.toml") && msg.contains("robust") && msg.contains(why),
                "{msg}"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Bad `[robust]` entries are refused before any work, naming the file and the key.
    #[test]
    fn bad_robust_entries_are_refused_with_the_key() {
        let with = |body: &str| format!("[payload]\nmass = 0.25\n[robust]\n{body}");
        refused(&with("\"payload.mass\" = [0.3, 0.5]\n"), "robust.\"payload.mass\"");
        refused(&with("\"payload.mass\" = [0.5, 0.0]\n"), "robust.\"payload.mass\"");
        refused(&with("\"payload.mass\" = [0.5, 0.5]\n"), "robust.\"payload.mass\"");
        refused(&with("\"payload.mass\" = 0.5\n"), "robust.\"payload.mass\"");
        refused(&with("\"payload.mass\" = [-1.0, 0.5]\n"), "robust.\"payload.mass\"");
        refused(&with("\"robot.Q\" = [1.0, 2.0]\n"), "robust.\"robot.Q\"");
        refused(&with("\"amm.family\" = [1.0, 2.0]\n"), "robust.\"amm.family\"");
        refused(&with("\"robot.L[4]\" = [0.4, 0.6]\n"), "robust.\"robot.L[4]\"");
        refused(
            &with("\"payload.mass\" = [0.0, 0.5]\nquantile = 0.0\n"),
            "robust.quantile",
        );
        refused(
            &with("\"payload.mass\" = [0.0, 0.5]\nquantile = 1.5\n"),
            "robust.quantile",
        );
        refused(&with("\"payload.mass\" = [0.0, 0.5]\ndraws = 0\n"), "robust.draws");
        refused(&with("quantile = 0.5\n"), "robust");
        for t in ["0.0", "-0.5", "nan", "\"shaped\"", "[0.5]"] {
            refused(
                &with(&format!("\"payload.mass\" = [0.0, 0.5]\nt_move = {t}\n")),
                "robust.t_move",
            );
        }
        let msg = match read(&with("\"payload.mass\" = [0.3, 0.5]\n")) {
            Err(PlanError::Input(e)) => e.to_string(),
            other => panic!("{other:?}"),
        };
        assert!(msg.contains("excludes the experiment's own value 0.25"), "{msg}");
    }

    /// `[robust] t_move` as read: the plan's by default, `"zvd"`, seconds; seconds shorter than
    /// `[plan] t_move` refused before any work (a robust plan takes at least the nominal time).
    #[test]
    fn the_robust_duration_is_read_and_checked() {
        use crate::uncertainty::RobustDuration;
        let with = |body: &str| format!("[payload]\nmass = 0.25\n[robust]\n\"payload.mass\" = [0.0, 0.5]\n{body}");
        let duration = |body: &str| read(&with(body)).unwrap().robust.unwrap().t_move;
        assert_eq!(duration(""), RobustDuration::Plan);
        assert_eq!(duration("t_move = \"plan\"\n"), RobustDuration::Plan);
        assert_eq!(duration("t_move = \"zvd\"\n"), RobustDuration::Zvd);
        assert_eq!(duration("t_move = 0.9\n"), RobustDuration::Seconds(0.9));
        assert!(crate::planner::check_plan_input(&read(&with("t_move = 0.9\n")).unwrap()).is_ok());
        match crate::planner::check_plan_input(&read(&with("t_move = 0.3\n")).unwrap()) {
            Err(PlanError::Input(e)) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("smooth.toml") && msg.contains("robust.t_move") && msg.contains("0.42"),
                    "{msg}"
                );
            }
            other => panic!("a robust plan shorter than the plan accepted: {other:?}"),
        }
    }

    /// Bad values of the new keys are refused with the file and the key (4.8, 4.10).
    #[test]
    fn bad_smooth_keys_are_refused_with_the_key() {
        refused("[limits]\nj_max = 0.0\n", "limits.j_max");
        refused("[limits]\nj_max = -3.0\n", "limits.j_max");
        refused("[limits]\nj_max = nan\n", "limits.j_max");
        refused("[limits]\nj_max = inf\n", "limits.j_max");
        refused("peak_factor = 0.5\n", "plan.peak_factor");
        refused("peak_factor = nan\n", "plan.peak_factor");
        refused("peak_factor = \"of\"\n", "plan.peak_factor");
        refused("smoothness = -1.0\n", "plan.smoothness");
        refused("tip_weight = inf\n", "plan.tip_weight");
        match read("[limits]\njerk_max = 3.0\n") {
            Err(PlanError::Input(e)) => assert!(e.to_string().contains("jerk_max"), "{e}"),
            other => panic!("unknown key accepted: {other:?}"),
        }
    }
}
