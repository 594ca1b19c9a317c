//! The robust plan (`docs/motions.md` 4.11): the nominal plan of 4.9-4.10 first, then the sample
//! models (Eq. U2), then the worst-case (quantile) search over them (Eq. U1, [`crate::minimax`])
//! from the better of the plain quintic and the nominal plan; and the automatic shaper over the
//! same sample ([`flexstar_shaping::robust::shape_over`]). This crate plans; checking the motions
//! on the sample (AMM) and on fresh draws (FEM) is the command's (`flexstar_api::plan`).

use std::time::Duration;

use serde::Serialize;

use flexstar_model::{Experiment, ModelError};

use crate::family::Family;
use crate::lm::Jacobian;
use crate::minimax::{self, Models};
use crate::objective::{Eval, Evaluator, Rejected, SmoothRef, Terms};
use crate::planner::{effective_bounds, evaluate, peak_warnings, PeakComparison, PeakSet, Planned, Setup};
use crate::planner::{FLOOR_SHARE, WINDOW_PERIODS};
use crate::section::{Limits, PlanConfig};
use crate::slopes::Slopes;
use crate::uncertainty::{RobustDuration, Uncertainty};
use crate::PlanError;

/// Neighbouring sample models (sorted by their first frequency at the final pose) are at most
/// this ratio apart (Eq. U2).
pub const MAX_GAP: f64 = 1.25;

/// One sample model: its values (one per uncertain key) and first elastic frequency at the final
/// pose [Hz].
#[derive(Debug, Clone, Serialize)]
pub struct SampleModel {
    pub values: Vec<f64>,
    pub f1_hz: f64,
    /// Is it the file's own model?
    pub nominal: bool,
    #[serde(skip)]
    pub exp: Experiment,
}

/// What a robust plan adds to [`Planned`] (which holds the robust plan itself, evaluated on the
/// nominal model).
#[derive(Debug, Clone)]
pub struct RobustInfo {
    pub uncertainty: Uncertainty,
    /// The sample the search held over.
    pub sample: Vec<SampleModel>,
    /// The candidates (corners or ends) with their first frequency, the sample chosen from them.
    pub candidates: Vec<(Vec<f64>, f64)>,
    /// The nominal plan (4.9-4.10 on the file's model).
    pub nominal: Planned,
    /// The robust plan's duration [s] (`[robust] t_move`; the plain quintic and the nominal plan
    /// keep the plan's `t_move`).
    pub t_move_s: f64,
    /// The objective of Eq. U1 [m] (RMS over each model's window) at the plain quintic and the
    /// nominal plan (both at the plan's `t_move`) and the robust plan.
    pub objective_plain_m: f64,
    /// Eq. U1 at the plain quintic of the robust plan's duration, where that differs from the
    /// plan's `t_move` (the search's start when it started from the plain quintic) [m].
    pub objective_plain_robust_m: Option<f64>,
    pub objective_nominal_m: f64,
    pub objective_m: f64,
    /// Which the search started from (`"plain"` or `"nominal"`).
    pub start: &'static str,
    /// The shaped quintic over the uncertainty.
    pub shaped: flexstar_shaping::robust::Covering,
}

/// The sample models' evaluators and limits: what [`minimax::minimise`] searches over.
struct SampleSet<'a> {
    family: &'a Family,
    t_move: f64,
    evaluators: Vec<Evaluator>,
    /// Each model's Jacobians ([`Slopes::for_search`]: its coarse model, by the tangent where it
    /// covers the model).
    slopes: Vec<Option<Slopes>>,
    bounds: Vec<Limits>,
}

impl Models for SampleSet<'_> {
    fn count(&self) -> usize {
        self.evaluators.len()
    }

    fn eval(&self, k: usize, x: &[f64]) -> Result<Eval, Rejected> {
        evaluate(&self.evaluators[k], self.family, x, self.t_move)
    }

    fn accept(&self, k: usize, e: &Eval) -> bool {
        e.within(&self.bounds[k])
    }

    fn slope_jacobian(&self, k: usize, x: &[f64]) -> Option<Result<(Jacobian, usize), Rejected>> {
        self.slopes[k].as_ref().map(|s| s.jacobian(x))
    }
}

/// Plan robustly (the residual objective, `t_move` given): the nominal plan, the sample, the
/// search, the shaper over the sample.
pub fn plan_robust(
    cfg: &PlanConfig,
    s: &Setup,
    t_move: f64,
    zvd: Experiment,
    unc: &Uncertainty,
) -> Result<Planned, PlanError> {
    let t_robust = robust_duration(cfg, unc.t_move, t_move, &zvd)?;
    let (candidates, sample) = choose_sample(unc, &s.family.quintic(t_move), s.f1_hz)?;
    check_window(cfg, t_robust, &sample)?;
    let nominal = crate::planner::plan_residual(cfg, s, t_move, zvd)?;
    let plain_x = s.family.plain();
    let (set, plains) = sample_set(cfg, s, t_robust, &sample)?;
    let floors: Vec<f64> = plains.iter().map(|p| FLOOR_SHARE * p.norm_g()).collect();
    let evals_at = |x: &[f64]| -> Option<Vec<Eval>> {
        (0..set.count())
            .map(|k| set.eval(k, x).ok().filter(|e| set.accept(k, e)))
            .collect()
    };
    let score = |e: &[Eval]| minimax::objective(&e.iter().map(Eval::norm).collect::<Vec<_>>(), unc.quantile);
    let e_plain = evals_at(&plain_x)
        .ok_or_else(|| PlanError::Solver("the plain quintic breaks a sample model's limits".into()))?;
    let e_nominal = evals_at(&nominal.x);
    let (start, x0, e0) = match e_nominal {
        Some(e) if score(&e) < score(&e_plain) => ("nominal", nominal.x.clone(), e),
        _ => ("plain", plain_x.clone(), e_plain.clone()),
    };
    let stop = minimax::Stop {
        floors,
        deadline: s.started + Duration::from_secs_f64(cfg.plan.budget()),
    };
    let sol = minimax::minimise(&set, unc.quantile, x0, e0, &stop).map_err(|e| PlanError::Solver(e.to_string()))?;
    let k_nom = sample.iter().position(|m| m.nominal).unwrap_or(0);
    let shaped = flexstar_shaping::robust::shape_over(
        &with_trajectory(&s.frozen, s.family.quintic(t_move)),
        &sample.iter().map(|m| m.exp.clone()).collect::<Vec<_>>(),
    )
    .map_err(|e| PlanError::Solver(format!("the shaper over the uncertainty: {}", e.detail())))?;
    // the plain quintic's and the nominal plan's Eq. U1 at their own duration, the plan's t_move
    let at_plan = if t_robust == t_move {
        None
    } else {
        Some(sample_set(cfg, s, t_move, &sample)?)
    };
    let (objective_plain_m, objective_nominal_m) = match &at_plan {
        None => (score(&e_plain), e_nominal_score(&nominal, &set, unc.quantile)),
        Some((set_plan, plains_plan)) => (score(plains_plan), e_nominal_score(&nominal, set_plan, unc.quantile)),
    };
    // every evaluator's count: the sample models' (at the search's duration and at the plan's),
    // then the nominal plan's
    let total = |count: fn(&Evaluator) -> usize| {
        set.evaluators.iter().map(count).sum::<usize>()
            + at_plan
                .as_ref()
                .map_or(0, |(p, _)| p.evaluators.iter().map(count).sum::<usize>())
            + count(&s.evaluator)
    };
    let (runs, tangent_directions) = (total(Evaluator::runs), total(Evaluator::tangent_directions));
    let info = RobustInfo {
        uncertainty: unc.clone(),
        candidates,
        t_move_s: t_robust,
        objective_plain_robust_m: at_plan.is_some().then(|| score(&e_plain)),
        objective_plain_m,
        objective_nominal_m,
        objective_m: sol.objective,
        start,
        shaped,
        sample,
        nominal: nominal.clone(),
    };
    let peaks = PeakComparison {
        plain: PeakSet::of(&plains[k_nom]),
        planned: PeakSet::of(&sol.evals[k_nom]),
    };
    Ok(Planned {
        warnings: peak_warnings(&peaks.plain, &peaks.planned),
        peaks,
        t_move: t_robust,
        t_rest: cfg.plan.t0 + t_robust,
        trajectory: s.family.trajectory(&sol.x, t_robust),
        x: sol.x,
        eval: sol.evals[k_nom].clone(),
        plain: plains[k_nom].clone(),
        bounds: set.bounds[k_nom],
        r_floor_m: stop.floors[k_nom],
        trace: sol.trace,
        evaluations: runs,
        tangent_directions,
        reason: sol.reason,
        wall_s: s.started.elapsed().as_secs_f64(),
        robust: Some(Box::new(info)),
        ..nominal
    })
}

/// The robust plan's duration [s] (`[robust] t_move`): the plan's, the ZVD-shaped quintic's (its
/// rest minus the plan's start) or the seconds given.
fn robust_duration(cfg: &PlanConfig, d: RobustDuration, t_move: f64, zvd: &Experiment) -> Result<f64, PlanError> {
    match d {
        RobustDuration::Plan => Ok(t_move),
        RobustDuration::Seconds(t) => Ok(t),
        RobustDuration::Zvd => zvd
            .trajectory
            .t_rest()
            .map(|t| t - cfg.plan.t0)
            .ok_or_else(|| PlanError::Solver("the ZVD-shaped quintic has no end of motion".into())),
    }
}

/// `time.t_end` holds the robust plan and its residual window on every sample model (two periods
/// of the lowest first frequency after the rest), so that the comparison's runs judge it as the
/// search did.
fn check_window(cfg: &PlanConfig, t_robust: f64, sample: &[SampleModel]) -> Result<(), PlanError> {
    let f_lo = sample.iter().map(|m| m.f1_hz).fold(f64::INFINITY, f64::min);
    let needed = cfg.plan.t0 + t_robust + WINDOW_PERIODS / f_lo;
    if cfg.exp.time.t_end + 1e-12 < needed {
        return Err(ModelError::invalid(
            "time.t_end",
            format!(
                "{} s ends before the robust plan's residual window does: the plan rests at {:.4} s and its window (two periods of the lowest sample f1, {f_lo:.3} Hz) needs t_end >= {needed:.4} s",
                cfg.exp.time.t_end,
                cfg.plan.t0 + t_robust
            ),
        )
        .in_file(&cfg.exp.source)
        .into());
    }
    Ok(())
}

/// Eq. U1 at the nominal plan (infinite when it breaks a sample model's limits).
fn e_nominal_score(nominal: &Planned, set: &SampleSet, quantile: f64) -> f64 {
    let norms: Option<Vec<f64>> = (0..set.count())
        .map(|k| {
            set.eval(k, &nominal.x)
                .ok()
                .filter(|e| set.accept(k, e))
                .map(|e| e.norm())
        })
        .collect();
    norms.map_or(f64::INFINITY, |n| minimax::objective(&n, quantile))
}

/// `exp` with its trajectory replaced.
fn with_trajectory(exp: &Experiment, traj: flexstar_model::Trajectory) -> Experiment {
    let mut e = exp.clone();
    e.trajectory = traj;
    e
}

/// The candidates and the sample of Eq. U2: the nominal model and every candidate (corners),
/// each with its first frequency at the final pose of `quintic`; kept the nominal, the lowest and
/// the highest, then the candidate nearest the geometric middle of the widest gap while a gap
/// exceeds [`MAX_GAP`].
#[allow(clippy::type_complexity)]
pub fn choose_sample(
    unc: &Uncertainty,
    quintic: &flexstar_model::Trajectory,
    f1_nominal: f64,
) -> Result<(Vec<(Vec<f64>, f64)>, Vec<SampleModel>), PlanError> {
    let model = |values: &[f64]| -> Result<SampleModel, PlanError> {
        let mut exp = unc.model_at(values).map_err(PlanError::from)?;
        exp.trajectory = quintic.clone();
        let f1_hz = first_frequency(&exp)?;
        Ok(SampleModel {
            values: values.to_vec(),
            f1_hz,
            nominal: false,
            exp,
        })
    };
    let mut pool: Vec<SampleModel> = unc.candidates().iter().map(|v| model(v)).collect::<Result<_, _>>()?;
    let candidates = pool.iter().map(|m| (m.values.clone(), m.f1_hz)).collect();
    let mut nominal = model(&unc.nominal_values())?;
    nominal.nominal = true;
    nominal.f1_hz = f1_nominal;
    pool.sort_by(|a, b| a.f1_hz.total_cmp(&b.f1_hz));
    let mut chosen = vec![nominal];
    for end in [pool.first().cloned(), pool.last().cloned()].into_iter().flatten() {
        if !chosen.iter().any(|m| m.values == end.values) {
            chosen.push(end);
        }
    }
    loop {
        chosen.sort_by(|a, b| a.f1_hz.total_cmp(&b.f1_hz));
        let gap = chosen
            .windows(2)
            .enumerate()
            .map(|(i, w)| (i, w[1].f1_hz / w[0].f1_hz))
            .filter(|(_, r)| *r > MAX_GAP)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((i, _)) = gap else { break };
        let middle = (chosen[i].f1_hz * chosen[i + 1].f1_hz).sqrt();
        let fill = pool
            .iter()
            .filter(|m| m.f1_hz > chosen[i].f1_hz && m.f1_hz < chosen[i + 1].f1_hz)
            .filter(|m| !chosen.iter().any(|c| c.values == m.values))
            .min_by(|a, b| (a.f1_hz / middle).ln().abs().total_cmp(&(b.f1_hz / middle).ln().abs()));
        match fill {
            Some(m) => chosen.push(m.clone()),
            None => break,
        }
    }
    Ok((candidates, chosen))
}

/// The first elastic frequency at the final pose [Hz] (accurate AMM, sliders locked).
fn first_frequency(exp: &Experiment) -> Result<f64, PlanError> {
    flexstar_modal::analysis::final_pose_frequencies(exp, 1)
        .map_err(|e| PlanError::Solver(format!("modes at the final pose of a sample model: {e}")))?
        .and_then(|f| f.first().copied())
        .filter(|f| *f > 0.0)
        .ok_or_else(|| PlanError::Solver("a sample model has no elastic mode at the final pose".into()))
}

/// Each sample model's evaluator (N frozen at the nominal's, the window two periods of its own
/// first frequency), its plain quintic and its limits (4.10's, from its own plain quintic).
fn sample_set<'a>(
    cfg: &PlanConfig,
    s: &'a Setup,
    t_move: f64,
    sample: &[SampleModel],
) -> Result<(SampleSet<'a>, Vec<Eval>), PlanError> {
    let mut set = SampleSet {
        family: &s.family,
        t_move,
        evaluators: Vec::new(),
        slopes: Vec::new(),
        bounds: Vec::new(),
    };
    let mut plains = Vec::new();
    for m in sample {
        let mut exp = m.exp.clone();
        exp.amm.dt = s.frozen.amm.dt;
        let base = Evaluator::new(&exp, s.modes, WINDOW_PERIODS / m.f1_hz);
        let plain = evaluate(&base, &s.family, &s.family.plain(), t_move)
            .map_err(|e| PlanError::Solver(format!("the plain quintic on a sample model {:?}: {e}", m.values)))?;
        let bounds = effective_bounds(&cfg.limits, cfg.plan.peak_factor(), &plain);
        if let Some(max) = cfg.limits.fa_max.filter(|m| plain.fa.value > *m) {
            return Err(ModelError::invalid(
                "limits.Fa_max",
                format!(
                    "the plain quintic on the sample model {:?} of [robust] reaches |Fa| = {:.3} N, above Fa_max = {max} N",
                    m.values, plain.fa.value
                ),
            )
            .in_file(&cfg.exp.source)
            .into());
        }
        let floor = FLOOR_SHARE * plain.norm_g();
        let ev = base.with_limits(bounds).with_terms(Terms {
            tip_weight: cfg.plan.tip_weight(),
            smooth: SmoothRef::new(&plain, cfg.plan.smoothness(), floor),
            monotone: cfg.plan.monotone().then(|| s.family.clone()),
        });
        set.slopes.push(Slopes::for_search(&ev, &s.family, t_move));
        set.evaluators.push(ev);
        set.bounds.push(bounds);
        plains.push(plain);
    }
    Ok((set, plains))
}
