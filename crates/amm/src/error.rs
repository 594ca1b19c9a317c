//! The one error type of the AMM crate: every message says where (setting key, time, mode) and why.

use flexstar_kinematics::{Infeasible, KinematicsError};
use flexstar_model::{ModeFamily, ModelError};
use flexstar_numerics::NumericsError;

/// Errors of the assumed-modes solver. Input errors are raised before any work is done.
#[derive(Debug, thiserror::Error)]
pub enum AmmError {
    /// A setting or robot parameter that the AMM cannot use (key relative to the config file).
    #[error("amm: key `{key}`: {reason}")]
    InvalidSetting { key: String, reason: String },
    /// A mode-family name that is not one of the four known families.
    #[error("amm: unknown mode family `{0}`: expected pinned-free, slide-free, free-free, clamped-free or enriched")]
    UnknownFamily(String),
    /// The experiment itself is invalid (robot, time span or trajectory).
    #[error("amm: {0}")]
    Model(#[from] ModelError),
    /// The trajectory leaves the feasible range (checked over the whole span before any work).
    #[error("amm: {0}")]
    Infeasible(#[from] Infeasible),
    /// A direct run (forces or servo) left the feasible range at time `t` [s]: its motion is not
    /// known in advance, so this is found as it goes; nothing is written.
    #[error("amm: direct run left the feasible range at t = {t:.6} s: {violation}")]
    DirectInfeasible {
        t: f64,
        violation: flexstar_kinematics::Violation,
    },
    /// The rigid kinematics failed at time `t` (cannot happen after a successful feasibility scan,
    /// but is reported rather than unwrapped).
    #[error("amm: t = {t:.6} s: rigid kinematics: {source}")]
    Kinematics {
        t: f64,
        #[source]
        source: KinematicsError,
    },
    /// A characteristic equation (Eq. 34-1) has no root where the asymptotic estimate says.
    #[error("amm: {family} mode {index}: characteristic equation has no root in [{lo}, {hi}]")]
    RootNotFound {
        family: &'static str,
        index: usize,
        lo: f64,
        hi: f64,
    },
    /// The constraint matrix lost rank: the Schur complement `C S^-1 C^T` is singular at time `t`.
    #[error("amm: t = {t:.6} s: singular constraint system ({source})")]
    SingularConstraints {
        t: f64,
        #[source]
        source: RankError,
    },
    /// [`AmmError::SingularConstraints`] at the consistent initial accelerations: `modes` modes
    /// of `family` per beam cannot satisfy the beam's constraints.
    #[error("amm: t = {t:.6} s: singular constraint system ({source}; {modes} modes of the {family} family are too few for its constraints)")]
    TooFewModes {
        t: f64,
        modes: usize,
        family: ModeFamily,
        #[source]
        source: RankError,
    },
    /// The actuator law could not be evaluated at time `t` (a direct run).
    #[error("amm: t = {t:.6} s: drive: {source}")]
    Drive {
        t: f64,
        #[source]
        source: flexstar_drive::DriveError,
    },
    /// The solution diverged in the step ending at time `t` [s] (length `dt`): its coordinates
    /// reached `reached` in magnitude (`start` at the step's start), where the constraint system
    /// is singular though it is regular at the same pose undeformed (`source`: the rank test
    /// that failed); a blow-up of the time integration, not a loss of rank of the constraints.
    #[error("amm: t = {t:.6} s: the solution diverged in the step of {dt:.3e} s: its coordinates reached {reached:.2e} in magnitude ({start:.2e} at the step's start), where the constraint system is singular ({source}) though it is regular at the undeformed pose")]
    Diverged {
        t: f64,
        dt: f64,
        reached: f64,
        start: f64,
        #[source]
        source: RankError,
    },
    /// The solution stopped being finite at time `t`.
    #[error("amm: t = {t:.6} s: the solution is no longer finite (step {dt:e} s)")]
    NonFinite { t: f64, dt: f64 },
    /// The static equilibrium under gravity at the start pose did not converge (`change`: the
    /// last relative change of the coordinates).
    #[error("amm: t = {t:.6} s: the static equilibrium under gravity at the start pose did not converge (last relative change {change:.1e}): is the robot held at that pose?")]
    StaticStart { t: f64, change: f64 },
    /// A sleeve contact point left its beam during the run (`flexstar_model::sleeve_contact`).
    #[error("amm: {0}")]
    SleeveOffBeam(#[from] flexstar_model::sleeve_contact::OffBeam),
    /// The run was stopped on request ([`flexstar_model::cancel`]) at output time `t` [s].
    #[error("amm: cancelled at t = {t} s")]
    Cancelled { t: f64 },
    /// A stick-slip event the time step cannot resolve (`docs/friction.md` 9.1, as 8.3): at time
    /// `t` [s] the contact (`sleeve 2`, `slider 1 on its rail`) found neither sticking nor
    /// slipping consistent with the step's equations; no result is written.
    #[error("amm: unresolved stick-slip event of {contact} at t = {t} s: {reason}")]
    StickSlip { t: f64, contact: String, reason: String },
}

impl AmmError {
    pub(crate) fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Self {
        AmmError::InvalidSetting {
            key: key.into(),
            reason: reason.into(),
        }
    }
}

/// Why a constraint system of the AMM has no unique solution ([`AmmError::SingularConstraints`]).
#[derive(Debug, Clone, Copy, thiserror::Error)]
pub enum RankError {
    /// Row `row` (0-based) of the constraint matrix `A = C S^-1 C^T` is zero or not finite.
    #[error("constraint row {row} has no coupling")]
    NoCoupling { row: usize },
    /// The LU of the `size` x `size` matrix met a pivot below the rank threshold at `step`
    /// (`ratio`: the pivot against the largest entry).
    #[error("rank-deficient at elimination step {step} of {size} (pivot ratio {ratio:e})")]
    RankDeficient { step: usize, size: usize, ratio: f64 },
    /// The payload's rank-3 update of beam 1's step matrix (Eq. P6, Woodbury) is singular.
    #[error("beam 1's step matrix with the payload (Eq. P6) is singular")]
    Payload,
    /// The 3 x 3 system of the sliders' equations (Eq. 33) of a direct run is singular.
    #[error("the sliders' equations (Eq. 33) are singular")]
    Sliders,
    /// The constrained eigenproblem of a pose (dependent constraint rows, an eigensolver failure).
    #[error(transparent)]
    Modes(#[from] NumericsError),
}
