//! The `kinematics.csv` table of the CLI: one row per output step.

use std::path::Path;

use flexstar_io::output::{fmt_number, write_atomically};
use flexstar_model::{Attachments, Experiment, Robot, RobotGeometry};

use crate::feasibility::check_trajectory;
use crate::star_masses::rigid_inverse_dynamics_of;
use crate::state::RigidState;
use crate::KinematicsError;

/// Column header of `kinematics.csv` (a file contract, `docs/outputs.md`): the pose and its
/// derivatives, then the slider velocities `sd_i` [m/s] and accelerations `sdd_i` [m/s^2] and the
/// rigid driving forces `Fa_i` [N] of [`rigid_inverse_dynamics_of`] (the payload, load and
/// gravity included; a robot as built by `docs/as-built.md` 7). Units: `flexstar_model::quantity::QUANTITIES`.
pub const KINEMATICS_HEADER: [&str; 23] = [
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
    "sd1",
    "sd2",
    "sd3",
    "sdd1",
    "sdd2",
    "sdd3",
    "Fa1",
    "Fa2",
    "Fa3",
];

/// Rigid states at the experiment's output times, after checking feasibility over the span, on
/// the robot the experiment describes: the paper's compact form, or its robot as built
/// (`docs/as-built.md` 3).
pub fn kinematics_table(exp: &Experiment) -> Result<Vec<RigidState>, KinematicsError> {
    let robot = Robot::from_params(&exp.robot).map_err(KinematicsError::Robot)?;
    match robot.paper_form() {
        Some(p) => states_on(p, exp),
        None => states_on(&robot, exp),
    }
}

/// [`kinematics_table`] on the geometry `robot`.
fn states_on<K: RobotGeometry + ?Sized>(robot: &K, exp: &Experiment) -> Result<Vec<RigidState>, KinematicsError> {
    check_trajectory(robot, &exp.trajectory, exp.time.t_end, exp.time.dt_out)?;
    exp.time
        .output_times()
        .into_iter()
        .map(|t| RigidState::at(robot, &exp.trajectory, t))
        .collect()
}

/// One CSV row in the order of [`KINEMATICS_HEADER`] for `robot` carrying `attached`.
pub fn row(robot: &Robot, attached: &Attachments, st: &RigidState) -> [f64; 23] {
    let fa = rigid_inverse_dynamics_of(robot, attached, st).fa;
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
        st.s[0].d1,
        st.s[1].d1,
        st.s[2].d1,
        st.s[0].d2,
        st.s[1].d2,
        st.s[2].d2,
        fa[0],
        fa[1],
        fa[2],
    ]
}

/// The rows of the table ([`row`]), refused at the first value that is not finite (a robot whose
/// values overflow a derived quantity, e.g. a slider mass that makes `Fa` infinite): the error
/// names the time and the column.
pub fn kinematics_rows(
    robot: &Robot,
    attached: &Attachments,
    states: &[RigidState],
) -> Result<Vec<[f64; 23]>, KinematicsError> {
    states
        .iter()
        .map(|st| {
            let r = row(robot, attached, st);
            match r.iter().position(|v| !v.is_finite()) {
                None => Ok(r),
                Some(k) => Err(KinematicsError::NotFinite {
                    t: st.t,
                    column: KINEMATICS_HEADER[k],
                    value: r[k],
                }),
            }
        })
        .collect()
}

/// Write the table of `robot` carrying `attached` as CSV, whole or not at all; nothing is written
/// when a value is not finite ([`kinematics_rows`]).
pub fn write_kinematics_csv(
    path: &Path,
    robot: &Robot,
    attached: &Attachments,
    states: &[RigidState],
) -> Result<(), KinematicsError> {
    let rows = kinematics_rows(robot, attached, states)?;
    write_atomically(path, |w| {
        let mut out = csv::Writer::from_writer(w);
        out.write_record(KINEMATICS_HEADER)?;
        for r in &rows {
            out.write_record(r.iter().map(|v| fmt_number(*v)))?;
        }
        out.flush()?;
        Ok(())
    })
    .map_err(|e| KinematicsError::Write(e.into()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::catalogue::paper_case;

    #[test]
    fn every_column_has_a_unit_and_the_forces_are_the_rigid_inverse_dynamics() {
        for name in KINEMATICS_HEADER {
            assert!(
                flexstar_model::quantity::column_unit(name).is_some(),
                "{name} has no unit"
            );
        }
        let exp = paper_case(3);
        let st = RigidState::at(&exp.robot, &exp.trajectory, 0.25).unwrap();
        let robot = Robot::from_params(&exp.robot).unwrap();
        let r = row(&robot, &Attachments::default(), &st);
        let col = |name: &str| r[KINEMATICS_HEADER.iter().position(|c| *c == name).unwrap()];
        let f = crate::rigid_inverse_dynamics(&exp.robot, &st);
        for i in 0..3 {
            assert_eq!(col(&format!("Fa{}", i + 1)), f.fa[i]);
            assert_eq!(col(&format!("sd{}", i + 1)), st.s[i].d1);
            assert_eq!(col(&format!("sdd{}", i + 1)), st.s[i].d2);
        }
        // today's columns keep their place
        assert_eq!(
            KINEMATICS_HEADER[..14].join(","),
            "t,s1,s2,s3,Gx,Gy,theta,xp1,xp2,xp3,aGx,aGy,thetadot,thetaddot"
        );
    }
}
