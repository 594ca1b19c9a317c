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
    /// The solution diverged in the step ending at time `t` [s] (length `dt`) and carried sleeve
    /// `sleeve`'s (1-based) contact point off its beam: the point lies `shift` [m] along the beam
    /// from where the rigid motion puts it, more than [`DIVERGED_SHIFT`] of the beam's length `l`
    /// [m], which no elastic deflection of the model reaches (its axial and foreshortening parts
    /// stay a small fraction of the beam); a blow-up of the time integration, not the sleeve
    /// sliding off (`docs/friction.md` 9.5, "A divergence is named").
    #[error("amm: t = {t:.6} s: the solution diverged in the step of {dt:.3e} s: it carried sleeve {sleeve}'s contact point {shift:.3} m along beam {sleeve} from where the rigid motion puts it (L = {l} m) and off the beam; no elastic deflection moves it that far")]
    DivergedOffBeam {
        t: f64,
        dt: f64,
        sleeve: usize,
        shift: f64,
        l: f64,
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

/// Share of a beam's length beyond which a sleeve's contact point, found off its beam, has moved
/// from its rigid position by a divergence rather than by the motion ([`AmmError::DivergedOffBeam`]):
/// a quarter, far above the elastic shifts of the small-deflection range.
pub const DIVERGED_SHIFT: f64 = 0.25;

impl AmmError {
    /// A sleeve found off its beam ([`AmmError::SleeveOffBeam`]) in a step of length `dt` [s]
    /// whose contact point lies more than [`DIVERGED_SHIFT`] of the beam from its rigid position
    /// `rigid(t, i)` [m] (the material coordinate of sleeve i, 0-based, at time t with every
    /// elastic coordinate zero) becomes [`AmmError::DivergedOffBeam`]; any other error, or an
    /// unknown rigid position, is returned as it is.
    pub(crate) fn judge_off_beam(self, dt: f64, rigid: impl Fn(f64, usize) -> Option<f64>) -> Self {
        let AmmError::SleeveOffBeam(off) = &self else {
            return self;
        };
        match rigid(off.t, off.sleeve - 1) {
            Some(xp) if (off.xi - xp).abs() > DIVERGED_SHIFT * off.l || !off.xi.is_finite() => {
                AmmError::DivergedOffBeam {
                    t: off.t,
                    dt,
                    sleeve: off.sleeve,
                    shift: off.xi - xp,
                    l: off.l,
                }
            }
            _ => self,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::sleeve_contact::on_beam;

    /// A contact point off its beam by the rigid motion stays a sleeve sliding off; one carried a
    /// quarter of the beam or more from its rigid position (or to a non-finite coordinate) is a
    /// divergence, named with its shift.
    #[test]
    fn a_sleeve_carried_far_from_its_rigid_position_is_a_divergence() {
        let off = |xi: f64| AmmError::from(on_beam(0.7175, 0, [xi, xi - 0.015, xi + 0.015], 0.5).unwrap_err());
        // the rigid motion itself has the sleeve at the tip: it slides off
        let at_tip = off(0.51).judge_off_beam(5e-4, |_, _| Some(0.499));
        assert!(matches!(at_tip, AmmError::SleeveOffBeam(_)), "{at_tip}");
        // 0.33 m behind G while the rigid motion has it at 0.2 m from G: a divergence
        let far = off(-0.33).judge_off_beam(5e-4, |t, i| (t == 0.7175 && i == 0).then_some(0.2));
        let AmmError::DivergedOffBeam { sleeve, shift, l, .. } = far else {
            panic!("{far}");
        };
        assert_eq!((sleeve, l), (1, 0.5));
        assert!((shift + 0.53).abs() < 1e-12, "{shift}");
        assert!(far.to_string().contains("diverged"), "{far}");
        let nan = off(f64::NAN).judge_off_beam(5e-4, |_, _| Some(0.2));
        assert!(matches!(nan, AmmError::DivergedOffBeam { .. }), "{nan}");
        // other errors pass through
        let other = AmmError::NonFinite { t: 0.1, dt: 1e-3 }.judge_off_beam(1e-3, |_, _| Some(0.2));
        assert!(matches!(other, AmmError::NonFinite { .. }));
    }
}
