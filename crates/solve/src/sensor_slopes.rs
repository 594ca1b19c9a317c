//! The sensors' readings of an accurate-AMM run and their derivatives along moved problems, as
//! the data acquisition records them (`docs/measured.md` 4.5): the columns of a fit's Jacobian
//! from the tangent-linear AMM (`docs/amm.md` 2.2) instead of one run per parameter.

use flexstar_model::{AmmSettings, Problem, Response, SensorTable};

use crate::SolveError;

/// A run's response (its sensors acquired as [`crate::solve`] acquires them) and, per
/// direction, the derivatives of the acquired readings [the sensor's unit per unit of the
/// direction's parameter].
#[derive(Debug, Clone)]
pub struct SensorSlopes {
    pub response: Response,
    pub slopes: Vec<SensorTable>,
}

/// The AMM run of `problem` (a prescribed motion, at the fixed N and step of `settings`) with
/// the derivatives of its sensors' readings along each of `moved`, direction k the problem moved
/// by `eps[k]` along it (`flexstar_amm::solve_with_sensitivities`: its motion, or physical
/// parameters that keep the mode basis). Refused before any work: a problem without sensors, a
/// drive other than a prescribed motion, and what the tangent does not cover.
pub fn sensor_slopes(
    problem: &Problem,
    settings: &AmmSettings,
    moved: &[Problem],
    eps: &[f64],
) -> Result<SensorSlopes, SolveError> {
    let refuse = |key: &str, why: &str| {
        SolveError::Amm(flexstar_amm::AmmError::InvalidSetting {
            key: key.into(),
            reason: why.into(),
        })
    };
    if problem.sensors().is_empty() {
        return Err(refuse("sensors", "the sensors' derivatives need sensors"));
    }
    if flexstar_drive::law_for(problem)?.is_some() {
        return Err(refuse("drive", "the sensors' derivatives need a prescribed motion"));
    }
    flexstar_kinematics::check_problem_sensor_mounts(problem)?;
    let sens = flexstar_amm::solve_with_sensitivities(problem, settings, moved, eps)?;
    let mut response = sens.response;
    crate::acquire_sensors(problem, &mut response);
    let slopes = (sens.sensors.unwrap_or_default().iter())
        .map(|raw| problem.sensors().acquire_derivative(raw, problem.time().t_end))
        .collect();
    Ok(SensorSlopes { response, slopes })
}
