//! # flexstar-kinematics
//!
//! Rigid kinematics of the star-triangle robot (paper, section 3; docs/conventions.md):
//!
//! - [`as_built`]: the same for any base and any weld angles (`docs/as-built.md` 3: G sees each
//!   pair of revolute points under the gap between their beams);
//! - [`direct`]: G as the Fermat point of the revolute points I, J, K (Eqs. 4-7), the orientation
//!   theta (Eq. 9) and the sleeve positions xp_i (Eq. 10), generic over dual numbers so that
//!   [`RigidState`] carries first and second time derivatives exact to round-off (Eq. 8);
//! - [`RigidState::a_x`], [`RigidState::a_w`]: rigid accelerations of any beam point (Eqs. 11-12);
//! - [`feasibility`]: the first time a trajectory leaves the feasible range, with the reason;
//! - [`inverse_dynamics`]: driving forces of the rigid robot (Eq. 33 with a rigid star);
//! - [`star_masses`]: the same for a robot as built (`docs/as-built.md` 7, Eqs. N1-N6: the
//!   star's centre of mass off G), [`rigid_inverse_dynamics_of`] choosing between the two;
//! - [`table`]: the `kinematics.csv` table.
//!
//! The closed-form inverse kinematics lives in `flexstar_model::geometry` (trajectories need it)
//! and is re-exported here.

pub mod as_built;
pub mod direct;
pub mod feasibility;
pub mod inverse_dynamics;
pub mod sleeve_bands;
pub mod star_masses;
pub mod state;
pub mod table;

pub use direct::{direct_kinematics, RigidPose};
pub use feasibility::{
    check_configuration, check_motion, check_trajectory, preflight_step, CheckedMotion, Infeasible, Violation,
};
pub use flexstar_model::geometry::inverse_kinematics;
pub use inverse_dynamics::{rigid_inverse_dynamics, rigid_inverse_dynamics_with, RigidForces};
pub use sleeve_bands::{check_problem_sensor_mounts, check_sensor_mounts, sleeve_bands};
pub use star_masses::{rigid_inverse_dynamics_of, StarMasses};
pub use state::RigidState;

/// Errors of the rigid kinematics.
#[derive(Debug, thiserror::Error)]
pub enum KinematicsError {
    /// The revolute points do not admit a Fermat point inside the triangle.
    #[error("t = {t:.6} s: no rigid configuration: {reason}")]
    NoSolution { t: f64, reason: String },
    /// The trajectory itself failed (e.g. inverse kinematics of a task-space pose).
    #[error("t = {t:.6} s: trajectory: {source}")]
    Trajectory {
        t: f64,
        #[source]
        source: flexstar_model::ModelError,
    },
    /// The trajectory leaves the feasible range.
    #[error(transparent)]
    Infeasible(#[from] Infeasible),
    /// A value of the table is not finite: the robot's values overflow it.
    #[error(
        "t = {t:.6} s: {column} = {value} is not finite: the robot's values (lengths, masses, stiffnesses) \
         overflow it; give physical values"
    )]
    NotFinite { t: f64, column: &'static str, value: f64 },
    /// The experiment's robot is not a valid robot (its data as read from the file).
    #[error("robot: {0}")]
    Robot(flexstar_model::ModelError),
    /// Writing a result file failed.
    #[error(transparent)]
    Write(flexstar_model::ModelError),
}
