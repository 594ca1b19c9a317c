//! The rigid-body forward dynamics reference (tests/support/rigid_forward.rs) checked against the
//! Newton-Euler rigid inverse dynamics and energy.

#[path = "../../../tests/support/rigid_forward.rs"]
#[allow(dead_code)]
mod rigid_forward;

use flexstar_drive::{ForcePolynomials, RigidInverseForces};
use flexstar_model::catalogue::paper_case;
use flexstar_model::RobotParams;
use nalgebra::Vector3;
use rigid_forward::*;

/// Kinetic energy of the rigid robot [J] from the Jacobians: `1/2 v^T M v`.
fn kinetic_energy(params: &RobotParams, s: [f64; 3], v: [f64; 3]) -> f64 {
    let (jg, jth) = jacobians(params, s).unwrap();
    let v = Vector3::from(v);
    let g_dot = jg * v;
    0.5 * params.mpp_mpa * v.norm_squared()
        + 0.5 * params.star_mass() * g_dot.norm_squared()
        + 0.5 * (params.star_inertia() + 3.0 * params.jp) * jth.dot(&v).powi(2)
}

/// Newton-Euler inverse dynamics (kinematics crate) against virtual-power forward dynamics:
/// the forces of the one, fed to the other, give the paper's motions back. Measured: 1.3e-14 m
/// at worst over the four cases (round-off: on the trajectory both give the same s'', and
/// RK4 is exact for the paper's quadratic s(t)); a wrong mass matrix or quadratic term would
/// drift by its acceleration error times t^2/2.
#[test]
fn forward_dynamics_under_the_rigid_inverse_forces_follows_each_paper_case() {
    for case in 1..=4 {
        let exp = paper_case(case);
        let params = exp.robot;
        let jets0 = exp.trajectory.jets(&params, 0.0).unwrap();
        let law = RigidInverseForces {
            trajectory: exp.trajectory.clone(),
            params,
            attached: Default::default(),
        };
        let run = rigid_forward_dynamics(
            &params,
            jets0.map(|j| j.v),
            jets0.map(|j| j.d1),
            &law,
            exp.time.t_end,
            exp.time.dt_out,
            1e-4,
        )
        .unwrap();
        let worst = run
            .iter()
            .map(|r| {
                let s = exp.trajectory.s(&params, r.t).unwrap();
                (0..3).map(|i| (r.s[i] - s[i]).abs()).fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-9,
            "case {case}: forward run leaves the trajectory by {worst:e} m"
        );
    }
}

#[test]
fn free_motion_conserves_kinetic_energy_and_converges_at_fourth_order() {
    let params = RobotParams::paper();
    let zero = ForcePolynomials {
        coefficients: [vec![0.0], vec![0.0], vec![0.0]],
    };
    let (s0, v0) = ([0.0; 3], [0.3, -0.2, 0.1]);
    let t_end = 0.2;
    let run = |dt| rigid_forward_dynamics(&params, s0, v0, &zero, t_end, 0.01, dt).unwrap();
    let (coarse, fine, finest) = (run(2e-3), run(1e-3), run(5e-4));
    let t0 = kinetic_energy(&params, s0, v0);
    for r in &finest {
        let drift = (kinetic_energy(&params, r.s, r.v) - t0).abs() / t0;
        assert!(drift < 1e-9, "energy drift {drift:e} at t = {}", r.t);
    }
    let err = |a: &[RigidSample], b: &[RigidSample]| {
        let (x, y) = (a.last().unwrap().s, b.last().unwrap().s);
        (0..3).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max)
    };
    let ratio = err(&coarse, &fine) / err(&fine, &finest);
    assert!((12.0..20.0).contains(&ratio), "RK4 error ratio {ratio}, expected ~16");
}

#[test]
fn a_run_that_leaves_the_workspace_stops_with_time_and_reason() {
    let params = RobotParams::paper();
    let push = ForcePolynomials {
        coefficients: [vec![50.0], vec![0.0], vec![0.0]],
    };
    let err = rigid_forward_dynamics(&params, [0.0; 3], [0.0; 3], &push, 2.0, 0.01, 1e-3).unwrap_err();
    match err {
        ForwardError::Infeasible { t, violation } => {
            assert!(t > 0.0 && t < 2.0, "t = {t}");
            assert!(!violation.to_string().is_empty());
        }
        other => panic!("expected an infeasible stop, got {other}"),
    }
}

/// Eqs. P7-P8 (Newton-Euler with the sleeve forces, `rigid_inverse_dynamics_with`) against Eq.
/// P9 (virtual power on the sliders, `rigid_forward_dynamics_with`) with a payload off G (mass,
/// inertia, offset) and a load with all three components: the inverse forces fed forward give
/// the motion back (a wrong payload or load term in either would drift by its acceleration
/// error times t^2/2).
#[test]
fn forward_dynamics_with_payload_and_load_follows_the_motion() {
    use flexstar_model::{Attachments, LoadSettings, Payload};
    let exp = flexstar_model::catalogue::paper_case(3);
    let params = exp.robot;
    let trajectory = flexstar_model::catalogue::quintic_from_origin(flexstar_model::catalogue::GENERAL_TARGET, 0.4);
    let attached = Attachments {
        gravity: Default::default(),
        payload: Payload {
            mass: 0.8,
            j: 3e-3,
            offset: [0.04, 0.02],
        },
        load: LoadSettings::polynomials(Some(vec![2.0, -3.0]), Some(vec![-1.0, 0.0, 5.0]), Some(vec![0.3, -0.5])),
    };
    let jets0 = trajectory.jets(&params, 0.0).unwrap();
    let law = RigidInverseForces {
        trajectory: trajectory.clone(),
        params,
        attached: attached.clone(),
    };
    let run = rigid_forward_dynamics_with(
        &params,
        &attached,
        jets0.map(|j| j.v),
        jets0.map(|j| j.d1),
        &law,
        0.5,
        1e-3,
        1e-4,
    )
    .unwrap();
    let worst = run
        .iter()
        .map(|r| {
            let s = trajectory.s(&params, r.t).unwrap();
            (0..3).map(|i| (r.s[i] - s[i]).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-8, "the loaded forward run leaves the motion by {worst:e} m");
    // and the payload matters: the bare star's forces do not give that motion
    let bare = RigidInverseForces {
        trajectory: trajectory.clone(),
        params,
        attached: Default::default(),
    };
    let run = rigid_forward_dynamics_with(
        &params,
        &attached,
        jets0.map(|j| j.v),
        jets0.map(|j| j.d1),
        &bare,
        0.5,
        1e-3,
        1e-4,
    )
    .unwrap();
    let last = run.last().unwrap();
    let s = trajectory.s(&params, last.t).unwrap();
    assert!((0..3).any(|i| (last.s[i] - s[i]).abs() > 1e-3), "{:?} vs {s:?}", last.s);
}
