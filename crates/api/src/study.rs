//! `compare`, `verify` and `sweep`: the library functions of the compare and study crates, as
//! both fronts call them (options, progress callbacks and outcomes are theirs), and
//! [`compare`]/[`verify`], which return their errors as an [`ApiError`] (bad input, an infeasible
//! motion, a solver failure, a stop on request told apart, as `run` does).

pub use flexstar_compare::compare::{run_compare, CompareOptions, CompareOutcome};
pub use flexstar_compare::verify::{run_verify, VerifyOptions, VerifyOutcome};
pub use flexstar_compare::{Error as CompareError, Progress};
pub use flexstar_study::{
    merge, run_study, write_report, MergeReport, RunOptions as SweepOptions, RunOutcome as SweepOutcome, Shard, Study,
    StudyError,
};

use flexstar_compare::runs::{ProgressFn, RunError};

use crate::ApiError;

/// [`run_compare`] with its error told apart ([`api_error`]).
pub fn compare(opts: &CompareOptions, progress: Option<ProgressFn>) -> Result<CompareOutcome, ApiError> {
    run_compare(opts, progress).map_err(api_error)
}

/// [`run_verify`] with its error told apart ([`api_error`]).
pub fn verify(opts: &VerifyOptions, progress: Option<ProgressFn>) -> Result<VerifyOutcome, ApiError> {
    run_verify(opts, progress).map_err(api_error)
}

/// The kind of a `compare`/`verify` failure: the experiment or thresholds file and the flags are
/// bad input, the preflight's refusal an infeasible motion (with its time), a solver that stopped
/// on request a cancellation, any other solver failure a solver error. The message is unchanged.
pub fn api_error(e: CompareError) -> ApiError {
    let message = e.to_string();
    match e {
        CompareError::Config(m) => ApiError::from_model(m),
        CompareError::Input { file, reason } => ApiError::config(file, None, reason),
        CompareError::Thresholds(_) => ApiError::Config {
            file: "thresholds".into(),
            key: None,
            reason: message.clone(),
            message,
        },
        CompareError::Run(run) => run_error(run, message),
        CompareError::Figure(_) => ApiError::Output(message),
        // a recording (`--measured`) is bad input, named by its file
        CompareError::Measured(m) => ApiError::Config {
            file: m.path().map_or_else(|| "measured".into(), |p| p.display().to_string()),
            key: None,
            reason: message.clone(),
            message,
        },
        CompareError::Compare(_) | CompareError::Kinematics { .. } => ApiError::Solver { message },
    }
}

/// [`api_error`] of the solver runs' errors.
fn run_error(e: RunError, message: String) -> ApiError {
    match e {
        RunError::Input { file, reason } => ApiError::config(file, None, reason),
        RunError::Infeasible { source, .. } => ApiError::Infeasible {
            t: source.t,
            reason: source.violation.to_string(),
            message,
        },
        RunError::Amm { file, source, .. } => match *source {
            flexstar_amm::AmmError::Cancelled { t } => ApiError::Cancelled { file, t },
            _ => ApiError::Solver { message },
        },
        RunError::Fem { file, source } => match *source {
            flexstar_fem::FemError::Cancelled { t } => ApiError::Cancelled { file, t },
            _ => ApiError::Solver { message },
        },
    }
}
