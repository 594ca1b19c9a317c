//! The rigid state of the robot at one instant, with exact first and second time derivatives.

use flexstar_model::trajectory::Jet;
use flexstar_model::{RobotGeometry, Trajectory};
use num_dual::Dual2;

use crate::as_built::{angle_at, rigid_pose};
use crate::direct::largest_angle;
use crate::feasibility::Violation;
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
    /// The beams' weld angles phi_i [rad] (`docs/as-built.md` Eq. W1; the paper: 0, 120, 240
    /// degrees), which [`RigidState::e_x`] and [`RigidState::e_w`] add to theta.
    pub weld: [f64; 3],
}

impl RigidState {
    /// Rigid state for the actuator coordinates of `trajectory` at time `t`, on the paper's
    /// robot or one as built ([`RobotGeometry`]).
    pub fn at<K: RobotGeometry + ?Sized>(params: &K, trajectory: &Trajectory, t: f64) -> Result<Self, KinematicsError> {
        let s = trajectory
            .s(params, Dual2::from_re(t).derivative())
            .map_err(|source| KinematicsError::Trajectory { t, source })?;
        Self::from_actuators(params, s, t)
    }

    /// Rigid state for actuator coordinates given as second-order dual numbers in time (the
    /// pose of [`rigid_pose`]: the Fermat point on the paper's robot, `docs/as-built.md` D1-D3
    /// on one as built).
    pub fn from_actuators<K: RobotGeometry + ?Sized>(
        params: &K,
        s: [Dual2<f64>; 3],
        t: f64,
    ) -> Result<Self, KinematicsError> {
        let pose = rigid_pose(params, s).ok_or_else(|| KinematicsError::NoSolution {
            t,
            reason: no_pose_reason(params, s.map(|si| si.re)),
        })?;
        Ok(RigidState {
            t,
            s: s.map(Jet::from_dual2),
            g: pose.g.map(Jet::from_dual2),
            theta: Jet::from_dual2(pose.theta),
            xp: pose.xp.map(Jet::from_dual2),
            p: pose.p.map(|q| [q[0].re, q[1].re]),
            weld: std::array::from_fn(|i| params.weld_angle(i)),
        })
    }

    /// Unit vector e_xi along rigid beam i (0-based), Eq. 11.
    pub fn e_x(&self, i: usize) -> [f64; 2] {
        let a = self.theta.v + self.weld[i];
        [a.sin(), -a.cos()]
    }

    /// Unit vector e_wi normal to rigid beam i (0-based), Eq. 12.
    pub fn e_w(&self, i: usize) -> [f64; 2] {
        let a = self.theta.v + self.weld[i];
        [a.cos(), a.sin()]
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

/// Why no rigid pose exists at the actuator coordinates `s` [m], in the feasibility scan's words
/// ([`Violation`]): the angle of the revolute points' triangle that reaches the gap G must see its
/// opposite side under (120 degrees on the paper's robot: no Fermat point), or a degenerate
/// triangle.
pub(crate) fn no_pose_reason<K: RobotGeometry + ?Sized>(robot: &K, s: [f64; 3]) -> String {
    let pts: [[f64; 2]; 3] = std::array::from_fn(|i| robot.revolute_point(i, s[i]));
    if robot.paper_form().is_some() {
        let (ang, k) = largest_angle(&pts);
        return Violation::NoFermatPoint {
            vertex: k,
            angle_deg: ang.to_degrees(),
        }
        .to_string();
    }
    let gaps = robot.gaps();
    match (0..3).find(|&k| angle_at(&pts, k) >= gaps[k]) {
        Some(k) => Violation::NoAssembly {
            vertex: k,
            angle_deg: angle_at(&pts, k).to_degrees(),
            gap_deg: gaps[k].to_degrees(),
        }
        .to_string(),
        None => "the revolute points are (nearly) aligned".to_string(),
    }
}

pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
