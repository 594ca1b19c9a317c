//! Time integration of the constrained AMM system and its outputs (paper section 7; `docs/amm.md` section 2).
//!
//! ```text
//! M q'' + D(t) q' + K(t) q = f(t) + C(t)^T lambda,   C(t) q = 0,   q(0) = q'(0) = 0
//! ```
//! is integrated by the index-3 generalized-alpha method (Chung & Hulbert 1993; Arnold & Bruls
//! 2007) with the constraint rows scaled by 1/beta' (so the step matrix stays well conditioned as
//! h -> 0) and the position-level constraints `C(t_n+1) q_n+1 = 0` imposed at every step (no
//! drift). The system is linear, so each step is one linear solve (see the private `system` module and `docs/amm.md`).
//! Initial accelerations are consistent: `M q''(0) = f(0) + C^T lambda(0)`, `C q''(0) = 0`.

use flexstar_drive::{Drive, SolveRequest, Solved};
use flexstar_kinematics::{preflight_step, CheckedMotion, RigidState};
use flexstar_model::animation::{frame_times, ShapeTimes};
use flexstar_model::config::check_step;
#[cfg(test)]
use flexstar_model::Experiment;
use flexstar_model::{AmmSettings, DriveKind, ModeCount, ModeFamily, Problem, Response, RunInfo};
use flexstar_numerics::GenAlpha;
use num_dual::Dual2;

use crate::adaptive::{self, Pass};
use crate::error::AmmError;
use crate::events::{EventStepper, State};
use crate::modes::{ModeSet, MAX_MODES};
use crate::record::Recorder;
use crate::star::Star;
use crate::stick_slip::{self, FrictionOutput, StepEnd};
use crate::system::System;
use flexstar_model::Friction;

/// Default integration step [s], 1/6 ms (six steps per default output interval), from the
/// convergence study in `docs/amm.md`: halving it changes every tip and junction response of the
/// paper's four cases by an EVP below 0.1 % (largest 0.090 %) for every family at N = 25, 50, 100.
pub const DEFAULT_DT: f64 = 1.0e-3 / 6.0;

/// Default step [s] of the accurate model (automatic N at the default tolerance of 0.5 %): the
/// FEM's default step. There the time error of the enriched full model at N = 53, EVP(h, h/2)
/// mean over A, B, C, G, is 0.06-0.13 % on the paper's four cases (at most 0.25 % at a point), a
/// quarter of the tolerance; `docs/amm.md` section 9.
pub const TOLERANCE_DT: f64 = 5.0e-4;

/// Default step [s] when N follows a tolerance `tol` [%]: the time error is second order, so the
/// step scales with the square root of the tolerance to keep the time error at about a quarter
/// of it: `TOLERANCE_DT * sqrt(tol / 0.5)`, at most [`TOLERANCE_DT`] x 2 (1 ms).
pub fn tolerance_step(tol: f64) -> f64 {
    (TOLERANCE_DT * (tol / flexstar_model::config::DEFAULT_TOL_PERCENT).sqrt()).min(2.0 * TOLERANCE_DT)
}

/// The beams' time scale `L^2 sqrt(rho / EI)` [s]: the period of every bending mode is
/// `2 pi / (beta L)^2` times it (`docs/amm.md` 12.4).
pub fn beam_time_scale(robot: &flexstar_model::RobotParams) -> f64 {
    robot.l * robot.l * (robot.rho / robot.ei()).sqrt()
}

/// `docs/amm.md` 12.4: the tolerance step on a robot whose beams are faster than the
/// paper's scales with their time scale ([`beam_time_scale`]), so that its time error stays what
/// [`TOLERANCE_DT`] gives on the paper's robot: the factor `min(1, T / T_paper)`; exactly 1 for
/// the paper's robot and for slower beams.
pub fn robot_step_factor(robot: &flexstar_model::RobotParams) -> f64 {
    (beam_time_scale(robot) / beam_time_scale(&flexstar_model::RobotParams::paper())).min(1.0)
}

/// The fastest beam's time scale [s] (`docs/amm.md` 13, Eq. J8): [`beam_time_scale`] of the beam
/// whose is the smallest.
pub(crate) fn star_time_scale(problem: &Star) -> f64 {
    let [a, b, c] = problem.beams.map(|p| beam_time_scale(&p));
    a.min(b).min(c)
}

/// [`robot_step_factor`] of the fastest beam (`docs/amm.md` 13, Eq. J8).
pub(crate) fn star_step_factor(problem: &Star) -> f64 {
    let [a, b, c] = problem.beams.map(|p| robot_step_factor(&p));
    a.min(b).min(c)
}

/// Spectral radius at infinity of the generalized-alpha scheme: mild damping of the unresolved
/// high modes and of the multiplier oscillations of index-3 schemes (`docs/amm.md`).
pub const RHO_INF: f64 = 0.8;

/// Points per beam in the deformed-star snapshots (x = 0, L/100, ..., L).
pub const SHAPE_POINTS: usize = 101;

/// Parse a mode-family name (`pinned-free`, `slide-free`, `free-free`, `clamped-free`).
pub fn parse_family(name: &str) -> Result<ModeFamily, AmmError> {
    name.parse::<ModeFamily>()
        .map_err(|_| AmmError::UnknownFamily(name.to_string()))
}

/// Names of the extra output columns, in order (after the fixed `RESPONSE_HEADER`).
/// `dGx, dGy` [m, fixed frame] are the elastic displacement of G, `2/3 sum_i w_iG e_wi`
/// (`docs/motions.md` 2.1; [`flexstar_metrics::residual::dg_vector`]), as the FEM writes it; on
/// a robot as built `(sum e_wi e_wi^T)^-1 sum w_iG e_wi` (`docs/amm.md` 13, Eq. J7). `Fw` is the
/// multiplier of Eq. 40 (Eq. J5 on a robot as built, where beam i receives the shear `c_i Fw`).
pub const EXTRA_COLUMNS: [&str; 27] = [
    "Fix1", "Fix2", "Fix3", "M1G", "M2G", "M3G", "Fw", "Fp1", "Fp2", "Fp3", "FLp1", "FLp2", "FLp3", "FRp1", "FRp2",
    "FRp3", "Mp1", "Mp2", "Mp3", "thp1", "thp2", "thp3", "u1", "u2", "u3", "dGx", "dGy",
];

/// Check the settings against the problem (validated when it was built) before any work; returns
/// the step ceiling [s].
/// `scan`: check the trajectory's feasibility over the whole span (an inverse run, or a servo's
/// reference); otherwise only its start configuration (a forces-driven run).
pub(crate) fn validate(problem: &Star, settings: &AmmSettings, modes: usize, scan: bool) -> Result<f64, AmmError> {
    settings.validate(problem.time.dt_out).map_err(|e| match e {
        flexstar_model::ModelError::Invalid { key, reason, .. } => AmmError::invalid(key, reason),
        other => other.into(),
    })?;
    if modes == 0 || modes > MAX_MODES {
        return Err(AmmError::invalid(
            "amm.modes",
            format!("need 1 <= modes <= {MAX_MODES}, got {modes}"),
        ));
    }
    if let Some(i) = (0..3).find(|&i| problem.beam(i).jp <= 0.0) {
        return Err(AmmError::invalid(
            if problem.paper.is_some() {
                "robot.Jp".to_string()
            } else {
                format!("robot.Jp[{}]", i + 1)
            },
            format!(
                "the AMM needs a sleeve with rotational inertia (Eq. 31): Jp > 0, got {}",
                problem.beam(i).jp
            ),
        ));
    }
    let dt = match settings.dt {
        Some(dt) => {
            check_step("amm.dt", dt, problem.time.dt_out)?;
            dt
        }
        None => match settings.mode_count() {
            ModeCount::Tolerance(tol) => tolerance_step(tol) * star_step_factor(problem),
            ModeCount::Fixed(_) => DEFAULT_DT,
        }
        .min(problem.time.dt_out),
    };
    if problem.time.t_end / dt > 1e8 {
        return Err(AmmError::invalid(
            "amm.dt",
            format!("more than 1e8 steps ({} s / {dt} s)", problem.time.t_end),
        ));
    }
    if let Some(bad) = settings
        .snapshots
        .iter()
        .find(|t| !t.is_finite() || **t < 0.0 || **t > problem.time.t_end)
    {
        return Err(AmmError::invalid(
            "amm.snapshots",
            format!(
                "snapshot times must lie in [0, t_end = {}], got {bad}",
                problem.time.t_end
            ),
        ));
    }
    flexstar_model::animation::check_frames("amm.frames", settings.frames, problem.time.t_end).map_err(
        |e| match e {
            flexstar_model::ModelError::Invalid { key, reason, .. } => AmmError::invalid(key, reason),
            other => other.into(),
        },
    )?;
    if scan {
        problem.check_trajectory(preflight_step(problem.time.dt_out))?;
    } else {
        let s0 = problem.s_at(0.0)?;
        problem.check_start(s0, 0.0)?;
    }
    Ok(dt)
}

/// A time at which the integration stops: an output row and/or a snapshot.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stop {
    pub(crate) t: f64,
    pub(crate) output: Option<usize>,
    pub(crate) snapshot: Option<usize>,
}

pub(crate) fn stops(out_times: &[f64], snaps: &[f64], tol: f64) -> Vec<Stop> {
    let mut v: Vec<Stop> = out_times
        .iter()
        .enumerate()
        .map(|(k, &t)| Stop {
            t,
            output: Some(k),
            snapshot: None,
        })
        .collect();
    for (s, &ts) in snaps.iter().enumerate() {
        match v.iter_mut().find(|st| (st.t - ts).abs() <= tol) {
            Some(st) => st.snapshot = Some(s),
            None => v.push(Stop {
                t: ts,
                output: None,
                snapshot: Some(s),
            }),
        }
    }
    v.sort_by(|a, b| a.t.total_cmp(&b.t));
    v
}

/// Solve the paper's constrained assumed-modes model (Eqs. 30-44) for one experiment: the one
/// entry point of the AMM, for both drives of `request` (`flexstar_drive::SolveRequest`).
///
/// The robot may be the paper's or one as built (`docs/amm.md` 13, Eqs. J1-J8): unequal beams
/// (each its own mode set of the family and N, and its own block of the step), other weld angles
/// (the junction rows of Eqs. J4-J5) and an uneven base (the rails of Eq. J7); the paper's robot
/// runs exactly as the equal-beam model did.
///
/// `settings` are the `[amm]` settings after command-line overrides (`problem.amm` is not read).
/// `request.proof`: the trajectory is scanned for feasibility only when the preflight's proof does
/// not cover this experiment's robot, trajectory and span. `request.progress` is called once, with
/// 1, when the solve has finished.
///
/// The prescribed motion ([`Drive::Motion`], the inverse problem) returns the response at `problem.time.output_times()`, labelled `amm-<family>`: `w_iG = w_i(0)`,
/// tip `w_i(L)` (rigid beam frames, `docs/conventions.md`) [m], `Fa_i` (Eq. 33) [N], then the
/// columns [`EXTRA_COLUMNS`]: every multiplier (Fix [N], MiG [N m], Fw, Fp, FLp, FRp [N],
/// Mp [N m]), the sleeve rotations thp_i [rad] and the axial displacements u_i [m]; and the
/// deformed star at `settings.snapshots` and t_end. Multipliers of rows dropped for the family
/// (pinned-free: Fw; slide-free: MiG; clamped-free: both) are reported as 0.
///
/// Every input error (modes, step, snapshots, Jp, an infeasible trajectory) is returned before
/// any integration.
///
/// N is `settings.modes` when given; otherwise (`tol`, or the enriched family's default tolerance)
/// it is raised until the estimated truncation EVP is below the tolerance (`adaptive` module),
/// and `info.modes` / `info.error_estimate_percent` report the N used and the estimate.
///
/// An actuator law ([`Drive::Law`], the direct problem) returns the response described in
/// [`crate::direct`] (labelled `amm-<family>-direct`).
pub fn solve(problem: &Problem, settings: &AmmSettings, request: SolveRequest) -> Result<Solved<Stats>, AmmError> {
    let problem = &Star::new(problem);
    let covered = request.proof.is_some_and(|c| covers(c, problem));
    let (response, stats) = match request.drive {
        Drive::Motion => solve_scanned(problem, settings, !covered)?,
        Drive::Law(law) => {
            // the direct problem scans a servo's reference (its motion), else the start only
            let scan = problem.drive.kind == DriveKind::Servo && !covered;
            crate::direct::solve_direct_scanned(problem, settings, law, scan)?
        }
    };
    if let Some(progress) = request.progress {
        progress(1.0);
    }
    Ok(Solved { response, stats })
}

/// [`solve`] of the prescribed motion ([`Drive::Motion`]) at the fixed N of `settings.modes`,
/// with `after_step(k)` called after every time step, k = 1, 2, ... (the step's solve done, its
/// state accepted; output rows are recorded between the calls): a hook to measure a step's cost
/// (its time, its heap allocations) from outside the crate. The response is [`solve`]'s, bit for
/// bit. An automatic N (`settings.modes` unset) is refused: its runs would restart the count.
pub fn solve_stepwise(
    problem: &Problem,
    settings: &AmmSettings,
    mut after_step: impl FnMut(usize),
) -> Result<Response, AmmError> {
    let ModeCount::Fixed(n) = settings.mode_count() else {
        return Err(AmmError::invalid(
            "amm.modes",
            "a stepwise run needs a fixed N (amm.modes)".to_string(),
        ));
    };
    let mut k = 0;
    integrate(&Star::new(problem), settings, n, true, |_, _| {
        k += 1;
        after_step(k);
    })
}

/// Work counters of an AMM run ([`solve`]). Every integration run solves the
/// constrained system once for the initial accelerations and once per time step, each solve one
/// factorisation of the step matrix (the constraints move with t) and one substitution.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Stats {
    /// Modes per beam N of the delivered run.
    pub modes: usize,
    /// N of every integration run, in the order run: for the automatic N the estimate's runs
    /// (at the coarse step, or the delivered one), the time check's run at 2 h and the delivered
    /// run, last but on a span too short for the coarse grid, where the time check follows it
    /// (`adaptive` module); one entry for a fixed N.
    pub modes_tried: Vec<usize>,
    /// Time steps of the delivered run.
    pub steps: usize,
    /// Time steps of all runs.
    pub total_steps: usize,
    /// Linear solves (= factorisations of the step matrix) of all runs: `total_steps` plus one
    /// per run.
    pub solves: usize,
}

impl Stats {
    /// The counters of the runs `(N, steps)` in the order run, the delivered one last.
    pub(crate) fn from_runs(runs: &[(usize, usize)]) -> Self {
        Self::delivering(runs, runs.len().saturating_sub(1))
    }

    /// The counters of the runs `(N, steps)` in the order run, `runs[delivered]` the delivered one.
    pub(crate) fn delivering(runs: &[(usize, usize)], delivered: usize) -> Self {
        let total_steps = runs.iter().map(|r| r.1).sum();
        let (modes, steps) = runs.get(delivered).copied().unwrap_or_default();
        Stats {
            modes,
            modes_tried: runs.iter().map(|r| r.0).collect(),
            steps,
            total_steps,
            solves: total_steps + runs.len(),
        }
    }
}

/// Does `checked` cover the scan a run of `problem` would make?
pub(crate) fn covers(checked: &CheckedMotion, problem: &Star) -> bool {
    problem.covered_by(checked, preflight_step(problem.time.dt_out))
}

/// [`solve`] of the prescribed motion; `scan`: check the trajectory's feasibility over the whole span first.
fn solve_scanned(problem: &Star, settings: &AmmSettings, scan: bool) -> Result<(Response, Stats), AmmError> {
    let mut runs = Vec::new();
    let (resp, delivered) = match settings.mode_count() {
        ModeCount::Fixed(n) => {
            let mut steps = 0;
            let r = integrate(problem, settings, n, scan, |_, _| steps += 1)?;
            runs.push((n, steps));
            (r, 0)
        }
        ModeCount::Tolerance(tol) => solve_to_tolerance(problem, settings, tol, scan, &mut runs)?,
    };
    Ok((resp, Stats::delivering(&runs, delivered)))
}

/// [`solve`] with N chosen for the tolerance `tol` [%] (`adaptive` module): the estimate's pairs
/// at the coarse step on the coarse output grid, the chosen N at the delivered step `h`. The
/// system of the last N is built once and reused by its runs at both steps. `runs` receives
/// `(N, steps)` of every integration run, in order; returns the delivered run and its index in
/// `runs` (the last run at the delivered step: the time check may follow it, `adaptive` module).
fn solve_to_tolerance(
    problem: &Star,
    settings: &AmmSettings,
    tol: f64,
    scan: bool,
    runs: &mut Vec<(usize, usize)>,
) -> Result<(Response, usize), AmmError> {
    // every input error before any work, at the first N; the trajectory is scanned once here
    // (unless the caller has)
    let h = validate(problem, settings, adaptive::first_modes_of(problem), scan)?;
    let every = adaptive::estimate_grid_of(problem, h);
    let check_every = adaptive::time_check_grid_of(problem, h);
    let mut built: Option<(usize, System)> = None;
    let mut delivered = 0;
    let response = adaptive::solve_to_tolerance(problem, tol, every, Some(check_every), |n, pass| {
        let started = std::time::Instant::now();
        let mut steps = 0;
        let resp = match pass {
            // the robot without friction (docs/amm.md 12.16): its own system, not kept for N
            Pass::BareEstimate { .. } => {
                let bare = problem.without_friction();
                let sys = build_system(settings, n, &bare)?;
                run_pass(&bare, settings, sys, (h, pass), started, &mut steps)
            }
            _ => {
                let sys = match &built {
                    Some((m, sys)) if *m == n => sys.clone(),
                    _ => {
                        validate(problem, settings, n, false)?;
                        let sys = build_system(settings, n, problem)?;
                        built = Some((n, sys.clone()));
                        sys
                    }
                };
                run_pass(problem, settings, sys, (h, pass), started, &mut steps)
            }
        };
        if matches!(pass, Pass::Deliver | Pass::Refined { .. }) {
            delivered = runs.len();
        }
        runs.push((n, steps));
        resp
    })?;
    Ok((response, delivered))
}

/// One run of the automatic choice on the system `sys` of `problem` at the step of `pass`, the
/// delivered step being `h` [s]; `steps` counts its steps. For [`Pass::BareEstimate`] the caller
/// passes the robot without friction and its system.
fn run_pass(
    problem: &Star,
    settings: &AmmSettings,
    sys: System,
    (h, pass): (f64, Pass),
    started: std::time::Instant,
    steps: &mut usize,
) -> Result<Response, AmmError> {
    let count = |_: &System, _: &[f64]| *steps += 1;
    match pass {
        Pass::Deliver => integrate_system(problem, settings, sys, h, started, count),
        Pass::Refined { halvings } => {
            let step = h / f64::from(1u32 << halvings);
            let refined = AmmSettings {
                dt: Some(step),
                ..settings.clone()
            };
            integrate_system(problem, &refined, sys, step, started, count)
        }
        Pass::Estimate { every } | Pass::BareEstimate { every } => {
            let factor = adaptive::ESTIMATE_STEP_FACTOR;
            integrate_coarse(problem, settings, sys, h, factor, every, started, count)
        }
        Pass::TimeCheck { every } => {
            let factor = adaptive::TIME_CHECK_STEP_FACTOR;
            integrate_coarse(problem, settings, sys, h, factor, every, started, count)
        }
    }
}

/// A run of the automatic choice at `factor` times the delivered step `h` [s] (at most the
/// coarse output interval), output on a grid `every` times `problem.time.dt_out` (the estimate's or
/// the time check's), no snapshots or frames.
#[allow(clippy::too_many_arguments)]
fn integrate_coarse<F: FnMut(&System, &[f64])>(
    problem: &Star,
    settings: &AmmSettings,
    sys: System,
    h: f64,
    factor: f64,
    every: usize,
    started: std::time::Instant,
    observe: F,
) -> Result<Response, AmmError> {
    let mut coarse = *problem;
    coarse.time.dt_out = every as f64 * problem.time.dt_out;
    let step = (factor * h).min(coarse.time.dt_out);
    let pair_settings = AmmSettings {
        dt: Some(step),
        snapshots: Vec::new(),
        frames: 0,
        ..settings.clone()
    };
    integrate_system(&coarse, &pair_settings, sys, step, started, observe)
}

/// The constrained system of N = `n_modes` modes of `settings.family` for the robot of `problem`,
/// with its payload, damping and load (`docs/amm.md` section 11; nothing added at their defaults).
/// Each beam gets its own mode set of the family and N (`docs/amm.md` 13, Eq. J1); equal beams
/// share one.
pub(crate) fn build_system(settings: &AmmSettings, n_modes: usize, problem: &Star) -> Result<System, AmmError> {
    let key = crate::system_cache::SystemKey {
        family: settings.family,
        n_modes,
        mode_params: problem.mode_params().to_vec(),
        beams: problem.beams,
        weld: problem.weld,
        model: settings.model,
    };
    let mut sys = crate::system_cache::system(key, || {
        let modes = (problem.mode_params().iter())
            .map(|p| ModeSet::new(settings.family, n_modes, p))
            .collect::<Result<Vec<_>, _>>()?;
        Ok::<_, AmmError>(System::new(modes, &problem.beams, &problem.weld, settings.model))
    })?;
    if let Some(law) = problem.friction.filter(|f| f.sleeves_rub()) {
        sys.attach_friction(*law, &problem.beams, &problem.weld);
    }
    sys.attach(problem.payload, problem.damping, problem.load, problem.gravity);
    Ok(sys)
}

/// [`solve`] at N = `n_modes` with an observer called after every step with the system and the
/// coordinates q; `scan`: check the trajectory's feasibility over the whole span first (off when
/// the caller has, as the automatic N does once for all its runs).
pub(crate) fn integrate<F: FnMut(&System, &[f64])>(
    problem: &Star,
    settings: &AmmSettings,
    n_modes: usize,
    scan: bool,
    observe: F,
) -> Result<Response, AmmError> {
    let started = std::time::Instant::now();
    let dt_max = validate(problem, settings, n_modes, scan)?;
    let sys = build_system(settings, n_modes, problem)?;
    integrate_system(problem, settings, sys, dt_max, started, observe)
}

/// The snapshot times of the shapes file: the requested ones and `t_end`, sorted, duplicates
/// (within 1e-9 of the output step) merged.
pub(crate) fn snapshot_times(problem: &Star, settings: &AmmSettings) -> Vec<f64> {
    let mut snaps: Vec<f64> = settings.snapshots.clone();
    snaps.push(problem.time.t_end);
    snaps.sort_by(|a, b| a.total_cmp(b));
    snaps.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * problem.time.dt_out);
    snaps
}

/// The times at which the deformed star is recorded: the snapshots ([`snapshot_times`]) and the
/// animation frames of `settings.frames` (`docs/motions.md` section 5), merged.
pub(crate) fn shape_times(problem: &Star, settings: &AmmSettings) -> ShapeTimes {
    let frames = frame_times(problem.time.t_end, settings.frames);
    ShapeTimes::merge(&snapshot_times(problem, settings), &frames, 1e-9 * problem.time.dt_out)
}

/// [`integrate`] with the system `sys` built (fresh, not yet stepped) and the inputs validated:
/// steps of at most `dt_max` [s]; the reported wall time counts from `started`.
pub(crate) fn integrate_system<O: StepObserver>(
    problem: &Star,
    settings: &AmmSettings,
    mut sys: System,
    dt_max: f64,
    started: std::time::Instant,
    mut observe: O,
) -> Result<Response, AmmError> {
    let n_modes = sys.nm;
    let (nm, n) = (sys.nm, sys.dim());

    let out_times = problem.time.output_times();
    let times = shape_times(problem, settings);
    let stops = stops(&out_times, &times.all, 1e-9 * problem.time.dt_out);
    let mut rec = Recorder::new(&sys, settings, problem, out_times.len(), times);
    let ga = GenAlpha::new(RHO_INF);
    sys.set_third_order_step(ga.beta_prime(dt_max));
    let (mut q, mut v, mut acc, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut qhat, mut vhat, mut a_part) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let kin = |t: f64| problem.state(t);
    // a sleeve's material coordinate at t with the star undeformed (its rigid position), for
    // telling a divergence from a sleeve that slides off (`AmmError::judge_off_beam`)
    let rigid_sleeve = |t: f64, i: usize| kin(t).ok().map(|st| st.xp[i].v);

    // the start: undeformed, or under gravity the static equilibrium of the start pose (Eq. G4)
    // at rest, the rigid velocities and accelerations zero (a motion may start accelerating, as a
    // polynomial one does: its initial inertia is not part of the sag it starts from, as in the
    // direct run's start and the FEM's); then consistent initial accelerations:
    // M qdd = f - K q + C^T lambda, C qdd = 0 (q' = 0)
    let mut st = kin(0.0)?;
    if problem.gravity != [0.0; 2] {
        let still = problem.state_from(st.s.map(|j| Dual2::new(j.v, 0.0, 0.0)), 0.0)?;
        crate::static_start::static_equilibrium(&mut sys, &still, star_time_scale(problem), &mut q)?;
    }
    let mut friction = None;
    let first = match problem.friction {
        None => sys.solve(&st, 0.0, 0.0, &q, &v, &mut qdd),
        Some(law) => {
            friction_start(&mut sys, &st, (&q, &v), &mut qdd, law, out_times.len()).map(|out| friction = Some(out))
        }
    };
    first.map_err(|e| match e {
        AmmError::SingularConstraints { t, source } => AmmError::TooFewModes {
            t,
            modes: nm,
            family: settings.family,
            source,
        },
        other => other,
    })?;
    acc.copy_from_slice(&qdd);
    let start = Step {
        st: &st,
        h: 0.0,
        bp: 0.0,
        gp: 0.0,
        q: &q,
        v: &v,
        predicted: friction.is_none().then_some((&q[..], &v[..])),
        qdd: &qdd,
        output: stops[0].output,
    };
    observe.step(&mut sys, &start);

    let record = |rec: &mut Recorder,
                  out: Option<&mut FrictionOutput>,
                  sys: &System,
                  st: &RigidState,
                  stop: &Stop,
                  (q, v, qdd): (&[f64], &[f64], &[f64])| {
        let out = out.zip(problem.friction);
        let fa = out.as_ref().map(|(_, law)| friction_fa(rec, sys, st, q, qdd, law));
        rec.record(st, stop, q, [v, qdd], &sys.lam, sys.sleeves.axial(), fa);
        if let (Some((out, _)), Some(_)) = (out, stop.output) {
            out.sample(sys, stick_slip::sleeve_forces(sys, qdd), stick_slip::speeds(sys, st, v));
        }
    };

    let mut events = friction.as_ref().map(|_| EventStepper::new(ga, n, sys.rows.len()));
    record(&mut rec, friction.as_mut(), &sys, &st, &stops[0], (&q, &v, &qdd));
    for w in stops.windows(2) {
        let (t0, t1) = (w[0].t, w[1].t);
        let nsub = (((t1 - t0) / dt_max) - 1e-9).ceil().max(1.0) as usize;
        let h = (t1 - t0) / nsub as f64;
        let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
        for k in 1..=nsub {
            let t = if k == nsub { t1 } else { t0 + k as f64 * h };
            if let (Some(out), Some(events)) = (friction.as_mut(), events.as_mut()) {
                // with friction: the stick and slip events located within the step (`events`)
                let mut x = State {
                    q: &mut q,
                    v: &mut v,
                    acc: &mut acc,
                    qdd: &mut qdd,
                };
                let rails = |st: &RigidState| problem.friction.map_or(0.0, |law| prescribed_rails_power(law, st));
                events
                    .step(&mut sys, &kin, (&mut st, t), &mut x, out, &rails)
                    .map_err(|e| e.judge_off_beam(h, rigid_sleeve))?;
                let step = Step {
                    st: &st,
                    h,
                    bp,
                    gp,
                    q: &q,
                    v: &v,
                    predicted: None,
                    qdd: &qdd,
                    output: if k == nsub { w[1].output } else { None },
                };
                observe.step(&mut sys, &step);
                continue;
            }
            let state = q.iter().zip(&v).zip(acc.iter().zip(&qdd));
            let predicted = a_part.iter_mut().zip(qhat.iter_mut()).zip(vhat.iter_mut());
            for (((ap, qh), vh), ((&qi, &vi), (&ai, &di))) in predicted.zip(state) {
                (*ap, *qh, *vh) = ga.predict(h, qi, vi, ai, di);
            }
            st = kin(t)?;
            let predicted = (&qhat[..], &vhat[..], &a_part[..]);
            sys.solve(&st, bp, gp, &qhat, &vhat, &mut qdd)
                .map_err(|e| e.judge_off_beam(h, rigid_sleeve))?;
            if !accept(&ga, (bp, gp), predicted, &qdd, (&mut q, &mut v, &mut acc)) {
                return Err(AmmError::NonFinite { t, dt: h });
            }
            let step = Step {
                st: &st,
                h,
                bp,
                gp,
                q: &q,
                v: &v,
                predicted: Some((&qhat, &vhat)),
                qdd: &qdd,
                output: if k == nsub { w[1].output } else { None },
            };
            observe.step(&mut sys, &step);
        }
        record(&mut rec, friction.as_mut(), &sys, &st, &w[1], (&q, &v, &qdd));
        if flexstar_model::cancel::cancelled() {
            return Err(AmmError::Cancelled { t: t1 });
        }
    }

    let mut resp = rec.finish(format!("amm-{}", settings.family.name()));
    if let Some(out) = friction {
        out.finish(&mut resp);
        sys.release_contacts();
    }
    resp.rest_offset = crate::static_start::rest_offset(&mut sys, problem, star_time_scale(problem))?;
    resp.info = run_info("amm", settings, n_modes, dt_max, started);
    Ok(resp)
}

/// What an observer of [`integrate_system`] sees after a step (and after the consistent start,
/// `h = 0`): its rigid state (its time `st.t` [s]), length h [s], `beta'` and `gamma'` of the generalized-alpha method, the
/// coordinates q and rates q' after it, the predictors `(qhat, vhat)` it was solved about (`None` with
/// friction, whose events split the step), its accelerations, and the response's row it ends on
/// (the output time the recorder records after it; `None` within an output interval).
pub(crate) struct Step<'a> {
    pub(crate) st: &'a RigidState,
    pub(crate) h: f64,
    pub(crate) bp: f64,
    pub(crate) gp: f64,
    pub(crate) q: &'a [f64],
    pub(crate) v: &'a [f64],
    pub(crate) predicted: Option<(&'a [f64], &'a [f64])>,
    pub(crate) qdd: &'a [f64],
    pub(crate) output: Option<usize>,
}

/// An observer of [`integrate_system`], called after the consistent start and after every step
/// with the system as the step left it (its factors, forcing and multipliers).
pub(crate) trait StepObserver {
    fn step(&mut self, sys: &mut System, step: &Step);
}

/// A closure observes the steps only (not the start), with the system and q.
impl<F: FnMut(&System, &[f64])> StepObserver for F {
    fn step(&mut self, sys: &mut System, step: &Step) {
        if step.h > 0.0 {
            self(sys, step.q)
        }
    }
}

/// Accept a step: `q = q^ + bp q''`, `q' = v^ + gp q''` and the generalized-alpha acceleration
/// variable from the predictors `(q^, v^, a^)` and the step's `q''`; whether q is finite.
pub(crate) fn accept(
    ga: &GenAlpha,
    (bp, gp): (f64, f64),
    (qhat, vhat, a_part): (&[f64], &[f64], &[f64]),
    qdd: &[f64],
    (q, v, acc): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    let apq = ga.a_per_qdd();
    let mut finite = true;
    let state = q.iter_mut().zip(v.iter_mut()).zip(acc.iter_mut());
    let parts = qhat.iter().zip(vhat).zip(a_part.iter().zip(qdd));
    for (((qi, vi), ai), ((&qh, &vh), (&ap, &di))) in state.zip(parts) {
        *qi = qh + bp * di;
        *vi = vh + gp * di;
        *ai = ap + apq * di;
        finite &= qi.is_finite();
    }
    finite
}

/// The consistent start of a prescribed motion with friction (`docs/friction.md` 9.1): the
/// sleeves at rest stuck, the moving ones slipping, the start solved again with the signs of
/// its own multipliers while a sleeve slips on a load, and a stuck sleeve that cannot hold
/// released (`stick_slip::switching_step`). Returns the friction's outputs from t = 0, with
/// room for `rows` output samples.
fn friction_start(
    sys: &mut System,
    st: &RigidState,
    (q, v): (&[f64], &[f64]),
    qdd: &mut [f64],
    law: &Friction,
    rows: usize,
) -> Result<FrictionOutput, AmmError> {
    sys.start_contacts(st, q, v);
    let xi_start = stick_slip::coordinates(sys, st, q);
    let end = stick_slip::switching_step(sys, None, 0.0, 0.0, |sys, _, _| {
        sys.solve(st, 0.0, 0.0, q, v, qdd)?;
        if stick_slip::slipping_on_a_load(sys) {
            for _ in 0..3 {
                sys.solve(st, 0.0, 0.0, q, v, qdd)?;
            }
        }
        Ok(StepEnd {
            xi_start,
            vs: stick_slip::speeds(sys, st, v),
            ..StepEnd::default()
        })
    })?;
    let ff = stick_slip::sleeve_forces(sys, qdd);
    Ok(FrictionOutput::start(
        sys,
        ff,
        end.vs,
        prescribed_rails_power(law, st),
        rows,
    ))
}

/// The power the rails' friction dissipates under the prescribed sliders of `st` [W] (Eqs. F4, F18).
fn prescribed_rails_power(law: &Friction, st: &RigidState) -> f64 {
    (0..3)
        .map(|i| {
            let v = st.s[i].d1;
            stick_slip::rail_force(&law.rail(i), v) * v
        })
        .sum()
}

/// Eq. F12 of a prescribed motion: Eq. 33 ([`Recorder::eq33`]) with the sleeve's friction
/// along the rail and the rail's friction (F4) [N].
fn friction_fa(rec: &Recorder, sys: &System, st: &RigidState, q: &[f64], qdd: &[f64], law: &Friction) -> [f64; 3] {
    let ff = stick_slip::sleeve_forces(sys, qdd);
    [0, 1, 2].map(|i| {
        rec.force.eq33(i, st, q, &sys.lam, sys.sleeves.axial())
            + ff[i] * rec.force.along_rail(i, st)
            + stick_slip::rail_force(&law.rail(i), st.s[i].d1)
    })
}

/// What an AMM run reports about itself (sidecar JSON): `solver` ("amm" or "amm-direct"), the
/// settings' family and model, N used, the largest step [s] and the wall time since `started`.
pub(crate) fn run_info(
    solver: &str,
    settings: &AmmSettings,
    n_modes: usize,
    dt: f64,
    started: std::time::Instant,
) -> RunInfo {
    RunInfo {
        solver: solver.into(),
        family: Some(settings.family.name().into()),
        model: Some(settings.model.name().into()),
        modes: Some(n_modes),
        dt,
        wall_s: started.elapsed().as_secs_f64(),
        ..RunInfo::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every column the AMM writes is declared once in `flexstar_model::quantity` (its unit in
    /// the sidecar, its row in `docs/outputs.md`).
    #[test]
    fn every_column_is_a_declared_quantity() {
        let fixed = flexstar_model::response::RESPONSE_HEADER;
        for name in fixed.iter().chain(&EXTRA_COLUMNS) {
            assert!(
                flexstar_model::quantity::quantity_of(name).is_some(),
                "{name} is not declared"
            );
        }
    }
    use flexstar_model::{AmmModel, FemSettings, RobotParams, TimeSpan, Trajectory};

    fn case(k: [f64; 3], t_end: f64) -> Experiment {
        Experiment {
            name: "t".into(),
            description: String::new(),
            robot: RobotParams::paper(),
            base: None,
            time: TimeSpan { t_end, dt_out: 1e-3 },
            trajectory: Trajectory::quadratic(k),
            amm: AmmSettings::default(),
            fem: FemSettings::default(),
            drive: Default::default(),
            payload: Default::default(),
            damping: Default::default(),
            load: Default::default(),
            gravity: Default::default(),
            friction: None,
            shaper: None,
            report: Default::default(),
            sensors: Vec::new(),
            measured: None,
            fit: None,
            source: Default::default(),
            hash: String::new(),
        }
    }

    /// `exp` with a payload off G, Rayleigh damping and gravity in the plane.
    fn attached(mut exp: Experiment) -> Experiment {
        exp.payload = flexstar_model::Payload {
            mass: 0.3,
            j: 1e-3,
            offset: [0.02, -0.01],
        };
        exp.damping = flexstar_model::Damping::rayleigh(2.0, 1e-4);
        exp.gravity.g = [1.0, -9.81];
        exp
    }

    #[test]
    fn position_constraints_hold_at_every_step() {
        // index-3 scheme: C(t_n) q_n = 0 to round-off at every step, no drift
        for fam in ModeFamily::PAPER {
            let settings = AmmSettings::paper(fam, 20);
            let (mut worst, mut qmax, mut steps) = (0.0f64, 0.0f64, 0);
            let problem = case([1.0, 0.0, 0.5], 0.2).problem().unwrap();
            integrate(&Star::new(&problem), &settings, 20, true, |sys, q| {
                worst = worst.max(sys.constraint_violation(q));
                qmax = qmax.max(q.iter().fold(0.0f64, |m, v| m.max(v.abs())));
                steps += 1;
            })
            .unwrap();
            assert_eq!(steps, 1200, "0.2 s at the default step 1/6 ms");
            assert!(qmax > 1e-4, "{fam}: no motion");
            assert!(worst < 1e-12 * qmax, "{fam}: |C q| = {worst:e} with |q| = {qmax:e}");
        }
    }

    #[test]
    fn full_model_holds_the_beam_at_the_material_point_in_the_sleeve() {
        // the sleeve rows of the full model (docs/amm.md section 8) are linearised about the predictor each step;
        // the exact geometric conditions (the material point x_c = xp - u + f(x_c) drawn out by
        // the foreshortening, Eq. S1, and x_c +- Lp/2, on the sleeve axis) must hold to far
        // better than the shift u w' that the paper's rows neglect and than the foreshortening
        // shift f w' that the rows at xp - u neglected (docs/amm.md 12.11)
        let exp = case([1.0, 0.0, 0.5], 0.3);
        let problem = exp.problem().unwrap();
        let exp = Star::new(&problem);
        let settings = AmmSettings {
            modes: Some(30),
            ..AmmSettings::accurate()
        };
        let mut worst = [0.0f64; 5];
        let mut largest_thp = 0.0f64;
        integrate(&exp, &settings, 30, true, |sys, q| {
            let gaps = sys.sleeve_gaps(q, exp.beams.map(|b| b.lp));
            for (w, g) in worst.iter_mut().zip(gaps) {
                *w = w.max(g);
            }
            let nb = q.len() / 3;
            largest_thp = (0..3).fold(largest_thp, |m, i| m.max(q[i * nb + nb - 1].abs()));
        })
        .unwrap();
        let [material, unshifted, rigid, slope, slope_linear] = worst;
        eprintln!("largest gap at the material points {material:e} m, without the foreshortening {unshifted:e} m, at the rigid points {rigid:e} m");
        assert!(rigid > 1e-7, "the shift must matter in this test: {rigid:e} m");
        assert!(material < 1e-3 * rigid, "{material:e} m against {rigid:e} m");
        assert!(material < 0.05 * unshifted, "{material:e} m against {unshifted:e} m");
        // the slope row (Eq. S5, docs/amm.md 12.17): sin thp = w'(x_c), where thp = w'(x_c)
        // (Eq. 43 as printed) is off by about thp^3 / 6
        let cubic = largest_thp.powi(3) / 6.0;
        eprintln!("slope row: |sin thp - w'| {slope:e}, |thp - w'| {slope_linear:e}, thp^3 / 6 {cubic:e}");
        assert!(cubic > 1e-12, "the sleeves must turn in this test: thp {largest_thp:e}");
        assert!(slope < 0.05 * cubic, "{slope:e} against thp^3 / 6 = {cubic:e}");
        assert!(
            slope_linear > 0.5 * cubic,
            "{slope_linear:e} against thp^3 / 6 = {cubic:e}"
        );
    }

    #[test]
    fn a_kept_system_solves_as_a_fresh_build() {
        // docs/amm.md 2.1, the setup: a solve from the system kept for this robot, family, N and
        // model gives the fresh build's run bit for bit, with a payload, damping and gravity
        // attached to each (the kept system is the one System::new left, before any of them)
        let problem = attached(case([1.0, 0.0, 0.5], 0.1)).problem().unwrap();
        let star = Star::new(&problem);
        let settings = AmmSettings {
            modes: Some(24),
            ..AmmSettings::accurate()
        };
        let bits = |r: &Response| {
            let mut v: Vec<u64> = r.t.iter().map(|x| x.to_bits()).collect();
            for h in [&r.w_g, &r.w_tip, &r.fa] {
                v.extend(h.iter().flatten().map(|x| x.to_bits()));
            }
            v
        };
        let fresh = {
            let sys = System::new(
                vec![ModeSet::new(settings.family, 24, &star.beams[0]).unwrap()],
                &star.beams,
                &star.weld,
                settings.model,
            );
            let mut sys = sys;
            sys.attach(star.payload, star.damping, star.load, star.gravity);
            integrate_system(
                &star,
                &settings,
                sys,
                DEFAULT_DT,
                std::time::Instant::now(),
                |_: &System, _: &[f64]| {},
            )
            .unwrap()
        };
        for _ in 0..2 {
            let kept = integrate(&star, &settings, 24, true, |_, _| {}).unwrap();
            assert!(kept.w_tip[0].iter().any(|w| w.abs() > 1e-5), "no motion");
            assert_eq!(bits(&fresh), bits(&kept));
        }
    }

    #[test]
    fn the_per_beam_layout_reproduces_the_shared_one_bit_for_bit() {
        // docs/amm.md 13: three equal beams run through the general layout (a mode set, an
        // arrowhead, sleeve tables and G matrices per beam) give the shared layout's run exactly,
        // in both models, with a payload, damping, a load and gravity
        let mut exp = attached(case([1.0, 0.0, 0.5], 0.1));
        exp.load = flexstar_model::LoadSettings::polynomials(Some(vec![0.0, 5.0]), None, Some(vec![0.0, 0.0, 3.0]));
        let problem = exp.problem().unwrap();
        let star = Star::new(&problem);
        assert!(star.shared && star.paper.is_some());
        for settings in [
            AmmSettings {
                modes: Some(30),
                snapshots: vec![0.05],
                ..AmmSettings::accurate()
            },
            AmmSettings::paper(ModeFamily::FreeFree, 20),
        ] {
            let n = settings.modes.unwrap();
            let shared = integrate(&star, &settings, n, true, |_, _| {}).unwrap();
            let general = integrate(&star.per_beam(), &settings, n, true, |_, _| {}).unwrap();
            let bits = |r: &Response| {
                let mut v: Vec<u64> = r.t.iter().map(|x| x.to_bits()).collect();
                for h in [&r.w_g, &r.w_tip, &r.fa] {
                    v.extend(h.iter().flatten().map(|x| x.to_bits()));
                }
                v.extend(r.extra.iter().flat_map(|c| c.values.iter().map(|x| x.to_bits())));
                v.extend(
                    r.shapes
                        .iter()
                        .flat_map(|s| s.beams.iter().flat_map(|b| b.w.iter().map(|x| x.to_bits()))),
                );
                v
            };
            assert!(shared.w_tip[0].iter().any(|w| w.abs() > 1e-5), "no motion");
            assert_eq!(bits(&shared), bits(&general), "{:?}", settings.model);
        }
    }

    #[test]
    fn rows_dropped_per_family() {
        // docs/amm.md section 1: pinned-free loses sum w_iG, slide-free the slope equalities
        let p = RobotParams::paper();
        let count = |fam| {
            System::new(
                vec![ModeSet::new(fam, 25, &p).unwrap()],
                &[p; 3],
                &crate::star::Weld::paper(),
                AmmModel::Paper,
            )
            .rows
            .len()
        };
        assert_eq!(count(ModeFamily::FreeFree), 18);
        assert_eq!(count(ModeFamily::PinnedFree), 17);
        assert_eq!(count(ModeFamily::SlideFree), 16);
        assert_eq!(count(ModeFamily::ClampedFree), 15);
    }

    #[test]
    fn stops_merge_snapshots_with_outputs() {
        let s = stops(&[0.0, 0.1, 0.2], &[0.1, 0.15, 0.2], 1e-12);
        let t: Vec<f64> = s.iter().map(|x| x.t).collect();
        assert_eq!(t, vec![0.0, 0.1, 0.15, 0.2]);
        assert_eq!(s[1].snapshot, Some(0));
        assert_eq!(s[2].output, None);
        assert_eq!(s[3].output, Some(2));
    }
}
