//! The catalogue of test problems that the tests, examples and benches of every crate share
//! (one definition of each problem, as diffsol's `test_models`): the paper's four cases, read from
//! the same `configs/caseK.toml` files that `flexstar verify` runs, and rest-to-rest quintics.

use std::path::Path;

use crate::config::{AmmSettings, Experiment, FemSettings, TimeSpan};
use crate::params::RobotParams;
use crate::trajectory::{Pose, Trajectory};

const CASES: [(&str, &str); 4] = [
    ("configs/case1.toml", include_str!("../../../configs/case1.toml")),
    ("configs/case2.toml", include_str!("../../../configs/case2.toml")),
    ("configs/case3.toml", include_str!("../../../configs/case3.toml")),
    ("configs/case4.toml", include_str!("../../../configs/case4.toml")),
];

/// The paper's case `k` (1..=4, section 8) exactly as in `configs/caseK.toml`.
///
/// # Panics
/// If `k` is not 1..=4 or the bundled file does not parse (a test-fixture error).
pub fn paper_case(k: usize) -> Experiment {
    assert!((1..=4).contains(&k), "paper case {k} does not exist");
    let (path, text) = CASES[k - 1];
    Experiment::from_toml_str(text, Path::new(path)).unwrap_or_else(|e| panic!("bundled {path}: {e}"))
}

/// An experiment with default solver settings.
pub fn experiment(name: &str, robot: RobotParams, trajectory: Trajectory, t_end: f64, dt_out: f64) -> Experiment {
    Experiment {
        name: name.into(),
        description: String::new(),
        robot,
        base: None,
        time: TimeSpan { t_end, dt_out },
        trajectory,
        amm: AmmSettings::default(),
        fem: FemSettings::default(),
        drive: Default::default(),
        payload: Default::default(),
        damping: Default::default(),
        load: Default::default(),
        gravity: Default::default(),
        friction: None,
        shaper: None,
        report: Default::default(),
        sensors: Vec::new(),
        measured: None,
        fit: None,
        source: Default::default(),
        hash: String::new(),
    }
}

/// The start pose of the paper's cases: G = O, theta = 0.
pub const ORIGIN: Pose = Pose {
    gx: 0.0,
    gy: 0.0,
    theta: 0.0,
};

/// A general plane motion target (translation and rotation) used by the stiff-limit checks.
pub const GENERAL_TARGET: Pose = Pose {
    gx: 0.03,
    gy: -0.02,
    theta: 0.3,
};

/// Rest-to-rest quintic from [`ORIGIN`] at t = 0 to `to` at `t1` (zero velocity and acceleration
/// at both ends, so nothing is excited by a jump).
pub fn quintic_from_origin(to: Pose, t1: f64) -> Trajectory {
    Trajectory::Quintic {
        from: ORIGIN,
        to,
        t0: 0.0,
        t1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_four_paper_cases_parse_with_their_spans() {
        // docs/paper-defects.md (the four cases): end times 0.5, 0.4, 0.5, 0.5 s.
        for (k, t_end) in [(1, 0.5), (2, 0.4), (3, 0.5), (4, 0.5)] {
            let e = paper_case(k);
            assert_eq!(e.name, format!("case{k}"));
            assert_eq!(e.time.t_end, t_end);
            assert_eq!(e.robot, RobotParams::paper());
        }
        assert_eq!(paper_case(2).trajectory, Trajectory::quadratic([1.0, -0.5, -0.5]));
    }
}
