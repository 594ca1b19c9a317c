//! # flexstar-shaping
//!
//! Input shaping applied as an explicit step (`docs/motions.md` 3.4-3.7): [`shape`] turns the
//! `[shaper]` section of an experiment into its shaped motion. Reading a file never runs a solver:
//! a `[shaper]` with given frequencies is pure arithmetic and is applied when the file is read
//! (`flexstar_model::Experiment::apply_shaper`), while `f_hz = "auto"` needs the accurate AMM and
//! its modes at the final pose, so a loaded experiment keeps it pending
//! (`Experiment::shaper_pending`) until a front calls [`shape`]. A problem is not built from an
//! experiment whose shaper is still pending (`flexstar_model::Problem::new`).
//!
//! The same step first resolves the other value that needs the robot's modes: a `[damping] zeta`
//! given without `f_hz` holds at the first elastic frequency at the start pose
//! ([`resolve_damping`], `docs/usage.md`, damping), which the automatic shaper then designs with.
//!
//! [`robust::shape_over`] is the automatic shaper over an uncertainty (`docs/motions.md` 4.11):
//! the nominal choice's bands of frequencies over several models, covered by `si` shapers.
//!
//! Both read the experiment's robot, the paper's or one as built: its own modes at its own start
//! and final poses (`flexstar_modal`, `docs/modes.md`, a robot as built).

mod auto;
pub mod robust;

use flexstar_model::{Experiment, ModelError};

/// Apply the experiment's `[shaper]` to its motion: resolve `f_hz = "auto"` from the accurate AMM
/// (`docs/motions.md` 3.5, errors under the key `shaper.f_hz`) and replace `exp.trajectory` by the
/// shaped motion. A no-op without `[shaper]` or when the motion is already shaped (given
/// frequencies are applied when the file is read).
pub fn shape(exp: &mut Experiment) -> Result<(), ModelError> {
    resolve_damping(exp)?;
    if !exp.shaper_pending() {
        return exp.apply_shaper();
    }
    let choice = auto::resolve_auto(exp).map_err(|e| ModelError::invalid("shaper.f_hz", format!("\"auto\": {e}")))?;
    exp.apply_auto_shaper(choice)?;
    // the shaped motion rests later: `time.t_end` must still cover it (as for given frequencies)
    exp.validate()
}

/// `[damping]` at the robot's first elastic frequencies at the start pose of its motion (the
/// accurate AMM, sliders locked, the payload at G: `flexstar_modal::analysis::start_pose_frequencies`):
/// a `zeta` without `f_hz` holds at the first (two) of them, so that mode 1 (and 2) has the
/// ratio zeta (Eqs. D5, D15), and a mass-proportional `alpha` is checked to leave mode 1 below
/// critical damping (`flexstar_model::Damping::resolve`). The sidecar's resolved experiment
/// records the frequencies. A no-op when nothing needs them. Errors under `damping.zeta` or
/// `damping.alpha`.
pub fn resolve_damping(exp: &mut Experiment) -> Result<(), ModelError> {
    let n = exp.damping.frequencies_needed();
    if n == 0 {
        return Ok(());
    }
    let key = if exp.damping.zeta.is_some() {
        "damping.zeta"
    } else {
        "damping.alpha"
    };
    let first = flexstar_modal::analysis::start_pose_frequencies(exp, n)
        .map_err(|e| ModelError::invalid(key, format!("the first frequencies at the start pose: {e}")))?;
    exp.damping.resolve(&first)
}

/// [`shape`] of an experiment read from a file: a refusal names the file (as the loader's do).
pub fn shape_loaded(mut exp: Experiment) -> Result<Experiment, ModelError> {
    let source = exp.source.clone();
    shape(&mut exp).map_err(|e| e.in_file(&source))?;
    Ok(exp)
}
