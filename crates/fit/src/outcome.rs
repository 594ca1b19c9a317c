//! What a fit returns (`docs/measured.md` 4.9): the estimates with their statistics, the channels'
//! residuals before and after, the search's trace and why it stopped, the identifiability verdict.

use flexstar_model::SensorTable;
use serde::Serialize;

use crate::identifiability::{Identifiability, Verdict};
use crate::stats::Statistics;

/// Why the search stopped (`docs/measured.md` 4.6).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Stop {
    /// Eq. LS10: the relative offset fell below the tolerance.
    Converged { offset: f64 },
    /// Every parameter sits at a bound with the cost falling outwards: a corner of the box.
    AtBounds,
    /// No damped step lowers the cost any more, with the relative offset still above the
    /// tolerance.
    NoDecrease { offset: f64 },
    /// The most iterations, with the relative offset still above the tolerance.
    MaxIterations { offset: f64 },
    /// The model could not be evaluated on a Jacobian's step.
    EvaluationFailed { reason: String },
}

impl Stop {
    /// Did the search converge (Eq. LS10, or the box's corner)?
    pub fn converged(&self) -> bool {
        matches!(self, Stop::Converged { .. } | Stop::AtBounds)
    }

    /// One sentence.
    pub fn text(&self, tol: f64) -> String {
        match self {
            Stop::Converged { offset } => {
                format!("converged: relative offset {offset:.2e} below {tol:.0e} (Eq. LS10)")
            }
            Stop::AtBounds => "converged at a corner of the box: every parameter at a bound".into(),
            Stop::NoDecrease { offset } => {
                format!("not converged: no step lowers the cost any more, relative offset {offset:.2e} above {tol:.0e}")
            }
            Stop::MaxIterations { offset } => {
                format!("not converged: the most iterations, relative offset {offset:.2e} above {tol:.0e}")
            }
            Stop::EvaluationFailed { reason } => format!("not converged: the model failed on a step: {reason}"),
        }
    }
}

/// One accepted iterate (and the start, iteration 0).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Iteration {
    pub iteration: usize,
    /// Model evaluations so far.
    pub evaluations: usize,
    /// The cost `|r|^2 / 2` (Eq. LS4).
    pub cost: f64,
    /// The parameters (physical units).
    pub theta: Vec<f64>,
    /// The relative offset there (Eq. LS10).
    pub offset: f64,
    /// The Marquardt damping of the accepted step (relative to the diagonal; 0 at the start).
    pub damping: f64,
    /// Wall time since the start [s].
    pub wall_s: f64,
}

/// One parameter's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    pub key: String,
    pub lo: f64,
    pub hi: f64,
    pub start: f64,
    pub estimate: f64,
    /// Eq. LS12's, the noise's alone; `None` at a bound or for a singular problem.
    pub standard_error: Option<f64>,
    /// Eq. LS18's, residuals correlated in time (the model's own error included).
    pub standard_error_correlated: Option<f64>,
    /// The 95 % interval on the wider of the two (Eqs. LS14, LS19).
    pub interval: Option<[f64; 2]>,
    /// At a bound (then left out of the statistics).
    pub at_bound: bool,
}

/// One channel's result: the RMS of the model's error `y - m` in its unit, before (at the start)
/// and after (at the estimates).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelFit {
    pub column: String,
    pub unit: String,
    pub weight: f64,
    /// The noise level `sigma_c` of Eq. LS1 (estimated by Eq. LS2 unless given).
    pub noise: f64,
    pub rms_before: f64,
    pub rms_after: f64,
}

/// A channel whose error after the fit is more than this many times its noise level carries
/// something the model does not explain (`docs/measured.md` 4.7): flagged in the report.
pub const MISFIT: f64 = 3.0;

impl ChannelFit {
    /// Its error after the fit over its noise level, above [`MISFIT`]?
    pub fn misfit(&self) -> bool {
        self.rms_after > MISFIT * self.noise
    }
}

/// One start's search (`docs/measured.md` 4.6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StartOutcome {
    /// Where it started and where it ended, in the parameters' units.
    pub start: Vec<f64>,
    pub end: Vec<f64>,
    /// Eq. LS4 at the end (`NaN` where the start could not be evaluated).
    pub cost: f64,
    pub converged: bool,
    pub iterations: usize,
    /// Why it stopped, in words.
    pub reason: String,
    /// Its estimates are the fit's.
    pub chosen: bool,
}

/// A fit.
#[derive(Debug, Clone, Serialize)]
pub struct Fit {
    pub estimates: Vec<Estimate>,
    pub statistics: Statistics,
    pub channels: Vec<ChannelFit>,
    pub identifiability: Identifiability,
    pub stop: Stop,
    /// `stop` in words.
    pub reason: String,
    pub iterations: usize,
    /// The model runs, a Jacobian's counted as the runs it took.
    pub evaluations: usize,
    /// The Jacobians taken, and how many of them came from the model's sensitivities
    /// (`docs/measured.md` 4.5, Eq. LS9b; the rest by forward differences).
    pub jacobians: usize,
    pub tangent_jacobians: usize,
    pub wall_s: f64,
    pub trace: Vec<Iteration>,
    /// Every start's search (`docs/measured.md` 4.6): the given start first; the estimates are
    /// those of the best (converged before not, then the lowest cost).
    pub starts: Vec<StartOutcome>,
    /// The model's readings at the start and at the estimates (for the report's overlays).
    #[serde(skip)]
    pub before: SensorTable,
    #[serde(skip)]
    pub after: SensorTable,
}

impl Fit {
    /// Did the search converge?
    pub fn converged(&self) -> bool {
        self.stop.converged()
    }

    /// Are the estimates a calibration: converged, and the Jacobian there not rank-deficient
    /// (`docs/measured.md` 4.8)?
    pub fn calibrated(&self) -> bool {
        self.converged() && self.identifiability.verdict != Verdict::RankDeficient
    }

    /// The estimates, in the order of the parameters.
    pub fn theta(&self) -> Vec<f64> {
        self.estimates.iter().map(|e| e.estimate).collect()
    }
}
