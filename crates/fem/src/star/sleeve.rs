//! The sleeve: the passive prismatic joint through which beam i slides, a rigid body of
//! rotational inertia `Jp_i` [kg m^2] and length `Lp_i` [m] (beam i's data) pinned at the
//! revolute point `P_i(t) = o_i + s_i(t) u_i` of slider i (Eqs. 1-3 on the paper's base).
//!
//! **Unknowns of sleeve i** (fixed XY frame, SI units; indices [`Star::psi`], [`Star::xi`], the
//! [`SLEEVE_COORDINATES`] after the nodes' `3 n_nodes`):
//! - `psi_i` [rad]: rotation increment of the sleeve's axis from the initial beam direction
//!   `gamma0_i` (the angle of `e_xi(theta0)`), inertia Jp: `Jp psi_i'' + (Phi_q^T lambda)_psi = 0`;
//! - `xi_ic, xi_il, xi_ir` [m]: material coordinates on beam i (from G) of the sleeve's centre and
//!   its left and right edges; massless, fixed by the constraints alone.
//!
//! **Constraints of sleeve i** ([`ROWS`] = 7 rows, multipliers `lambda` [N, N, N, N, N, N, N m]),
//! with `a = [cos, sin](gamma0_i + psi_i)` the sleeve axis (`docs/fem.md` section 2, the FEM's
//! form of the paper's Eqs. 41-43):
//!
//! ```text
//! r_i(xi_c) - P_i(t)              = 0   (2)  centre on the pin                 (Eq. 41)
//! r_i(xi_l) - P_i(t) + Lp/2 a     = 0   (2)  left edge on the beam             (Eq. 42)
//! r_i(xi_r) - P_i(t) - Lp/2 a     = 0   (2)  right edge on the beam            (Eq. 42)
//! alpha_i(xi_c) - gamma0_i - psi_i = 0   (1)  beam tangent along the sleeve axis (Eq. 43)
//! ```
//!
//! ([`ROW_POINT`]: the contact point of each row.) `r_i(xi)` and `alpha_i(xi)` are the element
//! interpolations of [`crate::element`] in the element that contains `xi`; they are continuous
//! (position and angle) across element boundaries, so a contact point slides from one element
//! into the next without a jump. [`Star::row_terms`] gives each row's value and its Jacobian
//! blocks (element DOFs, contact coordinate, sleeve rotation), [`Star::constraints`] the values
//! alone; [`Star::sleeve_rows`] adds the sleeve's part to the Newton imbalance and matrix (the slot
//! layout of its rows is `pattern.rs`'s, their place in the border `crate::bordered`'s).
//!
//! The tangent row carries the interior-field correction of Eq. S9 (`docs/fem.md` section 2.1,
//! [`Star::interior_compliance`]): the slope that the point moment and force of the sleeve add
//! inside the centre's element, `F_ut P + F_tt C` with the multipliers as loads, which makes the
//! mesh converge at second order where the sleeve's moment is large.
//!
//! **Forces.** The generalized force of the constraints on the beam is `-Phi_q^T lambda`: sleeve i
//! pushes the beam with the point forces `-lambda_c`, `-lambda_l`, `-lambda_r` (fixed frame), and
//! the beam pushes the sleeve, hence its pin and slider, with `F_i = lambda_c + lambda_l +
//! lambda_r` ([`pin_forces`]; Eq. 33 in `crate::integrator`). The post-processing (`solve.rs`)
//! reads the sleeve as `xp_i` = `xi_ic` ([`Star::sleeve_centre`]), `thp_i` = the sleeve angle
//! `gamma0_i + psi_i` ([`Star::sleeve_angle`]) less the rigid beam direction, and `Fn_i = -F_i . e_wi`.
//!
//! **Friction** (`docs/friction.md` 8, `crate::star::friction`). Without friction nothing but
//! the constraints acts on the contact coordinates: the equation of `xi_p` in the Newton
//! imbalance is `res[xi_p] = sum_r (d Phi_r / d xi_p) lambda_r = lambda_p . dr/dxi` (the `gxi * l`
//! terms of [`Star::sleeve_rows`]), which sets to zero the component of each contact force along
//! the beam, and its diagonal slot in the matrix (`vals[off_psi + 4 i + 1 + p]`) is 0. With
//! `[friction]` the centre's equation gains the friction force `F_fi` (Eq. F8: slipping, the law
//! of Eq. F5 with its derivatives in that diagonal slot and in the friction slot group against
//! the sleeve's multipliers), or, stuck, `xi_ic` is frozen (Eq. F9) and the tangential force
//! `lambda_c . dr/dxi` is what the stick needs. The pin force `F_i` carries the tangential part by
//! itself, so Eq. 33 and `Fn_i` need no change.
//!
//! **Direct problem** (`docs/fem.md` section 8): the pins move with the slider unknowns
//! (`P_i = P_i(s_i)`, linear), so the six position rows gain the gradient `-u_i` in `s_i`
//! (`Star::assemble_sliders`).

use super::*;

/// Constraint rows per sleeve.
pub(crate) const ROWS: usize = 7;
/// Contact point of each constraint row: 0 centre, 1 left edge, 2 right edge.
pub(crate) const ROW_POINT: [usize; ROWS] = [0, 0, 1, 1, 2, 2, 0];
/// Coordinates of the three sleeves, after the nodes': three rotations `psi_i`, then the three
/// contact coordinates `xi_ic, xi_il, xi_ir` of each sleeve.
pub(crate) const SLEEVE_COORDINATES: usize = 12;

/// The sleeves' initial coordinates (from `psi0`: three rotations, then the three contact points
/// of each sleeve at xp_i and xp_i -+ Lp_i/2), turning with the star at `init.theta_dot` and
/// sliding at `init.xp_dot`.
pub(super) fn initial_sleeves(robot: &Robot, psi0: usize, init: &InitialState, q: &mut [f64], v: &mut [f64]) {
    for i in 0..3 {
        let lp = robot.beams()[i].sleeve_length;
        v[psi0 + i] = init.theta_dot;
        for (p, off) in [0.0, -0.5 * lp, 0.5 * lp].iter().enumerate() {
            q[psi0 + 3 + 3 * i + p] = init.xp[i] + off;
            v[psi0 + 3 + 3 * i + p] = init.xp_dot[i];
        }
    }
}

/// Force `F_i = lambda_c + lambda_l + lambda_r` the beam exerts on sleeve i, hence on its pin
/// and slider [N], fixed frame.
pub(crate) fn pin_forces(lam: &[f64]) -> [[f64; 2]; 3] {
    [0, 1, 2].map(|i| {
        let l = &lam[ROWS * i..ROWS * i + ROWS];
        [l[0] + l[2] + l[4], l[1] + l[3] + l[5]]
    })
}

impl Star {
    /// Index of the sleeve rotation psi_i.
    pub fn psi(&self, i: usize) -> usize {
        3 * self.n_nodes + i
    }

    /// Index of contact coordinate `p` (0 centre, 1 left, 2 right) of sleeve i.
    pub fn xi(&self, i: usize, p: usize) -> usize {
        3 * self.n_nodes + 3 + 3 * i + p
    }

    /// Material coordinate of sleeve i's centre on its beam [m] (the output `xp_i`).
    pub fn sleeve_centre(&self, i: usize, q: &[f64]) -> f64 {
        q[self.xi(i, 0)]
    }

    /// Absolute angle `gamma0_i + psi_i` of sleeve i's axis [rad] (the output `thp_i` less the
    /// rigid beam direction).
    pub fn sleeve_angle(&self, i: usize, q: &[f64]) -> f64 {
        self.gamma0[i] + q[self.psi(i)]
    }

    /// Kinetic energy of the sleeves' rotations [J] at velocities `v`: `1/2 sum Jp_i psi_i'^2`
    /// (on equal beams `1/2 Jp sum psi_i'^2`, as it was written before per-beam data).
    pub fn sleeve_energy(&self, v: &[f64]) -> f64 {
        let jp = self.robot.beams().map(|b| b.sleeve_inertia);
        if jp[1] == jp[0] && jp[2] == jp[0] {
            return 0.5 * jp[0] * (0..3).map(|i| v[self.psi(i)].powi(2)).sum::<f64>();
        }
        0.5 * (0..3).map(|i| jp[i] * v[self.psi(i)].powi(2)).sum::<f64>()
    }

    /// The sleeves must stay on their beams: every contact point of sleeve i inside (0, L_i) at
    /// time `t` [s].
    pub fn check_on_beams(&self, q: &[f64], t: f64) -> Result<(), FemError> {
        for i in 0..3 {
            let xi = [0, 1, 2].map(|p| q[self.xi(i, p)]);
            flexstar_model::sleeve_contact::on_beam(t, i, xi, self.beam(i).length)?;
        }
        Ok(())
    }

    /// The sleeve part of [`Star::assemble`] for sleeve i: the rotation's inertia, then per
    /// constraint row its value, its gradient times the multiplier into the imbalance and, with
    /// `matrix`, its slots (row block, then transposed block).
    #[inline]
    pub(super) fn sleeve_rows(
        &mut self,
        i: usize,
        it: &Iterate,
        cf: f64,
        compliance: Option<f64>,
        res: &mut [f64],
        matrix: bool,
    ) {
        let Iterate { q, qdd, lam, pins, .. } = *it;
        let ps = self.psi(i);
        let jp = self.beam(i).sleeve_inertia;
        res[ps] += cf * jp * qdd[ps];
        if matrix {
            self.vals[self.off_psi + 4 * i] = jp;
            for p in 0..3 {
                self.vals[self.off_psi + 4 * i + 1 + p] = 0.0;
            }
        }
        // per contact point: the element holding it, its local coordinate and the element's
        // state (recomputed: cheaper than storing every element's state, which at 3000
        // elements leaves the cache)
        let points: [(usize, f64, ElementState); 3] = [0, 1, 2].map(|p| {
            let (e, z) = self.locate(i, q[self.xi(i, p)]);
            let el = &self.elements[i * self.ne + e];
            (e, z, ElementState::new(el, &self.element_q(el, q)))
        });
        for r in 0..ROWS {
            let p = ROW_POINT[r];
            let xi_idx = self.xi(i, p);
            let (e, z, st) = points[p];
            let ge = i * self.ne + e;
            let na = self.node(i, e);
            let (phi, grad, gxi, gpsi) = self.row_terms(&st, [q[3 * na], q[3 * na + 1]], i, q[ps], pins.p[i], r, z);
            let row = self.n_dof + ROWS * i + r;
            let l = lam[ROWS * i + r];
            res[row] = phi;
            if r == ROWS - 1 {
                if let Some(scale) = compliance {
                    res[row] += self.interior_compliance(i, &st, z, lam, scale, matrix);
                }
            }
            let d = dofs(&self.elements[ge]);
            for a in 0..6 {
                res[d[a]] += grad[a] * l;
            }
            res[xi_idx] += gxi * l;
            res[ps] += gpsi * l;
            if !matrix {
                continue;
            }
            // matrix slots: row block then transposed block
            let base = self.off_con + (ROWS * i + r) * 2 * self.ncol_c;
            let lo = self.win[i][p];
            let nc = self.ncol_c;
            self.vals[base..base + 2 * nc].iter_mut().for_each(|x| *x = 0.0);
            let c0 = 3 * (e - lo);
            for a in 0..6 {
                self.vals[base + c0 + a] = grad[a];
                self.vals[base + nc + c0 + a] = grad[a];
            }
            self.vals[base + nc - 2] = gxi;
            self.vals[base + 2 * nc - 2] = gxi;
            self.vals[base + nc - 1] = gpsi;
            self.vals[base + 2 * nc - 1] = gpsi;
        }
    }

    /// Eq. S9 (`docs/fem.md` section 2.1): the slope that the interior field of the centre's
    /// element adds at the contact point under the point moment `C = -lambda_7` and the normal
    /// point force `P = -lambda_c . e2` that the sleeve applies there, `F_ut P + F_tt C`, with the
    /// flexibilities of the element clamped at both nodes (length `h_i`, beam i's `EI_i`, contact at `a = z h`,
    /// `b = h - a`): `F_tt = a b (a^2 - a b + b^2) / (EI h^3)`, `F_ut = a^2 b^2 (b - a) / (2 EI h^3)`.
    /// `scale = 1 / cf` turns the scaled multipliers into forces. With `matrix`, writes the
    /// row's derivatives with respect to the multipliers into the slot group `off_nu`. Returns
    /// the term to add to the tangent row's value [rad].
    fn interior_compliance(
        &mut self,
        i: usize,
        st: &ElementState,
        z: f64,
        lam: &[f64],
        scale: f64,
        matrix: bool,
    ) -> f64 {
        let (f_ut, f_tt) = interior_flexibilities(z, self.h[i], self.beam(i).bending_stiffness());
        let e2 = [-st.s, st.c];
        let k = ROWS * i;
        // the row's derivatives with respect to (nu_7, nu_cx, nu_cy)
        let d = [-f_tt * scale, -f_ut * e2[0] * scale, -f_ut * e2[1] * scale];
        if matrix {
            for (c, v) in d.iter().enumerate() {
                self.vals[self.off_nu + NU_SLOTS * i + c] = *v;
            }
        }
        NU_COLUMNS.iter().zip(d).map(|(&r, dv)| dv * lam[k + r]).sum()
    }

    /// Value, element gradient, contact-coordinate derivative and sleeve-rotation derivative of
    /// constraint row `r` of sleeve i (module docs), for the state `st` of the element holding the
    /// contact point at local coordinate `z`, its first node at `node_a`, the sleeve rotation
    /// `psi` (axis at the angle `gamma0_i + psi`) and the pin `pin`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn row_terms(
        &self,
        st: &ElementState,
        node_a: [f64; 2],
        i: usize,
        psi: f64,
        pin: [f64; 2],
        r: usize,
        z: f64,
    ) -> (f64, [f64; 6], f64, f64) {
        if r < 6 {
            let (k, lp2) = (r % 2, 0.5 * self.beam(i).sleeve_length);
            let ang = self.gamma0[i] + psi;
            let (a, aperp) = ([ang.cos(), ang.sin()], [-ang.sin(), ang.cos()]);
            let pos = st.position(node_a, z);
            let jac = st.jacobian(z);
            let rz = st.dr_dzeta(z);
            let (off, gpsi) = match ROW_POINT[r] {
                0 => (0.0, 0.0),
                1 => (lp2 * a[k], lp2 * aperp[k]),
                _ => (-lp2 * a[k], -lp2 * aperp[k]),
            };
            (pos[k] - pin[k] + off, jac[k], rz[k] / self.h[i], gpsi)
        } else {
            let (al, g, az) = st.angle(z);
            (al - psi, g, az / self.h[i], -1.0)
        }
    }

    /// Constraint values `Phi(q, t)` (21), for the consistent initial accelerations.
    pub fn constraints(&self, q: &[f64], pins: &Pins) -> Vec<f64> {
        let mut out = vec![0.0; 3 * ROWS];
        for i in 0..3 {
            let lp2 = 0.5 * self.beam(i).sleeve_length;
            let ang = self.gamma0[i] + q[self.psi(i)];
            let a = [ang.cos(), ang.sin()];
            for r in 0..ROWS {
                let p = ROW_POINT[r];
                let (e, z) = self.locate(i, q[self.xi(i, p)]);
                let el = &self.elements[i * self.ne + e];
                let st = ElementState::new(el, &self.element_q(el, q));
                let na = self.node(i, e);
                out[ROWS * i + r] = if r < 6 {
                    let k = r % 2;
                    let pos = st.position([q[3 * na], q[3 * na + 1]], z);
                    let off = match p {
                        0 => 0.0,
                        1 => lp2 * a[k],
                        _ => -lp2 * a[k],
                    };
                    pos[k] - pins.p[i][k] + off
                } else {
                    st.angle(z).0 - q[self.psi(i)]
                };
            }
        }
        out
    }
}

/// Flexibilities `(F_ut, F_tt)` of Eq. S9 (`docs/fem.md` section 2.1): the slope at the load
/// point of an element of length `h` [m] and bending stiffness `ei` [N m^2] clamped at both ends,
/// per unit point force (`F_ut` [1/N]) and per unit point moment (`F_tt` [1/(N m)]) at the local
/// coordinate `z` (`a = z h`, `b = h - a`): `F_ut = a^2 b^2 (b - a) / (2 EI h^3)`,
/// `F_tt = a b (a^2 - a b + b^2) / (EI h^3)`; zero at the nodes.
pub(crate) fn interior_flexibilities(z: f64, h: f64, ei: f64) -> (f64, f64) {
    let (a, b) = (z.clamp(0.0, 1.0) * h, (1.0 - z).clamp(0.0, 1.0) * h);
    let den = ei * h * h * h;
    (
        a * a * b * b * (b - a) / (2.0 * den),
        a * b * (a * a - a * b + b * b) / den,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slope at the load point `z` of a clamped-clamped beam (length `h`, stiffness `ei`)
    /// under the point force `force` and moment `moment`, by minimising the discrete energy
    /// `sum EI/2 (second difference)^2 dx - P w(a) - C w'(a)` on `n` intervals (clamped ends by
    /// mirrored ghost nodes; `w'(a)` by a central difference, also for the slope measured).
    fn finite_difference_slope(h: f64, ei: f64, n: usize, z: f64, force: f64, moment: f64) -> f64 {
        let dx = h / n as f64;
        // energy Hessian on the unknowns w_1..w_{n-1} (w_0 = w_n = 0, w_-1 = w_1, w_n+1 = w_n-1)
        let m = n - 1;
        let mut k = vec![vec![0.0; m]; m];
        for node in 0..=n {
            // curvature at `node` as coefficients on the unknowns
            let mut c: Vec<(usize, f64)> = Vec::new();
            let mut add = |j: isize, v: f64| {
                let j = if j < 0 {
                    -j
                } else if j > n as isize {
                    2 * n as isize - j
                } else {
                    j
                };
                if j > 0 && (j as usize) < n {
                    c.push((j as usize - 1, v / (dx * dx)));
                }
            };
            let j = node as isize;
            add(j - 1, 1.0);
            add(j, -2.0);
            add(j + 1, 1.0);
            let w = if node == 0 || node == n { 0.5 } else { 1.0 } * ei * dx;
            for &(p, vp) in &c {
                for &(q, vq) in &c {
                    k[p][q] += w * vp * vq;
                }
            }
        }
        // node `at` is unknown at - 1
        let at = (z * n as f64).round() as usize;
        let mut f = vec![0.0; m];
        f[at - 1] += force;
        f[at] += moment / (2.0 * dx);
        f[at - 2] -= moment / (2.0 * dx);
        let w = solve_dense(k, f);
        (w[at] - w[at - 2]) / (2.0 * dx)
    }

    /// Eq. S9's flexibilities against an independent solution of the clamped-clamped beam
    /// ([`finite_difference_slope`]) for a unit force and a unit moment at four points. The
    /// finite differences err by `O(dx)` (the moment is a dipole over `2 dx`): extrapolated
    /// from 200 and 400 intervals (Richardson, first order), they agree to 1e-3 relative; a
    /// wrong coefficient or sign fails by far more.
    #[test]
    fn interior_flexibilities_match_a_finite_difference_beam() {
        let (h, ei) = (0.004, 0.35);
        for z in [0.1, 0.3, 0.5, 0.8] {
            let (f_ut, f_tt) = interior_flexibilities(z, h, ei);
            for (force, moment) in [(1.0, 0.0), (0.0, 1.0)] {
                let coarse = finite_difference_slope(h, ei, 200, z, force, moment);
                let fine = finite_difference_slope(h, ei, 400, z, force, moment);
                let extrapolated = 2.0 * fine - coarse;
                let want = force * f_ut + moment * f_tt;
                let scale = f_tt * if force != 0.0 { h } else { 1.0 };
                let rel = (extrapolated - want).abs() / scale;
                eprintln!("z {z}, P {force}, C {moment}: {extrapolated:e} against {want:e}, {rel:.1e}");
                assert!(
                    rel <= 1e-3,
                    "z = {z}, P = {force}, C = {moment}: finite differences {fine:e} (extrapolated {extrapolated:e}), Eq. S9 {want:e}"
                );
            }
        }
        assert_eq!(interior_flexibilities(0.0, h, ei), (0.0, 0.0));
        assert_eq!(interior_flexibilities(1.0, h, ei).1, 0.0);
    }

    /// Gaussian elimination with partial pivoting (the test's small dense systems).
    fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for c in 0..n {
            let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap();
            a.swap(c, p);
            b.swap(c, p);
            for r in c + 1..n {
                let f = a[r][c] / a[c][c];
                if f != 0.0 {
                    for j in c..n {
                        a[r][j] -= f * a[c][j];
                    }
                    b[r] -= f * b[c];
                }
            }
        }
        let mut x = vec![0.0; n];
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|j| a[r][j] * x[j]).sum();
            x[r] = (b[r] - s) / a[r][r];
        }
        x
    }

    /// The constraint Jacobian of [`Star::row_terms`] (the rows' element gradients, contact
    /// coordinate and sleeve-rotation derivatives, assembled as [`Star::assemble`] does) against
    /// central differences of the constraint violation [`Star::constraints`] (Eq. 21), column by
    /// column over every coordinate, at three states of paper case 3 (rigid poses at t = 0.1, 0.3,
    /// 0.5 s, the nodes displaced by up to 2 mm and 0.02 rad, the sleeves turned): two
    /// independent codes (values against derivatives).
    ///
    /// Tolerance: with the step `h = 1e-6` (metres or radians) the central difference errs by
    /// `h^2 |d3 Phi| / 6 + eps |Phi| / h`; the rows are positions of order 0.5 m and angles of
    /// order 1 rad, cubic in the element's local coordinate, so their third derivatives are of
    /// order 1 / h_el^2 ~ 1e4 at 40 elements per beam: a truncation below ~2e-9, a round-off
    /// ~2e-16 / 1e-6 ~ 2e-10. `1e-6 (1 + |J|)` holds both with margin, while a wrong or missing
    /// derivative (entries of order 1e-3 to 1) is far above it.
    #[test]
    fn row_terms_match_central_differences_of_the_constraints() {
        let exp = flexstar_model::catalogue::paper_case(3);
        let params = exp.robot;
        let robot = Robot::from_params(&params).unwrap();
        let ne = 40;
        let h = 1e-6;
        let mut checked = 0;
        for (n, &t) in [0.1, 0.3, 0.5].iter().enumerate() {
            let r = flexstar_kinematics::RigidState::at(&params, &exp.trajectory, t).unwrap();
            let init = InitialState {
                g: [r.g[0].v, r.g[1].v],
                g_dot: [0.0; 2],
                theta: r.theta.v,
                theta_dot: 0.0,
                xp: r.xp.map(|x| x.v),
                xp_dot: [0.0; 3],
            };
            let pins = Pins::new(&robot, r.s.map(|s| [s.v, s.d1, s.d2]));
            let (star, mut q, _) = Star::new(&robot, ne, &init, None).unwrap();
            for (j, x) in q.iter_mut().enumerate().take(3 * star.n_nodes) {
                let amp = if j % 3 == 2 { 0.02 } else { 2e-3 };
                *x += amp * (0.7 * j as f64 + n as f64).sin();
            }
            for i in 0..3 {
                q[star.psi(i)] += 0.01 * (i as f64 + 1.0);
                // contact points well inside their elements (the Jacobian jumps at nodes)
                for p in 0..3 {
                    let (_, z) = star.locate(i, q[star.xi(i, p)]);
                    if !(0.05..=0.95).contains(&z) {
                        q[star.xi(i, p)] += 0.3 * star.h[i];
                    }
                }
            }
            // analytic Jacobian: 3 ROWS rows, n_dof columns
            let nd = star.n_dof;
            let mut jac = vec![vec![0.0; nd]; 3 * ROWS];
            for i in 0..3 {
                let ps = star.psi(i);
                for r in 0..ROWS {
                    let p = ROW_POINT[r];
                    let (e, z) = star.locate(i, q[star.xi(i, p)]);
                    let el = &star.elements[i * star.ne + e];
                    let st = ElementState::new(el, &star.element_q(el, &q));
                    let na = star.node(i, e);
                    let (_, grad, gxi, gpsi) =
                        star.row_terms(&st, [q[3 * na], q[3 * na + 1]], i, q[ps], pins.p[i], r, z);
                    let row = &mut jac[ROWS * i + r];
                    for (a, &d) in dofs(el).iter().enumerate() {
                        row[d] += grad[a];
                    }
                    row[star.xi(i, p)] += gxi;
                    row[ps] += gpsi;
                }
            }
            for c in 0..nd {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[c] += h;
                qm[c] -= h;
                let (fp, fm) = (star.constraints(&qp, &pins), star.constraints(&qm, &pins));
                for k in 0..3 * ROWS {
                    let fd = (fp[k] - fm[k]) / (2.0 * h);
                    let an = jac[k][c];
                    assert!(
                        (fd - an).abs() <= 1e-6 * (1.0 + an.abs()),
                        "t = {t} s, row {k}, column {c}: analytic {an:e}, central difference {fd:e}"
                    );
                    if an.abs() > 1e-3 {
                        checked += 1;
                    }
                }
            }
        }
        // every row has its 6 element entries, the contact coordinate and psi, at three states
        assert!(checked >= 3 * 3 * ROWS * 6, "only {checked} entries above 1e-3");
    }
}
