//! The rigid state of the robot at one instant, with exact first and second time derivatives.

use flexstar_model::geometry::{e_w, e_x};
use flexstar_model::trajectory::Jet;
use flexstar_model::{RobotParams, Trajectory};
use num_dual::Dual2;

use crate::direct::{direct_kinematics, largest_angle};
use crate::KinematicsError;

/// Rigid kinematics at time t: every quantity with its first and second time derivative
/// (automatic differentiation, exact to round-off).
#[derive(Debug, Clone, Copy)]
pub struct RigidState {
    /// Time [s].
    pub t: f64,
    /// Actuator coordinates s_i [m].
    pub s: [Jet; 3],
    /// Centre G of the rigid star [m], fixed frame; `d2` is a_G of Eq. 8.
    pub g: [Jet; 2],
    /// Orientation theta [rad] (Eq. 9).
    pub theta: Jet,
    /// Sleeve positions xp_i [m] along the rigid beams, from G (Eq. 10).
    pub xp: [Jet; 3],
    /// Revolute points I, J, K [m], fixed frame (Eqs. 1-3).
    pub p: [[f64; 2]; 3],
}

impl RigidState {
    /// Rigid state for the actuator coordinates of `trajectory` at time `t`.
    pub fn at(params: &RobotParams, trajectory: &Trajectory, t: f64) -> Result<Self, KinematicsError> {
        let s = trajectory
            .s(params, Dual2::from_re(t).derivative())
            .map_err(|source| KinematicsError::Trajectory { t, source })?;
        Self::from_actuators(params, s, t)
    }

    /// Rigid state for actuator coordinates given as second-order dual numbers in time.
    pub fn from_actuators(params: &RobotParams, s: [Dual2<f64>; 3], t: f64) -> Result<Self, KinematicsError> {
        let pose = direct_kinematics(params.d, s).ok_or_else(|| {
            let p = s.map(|si| si.re);
            let pts = [0, 1, 2].map(|i| flexstar_model::geometry::revolute_point(i, params.d, p[i]));
            let (ang, k) = largest_angle(&pts);
            KinematicsError::NoSolution {
                t,
                reason: format!(
                    "triangle IJK has an angle of {:.2} degrees at {} (a Fermat point needs every angle below 120)",
                    ang.to_degrees(),
                    ["I", "J", "K"][k]
                ),
            }
        })?;
        Ok(RigidState {
            t,
            s: s.map(Jet::from_dual2),
            g: pose.g.map(Jet::from_dual2),
            theta: Jet::from_dual2(pose.theta),
            xp: pose.xp.map(Jet::from_dual2),
            p: pose.p.map(|q| [q[0].re, q[1].re]),
        })
    }

    /// Unit vector e_xi along rigid beam i (0-based), Eq. 11.
    pub fn e_x(&self, i: usize) -> [f64; 2] {
        e_x(i, self.theta.v)
    }

    /// Unit vector e_wi normal to rigid beam i (0-based), Eq. 12.
    pub fn e_w(&self, i: usize) -> [f64; 2] {
        e_w(i, self.theta.v)
    }

    /// Acceleration of G, a_G [m/s^2] (Eq. 8).
    pub fn a_g(&self) -> [f64; 2] {
        [self.g[0].d2, self.g[1].d2]
    }

    /// Eq. 11: rigid axial acceleration `a_xi = a_G . e_xi - x theta'^2` of the point at material
    /// coordinate x [m] of beam i.
    pub fn a_x(&self, i: usize, x: f64) -> f64 {
        dot(self.a_g(), self.e_x(i)) - x * self.theta.d1 * self.theta.d1
    }

    /// Eq. 12: rigid transverse acceleration `a_wi = a_G . e_wi + x theta''` of the point at
    /// material coordinate x [m] of beam i.
    pub fn a_w(&self, i: usize, x: f64) -> f64 {
        dot(self.a_g(), self.e_w(i)) + x * self.theta.d2
    }

    /// Position of the rigid beam point at material coordinate x [m] of beam i, fixed frame.
    pub fn point(&self, i: usize, x: f64) -> [f64; 2] {
        let e = self.e_x(i);
        [self.g[0].v + x * e[0], self.g[1].v + x * e[1]]
    }
}

pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
