//! The payload welded at G in the AMM's step (`docs/amm.md` 11.1, Eqs. P1-P6).
//!
//! The payload's elastic state is read on beam 1's coordinates (index 0 in the code),
//! `z = P q_1 = (u_1, phi(0) . alpha_1, phi'(0) . alpha_1)` [m, m, rad] (Eq. P1), and its
//! generalized inertia force, kept linear in z, is `M_p z'' + D_p z' + K_p z - f_p` (Eqs. P2-P5),
//! componentwise in beam 1's rigid frame `(e_x1, e_w1)` and on the angle psi. Beam 1's equations
//! gain `P^T (M_p P q'' + D_p P q' + K_p P q) = P^T f_p` (Eq. P6); the step matrix gains the
//! rank-3 term `P^T S_p P`, `S_p = M_p + gamma' D_p + beta' K_p`, inverted by Woodbury in the
//! form that needs no `S_p^-1` (`S_p` is singular for a point mass): with `H = P S^-1 P^T`,
//!
//! ```text
//! (S + P^T S_p P)^-1 = S^-1 - S^-1 P^T W P S^-1,     W = (I + S_p H)^-1 S_p.
//! ```
//! `I + S_p H` is singular exactly when `S + P^T S_p P` is (Sylvester's determinant identity).

use flexstar_model::Payload;

/// A 3 x 3 matrix, row-major.
pub(crate) type Mat3 = [[f64; 3]; 3];

/// The rigid-motion quantities Eqs. P3-P5 are linear in: `[a1, a2, theta'', theta', theta'^2]`
/// with `a1 = a_G . e_x1`, `a2 = a_G . e_w1` [m/s^2], theta'' [rad/s^2], theta' [rad/s]
/// (the Coriolis factor of Eq. P3) and `theta'^2` [rad^2/s^2] (the centrifugal terms). A change
/// of the motion `(d a1, d a2, d theta'', d theta', 2 theta' d theta')` in the same slots gives
/// the derivative of the terms exactly (the direct dynamics' sensitivity).
pub(crate) type RigidTerms = [f64; 5];

/// The payload's terms in beam 1's equations (module docs; Eqs. P2-P5) and the Woodbury data of
/// the last prepared step.
#[derive(Debug, Clone)]
pub(crate) struct PayloadTerms {
    /// Mass m [kg].
    m: f64,
    /// Rotational inertia about G, `J + m |o|^2` [kg m^2].
    j_g: f64,
    /// Offset `(ox, oy)` [m] of the centre of mass from G in `(e_x1, e_w1)`.
    o: [f64; 2],
    /// Eq. P2: the rigid-body mass matrix about G on z (constant).
    mass: Mat3,
    /// `W = (I + S_p H)^-1 S_p` of the last prepared step.
    pub(crate) w: Mat3,
    /// `C_0 S^-1 P^T` of the last prepared step: row k of beam 1's constraint rows against the
    /// three payload rows.
    pub(crate) cross: Vec<[f64; 3]>,
    /// `S_p` of the last prepared step ([`PayloadTerms::step_matrix`]): the step's residual
    /// holds `P^T S_p P q''` (`system::kkt`).
    pub(crate) sp: Mat3,
}

impl PayloadTerms {
    /// The terms of `p`, or `None` without a payload (mass and J zero: nothing is added);
    /// `rows`: the constraint rows that touch beam 1.
    pub(crate) fn new(p: &Payload, rows: usize) -> Option<Self> {
        if p.is_none() {
            return None;
        }
        let (m, [ox, oy]) = (p.mass, p.offset);
        let j_g = p.inertia_about_g();
        Some(PayloadTerms {
            m,
            j_g,
            o: p.offset,
            mass: [[m, 0.0, -m * oy], [0.0, m, m * ox], [-m * oy, m * ox, j_g]],
            w: [[0.0; 3]; 3],
            cross: vec![[0.0; 3]; rows],
            sp: [[0.0; 3]; 3],
        })
    }

    /// Eqs. P3-P5 at the rigid motion `x` ([`RigidTerms`]): the gyroscopic matrix `D_p`
    /// [kg/s], the stiffness `K_p` [kg/s^2] (centrifugal, theta'' couplings, the pendulum term
    /// `-m (o . a_G)` on psi) and the rigid inertia forcing `f_p` [N, N, N m].
    pub(crate) fn rates(&self, [a1, a2, thdd, thd, thd2]: RigidTerms) -> (Mat3, Mat3, [f64; 3]) {
        let (m, [ox, oy]) = (self.m, self.o);
        let c = 2.0 * m * thd;
        let d = [[0.0, -c, -c * ox], [c, 0.0, -c * oy], [c * ox, c * oy, 0.0]];
        let k = [
            [-m * thd2, -m * thdd, m * (-thdd * ox + thd2 * oy)],
            [m * thdd, -m * thd2, m * (-thdd * oy - thd2 * ox)],
            [
                m * (thdd * ox + thd2 * oy),
                m * (thdd * oy - thd2 * ox),
                -m * (ox * a1 + oy * a2),
            ],
        ];
        let f = [
            -m * (a1 - thdd * oy - thd2 * ox),
            -m * (a2 + thdd * ox - thd2 * oy),
            -(m * (ox * a2 - oy * a1) + self.j_g * thdd),
        ];
        (d, k, f)
    }

    /// The payload's part of the step's forcing, `f_p - D_p z_v - K_p z_q` (Eq. P6) [N, N, N m],
    /// for `z_q = P qhat`, `z_v = P vhat`. Linear in `x`, so at a change of the motion it is the
    /// derivative of the forcing ([`RigidTerms`]).
    pub(crate) fn forcing(&self, x: RigidTerms, zq: [f64; 3], zv: [f64; 3]) -> [f64; 3] {
        let (d, k, f) = self.rates(x);
        std::array::from_fn(|a| f[a] - (0..3).map(|b| d[a][b] * zv[b] + k[a][b] * zq[b]).sum::<f64>())
    }

    /// Set `W = (I + S_p H)^-1 S_p` for the step's `S_p` ([`PayloadTerms::sp`], set from
    /// [`PayloadTerms::step_matrix`]) and `H = P S^-1 P^T`; `false` when `I + S_p H` is singular
    /// (so is beam 1's step matrix).
    pub(crate) fn set_woodbury(&mut self, h: &Mat3) -> bool {
        let sp = nalgebra::Matrix3::from_fn(|a, b| self.sp[a][b]);
        let hm = nalgebra::Matrix3::from_fn(|a, b| h[a][b]);
        let lhs = nalgebra::Matrix3::identity() + sp * hm;
        // nalgebra inverts a 3 x 3 in closed form (its determinant tested against zero)
        match lhs.try_inverse().map(|inv| inv * sp) {
            Some(w) if w.iter().all(|v| v.is_finite()) => {
                self.w = std::array::from_fn(|a| std::array::from_fn(|b| w[(a, b)]));
                true
            }
            _ => false,
        }
    }

    /// The payload's step matrix `S_p = c_m M_p + gp D_p + bp K_p` at the rigid motion `x`
    /// (Eqs. P2-P6; `c_m = 1 + gp alpha` with mass-proportional damping, Eq. D19, else 1).
    pub(crate) fn step_matrix(&self, x: RigidTerms, (bp, gp, c_m): (f64, f64, f64)) -> Mat3 {
        let (d, k, _) = self.rates(x);
        std::array::from_fn(|a| std::array::from_fn(|b| c_m * self.mass[a][b] + gp * d[a][b] + bp * k[a][b]))
    }

    /// Eq. P2, the payload's mass matrix on z.
    pub(crate) fn mass_matrix(&self) -> Mat3 {
        self.mass
    }

    /// `W z` for a 3-vector z.
    pub(crate) fn apply_w(&self, z: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| (0..3).map(|b| self.w[a][b] * z[b]).sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_mass_at_g_has_the_beams_structure() {
        // docs/amm.md 11.1: for o = 0 the rows are a point mass m at G (u row -2 m th' w',
        // w row +2 m th' u' + m th'' u), J only in the psi row
        let p = PayloadTerms::new(
            &Payload {
                mass: 2.0,
                j: 0.5,
                offset: [0.0, 0.0],
            },
            3,
        )
        .unwrap();
        let (d, k, f) = p.rates([1.0, 2.0, 3.0, 4.0, 16.0]);
        assert_eq!(d, [[0.0, -16.0, 0.0], [16.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        assert_eq!(k, [[-32.0, -6.0, 0.0], [6.0, -32.0, 0.0], [0.0, 0.0, 0.0]]);
        assert_eq!(f, [-2.0, -4.0, -1.5]);
        // D_p is skew, M_p symmetric, for any offset
        let p = PayloadTerms::new(
            &Payload {
                mass: 2.0,
                j: 0.5,
                offset: [0.1, -0.3],
            },
            3,
        )
        .unwrap();
        let (d, _, _) = p.rates([1.0, 2.0, 3.0, 4.0, 16.0]);
        for (a, b) in (0..3).flat_map(|a| (0..3).map(move |b| (a, b))) {
            assert_eq!(d[a][b], -d[b][a]);
            assert_eq!(p.mass[a][b], p.mass[b][a]);
        }
    }

    #[test]
    fn woodbury_inverts_the_updated_matrix() {
        // S = diag(2, 3, 5) standing in for P S^-1 P^T's context: (S + S_p)^-1 against
        // S^-1 - S^-1 W S^-1 with H = S^-1 (P the identity)
        let mut p = PayloadTerms::new(
            &Payload {
                mass: 1.5,
                j: 0.2,
                offset: [0.05, 0.02],
            },
            3,
        )
        .unwrap();
        let x = [0.3, -0.2, 1.1, 0.7, 0.49];
        let (bp, gp) = (1e-3, 0.05);
        let s = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(2.0, 3.0, 5.0));
        let s_inv = s.try_inverse().unwrap();
        let h: Mat3 = std::array::from_fn(|a| std::array::from_fn(|b| s_inv[(a, b)]));
        p.sp = p.step_matrix(x, (bp, gp, 1.0));
        assert!(p.set_woodbury(&h));
        let (d, k, _) = p.rates(x);
        let sp = nalgebra::Matrix3::from_fn(|a, b| p.mass[a][b] + gp * d[a][b] + bp * k[a][b]);
        let exact = (s + sp).try_inverse().unwrap();
        let w = nalgebra::Matrix3::from_fn(|a, b| p.w[a][b]);
        let wood = s_inv - s_inv * w * s_inv;
        assert!((exact - wood).norm() < 1e-14 * exact.norm(), "{exact} {wood}");
    }
}
