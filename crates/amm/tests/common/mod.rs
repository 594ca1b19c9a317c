//! Shared test problems (the paper's four cases, a rest-to-rest quintic) and the EVP measure.
#![allow(dead_code)]

use flexstar_model::{AmmSettings, Experiment, FemSettings, ModeFamily, Pose, RobotParams, TimeSpan, Trajectory};

/// The paper's case `k` (section 8): `s_i = c_i t^2` and its end time.
pub fn paper_case(k: usize) -> Experiment {
    let (c, t_end) = match k {
        1 => ([1.0, 1.0, 1.0], 0.5),
        2 => ([1.0, -0.5, -0.5], 0.4),
        3 => ([1.0, 0.0, 0.5], 0.5),
        4 => ([1.0, -1.0, 0.0], 0.5),
        _ => panic!("paper case {k} does not exist"),
    };
    experiment(
        &format!("case{k}"),
        RobotParams::paper(),
        Trajectory::quadratic(c),
        t_end,
        1e-3,
    )
}

/// A rest-to-rest task-space quintic (zero velocity and acceleration at both ends).
pub fn quintic(params: RobotParams, t_end: f64) -> Experiment {
    let traj = Trajectory::Quintic {
        from: Pose {
            gx: 0.0,
            gy: 0.0,
            theta: 0.0,
        },
        to: Pose {
            gx: 0.03,
            gy: -0.02,
            theta: 0.3,
        },
        t0: 0.0,
        t1: t_end,
    };
    experiment("quintic", params, traj, t_end, 1e-3)
}

pub fn experiment(name: &str, robot: RobotParams, trajectory: Trajectory, t_end: f64, dt_out: f64) -> Experiment {
    Experiment {
        name: name.into(),
        description: String::new(),
        robot,
        time: TimeSpan { t_end, dt_out },
        trajectory,
        amm: AmmSettings::default(),
        fem: FemSettings::default(),
        source: Default::default(),
    }
}

pub fn settings(family: ModeFamily, modes: usize, dt: Option<f64>) -> AmmSettings {
    AmmSettings {
        family,
        modes,
        dt,
        snapshots: Vec::new(),
    }
}

/// Eq. 45: `EVP = int |a - b| dt / int |b| dt * 100` (trapezoidal rule on a uniform grid).
pub fn evp(a: &[f64], b: &[f64]) -> f64 {
    let trap = |f: &dyn Fn(usize) -> f64| -> f64 {
        let n = a.len();
        (0..n)
            .map(|k| if k == 0 || k == n - 1 { 0.5 * f(k) } else { f(k) })
            .sum::<f64>()
    };
    trap(&|k| (a[k] - b[k]).abs()) / trap(&|k| b[k].abs()) * 100.0
}

/// Largest absolute value.
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}
