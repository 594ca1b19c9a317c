//! Actuator drives of the 3-PRP star-triangle robot (direct dynamics, `docs/drives.md`).
//!
//! The paper solves the inverse problem (motion given, Eq. 33 gives the forces). In the direct
//! problem the slider positions `s_i` are unknowns and each slider is pushed along `+u_i` by a
//! force `Fa_i` that depends on time and, for a servo, on the slider's own state. Both solvers
//! (AMM and FEM) take the drive as an [`ActuatorLaw`], so they never need to know which kind of
//! drive it is.
//!
//! Sign convention (docs/conventions.md, "Forces"): `Fa_i` [N] is the force actuator `i` applies to
//! its slider along `+u_i`.

/// A drive: the actuator forces as a function of time and of the sliders' state.
///
/// The law is diagonal: `Fa_i` depends on `s_i` and `s_i'` only (each actuator sees its own
/// slider), which is what a per-axis servo does and what a prescribed force profile does
/// trivially (no dependence at all).
pub trait ActuatorLaw: Send + Sync {
    /// `Fa_i` [N] at time `t` [s] with slider positions `s` [m] and speeds `v` [m/s].
    /// Errors only where the law cannot be evaluated (a servo reference outside its valid range).
    fn force(&self, t: f64, s: [f64; 3], v: [f64; 3]) -> Result<[f64; 3], DriveError>;

    /// `-dFa_i/ds_i` [N/m], constant: the servo's `kp`, zero for prescribed forces. Implicit
    /// integrators put it in their iteration matrix.
    fn stiffness(&self) -> [f64; 3];

    /// `-dFa_i/ds_i'` [N s/m], constant: the servo's `kd`, zero for prescribed forces.
    fn damping(&self) -> [f64; 3];
}

mod laws;
mod request;

pub use laws::{ForcePolynomials, ForceTable, ReferencePoint, RigidInverseForces, Servo};
pub use request::{Drive, Progress, SolveRequest, Solved};

use flexstar_model::{DriveKind, Feedforward, Problem, RobotGeometry};

/// The actuator law of a problem's drive (`docs/drives.md`): `None` for `kind = "motion"` (the
/// trajectory is imposed), else the forces (table or polynomials) or the servo tracking
/// the problem's trajectory with its gains resolved (`bandwidth_hz` with each slider's mass
/// `mpp_mpa_i`). The drive was validated with the problem; errors name the `drive.` key. Every
/// drive takes any robot: a servo on a robot as built has its own slider masses in its gains and
/// the robot's rigid inverse dynamics as feed-forward (`docs/as-built.md` 7).
pub fn law_for(problem: &flexstar_model::Problem) -> Result<Option<Box<dyn ActuatorLaw>>, DriveError> {
    let d = problem.drive();
    let invalid = |e: flexstar_model::ModelError| match e {
        flexstar_model::ModelError::Invalid { key, reason, .. } => DriveError::Config(format!("key `{key}`: {reason}")),
        other => DriveError::Config(other.to_string()),
    };
    Ok(match d.kind {
        DriveKind::Motion => None,
        DriveKind::Forces => match (&d.samples, &d.fa1, &d.fa2, &d.fa3) {
            (Some(s), _, _, _) => Some(Box::new(ForceTable::new(s.t.clone(), s.fa.clone())?)),
            (None, Some(a), Some(b), Some(c)) => Some(Box::new(ForcePolynomials {
                coefficients: [a.clone(), b.clone(), c.clone()],
            })),
            _ => {
                return Err(DriveError::Config(
                    "drive: forces given neither as a file nor as Fa1, Fa2, Fa3".into(),
                ))
            }
        },
        DriveKind::Servo => {
            let robot = problem.robot();
            let g = d.slider_gains(robot.beams().map(|b| b.sleeve_mass)).map_err(invalid)?;
            Some(Box::new(Servo {
                kp: g.map(|g| g.kp),
                kd: g.map(|g| g.kd),
                rigid_feedforward: d.feedforward.unwrap_or_default() == Feedforward::Rigid,
                reference: problem.trajectory().clone(),
                params: robot.to_params(),
                attached: flexstar_model::Attachments {
                    payload: *problem.payload(),
                    load: problem.load().clone(),
                    gravity: flexstar_model::Gravity::new(problem.gravity()),
                },
            }))
        }
    })
}

/// Errors of the drives; the config loader adds file and key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DriveError {
    /// A force table that cannot be used (row and reason).
    #[error("force table: {0}")]
    Table(#[from] flexstar_model::SampleError),
    /// The servo reference cannot be evaluated at time `t`.
    #[error("servo reference at t = {t} s: {reason}")]
    Reference { t: f64, reason: String },
    /// The `[drive]` section cannot be turned into a law (the message names the key).
    #[error("{0}")]
    Config(String),
}

/// Add the servo's tracking errors `e_i = s_ref,i(t) - s_i(t)` [m] to a direct run's response
/// as columns `e1, e2, e3` (after its other columns), from its `s1, s2, s3` columns and the
/// reference, the problem's trajectory on its robot (the paper's form or one as built).
pub fn add_tracking_errors(resp: &mut flexstar_model::Response, problem: &Problem) -> Result<(), DriveError> {
    let robot = problem.robot();
    let reference = |t: f64| match robot.paper_form() {
        Some(p) => problem.trajectory().s(p, t),
        None => problem.trajectory().s(robot, t),
    };
    let mut cols = [Vec::new(), Vec::new(), Vec::new()];
    for (i, col) in cols.iter_mut().enumerate() {
        let name = ["s1", "s2", "s3"][i];
        let s = resp
            .column(name)
            .ok_or_else(|| DriveError::Config(format!("the direct run has no column {name}")))?;
        *col = Vec::with_capacity(s.len());
        for (&t, &si) in resp.t.iter().zip(s) {
            let r = reference(t).map_err(|e| DriveError::Reference {
                t,
                reason: e.to_string(),
            })?;
            col.push(r[i] - si);
        }
    }
    for (name, values) in ["e1", "e2", "e3"].into_iter().zip(cols) {
        resp.extra.push(flexstar_model::Column {
            name: name.into(),
            values,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_interpolates_linearly_and_rejects_bad_rows() {
        let tab = ForceTable::new(
            vec![0.0, 1.0, 3.0],
            vec![[0.0, 1.0, 2.0], [2.0, 1.0, 0.0], [6.0, 1.0, -4.0]],
        )
        .unwrap();
        // A linear function of t sampled at the nodes is reproduced exactly in between.
        let f = tab.at(2.0);
        assert!((f[0] - 4.0).abs() < 1e-15 && (f[2] + 2.0).abs() < 1e-15);
        assert_eq!(tab.at(-1.0), [0.0, 1.0, 2.0]);
        assert!(tab.check_covers(0.0, 3.0).is_ok());
        assert!(tab.check_covers(0.0, 3.5).is_err());
        let err = ForceTable::new(vec![0.0, 0.0], vec![[0.0; 3]; 2]).unwrap_err();
        assert!(err.to_string().contains("row 2"), "{err}");
        assert!(ForceTable::new(vec![0.0, f64::NAN], vec![[0.0; 3]; 2]).is_err());
    }

    /// The law of an experiment's drive, through its problem (where the drive is validated).
    fn law_of(exp: &flexstar_model::Experiment) -> Result<Option<Box<dyn ActuatorLaw>>, String> {
        let problem = exp.problem().map_err(|e| e.to_string())?;
        law_for(&problem).map_err(|e| e.to_string())
    }

    #[test]
    fn law_for_builds_each_kind() {
        let mut exp = flexstar_model::catalogue::paper_case(1);
        assert!(law_of(&exp).unwrap().is_none());
        exp.drive.kind = DriveKind::Forces;
        exp.drive.fa1 = Some(vec![1.0, 2.0]);
        exp.drive.fa2 = Some(vec![0.0]);
        exp.drive.fa3 = Some(vec![0.0, 0.0, 3.0]);
        let law = law_of(&exp).unwrap().unwrap();
        assert_eq!(law.force(2.0, [0.0; 3], [0.0; 3]).unwrap(), [5.0, 0.0, 12.0]);
        assert_eq!(law.stiffness(), [0.0; 3]);
        let mut exp = flexstar_model::catalogue::paper_case(1);
        exp.drive.kind = DriveKind::Servo;
        exp.drive.bandwidth_hz = Some(20.0);
        exp.drive.damping_ratio = Some(0.7);
        let law = law_of(&exp).unwrap().unwrap();
        let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 20.0, 0.7);
        assert_eq!((law.stiffness()[1], law.damping()[2]), (kp, kd));
        exp.drive.kp = Some(1.0);
        exp.drive.kd = Some(1.0);
        let e = law_of(&exp).err().unwrap();
        assert!(e.contains("drive.bandwidth_hz"), "{e}");
    }

    /// A servo on a robot as built: each slider's gains on its own mass, and at zero tracking
    /// error the robot as built's rigid inverse dynamics (`docs/as-built.md` 7) on its own
    /// geometry.
    #[test]
    fn a_servo_on_a_robot_as_built_has_its_own_gains_and_feedforward() {
        let text = "name = \"b\"\n[time]\nt_end = 0.3\n[trajectory]\nkind = \"quintic\"\n\
                    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.02, Gy = -0.01, theta = 0.1 }\n\
                    t0 = 0.0\nt1 = 0.25\n[robot]\nL = [0.52, 0.48, 0.5]\nmpp_mpa = [0.2, 0.26, 0.17]\n\
                    weld_deg = [0, 118, 242.5]\n[base]\nsides = [0.63, 0.6, 0.64]\n[gravity]\ng = [0.0, -9.81]\n\
                    [drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n";
        let exp = flexstar_model::Experiment::from_toml_str(text, std::path::Path::new("b.toml")).unwrap();
        let problem = exp.problem().unwrap();
        let law = law_for(&problem).unwrap().unwrap();
        for (i, m) in [0.2, 0.26, 0.17].into_iter().enumerate() {
            let (kp, kd) = Servo::gains_from_bandwidth(m, 20.0, 0.7);
            assert_eq!((law.stiffness()[i], law.damping()[i]), (kp, kd), "slider {}", i + 1);
        }
        let robot = problem.robot();
        let t = 0.12;
        let jets = problem.trajectory().jets(robot, t).unwrap();
        let f = law.force(t, jets.map(|j| j.v), jets.map(|j| j.d1)).unwrap();
        let state = flexstar_kinematics::RigidState::at(robot, problem.trajectory(), t).unwrap();
        let attached = flexstar_model::Attachments::of(&exp);
        let ff = flexstar_kinematics::rigid_inverse_dynamics_of(robot, &attached, &state).fa;
        for i in 0..3 {
            assert!((f[i] - ff[i]).abs() < 1e-12 * ff[i].abs().max(1.0), "{f:?} vs {ff:?}");
        }
    }

    #[test]
    fn bandwidth_gains_give_the_requested_free_mass_poles() {
        // m x'' + kd x' + kp x = 0 has natural frequency sqrt(kp/m) and ratio kd/(2 sqrt(kp m)).
        let (kp, kd) = Servo::gains_from_bandwidth(2.5, 20.0, 0.7);
        let wn = (kp / 2.5_f64).sqrt();
        assert!((wn / (2.0 * std::f64::consts::PI) - 20.0).abs() < 1e-12);
        assert!((kd / (2.0 * (kp * 2.5_f64).sqrt()) - 0.7).abs() < 1e-12);
    }

    #[test]
    fn servo_with_zero_error_returns_the_rigid_feedforward() {
        let params = flexstar_model::RobotParams::paper();
        let reference = flexstar_model::catalogue::paper_case(1).trajectory;
        let servo = Servo {
            kp: [1e5; 3],
            kd: [1e3; 3],
            rigid_feedforward: true,
            reference: reference.clone(),
            params,
            attached: Default::default(),
        };
        let t = 0.2;
        let jets = reference.jets(&params, t).unwrap();
        let f = servo.force(t, jets.map(|j| j.v), jets.map(|j| j.d1)).unwrap();
        let state = flexstar_kinematics::RigidState::at(&params, &reference, t).unwrap();
        let ff = flexstar_kinematics::rigid_inverse_dynamics(&params, &state).fa;
        for i in 0..3 {
            assert!((f[i] - ff[i]).abs() < 1e-9 * ff[i].abs().max(1.0));
        }
        // 1 mm behind the reference on slider 1: kp * 1e-3 more push.
        let mut s = jets.map(|j| j.v);
        s[0] -= 1e-3;
        let g = servo.force(t, s, jets.map(|j| j.d1)).unwrap();
        assert!((g[0] - ff[0] - 100.0).abs() < 1e-9);
    }
}
