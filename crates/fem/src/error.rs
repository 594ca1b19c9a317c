//! Errors of the finite-element solver: every message says when (time), where (element, sleeve)
//! and why.

use faer::linalg::evd::EvdError;
use faer::sparse::linalg::LuError;
use faer::sparse::FaerError;
use flexstar_drive::DriveError;
use flexstar_kinematics::{KinematicsError, Violation};
use flexstar_model::ModelError;
use flexstar_numerics::NumericsError;

/// Everything that stops the FEM. No partial output is produced after an error.
#[derive(Debug, thiserror::Error)]
pub enum FemError {
    /// The experiment or the settings are unusable (message names the key and the bound).
    #[error("invalid FEM input: {0}")]
    Input(String),
    /// A setting fails a model check (animation frames) or the robot a model check of the
    /// pose modes' robot; the model's error, with its key.
    #[error("invalid FEM input: {0}")]
    Problem(#[source] ModelError),
    /// The feasibility scan before any step refused the motion: its time and violation.
    #[error("invalid FEM input: {0}")]
    Scan(#[source] flexstar_kinematics::Infeasible),
    /// The rigid state at the start could not be evaluated.
    #[error("invalid FEM input: {0}")]
    Start(#[source] KinematicsError),
    /// `fem.elements` cannot be split over the three beams: the mesh has the same number of
    /// elements on every beam (`docs/fem.md` section 10: the beams are lanes of one element
    /// loop and one banded solver), so the total must be a positive multiple of 3.
    #[error("fem.elements = {elements}: {reason}; give a positive multiple of 3 (the same number of elements on each of the three beams)")]
    Elements { elements: usize, reason: &'static str },
    /// The mesh is too coarse to hold a sleeve: fewer than 2 elements of beam `beam` (1-based)
    /// across its sleeve's Lp.
    #[error(
        "mesh too coarse: {per_beam} elements per beam give beam {beam} an element length {h:.4e} m, but its sleeve of length Lp = {lp} m needs at least 2 elements across it (at least {needed} elements per beam, {} in all)",
        3 * needed
    )]
    MeshTooCoarse {
        beam: usize,
        per_beam: usize,
        h: f64,
        lp: f64,
        needed: usize,
    },
    /// The trajectory could not be evaluated.
    #[error("trajectory at t = {t} s: {source}")]
    Trajectory {
        t: f64,
        #[source]
        source: ModelError,
    },
    /// Newton's method did not converge within the iteration limit.
    #[error("Newton failure at t = {t} s (step {h:.3e} s): {reason}")]
    Newton { t: f64, h: f64, reason: NewtonFailure },
    /// A factorisation or an eigenproblem failed (singular iteration matrix, a mechanism); `t`
    /// is 0 for the modes of a pose.
    #[error("linear solver failure at t = {t} s: {source}")]
    LinearSolver {
        t: f64,
        #[source]
        source: LinearError,
    },
    /// The run was stopped on request ([`flexstar_model::cancel`]) at output time `t` [s].
    #[error("cancelled at t = {t} s")]
    Cancelled { t: f64 },
    /// A stick-slip event the time step cannot resolve (`docs/friction.md` 8.3): at time `t` [s]
    /// the contact (`sleeve 2`, `slider 1`) found neither sticking nor slipping consistent with
    /// the step's equations; no result is written.
    #[error("unresolved stick-slip event of {contact} at t = {t} s: {reason}")]
    StickSlip { t: f64, contact: String, reason: String },
    /// A sleeve contact point left the beam: its material coordinate is outside (0, L_i)
    /// (the check shared with the AMM, `flexstar_model::sleeve_contact`).
    #[error(transparent)]
    SleeveOffBeam(#[from] flexstar_model::sleeve_contact::OffBeam),
    /// A slider left its side of the base triangle: `s` [m] outside the open interval `travel`
    /// between the side's two corners (`(-sqrt(3) d, sqrt(3) d)` on the paper's base).
    #[error(
        "slider {slider} left its base side at t = {t} s: s = {s:.5} m, it must stay between the side's corners, {:.5} < s < {:.5} m",
        travel[0],
        travel[1]
    )]
    SliderOffBase {
        t: f64,
        slider: usize,
        s: f64,
        travel: [f64; 2],
    },
    /// The simulated configuration of a direct run left the feasible range (the reason names
    /// the limit: slider off its base side, sleeve at G or off the tip, no Fermat point).
    #[error("direct run left the feasible range at t = {t} s: {violation}")]
    Infeasible { t: f64, violation: Violation },
    /// The actuator law could not be evaluated (e.g. a servo reference outside its range).
    #[error("actuator law at t = {t} s: {source}")]
    Drive {
        t: f64,
        #[source]
        source: DriveError,
    },
    /// Post-processing with the rigid kinematics of the prescribed motion failed at an output
    /// time.
    #[error("post-processing at t = {t} s: {source}")]
    PostProcessing {
        t: f64,
        #[source]
        source: KinematicsError,
    },
    /// Post-processing of a direct run: the simulated sliders `s` [m] have no rigid
    /// configuration at an output time.
    #[error("post-processing at t = {t} s: no rigid configuration for the simulated sliders s = {s:?} m")]
    NoRigidConfiguration { t: f64, s: [f64; 3] },
    /// Mass-proportional damping needs the star's rigid twist from the slider velocities (Eq.
    /// D17), which a singular pose leaves undetermined: the three lines through the pins along the
    /// sleeves' normals meet at one point (or are parallel). `det` is the twist matrix's
    /// determinant relative to the product of its rows' norms.
    #[error(
        "singular pose at t = {t} s: the lines through the three pins normal to the sleeves meet at one point (relative determinant {det:.2e}), so the rigid velocity of the star is not determined by the sliders' and the mass-proportional damping (damping.alpha) cannot be applied"
    )]
    SingularPose { t: f64, det: f64 },
    /// The static equilibrium under gravity (Eq. G8 of `docs/fem.md` 9.5: the start of a run, or
    /// the rest pose of its residual's reference) did not converge at the pose of time `t` [s]
    /// with the sliders held at `s` [m].
    #[error(
        "the static equilibrium under gravity at the pose of t = {t} s (sliders held at s = {s:?} m, pins fixed) failed: {reason}; is the robot held at that pose (a singular pose, a sleeve near the end of its beam)?"
    )]
    StaticEquilibrium { t: f64, s: [f64; 3], reason: NewtonFailure },
    /// A non-finite number appeared (element index given when known).
    #[error("non-finite value at t = {t} s in element {element}: {reason}")]
    NonFinite { t: f64, element: usize, reason: String },
}

/// Why Newton's method stopped without a solution ([`FemError::Newton`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NewtonFailure {
    /// An increment of the coordinates or the multipliers was NaN or infinite.
    NonFiniteIncrement,
    /// `iterations` iterations without convergence; the last increments' largest entries,
    /// coordinates `dq` [m] and multipliers `dl` [N].
    NoConvergence { iterations: usize, dq: f64, dl: f64 },
    /// The static clamped-beam solve of the beam tests: a singular stiffness matrix.
    SingularStiffness,
    /// The static clamped-beam solve of the beam tests did not converge at load step `step`.
    StaticNoConvergence { step: usize },
}

impl std::fmt::Display for NewtonFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            NewtonFailure::NonFiniteIncrement => write!(f, "non-finite Newton increment"),
            NewtonFailure::NoConvergence { iterations, dq, dl } => write!(
                f,
                "no convergence in {iterations} iterations (last increments: {dq:.3e} m, {dl:.3e} N)"
            ),
            NewtonFailure::SingularStiffness => write!(f, "singular stiffness"),
            NewtonFailure::StaticNoConvergence { step } => {
                write!(f, "static Newton did not converge at load step {step}")
            }
        }
    }
}

/// Why the structured factorisation of the Newton matrix (`bordered`, banded beam blocks and a
/// dense border) failed; the FEM then falls back to the sparse LU and keeps this in
/// [`crate::Stats::last_fallback`].
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PivotError {
    /// The banded Cholesky of beam `beam` (1-based) met a pivot that is not positive and finite
    /// at row `row` of its band (tip-first rows, 0-based).
    #[error("beam {beam} block not positive definite at row {row} (pivot {pivot:e})")]
    BeamBlock { beam: usize, row: usize, pivot: f64 },
    /// The LU of the border's Schur complement met a zero or non-finite pivot at step `index`.
    #[error("border Schur complement singular at pivot {index} ({pivot:e})")]
    Schur { index: usize, pivot: f64 },
}

/// Why a sparse factorisation or an eigenproblem of the FEM failed ([`FemError::LinearSolver`]).
#[derive(Debug, Clone, thiserror::Error)]
pub enum LinearError {
    /// The structured solver failed (only reported where there is no fallback).
    #[error(transparent)]
    Pivot(#[from] PivotError),
    /// A matrix slot outside the matrix.
    #[error("slot ({row}, {col}) outside a {n} x {n} matrix")]
    SlotOutside { row: usize, col: usize, n: usize },
    /// A NaN or infinite matrix entry (index into the compressed values).
    #[error("non-finite matrix entry at value index {index}")]
    NonFiniteEntry { index: usize },
    /// faer's symbolic sparse LU failed.
    #[error("{0:?}")]
    Symbolic(FaerError),
    /// faer's numeric sparse LU failed (a singular matrix).
    #[error("{0:?}")]
    Numeric(LuError),
    /// A dense constrained eigenproblem failed.
    #[error(transparent)]
    Dense(#[from] NumericsError),
    /// The sparse eigenproblem's input: `rows` constraint rows for `n` coordinates, or a shift
    /// that is negative or NaN.
    #[error("{rows} constraint rows for {n} coordinates, shift {shift:e}")]
    ModalSizes { rows: usize, n: usize, shift: f64 },
    /// A triplet entry that is non-finite or outside the `n` coordinates.
    #[error("entry ({row}, {col}) = {value:e}: non-finite or outside {n} coordinates")]
    ModalEntry {
        row: usize,
        col: usize,
        value: f64,
        n: usize,
    },
    /// A constraint triplet in row `row` of a system with `rows` constraint rows.
    #[error("constraint entry in row {row} of {rows}")]
    ConstraintRowOutside { row: usize, rows: usize },
    /// Constraint row `row` (1-based) has no entry.
    #[error("constraint row {row} is empty")]
    EmptyConstraintRow { row: usize },
    /// The bordered system of the subspace iteration could not be factored.
    #[error("the bordered system is singular ({source}): a mechanism or dependent constraints")]
    BorderedSingular {
        #[source]
        source: Box<LinearError>,
    },
    /// The bordered solve gave a non-finite vector.
    #[error("the bordered system K + sigma M with the constraints is singular")]
    BorderedNonFinite,
    /// Subspace vector `vector` has no mass (its squared M-norm is `norm2`).
    #[error("subspace vector {vector} has no mass (M-norm^2 {norm2:e}): a massless mode")]
    Massless { vector: usize, norm2: f64 },
    /// The projected eigenproblem of the subspace iteration failed.
    #[error("projected eigenproblem failed ({0:?})")]
    Projected(EvdError),
    /// The subspace iteration did not converge in `iterations` iterations.
    #[error("subspace iteration did not converge in {iterations} iterations")]
    NoConvergence { iterations: usize },
}
