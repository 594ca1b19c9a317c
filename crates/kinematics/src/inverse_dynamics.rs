//! Rigid-body inverse dynamics of star + sleeves + sliders: the driving forces the robot needs if
//! the star were rigid. The flexible models must reach it in the stiff limit.
//!
//! Unknowns: the normal force `f_i e_wi` that sleeve i exerts on the star (frictionless, so no
//! component along the beam; it passes through the pin, which lies on the beam). Each sleeve
//! turns with the star (theta_pi = 0), so the moment it exerts on the star is `-Jp theta''`.
//! Newton-Euler for the star about its centre of mass G (sum of e_xi is zero):
//!
//! ```text
//! 3 rho L a_G                      = sum_i f_i e_wi
//! (rho L^3 + 3 Jp) theta''         = sum_i xp_i f_i
//! ```
//! and for slider i (mass mpp + mpa along u_i), Eq. 33 with `e_wi . u_i = cos(theta)`:
//! `Fa_i = (mpp + mpa) s_i'' + f_i e_wi . u_i`.
//!
//! With a payload welded at G (mass m, inertia J about its centre of mass at `r = ox e_x1 +
//! oy e_w1` from G) and a load `(F, Mz)` at G, Newton for the whole and Euler about G
//! (`docs/amm.md` 11.1, Eqs. P7-P8):
//!
//! ```text
//! (3 rho L + m) a_G + m (theta'' k x r - theta'^2 r)        = sum_i f_i e_wi + F
//! (rho L^3 + 3 Jp + J + m |r|^2) theta'' + m (r x a_G)      = sum_i xp_i f_i + Mz
//! ```
//! Under gravity g (`docs/as-built.md` 5, Eqs. G1-G3) every weight is a uniform acceleration of
//! the base opposite to g: `a_G` reads `a_G - g` in both, and `s_i''` reads `s_i'' - g . u_i` in
//! Eq. 33 (the sleeve and the slider, whose centre of mass is on the pin, weigh on the rail).

use flexstar_model::geometry::slider_direction;
use flexstar_model::{Attachments, RobotParams};
use nalgebra::{Matrix3, Vector3};

use crate::state::{dot, RigidState};

/// Forces of the rigid robot at one instant [N].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidForces {
    /// Driving force of actuator i along +s_i (Eq. 33).
    pub fa: [f64; 3],
    /// Normal force of sleeve i on the star along e_wi (`Fp + FL + FR` of Eq. 33).
    pub normal: [f64; 3],
}

/// Driving forces of the rigid robot (Eq. 33 with a rigid star and `theta_pi = 0`), the paper's
/// bare star (no payload, no load). `params` is read in the paper's compact form (its `as_built`
/// is not read): a robot as built takes [`crate::rigid_inverse_dynamics_of`].
pub fn rigid_inverse_dynamics(params: &RobotParams, state: &RigidState) -> RigidForces {
    let a = state.a_g();
    let m = params.star_mass();
    let j = params.star_inertia() + 3.0 * params.jp;
    forces_for(params, state, [m * a[0], m * a[1], j * state.theta.d2])
}

/// Driving forces of the rigid robot carrying `attached`'s payload and load at time `state.t`
/// (Eqs. P7-P8 and Eq. 33); the bare star's [`rigid_inverse_dynamics`] when there is neither.
/// The paper's compact form, as [`rigid_inverse_dynamics`]; a robot as built takes
/// [`crate::rigid_inverse_dynamics_of`] (`docs/as-built.md` 7).
pub fn rigid_inverse_dynamics_with(params: &RobotParams, attached: &Attachments, state: &RigidState) -> RigidForces {
    if attached.is_none() {
        return rigid_inverse_dynamics(params, state);
    }
    // Eq. G1: the rigid acceleration of G less gravity
    let g = attached.gravity.g;
    let a = state.a_g();
    let a = [a[0] - g[0], a[1] - g[1]];
    let (th1, th2) = (state.theta.d1, state.theta.d2);
    let p = &attached.payload;
    let (ex, ew) = (state.e_x(0), state.e_w(0));
    // r: the payload's centre of mass from G, fixed frame; k x r a quarter turn of it
    let r = [0, 1].map(|c| p.offset[0] * ex[c] + p.offset[1] * ew[c]);
    let kr = [-r[1], r[0]];
    let [fx, fy, mz] = attached.load.at(state.t);
    let m = params.star_mass() + p.mass;
    let j = params.star_inertia() + 3.0 * params.jp + p.inertia_about_g();
    let newton = |c: usize, f: f64| m * a[c] + p.mass * (th2 * kr[c] - th1 * th1 * r[c]) - f;
    let euler = j * th2 + p.mass * (r[0] * a[1] - r[1] * a[0]) - mz;
    let mut forces = forces_for(params, state, [newton(0, fx), newton(1, fy), euler]);
    // Eq. G2: the sleeve and slider's weight along the rail
    for (i, fa) in forces.fa.iter_mut().enumerate() {
        *fa -= params.mpp_mpa * dot(g, slider_direction(i));
    }
    forces
}

/// The sleeves' normal forces that give the star the resultant `rhs = (Fx, Fy, Mz about G)` [N,
/// N, N m], and the driving forces of Eq. 33 with them.
fn forces_for(params: &RobotParams, state: &RigidState, rhs: [f64; 3]) -> RigidForces {
    let ew = [0, 1, 2].map(|i| state.e_w(i));
    let normal = sleeve_forces(state, rhs);
    let fa = [0, 1, 2].map(|i| params.mpp_mpa * state.s[i].d2 + normal[i] * dot(ew[i], slider_direction(i)));
    RigidForces { fa, normal }
}

/// The sleeves' normal forces `f_i` [N] along `e_wi` that give the star the resultant `rhs =
/// (Fx, Fy, Mz about G)` [N, N, N m]: `sum f_i e_wi = (Fx, Fy)`, `sum xp_i f_i = Mz` (the system
/// of Eqs. P7-P8, `docs/as-built.md` Eq. N5 for any weld angles).
pub(crate) fn sleeve_forces(state: &RigidState, rhs: [f64; 3]) -> [f64; 3] {
    let ew = [0, 1, 2].map(|i| state.e_w(i));
    let rows = [
        [ew[0][0], ew[1][0], ew[2][0], rhs[0]],
        [ew[0][1], ew[1][1], ew[2][1], rhs[1]],
        [state.xp[0].v, state.xp[1].v, state.xp[2].v, rhs[2]],
    ];
    solve3(rows)
}

/// Cramer's rule for a 3x3 system given as augmented rows, on nalgebra's determinant (the
/// matrix is well conditioned whenever the pose exists: its determinant is
/// `xp_1 sin(g_23) + xp_2 sin(g_31) + xp_3 sin(g_12) > 0`, `docs/as-built.md` 7.4).
fn solve3(r: [[f64; 4]; 3]) -> [f64; 3] {
    let a = Matrix3::from_fn(|i, j| r[i][j]);
    let b = Vector3::from_fn(|i, _| r[i][3]);
    let d = a.determinant();
    [0, 1, 2].map(|c| {
        let mut with_b = a;
        with_b.set_column(c, &b);
        with_b.determinant() / d
    })
}
