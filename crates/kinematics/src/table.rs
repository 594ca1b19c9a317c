//! The `kinematics.csv` table of the CLI: one row per output step.

use std::path::Path;

use flexstar_model::output::{fmt_number, write_atomically};
use flexstar_model::Experiment;

use crate::feasibility::check_trajectory;
use crate::state::RigidState;
use crate::KinematicsError;

/// Column header of `kinematics.csv` (issue contract).
pub const KINEMATICS_HEADER: [&str; 14] = [
    "t",
    "s1",
    "s2",
    "s3",
    "Gx",
    "Gy",
    "theta",
    "xp1",
    "xp2",
    "xp3",
    "aGx",
    "aGy",
    "thetadot",
    "thetaddot",
];

/// Rigid states at the experiment's output times, after checking feasibility over the span.
pub fn kinematics_table(exp: &Experiment) -> Result<Vec<RigidState>, KinematicsError> {
    check_trajectory(&exp.robot, &exp.trajectory, exp.time.t_end, exp.time.dt_out)?;
    exp.time
        .output_times()
        .into_iter()
        .map(|t| RigidState::at(&exp.robot, &exp.trajectory, t))
        .collect()
}

/// One CSV row in the order of [`KINEMATICS_HEADER`].
pub fn row(st: &RigidState) -> [f64; 14] {
    [
        st.t,
        st.s[0].v,
        st.s[1].v,
        st.s[2].v,
        st.g[0].v,
        st.g[1].v,
        st.theta.v,
        st.xp[0].v,
        st.xp[1].v,
        st.xp[2].v,
        st.g[0].d2,
        st.g[1].d2,
        st.theta.d1,
        st.theta.d2,
    ]
}

/// Write the table as CSV, whole or not at all.
pub fn write_kinematics_csv(path: &Path, states: &[RigidState]) -> Result<(), KinematicsError> {
    write_atomically(path, |w| {
        let mut out = csv::Writer::from_writer(w);
        out.write_record(KINEMATICS_HEADER)?;
        for st in states {
            out.write_record(row(st).iter().map(|v| fmt_number(*v)))?;
        }
        out.flush()?;
        Ok(())
    })
    .map_err(KinematicsError::Write)
}
