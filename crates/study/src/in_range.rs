//! Whether a case lies in the small-deflection range: the program's own check
//! (`flexstar_metrics::validity`: peak tip and `|w_iG|` at most 0.05 L, sleeve slope at most
//! 0.075) on the case's AMM run, every beam judged against the shortest beam's L on a robot as
//! built (stricter than `flexstar run`, which judges each beam against its own L; the validation
//! study of robots as built was drawn and measured with this criterion).
//! The validation envelopes (`docs/validation.md` sections 8 and 9) hold their targets on the
//! cases in range.

use flexstar_model::sidecar::ValidityExceeded;
use flexstar_model::Experiment;
use flexstar_solve::Settings;

/// The length [m] the study's small-deflection check judges every beam of `exp` by: the
/// shortest beam's.
pub fn check_length(exp: &Experiment) -> f64 {
    flexstar_model::Robot::from_params(&exp.robot)
        .map(|r| r.beams().iter().map(|b| b.length).fold(f64::INFINITY, f64::min))
        .unwrap_or(exp.robot.l)
}

/// The first bound the AMM run of `exp` (its own `[amm]` settings) exceeds, `None` in range; an
/// error when the run fails.
pub fn small_deflection(exp: &Experiment) -> Result<Option<ValidityExceeded>, String> {
    let problem = exp.problem().map_err(|e| e.to_string())?;
    let r = flexstar_solve::response(&problem, Settings::Amm(&exp.amm), None, None).map_err(|e| e.to_string())?;
    Ok(flexstar_metrics::validity::small_deflection_check_lengths(
        &r,
        [check_length(exp); 3],
    ))
}
