//! TOML experiment files: robot parameters, trajectory, time span and solver settings.
//!
//! ```toml
//! name = "case1"
//! [robot]            # optional; every key defaults to the paper (section 8)
//! L = 0.5
//! [time]
//! t_end = 0.5        # s
//! dt_out = 0.001     # s, output step
//! [trajectory]
//! kind = "polynomial"
//! s1 = [0.0, 0.0, 1.0]   # s1(t) = t^2
//! s2 = [0.0, 0.0, 1.0]
//! s3 = [0.0, 0.0, 1.0]
//! [amm]              # optional
//! family = "pinned-free"
//! modes = 25
//! [fem]              # optional
//! elements = 300
//! ```
//! Unknown keys are rejected; errors name the file, the key and the reason.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::params::RobotParams;
use crate::trajectory::Trajectory;

/// Simulated time span and output sampling.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpan {
    /// End time [s]; the motion starts at t = 0 from the configuration s_i(0), at rest, undeformed.
    pub t_end: f64,
    /// Output step [s].
    #[serde(default = "default_dt_out")]
    pub dt_out: f64,
}

fn default_dt_out() -> f64 {
    1e-3
}

impl TimeSpan {
    /// Output times `0, dt_out, 2 dt_out, ...` up to and including `t_end`.
    pub fn output_times(&self) -> Vec<f64> {
        let n = (self.t_end / self.dt_out - 1e-9).ceil() as usize;
        (0..=n).map(|k| (k as f64 * self.dt_out).min(self.t_end)).collect()
    }

    pub fn validate(&self) -> Result<(), ModelError> {
        if !self.t_end.is_finite() || self.t_end <= 0.0 {
            return Err(ModelError::invalid(
                "time.t_end",
                format!("the time span must be non-empty: need t_end > 0, got {}", self.t_end),
            ));
        }
        if !self.dt_out.is_finite() || self.dt_out <= 0.0 || self.dt_out > self.t_end {
            return Err(ModelError::invalid(
                "time.dt_out",
                format!("need 0 < dt_out <= t_end = {}, got {}", self.t_end, self.dt_out),
            ));
        }
        if self.t_end / self.dt_out > 1e7 {
            return Err(ModelError::invalid(
                "time.dt_out",
                format!("more than 1e7 output steps ({} / {})", self.t_end, self.dt_out),
            ));
        }
        Ok(())
    }
}

/// Assumed-mode families (Eq. 34-1, MODEL-NOTES section 4), named by the boundary condition at G
/// then at the tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModeFamily {
    PinnedFree,
    SlideFree,
    FreeFree,
    ClampedFree,
}

impl ModeFamily {
    /// The three families of the paper, in Table I's column order.
    pub const PAPER: [ModeFamily; 3] = [ModeFamily::PinnedFree, ModeFamily::SlideFree, ModeFamily::FreeFree];

    /// Kebab-case name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            ModeFamily::PinnedFree => "pinned-free",
            ModeFamily::SlideFree => "slide-free",
            ModeFamily::FreeFree => "free-free",
            ModeFamily::ClampedFree => "clamped-free",
        }
    }
}

impl std::str::FromStr for ModeFamily {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        [
            ModeFamily::PinnedFree,
            ModeFamily::SlideFree,
            ModeFamily::FreeFree,
            ModeFamily::ClampedFree,
        ]
        .into_iter()
        .find(|f| f.name() == s)
        .ok_or_else(|| {
            format!("unknown mode family `{s}`: expected pinned-free, slide-free, free-free or clamped-free")
        })
    }
}

impl std::fmt::Display for ModeFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// `[amm]` section: settings of the assumed-modes solver. Command-line flags override them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AmmSettings {
    /// Mode family.
    pub family: ModeFamily,
    /// Modes per beam N, rigid ones included (paper: 25).
    pub modes: usize,
    /// Integration step [s]; `None` takes the solver's default (from its convergence study).
    pub dt: Option<f64>,
    /// Times [s] at which the deformed star is recorded (t_end is always added).
    pub snapshots: Vec<f64>,
}

impl Default for AmmSettings {
    fn default() -> Self {
        AmmSettings {
            family: ModeFamily::FreeFree,
            modes: 25,
            dt: None,
            snapshots: Vec::new(),
        }
    }
}

/// `[fem]` section: settings of the finite-element reference. Command-line flags override them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FemSettings {
    /// Elements in the whole star (three equal beams; paper: 300).
    pub elements: usize,
    /// Integration step [s]; `None` takes the solver's default (from its convergence study).
    pub dt: Option<f64>,
    /// Spectral radius at infinity of the generalized-alpha scheme, 0..1.
    pub rho_inf: Option<f64>,
    /// Times [s] at which the deformed star is recorded (t_end is always added).
    pub snapshots: Vec<f64>,
}

impl Default for FemSettings {
    fn default() -> Self {
        FemSettings {
            elements: 300,
            dt: None,
            rho_inf: None,
            snapshots: Vec::new(),
        }
    }
}

/// One experiment: what the TOML file says.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// Name; results go to `<out>/<name>/`.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub robot: RobotParams,
    pub time: TimeSpan,
    pub trajectory: Trajectory,
    #[serde(default)]
    pub amm: AmmSettings,
    #[serde(default)]
    pub fem: FemSettings,
    /// Where the experiment was read from (not a TOML key).
    #[serde(skip)]
    pub source: PathBuf,
}

impl Experiment {
    /// Read, parse and validate an experiment file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Parse and validate TOML text; `path` is used in messages only.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self, ModelError> {
        let mut exp: Experiment = toml::from_str(text).map_err(|e| ModelError::Parse {
            file: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        exp.source = path.to_path_buf();
        exp.validate().map_err(|e| e.in_file(path))?;
        Ok(exp)
    }

    /// Check every value (keys named relative to the file).
    pub fn validate(&self) -> Result<(), ModelError> {
        let name_ok = !self.name.is_empty()
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.')
            && !self.name.starts_with('.');
        if !name_ok {
            return Err(ModelError::invalid(
                "name",
                format!(
                    "must be a non-empty file name of letters, digits, '-', '_', '.', got {:?}",
                    self.name
                ),
            ));
        }
        self.robot.validate()?;
        self.time.validate()?;
        self.trajectory.validate(&self.robot)?;
        if self.amm.modes == 0 || self.amm.modes > 400 {
            return Err(ModelError::invalid(
                "amm.modes",
                format!("need 1 <= modes <= 400, got {}", self.amm.modes),
            ));
        }
        if let Some(dt) = self.amm.dt {
            check_step("amm.dt", dt, self.time.dt_out)?;
        }
        if self.fem.elements < 3 || !self.fem.elements.is_multiple_of(3) || self.fem.elements > 30_000 {
            return Err(ModelError::invalid(
                "fem.elements",
                format!(
                    "need a multiple of 3 between 3 and 30000 (three equal beams), got {}",
                    self.fem.elements
                ),
            ));
        }
        if let Some(dt) = self.fem.dt {
            check_step("fem.dt", dt, self.time.dt_out)?;
        }
        if let Some(r) = self.fem.rho_inf {
            if !(0.0..=1.0).contains(&r) {
                return Err(ModelError::invalid(
                    "fem.rho_inf",
                    format!("need 0 <= rho_inf <= 1, got {r}"),
                ));
            }
        }
        for (key, snaps) in [
            ("amm.snapshots", &self.amm.snapshots),
            ("fem.snapshots", &self.fem.snapshots),
        ] {
            if let Some(bad) = snaps
                .iter()
                .find(|t| !t.is_finite() || **t < 0.0 || **t > self.time.t_end)
            {
                return Err(ModelError::invalid(
                    key,
                    format!("snapshot times must lie in [0, t_end = {}], got {bad}", self.time.t_end),
                ));
            }
        }
        Ok(())
    }
}

/// A solver step must be positive and not larger than the output interval.
pub fn check_step(key: &str, dt: f64, dt_out: f64) -> Result<(), ModelError> {
    if !dt.is_finite() || dt <= 0.0 {
        return Err(ModelError::invalid(key, format!("the step must be positive, got {dt}")));
    }
    if dt > dt_out * (1.0 + 1e-12) {
        return Err(ModelError::invalid(
            key,
            format!("the step {dt} s is larger than the output interval time.dt_out = {dt_out} s"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const CASE1: &str = r#"
name = "case1"
[time]
t_end = 0.5
dt_out = 0.001
[trajectory]
kind = "polynomial"
s1 = [0.0, 0.0, 1.0]
s2 = [0.0, 0.0, 1.0]
s3 = [0.0, 0.0, 1.0]
"#;

    #[test]
    fn parses_minimal_file_with_paper_defaults() {
        let e = Experiment::from_toml_str(CASE1, Path::new("case1.toml")).unwrap();
        assert_eq!(e.robot, RobotParams::paper());
        assert_eq!(e.amm.modes, 25);
        assert_eq!(e.fem.elements, 300);
        assert_eq!(e.time.output_times().len(), 501);
    }

    #[test]
    fn unknown_key_is_named() {
        let text = CASE1.replace("[time]", "[robot]\nLq = 0.1\n[time]");
        let err = Experiment::from_toml_str(&text, Path::new("bad.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("bad.toml") && err.contains("Lq"), "{err}");
        let text = CASE1.replace("kind = \"polynomial\"", "kind = \"polynomial\"\ns4 = [1.0]");
        let err = Experiment::from_toml_str(&text, Path::new("bad.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("s4"), "{err}");
    }

    #[test]
    fn invalid_values_name_file_and_key() {
        let text = CASE1.replace("[time]", "[robot]\nrho = -1.0\n[time]");
        let err = Experiment::from_toml_str(&text, Path::new("neg.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("neg.toml") && err.contains("robot.rho"), "{err}");
        let text = CASE1.replace("t_end = 0.5", "t_end = 0.0");
        let err = Experiment::from_toml_str(&text, Path::new("e.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("time.t_end"), "{err}");
        let text = CASE1.replace("[trajectory]", "[amm]\ndt = 0.01\n[trajectory]");
        let err = Experiment::from_toml_str(&text, Path::new("e.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("amm.dt"), "{err}");
    }
}
