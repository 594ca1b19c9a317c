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
    Ok(residual_with_hold(exp, r, settle_hold_s(exp)?))
}

/// [`run_residual`] with the settling hold `hold` [s] of [`settle_hold_s`] already computed.
pub fn residual_with_hold(exp: &Experiment, r: &Response, hold: Option<f64>) -> Option<Residual> {
    let (Some(t_rest), Some(hold)) = (motion_end(exp), hold) else {
        return None;
    };
    residual_after(r, t_rest, exp.report.settle_tol, hold)
}

/// The residual of `r`, a run of `exp`, per dwell (`docs/motions.md` 2.5), in the band
/// `[report] settle_tol`: every move's dwell ([`flexstar_metrics::dwell::dwell_windows`]) judged
/// with the hold of one period of the first elastic mode at the dwell's pose (sliders locked, the
/// accurate AMM, payload included; for the last dwell the hold of [`settle_hold_s`]). Under
/// gravity a dwell away from the final pose is listed unmeasured (its sag is not computed).
/// `g_pinned`: the run's modes pin G. `None` when no move ends before `t_end`.
pub fn run_dwells(
    exp: &Experiment,
    r: &Response,
    g_pinned: bool,
) -> Result<Option<Vec<flexstar_model::DwellKeys>>, ModalError> {
    dwells_with_hold(exp, r, g_pinned, settle_hold_s(exp)?)
}

/// [`run_dwells`] with the final pose's hold `final_hold` [s] of [`settle_hold_s`] already
/// computed: a dwell held by the sliders of the final rest (to the bit) takes it instead of
/// solving the final pose's modes again. The experiment's robot may be one as built (its own
/// poses and modes, [`crate::robot`]).
pub fn dwells_with_hold(
    exp: &Experiment,
    r: &Response,
    g_pinned: bool,
    final_hold: Option<f64>,
) -> Result<Option<Vec<flexstar_model::DwellKeys>>, ModalError> {
    use flexstar_metrics::dwell::{dwell_residual, dwell_windows, moves, Baseline};
    let moves: Vec<(f64, f64)> = moves(&exp.trajectory)
        .into_iter()
        .filter(|m| m.1 < exp.time.t_end)
        .collect();
    let Some(&t_last) = r.t.last() else {
        return Ok(None);
    };
    let windows = dwell_windows(&moves, t_last);
    if windows.is_empty() {
        return Ok(None);
    }
    let robot = crate::robot(exp)?;
    let model = crate::analysis::amm_pose_model(exp)?;
    let s_rest = match exp.trajectory.t_rest() {
        Some(t) => Some(exp.trajectory.s(&robot, t)?),
        None => None,
    };
    let mut out = Vec::with_capacity(windows.len());
    for w in &windows {
        let s = exp.trajectory.s(&robot, w.move_end)?;
        let hold = match final_hold.filter(|_| s_rest == Some(s)) {
            Some(hold) => hold,
            None => dwell_hold(&model, &robot, s, w)?,
        };
        // the sag is known at the final pose only (as-built.md 5.5)
        let at_rest_pose = s_rest.is_some_and(|sr| (0..3).all(|i| (s[i] - sr[i]).abs() <= 1e-12));
        let baseline = if r.rest_offset.is_some() && !at_rest_pose {
            Baseline::Unknown
        } else {
            Baseline::RestPose
        };
        out.push(dwell_residual(r, w, exp.report.settle_tol, hold, baseline, g_pinned));
    }
    Ok(Some(out))
}

/// One period [s] of the first elastic mode at the pose the sliders `s` [m] hold during dwell
/// `w` (sliders locked, the AMM's `model`).
fn dwell_hold(
    model: &flexstar_amm::pose_modes::PoseModel,
    robot: &flexstar_model::Robot,
    s: [f64; 3],
    w: &flexstar_metrics::dwell::DwellWindow,
) -> Result<f64, ModalError> {
    let pose = crate::pose::pose_from_sliders(robot, s)?;
    let f = model.frequencies_at(&pose, flexstar_model::Sliders::Locked, 1)?;
    match f.first() {
        Some(&f1) if f1 > 0.0 => Ok(1.0 / f1),
        _ => Err(ModalError::Input(format!(
            "no elastic mode at the pose of dwell {} (t = {} s) to time the settling by",
            w.dwell, w.move_end
        ))),
    }
}
