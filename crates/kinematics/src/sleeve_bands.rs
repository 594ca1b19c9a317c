//! Where the sleeves pass over the beams during a motion: the band of Eq. S10 of
//! `docs/sensors.md`, in which no sensor can be mounted.

use flexstar_model::{Experiment, ModelError, Problem, RobotGeometry, Sensors, TimeSpan, Trajectory};

use crate::{KinematicsError, RigidState};

/// Eq. S10: for each beam, the material coordinates `[lo, hi]` [m] from G that sleeve i covers
/// over `[0, t_end]`: the range of the rigid `xp_i(t)` at the times `k step` (and `t_end`)
/// widened by `Lp_i / 2` each side.
pub fn sleeve_bands<K: RobotGeometry + ?Sized>(
    params: &K,
    traj: &Trajectory,
    t_end: f64,
    step: f64,
) -> Result<[[f64; 2]; 3], KinematicsError> {
    let n = (t_end / step).ceil().max(1.0) as usize;
    let mut range = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
    for k in 0..=n {
        let t = (k as f64 * step).min(t_end);
        let st = RigidState::at(params, traj, t)?;
        for (r, xp) in range.iter_mut().zip(st.xp) {
            r[0] = r[0].min(xp.v);
            r[1] = r[1].max(xp.v);
        }
    }
    Ok(std::array::from_fn(|i| {
        let half = 0.5 * params.sleeve_length(i);
        [range[i][0] - half, range[i][1] + half]
    }))
}

/// Refuse a sensor of `sensors` mounted where a sleeve of `exp` passes during its motion (the
/// `[trajectory]`, at the preflight's step; `Sensors::check_mounts`). Nothing to do without a
/// sensor on a beam.
pub fn check_sensor_mounts(exp: &Experiment, sensors: &Sensors) -> Result<(), ModelError> {
    check_mounts_on(&exp.robot, &exp.trajectory, &exp.time, sensors)
}

/// [`check_sensor_mounts`] on the robot of `problem` (which `Problem::with_robot` may have
/// changed since the experiment was read): its sensors against the sleeve bands (Eq. S10) of
/// its own robot and motion.
pub fn check_problem_sensor_mounts(problem: &Problem) -> Result<(), ModelError> {
    check_mounts_on(problem.robot(), problem.trajectory(), problem.time(), problem.sensors())
}

/// Eq. S10 for `sensors` on `robot` moved by `traj` over `time`, at the preflight's step.
fn check_mounts_on<K: RobotGeometry + ?Sized>(
    robot: &K,
    traj: &Trajectory,
    time: &TimeSpan,
    sensors: &Sensors,
) -> Result<(), ModelError> {
    if sensors.list().iter().all(|s| s.beam_point().is_none()) {
        return Ok(());
    }
    let step = crate::preflight_step(time.dt_out);
    let bands =
        sleeve_bands(robot, traj, time.t_end, step).map_err(|e| ModelError::invalid("trajectory", e.to_string()))?;
    sensors.check_mounts(&bands)
}
