//! `flexstar run CONFIG --solver amm|fem [...]`: one solver on one experiment.

use std::io::IsTerminal;
use std::path::PathBuf;

use flexstar_api::{Forces, Prepared, RunOutcome, RunSettings};
use flexstar_model::ModeFamily;

/// Run a solver on an experiment; writes DIR/<name>/amm-<family>.csv or DIR/<name>/fem.csv
/// (`t,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3` then more columns) and the deformed star
/// snapshots in `...-shapes.csv`. With a `[drive]` of kind forces or servo (or `--forces FILE`)
/// the direct problem: DIR/<name>/amm-<family>-direct.csv or fem-direct.csv
/// (`t,s1,s2,s3,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3,Gx,Gy,theta`, for a servo `e1,e2,e3`,
/// then more columns).
#[derive(clap::Args)]
pub struct Args {
    /// Experiment file (TOML)
    config: PathBuf,
    /// Which model to run
    #[arg(long, value_enum)]
    solver: super::SolverArg,
    /// AMM mode family (overrides [amm] family): pinned-free, slide-free, free-free, clamped-free, enriched
    #[arg(long)]
    family: Option<ModeFamily>,
    /// AMM modes per beam N, rigid ones included (overrides [amm] modes and tol: a fixed N)
    #[arg(long)]
    modes: Option<usize>,
    /// AMM equations: paper (as printed) or full (the dropped terms restored; overrides [amm] model)
    #[arg(long)]
    model: Option<flexstar_model::AmmModel>,
    /// AMM error tolerance [%]: N is raised until the estimated truncation EVP is below it
    /// (overrides [amm] tol and modes)
    #[arg(long)]
    tol: Option<f64>,
    /// FEM elements in the whole star, a multiple of 3 (overrides [fem] elements)
    #[arg(long)]
    elements: Option<usize>,
    /// Integration step [s] (overrides [amm] dt or [fem] dt)
    #[arg(long)]
    dt: Option<f64>,
    /// Drive the sliders by these actuator forces instead (the direct problem): a CSV whose header
    /// starts with t and names Fa1, Fa2, Fa3, e.g. a solver output; replaces the config's [drive]
    #[arg(long, value_name = "FILE")]
    forces: Option<PathBuf>,
    /// Also draw figures (SVG and PNG) in DIR/<name>/figures/: for a direct run the sliders
    /// against the [trajectory], the servo's tracking errors, the tips and the forces
    #[arg(long)]
    figures: bool,
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

impl Args {
    /// The run's settings over the experiment (the flags given).
    fn settings(&self) -> RunSettings {
        RunSettings {
            solver: self.solver.into(),
            family: self.family,
            modes: self.modes,
            model: self.model,
            tol: self.tol,
            elements: self.elements,
            dt: self.dt,
            forces: self.forces.clone().map(Forces::File),
            figures: self.figures,
        }
    }
}

/// What will be solved, on stderr.
fn announce(p: &Prepared) {
    for n in &p.notes {
        eprintln!("{n}");
    }
    eprintln!("{}", p.describe());
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let exp = super::load(&args.config)?;
    super::note_other_experiment(&args.out, &exp);
    let cfg = args.config.display().to_string();
    let settings = args.settings();
    let started = std::time::Instant::now();
    let fem = settings.solver == flexstar_solve::Solver::Fem;
    let outcome = if fem && std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(1000);
        bar.set_style(
            indicatif::ProgressStyle::with_template("FEM {bar:40} {percent:>3}% eta {eta}").expect("valid template"),
        );
        let tick = |f: f64| bar.set_position((f * 1000.0) as u64);
        let r = flexstar_api::run::run_to_dir(exp, &cfg, &settings, &args.out, announce, Some(&tick));
        bar.finish_and_clear();
        r
    } else {
        flexstar_api::run::run_to_dir(exp, &cfg, &settings, &args.out, announce, None)
    }?;
    summary(&outcome, args.figures, started.elapsed().as_secs_f64());
    Ok(())
}

/// The figures written, the validity warning and the peaks, on stderr.
fn summary(o: &RunOutcome, figures: bool, seconds: f64) {
    let exp = &o.exp;
    if figures {
        let svgs = o
            .files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "svg"))
            .count();
        let dir = o
            .csv
            .as_ref()
            .and_then(|c| c.parent())
            .map(|d| d.join("figures"))
            .unwrap_or_default();
        eprintln!("{}: {svgs} figures in {}", exp.name, dir.display());
    }
    if let Some(w) = &o.warning {
        eprintln!("warning: {w}");
    }
    let r = &o.response;
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    eprintln!(
        "{}: {} rows to {} in {seconds:.2} s; peak |tip| A/B/C = {:.3e}/{:.3e}/{:.3e} m, peak |w_iG| = {:.3e} m",
        exp.name,
        r.len(),
        o.csv.as_ref().map(|c| c.display().to_string()).unwrap_or_default(),
        peak(&r.w_tip[0]),
        peak(&r.w_tip[1]),
        peak(&r.w_tip[2]),
        (0..3).map(|i| peak(&r.w_g[i])).fold(0.0, f64::max)
    );
    if let Some(line) = flexstar_api::run::residual_line(&o.sidecar) {
        eprintln!("{}: {line}", exp.name);
    }
    for line in flexstar_api::run::dwell_lines(&o.sidecar) {
        eprintln!("{}: {line}", exp.name);
    }
    if let Some(line) = flexstar_api::run::envelope_line(&o.sidecar) {
        eprintln!("note: {}: {line}", exp.name);
    }
}
