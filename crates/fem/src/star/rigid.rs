//! The star's rigid velocity field (`docs/fem.md` 9.2.1, Eq. D17): the twist `(V, Omega)` about
//! node G of a rigid star sliding through its sleeves at the sliders' velocities, from the FEM's
//! current configuration alone (sleeve axes, pins, node positions; no rigid kinematics), and the
//! velocity `v_r` it gives every coordinate with mass. The mass-proportional damping acts on the
//! velocities relative to it (Eqs. D16, D18).

use std::ops::Range;

use super::*;

/// Relative determinant (`|det A|` over the product of its rows' norms, lever arms divided by L)
/// below which the twist matrix `A` of Eq. D17 counts as singular.
const SINGULAR: f64 = 1e-9;

/// The rigid twist of the star per unit slider velocity at one configuration (Eq. D17), fixed
/// frame, about node G.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RigidTwist {
    /// `per_slider[i]` = `(V_x, V_y, Omega)` [m/s, m/s, rad/s] of the twist for `s_i' = 1` m/s
    /// and the other sliders at rest: column i of `A^-1 D`.
    pub per_slider: [[f64; 3]; 3],
}

impl RigidTwist {
    /// Eq. D17, first line: `n_i . (V + Omega k x (P_i - x_G)) = s_i' n_i . u_i` for G at `g`
    /// [m], the pins `p` [m], the sliders' unit directions `u` and the sleeve axes at the angles
    /// `axis` [rad] (fixed frame), with `l` [m] the scale of the lever arms; `Err` with the
    /// relative determinant at a singular pose (the three lines through the pins along the
    /// sleeves' normals concurrent or parallel).
    pub fn solve(g: [f64; 2], p: &[[f64; 2]; 3], u: &[[f64; 2]; 3], axis: [f64; 3], l: f64) -> Result<Self, f64> {
        let rows: [[f64; 3]; 3] = std::array::from_fn(|i| {
            let n = [-axis[i].sin(), axis[i].cos()];
            let r = [p[i][0] - g[0], p[i][1] - g[1]];
            [n[0], n[1], (r[0] * n[1] - r[1] * n[0]) / l]
        });
        let norms: f64 = rows
            .iter()
            .map(|r| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt())
            .product();
        let (adj, det) = adjugate(&rows);
        let relative = det.abs() / norms;
        // a NaN configuration is singular too
        if relative.is_nan() || relative < SINGULAR {
            return Err(relative);
        }
        // column i of A^-1 D: adj column i times n_i . u_i / det; the third unknown is Omega l
        let per_slider = std::array::from_fn(|i| {
            let u = u[i];
            let d = (rows[i][0] * u[0] + rows[i][1] * u[1]) / det;
            [adj[0][i] * d, adj[1][i] * d, adj[2][i] * d / l]
        });
        Ok(RigidTwist { per_slider })
    }

    /// The twist `(V_x, V_y, Omega)` [m/s, m/s, rad/s] at the slider velocities `sd` [m/s].
    pub fn at(&self, sd: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|c| (0..3).map(|i| self.per_slider[i][c] * sd[i]).sum())
    }
}

/// Eq. D17, second line, for one node at `x` [m]: `(V + Omega k x (x - x_G), Omega)` under the
/// twist `w = (V_x, V_y, Omega)` about G at `g` [m] ([m/s, m/s, rad/s]).
#[inline(always)]
fn node_velocity(w: [f64; 3], x: [f64; 2], g: [f64; 2]) -> [f64; 3] {
    [w[0] - w[2] * (x[1] - g[1]), w[1] + w[2] * (x[0] - g[0]), w[2]]
}

/// Adjugate (transposed cofactors) and determinant of a 3 x 3 matrix: `A adj(A) = det(A) I`.
fn adjugate(a: &[[f64; 3]; 3]) -> ([[f64; 3]; 3], f64) {
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]
    };
    let adj = std::array::from_fn(|r| std::array::from_fn(|c| cof(c, r)));
    let det = (0..3).map(|c| a[0][c] * cof(0, c)).sum();
    (adj, det)
}

impl Star {
    /// The coordinates with mass apart from the sliders: the nodes' `[x, y, phi]`, then the three
    /// sleeve rotations `psi_i` (contiguous; the contact coordinates after them are massless).
    pub fn massive(&self) -> Range<usize> {
        0..3 * self.n_nodes + 3
    }

    /// Eq. D17's twist per unit slider velocity at the coordinates `q` with the pins at `p` [m]
    /// (G at node 0, the sleeve axes at `gamma0_i + psi_i`); a singular pose is
    /// [`FemError::SingularPose`] at time `t` [s].
    pub fn rigid_twist(&self, q: &[f64], p: &[[f64; 2]; 3], t: f64) -> Result<RigidTwist, FemError> {
        let axis = [0, 1, 2].map(|i| self.sleeve_angle(i, q));
        let u = [0, 1, 2].map(|i| self.slider_direction(i));
        RigidTwist::solve([q[0], q[1]], p, &u, axis, self.length_scale())
            .map_err(|det| FemError::SingularPose { t, det })
    }

    /// Eq. D17, second line: the rigid velocity of coordinate `k` (in [`Star::massive`]) at the
    /// coordinates `q` under the twist `w = (V_x, V_y, Omega)` about G: a node's
    /// `(V + Omega k x (x_j - x_G), Omega)` [m/s, m/s, rad/s], a sleeve rotation's `Omega`.
    #[inline]
    pub fn rigid_velocity(&self, q: &[f64], w: [f64; 3], k: usize) -> f64 {
        if k >= 3 * self.n_nodes {
            return w[2];
        }
        let j = k - k % 3;
        node_velocity(w, [q[j], q[j + 1]], [q[0], q[1]])[k % 3]
    }

    /// `out[k] += alpha (v - v_r)` [m/s^2, rad/s^2] on every coordinate `k` of
    /// [`Star::massive`] at the coordinates `q` and velocities `v`, with `w` the twist of the
    /// current slider velocities (Eq. D16 divided by `-M`; one node at a time).
    fn add_relative_rates(&self, q: &[f64], v: &[f64], w: [f64; 3], out: &mut [f64]) {
        let alpha = self.attached.alpha;
        let g = [q[0], q[1]];
        let nodes = 3 * self.n_nodes;
        for ((o, qj), vj) in out[..nodes]
            .chunks_exact_mut(3)
            .zip(q[..nodes].chunks_exact(3))
            .zip(v[..nodes].chunks_exact(3))
        {
            let vr = node_velocity(w, [qj[0], qj[1]], g);
            for c in 0..3 {
                o[c] += alpha * (vj[c] - vr[c]);
            }
        }
        for k in nodes..self.massive().end {
            out[k] += alpha * (v[k] - w[2]);
        }
    }

    /// Eq. D16 through the inertia routines: the accelerations `qdd + alpha (v - v_r)` on
    /// [`Star::massive`] (the sliders' and contact coordinates' unchanged) at the iterate `it`,
    /// written into `out`; `v_r` from the iterate's pins and slider velocities (Eq. D17). Under
    /// gravity, less the weights' field `t_g` (Eqs. G6-G7, `Star::subtract_weight_field`).
    pub(super) fn shifted_accelerations(&self, it: &Iterate, t: f64, out: &mut Vec<f64>) -> Result<(), FemError> {
        out.clear();
        out.extend_from_slice(it.qdd);
        if self.attached.alpha > 0.0 {
            let w = self.rigid_twist(it.q, &it.pins.p, t)?.at(it.pins.s.map(|s| s[1]));
            self.add_relative_rates(it.q, it.v, w, out);
        }
        if self.attached.weighs() {
            self.subtract_weight_field(out);
        }
        Ok(())
    }

    /// The mass-proportional part of Eq. D18's Newton matrix outside the element pass (whose
    /// blocks take it as `Factors::cm`): `c Jp` on the sleeves' diagonal and `c M_p` in the
    /// payload's G block, `c = gamma' alpha`, at the coordinates `q`.
    pub(super) fn add_mass_damping(&mut self, q: &[f64], c: f64) {
        for i in 0..3 {
            self.vals[self.off_psi + 4 * i] += c * self.beam(i).sleeve_inertia;
        }
        if let Some(p) = self.attached.payload {
            self.add_payload_block(&p, q[2], c);
        }
    }

    /// `P_d,alpha` of Eq. D16 [W]: `alpha v^T M (v - v_r)` over the elements, the sleeves'
    /// rotations and the payload, at the coordinates `q`, velocities `v` and pins `pins` (time
    /// `t` [s] for a singular pose's error).
    pub(super) fn mass_damping_power(&self, q: &[f64], v: &[f64], pins: &Pins, t: f64) -> Result<f64, FemError> {
        let w = self.rigid_twist(q, &pins.p, t)?.at(pins.s.map(|s| s[1]));
        let mut rel = vec![0.0; q.len()];
        self.add_relative_rates(q, v, w, &mut rel);
        let beams = element_pass::mass_product(&self.elements, q, v, &rel, &self.section());
        let sleeves: f64 = (0..3)
            .map(|i| self.beam(i).sleeve_inertia * v[self.psi(i)] * rel[self.psi(i)])
            .sum();
        let payload = self.attached.payload.map_or(0.0, |p| {
            let mp = p.mass_matrix(q[2]);
            (0..3)
                .map(|a| v[a] * (0..3).map(|b| mp[a][b] * rel[b]).sum::<f64>())
                .sum()
        });
        Ok(beams + sleeves + payload)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_kinematics::RigidState;

    /// Eq. D17 against the rigid kinematics (`flexstar-kinematics`, independent of the FEM): a
    /// star meshed at the rigid pose of paper case 3 at three times and moving with the rigid
    /// velocities (G's, theta's, the sleeves' sliding) has, at every node and sleeve rotation,
    /// the velocity `v_r` computed from its configuration and the sliders' velocities alone.
    /// Both are exact rigid kinematics: they agree to round-off (1e-12 of the largest speed).
    #[test]
    fn rigid_field_is_the_velocity_of_the_rigid_robot() {
        let exp = flexstar_model::catalogue::paper_case(3);
        let params = exp.robot;
        let robot = Robot::from_params(&params).unwrap();
        for t in [0.1, 0.25, 0.4] {
            let r = RigidState::at(&params, &exp.trajectory, t).unwrap();
            let init = crate::solve::initial_state(&r);
            let (star, q, v) = Star::new(&robot, 36, &init, None).unwrap();
            let pins = Pins::new(&robot, r.s.map(|s| [s.v, s.d1, s.d2]));
            let w = star.rigid_twist(&q, &pins.p, t).unwrap().at(pins.s.map(|s| s[1]));
            let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(scale > 0.1, "the robot must move at t = {t}: {scale}");
            for k in star.massive() {
                let vr = star.rigid_velocity(&q, w, k);
                assert!(
                    (vr - v[k]).abs() < 1e-12 * scale,
                    "t = {t}, coordinate {k}: v_r {vr} vs v {}",
                    v[k]
                );
            }
        }
    }

    /// Sliders at rest: no rigid velocity; pins on G (every normal line through G): singular.
    #[test]
    fn rest_gives_zero_and_concurrent_normals_are_singular() {
        let axis = [0.3, 0.3 + 2.1, 0.3 + 4.2];
        let g = [0.01, -0.02];
        let p = [0, 1, 2].map(|i: usize| {
            let a: f64 = axis[i];
            [g[0] + 0.2 * a.cos(), g[1] + 0.2 * a.sin()]
        });
        let u = [0, 1, 2].map(flexstar_model::geometry::slider_direction);
        let tw = RigidTwist::solve(g, &p, &u, axis, 0.5).unwrap();
        assert_eq!(tw.at([0.0; 3]), [0.0; 3]);
        // the twist satisfies its three equations for any slider velocities
        let sd = [0.3, -0.7, 1.1];
        let w = tw.at(sd);
        for i in 0..3 {
            let n = [-axis[i].sin(), axis[i].cos()];
            let r = [p[i][0] - g[0], p[i][1] - g[1]];
            let vp = [w[0] - w[2] * r[1], w[1] + w[2] * r[0]];
            let u = u[i];
            let lhs = n[0] * vp[0] + n[1] * vp[1];
            assert!((lhs - sd[i] * (n[0] * u[0] + n[1] * u[1])).abs() < 1e-14, "row {i}");
        }
        let det = RigidTwist::solve(g, &[g; 3], &u, axis, 0.5).unwrap_err();
        assert!(det < 1e-12, "{det}");
        let msg = FemError::SingularPose { t: 0.2, det }.to_string();
        assert!(msg.contains("t = 0.2 s") && msg.contains("damping.alpha"), "{msg}");
    }
}
