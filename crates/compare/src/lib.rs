//! # flexstar-compare
//!
//! Judging the AMM against the FEM reference (paper, section 9): the error variance parameter
//! ([`evp`], Eq. 45), the behaviour of G and the correctness of each mode family
//! ([`behaviour`]), the regenerated Table I ([`table`]) beside the paper's ([`paper`]), figures
//! ([`figures`], drawn with `flexstar-plot`) and the HTML report ([`report`]). [`runs`] runs the
//! solvers of an experiment (the FEM and a list of AMM runs); [`compare`] does that for any
//! experiment file and writes its outputs ([`case_output`]), with a recording laid over the
//! runs ([`measured`], [`measured_figures`]); [`verify`] is compare over the paper's four cases plus Table I and
//! the checks of [`thresholds`]. The EVP decisions the paper leaves open are written up in
//! `docs/validation.md`, every output column in `docs/outputs.md`.

pub mod behaviour;
pub mod builtin;
pub mod case_output;
pub mod compare;
pub mod direct_figures;
pub mod dwells;
pub mod evp;
pub mod figures;
pub mod measured;
pub mod measured_figures;
pub mod paper;
pub mod report;
pub mod residual;
pub mod runs;
pub mod sensitivity;
pub mod sensors;
pub mod servo;
pub mod table;
pub mod thresholds;
pub mod verify;

pub use behaviour::Behaviour;
pub use evp::{point_evps, CompareError, Point, PointEvps};
pub use runs::{AmmRun, CaseResults, CaseSpec, Progress};
pub use table::{TableI, TableRow};

/// Everything that stops `compare` or `verify` (a failed threshold check is not an error).
/// Every message names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Config(#[from] flexstar_model::ModelError),
    #[error(transparent)]
    Thresholds(#[from] thresholds::ThresholdsError),
    #[error(transparent)]
    Run(#[from] runs::RunError),
    #[error(transparent)]
    Compare(#[from] evp::CompareError),
    #[error(transparent)]
    Figure(#[from] flexstar_plot::FigureError),
    #[error("{file}: rigid kinematics: {source}")]
    Kinematics {
        file: String,
        #[source]
        source: Box<flexstar_kinematics::KinematicsError>,
    },
    #[error("{file}: {reason}")]
    Input { file: String, reason: String },
    #[error(transparent)]
    Measured(#[from] flexstar_measured::MeasuredError),
}

impl From<flexstar_io::WriteError> for Error {
    /// A result file that could not be written, as the model's `ModelError::Write` (same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        flexstar_model::ModelError::from(e).into()
    }
}
