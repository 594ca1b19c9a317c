//! The kinematics tests' task-space motion: a rest-to-rest quintic between two poses.

use flexstar_model::{Pose, Trajectory};

/// The quintic from `from` to `to` (`[Gx, Gy, theta]`, m and rad) over `0..t1` [s].
pub fn quintic(from: [f64; 3], to: [f64; 3], t1: f64) -> Trajectory {
    let pose = |p: [f64; 3]| Pose {
        gx: p[0],
        gy: p[1],
        theta: p[2],
    };
    Trajectory::Quintic {
        from: pose(from),
        to: pose(to),
        t0: 0.0,
        t1,
    }
}
