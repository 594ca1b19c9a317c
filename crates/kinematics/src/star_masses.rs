//! The rigid inverse dynamics of a robot as built (`docs/as-built.md` 7, Eqs. N1-N6): each
//! beam's own mass and length, so that the star's centre of mass is off G in general, each
//! sleeve's own inertia, each slider's own mass on its own rail.
//!
//! ```text
//! M = sum rho_i L_i,   S = sum (rho_i L_i^2 / 2) e_xi,   I_G = sum rho_i L_i^3 / 3             (N1)
//! (M + m)(a_G - g) + theta'' k x Q - theta'^2 Q               = sum f_i e_wi + F                (N3)
//! (I_G + sum Jp_i + J + m |r|^2) theta'' + Q x (a_G - g)      = sum xp_i f_i + Mz               (N4)
//! Fa_i = m_i (s_i'' - g . u_i) + f_i e_wi . u_i                                                 (N6)
//! ```
//! with `Q = S + m r` the first moment of the star and the payload about G. For the paper's robot
//! `S = 0` and these are the paper's formulas of [`crate::inverse_dynamics`], which
//! [`rigid_inverse_dynamics_of`] keeps for it.

use flexstar_model::{Attachments, Robot, RobotGeometry};

use crate::inverse_dynamics::{rigid_inverse_dynamics_with, sleeve_forces, RigidForces};
use crate::state::{dot, RigidState};

/// The rigid robot's mass data as built (`docs/as-built.md` 7.1, Eq. N1, and the sliders of Eq.
/// N6), 0-based by beam and slider.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StarMasses {
    /// Each beam's mass `rho_i L_i` [kg].
    pub beam_mass: [f64; 3],
    /// Each beam's first moment about G along its axis, `rho_i L_i^2 / 2` [kg m]: S of Eq. N1 is
    /// `sum beam_moment[i] e_xi`.
    pub beam_moment: [f64; 3],
    /// The star's inertia about G with the sleeves turning with it, `I_G + sum Jp_i` [kg m^2]
    /// (Eqs. N1, N4).
    pub inertia: f64,
    /// Each slider's mass with its sleeve, `m_i = mpp_i + mpa_i` [kg] (Eq. N6).
    pub slider_mass: [f64; 3],
    /// Each slider's rail direction `u_i` (unit, fixed frame; `docs/as-built.md` 2).
    pub rail: [[f64; 2]; 3],
}

impl StarMasses {
    /// The mass data of `robot`'s beams, sleeves, sliders and rails (Eq. N1).
    pub fn of(robot: &Robot) -> Self {
        let b = robot.beams();
        let star: f64 = b.iter().map(|b| b.mass_per_length * b.length.powi(3) / 3.0).sum();
        let sleeves: f64 = b.iter().map(|b| b.sleeve_inertia).sum();
        StarMasses {
            beam_mass: b.map(|b| b.mass_per_length * b.length),
            beam_moment: b.map(|b| b.mass_per_length * b.length * b.length / 2.0),
            inertia: star + sleeves,
            slider_mass: b.map(|b| b.sleeve_mass),
            rail: std::array::from_fn(|i| robot.axis(i).direction),
        }
    }

    /// The star's mass M [kg] (Eq. N1).
    pub fn mass(&self) -> f64 {
        self.beam_mass.iter().sum()
    }

    /// The star's first moment about G, S [kg m], fixed frame, at the orientation of `state`
    /// (Eq. N1; its centre of mass is at `G + S / M`).
    pub fn first_moment(&self, state: &RigidState) -> [f64; 2] {
        let mut s = [0.0; 2];
        for (i, m) in self.beam_moment.iter().enumerate() {
            let e = state.e_x(i);
            s[0] += m * e[0];
            s[1] += m * e[1];
        }
        s
    }

    /// Driving forces and sleeve forces of the rigid robot as built carrying `attached`'s
    /// payload, load and gravity at time `state.t` (Eqs. N3-N6) [N].
    pub fn inverse_dynamics(&self, attached: &Attachments, state: &RigidState) -> RigidForces {
        let g = attached.gravity.g;
        let normal = sleeve_forces(state, self.resultant(attached, state));
        let ew = [0, 1, 2].map(|i| state.e_w(i));
        let fa = std::array::from_fn(|i| {
            self.slider_mass[i] * (state.s[i].d2 - dot(g, self.rail[i])) + normal[i] * dot(ew[i], self.rail[i])
        });
        RigidForces { fa, normal }
    }

    /// The resultant `(Fx, Fy, Mz about G)` [N, N, N m] the sleeves must give the star and its
    /// payload: the right-hand side of Eq. N5 from Eqs. N3-N4.
    fn resultant(&self, attached: &Attachments, state: &RigidState) -> [f64; 3] {
        // Eq. G1: the rigid acceleration of G less gravity
        let g = attached.gravity.g;
        let a = [state.g[0].d2 - g[0], state.g[1].d2 - g[1]];
        let (th1, th2) = (state.theta.d1, state.theta.d2);
        let p = &attached.payload;
        // Q = S + m r: the payload's centre of mass at r from G, turned with beam 1
        let (ex, ew) = (state.e_x(0), state.e_w(0));
        let r = [0, 1].map(|c| p.offset[0] * ex[c] + p.offset[1] * ew[c]);
        let s = self.first_moment(state);
        let q = [s[0] + p.mass * r[0], s[1] + p.mass * r[1]];
        let kq = [-q[1], q[0]];
        let [fx, fy, mz] = attached.load.at(state.t);
        let m = self.mass() + p.mass;
        let j = self.inertia + p.inertia_about_g();
        let newton = |c: usize, f: f64| m * a[c] + th2 * kq[c] - th1 * th1 * q[c] - f;
        let euler = j * th2 + (q[0] * a[1] - q[1] * a[0]) - mz;
        [newton(0, fx), newton(1, fy), euler]
    }
}

/// Driving forces of the rigid robot `robot` carrying `attached` at time `state.t` (state from
/// [`RigidState::at`] on the same robot): the paper's formulas
/// ([`rigid_inverse_dynamics_with`], bit for bit as on the paper's compact form) when it is the
/// paper's robot ([`Robot::equal_beams`]), Eqs. N1-N6 of `docs/as-built.md` 7 otherwise.
pub fn rigid_inverse_dynamics_of(robot: &Robot, attached: &Attachments, state: &RigidState) -> RigidForces {
    match robot.paper_form() {
        Some(p) => rigid_inverse_dynamics_with(p, attached, state),
        None => StarMasses::of(robot).inverse_dynamics(attached, state),
    }
}
