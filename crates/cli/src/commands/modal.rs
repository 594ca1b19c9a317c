//! `flexstar modal`, `flexstar freqmap` and `flexstar linearize` (issue 11): modes at a pose,
//! frequency maps and linear models (thin layer over `flexstar_modal`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_modal::analysis::{modal, write_modal_csv};
use flexstar_modal::freqmap::{check_grid, freqmap, write_freqmap_csv, Axis, Solver};
use flexstar_modal::plots::{mode_shapes_figure, paper_paths, FreqMapFigure};
use flexstar_modal::pose::{parse_pose, pose_at_time, pose_from_task};
use flexstar_model::{Experiment, RestPose, Sliders};
use flexstar_plot::write_svg_png;

use crate::progress::Reporter;

/// Where the pose comes from: a time of the trajectory or a task-space pose.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
pub struct PoseArgs {
    /// Pose of the experiment's trajectory at time T [s] (within [0, t_end])
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    at: Option<f64>,
    /// Task-space pose GX,GY,THETA [m, m, rad]; inverse kinematics gives the sliders
    #[arg(long, value_name = "GX,GY,THETA", allow_hyphen_values = true)]
    pose: Option<String>,
}

impl PoseArgs {
    /// The rest pose, checked against the workspace (the error names the limit).
    fn resolve(&self, exp: &Experiment) -> anyhow::Result<RestPose> {
        let pose = match (&self.at, &self.pose) {
            (Some(t), _) => pose_at_time(exp, *t)?,
            (None, Some(p)) => {
                let [gx, gy, th] = parse_pose(p)?;
                pose_from_task(&exp.robot, gx, gy, th).map_err(|e| anyhow::anyhow!("--pose {p}: {e}"))?
            }
            (None, None) => anyhow::bail!("give --at T or --pose GX,GY,THETA"),
        };
        Ok(pose)
    }
}

/// How the sliders are held (`--sliders`).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SlidersArg {
    /// Revolute points fixed (actuators locked)
    Locked,
    /// Sliders free on their rails with mass mpp + mpa (three rigid modes at 0 Hz)
    Free,
}

/// Which solver computes a frequency map (`--solver`).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SolverArg {
    Amm,
    Fem,
}

/// Modes at a pose from the AMM and the FEM: DIR/<name>/modal.csv and the first six shapes
#[derive(clap::Args)]
pub struct ModalArgs {
    /// Experiment file (TOML)
    config: PathBuf,
    #[command(flatten)]
    pose: PoseArgs,
    /// Number of elastic modes K (1..=50)
    #[arg(long = "modes", default_value_t = 6)]
    k: usize,
    /// How the sliders are held
    #[arg(long, value_enum, default_value = "locked")]
    sliders: SlidersArg,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

/// First K frequencies over a grid of poses: DIR/<name>/freqmap.csv and the heat map of f1, f2
#[derive(clap::Args)]
pub struct FreqmapArgs {
    /// Experiment file (TOML)
    config: PathBuf,
    /// Grid of Gx [m]: MIN:MAX:N (N >= 2)
    #[arg(long, allow_hyphen_values = true)]
    gx: String,
    /// Grid of Gy [m]: MIN:MAX:N (N >= 2)
    #[arg(long, allow_hyphen_values = true)]
    gy: String,
    /// Orientation of the star theta [rad]
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    theta: f64,
    /// Number of frequencies K (1..=50)
    #[arg(long = "modes", default_value_t = 6)]
    k: usize,
    /// Solver of the map
    #[arg(long, value_enum, default_value = "amm")]
    solver: SolverArg,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

/// Linear state-space model about a pose (sliders free): DIR/<name>/linear/
#[derive(clap::Args)]
pub struct LinearizeArgs {
    /// Experiment file (TOML)
    config: PathBuf,
    #[command(flatten)]
    pose: PoseArgs,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

/// Warn when the experiment asks for another AMM family than the enriched one: the paper's
/// families are meant for the time-domain comparison and miss the modes badly at some poses
/// (case 4's end pose with pinned-free: f1 79 % above the FEM's).
fn warn_family(config: &Path, exp: &Experiment) {
    if exp.amm.family != flexstar_model::ModeFamily::Enriched {
        eprintln!(
            "note: {}: [amm] family = {} is for the time-domain runs; the modes use the accurate basis (enriched, N = {})",
            config.display(),
            exp.amm.family,
            flexstar_modal::analysis::amm_modes_per_beam(exp)
        );
    }
}

/// Errors of the modal library prefixed with the experiment file.
fn in_file(config: &Path) -> impl Fn(flexstar_modal::ModalError) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("{}: {e}", config.display())
}

pub fn run_modal(args: ModalArgs) -> anyhow::Result<()> {
    let exp = super::load(&args.config)?;
    warn_family(&args.config, &exp);
    flexstar_modal::check_k(args.k)?;
    let pose = args
        .pose
        .resolve(&exp)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.config.display()))?;
    let sliders = match args.sliders {
        SlidersArg::Locked => Sliders::Locked,
        SlidersArg::Free => Sliders::Free,
    };
    let dir = super::case_dir(&args.out, &exp)?;
    let start = Instant::now();
    let m = modal(&exp, &pose, sliders, args.k).map_err(in_file(&args.config))?;
    let figure = mode_shapes_figure("modal-shapes", &m, &pose, exp.robot.l);
    write_modal_csv(&dir.join("modal.csv"), &m)?;
    write_svg_png(&figure, &dir)?;
    eprintln!(
        "{}: pose G = ({:.5}, {:.5}) m, theta = {:.5} rad, s = {:.5}/{:.5}/{:.5} m, sliders {} ({:.2} s)",
        exp.name,
        pose.g[0],
        pose.g[1],
        pose.theta,
        pose.s[0],
        pose.s[1],
        pose.s[2],
        sliders.name(),
        start.elapsed().as_secs_f64()
    );
    for (mode, a, f, rel) in m.rows() {
        eprintln!(
            "  mode {mode:>2}: AMM {a:>10.4} Hz  FEM {f:>10.4} Hz  {:>+8.3} %",
            100.0 * rel
        );
    }
    eprintln!("{}: modal.csv, modal-shapes.svg/.png in {}", exp.name, dir.display());
    Ok(())
}

pub fn run_freqmap(args: FreqmapArgs) -> anyhow::Result<()> {
    let exp = super::load(&args.config)?;
    warn_family(&args.config, &exp);
    let gx = Axis::parse("--gx", &args.gx)?;
    let gy = Axis::parse("--gy", &args.gy)?;
    check_grid(&gx, &gy)?;
    flexstar_modal::check_k(args.k)?;
    if !args.theta.is_finite() {
        anyhow::bail!("--theta {}: must be a finite angle in rad", args.theta);
    }
    let solver = match args.solver {
        SolverArg::Amm => Solver::Amm,
        SolverArg::Fem => Solver::Fem,
    };
    let paths = paper_paths()?;
    let dir = super::case_dir(&args.out, &exp)?;
    let start = Instant::now();
    let reporter = Reporter::new("freqmap");
    let tick = |done: usize, total: usize| {
        reporter.update(flexstar_compare::Progress {
            done,
            total,
            fraction: done as f64 / total as f64,
            elapsed: start.elapsed().as_secs_f64(),
        })
    };
    let points = freqmap(&exp, &gx, &gy, args.theta, args.k, solver, tick);
    reporter.finish();
    let points = points.map_err(in_file(&args.config))?;
    let feasible = points.iter().filter(|p| p.result.is_ok()).count();
    let figure = FreqMapFigure {
        name: "freqmap".into(),
        title: format!(
            "{}: first frequencies over the workspace, theta = {} rad, sliders locked ({})",
            exp.name,
            args.theta,
            if matches!(solver, Solver::Amm) { "AMM" } else { "FEM" }
        ),
        gx,
        gy,
        points,
        shown: args.k.min(2),
        paths,
    };
    write_freqmap_csv(&dir, &figure.points, args.k)?;
    write_svg_png(&figure, &dir)?;
    eprintln!(
        "{}: {} poses ({feasible} feasible) in {:.2} s; freqmap.csv, freqmap-infeasible.csv, freqmap.svg/.png in {}",
        exp.name,
        figure.points.len(),
        start.elapsed().as_secs_f64(),
        dir.display()
    );
    Ok(())
}

pub fn run_linearize(args: LinearizeArgs) -> anyhow::Result<()> {
    let exp = super::load(&args.config)?;
    warn_family(&args.config, &exp);
    let pose = args
        .pose
        .resolve(&exp)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.config.display()))?;
    let dir = super::case_dir(&args.out, &exp)?;
    let ss = flexstar_modal::linear::linearize(&exp, &pose).map_err(in_file(&args.config))?;
    flexstar_modal::linear::write_linear(&dir, &exp, &ss).map_err(in_file(&args.config))?;
    eprintln!(
        "{}: {} states, 3 inputs, 9 outputs about G = ({:.5}, {:.5}) m, theta = {:.5} rad; A.mtx .. D.mtx, M.mtx, K.mtx, Phi_q.mtx, statespace.json in {}",
        exp.name,
        ss.a.rows(),
        pose.g[0],
        pose.g[1],
        pose.theta,
        dir.join("linear").display()
    );
    Ok(())
}
