//! `kinematics`: the rigid kinematics of an experiment (Eqs. 1-12) over its output times.

use std::path::{Path, PathBuf};

use flexstar_kinematics::table::{kinematics_table, write_kinematics_csv};
use flexstar_kinematics::{KinematicsError, RigidState};
use flexstar_model::{Experiment, Robot};

use crate::{ApiError, Result};

/// A kinematics error on `source`: infeasible motions keep their time.
fn from_kinematics(source: &str, e: KinematicsError) -> ApiError {
    match &e {
        KinematicsError::Infeasible(inf) => ApiError::infeasible(source, inf.t, &e),
        KinematicsError::NoSolution { t, .. } | KinematicsError::Trajectory { t, .. } => {
            ApiError::infeasible(source, *t, &e)
        }
        KinematicsError::NotFinite { .. } | KinematicsError::Robot(_) => {
            ApiError::config(source, Some("robot"), e.to_string())
        }
        KinematicsError::Write(_) => ApiError::Output(e.to_string()),
    }
}

/// G, theta, xp_i and their derivatives (SI units, base frame) at every output time of `exp`
/// (from `source`), after the feasibility scan of the whole motion; the paper's robot or one as
/// built (`docs/as-built.md` 3).
pub fn table(exp: &Experiment, source: &str) -> Result<Vec<RigidState>> {
    crate::ApiError::frictionless(exp, source, "flexstar kinematics (the rigid inverse dynamics)")?;
    kinematics_table(exp).map_err(|e| from_kinematics(source, e))
}

/// Write the table to `out/<name>/kinematics.csv` (the folder checked writable first), its
/// forces the rigid inverse dynamics of the robot `exp` describes (`docs/as-built.md` 7 for a
/// robot as built).
pub fn write(out: &Path, exp: &Experiment, states: &[RigidState]) -> Result<PathBuf> {
    let source = exp.source.display().to_string();
    let robot = Robot::from_params(&exp.robot).map_err(|e| from_kinematics(&source, KinematicsError::Robot(e)))?;
    let path = crate::case_dir(out, exp)?.join("kinematics.csv");
    write_kinematics_csv(&path, &robot, &flexstar_model::Attachments::of(exp), states)
        .map_err(|e| from_kinematics(&source, e))?;
    Ok(path)
}
