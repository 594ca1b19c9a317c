//! One evaluation of a candidate motion (`docs/motions.md` 4.3 as amended): the accurate AMM,
//! its N frozen, run over the move and a residual window of `W` seconds after `t_rest`; the
//! residual vector `r` holds the elastic displacement of G over the window,
//! `r = sqrt(2/3) w_iG(t_k) / sqrt(n)` for the `n` output times `t_k` in `[t_rest, t_rest + W]`
//! and i = 1..3, so that `|r|^2` is the mean square of |dG| over the window (Eq. R1 of 2.1).
//! `r` is linear in the AMM's state, hence smooth in the variables.
//!
//! With the terms of `docs/motions.md` 4.10, `r` also holds the tips' rows (Eq. S2, weight
//! `w_t`) and the smoothness rows (Eq. S1, weight `w_s`), after the rows of G; the evaluation
//! records the usage of every limit (jerk included) and, for monotone progress, the progress
//! rows that must stay at or below zero.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use flexstar_kinematics::CheckedMotion;
use flexstar_metrics::residual::dg_magnitude;
use flexstar_model::{AmmSettings, Experiment, Problem, Response, Trajectory};

use crate::family::Family;
use crate::limits::{slider_samples, KinematicPeaks, Peak};
use crate::section::Limits;

/// A progress row may exceed zero by this much and still count as monotone (a backward rate of
/// 1e-6 of the mean rate `1/T`: the QP's own tolerance; `docs/motions.md` 4.10).
pub const PROGRESS_TOL: f64 = 1e-6;

/// The Jacobian's runs take this many times fewer steps than the evaluations that judge the
/// iterates (`docs/motions.md` 4.9, "The Jacobian's step").
pub const SLOPE_STEP_RATIO: f64 = 2.0;

/// What one evaluation gives.
#[derive(Debug, Clone)]
pub struct Eval {
    /// The residual vector (m): the `n_g` rows of G, then the tips' and the smoothness rows.
    pub r: Vec<f64>,
    /// How many rows of `r` are G's.
    pub n_g: usize,
    /// Peak |dG| [m] over the window.
    pub window_peak_m: f64,
    /// Peak |Fa_i| [N] over the run (the AMM's, Eq. 33).
    pub fa: Peak,
    /// Peaks of |s_i'| [m/s], |s_i''| [m/s^2] and |s_i'''| [m/s^3] over the move.
    pub v: Peak,
    pub a: Peak,
    pub j: Peak,
    /// The usage `u = g / g_max` of every sample of every given limit (4.4, 4.10): `|s_i'| /
    /// v_max`, `|s_i''| / a_max` and `|s_i'''| / j_max` at the kinematic samples, `|Fa_i| /
    /// Fa_max` at every output time; the same samples in every evaluation, so that the search can
    /// linearise them.
    pub usage: Vec<f64>,
    /// The progress rows (4.10), each at most zero for a monotone motion: `-T p'(t_k)` at the
    /// interior samples and `p(t_j) - p(t_j+1)` for consecutive knots (ends included). Empty when
    /// progress is free.
    pub progress: Vec<f64>,
    /// `s_i'''(t_k)` [m/s^3] at the kinematic samples (three per sample): the smoothness term's
    /// reference when this is the plain quintic.
    pub jerk: Vec<f64>,
}

impl Eval {
    /// `|r|`: the square root of the objective (4.10; with no tips' or smoothness rows, the RMS
    /// of |dG| over the window) [m].
    pub fn norm(&self) -> f64 {
        self.r.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// The RMS of |dG| over the window [m] (the rows of G alone).
    pub fn norm_g(&self) -> f64 {
        self.r[..self.n_g].iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// The kinematic peaks.
    pub fn kinematic(&self) -> KinematicPeaks {
        KinematicPeaks {
            v: self.v,
            a: self.a,
            j: self.j,
        }
    }

    /// The limits this evaluation breaks, by name (`v_max`, `a_max`, `j_max`, `Fa_max`).
    pub fn broken(&self, limits: &Limits) -> Vec<&'static str> {
        let mut out = Vec::new();
        for (name, peak, max) in [
            ("v_max", self.v, limits.v_max),
            ("a_max", self.a, limits.a_max),
            ("j_max", self.j, limits.j_max),
            ("Fa_max", self.fa, limits.fa_max),
        ] {
            if max.is_some_and(|m| peak.value > m) {
                out.push(name);
            }
        }
        out
    }

    /// Within `limits`, and monotone when the evaluation has progress rows (4.4, 4.10)?
    pub fn within(&self, limits: &Limits) -> bool {
        self.broken(limits).is_empty() && self.progress.iter().all(|&p| p <= PROGRESS_TOL)
    }
}

/// The smoothness term's reference (`docs/motions.md` 4.10, Eq. S1): the plain quintic's slider
/// jerk at the kinematic samples and the scale `sqrt(w_s) r_floor / |j_q|` of the rows
/// `scale (s_i'''(t_k) - j_q,ik)`.
#[derive(Debug, Clone)]
pub struct SmoothRef {
    pub jerk: Vec<f64>,
    pub scale: f64,
}

impl SmoothRef {
    /// The reference of weight `w_s` from the plain quintic's evaluation and the search's floor
    /// `r_floor` [m]; `None` when the weight is zero.
    pub fn new(plain: &Eval, weight: f64, r_floor: f64) -> Option<Self> {
        let norm = plain.jerk.iter().map(|x| x * x).sum::<f64>().sqrt();
        (weight > 0.0 && norm > 0.0).then(|| SmoothRef {
            jerk: plain.jerk.clone(),
            scale: weight.sqrt() * r_floor / norm,
        })
    }
}

/// The terms beyond G's residual (`docs/motions.md` 4.10).
#[derive(Debug, Clone, Default)]
pub struct Terms {
    /// Weight `w_t` of the tips' rows (Eq. S2).
    pub tip_weight: f64,
    /// The smoothness rows' reference (Eq. S1).
    pub smooth: Option<SmoothRef>,
    /// The family whose progress must be monotone (`None`: free).
    pub monotone: Option<Family>,
}

/// Why a candidate has no evaluation.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejected {
    /// The motion leaves the feasible workspace (time, reason).
    Infeasible(String),
    /// The solver failed or the model's range was left (small deflections).
    Solver(String),
}

impl std::fmt::Display for Rejected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rejected::Infeasible(s) => write!(f, "infeasible: {s}"),
            Rejected::Solver(s) => write!(f, "{s}"),
        }
    }
}

/// The evaluator: the experiment (robot, payload, damping, loads), the frozen AMM settings and
/// the residual window.
#[derive(Debug, Clone)]
pub struct Evaluator {
    exp: Experiment,
    settings: AmmSettings,
    /// Residual window W [s].
    pub window: f64,
    /// The limits whose usage the evaluations record.
    limits: Limits,
    /// The objective's terms beyond G (4.10).
    terms: Terms,
    /// AMM runs made by this evaluator and its copies (shared).
    runs: Arc<AtomicUsize>,
    /// The directions the tangent carried in those runs (shared).
    directions: Arc<AtomicUsize>,
}

impl Evaluator {
    /// An evaluator over `exp` with the accurate AMM at `modes` per beam (frozen) and the
    /// residual window `window` [s].
    pub fn new(exp: &Experiment, modes: usize, window: f64) -> Self {
        let settings = AmmSettings {
            modes: Some(modes),
            tol: None,
            snapshots: Vec::new(),
            frames: 0,
            ..exp.amm.clone()
        };
        let mut exp = exp.clone();
        exp.shaper = None;
        Evaluator {
            exp,
            settings,
            window,
            limits: Limits::default(),
            terms: Terms::default(),
            runs: Arc::new(AtomicUsize::new(0)),
            directions: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// The same evaluator recording the usage of `limits`.
    pub fn with_limits(&self, limits: Limits) -> Self {
        Evaluator { limits, ..self.clone() }
    }

    /// The evaluator of the search's Jacobian runs (`docs/motions.md` 4.9, "The Jacobian's
    /// step"): the same model at half as many steps per output interval (at least one), `None`
    /// when its step already spans the output interval.
    pub fn for_slopes(&self) -> Option<Evaluator> {
        let dt_out = self.exp.time.dt_out;
        let per_output = |h: f64| ((dt_out / h) - 1e-9).ceil().max(1.0);
        let fine = per_output(self.settings.dt.unwrap_or(flexstar_amm::DEFAULT_DT));
        let coarse = (fine / SLOPE_STEP_RATIO).ceil().max(1.0);
        (coarse < fine).then(|| {
            let mut ev = self.clone();
            ev.settings.dt = Some(dt_out / coarse);
            ev
        })
    }

    /// The same evaluator with the terms of 4.10.
    pub fn with_terms(&self, terms: Terms) -> Self {
        Evaluator { terms, ..self.clone() }
    }

    /// AMM runs made so far by this evaluator and every copy of it.
    pub fn runs(&self) -> usize {
        self.runs.load(Ordering::Relaxed)
    }

    /// The directions carried so far by the tangent in those runs
    /// ([`Evaluator::eval_with_tangents`]): each costs about 0.7 of a run (`docs/amm.md` 2.2).
    pub fn tangent_directions(&self) -> usize {
        self.directions.load(Ordering::Relaxed)
    }

    /// The AMM run of `traj` up to `t_end` [s] (feasibility checked first over that span).
    pub fn run(&self, traj: &Trajectory, t_end: f64) -> Result<Response, Rejected> {
        let (problem, checked) = self.checked(traj, t_end)?;
        self.runs.fetch_add(1, Ordering::Relaxed);
        let r = flexstar_amm::solve(
            &problem,
            &self.settings,
            flexstar_drive::SolveRequest::motion().with_proof(Some(&checked)),
        )
        .map(|s| s.response)
        .map_err(|e| Rejected::Solver(e.to_string()))?;
        self.small_deflections(r)
    }

    /// The problem of `traj` up to `t_end` [s] and the proof of its feasibility over that span.
    fn checked(&self, traj: &Trajectory, t_end: f64) -> Result<(Problem, CheckedMotion), Rejected> {
        let mut exp = self.exp.clone();
        exp.trajectory = traj.clone();
        exp.time.t_end = t_end;
        let step = flexstar_kinematics::preflight_step(exp.time.dt_out);
        let checked = flexstar_kinematics::check_motion(&exp.robot, traj, t_end, step)
            .map_err(|e| Rejected::Infeasible(format!("t = {:.4} s: {}", e.t, e.violation)))?;
        let problem = exp.problem().map_err(|e| Rejected::Infeasible(e.detail()))?;
        Ok((problem, checked))
    }

    /// `r`, refused outside the small-deflection range.
    fn small_deflections(&self, r: Response) -> Result<Response, Rejected> {
        match flexstar_metrics::small_deflection_check(&r, &self.exp.robot) {
            Some(v) => Err(Rejected::Solver(format!("outside the small-deflection range: {v}"))),
            None => Ok(r),
        }
    }

    /// Whether [`Evaluator::eval_with_tangents`] covers this evaluator: the tangent-linear AMM
    /// covers its experiment (`flexstar_amm::sensitivities_cover`: no friction or gravity).
    pub fn tangent_covers(&self) -> bool {
        self.exp
            .problem()
            .is_ok_and(|p| flexstar_amm::sensitivities_cover(&p, &self.settings).is_ok())
    }

    /// [`Evaluator::eval`] of `traj` and of each `moved[k] = (trajectory, h_k)` to first order
    /// in `h_k` (`docs/motions.md` 4.9, "The Jacobian from the tangent"): one AMM run of `traj`
    /// with the derivatives of its elastic outputs along each moved motion
    /// (`flexstar_amm::solve_with_sensitivities`, `docs/amm.md` 2.2), and each moved motion's
    /// evaluation from that run's outputs moved by `h_k` times their derivatives, its kinematic
    /// rows (usage, progress, smoothness) from its own trajectory. The moved evaluations' rows of
    /// G and the tips, and their forces, are then the base's plus `h_k` times their derivatives
    /// ([`Evaluator::tangent_covers`] says where this applies).
    pub fn eval_with_tangents(
        &self,
        traj: &Trajectory,
        moved: &[(Trajectory, f64)],
        t_rest: f64,
        knots: &[f64],
    ) -> Result<(Eval, Vec<Eval>), Rejected> {
        let t_end = t_rest + self.window;
        let (problem, _) = self.checked(traj, t_end)?;
        let problems: Vec<Problem> = moved
            .iter()
            .map(|(m, _)| self.checked(m, t_end).map(|(p, _)| p))
            .collect::<Result<_, _>>()?;
        let steps: Vec<f64> = moved.iter().map(|(_, h)| *h).collect();
        self.runs.fetch_add(1, Ordering::Relaxed);
        self.directions.fetch_add(moved.len(), Ordering::Relaxed);
        let sens = flexstar_amm::solve_with_sensitivities(&problem, &self.settings, &problems, &steps)
            .map_err(|e| Rejected::Solver(e.to_string()))?;
        let resp = self.small_deflections(sens.response)?;
        let base = self.assess(&resp, traj, t_rest, knots)?;
        let evals = moved
            .iter()
            .enumerate()
            .map(|(k, (m, h))| {
                let mut linear = resp.clone();
                for i in 0..3 {
                    let along = |w: &mut Vec<f64>, d: &[f64]| w.iter_mut().zip(d).for_each(|(w, d)| *w += h * d);
                    along(&mut linear.w_g[i], &sens.w_g[k][i]);
                    along(&mut linear.w_tip[i], &sens.w_tip[k][i]);
                    along(&mut linear.fa[i], &sens.fa[k][i]);
                }
                self.assess(&linear, m, t_rest, knots)
            })
            .collect::<Result<_, _>>()?;
        Ok((base, evals))
    }

    /// Evaluate a motion that rests from `t_rest` [s]: the run over the move and the window,
    /// the residual vector, the peaks (`knots`: extra sample times of the kinematic peaks).
    pub fn eval(&self, traj: &Trajectory, t_rest: f64, knots: &[f64]) -> Result<Eval, Rejected> {
        let resp = self.run(traj, t_rest + self.window)?;
        self.assess(&resp, traj, t_rest, knots)
    }

    /// [`Evaluator::eval`] of a run already made: `resp`, the AMM run of `traj` by an evaluator
    /// with the same experiment, N, step and window (the limits and terms may differ).
    pub fn assess(&self, resp: &Response, traj: &Trajectory, t_rest: f64, knots: &[f64]) -> Result<Eval, Rejected> {
        let t0 = traj.t_start();
        let jets = slider_samples(&self.exp.robot, traj, (t0, t_rest), self.exp.time.dt_out, knots)
            .map_err(|e| Rejected::Infeasible(e.to_string()))?;
        let KinematicPeaks { v, a, j } = crate::limits::peaks_of(&jets);
        let jerk: Vec<f64> = jets.iter().flat_map(|(_, j)| j.map(|j| j.d3)).collect();
        let mut r = residual_vector(resp, t_rest);
        let n_g = r.len();
        if self.terms.tip_weight > 0.0 {
            r.extend(tip_vector(resp, t_rest, self.terms.tip_weight));
        }
        if let Some(s) = &self.terms.smooth {
            r.extend(jerk.iter().zip(&s.jerk).map(|(j, q)| s.scale * (j - q)));
        }
        let progress = match &self.terms.monotone {
            Some(family) => progress_rows(family, traj, (t0, t_rest), &jets, knots)?,
            None => Vec::new(),
        };
        Ok(Eval {
            r,
            n_g,
            window_peak_m: window_peak(resp, t_rest),
            fa: force_peak(resp),
            v,
            a,
            j,
            usage: self.usage(&jets, resp),
            progress,
            jerk,
        })
    }

    /// The samples of [`Eval::usage`].
    fn usage(&self, jets: &[(f64, [flexstar_model::trajectory::Jet4; 3])], resp: &Response) -> Vec<f64> {
        let mut usage = Vec::new();
        if let Some(v) = self.limits.v_max {
            usage.extend(jets.iter().flat_map(|(_, j)| j.iter().map(move |j| j.d1.abs() / v)));
        }
        if let Some(a) = self.limits.a_max {
            usage.extend(jets.iter().flat_map(|(_, j)| j.iter().map(move |j| j.d2.abs() / a)));
        }
        if let Some(jm) = self.limits.j_max {
            usage.extend(jets.iter().flat_map(|(_, j)| j.iter().map(move |j| j.d3.abs() / jm)));
        }
        if let Some(f) = self.limits.fa_max {
            usage.extend(resp.fa.iter().flatten().map(|x| x.abs() / f));
        }
        usage
    }

    /// The experiment the evaluator runs (its trajectory is replaced per run).
    pub fn experiment(&self) -> &Experiment {
        &self.exp
    }
}

/// The output rows at or after `t_rest`.
fn after(resp: &Response, t_rest: f64) -> std::ops::Range<usize> {
    resp.t.partition_point(|&t| t < t_rest - 1e-12)..resp.t.len()
}

/// `sqrt(2/3) w_iG(t_k) / sqrt(n)` for the rows at or after `t_rest` (module docs), about the
/// static equilibrium of the rest pose under gravity (`Response::w_g_about_rest`).
pub fn residual_vector(resp: &Response, t_rest: f64) -> Vec<f64> {
    let rows = after(resp, t_rest);
    let scale = (2.0 / 3.0 / rows.len().max(1) as f64).sqrt();
    rows.flat_map(|k| (0..3).map(move |i| scale * resp.w_g_about_rest(i, k)))
        .collect()
}

/// The tips' rows (`docs/motions.md` 4.10, Eq. S2): `sqrt(w_t / 3) w_i(L, t_k) / sqrt(n)` for the
/// `n` rows at or after `t_rest` and i = 1..3, about the rest pose's static equilibrium, so that
/// their squared norm is `w_t` times the mean square over the window of the tips' RMS
/// `sqrt(1/3 sum_i w_i(L)^2)` (the measure of 2.2).
pub fn tip_vector(resp: &Response, t_rest: f64, weight: f64) -> Vec<f64> {
    let rows = after(resp, t_rest);
    let scale = (weight / 3.0 / rows.len().max(1) as f64).sqrt();
    let offset = resp.rest_offset.map_or([0.0; 3], |o| o.w_tip);
    rows.flat_map(|k| (0..3).map(move |i| scale * (resp.w_tip[i][k] - offset[i])))
        .collect()
}

/// The progress rows of [`Eval::progress`] (`docs/motions.md` 4.10): `-T p'(t)` at the samples
/// strictly inside the move (the rate vanishes at both ends whatever the variables), then
/// `p(t_j) - p(t_j+1)` over the knots with `p = 0` at the start and 1 at the end.
fn progress_rows(
    family: &Family,
    traj: &Trajectory,
    (t0, t1): (f64, f64),
    jets: &[(f64, [flexstar_model::trajectory::Jet4; 3])],
    knots: &[f64],
) -> Result<Vec<f64>, Rejected> {
    use num_dual::Dual64;
    let span = t1 - t0;
    let bad = |e: flexstar_model::ModelError| Rejected::Infeasible(e.to_string());
    let inside = |t: f64| t > t0 + 1e-6 * span && t < t1 - 1e-6 * span;
    let mut rows = Vec::new();
    for (t, _) in jets.iter().filter(|(t, _)| inside(*t)) {
        let q = traj.pose(Dual64::from_re(*t).derivative()).map_err(bad)?;
        let rate = q.map_or([0.0; 3], |q| q.map(|c| c.eps));
        rows.push(-span * family.progress_rate(rate));
    }
    let mut p = vec![0.0];
    for &t in knots.iter().filter(|t| inside(**t)) {
        let q = traj.pose(t).map_err(bad)?.unwrap_or([0.0; 3]);
        p.push(family.progress(q));
    }
    p.push(1.0);
    rows.extend(p.windows(2).map(|w| w[0] - w[1]));
    Ok(rows)
}

/// Peak |dG| [m] at or after `t_rest` (about the rest pose's static equilibrium under gravity).
pub fn window_peak(resp: &Response, t_rest: f64) -> f64 {
    after(resp, t_rest)
        .map(|k| dg_magnitude([0, 1, 2].map(|i| resp.w_g_about_rest(i, k))))
        .fold(0.0, f64::max)
}

/// Peak |Fa_i| [N] over the whole run (the move and the window after it).
pub fn force_peak(resp: &Response) -> Peak {
    let mut best = Peak {
        value: 0.0,
        slider: 1,
        t: 0.0,
    };
    for (k, &t) in resp.t.iter().enumerate() {
        for i in 0..3 {
            let v = resp.fa[i][k].abs();
            if v > best.value {
                best = Peak {
                    value: v,
                    slider: i + 1,
                    t,
                };
            }
        }
    }
    best
}

/// A test's evaluation with residuals `r` (all on G) and no peaks, usage or progress.
#[cfg(test)]
pub(crate) fn eval_of(r: Vec<f64>) -> Eval {
    let p = crate::limits::Peak {
        value: 0.0,
        slider: 1,
        t: 0.0,
    };
    Eval {
        n_g: r.len(),
        r,
        window_peak_m: 0.0,
        fa: p,
        v: p,
        a: p,
        j: p,
        usage: Vec::new(),
        progress: Vec::new(),
        jerk: Vec::new(),
    }
}
