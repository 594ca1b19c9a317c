//! The readings of the sensors at one instant, from the kinematics a solver supplies
//! (`docs/sensors.md` section 3, Eqs. S4-S7).

use super::spec::{Axes, Kind, Place};
use super::Sensors;

/// The motion of a material point of a beam at one instant (fixed frame, SI).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointMotion {
    /// Acceleration `r''` [m/s^2], fixed frame (Eq. S2, S8).
    pub acc: [f64; 2],
    /// Tangent angle `beta` [rad] of Eq. S3: the tangent is `[sin beta, -cos beta]`.
    pub beta: f64,
    /// Curvature `kappa = d beta / ds` [1/m] (Eq. S7; FEM: Eq. S9).
    pub kappa: f64,
}

/// The motion of G and of the tangent there (the payload's frame) at one instant (Eq. S6).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JunctionMotion {
    /// Acceleration of G [m/s^2], fixed frame.
    pub acc: [f64; 2],
    /// Tangent angle `psi` [rad] of beam 1 at G (as `beta` of [`PointMotion`]).
    pub psi: f64,
    /// Its rate `psi'` [rad/s] and acceleration `psi''` [rad/s^2].
    pub psi_d: f64,
    pub psi_dd: f64,
}

/// What a solver knows at one output time: the kinematics of its material points, the sliders
/// and the actuator forces.
pub trait Instant {
    /// Beam `beam`'s (0-based) material point at `x` [m] from G.
    fn beam_point(&self, beam: usize, x: f64) -> PointMotion;
    /// G and beam 1's tangent there.
    fn junction(&self) -> JunctionMotion;
    /// Slider `i`'s position `s_i` [m] (0-based).
    fn slider(&self, i: usize) -> f64;
    /// Actuator `i`'s force `Fa_i` [N] (Eq. 33; 0-based).
    fn force(&self, i: usize) -> f64;
}

/// The tangent `[sin a, -cos a]` and normal `[cos a, sin a]` of angle `a` (Eq. S3).
pub fn tangent_normal(a: f64) -> ([f64; 2], [f64; 2]) {
    let (s, c) = a.sin_cos();
    ([s, -c], [c, s])
}

/// Eq. S5: the specific force `f` [m/s^2] in `axes` about the tangent angle `beta`.
pub fn in_axes(f: [f64; 2], beta: f64, axes: Axes) -> [f64; 2] {
    match axes {
        Axes::Fixed => f,
        Axes::Body => {
            let (t, n) = tangent_normal(beta);
            [f[0] * t[0] + f[1] * t[1], f[0] * n[0] + f[1] * n[1]]
        }
    }
}

/// Eq. S6: the acceleration [m/s^2] of the payload point `offset` [m] (payload frame) and the
/// angle of its axes.
pub fn payload_point(j: &JunctionMotion, offset: [f64; 2]) -> ([f64; 2], f64) {
    let (t, n) = tangent_normal(j.psi);
    let rho = [offset[0] * t[0] + offset[1] * n[0], offset[0] * t[1] + offset[1] * n[1]];
    let k_rho = [-rho[1], rho[0]];
    let w2 = j.psi_d * j.psi_d;
    let acc = [0, 1].map(|k| j.acc[k] + j.psi_dd * k_rho[k] - w2 * rho[k]);
    (acc, j.psi)
}

impl Sensors {
    /// Append the readings of every sensor at one instant to `row`, in the order of
    /// [`Sensors::columns`]; `g` [m/s^2]: gravity, base frame (Eq. S4).
    pub fn read(&self, at: &dyn Instant, g: [f64; 2], row: &mut Vec<f64>) {
        let specific = |a: [f64; 2]| [a[0] - g[0], a[1] - g[1]];
        for s in self.list() {
            match s.kind {
                Kind::Accelerometer { place, axes } => {
                    let (acc, beta) = match place {
                        Place::Beam { beam, x } => {
                            let p = at.beam_point(beam, x);
                            (p.acc, p.beta)
                        }
                        Place::G => {
                            let p = at.beam_point(0, 0.0);
                            (p.acc, p.beta)
                        }
                        Place::Payload { offset } => payload_point(&at.junction(), offset),
                    };
                    row.extend(in_axes(specific(acc), beta, axes));
                }
                Kind::Strain { beam, x, c } => row.push(-c * at.beam_point(beam, x).kappa),
                Kind::Encoder { slider } => row.push(at.slider(slider)),
                Kind::Force { slider } => row.push(at.force(slider)),
            }
        }
    }
}
