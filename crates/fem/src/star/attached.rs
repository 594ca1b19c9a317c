//! What an experiment attaches to the star (`docs/fem.md` section 9): a rigid payload welded to node G
//! (Eqs. P10-P12), the beams' Kelvin-Voigt retardation time (Eqs. D6-D10, evaluated in the
//! element pass), the mass-proportional damping of the elastic motion (Eqs. D16-D18, `rigid.rs`)
//! a load at G (Eq. L2) and gravity (Eqs. G6-G7, `gravity.rs`). Absent (the defaults), each adds
//! nothing: its code path is skipped, so the run is the bare star's bit for bit.

use flexstar_model::geometry::{e_w, e_x};
use flexstar_model::{LoadSettings, Payload, Problem};

use super::*;

/// A rigid body welded to node G: mass `m` [kg], rotational inertia `j` [kg m^2] about its own
/// centre of mass, and the offset `c0` [m] of that centre from G in the fixed frame at t = 0
/// (`ox e_x1(theta0) + oy e_w1(theta0)`). At the node state `(x, y, phi)` of G its centre is at
/// `X + c`, `c = R(phi) c0`, and it has turned by `phi` (Eq. P10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PayloadAtG {
    pub m: f64,
    pub j: f64,
    pub c0: [f64; 2],
}

impl PayloadAtG {
    /// The payload of `[payload]` on a star whose initial orientation is `theta0` [rad]; `None`
    /// without one (mass and inertia zero).
    pub fn new(p: &Payload, theta0: f64) -> Option<Self> {
        if p.is_none() {
            return None;
        }
        // beam 1's frame: its weld angle is 0 on every robot (docs/as-built.md Eq. W1)
        let (ex, ew) = (e_x(0, theta0), e_w(0, theta0));
        let [ox, oy] = p.offset;
        Some(PayloadAtG {
            m: p.mass,
            j: p.j,
            c0: [ox * ex[0] + oy * ew[0], ox * ex[1] + oy * ew[1]],
        })
    }

    /// The centre of mass `X + R(phi) c0` [m], fixed frame, at G's coordinates `q_g = (x, y, phi)`
    /// (Eq. P10).
    pub fn centre(&self, q_g: &[f64]) -> [f64; 2] {
        let c = self.offset(q_g[2]);
        [q_g[0] + c[0], q_g[1] + c[1]]
    }

    /// `c = R(phi) c0` [m]: the centre of mass from G, fixed frame.
    fn offset(&self, phi: f64) -> [f64; 2] {
        let (s, c) = phi.sin_cos();
        [c * self.c0[0] - s * self.c0[1], s * self.c0[0] + c * self.c0[1]]
    }

    /// `M_p(phi)` of Eq. P11 [kg, kg m, kg m^2], on G's `(x, y, phi)`.
    pub fn mass_matrix(&self, phi: f64) -> [[f64; 3]; 3] {
        let (m, c) = (self.m, self.offset(phi));
        [
            [m, 0.0, -m * c[1]],
            [0.0, m, m * c[0]],
            [-m * c[1], m * c[0], self.j + m * (c[0] * c[0] + c[1] * c[1])],
        ]
    }

    /// Generalized inertia force on G's `(x, y, phi)` [N, N, N m], Eq. P11:
    /// `(m a_c, m (k x c) . a_c + J phi'')` with `a_c = X'' + phi'' k x c - phi'^2 c`, for G's
    /// coordinates `q`, velocities `v` and accelerations `a` (fixed frame).
    pub fn inertia_force(&self, q: &[f64], v: &[f64], a: &[f64]) -> [f64; 3] {
        let c = self.offset(q[2]);
        let kc = [-c[1], c[0]];
        let w2 = v[2] * v[2];
        let ac = [0, 1].map(|k| a[k] + a[2] * kc[k] - w2 * c[k]);
        [
            self.m * ac[0],
            self.m * ac[1],
            self.m * (kc[0] * ac[0] + kc[1] * ac[1]) + self.j * a[2],
        ]
    }

    /// Kinetic energy [J]: `1/2 m |X' + phi' k x c|^2 + 1/2 J phi'^2`.
    pub fn kinetic_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let c = self.offset(q[2]);
        let vc = [v[0] - v[2] * c[1], v[1] + v[2] * c[0]];
        0.5 * self.m * (vc[0] * vc[0] + vc[1] * vc[1]) + 0.5 * self.j * v[2] * v[2]
    }
}

/// The additions to one run (`docs/fem.md` section 9): payload, damping, load, gravity (each
/// absent by default).
#[derive(Debug, Clone, Default)]
pub(crate) struct Attached {
    /// The payload welded to G.
    pub payload: Option<PayloadAtG>,
    /// Kelvin-Voigt retardation time beta [s] of the beams (0: undamped).
    pub beta: f64,
    /// Mass-proportional damping coefficient alpha [1/s] of the motion relative to the rigid
    /// robot (Eq. D16; 0: none).
    pub alpha: f64,
    /// The load at G, fixed frame.
    pub load: Option<LoadSettings>,
    /// Gravity `[gx, gy]` [m/s^2], fixed (base) frame (Eqs. G6-G7; `[0, 0]`: none).
    pub gravity: [f64; 2],
    /// Friction in the sleeves and on the rails (`docs/friction.md`; `friction.rs`), none by default.
    pub friction: Option<flexstar_model::Friction>,
    /// The sensors read at the output times (`docs/sensors.md`; massless: they add nothing to
    /// the equations), none by default.
    pub sensors: flexstar_model::sensors::Sensors,
}

impl Attached {
    /// The `[payload]`, `[damping]`, `[load]`, `[gravity]` and `[friction]` of `problem` for a star starting at
    /// the orientation `theta0` [rad].
    pub fn of(problem: &Problem, theta0: f64) -> Self {
        let load = problem.load();
        Attached {
            payload: PayloadAtG::new(problem.payload(), theta0),
            beta: problem.damping().beta(),
            alpha: problem.damping().alpha(),
            load: (!load.is_none()).then(|| load.clone()),
            gravity: problem.gravity(),
            friction: problem.friction().copied(),
            sensors: problem.sensors().clone(),
        }
    }

    /// Whether the run has gravity (every gravity code path is guarded on it, so a run without
    /// is the bare star's bit for bit).
    pub fn weighs(&self) -> bool {
        self.gravity != [0.0; 2]
    }

    /// `(Fx, Fy, Mz)` [N, N, N m] of the load at time `t` [s]; `None` without a load.
    pub fn load_at(&self, t: f64) -> Option<[f64; 3]> {
        self.load.as_ref().map(|l| l.at(t))
    }
}

impl Star {
    /// The payload's part of [`Star::assemble`] (Eq. P11): `cf f_p` into node G's imbalance rows
    /// and, with `matrix`, `M_p` into the G-G part of element 0's block (the border sums the
    /// three beams' G-G parts; the sparse LU sums repeated slots). Its tangents (Eq. P12) are
    /// left out, like the beams' `dM/dq` and gyroscopic terms.
    pub(super) fn add_payload(&mut self, p: &PayloadAtG, it: &Iterate, cf: f64, res: &mut [f64], matrix: bool) {
        let f = p.inertia_force(&it.q[..3], &it.v[..3], &it.qdd[..3]);
        for a in 0..3 {
            res[a] += cf * f[a];
        }
        if matrix {
            self.add_payload_block(p, it.q[2], 1.0);
        }
    }

    /// `scale M_p(phi)` (Eq. P11) into the G-G part of element 0's block (the border sums the
    /// three beams' G-G parts; the sparse LU sums repeated slots).
    pub(super) fn add_payload_block(&mut self, p: &PayloadAtG, phi: f64, scale: f64) {
        let mp = p.mass_matrix(phi);
        for a in 0..3 {
            for b in 0..3 {
                self.vals[element_pass::block_index(0, 6 * a + b)] += scale * mp[a][b];
            }
        }
    }

    /// Kinetic energy of the payload [J] (0 without one).
    pub fn payload_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        self.attached
            .payload
            .map_or(0.0, |p| p.kinetic_energy(&q[..3], &v[..3]))
    }

    /// Dissipated power [W] at the coordinates `q`, velocities `v` and pins `pins` (time `t`
    /// [s]): the beams' Kelvin-Voigt damping, Eq. D10, plus the mass-proportional damping's
    /// `alpha v^T M (v - v_r)`, Eq. D16 (each 0 without its coefficient).
    pub fn dissipation_power(&self, q: &[f64], v: &[f64], pins: &Pins, t: f64) -> Result<f64, FemError> {
        let mut p = if self.attached.beta > 0.0 {
            element_pass::dissipation_power(&self.elements, q, v, &self.section())
        } else {
            0.0
        };
        if self.attached.alpha > 0.0 {
            p += self.mass_damping_power(q, v, pins, t)?;
        }
        Ok(p)
    }

    /// Power of the load at G [W] at time `t` [s]: `Fx x' + Fy y' + Mz phi'` (0 without one).
    pub fn load_power(&self, v: &[f64], t: f64) -> f64 {
        self.attached
            .load_at(t)
            .map_or(0.0, |f| f[0] * v[0] + f[1] * v[1] + f[2] * v[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn payload_inertia_is_the_lagrangian_of_its_kinetic_energy() {
        // f_p = d/dt dT/dq' - dT/dq along q(t) = q + t v + t^2/2 a, by central differences of T
        let p = PayloadAtG::new(
            &Payload {
                mass: 1.7,
                j: 0.02,
                offset: [0.05, -0.03],
            },
            0.4,
        )
        .unwrap();
        let (q, v, a) = ([0.01, -0.02, 0.3], [0.2, -0.1, 2.5], [3.0, 1.0, -40.0]);
        let t_of = |q: [f64; 3], v: [f64; 3]| p.kinetic_energy(&q, &v);
        let h = 1e-5;
        let path = |t: f64| -> ([f64; 3], [f64; 3]) {
            (
                std::array::from_fn(|k| q[k] + t * v[k] + 0.5 * t * t * a[k]),
                std::array::from_fn(|k| v[k] + t * a[k]),
            )
        };
        let dt_dv = |qq: [f64; 3], vv: [f64; 3], k: usize| {
            let (mut vp, mut vm) = (vv, vv);
            vp[k] += h;
            vm[k] -= h;
            (t_of(qq, vp) - t_of(qq, vm)) / (2.0 * h)
        };
        let f = p.inertia_force(&q, &v, &a);
        let mp = p.mass_matrix(q[2]);
        for k in 0..3 {
            let ((qp, vp), (qm, vm)) = (path(h), path(-h));
            let ddt = (dt_dv(qp, vp, k) - dt_dv(qm, vm, k)) / (2.0 * h);
            let (mut qa, mut qb) = (q, q);
            qa[k] += h;
            qb[k] -= h;
            let dq = (t_of(qa, v) - t_of(qb, v)) / (2.0 * h);
            assert!(
                (ddt - dq - f[k]).abs() < 1e-5 * (1.0 + f[k].abs()),
                "f_p[{k}]: {} vs {}",
                ddt - dq,
                f[k]
            );
            // M_p = d f_p / d q''
            for j in 0..3 {
                let mut ap = a;
                ap[j] += 1.0;
                let d = p.inertia_force(&q, &v, &ap)[k] - f[k];
                assert!((d - mp[k][j]).abs() < 1e-12, "M_p[{k}][{j}]");
            }
        }
        // the offset in the star's frame: along e_x1 and e_w1 of theta0
        let (ex, ew) = (e_x(0, 0.4), e_w(0, 0.4));
        for k in 0..2 {
            assert!((p.c0[k] - (0.05 * ex[k] - 0.03 * ew[k])).abs() < 1e-15);
        }
        assert!(PayloadAtG::new(&Payload::default(), 0.0).is_none());
    }
}
