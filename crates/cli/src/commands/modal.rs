//! `flexstar modal`, `flexstar freqmap` and `flexstar linearize` (`docs/modes.md`): modes at a pose,
//! frequency maps and linear models (thin layer over `flexstar_modal`).

use std::path::PathBuf;
use std::time::Instant;

use flexstar_api::modal::{FreqmapSettings, LinearizeOptions, LoopKind, PoseSpec};
use flexstar_io::output::fmt_fixed;
use flexstar_model::{Experiment, Sleeves, Sliders};

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
    /// Where the pose comes from (`--pose` parsed; the error names the flag).
    fn spec(&self, config: &std::path::Path) -> anyhow::Result<PoseSpec> {
        match (&self.at, &self.pose) {
            (Some(t), _) => Ok(PoseSpec::At(*t)),
            (None, Some(p)) => {
                let pose =
                    flexstar_modal::pose::parse_pose(p).map_err(|e| anyhow::anyhow!("{}: {e}", config.display()))?;
                Ok(PoseSpec::Task { pose, text: p.clone() })
            }
            (None, None) => anyhow::bail!("give --at T or --pose GX,GY,THETA"),
        }
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

impl From<SlidersArg> for Sliders {
    fn from(s: SlidersArg) -> Sliders {
        match s {
            SlidersArg::Locked => Sliders::Locked,
            SlidersArg::Free => Sliders::Free,
        }
    }
}

/// Which linear system of the sleeves (`--sleeves`, `docs/modes.md` stuck sleeves).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SleevesArg {
    /// Each beam slides through its sleeve (the frictionless systems)
    Sliding,
    /// Each sleeve holds its beam's material point (a sticking robot's other linear system)
    Stuck,
}

impl From<SleevesArg> for Sleeves {
    fn from(s: SleevesArg) -> Sleeves {
        match s {
            SleevesArg::Sliding => Sleeves::Sliding,
            SleevesArg::Stuck => Sleeves::Stuck,
        }
    }
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
    /// Sleeves sliding on their beams or stuck (holding each beam's material point)
    #[arg(long, value_enum, default_value = "sliding")]
    sleeves: SleevesArg,
    /// Replace a modal.csv that other settings (pose, sliders, sleeves, K, solvers) wrote in DIR/<name>/
    #[arg(long)]
    force: bool,
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
    solver: super::SolverArg,
    /// How the sliders are held (free: f1 is the first elastic frequency, the rigid modes left out)
    #[arg(long, value_enum, default_value = "locked")]
    sliders: SlidersArg,
    /// Replace a freqmap.csv that other settings (grid, theta, sliders, K, solver) wrote in DIR/<name>/
    #[arg(long)]
    force: bool,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

/// Whether the servo loop is closed in the linear model (`--loop`).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum LoopArg {
    /// Inputs the actuator forces (sliders free) or the slider accelerations (sliders locked)
    Open,
    /// The experiment's PD servo ([drive] kind = "servo") closes the loop around the sliders
    Closed,
}

/// Linear state-space model about a pose: DIR/<name>/linear/
#[derive(clap::Args)]
pub struct LinearizeArgs {
    /// Experiment file (TOML)
    config: PathBuf,
    #[command(flatten)]
    pose: PoseArgs,
    /// Number of elastic modes K kept (1..=50), after the three rigid ones when the sliders are free
    #[arg(long = "modes", default_value_t = flexstar_modal::linear::ELASTIC_MODES)]
    k: usize,
    /// How the sliders are held: free (inputs Fa1..Fa3) or locked (inputs the slider accelerations)
    #[arg(long, value_enum, default_value = "free")]
    sliders: SlidersArg,
    /// Servo loop open or closed [default: closed when [drive] kind = "servo" and the sliders are free, else open]
    #[arg(long = "loop", value_enum)]
    loop_kind: Option<LoopArg>,
    /// Sleeves sliding on their beams or stuck (with --sliders locked the sliders become states, docs/modes.md Eqs. S4-S6)
    #[arg(long, value_enum, default_value = "sliding")]
    sleeves: SleevesArg,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

/// Load the experiment and print the note about the modes' basis.
fn load(config: &std::path::Path) -> anyhow::Result<(Experiment, String)> {
    let exp = super::load(config)?;
    let source = config.display().to_string();
    if let Some(note) = flexstar_api::modal::family_note(&source, &exp) {
        eprintln!("{note}");
    }
    Ok((exp, source))
}

pub fn run_modal(args: ModalArgs) -> anyhow::Result<()> {
    let (exp, source) = load(&args.config)?;
    super::note_other_experiment(&args.out, &exp);
    let sliders = Sliders::from(args.sliders);
    flexstar_api::modal::check_k(args.k)?;
    let spec = args.pose.spec(&args.config)?;
    let start = Instant::now();
    let hold = flexstar_api::modal::ModalHold {
        sliders,
        sleeves: args.sleeves.into(),
    };
    let o = flexstar_api::modal::modal_held(&exp, &source, &spec, hold, args.k, Some(&args.out), args.force)?;
    eprintln!(
        "{}: {} ({:.2} s)",
        exp.name,
        flexstar_api::modal::pose_text(&o.pose, sliders),
        start.elapsed().as_secs_f64()
    );
    for line in flexstar_api::modal::mode_lines(&o.modal) {
        eprintln!("  {line}");
    }
    let dir = args.out.join(&exp.name);
    eprintln!(
        "{}: modal.csv, modal.json, modal-shapes.svg/.png in {}",
        exp.name,
        dir.display()
    );
    Ok(())
}

pub fn run_freqmap(args: FreqmapArgs) -> anyhow::Result<()> {
    let (exp, source) = load(&args.config)?;
    super::note_other_experiment(&args.out, &exp);
    let settings = FreqmapSettings {
        gx: flexstar_api::modal::parse_axis("--gx", &args.gx)?,
        gy: flexstar_api::modal::parse_axis("--gy", &args.gy)?,
        theta: args.theta,
        k: args.k,
        solver: args.solver.into(),
        sliders: Sliders::from(args.sliders),
        force: args.force,
    };
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
    let figure = flexstar_api::modal::freqmap(&exp, &source, settings, Some(&args.out), tick);
    reporter.finish();
    let figure = figure?;
    let feasible = figure.points.iter().filter(|p| p.result.is_ok()).count();
    eprintln!(
        "{}: {} poses ({feasible} feasible) in {:.2} s; freqmap.csv, freqmap-infeasible.csv, freqmap.json, freqmap.svg/.png in {}",
        exp.name,
        figure.points.len(),
        start.elapsed().as_secs_f64(),
        args.out.join(&exp.name).display()
    );
    Ok(())
}

pub fn run_linearize(args: LinearizeArgs) -> anyhow::Result<()> {
    let (exp, source) = load(&args.config)?;
    super::note_other_experiment(&args.out, &exp);
    let spec = args.pose.spec(&args.config)?;
    let opts = LinearizeOptions {
        modes: Some(args.k),
        sliders: Some(args.sliders.into()),
        loop_kind: args.loop_kind.map(|l| match l {
            LoopArg::Open => LoopKind::Open,
            LoopArg::Closed => LoopKind::Closed,
        }),
        sleeves: Some(args.sleeves.into()),
    };
    let ss = flexstar_api::modal::linearize(&exp, &source, &spec, &opts, Some(&args.out))?;
    let h = ss.settings.holding;
    eprintln!(
        "{}: {} states, {} inputs, {} outputs (sliders {}, loop {}) about G = ({}, {}) m, theta = {} rad; A.mtx .. D.mtx, M.mtx, K.mtx, Phi_q.mtx, fem-coordinates.csv, statespace.json in {}",
        exp.name,
        ss.a.rows(),
        ss.inputs.len(),
        ss.outputs.len(),
        h.sliders().name(),
        if matches!(h, flexstar_modal::linear::Holding::Servo { .. }) { "closed" } else { "open" },
        fmt_fixed(ss.pose.g[0], 5),
        fmt_fixed(ss.pose.g[1], 5),
        fmt_fixed(ss.pose.theta, 5),
        args.out.join(&exp.name).join("linear").display()
    );
    Ok(())
}
