//! The one error type of the AMM crate: every message says where (setting key, time, mode) and why.

use flexstar_kinematics::{Infeasible, KinematicsError};
use flexstar_model::ModelError;

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
    #[error("amm: t = {t:.6} s: singular constraint system ({reason})")]
    SingularConstraints { t: f64, reason: String },
    /// The actuator law could not be evaluated at time `t` (a direct run).
    #[error("amm: t = {t:.6} s: drive: {source}")]
    Drive {
        t: f64,
        #[source]
        source: flexstar_drive::DriveError,
    },
    /// The solution stopped being finite at time `t`.
    #[error("amm: t = {t:.6} s: the solution is no longer finite (step {dt:e} s)")]
    NonFinite { t: f64, dt: f64 },
}

impl AmmError {
    pub(crate) fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Self {
        AmmError::InvalidSetting {
            key: key.into(),
            reason: reason.into(),
        }
    }
}
