//! `objective = "time"` (`docs/motions.md` 4.6): the shortest move whose residual peak of |dG|
//! after the move, the accurate AMM's over `[t_rest, t_end]`, is at most `residual_max`.
//! First the baseline: the shortest ZVD-shaped quintic (`f_hz = "auto"`) at that residual,
//! found by bracketing and bisection on its base duration; then the planned move by bisection on
//! T between the limits' lower bound and the baseline's duration, each step a
//! Levenberg-Marquardt search warm-started from the last success (the knots sit at fixed
//! fractions of T, so the variables carry over).

use std::time::Duration;

use serde::Serialize;

use crate::limits::{shortest_move, travels};
use crate::lm::{minimise, Stop};
use crate::objective::{window_peak, Eval};
use crate::planner::{
    effective_bounds, evaluate, peak_warnings, search_evaluator, zvd_experiment, PeakComparison, PeakSet, Planned,
    Setup,
};
use crate::section::{Objective, PlanConfig};
use crate::slopes::Slopes;
use crate::PlanError;

/// Bisection steps of each search (3 % of the bracket).
const BISECTIONS: usize = 5;
/// Largest growth steps of the baseline's bracket (x1.5 each).
const GROWTHS: usize = 12;
/// The LM search of one step stops once `|r|` is this share of `residual_max` (the peak over
/// the whole span is then checked by a run).
const TIME_FLOOR_SHARE: f64 = 0.2;

/// One trial duration of a search.
#[derive(Debug, Clone, Serialize)]
pub struct TimeStep {
    /// The trial duration [s] (the base quintic's for the baseline).
    pub t_move: f64,
    /// The AMM's residual peak of |dG| after the move [m].
    pub peak_m: f64,
    /// At most `residual_max` and within the limits?
    pub ok: bool,
    /// AMM runs this step made (the plain quintic's, the search's, the check over the span).
    pub evaluations: usize,
    /// Wall time since the start of the plan when the step ended [s].
    pub wall_s: f64,
    /// The planned bisection: the search's `|r|` (RMS of |dG| over the window) [m] and why it
    /// stopped (empty for the baseline's steps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r_norm_m: Option<f64>,
    #[serde(skip_serializing_if = "String::is_empty")]
    pub reason: String,
}

/// The record of the time objective (plan.json).
#[derive(Debug, Clone, Serialize)]
pub struct TimeSearch {
    pub residual_max_m: f64,
    /// The ZVD-shaped quintic at the same residual: base duration, whole duration (with the
    /// shaper's penalty) [s], its residual peak [m].
    pub zvd_base_s: f64,
    pub zvd_duration_s: f64,
    pub zvd_peak_m: f64,
    pub zvd_steps: Vec<TimeStep>,
    /// Wall time when the baseline was found [s] (from the start of the plan).
    pub zvd_found_s: f64,
    /// The planned move's bisection (AMM).
    pub steps: Vec<TimeStep>,
    /// The FEM's residual peak of the successes, shortest first, until one holds.
    pub fem_checks: Vec<TimeStep>,
    /// AMM runs of the baseline's search and of the planned bisection.
    pub zvd_evaluations: usize,
    pub search_evaluations: usize,
    /// How much shorter the planned move is than the baseline [%].
    pub shorter_percent: f64,
}

/// The AMM residual peak over `[t_rest, t_end]` of the ZVD-shaped quintic of base `t_base`, and
/// its whole duration.
fn zvd_peak(cfg: &PlanConfig, s: &Setup, t_base: f64) -> Result<(f64, f64), PlanError> {
    let x = zvd_experiment(&s.frozen, s.family.quintic(t_base))?;
    let t_rest = x.trajectory.t_rest().unwrap_or(cfg.exp.time.t_end);
    let r = s
        .evaluator
        .run(&x.trajectory, cfg.exp.time.t_end)
        .map_err(|e| PlanError::Solver(format!("the ZVD-shaped quintic of {t_base:.3} s: {e}")))?;
    Ok((window_peak(&r, t_rest), t_rest - cfg.plan.t0))
}

/// The shortest ZVD-shaped quintic at `residual_max`: grow from the limits' bound (or half a
/// period of the first mode) by 1.5 until the residual holds, then bisect.
fn zvd_baseline(
    cfg: &PlanConfig,
    s: &Setup,
    r_max: f64,
    t_lim: f64,
) -> Result<(f64, f64, f64, Vec<TimeStep>), PlanError> {
    let mut steps = Vec::new();
    let mut lo = t_lim;
    let mut t = t_lim.max(1.0 / s.f1_hz);
    let mut found = None;
    let step = |t: f64, peak: f64, runs: usize| TimeStep {
        t_move: t,
        peak_m: peak,
        ok: peak <= r_max,
        evaluations: s.evaluator.runs() - runs,
        wall_s: s.started.elapsed().as_secs_f64(),
        r_norm_m: None,
        reason: String::new(),
    };
    for _ in 0..GROWTHS {
        let runs = s.evaluator.runs();
        // a candidate the solver cannot run (too violent a move) counts as too short
        let (peak, dur) = match zvd_peak(cfg, s, t) {
            Ok(v) => v,
            Err(PlanError::Input(_)) => break,
            Err(_) => (f64::INFINITY, f64::NAN),
        };
        steps.push(step(t, peak, runs));
        if peak <= r_max {
            found = Some((t, dur, peak));
            break;
        }
        lo = t;
        t *= 1.5;
    }
    let Some(mut best) = found else {
        return Err(PlanError::Solver(format!(
            "no ZVD-shaped quintic that ends before time.t_end = {} s leaves |dG| <= residual_max = {r_max} m \
             (the baseline of objective = \"time\"): make t_end longer or residual_max larger",
            cfg.exp.time.t_end
        )));
    };
    let mut hi = best.0;
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        let runs = s.evaluator.runs();
        let (peak, dur) = zvd_peak(cfg, s, mid).unwrap_or((f64::INFINITY, f64::NAN));
        let ok = peak <= r_max;
        steps.push(step(mid, peak, runs));
        if ok {
            hi = mid;
            best = (mid, dur, peak);
        } else {
            lo = mid;
        }
    }
    Ok((best.0, best.1, best.2, steps))
}

/// The outcome of one step of the planned bisection.
enum Trial {
    /// The search ran (its solution, the peak over the whole span).
    Done(Box<Searched>),
    /// The start is rejected (infeasible, limits) or the search failed.
    Failed,
    /// The budget ran out during the search: the step says nothing.
    OutOfTime,
}

/// One step of the planned bisection: the LM search at `t_move` from `x0`, then the peak over
/// the whole span.
fn try_duration(cfg: &PlanConfig, s: &Setup, t_move: f64, x0: &[f64], r_max: f64) -> Trial {
    match search_at(cfg, s, t_move, x0, r_max) {
        Some(sr) if sr.peak > r_max && sr.sol.reason.contains("budget") => Trial::OutOfTime,
        Some(sr) => Trial::Done(Box::new(sr)),
        None => Trial::Failed,
    }
}

/// One LM search at a duration: its solution (variables, evaluation, trace, evaluations, why it
/// stopped), the residual peak over the whole span [m], the plain quintic of that duration and
/// the limits the search enforced (4.10).
#[derive(Debug, Clone)]
struct Searched {
    sol: crate::lm::Solution,
    peak: f64,
    plain: Eval,
    bounds: crate::section::Limits,
}

/// The search of [`try_duration`]; `None` when the start is rejected or a run fails. The limits
/// are those of the plain quintic of this duration (4.10), as is the smoothness reference.
fn search_at(cfg: &PlanConfig, s: &Setup, t_move: f64, x0: &[f64], r_max: f64) -> Option<Searched> {
    let plain = evaluate(&s.evaluator, &s.family, &s.family.plain(), t_move).ok()?;
    if cfg.limits.fa_max.is_some_and(|m| plain.fa.value > m) {
        return None;
    }
    let r_floor = TIME_FLOOR_SHARE * r_max;
    let bounds = effective_bounds(&cfg.limits, cfg.plan.peak_factor(), &plain);
    let ev = search_evaluator(cfg, s, bounds, &plain, r_floor);
    let deadline = s.started + Duration::from_secs_f64(cfg.plan.budget());
    let stop = Stop { r_floor, deadline };
    let f = |x: &[f64]| evaluate(&ev, &s.family, x, t_move);
    let slopes = Slopes::for_search(&ev, &s.family, t_move);
    let g = slopes.as_ref().map(|sl| move |x: &[f64]| sl.jacobian(x));
    let accept = |e: &Eval| e.within(&bounds);
    // a warm start that fails at this duration (a run fails, or it is outside this duration's
    // limits) falls back on the plain quintic
    let (x0, e0) = match f(x0).ok().filter(|e| accept(e)) {
        Some(e) => (x0.to_vec(), e),
        None => {
            let x = s.family.plain();
            let e = f(&x).ok()?;
            (x, e)
        }
    };
    if !accept(&e0) {
        return None;
    }
    let sol = minimise(&f, g.as_ref(), &accept, x0, e0, stop).ok()?;
    let traj = s.family.trajectory(&sol.x, t_move);
    let run = s.evaluator.run(&traj, cfg.exp.time.t_end).ok()?;
    let peak = window_peak(&run, cfg.plan.t0 + t_move);
    Some(Searched {
        sol,
        peak,
        plain,
        bounds,
    })
}

/// A success of the planned bisection: duration and the search's outcome.
type Success = (f64, Searched);

/// Bisection of the planned duration in `(lo, hi)`: the midpoints first (the baseline's
/// duration `hi` is tried last, only if no shorter one succeeded); a step cut by the budget ends
/// the search with the best so far.
fn bisect_planned(
    cfg: &PlanConfig,
    s: &Setup,
    (mut lo, mut hi): (f64, f64),
    r_max: f64,
) -> (Vec<TimeStep>, Vec<Success>) {
    let top = hi;
    let mut steps = Vec::new();
    let mut x = s.family.plain();
    let mut best: Vec<Success> = Vec::new();
    for k in 0..=BISECTIONS {
        let t = if k == BISECTIONS {
            if !best.is_empty() {
                break;
            }
            top
        } else {
            0.5 * (lo + hi)
        };
        let runs = s.evaluator.runs();
        let trial = try_duration(cfg, s, t, &x, r_max);
        let step = |peak: f64, ok: bool, sr: Option<&Searched>, reason: &str| TimeStep {
            t_move: t,
            peak_m: peak,
            ok,
            evaluations: s.evaluator.runs() - runs,
            wall_s: s.started.elapsed().as_secs_f64(),
            r_norm_m: sr.map(|sr| sr.sol.eval.norm_g()),
            reason: sr.map_or(reason.to_string(), |sr| sr.sol.reason.clone()),
        };
        match trial {
            Trial::OutOfTime => {
                steps.push(step(f64::NAN, false, None, "the wall-clock budget is spent"));
                break;
            }
            Trial::Done(sr) if sr.peak <= r_max => {
                steps.push(step(sr.peak, true, Some(sr.as_ref()), ""));
                hi = t;
                x = sr.sol.x.clone();
                best.push((t, *sr));
            }
            Trial::Done(sr) => {
                steps.push(step(sr.peak, false, Some(sr.as_ref()), ""));
                lo = t;
            }
            Trial::Failed => {
                steps.push(step(
                    f64::INFINITY,
                    false,
                    None,
                    "no feasible start within the limits, or a run failed",
                ));
                lo = t;
            }
        }
    }
    (steps, best)
}

/// The shortest success whose residual peak holds on the FEM too (the model the plan trusts,
/// checked where it matters: a fast move leaves a residual of the size of the AMM's own error);
/// when none holds, the longest, with the reason saying so.
fn fem_verified(
    cfg: &PlanConfig,
    s: &Setup,
    mut successes: Vec<Success>,
    r_max: f64,
) -> Result<(Success, Vec<TimeStep>), PlanError> {
    successes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut checks = Vec::new();
    for cand in &successes {
        let mut exp = cfg.exp.clone();
        exp.trajectory = s.family.trajectory(&cand.1.sol.x, cand.0);
        let problem = crate::planner::problem_of(&exp)?;
        let r = flexstar_fem::solve(&problem, &exp.fem, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .map_err(|e| PlanError::Solver(format!("the FEM check: {e}")))?;
        let peak = window_peak(&r, cfg.plan.t0 + cand.0);
        checks.push(TimeStep {
            t_move: cand.0,
            peak_m: peak,
            ok: peak <= r_max,
            evaluations: 0,
            wall_s: s.started.elapsed().as_secs_f64(),
            r_norm_m: None,
            reason: "the FEM's residual peak over [t_rest, t_end]".into(),
        });
        if peak <= r_max {
            return Ok((cand.clone(), checks));
        }
    }
    let mut longest = successes
        .pop()
        .ok_or_else(|| PlanError::Solver("no planned motion".into()))?;
    longest.1.sol.reason = format!(
        "{}; the FEM's residual exceeds residual_max at every duration tried",
        longest.1.sol.reason
    );
    Ok((longest, checks))
}

/// The time objective (module docs).
pub fn plan_time(cfg: &PlanConfig, s: &Setup) -> Result<Planned, PlanError> {
    let r_max = cfg.plan.residual_max.unwrap_or(f64::INFINITY);
    let travel = travels(&cfg.exp.robot, &s.family)?;
    let t_lim = shortest_move(travel, &cfg.limits).0;
    let (zvd_base, zvd_dur, zvd_peak_m, zvd_steps) = zvd_baseline(cfg, s, r_max, t_lim)?;
    let zvd_found_s = s.started.elapsed().as_secs_f64();
    let zvd_evaluations = s.evaluator.runs();
    let (steps, successes) = bisect_planned(cfg, s, (t_lim.max(0.25 * zvd_dur), zvd_dur), r_max);
    let search_evaluations = s.evaluator.runs() - zvd_evaluations;
    if successes.is_empty() {
        return Err(PlanError::Solver(format!(
            "no planned motion as long as the ZVD-shaped quintic ({zvd_dur:.3} s) reached residual_max = {r_max} m"
        )));
    }
    let (chosen, fem_checks) = fem_verified(cfg, s, successes, r_max)?;
    let (t_move, Searched { sol, plain, bounds, .. }) = chosen;
    let crate::lm::Solution {
        x, eval, trace, reason, ..
    } = sol;
    let peaks = PeakComparison {
        plain: PeakSet::of(&plain),
        planned: PeakSet::of(&eval),
    };
    Ok(Planned {
        objective: Objective::Time,
        limits: cfg.limits,
        bounds,
        peak_factor: cfg.plan.peak_factor(),
        warnings: peak_warnings(&peaks.plain, &peaks.planned),
        peaks,
        t_move,
        t_rest: cfg.plan.t0 + t_move,
        trajectory: s.family.trajectory(&x, t_move),
        x,
        family: s.family.clone(),
        eval,
        plain,
        modes: s.modes,
        dt: s.frozen.amm.dt,
        f1_hz: s.f1_hz,
        window_s: s.evaluator.window,
        r_floor_m: TIME_FLOOR_SHARE * r_max,
        trace,
        evaluations: s.evaluator.runs(),
        tangent_directions: s.evaluator.tangent_directions(),
        reason,
        wall_s: s.started.elapsed().as_secs_f64(),
        zvd: zvd_experiment(&cfg.exp, s.family.quintic(zvd_base))?,
        robust: None,
        time_search: Some(TimeSearch {
            residual_max_m: r_max,
            zvd_base_s: zvd_base,
            zvd_duration_s: zvd_dur,
            zvd_peak_m,
            zvd_steps,
            zvd_found_s,
            steps,
            fem_checks,
            zvd_evaluations,
            search_evaluations,
            shorter_percent: 100.0 * (1.0 - t_move / zvd_dur),
        }),
    })
}
