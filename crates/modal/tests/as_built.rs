//! The modal analyses and the linear model of a robot as built (`docs/modes.md`, a robot as
//! built), each against a reference independent of the code under test: the other solver (AMM
//! against FEM), the rails' part in the modes (Eq. M2: the paper robot's own modes), the robot's
//! rigid mass matrix written here from its kinetic energy, and the FEM's static deflection.

use crate::inertia_relief;

use flexstar_modal::analysis::modal;
use flexstar_modal::freqmap::{freqmap, Axis, Grid, Solver};
use flexstar_modal::linear::{linearize_with, Holding, LinearSettings, StateSpace};
use flexstar_modal::pose::{pose_at_time, pose_from_task};
use flexstar_model::robot::AsBuilt;
use flexstar_model::{ActuatorAxis, Experiment, RestPose, Robot, RobotGeometry, Sliders};
use nalgebra::Matrix3;

const MOTION: &str = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
                      s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";

/// Every datum its own: beams (length, section, mass, sleeve, slider) within +-10 % of the
/// paper's, welds off by up to 1.5 degrees, an uneven base.
const AS_BUILT: &str = "[robot]\nL = [0.52, 0.48, 0.5]\nI = [2.5e-12, 2.8e-12, 2.2e-12]\nrho = [0.25, 0.22, 0.234]\n\
                        Lp = [0.03, 0.033, 0.028]\nJp = [2e-4, 2.2e-4, 1.8e-4]\nmpp_mpa = [0.2, 0.18, 0.22]\n\
                        weld_deg = [0, 121.5, 238.5]\n[base]\nsides = [0.63, 0.6, 0.64]\n";

fn experiment(extra: &str) -> Experiment {
    Experiment::from_toml_str(&format!("{MOTION}{extra}"), std::path::Path::new("t.toml")).unwrap()
}

fn as_built() -> Experiment {
    let exp = experiment(AS_BUILT);
    assert!(exp.robot.as_built.is_some(), "a robot as built");
    exp
}

fn robot(exp: &Experiment) -> Robot {
    flexstar_modal::robot(exp).unwrap()
}

/// Two off-centre turned poses of the robot as built (no symmetry to hide an error).
const POSES: [[f64; 3]; 2] = [[0.03, -0.02, 0.1], [-0.06, 0.04, -0.12]];

/// AMM (enriched, N = 60) against the FEM (300 elements), both on the robot as built, sliders
/// locked and free: the first six elastic frequencies within 1 % (the tolerance of the paper
/// robot's `modal_checks.rs`). Measured: AMM above FEM by 0.003-0.06 % (locked), 0.004-0.08 %
/// (free).
#[test]
fn amm_and_fem_agree_on_a_robot_as_built() {
    let exp = as_built();
    let r = robot(&exp);
    for [gx, gy, th] in POSES {
        let pose = pose_from_task(&r, gx, gy, th).unwrap();
        for sliders in [Sliders::Locked, Sliders::Free] {
            let m = modal(&exp, &pose, sliders, 6).unwrap();
            let rigid = m.amm.rigid;
            assert_eq!(rigid, if sliders == Sliders::Free { 3 } else { 0 });
            for (mode, a, f, rel) in m.rows().into_iter().skip(rigid) {
                eprintln!(
                    "{gx},{gy},{th} {sliders:?} mode {mode}: AMM {a:.5} Hz, FEM {f:.5} Hz, {:+.4} %",
                    100.0 * rel
                );
                assert!(f > 0.5 && rel.abs() < 0.01, "mode {mode}: AMM {a} Hz, FEM {f} Hz");
            }
        }
    }
}

/// The paper's robot with each rail turned about the pin it holds at `pose` by `turn_deg`
/// (`docs/modes.md`, Eq. M2): the same star at the same `xp_i`, its sliders at s = 0. With
/// `effective_mass`, slider i's mass is scaled by `c_i'^2 / c_i^2`, `c = u_i . e_wi` at the pose
/// before and after the turn.
fn turned_rails(paper: &Experiment, pose: &RestPose, turn_deg: [f64; 3], effective_mass: bool) -> Experiment {
    let mut built = AsBuilt::of_paper(&paper.robot);
    for (i, turn) in turn_deg.iter().enumerate() {
        let (axis, delta) = (built.axes[i], turn.to_radians());
        let u = axis.direction;
        let turned = [
            u[0] * delta.cos() - u[1] * delta.sin(),
            u[0] * delta.sin() + u[1] * delta.cos(),
        ];
        let phi = built.beams[i].weld_angle;
        let ew = [(pose.theta + phi).cos(), (pose.theta + phi).sin()];
        let (c, c_turned) = (u[0] * ew[0] + u[1] * ew[1], turned[0] * ew[0] + turned[1] * ew[1]);
        if effective_mass {
            built.beams[i].sleeve_mass *= (c_turned / c).powi(2);
        }
        built.axes[i] = ActuatorAxis {
            origin: [axis.origin[0] + pose.s[i] * u[0], axis.origin[1] + pose.s[i] * u[1]],
            direction: turned,
        };
    }
    let mut exp = paper.clone();
    exp.robot.as_built = Some(built);
    exp
}

/// Largest relative difference of the elastic frequencies of two analyses, AMM and FEM apart.
fn largest_differences(a: &flexstar_modal::analysis::Modal, b: &flexstar_modal::analysis::Modal) -> (f64, f64) {
    let rel = |x: &[f64], y: &[f64]| {
        x.iter()
            .zip(y)
            .skip(a.amm.rigid)
            .map(|(p, q)| (p / q - 1.0).abs())
            .fold(0.0, f64::max)
    };
    (rel(&a.amm.freq_hz, &b.amm.freq_hz), rel(&a.fem.freq_hz, &b.fem.freq_hz))
}

/// Eq. M2 and the locked statement of `docs/modes.md`: a base whose rails pass through the paper
/// robot's revolute points at a pose, each turned about its pin, holds the paper's star at the
/// same `xp_i`. Sliders locked, its modes are the paper robot's at that pose; sliders free, they
/// are once each slider's mass is scaled to keep `m_i / c_i^2`, and they are not without that
/// scaling (the rails matter there). The reference is the paper robot's compact form, the robot
/// as built runs the general path of both solvers (its base is not the paper's).
/// Measured (rails turned by 25, -20, 15 degrees): locked AMM 2.0e-8, FEM 5.6e-10; free
/// (scaled) AMM 1.6e-8, FEM 3.1e-9; unscaled, the free modes move by up to 2.2 %.
#[test]
fn the_rails_enter_the_modes_only_through_the_sliders() {
    let paper = experiment("");
    let pose = pose_from_task(&robot(&paper), 0.03, -0.02, 0.1).unwrap();
    let turn = [25.0, -20.0, 15.0];
    for effective_mass in [true, false] {
        let exp = turned_rails(&paper, &pose, turn, effective_mass);
        let turned = pose_from_task(&robot(&exp), pose.g[0], pose.g[1], pose.theta).unwrap();
        assert!(robot(&exp).equal_beams().is_err(), "the general path");
        for i in 0..3 {
            assert!(
                turned.s[i].abs() < 1e-12 && (turned.xp[i] - pose.xp[i]).abs() < 1e-12,
                "{turned:?}"
            );
        }
        for sliders in [Sliders::Locked, Sliders::Free] {
            let (a, b) = (
                modal(&paper, &pose, sliders, 6).unwrap(),
                modal(&exp, &turned, sliders, 6).unwrap(),
            );
            let (amm, fem) = largest_differences(&a, &b);
            eprintln!("{sliders:?}, masses scaled {effective_mass}: AMM {amm:.1e}, FEM {fem:.1e}");
            match (sliders, effective_mass) {
                (Sliders::Free, false) => assert!(amm > 1e-2 && fem > 1e-2, "the rails do matter: {amm} {fem}"),
                // the AMM's eigenvalues are good to ~eps |D| (1e-8 of f1 at N = 60, docs/modes.md, speed)
                _ => assert!(amm < 1e-7 && fem < 1e-7, "AMM {amm:e}, FEM {fem:e}"),
            }
        }
    }
}

fn to_faer(m: &sprs::CsMat<f64>) -> faer::Mat<f64> {
    let d = m.to_dense();
    faer::Mat::from_fn(m.rows(), m.cols(), |r, c| d[[r, c]])
}

fn linear(exp: &Experiment, holding: Holding) -> StateSpace {
    let [gx, gy, th] = POSES[0];
    let pose = pose_from_task(&robot(exp), gx, gy, th).unwrap();
    linearize_with(
        exp,
        &pose,
        &LinearSettings {
            modes: 8,
            holding,
            ..Default::default()
        },
    )
    .unwrap()
}

/// `linearize` of the robot as built, free and locked sliders, K = 8: the eigenvalues of A
/// (faer's general eigensolver) are the six rigid zeros (free) and `+- i omega` with omega = 2 pi
/// f of the AMM's modal analysis (to 1e-9: the assembly of A) and of the FEM's (the independent
/// model, within 1 %).
#[test]
fn eigenvalues_of_a_are_the_modal_frequencies_of_the_robot_as_built() {
    let exp = as_built();
    let two_pi = 2.0 * std::f64::consts::PI;
    for (holding, sliders) in [(Holding::Free, Sliders::Free), (Holding::Locked, Sliders::Locked)] {
        let ss = linear(&exp, holding);
        let ev = to_faer(&ss.a).eigenvalues().unwrap();
        let wmax = ev.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
        let zero_tol = (f64::EPSILON * wmax * wmax).sqrt() * 10.0;
        let rigid = if sliders == Sliders::Free { 3 } else { 0 };
        assert_eq!(ev.iter().filter(|z| z.re.hypot(z.im) < zero_tol).count(), 2 * rigid);
        let mut w: Vec<f64> = ev.iter().filter(|z| z.im > zero_tol).map(|z| z.im).collect();
        w.sort_by(f64::total_cmp);
        assert_eq!(w.len(), 8);
        let m = modal(&exp, &ss.pose, sliders, 8).unwrap();
        for (j, wj) in w.iter().enumerate() {
            let (a, f) = (m.amm.freq_hz[rigid + j], m.fem.freq_hz[rigid + j]);
            assert!(
                (wj / (two_pi * a) - 1.0).abs() < 1e-9,
                "{holding:?} mode {j}: A {wj}, AMM {a} Hz"
            );
            assert!(
                (wj / (two_pi * f) - 1.0).abs() < 0.01,
                "{holding:?} mode {j}: A {wj}, FEM {f} Hz"
            );
        }
    }
}

/// The rigid robot's mass matrix on the slider coordinates, from its kinetic energy: each slider
/// (with its sleeve's translation) `m_i ds_i^2 / 2`; beam i, the point `G + x e_xi` moving at
/// `G' + x theta' e_wi`, `rho_i / 2 int_0^L_i |G' + x theta' e_wi|^2 dx`; each sleeve turning with
/// the star, `Jp_i theta'^2 / 2`. On (Gx, Gy, theta) the star's matrix is
/// `sum_i [[rho_i L_i I, rho_i L_i^2 / 2 e_wi], [., rho_i L_i^3 / 3 + Jp_i]]`, carried to the
/// sliders by the rigid Jacobian (dual numbers through the robot's kinematics).
fn rigid_mass_matrix(robot: &Robot, pose: &RestPose) -> Matrix3<f64> {
    let jac = Matrix3::from_fn(|r, j| {
        let s = [0, 1, 2].map(|i| num_dual::Dual2::new(pose.s[i], if i == j { 1.0 } else { 0.0 }, 0.0));
        let st = flexstar_kinematics::RigidState::from_actuators(robot, s, 0.0).unwrap();
        [st.g[0].d1, st.g[1].d1, st.theta.d1][r]
    });
    let mut star = Matrix3::zeros();
    for (i, b) in robot.beams().iter().enumerate() {
        let (rho, l) = (b.mass_per_length, b.length);
        let ew = robot.e_w(i, pose.theta);
        star[(0, 0)] += rho * l;
        star[(1, 1)] += rho * l;
        for c in 0..2 {
            star[(c, 2)] += rho * l * l / 2.0 * ew[c];
            star[(2, c)] += rho * l * l / 2.0 * ew[c];
        }
        star[(2, 2)] += rho * l.powi(3) / 3.0 + b.sleeve_inertia;
    }
    Matrix3::from_diagonal(&nalgebra::Vector3::from_fn(|i, _| robot.beams()[i].sleeve_mass))
        + jac.transpose() * star * jac
}

/// The free model's rigid part against the rigid robot as built: the three 0 Hz modes' residue
/// in `p^2 s / Fa`, `sum_{j rigid} C[s, j] B[nr + j, :]`, is the inverse of the rigid mass matrix
/// written above (each slider's own mass, each beam's own rho, L and weld). Measured 2.4e-8
/// relative; the tolerance of the paper robot's test (`linear_checks.rs`), 1e-7.
#[test]
fn rigid_residue_is_the_inverse_rigid_mass_matrix_of_the_robot_as_built() {
    let exp = as_built();
    let ss = linear(&exp, Holding::Free);
    let reference = rigid_mass_matrix(&robot(&exp), &ss.pose).try_inverse().unwrap();
    let (b, c) = (ss.b.to_dense(), ss.c.to_dense());
    let nr = ss.a.rows() / 2;
    let scale = reference.abs().max();
    let mut worst = 0.0f64;
    for i in 0..3 {
        for k in 0..3 {
            let residue: f64 = (0..3).map(|j| c[[i, j]] * b[[nr + j, k]]).sum();
            eprintln!(
                "M_r^-1[{i}][{k}]: residue {residue:.10e}, rigid {:.10e}",
                reference[(i, k)]
            );
            worst = worst.max((residue - reference[(i, k)]).abs());
        }
    }
    eprintln!("largest difference {:.2e} relative", worst / scale);
    assert!(worst < 1e-7 * scale, "largest difference {worst:e} of {scale:e}");
}

/// C's tip and G rows of the robot as built (each beam's own L_i and e_wi, Eq. M1) against the
/// FEM's inertia-relief static deflection (tests/support/inertia_relief.rs), as for the paper's
/// robot: within 0.5 % of the largest gain. Measured 0.10 % (4.5e-6 of 4.3e-3 m/N).
#[test]
fn elastic_static_gain_of_the_robot_as_built_matches_the_fem() {
    let exp = experiment(&format!("{AS_BUILT}[amm]\nfamily = \"enriched\"\nmodes = 60\n"));
    let settings = LinearSettings {
        modes: flexstar_modal::linear::ELASTIC_MODES,
        holding: Holding::Free,
        ..Default::default()
    };
    let [gx, gy, th] = POSES[0];
    let pose = pose_from_task(&robot(&exp), gx, gy, th).unwrap();
    let ss = linearize_with(&exp, &pose, &settings).unwrap();
    let (worst, scale) = inertia_relief::elastic_static_gain_error(&robot(&exp), &ss);
    eprintln!("largest difference {worst:.3e} m/N of {scale:.3e} m/N");
    assert!(scale > 0.0);
    assert!(
        worst < 5e-3 * scale,
        "largest difference {worst:e} m/N of {scale:e} m/N"
    );
}

/// A frequency map of the robot as built: its point at the start pose (t = 0 of the motion)
/// equals `modal` there (the map's values-only solver against the full one, 1e-7).
#[test]
fn the_map_at_the_start_pose_equals_modal_there() {
    let exp = as_built();
    let start = pose_at_time(&exp, 0.0).unwrap();
    let grid = Grid {
        gx: Axis {
            min: start.g[0],
            max: start.g[0] + 0.02,
            n: 2,
        },
        gy: Axis {
            min: start.g[1],
            max: start.g[1] + 0.02,
            n: 2,
        },
        theta: start.theta,
        sliders: Sliders::Locked,
    };
    let points = freqmap(&exp, &grid, 4, Solver::Amm, |_, _| {}).unwrap();
    let at_start = points[0].result.as_ref().unwrap();
    let m = modal(&exp, &start, Sliders::Locked, 4).unwrap();
    for (j, f) in at_start.iter().enumerate() {
        let reference = m.amm.freq_hz[j];
        assert!(
            (f / reference - 1.0).abs() < 1e-7,
            "mode {}: map {f} Hz, modal {reference} Hz",
            j + 1
        );
    }
    assert!(
        points.iter().all(|p| p.result.is_ok()),
        "a small grid about the start pose"
    );
}

/// The closed loop of a robot as built: gains given as kp and kd hold on the three sliders; from
/// `bandwidth_hz` they would differ with the sliders' masses, refused naming the key.
#[test]
fn a_servo_from_bandwidth_needs_equal_sliders() {
    let servo = |drive: &str| experiment(&format!("{AS_BUILT}[drive]\nkind = \"servo\"\n{drive}"));
    let given = Holding::servo_of(&servo("kp = 100.0\nkd = 2.0\n")).unwrap();
    assert_eq!(given, Holding::Servo { kp: 100.0, kd: 2.0 });
    let e = Holding::servo_of(&servo("bandwidth_hz = 10.0\ndamping_ratio = 0.7\n"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("drive.bandwidth_hz") && e.contains("kp and kd"), "{e}");
}
