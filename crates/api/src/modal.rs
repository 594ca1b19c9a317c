//! `modal`, `freqmap` and `linearize` (issue 11): modes at a pose, frequency maps over the
//! workspace and the linear state-space model about a pose (over `flexstar_modal`).

use std::path::{Path, PathBuf};

use flexstar_modal::analysis::{amm_modes_per_beam, write_modal_csv, Modal};
use flexstar_modal::freqmap::{check_grid, write_freqmap_csv, Axis};
use flexstar_modal::linear::{Holding, LinearSettings, StateSpace};
use flexstar_modal::plots::{mode_shapes_figure, paper_paths, FreqMapFigure};
use flexstar_modal::pose::{pose_at_time, pose_from_task};
use flexstar_modal::ModalError;
use flexstar_model::{DriveKind, Experiment, ModeFamily, RestPose, Sliders};
use flexstar_plot::write_svg_png;

pub use flexstar_modal::freqmap::{MapPoint, Solver as MapSolver};

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
fn from_modal(source: Option<&str>, t: f64, e: ModalError) -> ApiError {
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

/// The rest pose, checked against the workspace (the error names the limit).
pub fn resolve_pose(exp: &Experiment, source: &str, spec: &PoseSpec) -> Result<RestPose> {
    match spec {
        PoseSpec::At(t) => pose_at_time(exp, *t).map_err(|e| from_modal(Some(source), *t, e)),
        PoseSpec::Task {
            pose: [gx, gy, th],
            text,
        } => pose_from_task(&exp.robot, *gx, *gy, *th).map_err(|e| {
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

/// The outcome of `modal`: the pose, both analyses and the files written (if any).
pub struct ModalOutcome {
    pub pose: RestPose,
    pub modal: Modal,
    pub files: Vec<PathBuf>,
}

/// Modes at a pose from the AMM and the FEM, `k` elastic modes; with `out` writes
/// `out/<name>/modal.csv` and `modal-shapes.svg/.png` (the folder checked before any work).
pub fn modal(
    exp: &Experiment,
    source: &str,
    spec: &PoseSpec,
    sliders: Sliders,
    k: usize,
    out: Option<&Path>,
) -> Result<ModalOutcome> {
    check_k(k)?;
    let pose = resolve_pose(exp, source, spec)?;
    let dir = out.map(|o| crate::case_dir(o, exp)).transpose()?;
    let m =
        flexstar_modal::analysis::modal(exp, &pose, sliders, k).map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    let mut files = Vec::new();
    if let Some(dir) = dir {
        let figure = mode_shapes_figure("modal-shapes", &m, &pose, exp.robot.l);
        let csv = dir.join("modal.csv");
        write_modal_csv(&csv, &m).map_err(|e| from_modal(None, f64::NAN, e))?;
        write_svg_png(&figure, &dir)?;
        files.extend([csv, dir.join("modal-shapes.svg"), dir.join("modal-shapes.png")]);
    }
    Ok(ModalOutcome { pose, modal: m, files })
}

/// A frequency map's grid: `gx`, `gy` [m] at orientation `theta` [rad], `k` frequencies.
pub struct FreqmapSettings {
    pub gx: Axis,
    pub gy: Axis,
    pub theta: f64,
    pub k: usize,
    pub solver: MapSolver,
}

/// Parse a grid axis `MIN:MAX:N` (`flag` names it in errors).
pub fn parse_axis(flag: &str, text: &str) -> Result<Axis> {
    Axis::parse(flag, text).map_err(|e| from_modal(None, f64::NAN, e))
}

/// The first `k` frequencies (sliders locked) over the grid, in parallel (`tick(done, total)`
/// from the workers); with `out` writes `out/<name>/freqmap.csv`, `freqmap-infeasible.csv` and
/// the heat map `freqmap.svg/.png`. The figure holds the points.
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
    check_grid(&s.gx, &s.gy).map_err(|e| from_modal(None, f64::NAN, e))?;
    check_k(s.k)?;
    if !s.theta.is_finite() {
        let reason = "must be a finite angle in rad";
        let message = format!("--theta {}: {reason}", s.theta);
        return Err(ApiError::config_text("--theta", None, reason, message));
    }
    let paths = paper_paths().map_err(|e| from_modal(None, f64::NAN, e))?;
    let dir = out.map(|o| crate::case_dir(o, exp)).transpose()?;
    let points = flexstar_modal::freqmap::freqmap(exp, &s.gx, &s.gy, s.theta, s.k, s.solver, tick)
        .map_err(|e| from_modal(Some(source), f64::NAN, e))?;
    let solver = if matches!(s.solver, MapSolver::Amm) {
        "AMM"
    } else {
        "FEM"
    };
    let figure = FreqMapFigure {
        name: "freqmap".into(),
        title: format!(
            "{}: first frequencies over the workspace, theta = {} rad, sliders locked ({solver})",
            exp.name, s.theta
        ),
        gx: s.gx,
        gy: s.gy,
        points,
        shown: s.k.min(2),
        paths,
    };
    if let Some(dir) = dir {
        write_freqmap_csv(&dir, &figure.points, s.k).map_err(|e| from_modal(None, f64::NAN, e))?;
        write_svg_png(&figure, &dir)?;
    }
    Ok(figure)
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
    Ok(LinearSettings { modes, holding })
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
