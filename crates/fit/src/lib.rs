//! # flexstar-fit
//!
//! The identification of a model's physical parameters on a recording (`docs/measured.md`
//! section 4): the weighted least-squares problem on the sensor channels ([`problem`], Eqs.
//! LS1-LS5, with the channels' noise levels estimated from the recording, [`noise`]), a
//! Levenberg-Marquardt search within box bounds ([`search`], Eqs. LS6-LS10) on a Jacobian from the
//! model's forward sensitivities or by forward differences evaluated in parallel ([`jacobian`]), the statistics at the optimum ([`stats`], Eqs.
//! LS11-LS14) and the identifiability check ([`identifiability`], Eqs. LS15-LS16); the white-noise
//! density a residual spectrum is read against ([`noise::white_psd`], Eq. LS17).
//!
//! No solver code lives here: the crate is generic over an evaluation of the model, a [`Model`]
//! that returns the sensor readings at given parameter values (the command runs the accurate AMM,
//! `flexstar_api::fit`; the tests use closed forms).

pub mod identifiability;
pub mod jacobian;
pub mod noise;
pub mod outcome;
pub mod problem;
pub mod search;
pub mod starts;
pub mod stats;
mod step;

pub use identifiability::{Combination, Identifiability, Verdict};
pub use outcome::{ChannelFit, Estimate, Fit, Iteration, StartOutcome, Stop};
pub use problem::{Channel, Param, Problem};
pub use search::{fit, Settings};
pub use stats::Statistics;

use flexstar_model::SensorTable;

/// An evaluation of the model: its sensor readings at the parameter values `theta` (physical
/// units, in the order of [`Problem::params`]) on the recording's times. Evaluations run in
/// parallel (one per column of the Jacobian), hence `Sync`; an error says why the model could
/// not be evaluated there (the search treats a trial step that fails as a rejected one).
pub trait Model: Sync {
    fn evaluate(&self, theta: &[f64]) -> Result<SensorTable, String>;

    /// The readings at `theta` and their derivatives along each parameter k, from the model's
    /// forward sensitivities along the step `steps[k]` (the parameter's own unit;
    /// `docs/measured.md` 4.5, Eq. LS9b). `None`: the model has none, and the Jacobian is taken
    /// by forward differences; an error: they cannot be taken at `theta` (the same).
    fn slopes(&self, _theta: &[f64], _steps: &[f64]) -> Option<Result<Slopes, String>> {
        None
    }
}

/// What [`Model::slopes`] gives: the readings, their derivatives per parameter [the channel's
/// unit per unit of the parameter] on the same times, and the model runs that took.
#[derive(Debug, Clone)]
pub struct Slopes {
    pub readings: SensorTable,
    pub derivatives: Vec<SensorTable>,
    pub runs: usize,
}

impl<F> Model for F
where
    F: Fn(&[f64]) -> Result<SensorTable, String> + Sync,
{
    fn evaluate(&self, theta: &[f64]) -> Result<SensorTable, String> {
        self(theta)
    }
}

/// Why a fit could not be set up or started.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The recording and the model do not match (a column missing, other times), or the problem
    /// is empty.
    #[error("{0}")]
    Input(String),
    /// The model could not be evaluated at the start or on its first Jacobian.
    #[error("the model could not be evaluated at {at}: {reason}")]
    Evaluation { at: String, reason: String },
    /// The Jacobian at the start is rank-deficient: the data cannot separate the parameters
    /// (`docs/measured.md` Eq. LS16), named by their combination.
    #[error("{0}")]
    Unidentifiable(String),
}
