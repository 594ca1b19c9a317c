//! `modal`, `freqmap` and `linearize` (`docs/modes.md`): modes at a pose, frequency maps over the
//! workspace and the linear state-space model about a pose (over `flexstar_modal`), of the
//! paper's robot or one as built (`docs/modes.md`, a robot as built).

use std::path::{Path, PathBuf};

use flexstar_io::output::{fmt_display, fmt_fixed, Dest};
use flexstar_io::run_set::RunSet;
use flexstar_modal::analysis::{amm_modes_per_beam, write_modal_csv, Modal};
use flexstar_modal::freqmap::{check_grid, stage_freqmap_csv, Axis, Grid};
use flexstar_modal::linear::{Holding, LinearSettings, StateSpace};
use flexstar_modal::plots::{mode_shapes_figure, trajectory_path, FreqMapFigure};
use flexstar_modal::pose::{pose_at_time, pose_from_task};
use flexstar_modal::ModalError;
use flexstar_model::{DriveKind, Experiment, ModeFamily, RestPose, Sleeves, Sliders};
use flexstar_plot::write_svg_png;
use serde_json::{json, Map, Value};

pub use flexstar_modal::freqmap::MapPoint;
use flexstar_solve::Solver;

use crate::sidecar::TableSidecar;
use crate::solver_errors::{from_amm, from_fem};
use crate::{ApiError, Result};

/// Where the rest pose comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum PoseSpec {
    /// The experiment's trajectory at time `t` [s], within `[0, t_end]`.
    At(f64),
    /// The task-space pose `Gx, Gy` [m], `theta` [rad]; `text` names it in errors (`--pose`).
    Task { pose: [f64; 3], text: String },
}

/// A modal error; with `source` the experiment file comes first in the message.
pub(crate) fn from_modal(source: Option<&str>, t: f64, e: ModalError) -> ApiError {
    let file = source.unwrap_or("");
    let message = match source {
        Some(s) => format!("{s}: {e}"),
        None => e.to_string(),
    };
    match e {
        ModalError::Input(reason) => ApiError::config_text(file, None, &reason, message),
        ModalError::Infeasible(reason) => ApiError::Infeasible { t, reason, message },
        ModalError::Amm(a) => from_amm(file, a),
        ModalError::Fem(f) => from_fem(file, f),
        ModalError::Model(m) => ApiError::config_text(file, None, &m.to_string(), message),
    }
}

/// The note that the modes use the enriched basis when the experiment asks for another family:
/// the paper's families miss the modes badly at some poses (case 4's end pose with pinned-free:
/// f1 79 % above the FEM's).
pub fn family_note(source: &str, exp: &Experiment) -> Option<String> {
    (exp.amm.family != ModeFamily::Enriched).then(|| {
        format!(
            "note: {source}: [amm] family = {} is for the time-domain runs; the modes use the accurate basis (enriched, N = {})",
            exp.amm.family,
            amm_modes_per_beam(exp)
        )
    })
}

/// Check K, the number of modes or frequencies: 1..=50.
pub fn check_k(k: usize) -> Result<()> {
    flexstar_modal::check_k(k).map_err(|e| from_modal(None, f64::NAN, e))
}

/// The rest pose of the experiment's robot, checked against its workspace (the error names the
/// limit). A `[friction]` section is taken as it is: its coefficients do not enter the linear
/// systems, which `--sleeves` chooses (`docs/modes.md`, stuck sleeves).
pub fn resolve_pose(exp: &Experiment, source: &str, spec: &PoseSpec) -> Result<RestPose> {
    match spec {
        PoseSpec::At(t) => pose_at_time(exp, *t).map_err(|e| from_modal(Some(source), *t, e)),
        PoseSpec::Task {
            pose: [gx, gy, th],
            text,
        } => task_pose(exp, [*gx, *gy, *th]).map_err(|e| {
            let inner = format!("--pose {text}: {e}");
            match e {
                ModalError::Infeasible(reason) => ApiError::Infeasible {
                    t: f64::NAN,
                    reason,
                    message: format!("{source}: {inner}"),
                },
                _ => from_modal(Some(source), f64::NAN, ModalError::Input(inner)),
            }
        }),
    }
}

/// The pose `[Gx, Gy, theta]` [m, m, rad] of the experiment's robot (inverse kinematics).
fn task_pose(exp: &Experiment, [gx, gy, th]: [f64; 3]) -> std::result::Result<RestPose, ModalError> {
    pose_from_task(&flexstar_modal::robot(exp)?, gx, gy, th)
}

/// The outcome of `modal`: the pose, both analyses and the files written (if any).
pub struct ModalOutcome {
    pub pose: RestPose,
    pub modal: Modal,
    pub files: Vec<PathBuf>,
}

/// The pose of a sidecar: how it was given (`at` [s] or `task` `[Gx, Gy, theta]`), then the rest
/// pose it gives: sliders `s` [m], `G` [m], `theta` [rad].
fn pose_json(spec: &PoseSpec, pose: &RestPose) -> Value {
    let mut v = match spec {
        PoseSpec::At(t) => json!({ "at": t }),
        PoseSpec::Task { pose, .. } => json!({ "task": pose }),
    };
    v["s"] = json!(pose.s);
    v["G"] = json!(pose.g);
    v["theta"] = json!(pose.theta);
    v
}

/// The AMM's basis and the FEM's mesh of the modal analyses of `exp`.
fn amm_json(exp: &Experiment) -> Value {
    let (family, n) = flexstar_modal::analysis::amm_basis(exp);
    json!({ "solver": "amm", "family": family.to_string(), "modes_per_beam": n })
}

fn fem_json(exp: &Experiment) -> Value {
    json!({ "solver": "fem", "elements": exp.fem.elements })
}

/// How a modal analysis holds the robot: its sliders and its sleeves (`--sliders`, `--sleeves`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModalHold {
    pub sliders: Sliders,
    pub sleeves: Sleeves,
}

impl From<Sliders> for ModalHold {
    /// The sliders held as `sliders`, the sleeves sliding (the frictionless systems).
    fn from(sliders: Sliders) -> Self {
        ModalHold {
            sliders,
            sleeves: Sleeves::Sliding,
        }
    }
}

/// The settings of `modal`, as its sidecar records and a rerun compares them (`sleeves` only
/// when stuck: a sliding analysis's sidecar is as before).
fn modal_settings(exp: &Experiment, spec: &PoseSpec, pose: &RestPose, hold: ModalHold, k: usize) -> Map<String, Value> {
    let mut m = Map::new();
    m.insert("solvers".into(), json!([amm_json(exp), fem_json(exp)]));
    m.insert("pose".into(), pose_json(spec, pose));
    m.insert("sliders".into(), hold.sliders.name().into());
    if hold.sleeves == Sleeves::Stuck {
        m.insert("sleeves".into(), hold.sleeves.name().into());
    }
    m.insert("K".into(), k.into());
    m
}

/// Modes at a pose from the AMM and the FEM, `k` elastic modes; with `out` writes
/// `out/<name>/modal.csv` and its sidecar `modal.json` (published together), then
/// `modal-shapes.svg/.png`. The folder is checked before any work, and a `modal.csv` written with
/// other settings (solvers, pose, sliders, K) is kept (an error says what differs) unless `force`.
pub fn modal(
    exp: &Experiment,
    source: &str,
    spec: &PoseSpec,
    sliders: Sliders,
    k: usize,
    out: Option<&Path>,
    force: bool,
) -> Result<ModalOutcome> {
    modal_held(exp, source, spec, sliders.into(), k, out, force)
}

/// [`modal`] with the robot held as `hold`: the sleeves sliding (the frictionless systems,
/// [`modal`]) or stuck (`docs/modes.md`, stuck sleeves; the sidecar then records `sleeves`).
pub fn modal_held(
    exp: &Experiment,
    source: &str,
    spec: &PoseSpec,
    hold: ModalHold,
    k: usize,
    out: Option<&Path>,
    force: bool,
) -> Result<ModalOutcome> {
    check_k(k)?;
    let pose = resolve_pose(exp, source, spec)?;
    let sidecar = TableSidecar {
        command: "modal",
        csv: "modal.csv",
        settings: modal_settings(exp, spec, &pose, hold, k),
        experiment: exp,
    };
    let dir = out.map(|o| crate::case_dir(o, exp)).transpose()?;
    if let Some(dir) = &dir {
        sidecar.check_rerun(dir, force)?;
    }
    let m = flexstar_modal::analysis::modal_held(exp, &pose, hold.sliders, hold.sleeves, k)
        .map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    let mut files = Vec::new();
    if let Some(dir) = dir {
        let mut set = RunSet::begin(&dir)?;
        write_modal_csv(Dest::Set(&mut set, "modal.csv"), &m).map_err(|e| from_modal(None, f64::NAN, e))?;
        sidecar.stage(&mut set)?;
        set.commit()?;
        let figure = mode_shapes_figure("modal-shapes", &m, &pose, longest_beam(exp));
        write_svg_png(&figure, &dir)?;
        files.extend(["modal.csv", "modal.json", "modal-shapes.svg", "modal-shapes.png"].map(|f| dir.join(f)));
    }
    Ok(ModalOutcome { pose, modal: m, files })
}

/// The longest beam of the experiment's robot [m] (`robot.L` on the paper's robot): the scale of
/// the mode shapes' figure.
fn longest_beam(exp: &Experiment) -> f64 {
    match &exp.robot.as_built {
        None => exp.robot.l,
        Some(a) => a.beams.iter().map(|b| b.length).fold(0.0, f64::max),
    }
}

/// The pose and the sliders as `modal` reports them, five decimals and no `-0.00000`:
/// `pose G = (0.03000, -0.02000) m, theta = 0.10000 rad, s = .../.../... m, sliders locked`.
pub fn pose_text(pose: &RestPose, sliders: Sliders) -> String {
    let f = |v: f64| fmt_fixed(v, 5);
    format!(
        "pose G = ({}, {}) m, theta = {} rad, s = {}/{}/{} m, sliders {}",
        f(pose.g[0]),
        f(pose.g[1]),
        f(pose.theta),
        f(pose.s[0]),
        f(pose.s[1]),
        f(pose.s[2]),
        sliders.name()
    )
}

/// One line per mode of a modal analysis: `mode  1: AMM   123.4567 Hz  FEM   123.4000 Hz    +0.046 %`
/// (no negative zeros); with damping the AMM's ratio follows (`  zeta 0.01234`).
pub fn mode_lines(m: &Modal) -> Vec<String> {
    let zetas = m.damping_ratios();
    m.rows()
        .into_iter()
        .enumerate()
        .map(|(j, (mode, a, f, rel))| {
            let pct = fmt_fixed(100.0 * rel, 3);
            let pct = if pct.starts_with('-') { pct } else { format!("+{pct}") };
            let zeta = zetas
                .as_ref()
                .map_or(String::new(), |z| format!("  zeta {}", fmt_fixed(z[j].0, 5)));
            format!(
                "mode {mode:>2}: AMM {:>10} Hz  FEM {:>10} Hz  {pct:>8} %{zeta}",
                fmt_fixed(a, 4),
                fmt_fixed(f, 4)
            )
        })
        .collect()
}

/// A frequency map's grid: `gx`, `gy` [m] at orientation `theta` [rad], `k` frequencies, the
/// sliders held as `sliders`; `force` replaces a map written with other settings.
pub struct FreqmapSettings {
    pub gx: Axis,
    pub gy: Axis,
    pub theta: f64,
    pub k: usize,
    pub solver: Solver,
    pub sliders: Sliders,
    pub force: bool,
}

/// Parse a grid axis `MIN:MAX:N` (`flag` names it in errors).
pub fn parse_axis(flag: &str, text: &str) -> Result<Axis> {
    Axis::parse(flag, text).map_err(|e| from_modal(None, f64::NAN, e))
}

/// The settings of `freqmap`, as its sidecar records and a rerun compares them.
fn freqmap_settings(exp: &Experiment, s: &FreqmapSettings) -> Map<String, Value> {
    let axis = |a: &Axis| json!({ "min": a.min, "max": a.max, "n": a.n });
    let solver = match s.solver {
        Solver::Amm => amm_json(exp),
        Solver::Fem => fem_json(exp),
    };
    let mut m = Map::new();
    m.insert("solver".into(), solver);
    m.insert(
        "grid".into(),
        json!({ "Gx": axis(&s.gx), "Gy": axis(&s.gy), "theta": s.theta }),
    );
    m.insert("sliders".into(), s.sliders.name().into());
    m.insert("K".into(), s.k.into());
    m
}

/// The first `k` elastic frequencies over the grid, in parallel (`tick(done, total)` from the
/// workers); with `out` writes `out/<name>/freqmap.csv`, `freqmap-infeasible.csv` and the sidecar
/// `freqmap.json` (published together), then the heat map `freqmap.svg/.png` with the
/// experiment's path G(t) over it. A `freqmap.csv` written with other settings (solver, grid,
/// sliders, K) is kept (an error says what differs) unless `s.force`. The figure holds the points.
pub fn freqmap<P>(
    exp: &Experiment,
    source: &str,
    s: FreqmapSettings,
    out: Option<&Path>,
    tick: P,
) -> Result<FreqMapFigure>
where
    P: Fn(usize, usize) + Sync,
{
    ApiError::frictionless(exp, source, "flexstar freqmap")?;
    check_grid(&s.gx, &s.gy).map_err(|e| from_modal(None, f64::NAN, e))?;
    check_k(s.k)?;
    if !s.theta.is_finite() {
        let reason = "must be a finite angle in rad";
        let message = format!("--theta {}: {reason}", s.theta);
        return Err(ApiError::config_text("--theta", None, reason, message));
    }
    let sidecar = TableSidecar {
        command: "freqmap",
        csv: "freqmap.csv",
        settings: freqmap_settings(exp, &s),
        experiment: exp,
    };
    let dir = out.map(|o| crate::case_dir(o, exp)).transpose()?;
    if let Some(dir) = &dir {
        sidecar.check_rerun(dir, s.force)?;
    }
    let grid = Grid {
        gx: s.gx,
        gy: s.gy,
        theta: s.theta,
        sliders: s.sliders,
    };
    let points = flexstar_modal::freqmap::freqmap(exp, &grid, s.k, s.solver, tick)
        .map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    let figure = freqmap_figure(exp, &s, points);
    if let Some(dir) = dir {
        let mut set = RunSet::begin(&dir)?;
        stage_freqmap_csv(&mut set, &figure.points, s.k).map_err(|e| from_modal(None, f64::NAN, e))?;
        sidecar.stage(&mut set)?;
        set.commit()?;
        write_svg_png(&figure, &dir)?;
    }
    Ok(figure)
}

/// The heat map of a frequency map, the experiment's path G(t) over it.
fn freqmap_figure(exp: &Experiment, s: &FreqmapSettings, points: Vec<MapPoint>) -> FreqMapFigure {
    let solver = match s.solver {
        Solver::Amm => "AMM",
        Solver::Fem => "FEM",
    };
    FreqMapFigure {
        name: "freqmap".into(),
        title: format!(
            "{}: first frequencies over the workspace, theta = {} rad, sliders {} ({solver})",
            exp.name,
            fmt_display(s.theta),
            s.sliders.name()
        ),
        gx: s.gx,
        gy: s.gy,
        points,
        shown: s.k.min(2),
        paths: trajectory_path(exp, s.theta).into_iter().collect(),
    }
}

/// Whether the servo loop is closed in the linear model (`--loop`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopKind {
    /// Open loop: the actuator forces (sliders free) or the slider accelerations (locked) are
    /// the inputs.
    Open,
    /// The experiment's PD servo closes the loop around the sliders (`[drive] kind = "servo"`).
    Closed,
}

/// The settings of `linearize` as given; `None` takes the default: [`ELASTIC_MODES`] elastic
/// modes, sliders free, the loop closed when the experiment's drive is a servo (and the sliders
/// free), else open.
///
/// [`ELASTIC_MODES`]: flexstar_modal::linear::ELASTIC_MODES
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinearizeOptions {
    /// Elastic modes K (`--modes`).
    pub modes: Option<usize>,
    /// How the sliders are held (`--sliders`).
    pub sliders: Option<Sliders>,
    /// Servo loop (`--loop`).
    pub loop_kind: Option<LoopKind>,
    /// The sleeves' linear system (`--sleeves`; default sliding).
    pub sleeves: Option<Sleeves>,
}

/// The model's settings from `opts` and the experiment (defaults: [`LinearizeOptions`]); a closed
/// loop without a servo drive or with locked sliders is refused, naming the flags.
pub fn linear_settings(exp: &Experiment, source: &str, opts: &LinearizeOptions) -> Result<LinearSettings> {
    let modes = opts.modes.unwrap_or(flexstar_modal::linear::ELASTIC_MODES);
    check_k(modes)?;
    let sliders = opts.sliders.unwrap_or(Sliders::Free);
    let servo = exp.drive.kind == DriveKind::Servo;
    let closed = match opts.loop_kind {
        Some(LoopKind::Closed) => true,
        Some(LoopKind::Open) => false,
        None => servo && sliders == Sliders::Free,
    };
    let holding = match (closed, sliders) {
        (true, Sliders::Locked) => {
            let reason = "--loop closed: the servo acts on free sliders; --sliders locked leaves no loop to close (give --loop open or --sliders free)";
            return Err(from_modal(Some(source), f64::NAN, ModalError::Input(reason.into())));
        }
        (true, Sliders::Free) => Holding::servo_of(exp).map_err(|e| from_modal(Some(source), f64::NAN, e))?,
        (false, Sliders::Free) => Holding::Free,
        (false, Sliders::Locked) => Holding::Locked,
    };
    Ok(LinearSettings {
        modes,
        holding,
        sleeves: opts.sleeves.unwrap_or_default(),
    })
}

/// The linear state-space model about a pose with the settings of `opts` ([`linear_settings`];
/// states, inputs and outputs in `flexstar_modal::linear`); with `out` writes `out/<name>/linear/`
/// (Matrix Market A..D, M, K, Phi_q, fem-coordinates.csv, statespace.json).
pub fn linearize(
    exp: &Experiment,
    source: &str,
    spec: &PoseSpec,
    opts: &LinearizeOptions,
    out: Option<&Path>,
) -> Result<StateSpace> {
    let settings = linear_settings(exp, source, opts)?;
    let pose = resolve_pose(exp, source, spec)?;
    let dir = out.map(|o| crate::case_dir(o, exp)).transpose()?;
    let ss = flexstar_modal::linear::linearize_with(exp, &pose, &settings)
        .map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    if let Some(dir) = dir {
        flexstar_modal::linear::write_linear(&dir, exp, &ss).map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    }
    Ok(ss)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pose_is_reported_without_negative_zeros() {
        let pose = RestPose {
            s: [-0.0, -1e-9, 0.123456789],
            g: [-2e-7, -0.03],
            theta: -0.0,
            xp: [0.1; 3],
        };
        assert_eq!(
            pose_text(&pose, Sliders::Free),
            "pose G = (0.00000, -0.03000) m, theta = 0.00000 rad, s = 0.00000/0.00000/0.12346 m, sliders free"
        );
    }
}
