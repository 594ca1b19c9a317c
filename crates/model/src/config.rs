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

use crate::attachments::{Damping, LoadSettings, Payload};
use crate::drive_section::DriveSettings;
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

/// Assumed-mode families (Eq. 34-1, docs/paper-defects.md), named by the boundary condition at G
/// then at the tip; `Enriched` is flexstar's addition (free-free modes plus junction shapes that
/// carry the moment and shear the weld at G transmits, `docs/amm.md` section 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModeFamily {
    PinnedFree,
    SlideFree,
    FreeFree,
    ClampedFree,
    Enriched,
}

impl ModeFamily {
    /// The three families of the paper, in Table I's column order.
    pub const PAPER: [ModeFamily; 3] = [ModeFamily::PinnedFree, ModeFamily::SlideFree, ModeFamily::FreeFree];

    /// Every family, in the order used by listings.
    pub const ALL: [ModeFamily; 5] = [
        ModeFamily::PinnedFree,
        ModeFamily::SlideFree,
        ModeFamily::FreeFree,
        ModeFamily::ClampedFree,
        ModeFamily::Enriched,
    ];

    /// Kebab-case name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            ModeFamily::PinnedFree => "pinned-free",
            ModeFamily::SlideFree => "slide-free",
            ModeFamily::FreeFree => "free-free",
            ModeFamily::ClampedFree => "clamped-free",
            ModeFamily::Enriched => "enriched",
        }
    }
}

impl std::str::FromStr for ModeFamily {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        ModeFamily::ALL.into_iter().find(|f| f.name() == s).ok_or_else(|| {
            format!("unknown mode family `{s}`: expected pinned-free, slide-free, free-free, clamped-free or enriched")
        })
    }
}

impl std::fmt::Display for ModeFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which equations the AMM integrates (`[amm] model`, `--model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AmmModel {
    /// The paper's equations (Eqs. 30-44) as printed, corrected only where `docs/amm.md` section 1
    /// says: no axial-inertia stiffening (Eq. 23 dropped), sleeve rows at the rigid xp_i.
    Paper,
    /// The paper's equations with the terms it drops restored (`docs/amm.md` section 8): the
    /// geometric stiffness of the axial inertia force (Eq. 23) and the sleeve rows (Eqs. 41-43) at
    /// the material point xp_i - u_i, with Fa (Eq. 33) along the forces they then carry.
    Full,
}

impl AmmModel {
    /// Name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            AmmModel::Paper => "paper",
            AmmModel::Full => "full",
        }
    }
}

impl std::str::FromStr for AmmModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "paper" => Ok(AmmModel::Paper),
            "full" => Ok(AmmModel::Full),
            _ => Err(format!("unknown AMM model `{s}`: expected paper or full")),
        }
    }
}

impl std::fmt::Display for AmmModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Default modes per beam of the paper's families (paper, section 8).
pub const PAPER_MODES: usize = 25;

/// Default error tolerance of the enriched family [%] (`docs/amm.md` section 9): the automatic N stops when the
/// estimated EVP of the truncation is below it.
pub const DEFAULT_TOL_PERCENT: f64 = 0.5;

/// Smallest error tolerance [%] the automatic N accepts. The estimator of
/// `flexstar_amm::adaptive` resolves a truncation EVP only down to what N = 200
/// (`MAX_AUTO_MODES`) reaches: from about 1 % at its first N (46 for the paper's robot,
/// `2 L / Lp + 12`) the error falls like `N^-p` with p = 6.1-7.6 measured between N = 46 and 53,
/// so at N = 200 it is `1 % x (46 / 200)^p` = 3e-5 % (p = 7) to 1.3e-4 % (p = 6.1). A tolerance
/// below 1e-3 % would run every N up to 200 and then fail; it is refused before any run.
pub const MIN_TOL_PERCENT: f64 = 1e-3;

/// How the number of modes per beam is chosen (see [`AmmSettings::mode_count`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeCount {
    /// N fixed.
    Fixed(usize),
    /// N raised until the estimated truncation EVP is below this many percent.
    Tolerance(f64),
}

impl std::fmt::Display for ModeCount {
    /// `N = 25` or `tol = 0.5 %` (the number as [`flexstar_io::output::fmt_display`] writes it).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModeCount::Fixed(n) => write!(f, "N = {n}"),
            ModeCount::Tolerance(p) => write!(f, "tol = {} %", flexstar_io::output::fmt_display(*p)),
        }
    }
}

/// The refusal of a fixed N together with a tolerance, with the two settings named as the caller
/// spells them (`modes`/`tol` in a file, `--modes`/`--tol` on the command line).
pub fn modes_with_tol_reason(modes: &str, tol: &str) -> String {
    format!("give either {modes} (a fixed N) or {tol} (N chosen to meet the tolerance), not both")
}

/// `[amm]` section: settings of the assumed-modes solver. Command-line flags override them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AmmSettings {
    /// Mode family (default: enriched).
    pub family: ModeFamily,
    /// Equations (default: full).
    pub model: AmmModel,
    /// Modes per beam N, rigid ones and junction shapes included; fixes N (exclusive with `tol`).
    pub modes: Option<usize>,
    /// Error tolerance [%]: N is raised until the estimated EVP of the truncation is below it.
    pub tol: Option<f64>,
    /// Integration step [s]; `None` takes the solver's default (from its convergence study).
    pub dt: Option<f64>,
    /// Times [s] at which the deformed star is recorded (t_end is always added).
    pub snapshots: Vec<f64>,
    /// Animation frames per second (`docs/motions.md` section 5): the deformed star and its rigid
    /// pose at `k / frames` and `t_end`, written as `<stem>-frames.csv`; 0 (default): none.
    #[serde(skip_serializing_if = "is_zero")]
    pub frames: usize,
}

/// `frames = 0` is left out of a written experiment (the sidecars of runs without frames are
/// those of earlier versions).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl Default for AmmSettings {
    fn default() -> Self {
        AmmSettings {
            family: ModeFamily::Enriched,
            model: AmmModel::Full,
            modes: None,
            tol: None,
            dt: None,
            snapshots: Vec::new(),
            frames: 0,
        }
    }
}

impl AmmSettings {
    /// The paper's setting: `family` with N modes and the paper's equations.
    pub fn paper(family: ModeFamily, modes: usize) -> Self {
        AmmSettings {
            family,
            model: AmmModel::Paper,
            modes: Some(modes),
            ..AmmSettings::default()
        }
    }

    /// flexstar's accurate reduced model: enriched basis, full model, automatic N at the default
    /// tolerance.
    pub fn accurate() -> Self {
        AmmSettings::default()
    }

    /// How N is chosen: `modes` if given; else `tol` if given; else the default tolerance for the
    /// enriched family and [`PAPER_MODES`] for the paper's families.
    pub fn mode_count(&self) -> ModeCount {
        match (self.modes, self.tol) {
            (Some(n), _) => ModeCount::Fixed(n),
            (None, Some(p)) => ModeCount::Tolerance(p),
            (None, None) if self.family == ModeFamily::Enriched => ModeCount::Tolerance(DEFAULT_TOL_PERCENT),
            (None, None) => ModeCount::Fixed(PAPER_MODES),
        }
    }

    /// Check the values (keys named relative to the experiment file).
    pub fn validate(&self, dt_out: f64) -> Result<(), ModelError> {
        if let Some(n) = self.modes {
            if n == 0 || n > 400 {
                return Err(ModelError::invalid(
                    "amm.modes",
                    format!("need 1 <= modes <= 400, got {n}"),
                ));
            }
        }
        if let Some(p) = self.tol {
            if !p.is_finite() || p <= 0.0 {
                return Err(ModelError::invalid(
                    "amm.tol",
                    format!("the tolerance must be a positive percentage, got {p}"),
                ));
            }
            if p < MIN_TOL_PERCENT {
                return Err(ModelError::invalid(
                    "amm.tol",
                    format!(
                        "the tolerance {p} % is below what the error estimate resolves \
                         ({MIN_TOL_PERCENT} %: the truncation error reached with the most modes, \
                         N = 200); give tol >= {MIN_TOL_PERCENT}, or a fixed modes"
                    ),
                ));
            }
            if self.modes.is_some() {
                return Err(ModelError::invalid("amm.tol", modes_with_tol_reason("modes", "tol")));
            }
        }
        if let Some(dt) = self.dt {
            check_step("amm.dt", dt, dt_out)?;
        }
        Ok(())
    }
}

/// The FEM's default spectral radius at infinity of its generalized-alpha scheme (`[fem] rho_inf`
/// left out); `flexstar_fem::DEFAULT_RHO_INF` is this value.
pub const FEM_DEFAULT_RHO_INF: f64 = 0.7;

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
    /// Animation frames per second, as `[amm] frames`; 0 (default): none.
    #[serde(skip_serializing_if = "is_zero")]
    pub frames: usize,
}

impl Default for FemSettings {
    fn default() -> Self {
        FemSettings {
            elements: 300,
            dt: None,
            rho_inf: None,
            snapshots: Vec::new(),
            frames: 0,
        }
    }
}

/// Default `[report] settle_tol` [m]: the settling band on |dG| (`docs/motions.md` 2.3).
pub const DEFAULT_SETTLE_TOL: f64 = 1e-4;

/// The `[report]` section: how reports measure the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReportSettings {
    /// Settling band on the elastic displacement of G, |dG| [m] (default 1e-4).
    #[serde(default = "default_settle_tol")]
    pub settle_tol: f64,
}

fn default_settle_tol() -> f64 {
    DEFAULT_SETTLE_TOL
}

impl Default for ReportSettings {
    fn default() -> Self {
        ReportSettings {
            settle_tol: DEFAULT_SETTLE_TOL,
        }
    }
}

impl ReportSettings {
    /// `settle_tol` must be positive and finite.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.settle_tol.is_finite() && self.settle_tol > 0.0) {
            return Err(ModelError::invalid(
                "report.settle_tol",
                format!("need a positive, finite band in m, got {}", self.settle_tol),
            ));
        }
        Ok(())
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
    /// The actuator axes (`[base]`, `docs/as-built.md` 2): the paper's equilateral base is read
    /// into `robot.d` (and the section dropped), any other into `robot.as_built`; written back
    /// only then.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<crate::robot_section::BaseSection>,
    pub time: TimeSpan,
    pub trajectory: Trajectory,
    #[serde(default)]
    pub amm: AmmSettings,
    #[serde(default)]
    pub fem: FemSettings,
    /// What moves the sliders (`[drive]`, `docs/drives.md`): the trajectory (default), forces or a servo.
    #[serde(default)]
    pub drive: DriveSettings,
    /// A rigid body welded at G (`[payload]`, `docs/amm.md` section 11); none by default.
    #[serde(default)]
    pub payload: Payload,
    /// Rayleigh damping of the elastic motion (`[damping]`, `docs/amm.md` 11.2); none by default.
    #[serde(default)]
    pub damping: Damping,
    /// Force and moment at G (`[load]`, `docs/amm.md` section 11); none by default.
    #[serde(default)]
    pub load: LoadSettings,
    /// Gravity in the plane (`[gravity]`, `docs/as-built.md` 5); none by default (and then
    /// absent from the resolved experiment, so that the experiment's hash is unchanged).
    #[serde(default, skip_serializing_if = "crate::Gravity::is_none")]
    pub gravity: crate::Gravity,
    /// Friction in the sleeves and on the rails (`[friction]`, `docs/friction.md`); none by
    /// default (and then absent from the resolved experiment).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<crate::Friction>,
    /// Input shaping of the motion (`[shaper]`, `docs/motions.md` 3.7); none by
    /// default. Given frequencies are applied when the file is read ([`Experiment::apply_shaper`]);
    /// `f_hz = "auto"` waits for the explicit step `flexstar_shaping::shape`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shaper: Option<crate::shaper::ShaperSection>,
    /// How reports measure the run (`[report]`: the settling band, `docs/motions.md` 2.3).
    #[serde(default)]
    pub report: ReportSettings,
    /// The sensors read during a run (`[[sensors]]`, `docs/sensors.md`); none by default (and
    /// then absent from the resolved experiment).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<crate::sensors::SensorSpec>,
    /// How a recording maps onto the sensors' columns (`[measured]`, `docs/measured.md` section
    /// 1); none by default (and then absent from the resolved experiment).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured: Option<crate::measured_section::MeasuredSection>,
    /// The parameters `flexstar fit` calibrates on a recording (`[fit]`, `docs/measured.md`
    /// section 4); none by default (and then absent from the resolved experiment). Other commands
    /// read past it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<crate::fit_section::FitSection>,
    /// Where the experiment was read from (not a TOML key).
    #[serde(skip)]
    pub source: PathBuf,
    /// The experiment hash: of its text and the files it reads
    /// ([`crate::identity::experiment_hash`]; not a TOML key, empty for an experiment built in
    /// code).
    #[serde(skip)]
    pub hash: String,
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
            message: parse_message(text, e),
        })?;
        exp.source = path.to_path_buf();
        exp.read_base(text).map_err(|e| e.in_file(path))?;
        exp.drive.read_file(path)?;
        exp.load.read_file(path)?;
        exp.robot.validate().map_err(|e| e.in_file(path))?;
        exp.trajectory.read_file(path, &exp.robot)?;
        exp.apply_shaper().map_err(|e| e.in_file(path))?;
        exp.validate().map_err(|e| e.in_file(path))?;
        exp.hash = crate::identity::experiment_hash(text, &exp.input_files());
        Ok(exp)
    }

    /// Every file besides the experiment file itself that this experiment reads (the table of
    /// a `[trajectory]` of kind `table`, the forces table of a `[drive]` of kind `forces`, the
    /// table of a `[load]`), resolved against [`Experiment::source`]: what a fingerprint of the
    /// experiment must cover besides its text.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let traj = self.trajectory.file_path(&self.source);
        let drive = self.drive.file_path(&self.source);
        traj.into_iter()
            .chain(drive)
            .chain(self.load.file_path(&self.source))
            .collect()
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
        crate::problem::check_physics(self)?;
        self.amm.validate(self.time.dt_out)?;
        self.report.validate()?;
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
        if let Some(fit) = &self.fit {
            let sensors: Vec<(String, Vec<String>)> = self
                .sensors
                .iter()
                .map(|s| (s.name.clone(), crate::fit_section::spec_columns(s)))
                .collect();
            fit.validate(&sensors)?;
        }
        crate::animation::check_frames("amm.frames", self.amm.frames, self.time.t_end)?;
        crate::animation::check_frames("fem.frames", self.fem.frames, self.time.t_end)?;
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

impl Experiment {
    /// For a command or solver `by` that does not model friction yet (`docs/friction.md` 6): an
    /// error naming the `[friction]` key and `by` when the experiment has friction.
    pub fn frictionless(&self, by: &str) -> Result<(), ModelError> {
        match &self.friction {
            Some(f) if !f.is_none() => Err(crate::friction::unsupported(by)),
            _ => Ok(()),
        }
    }

    /// `[base]` into the robot: the paper's equilateral base sets `robot.d` (its in-radius; the
    /// section is then not written back), any other base makes the robot one as built
    /// ([`RobotParams::as_built`], `docs/as-built.md` 2); giving `robot.d` too is refused.
    fn read_base(&mut self, text: &str) -> Result<(), ModelError> {
        if self.base.is_none() {
            return Ok(());
        }
        let d_given = toml::from_str::<toml::Table>(text)
            .ok()
            .and_then(|t| t.get("robot").and_then(|r| r.get("d")).cloned())
            .is_some();
        if d_given {
            return Err(ModelError::invalid(
                "robot.d",
                "give the base once: robot.d (the paper's equilateral triangle of that in-radius) or [base]",
            ));
        }
        self.place_base()
    }

    /// The `[base]` section placed into the robot (a no-op without one): the paper's equilateral
    /// base sets `robot.d`, any other the axes of [`RobotParams::as_built`] (`docs/as-built.md`
    /// 2). Also for an experiment deserialised from a sidecar's JSON, which serde alone leaves on
    /// the paper's axes.
    pub fn place_base(&mut self) -> Result<(), ModelError> {
        let Some(base) = &self.base else {
            return Ok(());
        };
        let axes = base.axes().map_err(|(key, reason)| ModelError::invalid(key, reason))?;
        let paper_d = crate::robot_section::BaseSection::paper_in_radius(&axes);
        // the in-radius of the paper's base, or the distance from O to axis 1 (its in-radius
        // for a base given by sides)
        self.robot.d = paper_d.unwrap_or_else(|| {
            (axes[0].origin[0] * axes[0].direction[1] - axes[0].origin[1] * axes[0].direction[0]).abs()
        });
        match (&mut self.robot.as_built, paper_d) {
            (Some(a), _) => a.axes = axes,
            (None, Some(_)) => {}
            (None, None) => {
                let mut a = crate::robot::AsBuilt::of_paper(&self.robot);
                a.axes = axes;
                self.robot.as_built = Some(a);
            }
        }
        if paper_d.is_some() {
            self.base = None;
        }
        Ok(())
    }

    /// A rest-to-rest motion must end by `time.t_end` (`docs/motions.md` section 1.5): one that
    /// ends later would be cut off mid-move.
    pub(crate) fn check_motion_fits(&self) -> Result<(), ModelError> {
        let Some(t_rest) = self.trajectory.t_rest() else {
            return Ok(());
        };
        let t_end = self.time.t_end;
        // rounding noise of the motion's own sums (a shaper's impulse times) is no overrun
        if t_rest <= t_end * (1.0 + 1e-12) {
            return Ok(());
        }
        let (key, parts) = match &self.trajectory {
            Trajectory::Quintic { t0, .. } => ("trajectory.t1", format!(" (quintic from t0 = {t0} s to t1)")),
            Trajectory::Via(v) => ("trajectory.points", format!(" (the time of point {})", v.points.len())),
            Trajectory::Table(_) => ("trajectory.file", " (the time of the table's last row)".to_string()),
            Trajectory::Shaped(sh) => (
                "shaper",
                format!(
                    " (the unshaped motion's t_rest = {} s plus the shaper's {} s)",
                    flexstar_io::output::fmt_sig(sh.base.t_rest().unwrap_or(f64::NAN), 6),
                    flexstar_io::output::fmt_sig(crate::shaper::duration(&sh.impulses), 6)
                ),
            ),
            Trajectory::Polynomial { .. } => ("trajectory", String::new()),
        };
        Err(ModelError::invalid(
            key,
            format!(
                "the motion ends at t_rest = {} s{parts}, after time.t_end = {t_end} s \
                 (it would be cut off mid-move); raise time.t_end to at least {} s",
                flexstar_io::output::fmt_sig(t_rest, 6),
                flexstar_io::output::fmt_at_least(t_rest, 6)
            ),
        ))
    }
}

/// The message of a TOML error; an unknown key is reported together with every other unknown key
/// of the file, in file order (serde stops at the first, in the table's key order).
fn parse_message(text: &str, first: toml::de::Error) -> String {
    let render = |e: &toml::de::Error| e.to_string().trim_end().to_string();
    if !first.message().starts_with("unknown field") {
        return render(&first);
    }
    let Ok(mut doc) = toml::de::DeTable::parse(text) else {
        return render(&first);
    };
    let mut unknown = Vec::new();
    let mut err = first;
    // each pass removes the key just reported and parses again, until no unknown key is left
    while let Some(span) = err.span().filter(|_| err.message().starts_with("unknown field")) {
        if unknown.len() >= 64 || !remove_key(doc.get_mut(), &span) {
            break;
        }
        err.set_input(Some(text));
        unknown.push((span.start, render(&err)));
        match Experiment::deserialize(toml::de::Deserializer::from(doc.clone())) {
            Ok(_) => break,
            Err(next) => err = next,
        }
    }
    if unknown.len() <= 1 {
        return unknown.pop().map(|(_, m)| m).unwrap_or_default();
    }
    unknown.sort_by_key(|(start, _)| *start);
    let n = unknown.len();
    let all: Vec<String> = unknown.into_iter().map(|(_, m)| m).collect();
    format!("{n} unknown keys, in file order:\n{}", all.join("\n"))
}

/// Remove the entry whose key spans `span` from a parsed TOML table (searched recursively).
fn remove_key(table: &mut toml::de::DeTable<'_>, span: &std::ops::Range<usize>) -> bool {
    if let Some(key) = table.keys().find(|k| k.span() == *span).cloned() {
        table.remove(&key);
        return true;
    }
    table.iter_mut().any(|(_, v)| match v.get_mut() {
        toml::de::DeValue::Table(t) => remove_key(t, span),
        toml::de::DeValue::Array(a) => a.iter_mut().any(|item| match item.get_mut() {
            toml::de::DeValue::Table(t) => remove_key(t, span),
            _ => false,
        }),
        _ => false,
    })
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

    /// `[robot]` lists and `[base]` read from a file: equal lists are the paper's form, unequal
    /// ones and an uneven base a robot as built, written back in the same form (the resolved
    /// experiment reads back to the same robot); `[base]` may not come with `robot.d`.
    #[test]
    fn robot_lists_and_the_base_from_a_file() {
        let body = "name = \"r\"\n[time]\nt_end = 0.1\n[trajectory]\nkind = \"polynomial\"\n\
                    s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
        let read = |extra: &str| Experiment::from_toml_str(&format!("{body}{extra}"), Path::new("r.toml"));
        let plain = read("").unwrap();
        let listed = read("[robot]\nL = [0.5, 0.5, 0.5]\nweld_deg = [0, 120, 240]\n").unwrap();
        assert_eq!(listed.robot, plain.robot);
        let side = 2.0 * 3f64.sqrt() * 0.2;
        let based = read(&format!("[base]\nsides = [{side}, {side}, {side}]\n")).unwrap();
        assert!((based.robot.d - 0.2).abs() < 1e-15 && based.robot.as_built.is_none() && based.base.is_none());
        let e = read(&format!("[robot]\nd = 0.2\n[base]\nsides = [{side}, {side}, {side}]\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("robot.d") && e.contains("once"), "{e}");
        // a robot as built: its own data, and the same robot after writing and reading it back
        let built =
            read("[robot]\nL = [0.52, 0.5, 0.48]\nweld_deg = [0, 119, 241]\n[base]\nsides = [0.626, 0.618, 0.631]\n")
                .unwrap();
        let robot = crate::Robot::from_params(&built.robot).unwrap();
        assert_eq!(robot.beams().map(|b| b.length), [0.52, 0.5, 0.48]);
        assert_eq!(robot.beams()[2].weld_angle, 241f64.to_radians());
        assert_eq!(
            robot.axes(),
            &crate::ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap()
        );
        assert!(robot
            .paper_form_for("a command")
            .unwrap_err()
            .to_string()
            .contains("a command"));
        let text = toml::to_string(&built).unwrap();
        let again = Experiment::from_toml_str(&text, Path::new("again.toml")).unwrap();
        // the same robot, its defaulted EA now written
        assert_eq!(crate::Robot::from_params(&again.robot).unwrap(), robot, "{text}");
        let e = read("[robot]\nLp = [0.03, 0.03, 0.6]\n").unwrap_err().to_string();
        assert!(e.contains("r.toml") && e.contains("robot.Lp[3]"), "{e}");
        let e = read("[robot]\nweld_deg = [0, 200, 240]\n").unwrap_err().to_string();
        assert!(e.contains("robot.weld_deg"), "{e}");
        let e = read("[base]\nsides = [0.2, 0.2, 0.5]\n").unwrap_err().to_string();
        assert!(e.contains("base.sides"), "{e}");
    }

    #[test]
    fn settle_tol_must_be_positive() {
        for bad in [0.0, -1e-4, f64::NAN, f64::INFINITY] {
            let e = ReportSettings { settle_tol: bad }.validate().unwrap_err().to_string();
            assert!(e.contains("report.settle_tol"), "{e}");
        }
        ReportSettings::default().validate().unwrap();
    }

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
        assert_eq!(e.amm.family, ModeFamily::Enriched);
        assert_eq!(e.amm.model, AmmModel::Full);
        assert_eq!(e.amm.mode_count(), ModeCount::Tolerance(DEFAULT_TOL_PERCENT));
        assert_eq!(e.amm.mode_count().to_string(), "tol = 0.5 %");
        assert_eq!(ModeCount::Fixed(25).to_string(), "N = 25");
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

    /// The line the TOML parser's message points at (`TOML parse error at line N, ...`).
    fn error_line(err: &str) -> usize {
        let at = err.find("at line ").expect(err) + "at line ".len();
        err[at..].split(',').next().unwrap().parse().unwrap()
    }

    #[test]
    fn wrong_type_in_trajectory_points_at_the_key() {
        // CASE1 line 6 is `[trajectory]`, line 8 is `s1 = ...`
        let text = CASE1.replace("s1 = [0.0, 0.0, 1.0]", "s1 = [\"a\"]");
        let err = Experiment::from_toml_str(&text, Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert_eq!(error_line(&err), 8, "{err}");
        assert!(err.contains("t.toml") && err.contains("s1 = [\"a\"]"), "{err}");
        let quintic = "name = \"q\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"quintic\"\nfrom = 3\n\
                       to = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nt0 = 0.0\nt1 = 0.2\n";
        let err = Experiment::from_toml_str(quintic, Path::new("q.toml"))
            .unwrap_err()
            .to_string();
        assert_eq!(error_line(&err), 6, "{err}");
        assert!(err.contains("from = 3"), "{err}");
        // a key of the other kind, and a missing key, are named
        let text = CASE1.replace("kind = \"polynomial\"", "kind = \"polynomial\"\nt0 = 0.1");
        let err = Experiment::from_toml_str(&text, Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("trajectory.t0") && err.contains("polynomial"), "{err}");
        let text = CASE1.replace("s3 = [0.0, 0.0, 1.0]", "");
        let err = Experiment::from_toml_str(&text, Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("trajectory.s3"), "{err}");
    }

    #[test]
    fn every_unknown_key_is_named_in_file_order() {
        let text = CASE1.replace("[time]", "[robot]\nzz = 1\naa = 2\n[time]\nqq = 3");
        let err = Experiment::from_toml_str(&text, Path::new("u.toml"))
            .unwrap_err()
            .to_string();
        let at = |k: &str| {
            err.find(&format!("`{k}`"))
                .unwrap_or_else(|| panic!("{k} missing: {err}"))
        };
        assert!(err.contains("3 unknown keys") && err.contains("u.toml"), "{err}");
        assert!(at("zz") < at("aa") && at("aa") < at("qq"), "{err}");
    }

    #[test]
    fn quintic_after_t_end_is_refused_with_the_times() {
        let text = "name = \"q\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"quintic\"\n\
                    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.01, Gy = 0.0, theta = 0.0 }\n\
                    t0 = 0.6\nt1 = 0.8\n";
        let err = Experiment::from_toml_str(text, Path::new("q.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("trajectory.t1")
                && err.contains("0.6")
                && err.contains("t_rest = 0.8")
                && err.contains("t_end = 0.5"),
            "{err}"
        );
        // one that starts before t_end and ends after it would be cut off mid-move: refused too
        // (`docs/motions.md` 1.7), naming both times
        let cut = text.replace("t0 = 0.6", "t0 = 0.4");
        let err = Experiment::from_toml_str(&cut, Path::new("q.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("t_rest = 0.8") && err.contains("cut off") && err.contains("t_end = 0.5"),
            "{err}"
        );
        // ending exactly at t_end is allowed
        let exact = text.replace("t0 = 0.6", "t0 = 0.1").replace("t1 = 0.8", "t1 = 0.5");
        assert!(Experiment::from_toml_str(&exact, Path::new("q.toml")).is_ok());
    }

    #[test]
    fn tolerance_below_the_estimate_floor_is_refused() {
        for (tol, ok) in [("1e-9", false), ("0.0009", false), ("0.001", true), ("0.5", true)] {
            let text = CASE1.replace("[trajectory]", &format!("[amm]\ntol = {tol}\n[trajectory]"));
            let r = Experiment::from_toml_str(&text, Path::new("e.toml"));
            assert_eq!(r.is_ok(), ok, "tol = {tol}: {r:?}");
            if let Err(e) = r {
                let e = e.to_string();
                assert!(e.contains("amm.tol") && e.contains("0.001"), "{e}");
            }
        }
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
        for (bad, key) in [
            ("tol = 0.0", "amm.tol"),
            ("tol = nan", "amm.tol"),
            ("tol = 1.0\nmodes = 20", "amm.tol"),
            ("modes = 0", "amm.modes"),
        ] {
            let text = CASE1.replace("[trajectory]", &format!("[amm]\n{bad}\n[trajectory]"));
            let err = Experiment::from_toml_str(&text, Path::new("e.toml"))
                .unwrap_err()
                .to_string();
            assert!(err.contains(key) && err.contains("e.toml"), "{bad}: {err}");
        }
        let text = CASE1.replace("[trajectory]", "[amm]\nmodel = \"exact\"\n[trajectory]");
        let err = Experiment::from_toml_str(&text, Path::new("e.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("exact") && err.contains("model"), "{err}");
        let text = CASE1.replace("[trajectory]", "[amm]\ndt = 0.01\n[trajectory]");
        let err = Experiment::from_toml_str(&text, Path::new("e.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("amm.dt"), "{err}");
    }
}
