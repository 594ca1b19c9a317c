//! The robot's rigid data as the star reads it (`docs/fem.md` section 10): the motion's actuator
//! jets, the feasibility of a simulated configuration and the sliders' kinetic energy, each for
//! any base and any beams (`flexstar_model::RobotGeometry`: the paper's robot keeps the paper's
//! formulas, bit for bit the results from before per-beam data).

use flexstar_kinematics::Violation;
use flexstar_model::trajectory::Jet;
use flexstar_model::{ModelError, Trajectory};

use super::*;

impl Star {
    /// `s_i`, `s_i'`, `s_i''` of the prescribed motion `traj` at time `t` [s] on this robot (a
    /// task-space motion through the robot's own inverse kinematics, `docs/as-built.md` 3).
    pub(crate) fn jets(&self, traj: &Trajectory, t: f64) -> Result<[Jet; 3], ModelError> {
        traj.jets(&self.robot, t)
    }

    /// The limits of `flexstar_kinematics::feasibility` at the sliders' positions `s` [m]
    /// (sliders on their sides, a rigid pose, sleeves between G and the tips, with each beam's
    /// own L_i and Lp_i): a check of a simulated configuration, not an equation.
    pub(crate) fn check_configuration(&self, s: [f64; 3]) -> Result<(), Violation> {
        flexstar_kinematics::feasibility::check_configuration(&self.robot, s)
    }

    /// Kinetic energy of the sliders with their sleeves' translation [J],
    /// `1/2 sum (mpp + mpa)_i s_i'^2` at the pins' speeds (on equal beams `1/2 (mpp + mpa) sum
    /// s_i'^2`, as it was written before per-beam data).
    pub(crate) fn slider_energy(&self, pins: &Pins) -> f64 {
        let m = self.robot.beams().map(|b| b.sleeve_mass);
        if m[1] == m[0] && m[2] == m[0] {
            return 0.5 * m[0] * (0..3).map(|i| pins.s[i][1].powi(2)).sum::<f64>();
        }
        0.5 * (0..3).map(|i| m[i] * pins.s[i][1].powi(2)).sum::<f64>()
    }
}
