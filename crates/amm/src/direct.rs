//! Direct dynamics (`docs/amm.md` section 10): the actuator forces (or a servo) are
//! given and the slider positions s_i join the unknowns.
//!
//! ```text
//! M q'' + D q' + K q = f(a_G, theta', theta'') + C(xp)^T lambda,   C(xp) q = 0   (Eqs. 30-32, 37, 44)
//! (mpp + mpa) s_i'' = Fa_i(t, s_i, s_i') - F_i(lambda) e_wi . u_i               (Eq. 33)
//! ```
//! with `G, theta, xp` the exact direct kinematics of s (Eqs. 4-10), so that
//! `a_G = J_G s'' + H_G[s', s']`, `theta'' = J_th s'' + H_th[s', s']` (Jacobians and Hessians by
//! dual numbers, [`flexstar_kinematics::RigidState::from_actuators`]).
//!
//! Time integration: the elastic coordinates q and the sliders s share the index-3
//! generalized-alpha step of [`crate::solve`]. Per step the unknowns are q'' and s''; the coupled
//! step is linearised once about the predictor `s''_pred = s''_n`: the step matrix and the
//! constraint rows are built at the predicted rigid state, the forcing is affine in the correction
//! `ds''` through `d a_G / d s''`, `d theta' / d s''`, `d theta'' / d s''` (including the
//! generalized-alpha dependence of s and s' on s''), so four right-hand sides of one factored
//! system give `q'' = q''_0 + sum_k ds''_k q''_k` and the multipliers likewise, and Eq. 33
//! becomes a 3 x 3 linear system for `ds''`. What the linearisation drops is of second order in
//! the per-step change of s'' times the step (`docs/amm.md` section 10).

use flexstar_drive::ActuatorLaw;
use flexstar_kinematics::RigidState;
use flexstar_model::{AmmSettings, ModeCount, Response};
use flexstar_numerics::GenAlpha;
use num_dual::{Dual2, HyperDual64};

use crate::adaptive;
use crate::error::{AmmError, RankError};
use crate::record::Recorder;
use crate::solver::{shape_times, star_time_scale, stops, validate, Stats, Stop, RHO_INF};
use crate::star::Star;
use crate::stick_slip::{self, FrictionOutput, Rails, StepEnd};
use crate::system::System;
use flexstar_model::Contact;

/// Columns a direct run writes first among its extra columns: the sliders `s_i` [m] and `s_i'`
/// [m/s], and the rigid pose of the simulated sliders by the exact direct kinematics: `Gx`, `Gy`
/// [m] and `theta` [rad]. The columns of [`crate::EXTRA_COLUMNS`] follow.
pub const DIRECT_COLUMNS: [&str; 9] = ["s1", "s2", "s3", "sd1", "sd2", "sd3", "Gx", "Gy", "theta"];

/// The direct problem (`crate::solve` with `Drive::Law`): the sliders driven by `law`, from `s(0)`,
/// `s'(0)` of `problem.trajectory` at t = 0 with the star at rest elastically (as an inverse run
/// starts).
///
/// Returns the response labelled `amm-<family>-direct` (`info.solver = "amm-direct"`): the
/// standard columns with `Fa_i` the law's forces at the output times, then [`DIRECT_COLUMNS`],
/// then [`crate::EXTRA_COLUMNS`]. Every family, both models, fixed N or tolerance, as the
/// prescribed motion; and the work counters of every integration run.
///
/// `scan`: check the reference over the whole span (a servo's, when the caller holds no proof),
/// else its start only. The configuration reached is checked at every step: leaving the feasible
/// range stops the run with the time (to one step) and the reason.
pub(crate) fn solve_direct_scanned(
    problem: &Star,
    settings: &AmmSettings,
    law: &dyn ActuatorLaw,
    scan: bool,
) -> Result<(Response, Stats), AmmError> {
    let mut runs = Vec::new();
    let response = match settings.mode_count() {
        ModeCount::Fixed(n) => integrate_direct(problem, settings, law, n, scan, &mut runs)?,
        ModeCount::Tolerance(tol) => {
            validate(problem, settings, adaptive::first_modes_of(problem), scan)?;
            // the pairs at the delivered step: the coarse-step estimate (`adaptive`) is measured
            // on inverse runs only, and a servo's loop may not tolerate the coarse step
            // (the reference was scanned once just above: not again per N); no time check, so
            // the delivered run is the last
            adaptive::solve_to_tolerance(problem, tol, None, None, |n, _| {
                integrate_direct(problem, settings, law, n, false, &mut runs)
            })?
        }
    };
    Ok((response, Stats::from_runs(&runs)))
}

/// The rigid state of sliders at `s` [m], `sd` [m/s], `sdd` [m/s^2] at time `t`.
fn rigid_at(star: &Star, s: [f64; 3], sd: [f64; 3], sdd: [f64; 3], t: f64) -> Result<RigidState, AmmError> {
    let sv = [0, 1, 2].map(|i| Dual2::new(s[i], sd[i], sdd[i]));
    star.state_from(sv, t)
}

/// The configuration `s` [m] reached at `t` [s] is feasible, or the run stops there.
fn check_reached(star: &Star, s: [f64; 3], t: f64) -> Result<(), AmmError> {
    star.check_configuration(s)
        .map_err(|violation| AmmError::DirectInfeasible { t, violation })
}

/// Derivatives of the rigid motion's a_G, theta' and theta'' with respect to s''_k, where
/// `s = shat + bp s''` and `s' = sdhat + gp s''` (the terms of order bp dropped):
/// `d a_G = J_G e_k + 2 gp H_G[s', e_k]`, `d theta'' = J_th e_k + 2 gp H_th[s', e_k]`,
/// `d theta' = gp J_th e_k`, with J and the mixed second derivative H[s', e_k] exact from one
/// hyper-dual evaluation of the direct kinematics at `s + eps1 s' + eps2 e_k` per slider.
struct Sensitivity {
    d_ag: [[f64; 2]; 3],
    d_thd: [f64; 3],
    d_thdd: [f64; 3],
}

fn sensitivity(star: &Star, s: [f64; 3], sd: [f64; 3], gp: f64, t: f64) -> Result<Sensitivity, AmmError> {
    let mut out = Sensitivity {
        d_ag: [[0.0; 2]; 3],
        d_thd: [0.0; 3],
        d_thdd: [0.0; 3],
    };
    for k in 0..3 {
        let sv = [0, 1, 2].map(|i| HyperDual64::new(s[i], sd[i], if i == k { 1.0 } else { 0.0 }, 0.0));
        // the paper's Fermat construction on the paper's robot, the apex construction (D1-D3 of
        // docs/as-built.md) on a robot as built
        let pose = flexstar_kinematics::as_built::rigid_pose(star.robot, sv).ok_or_else(|| AmmError::Kinematics {
            t,
            source: flexstar_kinematics::KinematicsError::NoSolution {
                t,
                reason: "no pose of the star at the sliders' configuration".into(),
            },
        })?;
        let (gx, gy, th) = (pose.g[0], pose.g[1], pose.theta);
        // eps2: J e_k; eps1eps2: H[s', e_k]
        out.d_ag[k] = [gx.eps2 + 2.0 * gp * gx.eps1eps2, gy.eps2 + 2.0 * gp * gy.eps1eps2];
        out.d_thdd[k] = th.eps2 + 2.0 * gp * th.eps1eps2;
        out.d_thd[k] = gp * th.eps2;
    }
    Ok(out)
}

/// Buffers of the coupled step: the base solution and one sensitivity per slider.
struct Coupled {
    /// The base solution's forcing, kept for the fixed-point pass (the sensitivities' forcing
    /// derivatives overwrite the system's).
    forcing0: Vec<f64>,
    qdd0: Vec<f64>,
    lam0: Vec<f64>,
    dqdd: [Vec<f64>; 3],
    dlam: [Vec<f64>; 3],
    qnew: Vec<f64>,
}

impl Coupled {
    /// Buffers for `n` coordinates and `n_lam` multipliers.
    fn new(n: usize, n_lam: usize) -> Self {
        Coupled {
            forcing0: vec![0.0; n],
            qdd0: vec![0.0; n],
            lam0: vec![0.0; n_lam],
            dqdd: std::array::from_fn(|_| vec![0.0; n]),
            dlam: std::array::from_fn(|_| vec![0.0; n_lam]),
            qnew: vec![0.0; n],
        }
    }
}

/// One coupled step (module docs): returns s'' and writes q'' and `sys.lam`. `shat`, `sdhat`:
/// the sliders' predictors; `x_pred`: the predicted s''.
#[allow(clippy::too_many_arguments)]
fn coupled_step(
    sys: &mut System,
    rec: &Recorder,
    buf: &mut Coupled,
    law: &dyn ActuatorLaw,
    star: &Star,
    t: f64,
    (bp, gp): (f64, f64),
    (shat, sdhat, x_pred): ([f64; 3], [f64; 3], [f64; 3]),
    (qhat, vhat): (&[f64], &[f64]),
    qdd: &mut [f64],
    rails: Option<&Rails>,
) -> Result<[f64; 3], AmmError> {
    let s = [0, 1, 2].map(|i| shat[i] + bp * x_pred[i]);
    let sd = [0, 1, 2].map(|i| sdhat[i] + gp * x_pred[i]);
    check_reached(star, s, t)?;
    let st = rigid_at(star, s, sd, x_pred, t)?;
    let sens = sensitivity(star, s, sd, gp, t)?;

    // base solution at the predictor, then the sensitivities with the same factors
    if sys.friction.is_some() {
        sys.predict_friction(&st, vhat, (bp, gp));
    }
    sys.prepare(&st, bp, gp, qhat)?;
    base_solution(sys, buf, &st, bp, qhat, vhat);
    for k in 0..3 {
        sys.forcing_derivative(&st, sens.d_ag[k], sens.d_thd[k], sens.d_thdd[k], qhat, vhat);
        sys.solve_prepared(bp, None, &mut buf.dqdd[k]);
        buf.dlam[k].copy_from_slice(&sys.lam);
    }
    let slider = SliderStep {
        law,
        star,
        t,
        s,
        sd,
        x_pred,
        gp,
        bp,
        rails,
    };
    let mut dx = slider_correction(sys, rec, buf, &st, &slider)?;
    compose(sys, buf, dx, qdd);
    if sys.iterates_lagged_accelerations() {
        // the inverse step's fixed-point pass (`System::solve`), so that a direct run inverts an
        // inverse one under gravity: the base solution again with the lagged terms of the
        // accelerations just solved, the sensitivities (independent of them) kept
        sys.restore_forcing(&buf.forcing0);
        sys.refresh_lagged_forcing();
        substitute_base(sys, buf, bp, qhat);
        dx = slider_correction(sys, rec, buf, &st, &slider)?;
        compose(sys, buf, dx, qdd);
    }
    Ok([0, 1, 2].map(|i| x_pred[i] + dx[i]))
}

/// The coupled step's base solution: q'' and the multipliers at the predicted s'' (`buf.qdd0`,
/// `buf.lam0`) and the predicted coordinates `buf.qnew`, with the factors of `System::prepare`.
fn base_solution(sys: &mut System, buf: &mut Coupled, st: &RigidState, bp: f64, qhat: &[f64], vhat: &[f64]) {
    sys.forcing(st, qhat, vhat);
    if sys.iterates_lagged_accelerations() {
        buf.forcing0.copy_from_slice(sys.forcing_values());
    }
    substitute_base(sys, buf, bp, qhat);
}

/// The base solution's substitution with the system's current forcing.
fn substitute_base(sys: &mut System, buf: &mut Coupled, bp: f64, qhat: &[f64]) {
    sys.solve_prepared(bp, Some(qhat), &mut buf.qdd0);
    buf.lam0.copy_from_slice(&sys.lam);
    for (qn, (qh, a)) in buf.qnew.iter_mut().zip(qhat.iter().zip(&buf.qdd0)) {
        *qn = qh + bp * a;
    }
}

/// What the sliders' rows of the coupled step need: the actuator law at time `t` [s], the
/// predicted slider positions `s` [m], rates `sd` [m/s] and accelerations `x_pred` [m/s^2], the
/// integrator's `beta'` [s^2] and `gamma'` [s], and the rails' friction.
struct SliderStep<'a> {
    law: &'a dyn ActuatorLaw,
    star: &'a Star<'a>,
    t: f64,
    s: [f64; 3],
    sd: [f64; 3],
    x_pred: [f64; 3],
    gp: f64,
    bp: f64,
    rails: Option<&'a Rails>,
}

/// Eq. 33 for the correction ds'': (m + kp bp + kd gp) ds'' + dPush/ds'' ds'' = residual, from
/// the base solution and the sensitivities in `buf`.
fn slider_correction(
    sys: &System,
    rec: &Recorder,
    buf: &Coupled,
    st: &RigidState,
    p: &SliderStep,
) -> Result<[f64; 3], AmmError> {
    let t = p.t;
    let fa = p
        .law
        .force(t, p.s, p.sd)
        .map_err(|source| AmmError::Drive { t, source })?;
    let (kp, kd) = (p.law.stiffness(), p.law.damping());
    let mut a = [[0.0; 4]; 3];
    for (i, row) in a.iter_mut().enumerate() {
        // each slider's own sleeve and slider mass (docs/amm.md 13)
        let m = p.star.beam(i).mpp_mpa;
        for (k, dlam) in buf.dlam.iter().enumerate() {
            row[k] = rec.force.sleeve_push(i, st, &buf.qnew, dlam, sys.sleeves.axial());
        }
        row[i] += m + kp[i] * p.bp + kd[i] * p.gp;
        // Eq. 33 with the weight along the rail (Eq. G2)
        row[3] = fa[i] + m * rec.force.gravity_along(i)
            - m * p.x_pred[i]
            - rec.force.sleeve_push(i, st, &buf.qnew, &buf.lam0, sys.sleeves.axial());
        if sys.friction.is_some() || p.rails.is_some() {
            friction_row(
                sys,
                rec,
                buf,
                st,
                i,
                row,
                p.rails.map(|r| (r, p.sd[i], p.x_pred[i], p.gp)),
            );
        }
    }
    solve3(a).ok_or(AmmError::SingularConstraints {
        t,
        source: RankError::Sliders,
    })
}

/// q'' and the multipliers of the corrected step: the base solution plus `dx` times the
/// sensitivities; remembers the lagged accelerations (`System::set_axial_acceleration`).
fn compose(sys: &mut System, buf: &Coupled, dx: [f64; 3], qdd: &mut [f64]) {
    qdd.copy_from_slice(&buf.qdd0);
    sys.lam.copy_from_slice(&buf.lam0);
    for ((dxk, dq), dl) in dx.iter().zip(&buf.dqdd).zip(&buf.dlam) {
        for (q, d) in qdd.iter_mut().zip(dq) {
            *q += dxk * d;
        }
        for (l, d) in sys.lam.iter_mut().zip(dl) {
            *l += dxk * d;
        }
    }
    sys.set_axial_acceleration(qdd);
}

/// Friction in slider i's row of the 3 x 3 system (Eq. F17, `docs/friction.md` 9.1): the
/// sleeve's friction along the rail (`F_fi (e_xi . u_i)`, affine in the multipliers and `u_i''`:
/// its change along each sensitivity in the columns, its base value on the right), and the rail
/// (`rail`: the rails, the slider's predicted speed [m/s] and s'' [m/s^2], gamma' [s]):
/// slipping, `Fc s + b s'` with `b gamma'` on the diagonal; stuck, the row `ds''_i = -s''_pred`.
fn friction_row(
    sys: &System,
    rec: &Recorder,
    buf: &Coupled,
    st: &RigidState,
    i: usize,
    row: &mut [f64; 4],
    rail: Option<(&Rails, f64, f64, f64)>,
) {
    let u = sys.nb * i + sys.nm;
    if sys.friction.is_some() {
        let along = rec.force.along_rail(i, st);
        for (k, (dlam, dqdd)) in buf.dlam.iter().zip(&buf.dqdd).enumerate() {
            row[k] += along * sys.sleeve_friction_force(i, dlam, dqdd[u], false);
        }
        row[3] -= along * sys.sleeve_friction_force(i, &buf.lam0, buf.qdd0[u], true);
    }
    let Some((rails, sd, x_pred, gp)) = rail else {
        return;
    };
    let law = rails.law[i];
    match rails.contacts[i] {
        Contact::Free => {}
        Contact::Slip(s) => {
            row[i] += law.b * gp;
            row[3] -= law.fc * s + law.b * sd;
        }
        Contact::Stuck(_) => {
            *row = [0.0; 4];
            row[i] = 1.0;
            row[3] = -x_pred;
        }
    }
}

/// The force a stuck slider i needs from its rail [N] (Eq. F17 at `s_i'' = 0`) after the step's
/// solve (`sys.lam` its multipliers, `qdd` its accelerations) at the rigid state `st`.
fn rail_need(sys: &System, rec: &Recorder, fa: [f64; 3], st: &RigidState, q: &[f64], qdd: &[f64]) -> [f64; 3] {
    let ff = stick_slip::sleeve_forces(sys, qdd);
    [0, 1, 2].map(|i| {
        let m = rec.force.mass(i);
        fa[i] + m * rec.force.gravity_along(i)
            - rec.force.sleeve_push(i, st, q, &sys.lam, sys.sleeves.axial())
            - ff[i] * rec.force.along_rail(i, st)
    })
}

/// The 3 x 3 system given as augmented rows, by nalgebra's LU with partial pivoting; `None` when
/// it is singular or the solution is not finite.
fn solve3(a: [[f64; 4]; 3]) -> Option<[f64; 3]> {
    let m = nalgebra::Matrix3::from_fn(|i, j| a[i][j]);
    let b = nalgebra::Vector3::from_fn(|i, _| a[i][3]);
    let x = m.lu().solve(&b)?;
    x.iter().all(|v| v.is_finite()).then(|| [x[0], x[1], x[2]])
}

/// [`solve_direct_scanned`] at N = `n_modes`: the system and recorder set up, the consistent start, then
/// generalized-alpha substeps between consecutive stops (output times and snapshots).
fn integrate_direct(
    problem: &Star,
    settings: &AmmSettings,
    law: &dyn ActuatorLaw,
    n_modes: usize,
    scan: bool,
    runs: &mut Vec<(usize, usize)>,
) -> Result<Response, AmmError> {
    let started = std::time::Instant::now();
    let dt_max = validate(problem, settings, n_modes, scan)?;
    let mut steps = 0;
    let mut sys = crate::solver::build_system(settings, n_modes, problem)?;
    let n = sys.dim();

    let out_times = problem.time.output_times();
    let times = shape_times(problem, settings);
    let stops = stops(&out_times, &times.all, 1e-9 * problem.time.dt_out);
    let mut out = DirectOutput {
        rec: Recorder::new(&sys, settings, problem, out_times.len(), times),
        cols: (0..DIRECT_COLUMNS.len())
            .map(|_| Vec::with_capacity(out_times.len()))
            .collect(),
        friction: None,
    };
    sys.set_third_order_step(GenAlpha::new(RHO_INF).beta_prime(dt_max));
    let mut buf = Coupled::new(n, sys.lam.len());
    let mut ctx = StepContext {
        buf: &mut buf,
        law,
        star: problem,
    };

    let (mut state, mut rails) = match problem.friction {
        None => (initial_state(problem, &mut sys, &mut ctx, &out.rec, n, None)?, None),
        Some(fr) => {
            let (state, rails, output) = friction_start(problem, &mut sys, &mut ctx, &out.rec, n, fr)?;
            out.friction = Some(output);
            (state, Some(rails))
        }
    };
    out.record(&sys, &ctx, &stops[0], 0.0, &state)?;

    let ga = GenAlpha::new(RHO_INF);
    let mut scratch = Predictors::new(n);
    for w in stops.windows(2) {
        let (t0, t1) = (w[0].t, w[1].t);
        let nsub = (((t1 - t0) / dt_max) - 1e-9).ceil().max(1.0) as usize;
        let h = (t1 - t0) / nsub as f64;
        for k in 1..=nsub {
            let t = if k == nsub { t1 } else { t0 + k as f64 * h };
            match (rails.as_mut(), out.friction.as_mut()) {
                (Some(rails), Some(output)) => {
                    let step = FrictionStep {
                        rec: &out.rec,
                        ga: &ga,
                        h,
                        t,
                    };
                    step.take(&mut sys, &mut ctx, rails, output, &mut state, &mut scratch)?;
                }
                _ => substep(&mut sys, &mut ctx, &out.rec, &ga, h, t, &mut state, &mut scratch, None)?,
            }
            steps += 1;
        }
        out.record(&sys, &ctx, &w[1], t1, &state)?;
        if flexstar_model::cancel::cancelled() {
            return Err(AmmError::Cancelled { t: t1 });
        }
    }
    runs.push((n_modes, steps));
    let mut resp = out.finish(settings, n_modes, dt_max, started);
    sys.release_contacts();
    // the residual's reference: the static equilibrium where the reference motion rests
    let scale = star_time_scale(problem);
    resp.rest_offset = crate::static_start::rest_offset(&mut sys, problem, scale)?;
    Ok(resp)
}

/// What every coupled step of one run borrows: the step buffers, the actuator law and the robot.
struct StepContext<'a> {
    buf: &'a mut Coupled,
    law: &'a dyn ActuatorLaw,
    star: &'a Star<'a>,
}

/// The state of a direct run at a step: elastic coordinates q [-], their rates and the
/// generalized-alpha acceleration-like variable `acc`, q''; the sliders s [m], s' [m/s], s''
/// [m/s^2] and their `sacc`.
#[derive(Clone)]
struct DirectState {
    q: Vec<f64>,
    v: Vec<f64>,
    acc: Vec<f64>,
    qdd: Vec<f64>,
    s: [f64; 3],
    sd: [f64; 3],
    sdd: [f64; 3],
    sacc: [f64; 3],
}

/// The predictors of one step (elastic part), kept between steps to avoid allocation.
struct Predictors {
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    a_part: Vec<f64>,
}

impl Predictors {
    fn new(n: usize) -> Self {
        Predictors {
            qhat: vec![0.0; n],
            vhat: vec![0.0; n],
            a_part: vec![0.0; n],
        }
    }
}

/// The initial state: s, s' of the trajectory at t = 0, the star at rest elastically (undeformed,
/// or under gravity in the static equilibrium of the start pose with the sliders held, Eq. G4);
/// consistent accelerations of both (bp = gp = 0: the step is linear, the solve exact). `rails`:
/// with friction, the rails' contacts (a stuck slider's s'' is 0).
fn initial_state(
    problem: &Star,
    sys: &mut System,
    ctx: &mut StepContext,
    rec: &Recorder,
    n: usize,
    rails: Option<&Rails>,
) -> Result<DirectState, AmmError> {
    let (mut q, v) = (vec![0.0; n], vec![0.0; n]);
    let mut qdd = vec![0.0; n];
    let jets = problem.jets(0.0)?;
    let (s, sd) = (jets.map(|j| j.v), jets.map(|j| j.d1));
    if problem.gravity != [0.0; 2] {
        let rest = rigid_at(ctx.star, s, [0.0; 3], [0.0; 3], 0.0)?;
        let scale = star_time_scale(ctx.star);
        let free = sys.friction.as_ref().map(|f| f.contacts);
        sys.release_contacts();
        crate::static_start::static_equilibrium(sys, &rest, scale, &mut q)?;
        if let (Some(f), Some(c)) = (sys.friction.as_mut(), free) {
            f.contacts = c;
        }
    }
    let mut x_pred = jets.map(|j| j.d2);
    if let Some(r) = rails {
        for i in (0..3).filter(|&i| r.contacts[i].stuck().is_some()) {
            x_pred[i] = 0.0;
        }
    }
    let sdd = coupled_step(
        sys,
        rec,
        ctx.buf,
        ctx.law,
        ctx.star,
        0.0,
        (0.0, 0.0),
        (s, sd, x_pred),
        (&q, &v),
        &mut qdd,
        rails,
    )?;
    let acc = qdd.clone();
    Ok(DirectState {
        q,
        v,
        acc,
        qdd,
        s,
        sd,
        sdd,
        sacc: sdd,
    })
}

/// One generalized-alpha substep of length `h` ending at `t`: predict q and s, solve the coupled
/// step, correct; a non-finite state stops the run with the time and the step. `rails`: with
/// friction, the rails' contacts (a stuck slider frozen: `s = s*`, `s' = s'' = 0`, Eq. F17).
#[allow(clippy::too_many_arguments)]
fn substep(
    sys: &mut System,
    ctx: &mut StepContext,
    rec: &Recorder,
    ga: &GenAlpha,
    h: f64,
    t: f64,
    x: &mut DirectState,
    p: &mut Predictors,
    rails: Option<&Rails>,
) -> Result<(), AmmError> {
    let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
    let apq = ga.a_per_qdd();
    let predict = |x: f64, xd: f64, xa: f64, xdd: f64| ga.predict(h, x, xd, xa, xdd);
    let n = x.q.len();
    for i in 0..n {
        (p.a_part[i], p.qhat[i], p.vhat[i]) = predict(x.q[i], x.v[i], x.acc[i], x.qdd[i]);
    }
    let mut sa_part = [0.0; 3];
    let (mut shat, mut sdhat) = ([0.0; 3], [0.0; 3]);
    for i in 0..3 {
        (sa_part[i], shat[i], sdhat[i]) = predict(x.s[i], x.sd[i], x.sacc[i], x.sdd[i]);
    }
    let stuck = rails.map_or([None; 3], |r| r.contacts.map(|c| c.stuck()));
    for (i, at) in stuck.iter().enumerate() {
        if let Some(at) = at {
            (shat[i], sdhat[i], x.sdd[i], sa_part[i]) = (*at, 0.0, 0.0, 0.0);
        }
    }
    x.sdd = coupled_step(
        sys,
        rec,
        ctx.buf,
        ctx.law,
        ctx.star,
        t,
        (bp, gp),
        (shat, sdhat, x.sdd),
        (&p.qhat, &p.vhat),
        &mut x.qdd,
        rails,
    )?;
    let mut norm = 0.0;
    for i in 0..n {
        x.q[i] = p.qhat[i] + bp * x.qdd[i];
        x.v[i] = p.vhat[i] + gp * x.qdd[i];
        x.acc[i] = p.a_part[i] + apq * x.qdd[i];
        norm += x.q[i].abs();
    }
    for i in 0..3 {
        x.s[i] = shat[i] + bp * x.sdd[i];
        x.sd[i] = sdhat[i] + gp * x.sdd[i];
        x.sacc[i] = sa_part[i] + apq * x.sdd[i];
        norm += x.s[i].abs() + x.sd[i].abs();
    }
    if !norm.is_finite() {
        return Err(AmmError::NonFinite { t, dt: h });
    }
    Ok(())
}

/// The consistent start with friction (`docs/friction.md` 9.1): the sleeves and sliders at
/// rest stuck, the moving ones slipping, the start solved again (four times) so that the load's
/// signs and a stuck sleeve's `xp''` are those of its own solution, and a contact that cannot
/// hold released (`stick_slip::switching_step`).
fn friction_start(
    problem: &Star,
    sys: &mut System,
    ctx: &mut StepContext,
    rec: &Recorder,
    n: usize,
    law: &flexstar_model::Friction,
) -> Result<(DirectState, Rails, FrictionOutput), AmmError> {
    let jets = problem.jets(0.0)?;
    let (s, sd) = (jets.map(|j| j.v), jets.map(|j| j.d1));
    let mut rails = Rails::start(law, s, sd);
    let st = rigid_at(ctx.star, s, sd, jets.map(|j| j.d2), 0.0)?;
    let zero = vec![0.0; n];
    sys.start_contacts(&st, &zero, &zero);
    let xi_start = stick_slip::coordinates(sys, &st, &zero);
    let mut state = None;
    let end = stick_slip::switching_step(sys, Some(&mut rails), 0.0, 0.0, |sys, rails, _| {
        let mut x = initial_state(problem, sys, ctx, rec, n, rails)?;
        for _ in 0..4 {
            let sdd = coupled_step(
                sys,
                rec,
                ctx.buf,
                ctx.law,
                ctx.star,
                0.0,
                (0.0, 0.0),
                (x.s, x.sd, x.sdd),
                (&x.q, &x.v),
                &mut x.qdd,
                rails,
            )?;
            (x.sdd, x.sacc) = (sdd, sdd);
        }
        x.acc.copy_from_slice(&x.qdd);
        let end = step_end(sys, ctx, rec, &x, (xi_start, s), 0.0)?;
        state = Some(x);
        Ok(end)
    })?;
    let x = state.expect("the start was solved");
    let (ff, vs) = (stick_slip::sleeve_forces(sys, &x.qdd), end.vs);
    let rows = problem.time.output_times().len();
    let output = FrictionOutput::start(sys, ff, vs, rails.power(x.sd), rows);
    Ok((x, rails, output))
}

/// What the judging of a converged direct step reads (`stick_slip::StepEnd`) at its end state
/// `x` and time `t`; `(xi_start, s_start)`: the sleeves' material coordinates and the sliders'
/// positions at the step's start [m].
fn step_end(
    sys: &System,
    ctx: &StepContext,
    rec: &Recorder,
    x: &DirectState,
    (xi_start, s_start): ([f64; 3], [f64; 3]),
    t: f64,
) -> Result<StepEnd, AmmError> {
    let st = rigid_at(ctx.star, x.s, x.sd, x.sdd, t)?;
    let fa = ctx
        .law
        .force(t, x.s, x.sd)
        .map_err(|source| AmmError::Drive { t, source })?;
    Ok(StepEnd {
        xi_start,
        vs: stick_slip::speeds(sys, &st, &x.v),
        s_start,
        sd: x.sd,
        rail_need: rail_need(sys, rec, fa, &st, &x.q, &x.qdd),
    })
}

/// One step of a direct run with friction: [`substep`] with the switching of the contacts.
struct FrictionStep<'a> {
    rec: &'a Recorder,
    ga: &'a GenAlpha,
    h: f64,
    t: f64,
}

impl FrictionStep<'_> {
    /// Take the step from `x` (module doc of `stick_slip`), the friction's tally advanced.
    fn take(
        &self,
        sys: &mut System,
        ctx: &mut StepContext,
        rails: &mut Rails,
        output: &mut FrictionOutput,
        x: &mut DirectState,
        p: &mut Predictors,
    ) -> Result<(), AmmError> {
        let (h, t) = (self.h, self.t);
        let start = x.clone();
        let st0 = rigid_at(ctx.star, x.s, x.sd, x.sdd, t - h)?;
        let starts = (stick_slip::coordinates(sys, &st0, &x.q), x.s);
        let end = stick_slip::switching_step(sys, Some(rails), t, h, |sys, rails, retake| {
            if retake {
                x.clone_from(&start);
                sys.set_axial_acceleration(&start.qdd);
            }
            substep(sys, ctx, self.rec, self.ga, h, t, x, p, rails)?;
            step_end(sys, ctx, self.rec, x, starts, t)
        })?;
        let ff = stick_slip::sleeve_forces(sys, &x.qdd);
        output.advance(sys, (ff, end.vs), (&rails.contacts, rails.power(x.sd)), h);
        Ok(())
    }
}

/// The recorder of a direct run and its [`DIRECT_COLUMNS`] at the output times.
struct DirectOutput {
    rec: Recorder,
    cols: Vec<Vec<f64>>,
    /// With friction: its outputs (`docs/friction.md` 7).
    friction: Option<FrictionOutput>,
}

impl DirectOutput {
    /// Record the state at a stop: the configuration reached is checked (leaving the feasible
    /// range stops the run with the time and the reason), the law's forces evaluated.
    fn record(
        &mut self,
        sys: &System,
        ctx: &StepContext,
        stop: &Stop,
        t: f64,
        x: &DirectState,
    ) -> Result<(), AmmError> {
        let (s, sd, sdd) = (x.s, x.sd, x.sdd);
        check_reached(ctx.star, s, t)?;
        let st = rigid_at(ctx.star, s, sd, sdd, t)?;
        let fa = ctx
            .law
            .force(t, s, sd)
            .map_err(|source| AmmError::Drive { t, source })?;
        self.rec
            .record(&st, stop, &x.q, [&x.v, &x.qdd], &sys.lam, sys.sleeves.axial(), Some(fa));
        if let (Some(out), Some(_)) = (self.friction.as_mut(), stop.output) {
            out.sample(
                sys,
                stick_slip::sleeve_forces(sys, &x.qdd),
                stick_slip::speeds(sys, &st, &x.v),
            );
        }
        if stop.output.is_some() {
            let vals = [s[0], s[1], s[2], sd[0], sd[1], sd[2], st.g[0].v, st.g[1].v, st.theta.v];
            for (c, v) in self.cols.iter_mut().zip(vals) {
                c.push(v);
            }
        }
        Ok(())
    }

    /// The response labelled `amm-<family>-direct`: [`DIRECT_COLUMNS`] first among the extra
    /// columns, the run's info.
    fn finish(self, settings: &AmmSettings, n_modes: usize, dt_max: f64, started: std::time::Instant) -> Response {
        let mut resp = self.rec.finish(format!("amm-{}-direct", settings.family.name()));
        let mut extra: Vec<flexstar_model::Column> = DIRECT_COLUMNS
            .iter()
            .zip(self.cols)
            .map(|(name, values)| flexstar_model::Column {
                name: name.to_string(),
                values,
            })
            .collect();
        extra.append(&mut resp.extra);
        resp.extra = extra;
        if let Some(out) = self.friction {
            out.finish(&mut resp);
        }
        resp.info = crate::solver::run_info("amm-direct", settings, n_modes, dt_max, started);
        resp
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensitivity_matches_finite_differences() {
        // s' = sdhat + gp s'' (bp = 0, the terms the sensitivity drops): the derivatives of a_G,
        // theta', theta'' with respect to s''_k against central differences
        let problem = flexstar_model::catalogue::paper_case(1).problem().unwrap();
        let star = Star::new(&problem);
        let params = star;
        let (s, sdhat, x, gp) = ([0.03, -0.02, 0.05], [0.4, -0.3, 0.6], [2.0, -1.0, 3.0], 0.05);
        let state = |x: [f64; 3]| {
            let sd = [0, 1, 2].map(|i| sdhat[i] + gp * x[i]);
            let st = rigid_at(&params, s, sd, x, 0.0).unwrap();
            [st.g[0].d2, st.g[1].d2, st.theta.d1, st.theta.d2]
        };
        let sd = [0, 1, 2].map(|i| sdhat[i] + gp * x[i]);
        let sens = sensitivity(&params, s, sd, gp, 0.0).unwrap();
        let h = 1e-4;
        for k in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[k] += h;
            xm[k] -= h;
            let (fp, fm) = (state(xp), state(xm));
            let fd: [f64; 4] = std::array::from_fn(|c| (fp[c] - fm[c]) / (2.0 * h));
            let an = [sens.d_ag[k][0], sens.d_ag[k][1], sens.d_thd[k], sens.d_thdd[k]];
            for c in 0..4 {
                assert!(
                    (fd[c] - an[c]).abs() < 1e-7 * (1.0 + fd[c].abs()),
                    "k {k} c {c}: {} vs {}",
                    fd[c],
                    an[c]
                );
            }
            // the gp H[s', e_k] term matters here: J e_k alone is off
            let j_only = rigid_at(
                &params,
                s,
                std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 }),
                [0.0; 3],
                0.0,
            )
            .unwrap();
            assert!(
                (j_only.theta.d1 - fd[3]).abs() > 1e-4,
                "k {k}: the test does not probe the cross term"
            );
        }
    }
}
