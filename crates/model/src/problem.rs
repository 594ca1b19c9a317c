//! What a solver solves: the robot and its run, validated once and immutable
//! (`docs/architecture.md`, "The robot description").
//!
//! An [`Experiment`] is what a TOML file says (names, solver settings, reports, all public and
//! mutable); a [`Problem`] is the part of it that is physics: the [`Robot`], the time span, the
//! trajectory, the drive and the attachments. [`Problem::new`] is the one validating conversion
//! (the keys named as in the file); the solvers take a `&Problem` and never check it again.

use crate::attachments::{Damping, LoadSettings, Payload};
use crate::config::{Experiment, TimeSpan};
use crate::drive_section::DriveSettings;
use crate::error::ModelError;
use crate::params::RobotParams;
use crate::robot::Robot;
use crate::trajectory::Trajectory;

/// The robot and its run, validated (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    robot: Robot,
    time: TimeSpan,
    trajectory: Trajectory,
    drive: DriveSettings,
    payload: Payload,
    damping: Damping,
    load: LoadSettings,
    gravity: [f64; 2],
    friction: Option<crate::Friction>,
    sensors: crate::sensors::Sensors,
}

impl Problem {
    /// The physics of `exp`, every value checked: the robot, the time span, the trajectory (and
    /// that a rest-to-rest motion ends by `t_end`), the drive, the payload, the damping and the
    /// load. A pending `[shaper] f_hz = "auto"` is refused: the motion would run unshaped (apply
    /// it first, `flexstar_shaping::shape`). Errors name the key; the file is added by the loader.
    pub fn new(exp: &Experiment) -> Result<Self, ModelError> {
        if exp.damping.pending() {
            return Err(ModelError::invalid(
                "damping.f_hz",
                "zeta without f_hz holds at the first frequency at the start pose, not computed yet: resolve it \
                 first (flexstar_shaping::shape)",
            ));
        }
        if exp.shaper_pending() {
            return Err(ModelError::invalid(
                "shaper.f_hz",
                "\"auto\" is not resolved yet: apply the shaper first (flexstar_shaping::shape)",
            ));
        }
        let robot = check_physics(exp)?;
        let sensors = sensors_of(exp, &robot)?;
        Ok(Problem {
            robot,
            time: exp.time,
            trajectory: exp.trajectory.clone(),
            drive: exp.drive.clone(),
            payload: exp.payload,
            damping: exp.damping,
            load: exp.load.clone(),
            gravity: exp.gravity.g,
            friction: exp.friction.filter(|f| !f.is_none()),
            sensors,
        })
    }

    /// The robot: per-beam data and the actuator axes.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The problem as the solvers' equal-beam models read it: its parts, with the robot in the
    /// paper's form. This is the explicit check of [`Robot::equal_beams`]; its error names the
    /// datum that makes the robot other than the paper's.
    pub fn equal_beams(&self) -> Result<EqualBeams<'_>, ModelError> {
        let robot = self.robot.equal_beams()?;
        Ok(EqualBeams {
            robot,
            time: self.time,
            trajectory: &self.trajectory,
            drive: &self.drive,
            payload: &self.payload,
            damping: &self.damping,
            load: &self.load,
            gravity: self.gravity,
        })
    }

    /// The same run on another robot. The checks that depend on the robot are run again: the
    /// servo's slider masses on any robot, the trajectory's start on a robot in the paper's form,
    /// every sensor's point on its beam (`docs/sensors.md` section 5; where the sleeves pass,
    /// Eq. S10, needs the kinematics: `flexstar_kinematics::check_problem_sensor_mounts`, which
    /// `flexstar_solve` runs before any solve).
    pub fn with_robot(&self, robot: Robot) -> Result<Self, ModelError> {
        if let Ok(p) = robot.equal_beams() {
            self.trajectory.validate(p)?;
        }
        self.drive.validate(self.time.t_end, slider_masses(&robot))?;
        self.sensors.check_on(&robot)?;
        Ok(Problem { robot, ..self.clone() })
    }

    /// Simulated span and output step.
    pub fn time(&self) -> &TimeSpan {
        &self.time
    }

    /// The actuator motion `s_i(t)` (already shaped, when the experiment has a shaper).
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// What moves the sliders: the trajectory, forces or a servo.
    pub fn drive(&self) -> &DriveSettings {
        &self.drive
    }

    /// The rigid body welded at G (zero mass: none).
    pub fn payload(&self) -> &Payload {
        &self.payload
    }

    /// The beams' damping.
    pub fn damping(&self) -> &Damping {
        &self.damping
    }

    /// The force and moment at G.
    pub fn load(&self) -> &LoadSettings {
        &self.load
    }

    /// Gravity `[gx, gy]` [m/s^2], base frame (`docs/as-built.md` 5); `[0, 0]`: none.
    pub fn gravity(&self) -> [f64; 2] {
        self.gravity
    }

    /// Friction in the sleeves and on the rails (`docs/friction.md`); `None`: none (also for a
    /// `[friction]` whose coefficients are all zero, which is the frictionless run bit for bit).
    /// The sensors read during the run (`[[sensors]]`, `docs/sensors.md`; empty without).
    pub fn sensors(&self) -> &crate::sensors::Sensors {
        &self.sensors
    }

    pub fn friction(&self) -> Option<&crate::Friction> {
        self.friction.as_ref()
    }

    /// For a solver or command `by` that does not model friction yet: an error naming the key
    /// `friction` and `by` when the problem has friction (`docs/friction.md` 6).
    pub fn frictionless(&self, by: &str) -> Result<(), ModelError> {
        match self.friction {
            Some(_) => Err(crate::friction::unsupported(by)),
            None => Ok(()),
        }
    }
}

/// Check every physical value of `exp` (all but a pending shaper): the robot it describes.
pub(crate) fn check_physics(exp: &Experiment) -> Result<Robot, ModelError> {
    let robot = Robot::from_params(&exp.robot)?;
    exp.time.validate()?;
    exp.trajectory.validate(&exp.robot)?;
    exp.check_motion_fits()?;
    exp.drive.validate(exp.time.t_end, slider_masses(&robot))?;
    exp.payload.validate()?;
    exp.damping.validate()?;
    exp.load.validate(exp.time.t_end)?;
    exp.gravity.validate()?;
    if let Some(f) = &exp.friction {
        f.validate()?;
    }
    let sensors = sensors_of(exp, &robot)?;
    if let Some(m) = &exp.measured {
        m.validate(&sensors.columns(), exp.time.t_end)?;
    }
    Ok(robot)
}

/// Each slider's mass with its sleeve, `mpp_mpa_i` [kg] (a servo's gains from a bandwidth).
/// The checked `[[sensors]]` of `exp` on `robot` (`docs/sensors.md` section 5).
fn sensors_of(exp: &Experiment, robot: &Robot) -> Result<crate::sensors::Sensors, ModelError> {
    crate::sensors::Sensors::from_specs(&exp.sensors, robot, !exp.payload.is_none(), exp.time.dt_out)
}

fn slider_masses(robot: &Robot) -> [f64; 3] {
    robot.beams().map(|b| b.sleeve_mass)
}

/// A [`Problem`] whose robot is the paper's: three equal beams welded 120 degrees apart on an
/// equilateral base ([`Problem::equal_beams`]). The parts of the problem by reference, the time
/// span by value (a solver's coarse internal runs change its output step).
#[derive(Debug, Clone, Copy)]
pub struct EqualBeams<'a> {
    /// The robot in the paper's form (section 8 keys).
    pub robot: &'a RobotParams,
    pub time: TimeSpan,
    pub trajectory: &'a Trajectory,
    pub drive: &'a DriveSettings,
    pub payload: &'a Payload,
    pub damping: &'a Damping,
    pub load: &'a LoadSettings,
    /// Gravity `[gx, gy]` [m/s^2], base frame.
    pub gravity: [f64; 2],
}

impl Experiment {
    /// The physics of this experiment as the solvers take it ([`Problem::new`]).
    pub fn problem(&self) -> Result<Problem, ModelError> {
        Problem::new(self)
    }
}
