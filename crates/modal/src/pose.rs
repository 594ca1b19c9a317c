//! The rest pose of a modal analysis: from the experiment's trajectory at time T (`--at T`) or
//! from a task-space pose (`--pose GX,GY,THETA`, inverse kinematics for the sliders), of the
//! paper's robot or one as built: the generic rigid kinematics of `docs/as-built.md` 3 (each axis,
//! weld angle, beam and sleeve length its own), which is the paper's construction bit for bit on
//! the paper's robot.

use flexstar_kinematics::feasibility::check_trajectory;
use flexstar_kinematics::RigidState;
use flexstar_model::geometry::inverse_kinematics;
use flexstar_model::{Experiment, RestPose, Robot, Trajectory};
use num_dual::Dual2;

use crate::ModalError;

/// The pose of the experiment's trajectory at time `t` [s], which must lie in `[0, t_end]`.
pub fn pose_at_time(exp: &Experiment, t: f64) -> Result<RestPose, ModalError> {
    if !(t.is_finite() && (0.0..=exp.time.t_end).contains(&t)) {
        return Err(ModalError::Input(format!(
            "--at {t}: the time must lie in the span [0, {}] s of {}",
            exp.time.t_end,
            exp.source.display()
        )));
    }
    let robot = crate::robot(exp)?;
    pose_of_motion(exp, &robot, t)
}

/// The pose of `robot` (the experiment's) held by the sliders of the experiment's motion at
/// time `t` [s] (not checked against the span: the callers' times are the motion's own).
pub fn pose_of_motion(exp: &Experiment, robot: &Robot, t: f64) -> Result<RestPose, ModalError> {
    let s = exp.trajectory.s(robot, t)?;
    pose_from_sliders(robot, s)
}

/// The pose with centre `(gx, gy)` [m] and orientation `theta` [rad] (inverse kinematics).
/// `robot` is the experiment's ([`crate::robot`]).
pub fn pose_from_task(robot: &Robot, gx: f64, gy: f64, theta: f64) -> Result<RestPose, ModalError> {
    let s = inverse_kinematics(robot, [gx, gy], theta).map_err(|e| ModalError::Infeasible(e.to_string()))?;
    pose_from_sliders(robot, s)
}

/// The rest pose held by the sliders at `s` [m], checked against every limit of the feasible
/// range (docs/conventions.md; each beam's own L_i, Lp_i and each slider's travel on its side of
/// the base for a robot as built); the error names the one violated.
pub fn pose_from_sliders(robot: &Robot, s: [f64; 3]) -> Result<RestPose, ModalError> {
    let still = Trajectory::Polynomial {
        s1: vec![s[0]],
        s2: vec![s[1]],
        s3: vec![s[2]],
    };
    check_trajectory(robot, &still, 1e-6, 1e-6).map_err(|e| ModalError::Infeasible(e.violation.to_string()))?;
    let st = RigidState::from_actuators(robot, s.map(Dual2::from_re), 0.0)
        .map_err(|e| ModalError::Infeasible(e.to_string()))?;
    Ok(RestPose {
        s,
        g: [st.g[0].v, st.g[1].v],
        theta: st.theta.v,
        xp: st.xp.map(|x| x.v),
    })
}

/// Parse `GX,GY,THETA` [m, m, rad].
pub fn parse_pose(text: &str) -> Result<[f64; 3], ModalError> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| ModalError::Input(format!("--pose {text}: {e} (expected GX,GY,THETA in m, m, rad)")))?;
    match v.as_slice() {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        _ => Err(ModalError::Input(format!(
            "--pose {text}: expected three finite numbers GX,GY,THETA (m, m, rad)"
        ))),
    }
}
