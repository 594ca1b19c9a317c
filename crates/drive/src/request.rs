//! The one shape of a solve: what every solver takes besides the experiment and its own settings
//! (the drive, the preflight's proof, an observer of progress) and what it gives back (the
//! response with the solver's work counters). Both solvers expose exactly one entry point of this
//! shape, `flexstar_amm::solve` and `flexstar_fem::solve`; `flexstar_solve::solve` dispatches
//! between them (`docs/architecture.md`, "One way to solve").

use flexstar_kinematics::CheckedMotion;
use flexstar_model::Response;

use crate::ActuatorLaw;

/// How the sliders move in a solve.
#[derive(Clone, Copy, Default)]
pub enum Drive<'a> {
    /// The experiment's trajectory `s_i(t)` is imposed (the paper's inverse problem: Eq. 33 gives
    /// the actuator forces `Fa_i` [N]).
    #[default]
    Motion,
    /// The sliders are pushed by an actuator law (the direct problem: `s_i(t)` are unknowns).
    Law(&'a dyn ActuatorLaw),
}

impl std::fmt::Debug for Drive<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Drive::Motion => f.write_str("Motion"),
            Drive::Law(_) => f.write_str("Law(..)"),
        }
    }
}

/// Observer of a solve's progress: the fraction of the time span done, in [0, 1].
pub type Progress<'a> = &'a (dyn Fn(f64) + Sync);

/// What a solve takes besides the experiment and the solver's settings.
#[derive(Clone, Copy, Default)]
pub struct SolveRequest<'a> {
    /// How the sliders move.
    pub drive: Drive<'a>,
    /// The preflight's proof that the motion (a servo's reference) is feasible over the span: the
    /// solver scans the trajectory again only when the proof does not cover this experiment's
    /// robot, trajectory and span. `None`: the solver scans it.
    pub proof: Option<&'a CheckedMotion>,
    /// Called with the fraction of the span done (the FEM at every output time, the AMM once at
    /// the end).
    pub progress: Option<Progress<'a>>,
}

impl std::fmt::Debug for SolveRequest<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolveRequest")
            .field("drive", &self.drive)
            .field("proof", &self.proof.is_some())
            .field("progress", &self.progress.is_some())
            .finish()
    }
}

impl<'a> SolveRequest<'a> {
    /// The prescribed motion, scanned by the solver, no observer.
    pub fn motion() -> Self {
        SolveRequest::default()
    }

    /// The direct problem under `law`, no proof, no observer.
    pub fn law(law: &'a dyn ActuatorLaw) -> Self {
        SolveRequest {
            drive: Drive::Law(law),
            ..SolveRequest::default()
        }
    }

    /// This request with the preflight's proof `proof`.
    pub fn with_proof(self, proof: Option<&'a CheckedMotion>) -> Self {
        SolveRequest { proof, ..self }
    }

    /// This request with the progress observer `progress`.
    pub fn with_progress(self, progress: Option<Progress<'a>>) -> Self {
        SolveRequest { progress, ..self }
    }
}

/// A finished solve: the response and the solver's work counters `S` (steps, factorisations, the
/// N tried: each solver's own `Stats`).
#[derive(Debug, Clone)]
pub struct Solved<S> {
    pub response: Response,
    pub stats: S,
}
