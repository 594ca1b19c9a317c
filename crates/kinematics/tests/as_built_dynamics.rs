//! The rigid inverse dynamics of a robot as built (`docs/as-built.md` 7, Eqs. N1-N6) against
//! identities Newton-Euler does not use, written here from the bodies themselves: the power
//! balance (Eq. N7) with the kinetic and potential energies summed over the beams' points (Simpson
//! quadrature), the sleeves, the sliders and the payload and differentiated in time by finite
//! differences; the principle of virtual power per slider, with the Jacobian of G and theta from
//! finite differences of the direct kinematics; and at rest the gradient of the potential energy.
//! The paper's robot through the general formulas agrees with the paper's own.

use flexstar_kinematics::as_built::rigid_pose;
use flexstar_kinematics::{rigid_inverse_dynamics_of, rigid_inverse_dynamics_with, RigidState, StarMasses};
use flexstar_model::{
    ActuatorAxis, Attachments, Gravity, LoadSettings, Payload, Robot, RobotGeometry, RobotParams, Trajectory,
};

use crate::quintic;
use quintic::quintic;

/// Every beam its own length, mass per length, sleeve inertia and slider mass; welds at 0, 117 and
/// 243.5 degrees; the base from uneven sides.
fn robot() -> Robot {
    let paper = Robot::from_params(&RobotParams::paper()).unwrap();
    let mut beams = *paper.beams();
    let welds = [0.0, 117.0, 243.5];
    for (i, b) in beams.iter_mut().enumerate() {
        b.length = [0.5, 0.46, 0.53][i];
        b.mass_per_length = [0.234, 0.27, 0.21][i];
        b.sleeve_inertia = [2e-4, 1.4e-4, 2.8e-4][i];
        b.sleeve_mass = [0.2, 0.26, 0.16][i];
        b.weld_angle = f64::to_radians(welds[i]);
    }
    Robot::new(beams, ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap()).unwrap()
}

/// Gravity in the plane, a payload off G and a load varying in time.
fn attached() -> Attachments {
    Attachments {
        gravity: Gravity::new([2.5, -9.49]),
        payload: Payload {
            mass: 0.7,
            j: 2e-3,
            offset: [0.03, -0.02],
        },
        load: LoadSettings::polynomials(Some(vec![1.5, -2.0]), Some(vec![-0.5, 0.0, 4.0]), Some(vec![0.2, 0.1])),
    }
}

fn motion() -> Trajectory {
    quintic([0.004, -0.003, 0.01], [0.03, -0.02, 0.2], 0.4)
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// `k x r`, the quarter turn.
fn turn(r: [f64; 2]) -> [f64; 2] {
    [-r[1], r[0]]
}

/// Beam i's axis at orientation theta (Eq. W1, written from the weld angle).
fn axis(robot: &Robot, i: usize, theta: f64) -> [f64; 2] {
    let a = theta + robot.beams()[i].weld_angle;
    [a.sin(), -a.cos()]
}

/// Simpson's rule on `[0, l]` with 8 intervals: nodes and weights (exact for the quadratic
/// integrands of a rigid beam's energies).
fn simpson(l: f64) -> Vec<(f64, f64)> {
    let n = 8;
    let h = l / n as f64;
    (0..=n)
        .map(|k| {
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            (k as f64 * h, w * h / 3.0)
        })
        .collect()
}

/// The payload's centre of mass from G at orientation theta (its offset in beam 1's frame).
fn payload_arm(p: &Payload, theta: f64) -> [f64; 2] {
    let (ex, ew) = ([theta.sin(), -theta.cos()], [theta.cos(), theta.sin()]);
    [0, 1].map(|c| p.offset[0] * ex[c] + p.offset[1] * ew[c])
}

/// Kinetic energy [J] of the beams (point by point), sleeves (turning with the star), sliders
/// with their sleeves (moving with the pins along the rails) and the payload, from the
/// velocities of the state.
fn kinetic(robot: &Robot, p: &Payload, st: &RigidState) -> f64 {
    let vg = [st.g[0].d1, st.g[1].d1];
    let w = st.theta.d1;
    let velocity = |r: [f64; 2]| [vg[0] + w * turn(r)[0], vg[1] + w * turn(r)[1]];
    let mut t = 0.0;
    for (i, b) in robot.beams().iter().enumerate() {
        let e = axis(robot, i, st.theta.v);
        for (x, wt) in simpson(b.length) {
            let v = velocity([x * e[0], x * e[1]]);
            t += 0.5 * wt * b.mass_per_length * dot(v, v);
        }
        t += 0.5 * b.sleeve_inertia * w * w + 0.5 * b.sleeve_mass * st.s[i].d1 * st.s[i].d1;
    }
    let vc = velocity(payload_arm(p, st.theta.v));
    t + 0.5 * p.mass * dot(vc, vc) + 0.5 * p.j * w * w
}

/// Potential energy of the weights [J], `-g . sum m x`, at the pose (G, theta) with the
/// revolute points `pins`.
fn potential(robot: &Robot, a: &Attachments, gc: [f64; 2], theta: f64, pins: [[f64; 2]; 3]) -> f64 {
    let g = a.gravity.g;
    let height = |x: [f64; 2]| -dot(g, x);
    let mut v = 0.0;
    for (i, b) in robot.beams().iter().enumerate() {
        let e = axis(robot, i, theta);
        for (x, wt) in simpson(b.length) {
            v += wt * b.mass_per_length * height([gc[0] + x * e[0], gc[1] + x * e[1]]);
        }
        v += b.sleeve_mass * height(pins[i]);
    }
    let r = payload_arm(&a.payload, theta);
    v + a.payload.mass * height([gc[0] + r[0], gc[1] + r[1]])
}

/// The five-point central difference of `f` at `t` with step `h`.
fn rate(f: impl Fn(f64) -> f64, t: f64, h: f64) -> f64 {
    (-f(t + 2.0 * h) + 8.0 * f(t + h) - 8.0 * f(t - h) + f(t - 2.0 * h)) / (12.0 * h)
}

/// `sum Fa_i s_i' + F . v_G + Mz theta'` against `d/dt (T + V)` (Eq. N7): the defect and the
/// scale of the terms, at time t of `traj`, for the forces `fa`.
fn power_defect(robot: &Robot, a: &Attachments, traj: &Trajectory, t: f64, fa: [f64; 3]) -> (f64, f64) {
    let st = RigidState::at(robot, traj, t).unwrap();
    let [fx, fy, mz] = a.load.at(t);
    let drives: f64 = (0..3).map(|i| fa[i] * st.s[i].d1).sum();
    let load = fx * st.g[0].d1 + fy * st.g[1].d1 + mz * st.theta.d1;
    let energy = |tau: f64| {
        let s = RigidState::at(robot, traj, tau).unwrap();
        kinetic(robot, &a.payload, &s) + potential(robot, a, [s.g[0].v, s.g[1].v], s.theta.v, s.p)
    };
    let de = rate(energy, t, 2.5e-4);
    (drives + load - de, drives.abs() + load.abs() + de.abs())
}

#[test]
fn the_forces_as_built_balance_power() {
    let (robot, a, traj) = (robot(), attached(), motion());
    assert!(robot.paper_form().is_none());
    for t in [0.07, 0.15, 0.2, 0.28, 0.35] {
        let st = RigidState::at(&robot, &traj, t).unwrap();
        let fa = rigid_inverse_dynamics_of(&robot, &a, &st).fa;
        let (defect, scale) = power_defect(&robot, &a, &traj, t, fa);
        eprintln!("t = {t}: power defect {defect:.3e} W of {scale:.3e}");
        assert!(defect.abs() < 1e-10 * scale, "t = {t}: {defect} of {scale}");
    }
}

/// The balance is sharp: the same formulas with the star's first moment left out (its centre of
/// mass put at G, as on the paper's robot) miss it by far.
#[test]
fn the_power_balance_sees_the_centre_of_mass_off_g() {
    let (robot, a, traj) = (robot(), attached(), motion());
    let centred = StarMasses {
        beam_moment: [0.0; 3],
        ..StarMasses::of(&robot)
    };
    let t = 0.2;
    let st = RigidState::at(&robot, &traj, t).unwrap();
    let (defect, scale) = power_defect(&robot, &a, &traj, t, centred.inverse_dynamics(&a, &st).fa);
    eprintln!("centre of mass at G: power defect {defect:.3e} W of {scale:.3e}");
    assert!(defect.abs() > 1e-3 * scale, "{defect} of {scale}");
}

/// Virtual power per slider: for `ds = e_k` with `(dG, dtheta)` the Jacobian's column (central
/// differences of the direct kinematics), `Fa_k + F . dG + Mz dtheta` is the virtual power of
/// every body's inertia and weight, `int (a - g) . dv dm` plus the rotations' `J theta'' dtheta`.
/// Each component of Fa is checked, not only their power.
#[test]
fn each_force_as_built_is_the_virtual_power_of_its_slider() {
    let (robot, a, traj) = (robot(), attached(), motion());
    let g = a.gravity.g;
    for t in [0.1, 0.23, 0.31] {
        let st = RigidState::at(&robot, &traj, t).unwrap();
        let fa = rigid_inverse_dynamics_of(&robot, &a, &st).fa;
        let (w, wd) = (st.theta.d1, st.theta.d2);
        let accel = |r: [f64; 2]| [0, 1].map(|c| st.g[c].d2 + wd * turn(r)[c] - w * w * r[c] - g[c]);
        let s = st.s.map(|j| j.v);
        for k in 0..3 {
            let h = 1e-6;
            let pose = |sign: f64| {
                let mut q = s;
                q[k] += sign * h;
                rigid_pose(&robot, q).unwrap()
            };
            let (up, down) = (pose(1.0), pose(-1.0));
            let dg = [0, 1].map(|c| (up.g[c] - down.g[c]) / (2.0 * h));
            let dth = (up.theta - down.theta) / (2.0 * h);
            let dv = |r: [f64; 2]| [dg[0] + dth * turn(r)[0], dg[1] + dth * turn(r)[1]];
            let mut inertia = 0.0;
            for (i, b) in robot.beams().iter().enumerate() {
                let e = axis(&robot, i, st.theta.v);
                for (x, wt) in simpson(b.length) {
                    let r = [x * e[0], x * e[1]];
                    inertia += wt * b.mass_per_length * dot(accel(r), dv(r));
                }
                inertia += b.sleeve_inertia * wd * dth;
            }
            let u = robot.axis(k).direction;
            inertia += robot.beams()[k].sleeve_mass * (st.s[k].d2 - dot(g, u));
            let r = payload_arm(&a.payload, st.theta.v);
            inertia += a.payload.mass * dot(accel(r), dv(r)) + a.payload.j * wd * dth;
            let [fx, fy, mz] = a.load.at(t);
            let work = fa[k] + fx * dg[0] + fy * dg[1] + mz * dth;
            eprintln!("t = {t}, slider {}: virtual power {work:.9e} vs {inertia:.9e} W", k + 1);
            assert!(
                (work - inertia).abs() < 1e-7 * (1.0 + inertia.abs()),
                "t = {t}, slider {}: {work} vs {inertia}",
                k + 1
            );
        }
    }
}

/// At rest the drivers hold the weights: `Fa_i = dV/ds_i` (central differences of the direct
/// kinematics); the star's centre of mass off G puts a moment on it that the sleeves carry.
#[test]
fn at_rest_the_forces_as_built_hold_the_weights() {
    let (robot, mut a) = (robot(), attached());
    a.load = LoadSettings::default();
    let s0 = [0.02, -0.03, 0.01];
    let v = |s: [f64; 3]| {
        let pose = rigid_pose(&robot, s).unwrap();
        potential(&robot, &a, pose.g, pose.theta, pose.p)
    };
    let still = Trajectory::Polynomial {
        s1: vec![s0[0]],
        s2: vec![s0[1]],
        s3: vec![s0[2]],
    };
    let st = RigidState::at(&robot, &still, 0.0).unwrap();
    let fa = rigid_inverse_dynamics_of(&robot, &a, &st).fa;
    let h = 1e-6;
    for i in 0..3 {
        let (mut up, mut down) = (s0, s0);
        up[i] += h;
        down[i] -= h;
        let grad = (v(up) - v(down)) / (2.0 * h);
        eprintln!("slider {}: Fa {:.9e} vs dV/ds {grad:.9e} N", i + 1, fa[i]);
        assert!(
            (fa[i] - grad).abs() < 1e-7 * (1.0 + grad.abs()),
            "slider {}: {} vs {grad}",
            i + 1,
            fa[i]
        );
    }
}

/// The paper's robot: through `rigid_inverse_dynamics_of` its own formulas bit for bit; through
/// the general ones (Eqs. N1-N6), directly or because one beam differs by 1e-12 of its length,
/// the same forces to round-off.
#[test]
fn the_paper_robot_through_the_general_formulas_is_the_paper_form() {
    let p = RobotParams::paper();
    let paper = Robot::from_params(&p).unwrap();
    let mut beams = *paper.beams();
    beams[1].length *= 1.0 + 1e-12;
    let nudged = Robot::new(beams, *paper.axes()).unwrap();
    assert!(
        nudged.paper_form().is_none(),
        "the nudged robot takes the general formulas"
    );
    let traj = quintic([0.0; 3], [0.03, -0.02, 0.3], 0.5);
    for a in [Attachments::default(), attached()] {
        for t in [0.1, 0.25, 0.4] {
            let st = RigidState::at(&p, &traj, t).unwrap();
            let today = rigid_inverse_dynamics_with(&p, &a, &st);
            assert_eq!(rigid_inverse_dynamics_of(&paper, &a, &st), today);
            let scale = today.fa.iter().chain(&today.normal).fold(0.0f64, |m, v| m.max(v.abs()));
            let general = StarMasses::of(&paper).inverse_dynamics(&a, &st);
            let near = RigidState::at(&nudged, &traj, t).unwrap();
            let nudged = rigid_inverse_dynamics_of(&nudged, &a, &near);
            for f in [general, nudged] {
                let off = f.fa.iter().chain(&f.normal).zip(today.fa.iter().chain(&today.normal));
                eprintln!(
                    "t = {t}: general formulas off by {:.2e} of {scale:.3e} N",
                    off.clone().fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
                );
                for (x, y) in off {
                    assert!((x - y).abs() < 1e-9 * scale, "t = {t}: {x} vs {y}");
                }
            }
        }
    }
}
