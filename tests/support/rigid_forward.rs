//! Rigid-body forward dynamics of the 3-DOF robot: the reference for the direct runs' stiff limit
//! (test support: included by the tests of drive, amm, fem and modal with `#[path]`; no library
//! code uses it).
//!
//! Independent of [`flexstar_kinematics::rigid_inverse_dynamics`] (Newton-Euler with the sleeves'
//! normal forces as unknowns): here the equations come from the principle of virtual power with
//! the sliders as generalised coordinates `q = s` [m] and the exact Jacobians of the Fermat-point
//! direct kinematics (Eqs. 4-10), differentiated by dual numbers:
//!
//! `(mpp+mpa) s'' + m J_G^T G'' + (J_star + 3 Jp) j_th theta'' = Fa`,
//! with `G'' = J_G s'' + s'^T H_G s'`, `theta'' = j_th . s'' + s'^T H_th s'`,
//!
//! `m = 3 rho L` the star's mass, `J_star = rho L^3` its inertia about G, `J_G = dG/ds` (2 x 3),
//! `j_th = dtheta/ds` (3). The sleeves turn with the star (rigid limit: `theta_p = 0`), their
//! translating mass is in `mpp_mpa`, as in Eq. 33. Integrated by the classical fourth-order
//! Runge-Kutta scheme at a fixed step.
//!
//! A payload welded at G (mass m_p at `c = G + r`, `r = R(theta) o`, inertia J_p) and a load
//! `(F, Mz)` at G add (`docs/amm.md` 11.1, Eq. P9), with `J_c = J_G + (k x r) j_th^T`:
//! `mass += m_p J_c^T J_c + J_p j_th j_th^T`,
//! `rhs += -m_p J_c^T (s'^T H_G s' + (k x r) s'^T H_th s' - theta'^2 r) - J_p j_th s'^T H_th s'
//! + J_G^T F + j_th Mz`.

use flexstar_kinematics::{check_configuration, direct_kinematics, Violation};
use flexstar_model::{Attachments, RobotParams};
use nalgebra::{Matrix3, Vector3};
use num_dual::{Dual2, DualSVec64};

use flexstar_drive::{ActuatorLaw, DriveError};

/// One sample of a rigid forward-dynamics run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidSample {
    /// Time [s].
    pub t: f64,
    /// Slider positions [m].
    pub s: [f64; 3],
    /// Slider speeds [m/s].
    pub v: [f64; 3],
    /// Actuator forces applied [N].
    pub fa: [f64; 3],
}

/// Errors of the rigid forward dynamics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ForwardError {
    /// The motion reached a limit of the feasible range.
    #[error("rigid forward dynamics: infeasible at t = {t:.6} s: {violation}")]
    Infeasible { t: f64, violation: Violation },
    /// The rigid accelerations could not be computed at time `t`.
    #[error("rigid forward dynamics: infeasible at t = {t:.6} s: {reason}")]
    Singular { t: f64, reason: Singular },
    /// The drive could not be evaluated.
    #[error("rigid forward dynamics: {0}")]
    Drive(#[from] DriveError),
    /// Bad step or span.
    #[error("rigid forward dynamics: {0}")]
    Input(String),
}

/// Why [`rigid_acceleration`] has no answer at a state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Singular {
    /// The sliders' positions have no Fermat point (Eqs. 4-10).
    #[error("no Fermat point")]
    NoFermatPoint,
    /// The mass matrix of the virtual-power equations is not positive definite.
    #[error("the rigid mass matrix is not positive definite")]
    MassMatrix,
}

/// Accelerations `s''` [m/s^2] of the rigid robot at state (`s`, `v`) under forces `fa` [N].
pub fn rigid_acceleration(params: &RobotParams, s: [f64; 3], v: [f64; 3], fa: [f64; 3]) -> Result<[f64; 3], Singular> {
    rigid_acceleration_with(params, &Attachments::default(), 0.0, s, v, fa)
}

/// Accelerations `s''` [m/s^2] of the rigid robot carrying `attached` at time `t` [s] (the
/// load's time) and state (`s`, `v`) under forces `fa` [N] (Eq. P9).
pub fn rigid_acceleration_with(
    params: &RobotParams,
    attached: &Attachments,
    t: f64,
    s: [f64; 3],
    v: [f64; 3],
    fa: [f64; 3],
) -> Result<[f64; 3], Singular> {
    let (jg, jth) = jacobians(params, s)?;
    let (kg, kth, theta) = quadratic_terms(params, s, v)?;
    let m = params.star_mass();
    let j = params.star_inertia() + 3.0 * params.jp;
    let mut mass = Matrix3::identity() * params.mpp_mpa + jg.transpose() * jg * m + jth * jth.transpose() * j;
    let mut rhs = Vector3::from(fa) - jg.transpose() * kg * m - jth * (kth * j);
    if !attached.is_none() {
        let p = &attached.payload;
        let (ex, ew) = (
            flexstar_model::geometry::e_x(0, theta),
            flexstar_model::geometry::e_w(0, theta),
        );
        let r = nalgebra::Vector2::new(
            p.offset[0] * ex[0] + p.offset[1] * ew[0],
            p.offset[0] * ex[1] + p.offset[1] * ew[1],
        );
        let kr = nalgebra::Vector2::new(-r[1], r[0]);
        let jc = jg + kr * jth.transpose();
        let omega = jth.dot(&Vector3::from(v));
        let quad = kg + kr * kth - r * (omega * omega);
        let [fx, fy, mz] = attached.load.at(t);
        mass += jc.transpose() * jc * p.mass + jth * jth.transpose() * p.j;
        rhs += -(jc.transpose() * quad * p.mass) - jth * (kth * p.j)
            + jg.transpose() * nalgebra::Vector2::new(fx, fy)
            + jth * mz;
    }
    let a = mass.cholesky().ok_or(Singular::MassMatrix)?.solve(&rhs);
    Ok([a[0], a[1], a[2]])
}

type Jacobians = (nalgebra::Matrix2x3<f64>, Vector3<f64>);

/// `J_G = dG/ds` (2 x 3) and `j_th = dtheta/ds` at `s`.
pub fn jacobians(params: &RobotParams, s: [f64; 3]) -> Result<Jacobians, Singular> {
    let sd: [DualSVec64<3>; 3] = [0, 1, 2].map(|k| DualSVec64::from_re(s[k]).derivative(k));
    let pose = direct_kinematics(params.d, sd).ok_or(Singular::NoFermatPoint)?;
    let grad = |x: &DualSVec64<3>| {
        let e = x.eps.unwrap_generic(nalgebra::Const::<3>, nalgebra::Const::<1>);
        Vector3::new(e[0], e[1], e[2])
    };
    let (gx, gy) = (grad(&pose.g[0]), grad(&pose.g[1]));
    let jg = nalgebra::Matrix2x3::from_rows(&[gx.transpose(), gy.transpose()]);
    Ok((jg, grad(&pose.theta)))
}

/// `s'^T H s'` for G (2-vector) and theta: the accelerations at `s'' = 0`; and theta [rad].
fn quadratic_terms(
    params: &RobotParams,
    s: [f64; 3],
    v: [f64; 3],
) -> Result<(nalgebra::Vector2<f64>, f64, f64), Singular> {
    let sd: [Dual2<f64>; 3] = [0, 1, 2].map(|k| Dual2::new(s[k], v[k], 0.0));
    let pose = direct_kinematics(params.d, sd).ok_or(Singular::NoFermatPoint)?;
    Ok((
        nalgebra::Vector2::new(pose.g[0].v2, pose.g[1].v2),
        pose.theta.v2,
        pose.theta.re,
    ))
}

/// Integrate from (`s0`, `v0`) at t = 0 to `t_end` [s] under `law`, with RK4 steps of at most
/// `dt_max` [s], sampling every `dt_out` [s] (the step is shortened so that samples fall on steps).
///
/// Every step's configuration is checked against the feasible range; the run stops at the first
/// step outside it with the time and the limit.
pub fn rigid_forward_dynamics(
    params: &RobotParams,
    s0: [f64; 3],
    v0: [f64; 3],
    law: &dyn ActuatorLaw,
    t_end: f64,
    dt_out: f64,
    dt_max: f64,
) -> Result<Vec<RigidSample>, ForwardError> {
    let bare = Attachments::default();
    rigid_forward_dynamics_with(params, &bare, s0, v0, law, t_end, dt_out, dt_max)
}

/// [`rigid_forward_dynamics`] of the robot carrying `attached`'s payload and load (Eq. P9).
#[allow(clippy::too_many_arguments)]
pub fn rigid_forward_dynamics_with(
    params: &RobotParams,
    attached: &Attachments,
    s0: [f64; 3],
    v0: [f64; 3],
    law: &dyn ActuatorLaw,
    t_end: f64,
    dt_out: f64,
    dt_max: f64,
) -> Result<Vec<RigidSample>, ForwardError> {
    if !(t_end > 0.0 && dt_out > 0.0 && dt_max > 0.0 && t_end.is_finite() && dt_out <= t_end) {
        return Err(ForwardError::Input(format!(
            "need 0 < dt_out <= t_end and dt_max > 0, got t_end = {t_end}, dt_out = {dt_out}, dt_max = {dt_max}"
        )));
    }
    let n_out = (t_end / dt_out).round() as usize;
    let sub = (dt_out / dt_max).ceil().max(1.0) as usize;
    let h = dt_out / sub as f64;
    let mut x = State { s: s0, v: v0 };
    let mut out = Vec::with_capacity(n_out + 1);
    out.push(RigidSample {
        t: 0.0,
        s: x.s,
        v: x.v,
        fa: law.force(0.0, x.s, x.v)?,
    });
    for k in 0..n_out {
        for j in 0..sub {
            let t = k as f64 * dt_out + j as f64 * h;
            x = rk4_step((params, attached), law, t, x, h)?;
            check_configuration(params, x.s).map_err(|violation| ForwardError::Infeasible { t: t + h, violation })?;
        }
        let t = (k + 1) as f64 * dt_out;
        out.push(RigidSample {
            t,
            s: x.s,
            v: x.v,
            fa: law.force(t, x.s, x.v)?,
        });
    }
    Ok(out)
}

#[derive(Debug, Clone, Copy)]
struct State {
    s: [f64; 3],
    v: [f64; 3],
}

/// The robot and what it carries.
type Robot<'a> = (&'a RobotParams, &'a Attachments);

fn rate(robot: Robot<'_>, law: &dyn ActuatorLaw, t: f64, x: State) -> Result<State, ForwardError> {
    let fa = law.force(t, x.s, x.v)?;
    let a = rigid_acceleration_with(robot.0, robot.1, t, x.s, x.v, fa)
        .map_err(|reason| ForwardError::Singular { t, reason })?;
    Ok(State { s: x.v, v: a })
}

fn rk4_step(params: Robot<'_>, law: &dyn ActuatorLaw, t: f64, x: State, h: f64) -> Result<State, ForwardError> {
    let add = |x: State, k: State, c: f64| State {
        s: [0, 1, 2].map(|i| x.s[i] + c * k.s[i]),
        v: [0, 1, 2].map(|i| x.v[i] + c * k.v[i]),
    };
    let k1 = rate(params, law, t, x)?;
    let k2 = rate(params, law, t + h / 2.0, add(x, k1, h / 2.0))?;
    let k3 = rate(params, law, t + h / 2.0, add(x, k2, h / 2.0))?;
    let k4 = rate(params, law, t + h, add(x, k3, h))?;
    Ok(State {
        s: [0, 1, 2].map(|i| x.s[i] + h / 6.0 * (k1.s[i] + 2.0 * k2.s[i] + 2.0 * k3.s[i] + k4.s[i])),
        v: [0, 1, 2].map(|i| x.v[i] + h / 6.0 * (k1.v[i] + 2.0 * k2.v[i] + 2.0 * k3.v[i] + k4.v[i])),
    })
}
