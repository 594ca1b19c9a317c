//! The public entry point [`solve`]: run the FEM on an experiment, the inverse problem (motion
//! given, forces found) or the direct one (forces or a servo given, motion found), and post-process its absolute results into the shared [`Response`] (projections of
//! `docs/conventions.md`).

use std::borrow::Cow;

use flexstar_drive::{ActuatorLaw, Drive, SolveRequest, Solved};
use flexstar_kinematics::as_built::rigid_pose;
use flexstar_kinematics::{check_trajectory, preflight_step, CheckedMotion, KinematicsError, RigidState};
use flexstar_model::animation::{frame_times, ShapeTimes};
use flexstar_model::{
    Beam, BeamShape, FemSettings, FramePose, Problem, Response, RestOffset, Robot, RobotGeometry, RobotParams, RunInfo,
    StarShape, Trajectory,
};

use crate::integrator::{
    integrate, static_equilibrium, FrictionSample, History, Motion, RunSettings, Sample, Snapshot, Stats,
};
use crate::star::{Attached, InitialState};
use crate::FemError;

/// Default integration step [s] of the paper's robot and of every robot whose beams are no
/// stiffer than its (lower first frequency), from the convergence study in `docs/fem.md`
/// section 4; stiffer robots get [`default_dt`].
pub const DEFAULT_DT: f64 = 5e-4;

/// `(beta_1 L)^2` of the clamped-free beam's first bending mode (beta_1 L = 1.875104).
const CLAMPED_FREE_1: f64 = 1.875_104_068_711_961 * 1.875_104_068_711_961;

/// First clamped-free bending frequency `omega_1 = (beta_1 L)^2 sqrt(EI / (rho L^4))` [rad/s]
/// of one beam of `params` (the robot's time scale in the step rule, Eq. S10 of `docs/fem.md`
/// section 4.1).
pub fn first_beam_frequency(params: &RobotParams) -> f64 {
    CLAMPED_FREE_1 * (params.ei() / (params.rho * params.l.powi(4))).sqrt()
}

/// First clamped-free bending frequency of one beam [rad/s],
/// `omega_1 = (beta_1 L_i)^2 sqrt(EI_i / (rho_i L_i^4))` (Eq. S10 of `docs/fem.md` section 4.1 with
/// beam i's own data, section 10).
pub fn beam_frequency(beam: &Beam) -> f64 {
    CLAMPED_FREE_1 * (beam.bending_stiffness() / (beam.mass_per_length * beam.length.powi(4))).sqrt()
}

/// The FEM's default integration step [s] for a robot as built (Eq. S10, `docs/fem.md` sections
/// 4.1 and 10): [`default_dt`]'s rule at the stiffest beam's first clamped-free frequency
/// ([`beam_frequency`], the highest of the three), so that every beam's first modes are
/// resolved as on the paper's robot; on equal beams exactly [`default_dt`] of their parameters.
pub fn default_dt_of(robot: &Robot) -> f64 {
    if let Ok(p) = robot.equal_beams() {
        return default_dt(p);
    }
    let omega = robot.beams().map(|b| beam_frequency(&b));
    let ratio = first_beam_frequency(&RobotParams::paper()) / omega[0].max(omega[1]).max(omega[2]);
    (DEFAULT_DT * ratio.powf(1.5).min(1.0)).max(MIN_DEFAULT_DT)
}

/// The FEM's default integration step [s] for `params` (Eq. S10, `docs/fem.md` section 4.1):
/// `DEFAULT_DT min(1, (omega_ref / omega_1)^(3/2))`, with `omega_1` the robot's first
/// clamped-free beam frequency ([`first_beam_frequency`]) and `omega_ref` the paper robot's
/// (20.6 rad/s). The exponent keeps the generalized-alpha phase error of the first modes,
/// accumulated over the motion (`~ omega^3 dt^2 T`), at the paper robot's level, which the study
/// of section 4 showed to be converged; the paper's robot and softer ones keep 5e-4 s. The run
/// takes at most this step (every output interval is split into equal steps, section 3). Floor:
/// [`MIN_DEFAULT_DT`] (`omega_1` above 280 rad/s, beyond the range the rule was checked on).
pub fn default_dt(params: &RobotParams) -> f64 {
    let ratio = first_beam_frequency(&RobotParams::paper()) / first_beam_frequency(params);
    (DEFAULT_DT * ratio.powf(1.5).min(1.0)).max(MIN_DEFAULT_DT)
}

/// Smallest step [s] that [`default_dt`] chooses (a fiftieth of [`DEFAULT_DT`], reached at
/// `omega_1 = 280 rad/s`, e.g. EI = 2 N m^2, rho = 0.05 kg/m, L = 0.3 m): a practically rigid star
/// (the stiff-limit tests' EI x 1e4) would otherwise get steps of 1e-7 s for elastic deflections
/// too small to matter; set `[fem] dt` there (docs/fem.md section 4.1).
pub const MIN_DEFAULT_DT: f64 = DEFAULT_DT / 50.0;
/// Default spectral radius at infinity of the generalized-alpha scheme (docs/fem.md).
pub const DEFAULT_RHO_INF: f64 = flexstar_model::config::FEM_DEFAULT_RHO_INF;

/// Names of the extra columns of every run (see [`solve`]).
const EXTRA: [&str; 17] = [
    "xp1",
    "xp2",
    "xp3",
    "thp1",
    "thp2",
    "thp3",
    "Fn1",
    "Fn2",
    "Fn3",
    "dGx",
    "dGy",
    "Ek_star",
    "Ek_sleeves",
    "Ek_sliders",
    "U",
    "W",
    "slopeG",
];

/// The energies of the payload, the load, the damping and the weights, each written only with
/// its section.
const ATTACHED: [&str; 4] = ["Ek_payload", "W_load", "E_d", "V_g"];

/// Extra columns a direct run writes first (see [`solve`] with [`Drive::Law`]).
const DIRECT_EXTRA: [&str; 9] = ["s1", "s2", "s3", "sd1", "sd2", "sd3", "Gx", "Gy", "theta"];

/// Run the finite-element reference on `problem` with `settings` (which override `problem.fem`).
///
/// The robot is the problem's as built (`docs/fem.md` section 10): each beam with its own
/// section, length, sleeve and weld angle, each slider on its own axis `o_i + s u_i`; the
/// paper's robot (three equal beams welded 120 degrees apart on an equilateral base) is one
/// value of it, solved bit for bit as before per-beam data. Beam i's frame below is
/// `e_xi = [sin(theta + phi_i), -cos(theta + phi_i)]`, `e_wi = [cos(theta + phi_i), sin(theta +
/// phi_i)]` with its weld angle phi_i (`docs/as-built.md` Eq. W1; Eqs. 11-12 on the paper's robot).
///
/// Returns the response labelled `fem` at `problem.time.output_times()`:
/// - `w_iG = (G_fem - G_rigid) . e_wi` and the tip value `w_i(L_i) = (tip_fem - (G_rigid + L_i e_xi)) . e_wi`
///   [m], projected on the rigid frames of Eqs. 11-12 (post-processing only);
/// - `Fa_i` [N], Eq. 33, from the pin reactions: `Fa_i = (mpp + mpa)_i s_i'' + F_i . u_i` with `F_i`
///   the force the sleeve exerts on the beam (sum over centre and edges) and `u_i` the slider
///   direction;
/// - extra columns: `xp1..3` (material coordinate of each sleeve centre on its beam [m]),
///   `thp1..3` (sleeve rotation relative to the rigid beam direction [rad]), `Fn1..3` (force of
///   sleeve i on its beam along e_wi [N], the paper's `Fp + FL + FR`), `dGx, dGy` (G_fem - G_rigid
///   in the fixed frame [m]), `Ek_star, Ek_sleeves, Ek_sliders, U` (kinetic energies of beams,
///   sleeve rotations, sliders and strain energy [J]), `W` (work of the drivers since t = 0 [J]),
///   `slopeG` (elastic slope of the beams at G: rotation of the weld node minus the rigid
///   rotation theta(t) - theta(0) [rad]; the junction measure of Table I);
/// - payload, damping and load, each only when its section is present (so a run at the defaults writes the
///   columns above and nothing else): `Ek_payload` (kinetic energy of the payload [J]) with a
///   `[payload]`, `W_load` (work of the load at G since t = 0 [J], trapezoidal rule on the steps)
///   with a `[load]`, `E_d` (energy dissipated since t = 0 [J] by the beams' Kelvin-Voigt
///   damping, Eq. D10, and the mass-proportional damping of the elastic motion, Eq. D16) with a
///   `[damping]`, `V_g` (potential energy of the weights of beams, payload, sleeves and sliders
///   [J], base frame origin, `docs/fem.md` 9.5) with a `[gravity]`; the energy balance is then
///   Eq. C6, `W + W_load = Delta(Ek_star + Ek_sleeves + Ek_sliders + Ek_payload + U + V_g) + E_d`;
/// - under gravity (`docs/fem.md` 9.5, Eqs. G6-G8): the weights act on the beams, the payload and
///   the sliders (`Fa_i` gains `- (mpp + mpa)_i g . u_i`, Eq. G7), the run starts at rest in the
///   deflected static equilibrium of its start pose (Eq. G8; every elastic output includes the
///   sag), and `rest_offset` holds the static equilibrium's `w_iG`, `w_i(L_i)` at the pose where
///   the motion comes to rest (`Trajectory::t_rest`, when within the run);
/// - `shapes`: the deformed star at `settings.snapshots` and at t_end (beam i's material
///   positions `k L_i / ne`).
///
/// `progress` receives the fraction of the time span done, in [0, 1].
///
/// The one entry point of the FEM, for both drives of `request` (`flexstar_drive::SolveRequest`):
/// the prescribed motion ([`Drive::Motion`], described above; its feasibility is scanned first
/// unless `request.proof` covers the run) or an actuator law ([`Drive::Law`], see
/// the direct dynamics below). `request.progress` receives the fraction of the time span done, in [0, 1].
/// Returns the response and the work counters (steps, Newton iterations, factorisations).
/// `settings.elements` must be a positive multiple of 3 ([`FemError::Elements`]): each beam gets
/// a third of them.
pub fn solve(problem: &Problem, settings: &FemSettings, request: SolveRequest) -> Result<Solved<Stats>, FemError> {
    let (mut response, stats) = match request.drive {
        Drive::Motion => solve_prescribed(problem, settings, request.proof, request.progress)?,
        Drive::Law(law) => solve_direct(problem, settings, law, request.progress)?,
    };
    if problem.gravity() != [0.0; 2] {
        response.rest_offset = rest_offset(problem, settings)?;
    }
    Ok(Solved { response, stats })
}

/// [`solve`] of the prescribed motion, the feasibility scan skipped when `checked` covers the run.
fn solve_prescribed(
    problem: &Problem,
    settings: &FemSettings,
    checked: Option<&CheckedMotion>,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<(Response, Stats), FemError> {
    let started = std::time::Instant::now();
    let robot = &*meshed(problem.robot())?;
    let trajectory = problem.trajectory();
    let run = validate(problem, settings)?;
    // the same feasibility scan as the AMM and the kinematics, before any work: a pre-flight check
    // of the requested motion only (the FEM's equations never use the rigid kinematics)
    let (dt_out, t_end) = (problem.time().dt_out, problem.time().t_end);
    let step = preflight_step(dt_out);
    scan(robot, trajectory, t_end, step, checked)?;
    let rigid = |t: f64| rigid_state(robot, trajectory, t).map_err(|source| FemError::PostProcessing { t, source });
    let r0 = rigid(0.0)?;
    let (t_out, shape_times) = times(problem, settings);
    let motion = Motion::Prescribed(trajectory);
    let attached = Attached::of(problem, r0.theta.v);
    let hist = integrate(
        robot,
        &motion,
        &t_out,
        &shape_times.all,
        &initial_state(&r0),
        &run,
        &attached,
        progress,
    )?;

    // post-processing with the rigid kinematics of the prescribed motion
    let frame = |t: f64, _s: [f64; 3]| {
        let r = rigid(t)?;
        Ok(RigidFrame {
            g: [r.g[0].v, r.g[1].v],
            theta: r.theta.v,
        })
    };
    let mut resp = post_process(robot, &hist, "fem", &frame, r0.theta.v, false)?;
    add_shapes(robot, &mut resp, &hist, &shape_times, &frame)?;
    if let Some(cb) = progress {
        cb(1.0);
    }
    resp.info = run_info("fem", settings, &run, started);
    Ok((resp, hist.stats))
}

/// Direct dynamics ([`solve`] with [`Drive::Law`]): the sliders move under the actuator law `law` instead of
/// following `problem.trajectory`.
///
/// Each slider is a body of mass `(mpp + mpa)_i` on its rail, pushed along `+u_i` by
/// `Fa_i(t, s_i, s_i')` and by the beam through the sleeve's pin (Eq. 33 read the other way
/// round, `docs/fem.md` section 8); its coordinate `s_i` is an unknown of the FEM, and the servo's
/// `kp`, `kd` (`law.stiffness()`, `law.damping()`) enter the iteration matrix. Initial state:
/// `s(0)`, `s'(0)` from `problem.trajectory` at t = 0, the star undeformed and moving rigidly, or
/// under gravity in the static equilibrium with the sliders held at `s(0)` (Eq. G8; as [`solve`] starts), so that the `Fa` of an inverse run fed back reproduces that run. The
/// payload, damping and load of `problem` act as in [`solve`] (`docs/fem.md` section 9).
///
/// The configuration is checked at every step (sleeves on their beams, then the limits of
/// `flexstar_kinematics::feasibility` on the simulated `s`): leaving the feasible range stops the
/// run with [`FemError::Infeasible`] (or [`FemError::SleeveOffBeam`]), time and reason, and no
/// output.
///
/// Returns the response and the work counters; the response labelled `fem-direct` (`info.solver = "fem-direct"`) at
/// `problem.time.output_times()`: `w_iG`, `w_i(L_i)` projected on the rigid frames of the *simulated*
/// sliders' direct kinematics (post-processing only; `docs/as-built.md` Eqs. D1-D3 on a robot as
/// built), `Fa_i` [N] the law's forces at the output
/// time, then the extra columns `s1..3` [m], `sd1..3` [m/s] (simulated sliders), `Gx, Gy` [m],
/// `theta` [rad] (their rigid pose, Eqs. 4-9), then those of [`solve`] (with `dGx, dGy` and
/// `slopeG` relative to that pose, `W` the work of the law's forces).
fn solve_direct(
    problem: &Problem,
    settings: &FemSettings,
    law: &dyn ActuatorLaw,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<(Response, Stats), FemError> {
    let started = std::time::Instant::now();
    let robot = &*meshed(problem.robot())?;
    let run = validate(problem, settings)?;
    let r0 = rigid_state(robot, problem.trajectory(), 0.0).map_err(FemError::Start)?;
    let (t_out, shape_times) = times(problem, settings);
    let motion = Motion::Driven {
        law,
        s0: r0.s.map(|s| s.v),
        v0: r0.s.map(|s| s.d1),
    };
    let attached = Attached::of(problem, r0.theta.v);
    let hist = integrate(
        robot,
        &motion,
        &t_out,
        &shape_times.all,
        &initial_state(&r0),
        &run,
        &attached,
        progress,
    )?;

    // post-processing with the rigid kinematics of the simulated sliders
    let frame = |t: f64, s: [f64; 3]| {
        let pose = rigid_pose(robot, s).ok_or(FemError::NoRigidConfiguration { t, s })?;
        Ok(RigidFrame {
            g: pose.g,
            theta: pose.theta,
        })
    };
    let mut resp = post_process(robot, &hist, "fem-direct", &frame, r0.theta.v, true)?;
    add_shapes(robot, &mut resp, &hist, &shape_times, &frame)?;
    if let Some(cb) = progress {
        cb(1.0);
    }
    resp.info = run_info("fem-direct", settings, &run, started);
    Ok((resp, hist.stats))
}

/// The robot the FEM solves: the problem's as built, or, when it is the paper's robot (equal
/// beams welded 120 degrees apart on an equilateral base centred at O, each datum equal to
/// rounding: `Robot::equal_beams`), exactly the paper's form of it (`Robot::from_params`), so
/// that a paper robot given beam by beam, its weld angles and axes computed by other sums of the
/// same numbers, is solved bit for bit as the paper's (`docs/fem.md` section 10).
pub(crate) fn meshed(robot: &Robot) -> Result<Cow<'_, Robot>, FemError> {
    match robot.equal_beams() {
        Ok(p) => Robot::from_params(p).map(Cow::Owned).map_err(FemError::Problem),
        Err(_) => Ok(Cow::Borrowed(robot)),
    }
}

/// The rigid state of `robot` at time `t` of `trajectory` (`flexstar_kinematics`: initial data
/// and post-processing only, never in the equations; the Fermat construction on the paper's
/// robot, `docs/as-built.md` Eqs. D1-D3 on one as built).
fn rigid_state(robot: &Robot, trajectory: &Trajectory, t: f64) -> Result<RigidState, KinematicsError> {
    RigidState::at(robot, trajectory, t)
}

/// The feasibility scan of the prescribed motion before any step (skipped when `checked`
/// covers the run), with each beam's own L_i, Lp_i and each slider's travel on its side:
/// [`FemError::Scan`] with the time and the limit.
fn scan(
    robot: &Robot,
    trajectory: &Trajectory,
    t_end: f64,
    step: f64,
    checked: Option<&CheckedMotion>,
) -> Result<(), FemError> {
    if !checked.is_some_and(|c| c.covers(robot, trajectory, t_end, step)) {
        check_trajectory(robot, trajectory, t_end, step).map_err(FemError::Scan)?;
    }
    Ok(())
}

/// Check the settings against the problem (validated when it was built); the run's numerical
/// settings.
fn validate(problem: &Problem, settings: &FemSettings) -> Result<RunSettings, FemError> {
    let elements = settings.elements;
    if elements < 3 || !elements.is_multiple_of(3) {
        let reason = if elements < 3 {
            "fewer than one element per beam"
        } else {
            "not a multiple of 3"
        };
        return Err(FemError::Elements { elements, reason });
    }
    let dt = settings
        .dt
        .unwrap_or(default_dt_of(problem.robot()).min(problem.time().dt_out));
    if !(dt.is_finite() && dt > 0.0) {
        return Err(FemError::Input(format!("fem.dt must be positive, got {dt}")));
    }
    let rho_inf = settings.rho_inf.unwrap_or(DEFAULT_RHO_INF);
    if !(0.0..=1.0).contains(&rho_inf) {
        return Err(FemError::Input(format!(
            "fem.rho_inf must lie in [0, 1], got {rho_inf}"
        )));
    }
    let t_end = problem.time().t_end;
    if let Some(bad) = settings
        .snapshots
        .iter()
        .find(|t| !(t.is_finite() && **t >= 0.0 && **t <= t_end))
    {
        return Err(FemError::Input(format!(
            "fem.snapshots must lie in [0, t_end = {t_end}], got {bad}"
        )));
    }
    flexstar_model::animation::check_frames("fem.frames", settings.frames, t_end).map_err(FemError::Problem)?;
    Ok(RunSettings {
        ne: elements / 3,
        dt,
        rho_inf,
    })
}

/// Initial data: the undeformed star in the rigid configuration at s(0), moving rigidly.
pub(crate) fn initial_state(r0: &RigidState) -> InitialState {
    InitialState {
        g: [r0.g[0].v, r0.g[1].v],
        g_dot: [r0.g[0].d1, r0.g[1].d1],
        theta: r0.theta.v,
        theta_dot: r0.theta.d1,
        xp: r0.xp.map(|x| x.v),
        xp_dot: r0.xp.map(|x| x.d1),
    }
}

/// Output times and the shape times: the snapshots (t_end always among them) and the animation
/// frames of `settings.frames` (`docs/motions.md` section 5).
fn times(problem: &Problem, settings: &FemSettings) -> (Vec<f64>, ShapeTimes) {
    let t_end = problem.time().t_end;
    let mut snaps = settings.snapshots.clone();
    snaps.push(t_end);
    snaps.sort_by(|a, b| a.total_cmp(b));
    snaps.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let frames = frame_times(t_end, settings.frames);
    (problem.time().output_times(), ShapeTimes::merge(&snaps, &frames, 1e-12))
}

fn run_info(solver: &str, settings: &FemSettings, run: &RunSettings, started: std::time::Instant) -> RunInfo {
    RunInfo {
        solver: solver.into(),
        elements: Some(settings.elements),
        dt: run.dt,
        wall_s: started.elapsed().as_secs_f64(),
        ..RunInfo::default()
    }
}

/// The rigid frame the absolute results are projected on: centre G [m] and orientation theta
/// [rad] (beam i along `e_xi(theta)` of its weld angle, `docs/as-built.md` Eq. W1).
struct RigidFrame {
    g: [f64; 2],
    theta: f64,
}

/// `e_xi` and `e_wi` of `robot`'s beam i at the orientation `theta` [rad] (`docs/as-built.md`
/// Eq. W1; Eqs. 11-12 on the paper's robot): `e_wi` is `e_xi` turned a quarter counter-clockwise.
fn beam_frame(robot: &Robot, i: usize, theta: f64) -> ([f64; 2], [f64; 2]) {
    let ex = robot.e_x(i, theta);
    (ex, [-ex[1], ex[0]])
}

/// Project the absolute history on the rigid frames given by `frame(t, s)` (`theta0` the frame's
/// orientation at t = 0); `direct` adds the sliders' columns first.
fn post_process(
    robot: &Robot,
    hist: &History,
    label: &str,
    frame: &dyn Fn(f64, [f64; 3]) -> Result<RigidFrame, FemError>,
    theta0: f64,
    direct: bool,
) -> Result<Response, FemError> {
    let n = hist.samples.len();
    let mut resp = Response::with_capacity(label, n);
    resp.sensors.clone_from(&hist.sensors);
    let mut extra: Vec<Vec<f64>> = vec![Vec::with_capacity(n); EXTRA.len()];
    let mut lead: Vec<Vec<f64>> = vec![Vec::with_capacity(n); if direct { DIRECT_EXTRA.len() } else { 0 }];
    for s in &hist.samples {
        let r = frame(s.t, s.s)?;
        let g = r.g;
        let dg = [s.g[0] - g[0], s.g[1] - g[1]];
        let (w_g, w_tip) = deflections(robot, &r, s.g, &s.tip);
        for i in 0..3 {
            let (ex, ew) = beam_frame(robot, i, r.theta);
            extra[i].push(s.xi_c[i]);
            extra[3 + i].push(wrap(s.sleeve_angle[i] - ex[1].atan2(ex[0])));
            extra[6 + i].push(-dot(s.pin_force[i], ew));
        }
        resp.push(s.t, w_g, w_tip, s.fa);
        let slope_g = wrap(s.phi_g - (r.theta - theta0));
        for (k, v) in [
            dg[0],
            dg[1],
            s.ke_star,
            s.ke_sleeves,
            s.ke_sliders,
            s.strain,
            s.work,
            slope_g,
        ]
        .into_iter()
        .enumerate()
        {
            extra[9 + k].push(v);
        }
        if direct {
            let row = [s.s[0], s.s[1], s.s[2], s.sd[0], s.sd[1], s.sd[2], g[0], g[1], r.theta];
            for (col, v) in lead.iter_mut().zip(row) {
                col.push(v);
            }
        }
    }
    let mut names: Vec<&str> = if direct {
        DIRECT_EXTRA.iter().chain(EXTRA.iter()).copied().collect()
    } else {
        EXTRA.to_vec()
    };
    lead.extend(extra);
    attachment_columns(hist, &mut names, &mut lead);
    let friction = friction_columns(hist);
    names.extend(friction.iter().map(|(n, _)| n.as_str()));
    lead.extend(friction.iter().map(|(_, c)| c.clone()));
    resp.set_extra(&names, lead);
    resp.friction = hist.friction.map(|f| f.tally.summary());
    Ok(resp)
}

/// With friction, its columns after all others (`docs/friction.md` 7,
/// [`flexstar_model::friction_run::friction_columns`]); none without friction.
fn friction_columns(hist: &History) -> Vec<(String, Vec<f64>)> {
    let rows: Vec<FrictionSample> = hist.samples.iter().filter_map(|s| s.friction).collect();
    if hist.friction.is_none() || rows.len() != hist.samples.len() {
        return Vec::new();
    }
    flexstar_model::friction_run::friction_columns(&rows)
}

/// `w_iG = (G_fem - G_rigid) . e_wi` and `w_i(L_i) = (tip_fem - (G_rigid + L_i e_xi)) . e_wi` [m]
/// of the FEM's G at `g` and tips `tips` (fixed frame) on the rigid frame `r` (Eqs. 11-12, W1).
fn deflections(robot: &Robot, r: &RigidFrame, g: [f64; 2], tips: &[[f64; 2]; 3]) -> ([f64; 3], [f64; 3]) {
    let dg = [g[0] - r.g[0], g[1] - r.g[1]];
    let w_g = [0, 1, 2].map(|i| dot(dg, beam_frame(robot, i, r.theta).1));
    let w_tip = [0, 1, 2].map(|i| {
        let (ex, ew) = beam_frame(robot, i, r.theta);
        let l = robot.beams()[i].length;
        let rel = [tips[i][0] - r.g[0] - l * ex[0], tips[i][1] - r.g[1] - l * ex[1]];
        dot(rel, ew)
    });
    (w_g, w_tip)
}

/// Under gravity, the static equilibrium's `w_iG` and `w_i(L_i)` at the pose where the problem's
/// motion comes to rest (`docs/fem.md` 9.5, Eq. G8; `docs/as-built.md` 5.5: the residual
/// vibration is measured about it), post-processed as the run's outputs on the rigid frame of
/// that pose; `None` without a rest within the run. The load acts at its value at `t_rest`.
fn rest_offset(problem: &Problem, settings: &FemSettings) -> Result<Option<RestOffset>, FemError> {
    let Some(t_rest) = problem.trajectory().t_rest().filter(|t| *t <= problem.time().t_end) else {
        return Ok(None);
    };
    let robot = &*meshed(problem.robot())?;
    let r = rigid_state(robot, problem.trajectory(), t_rest)
        .map_err(|source| FemError::PostProcessing { t: t_rest, source })?;
    let attached = Attached::of(problem, r.theta.v);
    let s = r.s.map(|s| s.v);
    let (star, q) = static_equilibrium(robot, settings.elements / 3, &initial_state(&r), &attached, s, t_rest)?;
    let pos = |j: usize| [q[3 * j], q[3 * j + 1]];
    let frame = RigidFrame {
        g: [r.g[0].v, r.g[1].v],
        theta: r.theta.v,
    };
    let (w_g, w_tip) = deflections(robot, &frame, pos(0), &[0, 1, 2].map(|i| pos(star.node(i, star.ne))));
    Ok(Some(RestOffset { t_rest, w_g, w_tip }))
}

/// The deformed-star snapshots and the animation frames of `resp` from the recorded shapes
/// (`times.all`, in order), each about the rigid frame `frame(t, s)` (post-processing only).
fn add_shapes(
    robot: &Robot,
    resp: &mut Response,
    hist: &History,
    times: &ShapeTimes,
    frame: &dyn Fn(f64, [f64; 3]) -> Result<RigidFrame, FemError>,
) -> Result<(), FemError> {
    let shape = |k: usize| -> Result<(StarShape, FramePose), FemError> {
        let snap = hist
            .snapshots
            .get(k)
            .ok_or_else(|| FemError::Input(format!("no deformed star recorded at t = {} s", times.all[k])))?;
        let r = frame(snap.t, snap.s)?;
        let pose = FramePose {
            g: r.g,
            theta: r.theta,
            s: snap.s,
        };
        Ok((star_shape(robot, hist, snap, &r), pose))
    };
    for &k in &times.snap_idx {
        resp.shapes.push(shape(k)?.0);
    }
    for &k in &times.frame_idx {
        let (shape, pose) = shape(k)?;
        resp.frames.push(flexstar_model::Frame { shape, pose });
    }
    Ok(())
}

/// An optional column: whether the run has it, its name, its value in a sample.
type OptionalColumn = (bool, &'static str, fn(&Sample) -> f64);

/// The payload's, load's, damping's and gravity's columns after the others, each only when the
/// run had its section: `Ek_payload`, `W_load`, `E_d`, `V_g` [J] (see [`solve`]).
fn attachment_columns(hist: &History, names: &mut Vec<&str>, cols: &mut Vec<Vec<f64>>) {
    let present: [OptionalColumn; 4] = [
        (hist.payload, ATTACHED[0], |s: &Sample| s.ke_payload),
        (hist.load, ATTACHED[1], |s: &Sample| s.w_load),
        (hist.damping, ATTACHED[2], |s: &Sample| s.e_d),
        (hist.gravity, ATTACHED[3], |s: &Sample| s.v_g),
    ];
    for (on, name, value) in present {
        if on {
            names.push(name);
            cols.push(hist.samples.iter().map(value).collect());
        }
    }
}

/// The deformed star of snapshot `snap`: per beam the node positions and their deflections `w`
/// [m] from the rigid beam of the frame at the snapshot's slider positions.
fn star_shape(robot: &Robot, hist: &History, snap: &Snapshot, r: &RigidFrame) -> StarShape {
    let g = r.g;
    let beams = [0, 1, 2].map(|i| {
        let (ex, ew) = beam_frame(robot, i, r.theta);
        let pos = snap.beams[i].clone();
        let w = hist.node_x[i]
            .iter()
            .zip(&pos)
            .map(|(x, p)| dot([p[0] - g[0] - x * ex[0], p[1] - g[1] - x * ex[1]], ew))
            .collect();
        BeamShape {
            x: hist.node_x[i].clone(),
            w,
            pos,
        }
    });
    StarShape { t: snap.t, beams }
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// An output angle wrapped by [`flexstar_numerics::angle::wrap`], first shifted by pi and back:
/// the shift rounds the angle as the output's earlier formula `(a + pi) mod 2 pi - pi` did, so
/// that the written columns stay bit for bit those of earlier versions (the two differ only by
/// that rounding, at most half an ulp of pi, and at -pi, which the wrap sends to pi).
fn wrap(a: f64) -> f64 {
    use std::f64::consts::PI;
    flexstar_numerics::angle::wrap((a + PI) - PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every column the FEM writes (a direct run's first, its own, the attachments' energies) is
    /// declared once in `flexstar_model::quantity`.
    #[test]
    fn every_column_is_a_declared_quantity() {
        let own = DIRECT_EXTRA.iter().chain(&EXTRA).chain(&ATTACHED);
        for name in own {
            assert!(
                flexstar_model::quantity::quantity_of(name).is_some(),
                "{name} is not declared"
            );
        }
    }
}
