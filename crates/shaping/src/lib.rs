//! # flexstar-shaping
//!
//! Input shaping applied as an explicit step (`docs/motions.md` 3.4-3.7): [`shape`] turns the
//! `[shaper]` section of an experiment into its shaped motion. Reading a file never runs a solver:
//! a `[shaper]` with given frequencies is pure arithmetic and is applied when the file is read
//! (`flexstar_model::Experiment::apply_shaper`), while `f_hz = "auto"` needs the accurate AMM and
//! its modes at the final pose, so a loaded experiment keeps it pending
//! (`Experiment::shaper_pending`) until a front calls [`shape`]. The solvers' dispatch
//! (`flexstar_solve::solve`) refuses an experiment whose shaper is still pending.

mod auto;

use flexstar_model::{Experiment, ModelError};

/// Apply the experiment's `[shaper]` to its motion: resolve `f_hz = "auto"` from the accurate AMM
/// (`docs/motions.md` 3.5, errors under the key `shaper.f_hz`) and replace `exp.trajectory` by the
/// shaped motion. A no-op without `[shaper]` or when the motion is already shaped (given
/// frequencies are applied when the file is read).
pub fn shape(exp: &mut Experiment) -> Result<(), ModelError> {
    if !exp.shaper_pending() {
        return exp.apply_shaper();
    }
    let choice = auto::resolve_auto(exp).map_err(|e| ModelError::invalid("shaper.f_hz", format!("\"auto\": {e}")))?;
    exp.apply_auto_shaper(choice)?;
    // the shaped motion rests later: `time.t_end` must still cover it (as for given frequencies)
    exp.validate()
}

/// [`shape`] of an experiment read from a file: a refusal names the file (as the loader's do).
pub fn shape_loaded(mut exp: Experiment) -> Result<Experiment, ModelError> {
    let source = exp.source.clone();
    shape(&mut exp).map_err(|e| e.in_file(&source))?;
    Ok(exp)
}
