//! One library entry point for both fronts of flexstar, the command line and the Python package:
//! what each command does beyond parsing its arguments (loading and checking the experiment, the
//! drive dispatch, the feasibility preflight, the solver call, the sidecar, the files written).
//! A front parses its arguments into the typed settings here, calls one function and prints or
//! returns the outcome; errors are an [`ApiError`] that tells bad input (file, key, reason), an
//! infeasible motion (time, reason) and a solver failure apart.

pub mod document;
mod error;
pub mod export;
mod figures;
pub mod fit;
mod fit_data;
mod fit_figures;
mod fit_model;
mod fit_params;
pub mod fit_report;
pub mod kinematics;
pub mod modal;
pub mod modes;
pub mod plan;
pub mod plan_cycle;
mod plan_cycle_report;
mod plan_figures;
mod plan_report;
pub mod plan_robust;
mod plan_robust_report;
pub mod run;
pub mod sidecar;
mod solver_errors;
pub mod study;

use std::path::{Path, PathBuf};

pub use document::ExperimentDoc;
pub use error::{ApiError, Result};
pub use flexstar_model::{Experiment, Provenance};
pub use run::{Forces, Prepared, RunOutcome, RunSettings, Solver};

/// Load and validate an experiment file (errors name the file, the key and the reason).
///
/// A `[shaper]` is applied to the motion here, `f_hz = "auto"` resolved from the accurate AMM
/// (`flexstar_shaping::shape`: reading the file alone never runs a solver).
pub fn load(config: &Path) -> Result<Experiment> {
    Ok(flexstar_shaping::shape_loaded(Experiment::load(config)?)?)
}

/// `DIR/<name>/`, created and checked writable (before any work is done).
pub fn case_dir(out: &Path, exp: &Experiment) -> Result<PathBuf> {
    let dir = out.join(&exp.name);
    flexstar_io::output::ensure_writable_dir(out)?;
    flexstar_io::output::ensure_writable_dir(&dir)?;
    Ok(dir)
}

/// This library's version, the commit it was built from (when known) and now: the provenance
/// fields of every sidecar.
pub fn provenance() -> Provenance {
    Provenance::now(option_env!("FLEXSTAR_GIT_COMMIT"))
}
