//! The planner (`docs/motions.md` 4.2-4.8): the checks before any work, the frozen AMM and the
//! residual window, the search from the plain quintic, and the ZVD baseline the plan is compared
//! with.

use std::time::{Duration, Instant};

use serde::Serialize;

use flexstar_model::geometry::inverse_kinematics;
use flexstar_model::{DriveKind, Experiment, ModelError, ShaperKind, ShaperSection, Trajectory};

use crate::family::Family;
use crate::limits::{check_quintic_kinematics, check_t_move, kinematic_peaks, quintic_breaks, travels, Peak};
use crate::lm::{minimise, Stop, TraceRow};
use crate::objective::{Eval, Evaluator, SmoothRef, Terms};
use crate::section::{Limits, Objective, PlanConfig};
use crate::slopes::Slopes;
use crate::uncertainty::RobustDuration;
use crate::PlanError;

/// The search stops when the RMS of |dG| over the window is this share of the plain quintic's
/// (`docs/motions.md` 4.5, the model floor: measured on target move 1, a plan pushed to 1 % left
/// a residual on which the AMM and the FEM differed by 27 %; at 2.5 % they agree within 1 %).
pub const FLOOR_SHARE: f64 = 0.025;
/// The residual window, in periods of the first elastic mode at the final pose.
pub const WINDOW_PERIODS: f64 = 2.0;

/// A plan: the motion, how it was found and what the AMM says of it.
#[derive(Debug, Clone, Serialize)]
pub struct Planned {
    pub objective: Objective,
    /// The limits the motion keeps, as given (`[limits]`).
    pub limits: crate::section::Limits,
    /// The limits the search enforced (`docs/motions.md` 4.10): each given limit, lowered to
    /// `peak_factor` times the plain quintic's peak for `a_max`, `j_max` and `Fa_max`.
    pub bounds: crate::section::Limits,
    /// The peak factor in force (`None`: lifted).
    pub peak_factor: Option<f64>,
    /// The peaks of the plain quintic and of the planned motion (AMM force, rigid kinematics).
    pub peaks: PeakComparison,
    /// A note for each peak of the plan above the plain quintic's (4.10): the CLI prints them,
    /// plan.json and plan.md carry them.
    pub warnings: Vec<String>,
    /// Duration of the planned move [s] and its end [s].
    pub t_move: f64,
    pub t_rest: f64,
    /// The interior via points' variables (progress or scaled offsets).
    pub x: Vec<f64>,
    #[serde(skip)]
    pub family: Family,
    /// The planned motion (`kind = "via"`, `rest = false`).
    #[serde(skip)]
    pub trajectory: Trajectory,
    /// The AMM's evaluation of the planned motion and of the plain quintic of the same duration.
    #[serde(skip)]
    pub eval: Eval,
    #[serde(skip)]
    pub plain: Eval,
    /// AMM modes per beam N (frozen), the first frequency at the final pose [Hz], the window [s].
    pub modes: usize,
    /// The AMM step of the searches [s] (the automatic choice's delivered step; `None`: the
    /// default step of a fixed N, 4.3).
    pub dt: Option<f64>,
    pub f1_hz: f64,
    pub window_s: f64,
    /// The model floor of the search [m].
    pub r_floor_m: f64,
    /// The search's trace (for `objective = "time"`, the chosen duration's search; the bisection
    /// is in `time_search.steps`).
    pub trace: Vec<TraceRow>,
    /// Every AMM run the planner's evaluator made (candidates, Jacobian columns, the plain
    /// quintic, for `objective = "time"` the ZVD baseline's runs and the checks over the span);
    /// not the one run that chose N.
    pub evaluations: usize,
    /// The directions carried by those of the runs that took the search's Jacobian by the
    /// tangent-linear AMM (`docs/motions.md` 4.9, "The Jacobian from the tangent"); 0 where the
    /// Jacobians were forward differences.
    pub tangent_directions: usize,
    /// Why the search stopped.
    pub reason: String,
    pub wall_s: f64,
    /// `objective = "time"`: the ZVD-shaped quintic at the same residual and the bisection.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_search: Option<crate::time::TimeSearch>,
    /// The baseline: the experiment of the ZVD-shaped quintic with `f_hz = "auto"` (of the
    /// same nominal duration, or at the same residual for `objective = "time"`).
    #[serde(skip)]
    pub zvd: Experiment,
    /// With `[robust]` (`docs/motions.md` 4.11): the sample, the nominal plan, the shaper over
    /// the uncertainty; this plan is then the robust one, its `eval` on the nominal model.
    #[serde(skip)]
    pub robust: Option<Box<crate::robust::RobustInfo>>,
}

/// The peaks of one motion: `|s_i'|` [m/s], `|s_i''|` [m/s^2], `|s_i'''|` [m/s^3] and the AMM's
/// `|Fa_i|` [N].
#[derive(Debug, Clone, Copy, Serialize)]
pub struct PeakSet {
    pub v: Peak,
    pub a: Peak,
    pub j: Peak,
    pub fa: Peak,
}

impl PeakSet {
    /// The peaks of an evaluation.
    pub fn of(e: &Eval) -> Self {
        PeakSet {
            v: e.v,
            a: e.a,
            j: e.j,
            fa: e.fa,
        }
    }
}

/// The plain quintic's peaks and the plan's.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct PeakComparison {
    pub plain: PeakSet,
    pub planned: PeakSet,
}

/// The limits a search enforces (`docs/motions.md` 4.10): `v_max` as given; `a_max`, `j_max`
/// and `Fa_max` each the smaller of the given limit and `factor` times the plain quintic's peak
/// (`plain`, the same duration); with the factor lifted (`None`), the given limits.
pub fn effective_bounds(limits: &Limits, factor: Option<f64>, plain: &Eval) -> Limits {
    let cap = |given: Option<f64>, quintic: f64| match factor {
        None => given,
        Some(f) => Some(given.map_or(f * quintic, |g| g.min(f * quintic))),
    };
    Limits {
        v_max: limits.v_max,
        a_max: cap(limits.a_max, plain.a.value),
        j_max: cap(limits.j_max, plain.j.value),
        fa_max: cap(limits.fa_max, plain.fa.value),
    }
}

/// A warning for each of the plan's peaks `|s''|`, `|s'''|`, `|Fa|` above the plain quintic's of
/// the same duration (`docs/motions.md` 4.10).
pub fn peak_warnings(plain: &PeakSet, planned: &PeakSet) -> Vec<String> {
    [
        ("|s''|", "m/s^2", plain.a, planned.a),
        ("|s'''|", "m/s^3", plain.j, planned.j),
        ("|Fa| (AMM)", "N", plain.fa, planned.fa),
    ]
    .into_iter()
    .filter(|(_, _, q, p)| p.value > q.value * (1.0 + 1e-9))
    .map(|(what, unit, q, p)| {
        format!(
            "the planned motion's peak {what} = {:.4} {unit} (slider {}, t = {:.3} s) is {:.2} x the plain quintic's {:.4} {unit} at the same t_move",
            p.value,
            p.slider,
            p.t,
            p.value / q.value,
            q.value
        )
    })
    .collect()
}

/// The evaluator of a search at one duration (`docs/motions.md` 4.10): the limits `bounds`,
/// the tips' weight, the smoothness reference from the plain quintic `plain` with the search's
/// floor `r_floor` [m], monotone progress unless lifted.
pub fn search_evaluator(cfg: &PlanConfig, s: &Setup, bounds: Limits, plain: &Eval, r_floor: f64) -> Evaluator {
    s.evaluator.with_limits(bounds).with_terms(Terms {
        tip_weight: cfg.plan.tip_weight(),
        smooth: SmoothRef::new(plain, cfg.plan.smoothness(), r_floor),
        monotone: cfg.plan.monotone().then(|| s.family.clone()),
    })
}

/// What every search shares: the family, the frozen AMM, the window.
#[derive(Debug, Clone)]
pub struct Setup {
    pub family: Family,
    pub evaluator: Evaluator,
    /// The experiment with N frozen (`[amm] modes`): what searches resolve shapers on.
    pub frozen: Experiment,
    pub modes: usize,
    pub f1_hz: f64,
    pub started: Instant,
}

impl Planned {
    /// "`n` evaluations", with the directions the tangent carried where it took the Jacobians
    /// (`docs/motions.md` 4.9, "The Jacobian from the tangent").
    pub fn evaluations_text(&self) -> String {
        match self.tangent_directions {
            0 => format!("{} evaluations", self.evaluations),
            d => format!("{} evaluations ({d} Jacobian columns by the tangent)", self.evaluations),
        }
    }
}

/// Plan the motion of `cfg` (every check of 4.8 first; nothing is written here).
pub fn plan(cfg: &PlanConfig) -> Result<Planned, PlanError> {
    plan_beside(cfg, |_| ()).0
}

/// [`plan`], with `beside` run on the comparison's plain quintic and ZVD-shaped quintic (4.7, in
/// that order) while the search runs, when they are known before it: with the residual
/// objective (the plain quintic of `t_move`, the ZVD baseline of 4.2), robust or not. With the
/// time objective they depend on the search, and `beside` is not called (`None`). The caller's
/// runs of the two baselines then fill the cores the search leaves idle (its sequential trials),
/// and the whole command waits less (`docs/motions.md` 4.9, "Wall time").
pub fn plan_beside<R: Send>(
    cfg: &PlanConfig,
    beside: impl FnOnce(Vec<Experiment>) -> R + Send,
) -> (Result<Planned, PlanError>, Option<R>) {
    let started = Instant::now();
    if let Err(e) = check_plan_input(cfg) {
        return (Err(e), None);
    }
    let t_ref = cfg
        .plan
        .t_move
        .unwrap_or(cfg.exp.trajectory.t_rest().unwrap_or(1.0) - cfg.plan.t0);
    if cfg.plan.objective == Objective::Time {
        let planned = setup(cfg, t_ref, started).and_then(|s| crate::time::plan_time(cfg, &s));
        return (planned, None);
    }
    let quintic = family_of(cfg).quintic(t_ref);
    let (setup, zvd) = rayon::join(
        || setup(cfg, t_ref, started),
        || zvd_experiment(&cfg.exp, quintic.clone()),
    );
    let (setup, zvd) = match (setup, zvd) {
        (Ok(s), Ok(z)) => (s, z),
        (Err(e), _) | (_, Err(e)) => return (Err(e), None),
    };
    let mut plain = cfg.exp.clone();
    plain.trajectory = quintic;
    let baselines = vec![plain, zvd.clone()];
    let (planned, beside) = rayon::join(
        || match &cfg.robust {
            None => plan_residual(cfg, &setup, t_ref, zvd),
            Some(unc) => crate::robust::plan_robust(cfg, &setup, t_ref, zvd, unc),
        },
        || beside(baselines),
    );
    (planned, Some(beside))
}

/// The checks of 4.8 that need the robot but no solver: a motion drive, reachable poses,
/// `t_move` within the limits, the plain quintic's slider peaks within the limits.
pub(crate) fn check_plan_input(cfg: &PlanConfig) -> Result<(), PlanError> {
    let file = &cfg.exp.source;
    let bad = |e: ModelError| PlanError::from(e.in_file(file));
    if cfg.exp.drive.kind != DriveKind::Motion {
        return Err(bad(ModelError::invalid(
            "drive.kind",
            "a plan is a prescribed motion: remove [drive] (forces and servos are not planned)",
        )));
    }
    for (key, p) in [("plan.from", cfg.plan.from), ("plan.to", cfg.plan.to)] {
        inverse_kinematics(&cfg.exp.robot, [p.gx, p.gy], p.theta).map_err(|e| {
            bad(ModelError::invalid(
                key,
                format!(
                    "(Gx = {}, Gy = {}, theta = {}) is outside the workspace: {e}",
                    p.gx, p.gy, p.theta
                ),
            ))
        })?;
    }
    let family = family_of(cfg);
    let travel = travels(&cfg.exp.robot, &family).map_err(bad)?;
    if let Some(t_move) = cfg.plan.t_move {
        check_t_move(t_move, travel, &cfg.limits).map_err(bad)?;
        let quintic = family.quintic(t_move);
        let span = (cfg.plan.t0, cfg.plan.t0 + t_move);
        let knots = knot_times(&family, t_move);
        let peaks = kinematic_peaks(&cfg.exp.robot, &quintic, span, cfg.exp.time.dt_out, &knots).map_err(bad)?;
        check_quintic_kinematics(t_move, peaks, &cfg.limits).map_err(bad)?;
        if let Some(RobustDuration::Seconds(t)) = cfg.robust.as_ref().map(|u| u.t_move) {
            if t < t_move {
                return Err(bad(ModelError::invalid(
                    "robust.t_move",
                    format!("{t} s is shorter than [plan] t_move = {t_move} s: a robust plan takes at least the nominal plan's time"),
                )));
            }
        }
    }
    Ok(())
}

/// The family of the plan's section.
pub fn family_of(cfg: &PlanConfig) -> Family {
    Family {
        shape: cfg.plan.shape,
        from: cfg.plan.from,
        to: cfg.plan.to,
        t0: cfg.plan.t0,
        m: cfg.plan.interior_points(),
    }
}

/// N from the accurate AMM's automatic choice on the plain quintic of `t_ref` [s] (then frozen,
/// 4.3), the first frequency at the final pose, the window.
pub fn setup(cfg: &PlanConfig, t_ref: f64, started: Instant) -> Result<Setup, PlanError> {
    let family = family_of(cfg);
    let mut exp = cfg.exp.clone();
    exp.trajectory = family.quintic(t_ref);
    // N and the step as the accurate AMM's automatic choice delivers them for the plain quintic
    // (docs/motions.md 4.9: the searches run at that N and step; a given N keeps its default step)
    let (modes, dt) = match exp.amm.modes {
        Some(n) => (n, exp.amm.dt),
        None => {
            let info = flexstar_amm::solve(&problem_of(&exp)?, &exp.amm, flexstar_drive::SolveRequest::motion())
                .map_err(|e| PlanError::Solver(format!("the plain quintic's AMM run: {e}")))?
                .response
                .info;
            let n = info
                .modes
                .ok_or_else(|| PlanError::Solver("the AMM did not report its N".into()))?;
            (n, exp.amm.dt.or(Some(info.dt)))
        }
    };
    exp.amm.dt = dt;
    let f1_hz = flexstar_modal::analysis::final_pose_frequencies(&exp, 1)
        .map_err(|e| PlanError::Solver(format!("modes at the final pose: {e}")))?
        .and_then(|f| f.first().copied())
        .filter(|f| *f > 0.0)
        .ok_or_else(|| PlanError::Solver("no elastic mode at the final pose".into()))?;
    let evaluator = Evaluator::new(&exp, modes, WINDOW_PERIODS / f1_hz);
    let mut frozen = exp.clone();
    frozen.amm.modes = Some(modes);
    frozen.amm.tol = None;
    Ok(Setup {
        family,
        evaluator,
        frozen,
        modes,
        f1_hz,
        started,
    })
}

/// The knot times of the family at duration `t_move`.
pub fn knot_times(family: &Family, t_move: f64) -> Vec<f64> {
    family.points(&family.plain(), t_move).iter().map(|p| p.t).collect()
}

/// The experiment of the ZVD-shaped quintic with `f_hz = "auto"` (the baseline), refused when
/// it ends after `time.t_end` (4.8).
pub fn zvd_experiment(exp: &Experiment, base: Trajectory) -> Result<Experiment, PlanError> {
    let mut x = exp.clone();
    let t_base = base.t_rest().unwrap_or(0.0);
    x.trajectory = base;
    x.shaper = Some(ShaperSection::auto(ShaperKind::Zvd));
    flexstar_shaping::shape(&mut x)
        .map_err(|e| PlanError::Solver(format!("the ZVD-shaped quintic: {}", e.detail())))?;
    let t_rest = x.trajectory.t_rest().unwrap_or(f64::INFINITY);
    if t_rest > exp.time.t_end {
        return Err(ModelError::invalid(
            "time.t_end",
            format!(
                "the ZVD-shaped quintic ends at {t_rest:.3} s (the quintic to {t_base} s + ZVD {:.3} s), after time.t_end = {} s; \
                 the plan compares with it: make t_end longer",
                t_rest - t_base,
                exp.time.t_end
            ),
        )
        .in_file(&exp.source)
        .into());
    }
    Ok(x)
}

/// The residual objective: LM from the plain quintic at the fixed `t_move`.
pub(crate) fn plan_residual(cfg: &PlanConfig, s: &Setup, t_move: f64, zvd: Experiment) -> Result<Planned, PlanError> {
    let deadline = s.started + Duration::from_secs_f64(cfg.plan.budget());
    let x0 = s.family.plain();
    let (traj0, knots, t_rest) = (
        s.family.trajectory(&x0, t_move),
        knot_times(&s.family, t_move),
        s.family.t0 + t_move,
    );
    let quintic_error = |e| PlanError::Solver(format!("the plain quintic: {e}"));
    // one run of the plain quintic, assessed without and with the search's limits and terms
    let run0 = s
        .evaluator
        .run(&traj0, t_rest + s.evaluator.window)
        .map_err(quintic_error)?;
    let plain = s
        .evaluator
        .assess(&run0, &traj0, t_rest, &knots)
        .map_err(quintic_error)?;
    if let Some(max) = cfg.limits.fa_max.filter(|m| plain.fa.value > *m) {
        let msg = quintic_breaks(t_move, "|Fa|", "N", plain.fa, max, None);
        return Err(ModelError::invalid("limits.Fa_max", msg)
            .in_file(&cfg.exp.source)
            .into());
    }
    let stop = Stop {
        r_floor: FLOOR_SHARE * plain.norm_g(),
        deadline,
    };
    let bounds = effective_bounds(&cfg.limits, cfg.plan.peak_factor(), &plain);
    let ev = search_evaluator(cfg, s, bounds, &plain, stop.r_floor);
    let f = |x: &[f64]| evaluate(&ev, &s.family, x, t_move);
    let slopes = Slopes::for_search(&ev, &s.family, t_move);
    let g = slopes.as_ref().map(|sl| move |x: &[f64]| sl.jacobian(x));
    let accept = |e: &Eval| e.within(&bounds);
    let e0 = ev.assess(&run0, &traj0, t_rest, &knots).map_err(quintic_error)?;
    if !accept(&e0) {
        return Err(PlanError::Solver(format!(
            "the plain quintic, the search's start, is outside the limits it enforces ({})",
            e0.broken(&bounds).join(", ")
        )));
    }
    let sol = minimise(&f, g.as_ref(), &accept, x0, e0, stop).map_err(|e| PlanError::Solver(e.to_string()))?;
    let peaks = PeakComparison {
        plain: PeakSet::of(&plain),
        planned: PeakSet::of(&sol.eval),
    };
    Ok(Planned {
        objective: Objective::Residual,
        limits: cfg.limits,
        bounds,
        peak_factor: cfg.plan.peak_factor(),
        warnings: peak_warnings(&peaks.plain, &peaks.planned),
        peaks,
        t_move,
        t_rest: cfg.plan.t0 + t_move,
        trajectory: s.family.trajectory(&sol.x, t_move),
        x: sol.x,
        family: s.family.clone(),
        eval: sol.eval,
        plain,
        modes: s.modes,
        dt: s.frozen.amm.dt,
        f1_hz: s.f1_hz,
        window_s: s.evaluator.window,
        r_floor_m: stop.r_floor,
        trace: sol.trace,
        evaluations: s.evaluator.runs(),
        tangent_directions: s.evaluator.tangent_directions(),
        reason: sol.reason,
        wall_s: s.started.elapsed().as_secs_f64(),
        time_search: None,
        zvd,
        robust: None,
    })
}

/// Evaluate the family's motion of the variables `x` and duration `t_move` with `ev`.
pub fn evaluate(ev: &Evaluator, family: &Family, x: &[f64], t_move: f64) -> Result<Eval, crate::objective::Rejected> {
    let traj = family.trajectory(x, t_move);
    let knots = knot_times(family, t_move);
    ev.eval(&traj, family.t0 + t_move, &knots)
}

/// The problem of a planner's experiment (its trajectory replaced by a candidate).
pub(crate) fn problem_of(exp: &flexstar_model::Experiment) -> Result<flexstar_model::Problem, PlanError> {
    exp.problem()
        .map_err(|e| PlanError::Solver(format!("the planned experiment: {}", e.detail())))
}
