//! # flexstar-model
//!
//! The data every other flexstar crate shares: the robot description ([`Robot`], per beam) and
//! the validated [`Problem`] the solvers take, the robot's parameters in the paper's form
//! (section 8), the base geometry (Eqs. 1-3), the actuator trajectories `s_i(t)`, the TOML
//! experiment files and the [`Response`] that every solver returns. No solver code lives here.
//!
//! Conventions (frames, signs, units) are written once, in `docs/conventions.md`; the items here
//! follow them. All quantities are SI: metres, seconds, kilograms, newtons, radians.

pub mod animation;
pub mod attachments;
pub mod cancel;
pub mod catalogue;
pub mod config;
pub mod damping;
pub mod drive_section;
pub mod error;
pub mod fit_section;
pub mod friction;
pub mod friction_events;
pub mod friction_run;
pub mod geometry;
pub mod gravity;
pub mod hash;
pub mod identity;
pub mod measured_section;
pub mod motion;
pub mod params;
pub mod problem;
pub mod provenance;
pub mod quantity;
pub mod response;
pub mod rest_pose;
pub mod robot;
pub mod robot_geometry;
pub mod robot_section;
pub mod sensors;
pub mod shaper;
pub mod sidecar;
pub mod sleeve_contact;
pub mod spline;
pub mod trajectory;

pub use animation::{Frame, FramePose};
pub use attachments::{Attachments, Damping, LoadSettings, Payload};
pub use cancel::Cancel;
pub use config::{AmmModel, AmmSettings, Experiment, FemSettings, ModeCount, ModeFamily, ReportSettings, TimeSpan};
pub use damping::ModeValues;
pub use drive_section::{DriveKind, DriveSettings, Feedforward, ForceSamples};
pub use error::{ModelError, SampleError};
pub use fit_section::{FitParam, FitSection};
pub use friction::{Friction, FrictionSummary, NormalLoad, RailFriction, RailLaw, SleeveLaw};
pub use friction_run::{Contact, FrictionSample, FrictionTally};
pub use gravity::Gravity;
pub use measured_section::{MeasuredSection, Offset};
pub use motion::{TableMotion, TableSpace, ViaMotion, ViaPoint};
pub use params::RobotParams;
pub use problem::{EqualBeams, Problem};
pub use provenance::Provenance;
pub use response::{BeamShape, Column, Response, RestOffset, RunInfo, StarShape};
pub use rest_pose::{RestPose, Sleeves, Sliders};
pub use robot::{ActuatorAxis, Beam, Robot};
pub use robot_geometry::{FeasibilityKey, RobotGeometry};
pub use sensors::{SensorSpec, SensorTable, Sensors};
pub use shaper::{Impulse, ShaperKind, ShaperSection};
pub use sidecar::{DwellKeys, FrictionRestKeys, ResidualKeys, RunSidecar, ValidityExceeded};
pub use trajectory::{Pose, ShapedMotion, Trajectory};
