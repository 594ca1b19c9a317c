//! Rigid kinematics against independent references: the geometric definition of the Fermat
//! point (120-degree angles), its variational characterisation (minimum of |GI|+|GJ|+|GK|, found
//! here by Weiszfeld's iteration), the closed-form case 1 of the paper, high-order finite
//! differences of the positions, and the energy balance of the rigid-body inverse dynamics.

use flexstar_kinematics::{
    check_trajectory, direct_kinematics, inverse_kinematics, rigid_inverse_dynamics, RigidState, Violation,
};
use flexstar_model::geometry::{revolute_point, slider_direction};
use flexstar_model::{RobotParams, Trajectory};
use proptest::prelude::*;

use crate::quintic;
use quintic::quintic;

fn paper() -> RobotParams {
    RobotParams::paper()
}

/// Weiszfeld's fixed-point iteration for the geometric median of three points.
fn weiszfeld(p: &[[f64; 2]; 3]) -> [f64; 2] {
    let mut g = [(p[0][0] + p[1][0] + p[2][0]) / 3.0, (p[0][1] + p[1][1] + p[2][1]) / 3.0];
    for _ in 0..20_000 {
        let (mut nx, mut ny, mut den) = (0.0, 0.0, 0.0);
        for q in p {
            let r = ((q[0] - g[0]).powi(2) + (q[1] - g[1]).powi(2)).sqrt().max(1e-300);
            nx += q[0] / r;
            ny += q[1] / r;
            den += 1.0 / r;
        }
        g = [nx / den, ny / den];
    }
    g
}

fn angle(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]).abs()
}

/// Actuator coordinates inside the feasible range of the paper's robot, drawn as poses.
fn feasible_pose() -> impl Strategy<Value = (f64, f64, f64)> {
    (-0.06..0.06f64, -0.06..0.06f64, -0.5..0.5f64)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn fermat_point_sees_vertices_at_120_degrees_and_minimises_distance((gx, gy, th) in feasible_pose()) {
        let p = paper();
        let s = inverse_kinematics(&p, [gx, gy], th).unwrap();
        let pose = direct_kinematics(p.d, s).unwrap();
        let v = pose.p.map(|q| [q[0] - pose.g[0], q[1] - pose.g[1]]);
        for k in 0..3 {
            let a = angle(v[k], v[(k + 1) % 3]);
            prop_assert!((a - 2.0 * std::f64::consts::FRAC_PI_3).abs() < 1e-9, "angle {a}");
        }
        let w = weiszfeld(&pose.p);
        prop_assert!((w[0] - pose.g[0]).abs() < 1e-7 && (w[1] - pose.g[1]).abs() < 1e-7, "weiszfeld {w:?} vs {:?}", pose.g);
    }

    #[test]
    fn inverse_of_direct_is_identity((gx, gy, th) in feasible_pose()) {
        let p = paper();
        let s = inverse_kinematics(&p, [gx, gy], th).unwrap();
        let pose = direct_kinematics(p.d, s).unwrap();
        prop_assert!((pose.g[0] - gx).abs() < 1e-12 && (pose.g[1] - gy).abs() < 1e-12);
        prop_assert!((pose.theta - th).abs() < 1e-12);
        let s2 = inverse_kinematics(&p, pose.g, pose.theta).unwrap();
        for i in 0..3 {
            prop_assert!((s2[i] - s[i]).abs() < 1e-12);
        }
    }

    #[test]
    fn direct_of_random_strokes_round_trips(s in prop::array::uniform3(-0.1..0.1f64)) {
        let p = paper();
        prop_assume!(flexstar_kinematics::feasibility::is_feasible_configuration(&p, s));
        let pose = direct_kinematics(p.d, s).unwrap();
        let back = inverse_kinematics(&p, pose.g, pose.theta).unwrap();
        for i in 0..3 {
            prop_assert!((back[i] - s[i]).abs() < 1e-11, "{back:?} vs {s:?}");
        }
    }
}

#[test]
fn case1_is_rotation_about_the_centre() {
    // s_i = t^2: G = O and theta = atan(t^2 / d) (I = (t^2, -d) seen from O).
    let p = paper();
    let tr = Trajectory::quadratic([1.0, 1.0, 1.0]);
    for k in 0..=10 {
        let t = 0.05 * k as f64;
        let st = RigidState::at(&p, &tr, t).unwrap();
        assert!(st.g[0].v.abs() < 1e-14 && st.g[1].v.abs() < 1e-14, "t = {t}");
        assert!(st.g[0].d2.abs() < 1e-12 && st.g[1].d2.abs() < 1e-12);
        let th = (t * t / p.d).atan();
        assert!((st.theta.v - th).abs() < 1e-14);
        // d/dt atan(t^2/d) = 2 t d / (d^2 + t^4)
        let thd = 2.0 * t * p.d / (p.d * p.d + t.powi(4));
        assert!((st.theta.d1 - thd).abs() < 1e-12);
        let xp = (p.d * p.d + t.powi(4)).sqrt();
        for i in 0..3 {
            assert!((st.xp[i].v - xp).abs() < 1e-14);
        }
    }
}

/// 8th-order central differences of f at t with step h: (first, second derivative).
fn fd8(f: &dyn Fn(f64) -> f64, t: f64, h: f64) -> (f64, f64) {
    let c1 = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
    let c2 = [8.0 / 5.0, -1.0 / 5.0, 8.0 / 315.0, -1.0 / 560.0];
    let mut d1 = 0.0;
    let mut d2 = -205.0 / 72.0 * f(t);
    for k in 1..=4 {
        let (fp, fm) = (f(t + k as f64 * h), f(t - k as f64 * h));
        d1 += c1[k - 1] * (fp - fm);
        d2 += c2[k - 1] * (fp + fm);
    }
    (d1 / h, d2 / (h * h))
}

#[test]
fn derivatives_agree_with_finite_differences() {
    let p = paper();
    let cases = [
        Trajectory::quadratic([1.0, -0.5, -0.5]),
        Trajectory::quadratic([1.0, 0.0, 0.5]),
        Trajectory::quadratic([1.0, -1.0, 0.0]),
        Trajectory::Polynomial {
            s1: vec![0.0, 0.02, 0.3, -0.4],
            s2: vec![0.0, -0.05, 0.1],
            s3: vec![0.0, 0.0, 0.0, 0.7],
        },
    ];
    for tr in &cases {
        for t in [0.1, 0.2, 0.3] {
            let st = RigidState::at(&p, tr, t).unwrap();
            let at = |t: f64| RigidState::at(&p, tr, t).unwrap();
            type Check<'a> = (&'a dyn Fn(f64) -> f64, [f64; 2]);
            let checks: [Check; 6] = [
                (&|t| at(t).g[0].v, [st.g[0].d1, st.g[0].d2]),
                (&|t| at(t).g[1].v, [st.g[1].d1, st.g[1].d2]),
                (&|t| at(t).theta.v, [st.theta.d1, st.theta.d2]),
                (&|t| at(t).xp[0].v, [st.xp[0].d1, st.xp[0].d2]),
                (&|t| at(t).xp[1].v, [st.xp[1].d1, st.xp[1].d2]),
                (&|t| at(t).xp[2].v, [st.xp[2].d1, st.xp[2].d2]),
            ];
            for (k, (f, ad)) in checks.iter().enumerate() {
                let (d1, d2) = fd8(*f, t, 1e-3);
                assert!(
                    (d1 - ad[0]).abs() < 1e-8 * (1.0 + ad[0].abs()),
                    "{tr:?} t={t} quantity {k}: fd {d1} ad {}",
                    ad[0]
                );
                assert!(
                    (d2 - ad[1]).abs() < 1e-6 * (1.0 + ad[1].abs()),
                    "{tr:?} t={t} quantity {k}: fd {d2} ad {}",
                    ad[1]
                );
            }
        }
    }
}

#[test]
fn rigid_point_accelerations_match_eqs_11_12() {
    // Second derivative of the rigid beam point position, projected on e_x / e_w.
    let p = paper();
    let tr = Trajectory::quadratic([1.0, 0.0, 0.5]);
    let t = 0.27;
    let st = RigidState::at(&p, &tr, t).unwrap();
    for i in 0..3 {
        for x in [0.0, 0.2, 0.5] {
            let ax = fd8(&|t| RigidState::at(&p, &tr, t).unwrap().point(i, x)[0], t, 1e-3).1;
            let ay = fd8(&|t| RigidState::at(&p, &tr, t).unwrap().point(i, x)[1], t, 1e-3).1;
            let (ex, ew) = (st.e_x(i), st.e_w(i));
            assert!((ax * ex[0] + ay * ex[1] - st.a_x(i, x)).abs() < 1e-6);
            assert!((ax * ew[0] + ay * ew[1] - st.a_w(i, x)).abs() < 1e-6);
        }
    }
}

#[test]
fn case2_leaves_the_feasible_range_when_sleeve_j_reaches_g() {
    // docs/paper-defects.md (the four cases): refused with a time between 0.40 and 0.44 s.
    let p = paper();
    let err = check_trajectory(&p, &Trajectory::quadratic([1.0, -0.5, -0.5]), 0.5, 1e-3).unwrap_err();
    assert!(err.t > 0.40 && err.t < 0.44, "t = {}", err.t);
    assert!(
        matches!(err.violation, Violation::SleeveAtJunction { beam: 2, .. }),
        "{err}"
    );
    // and the paper's span up to 0.4 s is fine
    check_trajectory(&p, &Trajectory::quadratic([1.0, -0.5, -0.5]), 0.4, 1e-3).unwrap();
}

#[test]
fn paper_cases_are_feasible_over_their_spans() {
    let p = paper();
    for (k, t_end) in [([1.0, 1.0, 1.0], 0.5), ([1.0, 0.0, 0.5], 0.5), ([1.0, -1.0, 0.0], 0.5)] {
        check_trajectory(&p, &Trajectory::quadratic(k), t_end, 1e-3).unwrap();
    }
}

#[test]
fn infeasible_from_the_start_is_reported_at_zero() {
    let p = paper();
    let tr = Trajectory::Polynomial {
        s1: vec![0.4],
        s2: vec![0.0],
        s3: vec![0.0],
    };
    let err = check_trajectory(&p, &tr, 0.1, 1e-3).unwrap_err();
    assert_eq!(err.t, 0.0);
    assert!(
        matches!(err.violation, Violation::SliderOffBase { slider: 1, .. }),
        "{err}"
    );
}

#[test]
fn rigid_inverse_dynamics_balances_power() {
    // Power of the drivers = d/dt of the kinetic energy of sliders, sleeves and rigid star:
    // T = 1/2 m_s |v_G|^2 + 1/2 (rho L^3 + 3 Jp) theta'^2 + 1/2 (mpp+mpa) sum s_i'^2.
    let p = paper();
    let trs = [Trajectory::quadratic([1.0, 0.0, 0.5]), general_quintic()];
    for tr in &trs {
        for t in [0.1, 0.25, 0.4] {
            let st = RigidState::at(&p, tr, t).unwrap();
            let f = rigid_inverse_dynamics(&p, &st);
            let power: f64 = (0..3).map(|i| f.fa[i] * st.s[i].d1).sum();
            let dtdt = p.star_mass() * (st.g[0].d1 * st.g[0].d2 + st.g[1].d1 * st.g[1].d2)
                + (p.star_inertia() + 3.0 * p.jp) * st.theta.d1 * st.theta.d2
                + p.mpp_mpa * (0..3).map(|i| st.s[i].d1 * st.s[i].d2).sum::<f64>();
            assert!(
                (power - dtdt).abs() < 1e-10 * (1.0 + dtdt.abs()),
                "{tr:?} t={t}: {power} vs {dtdt}"
            );
        }
    }
}

/// The task-space quintic from the origin to (0.03, -0.02, 0.3) in 0.5 s.
fn general_quintic() -> Trajectory {
    quintic([0.0; 3], [0.03, -0.02, 0.3], 0.5)
}

/// The rate of the kinetic energy of star, sleeves, sliders and a payload [W] (`1/2 m |v_c|^2 +
/// 1/2 J theta'^2` for the payload, `v_c` the velocity of its centre of mass, returned too).
fn kinetic_rate(p: &RobotParams, payload: &flexstar_model::Payload, st: &RigidState) -> (f64, [f64; 2]) {
    let (w, wd) = (st.theta.d1, st.theta.d2);
    let o = payload.offset;
    let (ex, ew) = (st.e_x(0), st.e_w(0));
    let r = [0, 1].map(|k| o[0] * ex[k] + o[1] * ew[k]);
    let kr = [-r[1], r[0]];
    let vc = [st.g[0].d1 + w * kr[0], st.g[1].d1 + w * kr[1]];
    let ac = [0, 1].map(|k| st.g[k].d2 + wd * kr[k] - w * w * r[k]);
    let rate = p.star_mass() * (st.g[0].d1 * st.g[0].d2 + st.g[1].d1 * st.g[1].d2)
        + (p.star_inertia() + 3.0 * p.jp) * w * wd
        + p.mpp_mpa * (0..3).map(|i| st.s[i].d1 * st.s[i].d2).sum::<f64>()
        + payload.mass * (vc[0] * ac[0] + vc[1] * ac[1])
        + payload.j * w * wd;
    (rate, vc)
}

/// Eqs. P7-P8 against the power balance of the loaded robot: the drivers' power plus the load's
/// (`F . v_G + Mz theta'`) is the rate of the kinetic energy of star, sleeves, sliders and the
/// payload (`1/2 m |v_G + theta' k x r|^2 + 1/2 J theta'^2`, r the offset turned with the star),
/// an identity Newton-Euler does not use.
#[test]
fn rigid_inverse_dynamics_with_payload_and_load_balances_power() {
    use flexstar_model::{Attachments, LoadSettings, Payload};
    let p = paper();
    let attached = Attachments {
        gravity: Default::default(),
        payload: Payload {
            mass: 0.7,
            j: 2e-3,
            offset: [0.03, -0.02],
        },
        load: LoadSettings::polynomials(Some(vec![1.5, -2.0]), Some(vec![-0.5, 0.0, 4.0]), Some(vec![0.2, 0.1])),
    };
    let tr = general_quintic();
    for t in [0.1, 0.25, 0.4] {
        let st = RigidState::at(&p, &tr, t).unwrap();
        let f = flexstar_kinematics::rigid_inverse_dynamics_with(&p, &attached, &st);
        let [fx, fy, mz] = attached.load.at(t);
        let w = st.theta.d1;
        let power: f64 = (0..3).map(|i| f.fa[i] * st.s[i].d1).sum::<f64>() + fx * st.g[0].d1 + fy * st.g[1].d1 + mz * w;
        let (dtdt, _) = kinetic_rate(&p, &attached.payload, &st);
        assert!(
            (power - dtdt).abs() < 1e-10 * (1.0 + dtdt.abs()),
            "t={t}: {power} vs {dtdt}"
        );
    }
    // no payload and no load: the bare star's forces, bit for bit
    let st = RigidState::at(&p, &tr, 0.25).unwrap();
    let bare = flexstar_kinematics::rigid_inverse_dynamics_with(&p, &Attachments::default(), &st);
    assert_eq!(bare, rigid_inverse_dynamics(&p, &st));
}

#[test]
fn slider_force_direction_is_cos_theta() {
    // Eq. 33 uses cos(theta + theta_p): e_wi . u_i = cos(theta) for every beam.
    let p = paper();
    let st = RigidState::at(&p, &Trajectory::quadratic([1.0, 0.0, 0.5]), 0.33).unwrap();
    for i in 0..3 {
        let (ew, u) = (st.e_w(i), slider_direction(i));
        assert!((ew[0] * u[0] + ew[1] * u[1] - st.theta.v.cos()).abs() < 1e-14);
        let q = revolute_point(i, p.d, st.s[i].v);
        assert!((q[0] - st.p[i][0]).abs() < 1e-15);
    }
}

/// The preflight's proof (`check_motion`) covers exactly what it checked: the same robot and
/// trajectory, a span and a scan step no finer; a faster version of a motion that leaves the
/// feasible range is not covered by the proof of the slow one, and the check itself refuses it
/// at the time `check_trajectory` names.
#[test]
fn a_checked_motion_covers_only_what_was_checked() {
    use flexstar_kinematics::{check_configuration, check_motion, preflight_step};
    use flexstar_model::Trajectory;
    let exp = flexstar_model::catalogue::paper_case(3);
    let (p, traj, t_end) = (exp.robot, exp.trajectory.clone(), exp.time.t_end);
    let step = preflight_step(exp.time.dt_out);
    let proof = check_motion(&p, &traj, t_end, step).expect("case 3 is feasible");
    assert!(proof.covers(&p, &traj, t_end, step));
    assert!(
        proof.covers(&p, &traj, 0.5 * t_end, 2.0 * step),
        "a shorter span, a coarser scan"
    );
    assert!(
        !proof.covers(&p, &traj, 2.0 * t_end, step),
        "a longer span is not covered"
    );
    assert!(
        !proof.covers(&p, &traj, t_end, 0.5 * step),
        "a finer scan is not covered"
    );
    let mut other = p;
    other.lp *= 1.5;
    assert!(!proof.covers(&other, &traj, t_end, step), "another robot");
    // the same polynomial ten times faster leaves the range: not covered, and refused
    let fast = match &traj {
        Trajectory::Polynomial { s1, s2, s3 } => {
            let scale = |c: &Vec<f64>| c.iter().enumerate().map(|(k, v)| v * 10f64.powi(k as i32)).collect();
            Trajectory::Polynomial {
                s1: scale(s1),
                s2: scale(s2),
                s3: scale(s3),
            }
        }
        other => panic!("case 3 is a polynomial motion, got {other:?}"),
    };
    assert!(!proof.covers(&p, &fast, t_end, step));
    let refused = check_motion(&p, &fast, t_end, step).expect_err("ten times faster leaves the range");
    assert!(refused.t > 0.0 && refused.t < t_end);
    // the time found is where the configuration itself leaves the range (checked pointwise,
    // not by the scan): feasible just before, infeasible just after
    let at = |t: f64| fast.s(&p, t).expect("a polynomial evaluates everywhere");
    assert!(check_configuration(&p, at(refused.t - 1e-6)).is_ok(), "{refused}");
    assert!(check_configuration(&p, at(refused.t + 1e-6)).is_err(), "{refused}");
}

/// `docs/as-built.md` 5 (Eqs. G1-G3) against two identities Newton-Euler does not use. At rest,
/// the drivers hold the weights: `Fa_i = dV/ds_i`, V the potential energy of the star (its mass
/// at G), the sleeves and sliders (on the pins) and the payload, differentiated by central
/// differences of the direct kinematics. Moving, the drivers' power is `dT/dt + dV/dt`.
#[test]
fn rigid_inverse_dynamics_under_gravity_holds_the_weights() {
    use flexstar_model::{Attachments, Gravity, Payload};
    let p = paper();
    let g = [2.5, -9.49];
    let attached = Attachments {
        gravity: Gravity::new(g),
        payload: Payload {
            mass: 0.7,
            j: 2e-3,
            offset: [0.03, -0.02],
        },
        load: Default::default(),
    };
    let m_p = attached.payload.mass;
    // the payload's centre of mass at the pose of s
    let centre = |gc: [f64; 2], theta: f64| {
        let o = attached.payload.offset;
        let (ex, ew) = ([theta.sin(), -theta.cos()], [theta.cos(), theta.sin()]);
        [0, 1].map(|k| gc[k] + o[0] * ex[k] + o[1] * ew[k])
    };
    let potential = |s: [f64; 3]| {
        let pose = flexstar_kinematics::direct_kinematics(p.d, s).unwrap();
        let c = centre(pose.g, pose.theta);
        let height = |x: [f64; 2]| -(g[0] * x[0] + g[1] * x[1]);
        p.star_mass() * height(pose.g)
            + p.mpp_mpa * (0..3).map(|i| height(revolute_point(i, p.d, s[i]))).sum::<f64>()
            + m_p * height(c)
    };
    let s0 = [0.02, -0.03, 0.01];
    let still = Trajectory::Polynomial {
        s1: vec![s0[0]],
        s2: vec![s0[1]],
        s3: vec![s0[2]],
    };
    let st = RigidState::at(&p, &still, 0.0).unwrap();
    let f = flexstar_kinematics::rigid_inverse_dynamics_with(&p, &attached, &st);
    let h = 1e-6;
    for i in 0..3 {
        let (mut up, mut down) = (s0, s0);
        up[i] += h;
        down[i] -= h;
        let grad = (potential(up) - potential(down)) / (2.0 * h);
        assert!(
            (f.fa[i] - grad).abs() < 1e-7 * (1.0 + grad.abs()),
            "slider {}: {} vs {grad}",
            i + 1,
            f.fa[i]
        );
    }
    // moving: power = dT/dt + dV/dt
    let tr = general_quintic();
    for t in [0.1, 0.25, 0.4] {
        let st = RigidState::at(&p, &tr, t).unwrap();
        let f = flexstar_kinematics::rigid_inverse_dynamics_with(&p, &attached, &st);
        let power: f64 = (0..3).map(|i| f.fa[i] * st.s[i].d1).sum();
        let (dtdt, vc) = kinetic_rate(&p, &attached.payload, &st);
        let dot_g = |v: [f64; 2]| g[0] * v[0] + g[1] * v[1];
        let dvdt = -(p.star_mass() * dot_g([st.g[0].d1, st.g[1].d1])
            + p.mpp_mpa * (0..3).map(|i| st.s[i].d1 * dot_g(slider_direction(i))).sum::<f64>()
            + m_p * dot_g(vc));
        assert!(
            (power - dtdt - dvdt).abs() < 1e-10 * (1.0 + power.abs()),
            "t={t}: {power} vs {dtdt} + {dvdt}"
        );
    }
}
