//! `flexstar run CONFIG --solver amm|fem [...]`: one solver on one experiment.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{anyhow, bail};
use flexstar_model::config::check_step;
use flexstar_model::{small_deflection_check, ModeFamily, Response};

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Solver {
    /// The paper's constrained assumed-modes method
    Amm,
    /// The independent finite-element reference
    Fem,
}

/// Run a solver on an experiment; writes DIR/<name>/amm-<family>.csv or DIR/<name>/fem.csv
/// (`t,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3` then more columns) and the deformed star
/// snapshots in `...-shapes.csv`.
#[derive(clap::Args)]
pub struct Args {
    /// Experiment file (TOML)
    config: PathBuf,
    /// Which model to run
    #[arg(long, value_enum)]
    solver: Solver,
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
    /// Output directory
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let mut exp = super::load(&args.config)?;
    let cfg = args.config.display();
    if let Some(dt) = args.dt {
        check_step("--dt", dt, exp.time.dt_out).map_err(|e| e.in_file(&args.config))?;
    }
    // the feasibility scan of both solvers, here too so that nothing is created for a motion
    // that is refused
    flexstar_kinematics::check_trajectory(&exp.robot, &exp.trajectory, exp.time.t_end, exp.time.dt_out.min(1e-3))
        .map_err(|e| anyhow!("{cfg}: {e}"))?;
    let started = std::time::Instant::now();
    let dir;
    let (response, file): (Response, String) = match args.solver {
        Solver::Amm => {
            if args.elements.is_some() {
                bail!("{cfg}: --elements applies to --solver fem only");
            }
            if let Some(f) = args.family {
                exp.amm.family = f;
            }
            if let Some(n) = args.modes {
                exp.amm.modes = Some(n);
                exp.amm.tol = None;
            }
            if let Some(p) = args.tol {
                exp.amm.tol = Some(p);
                exp.amm.modes = None;
            }
            if let Some(m) = args.model {
                exp.amm.model = m;
            }
            if args.dt.is_some() {
                exp.amm.dt = args.dt;
            }
            exp.validate()
                .map_err(|e| anyhow::anyhow!("{cfg} with the command-line flags: {e}"))?;
            dir = super::case_dir(&args.out, &exp)?;
            eprintln!("{}: AMM, {:?}, {}", exp.name, exp.amm.mode_count(), exp.amm.family);
            let r = flexstar_amm::solve(&exp, &exp.amm).map_err(|e| anyhow!("{cfg}: {e}"))?;
            (r, format!("amm-{}", exp.amm.family))
        }
        Solver::Fem => {
            if args.family.is_some() || args.modes.is_some() || args.model.is_some() || args.tol.is_some() {
                bail!("{cfg}: --family, --modes, --model and --tol apply to --solver amm only");
            }
            if let Some(n) = args.elements {
                exp.fem.elements = n;
            }
            if args.dt.is_some() {
                exp.fem.dt = args.dt;
            }
            exp.validate()
                .map_err(|e| anyhow::anyhow!("{cfg} with the command-line flags: {e}"))?;
            dir = super::case_dir(&args.out, &exp)?;
            eprintln!("{}: FEM, {} elements", exp.name, exp.fem.elements);
            let r = if std::io::stderr().is_terminal() {
                let bar = indicatif::ProgressBar::new(1000);
                bar.set_style(
                    indicatif::ProgressStyle::with_template("FEM {bar:40} {percent:>3}% eta {eta}")
                        .expect("valid template"),
                );
                let tick = |f: f64| bar.set_position((f * 1000.0) as u64);
                let r = flexstar_fem::solve(&exp, &exp.fem, Some(&tick));
                bar.finish_and_clear();
                r
            } else {
                flexstar_fem::solve(&exp, &exp.fem, None)
            }
            .map_err(|e| anyhow!("{cfg}: {e}"))?;
            (r, "fem".to_string())
        }
    };
    let csv = dir.join(format!("{file}.csv"));
    response.write_csv(&csv)?;
    response.write_shapes_csv(&dir.join(format!("{file}-shapes.csv")))?;
    response.write_sidecar(&dir.join(format!("{file}.json")), &exp, &super::provenance())?;
    if let Some(v) = small_deflection_check(&response, exp.robot.l) {
        eprintln!("warning: {cfg}: {file} {v}");
    }
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    eprintln!(
        "{}: {} rows to {} in {:.2} s; peak |tip| A/B/C = {:.3e}/{:.3e}/{:.3e} m, peak |w_iG| = {:.3e} m",
        exp.name,
        response.len(),
        csv.display(),
        started.elapsed().as_secs_f64(),
        peak(&response.w_tip[0]),
        peak(&response.w_tip[1]),
        peak(&response.w_tip[2]),
        (0..3).map(|i| peak(&response.w_g[i])).fold(0.0, f64::max)
    );
    Ok(())
}
