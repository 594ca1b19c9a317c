//! `flexstar run CONFIG --solver amm|fem [...]`: one solver on one experiment.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{anyhow, bail};
use flexstar_model::config::check_step;
use flexstar_model::{small_deflection_check, DriveKind, DriveSettings, Experiment, ModeFamily, Response};

/// The actuator law of the experiment's drive (a direct run).
fn law_of(exp: &Experiment, cfg: &impl std::fmt::Display) -> anyhow::Result<Box<dyn flexstar_drive::ActuatorLaw>> {
    flexstar_drive::law_for(exp)
        .map_err(|e| anyhow!("{cfg}: {e}"))?
        .ok_or_else(|| anyhow!("{cfg}: the drive is a motion, not a direct problem"))
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Solver {
    /// The paper's constrained assumed-modes method
    Amm,
    /// The independent finite-element reference
    Fem,
}

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

/// The FEM's direct dynamics (issue 10): each slider a body on its rail pushed by the law.
fn fem_direct(
    exp: &flexstar_model::Experiment,
    law: &dyn flexstar_drive::ActuatorLaw,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> anyhow::Result<Response> {
    Ok(flexstar_fem::solve_direct(exp, &exp.fem, law, progress)?)
}

/// `--figures`: a direct run's four figures, or the tips and forces of an inverse run.
fn write_figures(
    exp: &Experiment,
    stem: &str,
    r: &Response,
    direct: bool,
    dir: &std::path::Path,
) -> anyhow::Result<()> {
    use flexstar_compare::direct_figures::{direct_figures, run_style};
    use flexstar_compare::figures::{figure_forces, figure_tips, Run};
    let figs = if direct {
        direct_figures(exp, stem, r)
    } else {
        let runs = [Run {
            label: stem.to_string(),
            response: r,
            style: run_style(r),
        }];
        let mut v = vec![figure_tips(&exp.name, &runs), figure_forces(&exp.name, &runs, None)];
        for (f, kind) in v.iter_mut().zip(["tips", "forces"]) {
            f.name = format!("{stem}-{kind}");
        }
        v
    };
    let figdir = dir.join("figures");
    std::fs::create_dir_all(&figdir).map_err(|e| anyhow!("{}: {e}", figdir.display()))?;
    for f in &figs {
        f.write(&figdir)?;
    }
    eprintln!("{}: {} figures in {}", exp.name, figs.len(), figdir.display());
    Ok(())
}

/// Columns a direct run's file puts right after the fixed ones (issue 10 contract).
fn direct_columns(servo: bool) -> Vec<&'static str> {
    let mut v = vec!["Gx", "Gy", "theta"];
    if servo {
        v.extend(["e1", "e2", "e3"]);
    }
    v
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let mut exp = super::load(&args.config)?;
    let cfg = args.config.display();
    if let Some(f) = &args.forces {
        if exp.drive.is_direct() {
            eprintln!("note: --forces {} replaces the [drive] of {cfg}", f.display());
        }
        exp.drive = DriveSettings::forces_file(f)?;
    }
    if let Some(dt) = args.dt {
        check_step("--dt", dt, exp.time.dt_out).map_err(|e| e.in_file(&args.config))?;
    }
    let direct = exp.drive.is_direct();
    let servo = exp.drive.kind == DriveKind::Servo;
    // the feasibility scan of both solvers, here too so that nothing is created for a motion
    // that is refused (a forces-driven run: its start only; its motion is checked as it goes)
    if direct && !servo {
        let s0 = exp.trajectory.s(&exp.robot, 0.0).map_err(|e| anyhow!("{cfg}: {e}"))?;
        flexstar_kinematics::check_configuration(&exp.robot, s0)
            .map_err(|violation| anyhow!("{cfg}: {}", flexstar_kinematics::Infeasible { t: 0.0, violation }))?;
    } else {
        flexstar_kinematics::check_trajectory(&exp.robot, &exp.trajectory, exp.time.t_end, exp.time.dt_out.min(1e-3))
            .map_err(|e| anyhow!("{cfg}: {e}"))?;
    }
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
            if direct {
                let law = law_of(&exp, &cfg)?;
                let r = flexstar_amm::solve_direct(&exp, &exp.amm, law.as_ref()).map_err(|e| anyhow!("{cfg}: {e}"))?;
                (r, format!("amm-{}-direct", exp.amm.family))
            } else {
                let r = flexstar_amm::solve(&exp, &exp.amm).map_err(|e| anyhow!("{cfg}: {e}"))?;
                (r, format!("amm-{}", exp.amm.family))
            }
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
            let law = if direct { Some(law_of(&exp, &cfg)?) } else { None };
            let solve = |progress: Option<&(dyn Fn(f64) + Sync)>| -> anyhow::Result<Response> {
                match &law {
                    Some(law) => fem_direct(&exp, law.as_ref(), progress),
                    None => Ok(flexstar_fem::solve(&exp, &exp.fem, progress)?),
                }
            };
            let r = if std::io::stderr().is_terminal() {
                let bar = indicatif::ProgressBar::new(1000);
                bar.set_style(
                    indicatif::ProgressStyle::with_template("FEM {bar:40} {percent:>3}% eta {eta}")
                        .expect("valid template"),
                );
                let tick = |f: f64| bar.set_position((f * 1000.0) as u64);
                let r = solve(Some(&tick));
                bar.finish_and_clear();
                r
            } else {
                solve(None)
            }
            .map_err(|e| anyhow!("{cfg}: {e}"))?;
            (r, if direct { "fem-direct" } else { "fem" }.to_string())
        }
    };
    let mut response = response;
    let csv = dir.join(format!("{file}.csv"));
    if servo && direct {
        flexstar_drive::add_tracking_errors(&mut response, &exp).map_err(|e| anyhow!("{cfg}: {e}"))?;
    }
    // the run's three files are published together (a kill or a full disk keeps the old set)
    let after = direct_columns(servo);
    let order = direct.then_some((&["s1", "s2", "s3"][..], &after[..]));
    let mut set = flexstar_model::run_set::RunSet::begin(&dir)?;
    response.stage_run(&mut set, &file, order, &exp, &super::provenance())?;
    set.commit()?;
    if args.figures {
        write_figures(&exp, &file, &response, direct, &dir)?;
    }
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
