//! Gravity on the star's coordinates (`docs/fem.md` 9.5, Eqs. G6-G7): every weight is the
//! inertia force of the rigid translation field of acceleration `g`, so the inertia routines
//! take it through their accelerations, `q_dd -> q_dd - t_g` (Eq. G1 of `docs/as-built.md` on
//! the FEM's absolute coordinates), and the weights' potential energy for the energy balance.

use super::*;

impl Star {
    /// `g . u_i` [m/s^2]: gravity along slider i's rail (Eq. G7).
    pub fn gravity_along(&self, i: usize) -> f64 {
        let (g, u) = (self.attached.gravity, self.slider_direction(i));
        g[0] * u[0] + g[1] * u[1]
    }

    /// `out -= t_g` (Eqs. G6-G7), `t_g` the rigid translation field of acceleration `g` (fixed
    /// frame) on the coordinates: `(gx, gy, 0)` on every node, nothing on the sleeves' rotations
    /// and contact coordinates, `g . u_i` on slider `s_i` (direct problem). These are the
    /// accelerations the inertia routines see under gravity, so that `M (q_dd - t_g) + f_conv` is the inertia force less the weights (the beams'
    /// consistent loads `M_e(q) t_g`, the payload's `m g` at its centre of mass with its moment
    /// about G, the sliders' `(mpp + mpa) g . u_i`).
    pub(super) fn subtract_weight_field(&self, out: &mut [f64]) {
        let nodes = 3 * self.n_nodes;
        let g = self.attached.gravity;
        for o in out[..nodes].chunks_exact_mut(3) {
            o[0] -= g[0];
            o[1] -= g[1];
        }
        if self.direct {
            for i in 0..3 {
                out[self.slider(i)] -= self.gravity_along(i);
            }
        }
    }

    /// Potential energy of the weights [J] at the coordinates `q` with the pins `pins`,
    /// `V_g = -g . (sum_e rho_i int r dx + m r_c + sum_i (mpp + mpa)_i P_i)` (base frame origin): the
    /// beams' element interpolation ([`ElementState::mean_position`]), the payload's centre of
    /// mass (Eq. P10), the sleeves and sliders at their pins (their centre of mass, Eq. G7).
    /// Its gradient in q is `-M(q) t_g`, the weights of Eq. G6. 0 without gravity.
    pub fn gravity_potential(&self, q: &[f64], pins: &Pins) -> f64 {
        if !self.attached.weighs() {
            return 0.0;
        }
        let mut moment = [0.0; 2];
        let mut add = |m: f64, r: [f64; 2]| {
            moment[0] += m * r[0];
            moment[1] += m * r[1];
        };
        for (e, el) in self.elements.iter().enumerate() {
            let st = ElementState::new(el, &self.element_q(el, q));
            let a = 3 * el.nodes[0];
            add(
                self.beam(e / self.ne).mass_per_length * el.l0,
                st.mean_position([q[a], q[a + 1]]),
            );
        }
        if let Some(p) = self.attached.payload {
            add(p.m, p.centre(&q[..3]));
        }
        for (i, pin) in pins.p.iter().enumerate() {
            add(self.beam(i).sleeve_mass, *pin);
        }
        let g = self.attached.gravity;
        -(g[0] * moment[0] + g[1] * moment[1])
    }
}
