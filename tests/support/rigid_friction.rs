//! Rigid-body inverse dynamics of the paper's robot with friction in the sleeves and on the
//! rails: the reference for the stiff limit of both solvers with friction (`docs/friction.md` 4;
//! test support, no library code uses it).
//!
//! Independent of the solvers and of `flexstar_kinematics::rigid_inverse_dynamics` (which has no
//! friction): Newton-Euler on the rigid star with the sleeves' normal forces `N_i` (along `e_wi`,
//! on the beam) as unknowns and the friction on each beam along `e_xi` at its sleeve,
//! `F_i = mu |N_i| sign(v_i) + c v_i`, `v_i = xp_i'` (Eqs. F1, F5; the normal-load model, F3's
//! "normal"):
//!
//! - Newton: `m (a_G - g) = sum_i (N_i e_wi + F_i e_xi)`, `m = 3 rho L`;
//! - Euler about G: `(rho L^3 + 3 Jp) theta'' = sum_i xp_i N_i` (friction acts along the beam
//!   through G; the sleeves turn with the star and their couple is `-Jp theta''`);
//! - each slider along its axis `u_i`: `Fa_i = mpp_mpa (s_i'' - g . u_i) + (N_i e_wi + F_i e_xi) .
//!   u_i + F_ri`, the rail's `F_ri = Fc sign(s_i') + b s_i'` (Eqs. F4, F12).
//!
//! With the signs `sigma_i` of the `N_i` fixed, `|N_i| = sigma_i N_i` and the first two are a
//! linear 3 x 3 system; the signs are iterated to a consistent set.

use flexstar_kinematics::RigidState;
use flexstar_model::{RobotGeometry, RobotParams};
use nalgebra::{Matrix3, Vector3};

/// The friction laws of the reference, the same on the three sleeves and rails.
#[derive(Debug, Clone, Copy, Default)]
pub struct Laws {
    /// Sleeves: Coulomb coefficient and viscous coefficient [N s/m].
    pub mu: f64,
    pub c: f64,
    /// Rails: Coulomb force [N] and viscous coefficient [N s/m].
    pub fc: f64,
    pub b: f64,
}

/// The actuator forces [N] of the rigid robot `p` in the state `st` under gravity `g` [m/s^2]
/// with the sleeves' and rails' friction `laws` (`Laws::default()`: none); `None` when the signs
/// of the normal forces do not settle (a sleeve whose normal force is near zero).
pub fn rigid_forces(p: &RobotParams, st: &RigidState, g: [f64; 2], laws: Laws) -> Option<[f64; 3]> {
    let m = 3.0 * p.rho * p.l;
    let inertia = p.rho * p.l.powi(3) + 3.0 * p.jp;
    let a = [st.g[0].d2 - g[0], st.g[1].d2 - g[1]];
    let (ex, ew) = ([0, 1, 2].map(|i| st.e_x(i)), [0, 1, 2].map(|i| st.e_w(i)));
    let speed = [0, 1, 2].map(|i| st.xp[i].d1);
    let slide = speed.map(f64::signum);
    let viscous = speed.map(|v| laws.c * v);
    let mut sigma = [1.0; 3];
    for _ in 0..20 {
        let mut lhs = Matrix3::zeros();
        let mut rhs = Vector3::new(m * a[0], m * a[1], inertia * st.theta.d2);
        for i in 0..3 {
            let k = laws.mu * sigma[i] * slide[i];
            lhs[(0, i)] = ew[i][0] + k * ex[i][0];
            lhs[(1, i)] = ew[i][1] + k * ex[i][1];
            lhs[(2, i)] = st.xp[i].v;
            rhs[0] -= viscous[i] * ex[i][0];
            rhs[1] -= viscous[i] * ex[i][1];
        }
        let n = lhs.lu().solve(&rhs)?;
        let next = [0, 1, 2].map(|i| n[i].signum());
        if next == sigma || laws.mu == 0.0 {
            return Some(std::array::from_fn(|i| {
                let f = laws.mu * n[i].abs() * slide[i] + viscous[i];
                let on_beam = [n[i] * ew[i][0] + f * ex[i][0], n[i] * ew[i][1] + f * ex[i][1]];
                let u = p.axis(i).direction;
                let rail = laws.fc * st.s[i].d1.signum() + laws.b * st.s[i].d1;
                p.mpp_mpa * (st.s[i].d2 - g[0] * u[0] - g[1] * u[1]) + on_beam[0] * u[0] + on_beam[1] * u[1] + rail
            }));
        }
        sigma = next;
    }
    None
}
