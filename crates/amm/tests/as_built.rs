//! The AMM on a robot as built (`docs/amm.md` 13, Eqs. J1-J8): unequal beams, welds at 0, 117
//! and 243.5 degrees, an uneven base. References independent of the solver: a Newton-Euler
//! computation of the rigid robot written here (the stiff limit), the inverse run the direct
//! run must invert, the paper-form run a robot built through the general constructor with
//! three equal beams must reproduce, and a servo's reference (its tracking) and the rigid
//! robot's forces (very stiff gains without feed-forward on a stiff robot).

use crate::common;

use flexstar_drive::{ForceTable, SolveRequest};
use flexstar_kinematics::RigidState;
use flexstar_model::catalogue::{quintic_from_origin, GENERAL_TARGET};
use flexstar_model::{
    ActuatorAxis, AmmSettings, Beam, Experiment, Gravity, ModeFamily, Problem, Response, Robot, RobotParams,
};
use flexstar_model::{DriveKind, Feedforward, Pose, Trajectory};

/// Three different beams (every datum differs), welds 0, 117, 243.5 degrees, the base from the
/// sides 0.626, 0.618, 0.631 m; each beam's E times `stiff`.
fn as_built(stiff: f64) -> Robot {
    let p = RobotParams::paper();
    let welds = [0.0, 117f64.to_radians(), 243.5f64.to_radians()];
    let beams = std::array::from_fn(|i| Beam {
        youngs_modulus: p.e * stiff * [1.0, 1.2, 0.85][i],
        second_moment: p.i * [1.0, 0.9, 1.1][i],
        axial_stiffness: p.ea() * [1.0, 1.1, 0.95][i],
        mass_per_length: p.rho * [1.0, 1.15, 0.9][i],
        length: p.l * [1.0, 0.92, 1.06][i],
        sleeve_length: p.lp * [1.0, 1.2, 0.9][i],
        sleeve_mass: p.mpp_mpa * [1.0, 1.3, 0.8][i],
        sleeve_inertia: p.jp * [1.0, 0.7, 1.4][i],
        weld_angle: welds[i],
    });
    Robot::new(beams, ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap()).unwrap()
}

/// A rest-to-rest quintic of G and theta to the general target in `t_end` [s] on `robot`.
fn quintic_on(robot: Robot, t_end: f64, g: [f64; 2]) -> Problem {
    let mut exp = common::quintic(RobotParams::paper(), t_end);
    exp.trajectory = quintic_from_origin(GENERAL_TARGET, t_end);
    exp.gravity = Gravity::new(g);
    exp.problem().unwrap().with_robot(robot).unwrap()
}

fn solve(problem: &Problem, settings: &AmmSettings) -> Response {
    flexstar_amm::solve(problem, settings, SolveRequest::motion())
        .unwrap()
        .response
}

/// The rigid robot's actuator forces by Newton-Euler, written here from scratch for a star of
/// unequal beams (its centre of mass is not at G): with `M = sum rho_i L_i`, the first moment
/// `S = sum rho_i L_i^2 / 2 e_xi` and `I_G = sum rho_i L_i^3 / 3 + sum Jp_i`, the sleeves' normal
/// forces `f_i e_wi` at `xp_i e_xi` give the star
///
/// ```text
/// sum f_i e_wi  = M a + theta'' k x S - theta'^2 S,     sum xp_i f_i = S x a + I_G theta''
/// ```
/// (`a = a_G - g`, every weight a uniform acceleration of the base), and each slider
/// `Fa_i = m_i (s_i'' - g . u_i) + f_i e_wi . u_i`.
fn newton_euler(robot: &Robot, st: &RigidState, g: [f64; 2]) -> [f64; 3] {
    let b = robot.beams();
    let a = [st.g[0].d2 - g[0], st.g[1].d2 - g[1]];
    let (th1, th2) = (st.theta.d1, st.theta.d2);
    let ex = [0, 1, 2].map(|i| st.e_x(i));
    let ew = [0, 1, 2].map(|i| st.e_w(i));
    let m: f64 = b.iter().map(|b| b.mass_per_length * b.length).sum();
    let mut s = [0.0; 2];
    for i in 0..3 {
        let f = b[i].mass_per_length * b[i].length * b[i].length / 2.0;
        s[0] += f * ex[i][0];
        s[1] += f * ex[i][1];
    }
    let ig: f64 = b
        .iter()
        .map(|b| b.mass_per_length * b.length.powi(3) / 3.0 + b.sleeve_inertia)
        .sum();
    let rhs = [
        m * a[0] - th2 * s[1] - th1 * th1 * s[0],
        m * a[1] + th2 * s[0] - th1 * th1 * s[1],
        s[0] * a[1] - s[1] * a[0] + ig * th2,
    ];
    let mat = nalgebra::Matrix3::new(
        ew[0][0], ew[1][0], ew[2][0], ew[0][1], ew[1][1], ew[2][1], st.xp[0].v, st.xp[1].v, st.xp[2].v,
    );
    let f = mat.lu().solve(&nalgebra::Vector3::from(rhs)).unwrap();
    std::array::from_fn(|i| {
        let u = robot.axes()[i].direction;
        let gu = g[0] * u[0] + g[1] * u[1];
        b[i].sleeve_mass * (st.s[i].d2 - gu) + f[i] * (ew[i][0] * u[0] + ew[i][1] * u[1])
    })
}

/// Largest |Fa_amm - Fa_rigid| over time and actuators relative to the largest |Fa_rigid|.
fn stiff_limit_error(settings: &AmmSettings, g: [f64; 2]) -> f64 {
    let robot = as_built(1e4);
    let problem = quintic_on(robot.clone(), 0.5, g);
    let r = solve(&problem, settings);
    let (mut err, mut scale) = (0.0f64, 0.0f64);
    for k in 0..r.len() {
        let st = RigidState::at(&robot, problem.trajectory(), r.t[k]).unwrap();
        let rigid = newton_euler(&robot, &st, g);
        for (fa, rigid) in r.fa.iter().zip(rigid) {
            err = err.max((fa[k] - rigid).abs());
            scale = scale.max(rigid.abs());
        }
    }
    err / scale
}

#[test]
fn a_stiff_star_as_built_reproduces_its_rigid_newton_euler_forces() {
    // EI x 1e4: the AMM's Fa (Eq. 33 / J7) of the paper's model (free-free) and of the accurate
    // model (enriched, full; under gravity too) within 0.5 % of the rigid robot's
    let paper = AmmSettings {
        dt: Some(1e-4),
        ..AmmSettings::paper(ModeFamily::FreeFree, 10)
    };
    let accurate = AmmSettings {
        modes: Some(12),
        dt: Some(1e-4),
        ..AmmSettings::accurate()
    };
    for (name, settings, g) in [
        ("free-free, paper", &paper, [0.0, 0.0]),
        ("enriched, full", &accurate, [0.0, 0.0]),
        ("enriched, full, gravity", &accurate, [3.0, -9.81]),
    ] {
        let e = stiff_limit_error(settings, g);
        eprintln!("{name}: Fa off the rigid Newton-Euler forces by {:.4} %", e * 100.0);
        assert!(e < 5e-3, "{name}: {:.3} %", e * 100.0);
    }
}

#[test]
fn the_stiff_limit_sees_the_robot_as_built() {
    // the reference is sharp: the paper's robot's Newton-Euler forces (equal beams, 120-degree
    // welds) are far from the stiff robot as built's AMM forces
    let robot = as_built(1e4);
    let problem = quintic_on(robot.clone(), 0.5, [0.0; 2]);
    let settings = AmmSettings {
        dt: Some(1e-4),
        ..AmmSettings::paper(ModeFamily::FreeFree, 10)
    };
    let r = solve(&problem, &settings);
    let paper = Robot::from_params(&RobotParams::paper()).unwrap();
    let (mut err, mut scale) = (0.0f64, 0.0f64);
    for k in 0..r.len() {
        let st = RigidState::at(&paper, problem.trajectory(), r.t[k]).unwrap();
        let rigid = newton_euler(&paper, &st, [0.0; 2]);
        for (fa, rigid) in r.fa.iter().zip(rigid) {
            err = err.max((fa[k] - rigid).abs());
            scale = scale.max(rigid.abs());
        }
    }
    assert!(err > 0.05 * scale, "{err} of {scale}");
}

#[test]
fn the_direct_run_of_a_robot_as_built_inverts_its_inverse_run() {
    // the inverse run's Fa (output at every solver step) fed back as a force table give the
    // sliders' motion back (docs/amm.md section 10 with J7's projections and per-beam masses)
    let problem = quintic_on(as_built(1.0), 0.15, [0.0, -9.81]);
    let settings = AmmSettings {
        modes: Some(30),
        ..AmmSettings::accurate()
    };
    let dt = 5e-4 / 4.0;
    let fine_exp = {
        let mut e: Experiment = common::quintic(RobotParams::paper(), 0.15);
        e.trajectory = problem.trajectory().clone();
        e.time.dt_out = dt;
        e.gravity = Gravity::new(problem.gravity());
        e
    };
    let fine = fine_exp.problem().unwrap().with_robot(problem.robot().clone()).unwrap();
    let settings = AmmSettings {
        dt: Some(dt),
        ..settings
    };
    let inverse_fine = solve(&fine, &settings);
    let inverse = solve(&problem, &settings);
    let fa = (0..inverse_fine.len())
        .map(|k| [0, 1, 2].map(|i| inverse_fine.fa[i][k]))
        .collect();
    let table = ForceTable::new(inverse_fine.t.clone(), fa).unwrap();
    let direct = flexstar_amm::solve(&problem, &settings, SolveRequest::law(&table))
        .unwrap()
        .response;
    let mut ds = 0.0f64;
    for (k, &t) in direct.t.iter().enumerate() {
        let s = problem.trajectory().s(problem.robot(), t).unwrap();
        for (i, name) in ["s1", "s2", "s3"].into_iter().enumerate() {
            ds = ds.max((direct.column(name).unwrap()[k] - s[i]).abs());
        }
    }
    let evp = flexstar_metrics::evp::point_evps(&direct, &inverse).unwrap();
    let worst = evp.points.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
    eprintln!("as built: |s - s_ref| <= {ds:.3e} m, worst point EVP {worst:.2e} %");
    assert!(ds < 1e-6, "{ds:e} m");
    assert!(worst < 0.2, "{worst} %");
}

#[test]
fn equal_beams_built_through_the_general_constructor_give_the_paper_run_exactly() {
    // three equal beams from Robot::new with the weld angles and axes as data: bit for bit the
    // paper-form run (payload, gravity; the paper's and the accurate model); on the base built
    // from three equal sides (the paper's to rounding) the same to 1e-9
    let p = RobotParams::paper();
    let beam = |i: usize| Beam {
        youngs_modulus: p.e,
        second_moment: p.i,
        axial_stiffness: p.ea(),
        mass_per_length: p.rho,
        length: p.l,
        sleeve_length: p.lp,
        sleeve_mass: p.mpp_mpa,
        sleeve_inertia: p.jp,
        weld_angle: flexstar_model::geometry::beam_offset(i),
    };
    let robot = Robot::new(
        std::array::from_fn(beam),
        std::array::from_fn(|i| ActuatorAxis::paper(i, p.d)),
    )
    .unwrap();
    let side = 2.0 * 3f64.sqrt() * p.d;
    let from_sides = Robot::new(std::array::from_fn(beam), ActuatorAxis::from_sides([side; 3]).unwrap()).unwrap();
    let mut exp = common::paper_case(3);
    exp.time.t_end = 0.1;
    exp.payload.mass = 0.2;
    exp.payload.j = 1e-3;
    exp.gravity = Gravity::new([0.0, -9.81]);
    let paper = exp.problem().unwrap();
    let general = paper.with_robot(robot).unwrap();
    exp.gravity = Gravity::new([0.0, 0.0]);
    let paper_0g = exp.problem().unwrap();
    let sides = paper_0g.with_robot(from_sides).unwrap();
    for settings in [exp.amm.clone(), AmmSettings::accurate()] {
        let (a, b) = (solve(&paper, &settings), solve(&general, &settings));
        assert_eq!(a.t, b.t);
        assert_eq!(a.w_g, b.w_g);
        assert_eq!(a.w_tip, b.w_tip);
        assert_eq!(a.fa, b.fa);
        for (x, y) in a.extra.iter().zip(&b.extra) {
            assert_eq!(x.values, y.values, "{}", x.name);
        }
        // without gravity: the static start's passes stop at a relative change of 1e-6, where a
        // change of the data in the last bits may take one pass more or less
        let (a, c) = (solve(&paper_0g, &settings), solve(&sides, &settings));
        let mut worst = 0.0f64;
        for i in 0..3 {
            for (x, y) in [(&a.w_tip[i], &c.w_tip[i]), (&a.w_g[i], &c.w_g[i]), (&a.fa[i], &c.fa[i])] {
                let scale = common::max_abs(x);
                worst = x.iter().zip(y).fold(worst, |m, (u, v)| m.max((u - v).abs() / scale));
            }
        }
        eprintln!("base from equal sides: largest relative difference {worst:e}");
        assert!(worst < 1e-9, "{worst:e}");
    }
}

/// A servo drive (`bandwidth_hz` = `f_hz` on each slider's own mass, damping ratio 0.7, the
/// feed-forward `ff`) tracking a quintic to the general target in 0.3 s, at rest until 0.5 s, on
/// `robot` under gravity `g`; the AMM's direct run of it (through `flexstar_drive::law_for`).
fn servo_run(robot: Robot, f_hz: f64, ff: Feedforward, g: [f64; 2], settings: &AmmSettings) -> (Problem, Response) {
    let mut exp = common::quintic(RobotParams::paper(), 0.5);
    let origin = Pose {
        gx: 0.0,
        gy: 0.0,
        theta: 0.0,
    };
    exp.trajectory = Trajectory::Quintic {
        from: origin,
        to: GENERAL_TARGET,
        t0: 0.0,
        t1: 0.3,
    };
    exp.gravity = Gravity::new(g);
    exp.drive.kind = DriveKind::Servo;
    exp.drive.bandwidth_hz = Some(f_hz);
    exp.drive.damping_ratio = Some(0.7);
    exp.drive.feedforward = Some(ff);
    let problem = exp.problem().unwrap().with_robot(robot).unwrap();
    let law = flexstar_drive::law_for(&problem).unwrap().unwrap();
    let r = flexstar_amm::solve(&problem, settings, SolveRequest::law(law.as_ref()))
        .unwrap()
        .response;
    (problem, r)
}

/// `|s - s_ref|` [m] at each output time, largest over the sliders.
fn tracking(problem: &Problem, r: &Response) -> Vec<f64> {
    r.t.iter()
        .enumerate()
        .map(|(k, &t)| {
            let s_ref = problem.trajectory().s(problem.robot(), t).unwrap();
            (0..3).fold(0.0f64, |m, i| {
                m.max((r.column(["s1", "s2", "s3"][i]).unwrap()[k] - s_ref[i]).abs())
            })
        })
        .collect()
}

#[test]
fn a_servo_tracks_its_reference_on_a_robot_as_built() {
    // 20 Hz on each slider's own mass with the robot as built's rigid feed-forward, under
    // gravity, on a brisk move (G 36 mm, theta 0.3 rad in 0.3 s): what is left to track is the
    // flexible star's vibration, which the feed-forward cannot know. The sliders lag far less than
    // without the feed-forward, as little as on the paper's robot under the same servo, and
    // settle on the reference at rest.
    let settings = AmmSettings {
        modes: Some(20),
        ..AmmSettings::accurate()
    };
    let g = [0.0, -9.81];
    let peak_and_end = |robot: Robot, ff: Feedforward| {
        let (problem, r) = servo_run(robot, 20.0, ff, g, &settings);
        let e = tracking(&problem, &r);
        (e.iter().fold(0.0f64, |m, v| m.max(*v)), *e.last().unwrap())
    };
    let (peak, end) = peak_and_end(as_built(1.0), Feedforward::Rigid);
    let (lag, _) = peak_and_end(as_built(1.0), Feedforward::None);
    let paper = Robot::from_params(&RobotParams::paper()).unwrap();
    let (paper_peak, paper_end) = peak_and_end(paper, Feedforward::Rigid);
    eprintln!(
        "20 Hz servo as built: peak tracking error {peak:.3e} m, at the end {end:.3e} m; without feed-forward \
         {lag:.3e} m; the paper's robot {paper_peak:.3e} m, at the end {paper_end:.3e} m"
    );
    assert!(peak < 0.25 * lag, "{peak} m against {lag} m");
    assert!(
        peak < 2.0 * paper_peak && end < 2.0 * paper_end.max(1e-6),
        "{peak}, {end} m"
    );
    assert!(end < 0.1 * peak, "settles: {end} of {peak} m");
}

#[test]
fn very_stiff_servo_gains_drive_a_stiff_robot_as_built_with_its_rigid_forces() {
    // no feed-forward: the forces are the PD terms alone; as the gains stiffen (bandwidth 100,
    // 300, 1000 Hz) the sliders follow the reference ever closer and the forces of the stiff
    // robot as built (EI x 1e4) tend to its rigid inverse dynamics (the Newton-Euler of this file)
    let settings = AmmSettings {
        modes: Some(12),
        dt: Some(2e-5),
        ..AmmSettings::accurate()
    };
    let robot = as_built(1e4);
    let gaps = [100.0, 300.0, 1000.0].map(|f_hz| {
        let (problem, r) = servo_run(robot.clone(), f_hz, Feedforward::None, [0.0; 2], &settings);
        let (mut err, mut scale) = (0.0f64, 0.0f64);
        for k in 0..r.len() {
            let st = RigidState::at(&robot, problem.trajectory(), r.t[k]).unwrap();
            let rigid = newton_euler(&robot, &st, [0.0; 2]);
            for (fa, rigid) in r.fa.iter().zip(rigid) {
                err = err.max((fa[k] - rigid).abs());
                scale = scale.max(rigid.abs());
            }
        }
        err / scale
    });
    eprintln!("servo 100, 300, 1000 Hz without feed-forward: Fa off the rigid forces by {gaps:?}");
    assert!(gaps[1] < 0.5 * gaps[0] && gaps[2] < 0.5 * gaps[1], "{gaps:?}");
    assert!(gaps[2] < 0.02, "{gaps:?}");
}
