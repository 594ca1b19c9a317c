//! The checks of a robust plan (`docs/motions.md` 4.11): every motion of the comparison run on
//! each sample model (accurate AMM) and on the fresh models drawn in the box (seeded; the
//! accurate AMM or the FEM, `[robust] check`), the
//! residual peak of |dG| after each motion's own `t_rest` over equal windows; the worst and the
//! q-quantile per motion; the robustness curves (AMM, one key at a time over its range).

use rayon::prelude::*;
use serde::Serialize;

use flexstar_model::{Experiment, Trajectory};
use flexstar_plan::robust::RobustInfo;
use flexstar_plan::uncertainty::{CheckModel, Uncertainty};
use flexstar_solve::{Settings, Solver};

use crate::{ApiError, Result};

/// Points of each robustness curve (evenly spaced over the range, the nominal value added).
pub const CURVE_POINTS: usize = 5;

/// One model of a check: its values (one per uncertain key) and each motion's residual peak of
/// |dG| after its `t_rest` [m] (`None`: the run failed, the reason in `failures`).
#[derive(Debug, Clone, Serialize)]
pub struct ModelRow {
    pub values: Vec<f64>,
    pub residual_m: Vec<Option<f64>>,
}

/// Per motion: the worst and the q-quantile of the residual peaks over a set of models [m].
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub motion: String,
    pub worst_m: f64,
    pub quantile_m: f64,
}

/// One robustness curve: key `key`, the values, and per motion the AMM residual peaks [m].
#[derive(Debug, Clone, Serialize)]
pub struct Curve {
    pub key: String,
    pub values: Vec<f64>,
    pub residual_m: Vec<Vec<Option<f64>>>,
}

/// The checks of a robust plan.
#[derive(Debug, Clone, Serialize)]
pub struct RobustCheck {
    /// The motions, in the order of every row's columns.
    pub motions: Vec<String>,
    /// The window after each `t_rest` [s]: two periods of the lowest first frequency of the sample.
    pub window_s: f64,
    pub sample: Vec<ModelRow>,
    pub sample_summary: Vec<Summary>,
    pub draws: Vec<ModelRow>,
    pub draws_summary: Vec<Summary>,
    /// The model the draws ran on: `"AMM"` (the accurate AMM at the plan's N and step,
    /// [`CheckAmm`]) or `"FEM"`.
    pub draws_model: String,
    pub curves: Vec<Curve>,
    /// Runs that failed, with their reason (none expected).
    pub failures: Vec<String>,
    pub wall_s: f64,
}

/// The AMM of the checks: N and the step the plan's searches ran at (`modes`, `dt`: the accurate
/// AMM's automatic choice for the plain quintic on the file's model), without the estimate's
/// runs (`docs/motions.md` 4.11, "The check's model").
#[derive(Debug, Clone, Copy)]
pub struct CheckAmm {
    pub modes: usize,
    pub dt: Option<f64>,
}

impl CheckAmm {
    /// `exp` with its AMM at this N and step.
    fn applied(self, mut exp: Experiment) -> Experiment {
        exp.amm.modes = Some(self.modes);
        exp.amm.tol = None;
        exp.amm.dt = self.dt;
        exp
    }
}

/// Run the checks of `info` for the motions `(label, trajectory)`, the AMM's at `amm`.
pub fn check(info: &RobustInfo, motions: &[(String, Trajectory)], amm: CheckAmm) -> RobustCheck {
    let started = std::time::Instant::now();
    let unc = &info.uncertainty;
    let f_min = info.sample.iter().map(|m| m.f1_hz).fold(f64::INFINITY, f64::min);
    let window_s = 2.0 / f_min;
    let mut failures = Vec::new();
    let sample_models: Vec<(Vec<f64>, Result<Experiment>)> = info
        .sample
        .iter()
        .map(|m| (m.values.clone(), Ok(amm.applied(m.exp.clone()))))
        .collect();
    let sample = rows(&sample_models, motions, Solver::Amm, window_s, &mut failures);
    let draw_models: Vec<(Vec<f64>, Result<Experiment>)> = unc
        .fresh_draws()
        .into_iter()
        .map(|v| (v.clone(), model(unc, &v, amm)))
        .collect();
    let draws_solver = check_solver(unc);
    let draws = rows(&draw_models, motions, draws_solver, window_s, &mut failures);
    let curves = curves(unc, motions, window_s, amm, &mut failures);
    let labels: Vec<String> = motions.iter().map(|(l, _)| l.clone()).collect();
    RobustCheck {
        sample_summary: summaries(&labels, &sample, unc.quantile),
        draws_summary: summaries(&labels, &draws, unc.quantile),
        draws_model: draws_solver.name().to_uppercase(),
        motions: labels,
        window_s,
        sample,
        draws,
        curves,
        failures,
        wall_s: started.elapsed().as_secs_f64(),
    }
}

/// The solver of the fresh draws (`[robust] check`).
fn check_solver(unc: &Uncertainty) -> Solver {
    match unc.check {
        CheckModel::Amm => Solver::Amm,
        CheckModel::Fem => Solver::Fem,
    }
}

/// The model of `values` (its AMM at `amm`; the FEM takes no AMM settings).
fn model(unc: &Uncertainty, values: &[f64], amm: CheckAmm) -> Result<Experiment> {
    unc.model_at(values)
        .map(|e| amm.applied(e))
        .map_err(ApiError::from_model)
}

/// Every motion on every model, in parallel: the residual rows.
fn rows(
    models: &[(Vec<f64>, Result<Experiment>)],
    motions: &[(String, Trajectory)],
    solver: Solver,
    window_s: f64,
    failures: &mut Vec<String>,
) -> Vec<ModelRow> {
    let jobs: Vec<(usize, usize)> = (0..models.len())
        .flat_map(|i| (0..motions.len()).map(move |k| (i, k)))
        .collect();
    let results: Vec<std::result::Result<f64, String>> = jobs
        .par_iter()
        .map(|&(i, k)| match &models[i].1 {
            Ok(exp) => residual_on(exp, &motions[k].1, solver, window_s),
            Err(e) => Err(e.to_string()),
        })
        .collect();
    let mut out: Vec<ModelRow> = models
        .iter()
        .map(|(v, _)| ModelRow {
            values: v.clone(),
            residual_m: vec![None; motions.len()],
        })
        .collect();
    for (&(i, k), r) in jobs.iter().zip(results) {
        match r {
            Ok(v) => out[i].residual_m[k] = Some(v),
            Err(e) => failures.push(format!(
                "{} on {:?} ({}): {e}",
                motions[k].0,
                models[i].0,
                solver.name()
            )),
        }
    }
    out
}

/// The residual peak of |dG| [m] over `[t_rest, t_rest + window_s]` of `traj` on the model `exp`
/// (its trajectory replaced; the accurate AMM or the FEM at the model's own settings).
pub fn residual_on(
    exp: &Experiment,
    traj: &Trajectory,
    solver: Solver,
    window_s: f64,
) -> std::result::Result<f64, String> {
    let mut x = exp.clone();
    let t_rest = traj.t_rest().ok_or("the motion never comes to rest")?;
    x.trajectory = traj.clone();
    x.shaper = None;
    x.time.t_end = t_rest + window_s;
    let problem = x.problem().map_err(|e| e.detail())?;
    let r = flexstar_solve::response(&problem, Settings::of(&x, solver), None, None).map_err(|e| e.to_string())?;
    Ok(flexstar_plan::objective::window_peak(&r, t_rest))
}

/// The robustness curves: each key over its range, the others nominal, every motion on the AMM.
fn curves(
    unc: &Uncertainty,
    motions: &[(String, Trajectory)],
    window_s: f64,
    amm: CheckAmm,
    failures: &mut Vec<String>,
) -> Vec<Curve> {
    (0..unc.ranges.len())
        .map(|j| {
            let values = unc.sweep(j, CURVE_POINTS);
            let models: Vec<(Vec<f64>, Result<Experiment>)> = values
                .iter()
                .map(|&v| {
                    let mut all = unc.nominal_values();
                    all[j] = v;
                    (all.clone(), model(unc, &all, amm))
                })
                .collect();
            let rows = rows(&models, motions, Solver::Amm, window_s, failures);
            Curve {
                key: unc.ranges[j].key.clone(),
                values,
                residual_m: (0..motions.len())
                    .map(|k| rows.iter().map(|r| r.residual_m[k]).collect())
                    .collect(),
            }
        })
        .collect()
}

/// Per motion the worst and the q-quantile (the study's quantile, linear between order
/// statistics) of the rows' residuals; a failed run counts as infinite.
fn summaries(labels: &[String], rows: &[ModelRow], q: f64) -> Vec<Summary> {
    labels
        .iter()
        .enumerate()
        .map(|(k, label)| {
            let mut v: Vec<f64> = rows.iter().map(|r| r.residual_m[k].unwrap_or(f64::INFINITY)).collect();
            v.sort_by(f64::total_cmp);
            Summary {
                motion: label.clone(),
                worst_m: v.last().copied().unwrap_or(f64::NAN),
                quantile_m: flexstar_study::report::quantile(&v, q),
            }
        })
        .collect()
}
