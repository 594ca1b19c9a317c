//! The three kinds of actuator law: a force table (e.g. a solver's own `Fa` output fed back),
//! force polynomials, and a PD servo on each slider with optional rigid-body feedforward.

use flexstar_kinematics::{rigid_inverse_dynamics_of, rigid_inverse_dynamics_with, RigidState};
use flexstar_model::trajectory::Jet;
use flexstar_model::{Attachments, ForceSamples, Robot, RobotParams, Trajectory};

use crate::{ActuatorLaw, DriveError};

/// `Fa_i(t)` [N] sampled at increasing times [s], linearly interpolated in between.
///
/// Linear interpolation is exact for the round trip at the solver's own step: an inverse run
/// that writes `Fa` at every solver step gives back, at those steps, the very values the direct
/// run evaluates there.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceTable {
    samples: ForceSamples,
}

impl ForceTable {
    /// Build from samples; times must be finite and strictly increasing, forces finite.
    /// Errors name the sample (1-based row) and the reason; the caller adds file and key.
    pub fn new(t: Vec<f64>, fa: Vec<[f64; 3]>) -> Result<Self, DriveError> {
        ForceSamples::check(&t, &fa).map_err(DriveError::Table)?;
        Ok(ForceTable {
            samples: ForceSamples { t, fa },
        })
    }

    /// First and last sample time [s].
    pub fn span(&self) -> (f64, f64) {
        let t = &self.samples.t;
        (t[0], t[t.len() - 1])
    }

    /// Check that the table covers `[t0, t1]` [s] (with a relative slack of 1e-9 for times
    /// written with fewer digits than the solver keeps).
    pub fn check_covers(&self, t0: f64, t1: f64) -> Result<(), DriveError> {
        let (a, b) = self.span();
        ForceSamples::check_covers(a, b, t0, t1).map_err(DriveError::Table)
    }

    /// `Fa(t)` [N], linear between samples, held constant outside the span
    /// ([`ForceSamples::at`]).
    pub fn at(&self, t: f64) -> [f64; 3] {
        self.samples.at(t)
    }
}

impl ActuatorLaw for ForceTable {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], DriveError> {
        Ok(self.at(t))
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// `Fa_i(t) = sum_k c_ik t^k` [N], coefficients in increasing powers of t [s].
#[derive(Debug, Clone, PartialEq)]
pub struct ForcePolynomials {
    /// Coefficients of `Fa1`, `Fa2`, `Fa3`.
    pub coefficients: [Vec<f64>; 3],
}

impl ActuatorLaw for ForcePolynomials {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], DriveError> {
        Ok([0, 1, 2].map(|i| self.coefficients[i].iter().rev().fold(0.0, |acc, c| acc * t + c)))
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// A PD loop on each slider tracking the reference trajectory:
/// `Fa_i = ff_i(t) + kp_i (s_ref,i(t) - s_i) + kd_i (s_ref,i'(t) - s_i')` [N].
///
/// The feedforward `ff` is the rigid-body inverse dynamics of the reference (Eq. 33 with a rigid
/// star, [`rigid_inverse_dynamics_with`], carrying the payload and load; on a robot as built
/// `docs/as-built.md` 7, [`rigid_inverse_dynamics_of`]) or zero. The gains are per slider (from
/// a bandwidth, each on its own slider's mass: `docs/as-built.md` 7.6).
#[derive(Debug, Clone)]
pub struct Servo {
    /// Proportional gains [N/m].
    pub kp: [f64; 3],
    /// Derivative gains [N s/m].
    pub kd: [f64; 3],
    /// Add the rigid-body inverse dynamics of the reference.
    pub rigid_feedforward: bool,
    /// The reference motion `s_ref(t)`.
    pub reference: Trajectory,
    /// The robot (geometry of the reference, masses for the feedforward): the paper's compact
    /// form, or a robot as built carried whole in its `as_built` ([`Robot::to_params`]).
    pub params: RobotParams,
    /// The payload and load the feedforward includes (`docs/amm.md` 11.1; none: the bare star).
    pub attached: Attachments,
}

impl Servo {
    /// Gains from a closed-loop bandwidth `f_bw` [Hz] and damping ratio `zeta` for a slider of
    /// mass `m` [kg] treated as a free mass: `kp = m (2 pi f_bw)^2`, `kd = 2 zeta m (2 pi f_bw)`.
    /// ([`flexstar_model::drive_section::gains_from_bandwidth`]).
    pub fn gains_from_bandwidth(m: f64, f_bw: f64, zeta: f64) -> (f64, f64) {
        flexstar_model::drive_section::gains_from_bandwidth(m, f_bw, zeta)
    }

    /// Reference `s_ref`, `s_ref'` and the feedforward at time `t`; errors if the reference
    /// itself is not a valid pose at `t`.
    pub fn reference_at(&self, t: f64) -> Result<ReferencePoint, DriveError> {
        let robot = RigidRobot::of(&self.params)?;
        let jets = robot.jets(&self.reference, t)?;
        let feedforward = if self.rigid_feedforward {
            robot.forces(&self.attached, &self.reference, t)?
        } else {
            [0.0; 3]
        };
        Ok(ReferencePoint {
            s: jets.map(|j| j.v),
            v: jets.map(|j| j.d1),
            feedforward,
        })
    }
}

/// The robot a [`RobotParams`] describes, as the reference and the feedforward read it: the
/// paper's compact form itself (today's formulas, bit for bit), or the robot as built it
/// carries ([`RobotParams::as_built`], `docs/as-built.md` 3 and 7).
enum RigidRobot<'a> {
    Paper(&'a RobotParams),
    AsBuilt(Box<Robot>),
}

impl<'a> RigidRobot<'a> {
    fn of(params: &'a RobotParams) -> Result<Self, DriveError> {
        match params.as_built {
            None => Ok(RigidRobot::Paper(params)),
            Some(_) => Robot::from_params(params)
                .map(|r| RigidRobot::AsBuilt(Box::new(r)))
                .map_err(|e| DriveError::Config(e.to_string())),
        }
    }

    /// `s(t)` of `trajectory` with its first and second derivatives.
    fn jets(&self, trajectory: &Trajectory, t: f64) -> Result<[Jet; 3], DriveError> {
        match self {
            RigidRobot::Paper(p) => trajectory.jets(*p, t),
            RigidRobot::AsBuilt(r) => trajectory.jets(r.as_ref(), t),
        }
        .map_err(|e| reference_error(t, e))
    }

    /// The rigid-body inverse dynamics of `trajectory` at time `t` carrying `attached` [N]
    /// (Eq. 33 with a rigid star, Eqs. P7-P8; `docs/as-built.md` Eqs. N1-N6 as built).
    fn forces(&self, attached: &Attachments, trajectory: &Trajectory, t: f64) -> Result<[f64; 3], DriveError> {
        Ok(match self {
            RigidRobot::Paper(p) => {
                let state = RigidState::at(*p, trajectory, t).map_err(|e| reference_error(t, e))?;
                rigid_inverse_dynamics_with(p, attached, &state).fa
            }
            RigidRobot::AsBuilt(r) => {
                let state = RigidState::at(r.as_ref(), trajectory, t).map_err(|e| reference_error(t, e))?;
                rigid_inverse_dynamics_of(r, attached, &state).fa
            }
        })
    }
}

/// The reference cannot be evaluated at time `t` [s].
fn reference_error(t: f64, e: impl std::fmt::Display) -> DriveError {
    DriveError::Reference {
        t,
        reason: e.to_string(),
    }
}

/// The servo's reference at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferencePoint {
    /// `s_ref` [m].
    pub s: [f64; 3],
    /// `s_ref'` [m/s].
    pub v: [f64; 3],
    /// Feedforward force [N] (zero without feedforward).
    pub feedforward: [f64; 3],
}

impl ActuatorLaw for Servo {
    fn force(&self, t: f64, s: [f64; 3], v: [f64; 3]) -> Result<[f64; 3], DriveError> {
        let r = self.reference_at(t)?;
        Ok([0, 1, 2].map(|i| r.feedforward[i] + self.kp[i] * (r.s[i] - s[i]) + self.kd[i] * (r.v[i] - v[i])))
    }
    fn stiffness(&self) -> [f64; 3] {
        self.kp
    }
    fn damping(&self) -> [f64; 3] {
        self.kd
    }
}

/// The forces that move the *rigid* robot along `trajectory` (Eq. 33 with a rigid star), as a
/// drive: the open-loop input of the stiff-limit check.
#[derive(Debug, Clone)]
pub struct RigidInverseForces {
    /// The motion the forces are computed for.
    pub trajectory: Trajectory,
    /// The robot: the paper's compact form, or a robot as built carried in its `as_built`.
    pub params: RobotParams,
    /// The payload and load it carries (none: the bare star).
    pub attached: Attachments,
}

impl ActuatorLaw for RigidInverseForces {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], DriveError> {
        RigidRobot::of(&self.params)?.forces(&self.attached, &self.trajectory, t)
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}
