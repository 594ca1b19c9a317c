//! The rigid kinematics of a robot as built (`docs/as-built.md` 2-3) against independent
//! characterisations: the loop equations K1 (each revolute point on its beam's axis, at the
//! sleeve position), high-order finite differences of the pose for the dual-number derivatives,
//! the base triangle's own vertices for the sliders' travel, and each beam's own length for the
//! sleeves' limits; and the paper's robot given as data against the paper's form, bit for bit.

use flexstar_kinematics::{check_configuration, check_trajectory, RigidState, Violation};
use flexstar_model::{ActuatorAxis, Robot, RobotGeometry, RobotParams, Trajectory};

use crate::quintic;
use quintic::quintic;

/// Unequal beams (beam 3 shorter, its sleeve longer), welds at 0, 117 and 243.5 degrees, an
/// uneven base.
fn as_built() -> Robot {
    let paper = Robot::from_params(&RobotParams::paper()).unwrap();
    let mut beams = *paper.beams();
    beams[1].weld_angle = 117f64.to_radians();
    beams[2].weld_angle = 243.5f64.to_radians();
    beams[2].length = 0.42;
    beams[2].sleeve_length = 0.036;
    let axes = ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap();
    Robot::new(beams, axes).unwrap()
}

fn move_of(from: [f64; 3], to: [f64; 3]) -> Trajectory {
    quintic(from, to, 0.4)
}

#[test]
fn the_rigid_state_satisfies_the_loop_equations_with_the_weld_angles() {
    let robot = as_built();
    let traj = move_of([0.004, -0.003, 0.01], [0.03, -0.02, 0.2]);
    for t in [0.0, 0.13, 0.27, 0.4] {
        let st = RigidState::at(&robot, &traj, t).unwrap();
        for i in 0..3 {
            // K1: P_i = G + xp_i e_xi(theta + phi_i), with e_w normal to e_x
            let (e, w) = (st.e_x(i), st.e_w(i));
            for (k, ek) in e.iter().enumerate() {
                assert!(
                    (st.p[i][k] - (st.g[k].v + st.xp[i].v * ek)).abs() < 1e-13,
                    "t = {t}, beam {i}"
                );
            }
            assert!((e[0] * w[0] + e[1] * w[1]).abs() < 1e-15);
            let angle = (e[0] * w[1] - e[1] * w[0]).asin();
            assert!(
                (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-7,
                "e_w is e_x turned +90 degrees"
            );
        }
    }
}

#[test]
fn dual_derivatives_match_finite_differences_on_a_robot_as_built() {
    let robot = as_built();
    let traj = move_of([0.0, 0.0, 0.0], [0.03, -0.02, 0.2]);
    let h = 1e-4;
    let at = |t: f64| RigidState::at(&robot, &traj, t).unwrap();
    for t in [0.11, 0.23] {
        let (m2, m1, c, p1, p2) = (at(t - 2.0 * h), at(t - h), at(t), at(t + h), at(t + 2.0 * h));
        // fourth-order central differences of theta and G
        let d1 = |f: &dyn Fn(&RigidState) -> f64| (f(&m2) - 8.0 * f(&m1) + 8.0 * f(&p1) - f(&p2)) / (12.0 * h);
        let d2 = |f: &dyn Fn(&RigidState) -> f64| {
            (-f(&m2) + 16.0 * f(&m1) - 30.0 * f(&c) + 16.0 * f(&p1) - f(&p2)) / (12.0 * h * h)
        };
        let theta = |s: &RigidState| s.theta.v;
        let gx = |s: &RigidState| s.g[0].v;
        let xp3 = |s: &RigidState| s.xp[2].v;
        assert!(
            (c.theta.d1 - d1(&theta)).abs() < 1e-8 * (1.0 + c.theta.d1.abs()),
            "t = {t}"
        );
        assert!(
            (c.theta.d2 - d2(&theta)).abs() < 1e-5 * (1.0 + c.theta.d2.abs()),
            "t = {t}"
        );
        assert!((c.g[0].d1 - d1(&gx)).abs() < 1e-8, "t = {t}");
        assert!((c.g[0].d2 - d2(&gx)).abs() < 1e-5 * (1.0 + c.g[0].d2.abs()), "t = {t}");
        assert!((c.xp[2].d1 - d1(&xp3)).abs() < 1e-8, "t = {t}");
    }
}

#[test]
fn sliders_travel_on_their_own_side_and_sleeves_on_their_own_beam() {
    let robot = as_built();
    // slider 1 runs along side 1 from A_1 (s = -t_1) to A_2 (s = l_1 - t_1)
    let l = [0.626, 0.618, 0.631];
    let p = 0.5 * (l[0] + l[1] + l[2]);
    let t = robot.slider_travel(0);
    assert!(
        (t[0] + (p - l[1])).abs() < 1e-12 && (t[1] - (l[0] - (p - l[1]))).abs() < 1e-12,
        "{t:?}"
    );
    assert!(check_configuration(&robot, [0.0, 0.0, 0.0]).is_ok());
    // beam 3 is 0.42 m with a 36 mm sleeve: xp_3 + Lp_3 / 2 < 0.42 although the others reach 0.5
    // G moved away from beam 3's sleeve along -e_x3, theta = 0: xp_3 grows
    let e3 = robot.e_x(2, 0.0);
    let s_at = |k: usize| {
        let g = [-0.002 * k as f64 * e3[0], -0.002 * k as f64 * e3[1]];
        flexstar_model::geometry::inverse_kinematics(&robot, g, 0.0).unwrap()
    };
    let far = (0..300)
        .map(s_at)
        .find(|s| check_configuration(&robot, *s).is_err())
        .unwrap();
    let err = check_configuration(&robot, far).unwrap_err();
    match err {
        Violation::SleeveOffTip { beam: 3, xp } => assert!((xp + 0.018 - 0.42).abs() < 0.003, "xp3 = {xp}"),
        other => panic!("expected sleeve 3 off its tip, got {other}"),
    }
}

#[test]
fn the_scan_finds_the_first_limit_of_a_robot_as_built() {
    let robot = as_built();
    let traj = Trajectory::Polynomial {
        s1: vec![0.0],
        s2: vec![0.0, -0.8],
        s3: vec![0.0, 0.8],
    };
    let err = check_trajectory(&robot, &traj, 0.5, 1e-3).unwrap_err();
    // the configuration just before is feasible and the one just after violates the same limit
    let s_at = |t: f64| traj.s(&robot, t).unwrap();
    assert!(check_configuration(&robot, s_at(err.t - 1e-6)).is_ok(), "{err}");
    let after = check_configuration(&robot, s_at(err.t + 1e-6)).unwrap_err();
    assert_eq!(
        std::mem::discriminant(&after),
        std::mem::discriminant(&err.violation),
        "{err} / {after}"
    );
}

#[test]
fn the_paper_robot_as_data_is_the_paper_form_bit_for_bit() {
    let params = RobotParams::paper();
    let robot = Robot::from_params(&params).unwrap();
    let traj = move_of([0.0, 0.0, 0.0], [0.03, -0.02, 0.2]);
    for t in [0.0, 0.1, 0.2, 0.35] {
        let (a, b) = (
            RigidState::at(&params, &traj, t).unwrap(),
            RigidState::at(&robot, &traj, t).unwrap(),
        );
        assert_eq!(a.theta.d2.to_bits(), b.theta.d2.to_bits());
        assert_eq!(a.g[1].d2.to_bits(), b.g[1].d2.to_bits());
        assert_eq!(a.xp[2].d1.to_bits(), b.xp[2].d1.to_bits());
        assert_eq!(a.e_w(2), b.e_w(2));
    }
}
