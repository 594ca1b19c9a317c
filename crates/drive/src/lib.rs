//! Actuator drives of the 3-PRP star-triangle robot (issue 10: direct dynamics).
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
pub mod rigid_forward;

pub use laws::{ForcePolynomials, ForceTable, ReferencePoint, RigidInverseForces, Servo};
pub use rigid_forward::{rigid_forward_dynamics, RigidSample};

/// Errors of the drives; the config loader adds file and key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DriveError {
    /// A force table that cannot be used (row and reason).
    #[error("force table: {0}")]
    Table(String),
    /// The servo reference cannot be evaluated at time `t`.
    #[error("servo reference at t = {t} s: {reason}")]
    Reference { t: f64, reason: String },
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
