//! The residual vibration of a run after its motion has come to rest
//! (`docs/motions.md` 2.2-2.3): the measures of [`flexstar_metrics::residual`] with the settling
//! hold of section 2.3, one period of the first elastic mode at the final pose.

use flexstar_metrics::residual::{residual_after, Residual};
use flexstar_model::{Experiment, Response};

use crate::analysis::final_pose_frequencies;
use crate::ModalError;

/// End of the motion [s]: the `t_rest` of a rest-to-rest trajectory that ends before
/// `time.t_end`; `None` for a motion that never rests (polynomial) or rests only at `t_end`.
pub fn motion_end(exp: &Experiment) -> Option<f64> {
    exp.trajectory.t_rest().filter(|&t| t < exp.time.t_end)
}

/// One period [s] of the first elastic mode at the pose the motion ends in, sliders locked, by
/// the accurate AMM ([`final_pose_frequencies`], payload included): the quiet time a run must end with
/// to count as settled (motions.md 2.3). `None` without a rest before `t_end`.
pub fn settle_hold_s(exp: &Experiment) -> Result<Option<f64>, ModalError> {
    if motion_end(exp).is_none() {
        return Ok(None);
    }
    let f = final_pose_frequencies(exp, 1)?.unwrap_or_default();
    match f.first() {
        Some(&f1) if f1 > 0.0 => Ok(Some(1.0 / f1)),
        _ => Err(ModalError::Input(
            "no elastic mode at the final pose to time the settling by".to_string(),
        )),
    }
}

/// The residual of `r`, a run of `exp`, after the motion's end, in the band `[report]
/// settle_tol`; `None` when the motion does not rest before `t_end`.
pub fn run_residual(exp: &Experiment, r: &Response) -> Result<Option<Residual>, ModalError> {
    let (Some(t_rest), Some(hold)) = (motion_end(exp), settle_hold_s(exp)?) else {
        return Ok(None);
    };
    Ok(residual_after(r, t_rest, exp.report.settle_tol, hold))
}
