//! Test problems of the AMM tests, examples and bench: the shared catalogue of flexstar-model
//! (the paper's four cases as in configs/, rest-to-rest quintics) and the measures of
//! flexstar-numerics, plus the AMM settings shorthand.
#![allow(dead_code)]

pub use flexstar_model::catalogue::{experiment, paper_case};
#[allow(unused_imports)]
pub use flexstar_numerics::measures::max_abs;

use flexstar_model::catalogue::{quintic_from_origin, GENERAL_TARGET};
use flexstar_model::{AmmSettings, Experiment, ModeFamily, RobotParams};

/// A rest-to-rest task-space quintic to the catalogue's general target, ending at `t_end`.
pub fn quintic(params: RobotParams, t_end: f64) -> Experiment {
    experiment(
        "quintic",
        params,
        quintic_from_origin(GENERAL_TARGET, t_end),
        t_end,
        1e-3,
    )
}

pub fn settings(family: ModeFamily, modes: usize, dt: Option<f64>) -> AmmSettings {
    AmmSettings {
        dt,
        ..AmmSettings::paper(family, modes)
    }
}

/// Eq. 45 on the common output grid (1 ms, uniform): `int |a - b| dt / int |b| dt * 100`.
pub fn evp(a: &[f64], b: &[f64]) -> f64 {
    let t: Vec<f64> = (0..a.len()).map(|k| k as f64).collect();
    flexstar_numerics::measures::evp(&t, a, b).unwrap_or(f64::NAN)
}

/// The AMM's response to the experiment's prescribed motion: `flexstar_amm::solve` with
/// `SolveRequest::motion()` (the solver scans the motion itself), the work counters dropped.
pub fn motion_response(
    exp: &Experiment,
    settings: &AmmSettings,
) -> Result<flexstar_model::Response, flexstar_amm::AmmError> {
    flexstar_amm::solve(&exp.problem()?, settings, flexstar_drive::SolveRequest::motion()).map(|s| s.response)
}
