//! `flexstar verify`: the four paper cases with the three mode families and the FEM, run in
//! parallel (rayon); Table I, figures and report written to an output directory; the checks of
//! `configs/thresholds.toml` applied.

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_kinematics::{rigid_inverse_dynamics, RigidState};
use flexstar_model::output::write_string_atomically;
use flexstar_model::{Experiment, ModeFamily, Response};
use rayon::prelude::*;

use crate::figures::{
    figure_forces, figure_star, figure_tips, figure_w_g, Figure, Run, Style, FAMILY_COLORS, FEM_STYLE,
};
use crate::report::html_report;
use crate::table::{CaseResults, TableI};
use crate::thresholds::Thresholds;

/// What to verify and where to write.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    /// Experiment files, one per case.
    pub configs: Vec<PathBuf>,
    /// The thresholds file.
    pub thresholds: PathBuf,
    /// Output directory (table, figures, report, per-case CSV).
    pub out: PathBuf,
    /// Draw figures and the report (the CI regression test checks numbers only).
    pub figures: bool,
    /// Also run the AMM at the `n_study` mode counts of the thresholds file (table columns only).
    pub n_study: bool,
}

/// Errors that stop a verify run (a failed check is not an error: see [`VerifyOutcome`]).
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    #[error(transparent)]
    Config(#[from] flexstar_model::ModelError),
    #[error(transparent)]
    Thresholds(#[from] crate::thresholds::ThresholdsError),
    #[error("{case}: AMM {family}: {source}")]
    Amm {
        case: String,
        family: ModeFamily,
        #[source]
        source: flexstar_amm::AmmError,
    },
    #[error("{case}: FEM: {source}")]
    Fem {
        case: String,
        #[source]
        source: flexstar_fem::FemError,
    },
    #[error(transparent)]
    Compare(#[from] crate::evp::CompareError),
    #[error(transparent)]
    Figure(#[from] crate::figures::FigureError),
    #[error("{case}: rigid kinematics: {source}")]
    Kinematics {
        case: String,
        #[source]
        source: flexstar_kinematics::KinematicsError,
    },
}

/// The result of a verify run.
#[derive(Debug)]
pub struct VerifyOutcome {
    pub table: TableI,
    /// Failed checks; empty when everything holds.
    pub failures: Vec<String>,
    /// Wall time of the solves and of the whole run [s].
    pub solve_seconds: f64,
    pub total_seconds: f64,
}

enum Job {
    Fem(usize),
    Amm(usize, ModeFamily, usize),
}

enum Done {
    Fem(usize, Response),
    Amm(usize, ModeFamily, usize, Response),
}

/// Run every case, write outputs, apply the thresholds.
pub fn run_verify(opts: &VerifyOptions) -> Result<VerifyOutcome, VerifyError> {
    let start = Instant::now();
    let thresholds = Thresholds::load(&opts.thresholds)?;
    let exps: Vec<Experiment> = opts
        .configs
        .iter()
        .map(|c| Experiment::load(c))
        .collect::<Result<_, _>>()?;
    let mut jobs = Vec::new();
    for k in 0..exps.len() {
        jobs.push(Job::Fem(k));
    }
    for k in 0..exps.len() {
        for f in ModeFamily::PAPER {
            jobs.push(Job::Amm(k, f, thresholds.modes));
            for &n in thresholds.n_study.iter().filter(|_| opts.n_study) {
                if n != thresholds.modes {
                    jobs.push(Job::Amm(k, f, n));
                }
            }
        }
    }
    let done: Vec<Done> = jobs
        .par_iter()
        .map(|job| match *job {
            Job::Fem(k) => flexstar_fem::solve(&exps[k], &exps[k].fem, None)
                .map(|r| Done::Fem(k, r))
                .map_err(|source| VerifyError::Fem {
                    case: exps[k].name.clone(),
                    source,
                }),
            Job::Amm(k, family, modes) => {
                let settings = flexstar_model::AmmSettings {
                    snapshots: exps[k].amm.snapshots.clone(),
                    dt: exps[k].amm.dt,
                    ..flexstar_model::AmmSettings::paper(family, modes)
                };
                flexstar_amm::solve(&exps[k], &settings)
                    .map(|r| Done::Amm(k, family, modes, r))
                    .map_err(|source| VerifyError::Amm {
                        case: exps[k].name.clone(),
                        family,
                        source,
                    })
            }
        })
        .collect::<Result<_, _>>()?;
    let solve_seconds = start.elapsed().as_secs_f64();

    let mut cases: Vec<CaseResults> = exps
        .iter()
        .map(|e| CaseResults {
            name: e.name.clone(),
            description: e.description.clone(),
            beam_length: e.robot.l,
            fem: Response::default(),
            amm: Vec::new(),
            n_study: Vec::new(),
            modes: thresholds.modes,
        })
        .collect();
    for d in done {
        match d {
            Done::Fem(k, r) => cases[k].fem = r,
            Done::Amm(k, f, n, r) if n == thresholds.modes => cases[k].amm.push((f, r)),
            Done::Amm(k, f, n, r) => cases[k].n_study.push((f, n, r)),
        }
    }
    for c in &mut cases {
        c.amm
            .sort_by_key(|(f, _)| ModeFamily::PAPER.iter().position(|g| g == f));
    }
    let table = TableI::compute(&cases)?;
    let failures = thresholds.check(&table);

    write_outputs(opts, &exps, &cases, &table, &failures)?;
    Ok(VerifyOutcome {
        table,
        failures,
        solve_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
}

fn family_style(f: ModeFamily) -> Style {
    let k = ModeFamily::PAPER.iter().position(|g| *g == f).unwrap_or(3);
    Style {
        color: FAMILY_COLORS[k],
        width: 2,
        dashed: false,
    }
}

/// The paper's figure set for one case.
pub fn case_figures(exp: &Experiment, case: &CaseResults) -> Result<Vec<Figure>, VerifyError> {
    let mut runs = vec![Run {
        label: "FEM".into(),
        response: &case.fem,
        style: FEM_STYLE,
    }];
    for (f, r) in &case.amm {
        runs.push(Run {
            label: format!("AMM {f}"),
            response: r,
            style: family_style(*f),
        });
    }
    let kin = |t: f64| {
        RigidState::at(&exp.robot, &exp.trajectory, t).map_err(|source| VerifyError::Kinematics {
            case: exp.name.clone(),
            source,
        })
    };
    let t = &case.fem.t;
    let rigid: Vec<[f64; 3]> = t
        .iter()
        .map(|&ti| kin(ti).map(|s| rigid_inverse_dynamics(&exp.robot, &s).fa))
        .collect::<Result<_, _>>()?;
    let mut figs = vec![figure_w_g(&exp.name, &runs), figure_tips(&exp.name, &runs)];
    let last = kin(exp.time.t_end)?;
    let peak = case
        .fem
        .w_tip
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-9);
    // magnify the elastic part to about a fifth of the beam length
    let magnify = (0.2 * exp.robot.l / peak).clamp(1.0, 1e4).round();
    if let Some(f) = figure_star(&exp.name, &runs, &last, magnify) {
        figs.push(f);
    }
    figs.push(figure_forces(&exp.name, &runs, Some((t, &rigid))));
    Ok(figs)
}

fn write_outputs(
    opts: &VerifyOptions,
    exps: &[Experiment],
    cases: &[CaseResults],
    table: &TableI,
    failures: &[String],
) -> Result<(), VerifyError> {
    let out = &opts.out;
    for c in cases {
        let dir = out.join(&c.name);
        c.fem.write_csv(&dir.join("fem.csv"))?;
        for (f, r) in &c.amm {
            r.write_csv(&dir.join(format!("amm-{f}.csv")))?;
        }
    }
    write_string_atomically(&out.join("table1.md"), &table.to_markdown())?;
    write_string_atomically(&out.join("table1.csv"), &table.to_csv())?;
    write_string_atomically(&out.join("table1.json"), &table.to_json())?;
    let checks = if failures.is_empty() {
        "all checks hold\n".to_string()
    } else {
        failures.iter().map(|f| format!("FAIL {f}\n")).collect()
    };
    write_string_atomically(&out.join("checks.txt"), &checks)?;
    if !opts.figures {
        return Ok(());
    }
    let figdir = out.join("figures");
    let per_case: Vec<(String, Vec<Figure>)> = exps
        .par_iter()
        .zip(cases.par_iter())
        .map(|(e, c)| {
            let figs = case_figures(e, c)?;
            for f in &figs {
                f.write(&figdir)?;
            }
            Ok((e.name.clone(), figs))
        })
        .collect::<Result<_, VerifyError>>()?;
    let notes = "Regenerated by `flexstar verify` from configs/case1..4.toml. Reference: the FEM of crates/fem. \
                 How EVPs are computed and why rankings may differ from the paper: docs/validation.md.";
    let html = html_report(table, failures, &per_case, notes)?;
    write_string_atomically(&out.join("report.html"), &html)?;
    Ok(())
}

/// The default experiment files of the four paper cases, relative to `root`.
pub fn paper_configs(root: &Path) -> Vec<PathBuf> {
    (1..=4)
        .map(|k| root.join("configs").join(format!("case{k}.toml")))
        .collect()
}
