//! One evaluation of a candidate motion (`docs/motions.md` 4.3 as amended): the accurate AMM,
//! its N frozen, run over the move and a residual window of `W` seconds after `t_rest`; the
//! residual vector `r` holds the elastic displacement of G over the window,
//! `r = sqrt(2/3) w_iG(t_k) / sqrt(n)` for the `n` output times `t_k` in `[t_rest, t_rest + W]`
//! and i = 1..3, so that `|r|^2` is the mean square of |dG| over the window (Eq. R1 of 2.1).
//! `r` is linear in the AMM's state, hence smooth in the variables.

use flexstar_metrics::residual::dg_magnitude;
use flexstar_model::{AmmSettings, Experiment, Response, Trajectory};

use crate::limits::{slider_samples, Peak};
use crate::section::Limits;

/// What one evaluation gives.
#[derive(Debug, Clone)]
pub struct Eval {
    /// The residual vector (m).
    pub r: Vec<f64>,
    /// Peak |dG| [m] over the window.
    pub window_peak_m: f64,
    /// Peak |Fa_i| [N] over the run (the AMM's, Eq. 33).
    pub fa: Peak,
    /// Peaks of |s_i'| [m/s] and |s_i''| [m/s^2] over the move.
    pub v: Peak,
    pub a: Peak,
    /// The usage `u = g / g_max` of every sample of every given limit (4.4): `|s_i'| / v_max`
    /// and `|s_i''| / a_max` at the kinematic samples, `|Fa_i| / Fa_max` at every output time;
    /// the same samples in every evaluation, so that the search can linearise them.
    pub usage: Vec<f64>,
}

impl Eval {
    /// `|r|`: the RMS of |dG| over the window [m].
    pub fn norm(&self) -> f64 {
        self.r.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// The limits this evaluation breaks, by name (`v_max`, `a_max`, `Fa_max`).
    pub fn broken(&self, limits: &Limits) -> Vec<&'static str> {
        let mut out = Vec::new();
        for (name, peak, max) in [
            ("v_max", self.v, limits.v_max),
            ("a_max", self.a, limits.a_max),
            ("Fa_max", self.fa, limits.fa_max),
        ] {
            if max.is_some_and(|m| peak.value > m) {
                out.push(name);
            }
        }
        out
    }
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
        }
    }

    /// The same evaluator recording the usage of `limits`.
    pub fn with_limits(&self, limits: Limits) -> Self {
        Evaluator { limits, ..self.clone() }
    }

    /// The AMM run of `traj` up to `t_end` [s] (feasibility checked first over that span).
    pub fn run(&self, traj: &Trajectory, t_end: f64) -> Result<Response, Rejected> {
        let mut exp = self.exp.clone();
        exp.trajectory = traj.clone();
        exp.time.t_end = t_end;
        let step = flexstar_kinematics::preflight_step(exp.time.dt_out);
        let checked = flexstar_kinematics::check_motion(&exp.robot, traj, t_end, step)
            .map_err(|e| Rejected::Infeasible(format!("t = {:.4} s: {}", e.t, e.violation)))?;
        let problem = exp.problem().map_err(|e| Rejected::Infeasible(e.detail()))?;
        let r = flexstar_amm::solve(
            &problem,
            &self.settings,
            flexstar_drive::SolveRequest::motion().with_proof(Some(&checked)),
        )
        .map(|s| s.response)
        .map_err(|e| Rejected::Solver(e.to_string()))?;
        if let Some(v) = flexstar_metrics::small_deflection_check(&r, exp.robot.l) {
            return Err(Rejected::Solver(format!("outside the small-deflection range: {v}")));
        }
        Ok(r)
    }

    /// Evaluate a motion that rests from `t_rest` [s]: the run over the move and the window,
    /// the residual vector, the peaks (`knots`: extra sample times of the kinematic peaks).
    pub fn eval(&self, traj: &Trajectory, t_rest: f64, knots: &[f64]) -> Result<Eval, Rejected> {
        let resp = self.run(traj, t_rest + self.window)?;
        let t0 = traj.t_start();
        let jets = slider_samples(&self.exp.robot, traj, (t0, t_rest), self.exp.time.dt_out, knots)
            .map_err(|e| Rejected::Infeasible(e.to_string()))?;
        let (v, a) = crate::limits::peaks_of(&jets);
        Ok(Eval {
            r: residual_vector(&resp, t_rest),
            window_peak_m: window_peak(&resp, t_rest),
            fa: force_peak(&resp),
            v,
            a,
            usage: self.usage(&jets, &resp),
        })
    }

    /// The samples of [`Eval::usage`].
    fn usage(&self, jets: &[(f64, [flexstar_model::trajectory::Jet; 3])], resp: &Response) -> Vec<f64> {
        let mut usage = Vec::new();
        if let Some(v) = self.limits.v_max {
            usage.extend(jets.iter().flat_map(|(_, j)| j.iter().map(move |j| j.d1.abs() / v)));
        }
        if let Some(a) = self.limits.a_max {
            usage.extend(jets.iter().flat_map(|(_, j)| j.iter().map(move |j| j.d2.abs() / a)));
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
