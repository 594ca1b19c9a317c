//! The FEM as a reference on a robot unlike the paper's (`docs/fem.md` sections
//! 2.1 and 4.1, `docs/validation.md` "FEM convergence on other robots"): the sleeve-heavy robot 1
//! (`reference_values/robot1.toml`: Jp / (rho L^3) = 0.078, eleven times the paper
//! robot's), against a refined run of the FEM whose histories are committed
//! (`reference_values/robot1_refined.csv`, provenance in `reference_values/README.md`).
//!
//! Error measure: the project's mean EVP (Eq. 45, `flexstar_metrics::evp::point_evps`, over A, B,
//! C and G at every output time) of a run against the reference, or between two runs.
//!
//! - the defaults (300 elements, the robot-dependent step of Eq. S10) are within 0.1 % of the
//!   reference (measured 0.085 %; 0.62 % with the paper's fixed 5e-4 s before Eq. S10);
//! - the mesh converges at second order (Eq. S9 of the tangent rows; the pointwise row before
//!   it gave 1.4 and worsening, a first-order discretisation): observed orders against the
//!   reference and, Richardson's way, from three meshes alone;
//! - the step converges at the order of the generalized-alpha scheme (2, here pre-asymptotic).

use std::path::Path;

use flexstar_metrics::evp::point_evps;
use flexstar_model::{Experiment, FemSettings, Response};

const CONFIG: &str = include_str!("reference_values/robot1.toml");
const REFERENCE: &str = include_str!("reference_values/robot1_refined.csv");

fn experiment() -> Experiment {
    Experiment::from_toml_str(CONFIG, Path::new("reference_values/robot1.toml")).expect("robot 1")
}

/// The committed reference: rows `t, w1tip, w2tip, w3tip, w1G, w2G, w3G` at every output time.
fn reference() -> Response {
    let mut lines = REFERENCE.lines();
    assert_eq!(lines.next(), Some("t,w1tip,w2tip,w3tip,w1G,w2G,w3G"));
    let mut r = Response::with_capacity("fem-refined", 501);
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("a number")).collect();
        assert_eq!(v.len(), 7, "seven columns");
        r.push(v[0], [v[4], v[5], v[6]], [v[1], v[2], v[3]], [0.0; 3]);
    }
    r
}

/// The FEM on robot 1 with `elements` and the step `dt` (`None`: the default).
fn run(exp: &Experiment, elements: usize, dt: Option<f64>) -> Response {
    let settings = FemSettings {
        elements,
        dt,
        rho_inf: None,
        snapshots: vec![],
        frames: 0,
    };
    let problem = exp.problem().unwrap();
    flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .expect("FEM run")
}

/// Mean EVP [%] of `a` against `b` (Eq. 45).
fn evp(a: &Response, b: &Response) -> f64 {
    point_evps(a, b)
        .expect("same output times")
        .mean
        .expect("moving points")
}

#[test]
fn defaults_are_within_a_tenth_of_a_percent_of_the_converged_limit() {
    let exp = experiment();
    let dt = flexstar_fem::default_dt(&exp.robot);
    // Eq. S10: the stiffer robot gets a smaller step, the paper's keeps 5e-4 s
    assert!((dt - 1.358e-4).abs() < 1e-7, "default step {dt:e}");
    assert_eq!(flexstar_fem::default_dt(&flexstar_model::RobotParams::paper()), 5e-4);
    let reference = reference();
    let default = run(&exp, 300, None);
    assert_eq!(default.info.dt, dt);
    let e = evp(&default, &reference);
    eprintln!("defaults (300 elements, dt {dt:e} s): mean EVP {e:.4} % from the refined run");
    // the 0.1 % target (docs/validation.md section 7); measured 0.0852 %
    assert!(e <= 0.1, "defaults {e} % from the converged limit");
}

#[test]
fn mesh_converges_at_second_order() {
    let exp = experiment();
    let reference = reference();
    // at a step fine enough that the mesh error dominates (the reference's own step)
    let dt = Some(3.125e-5);
    let runs: Vec<Response> = [150, 300, 600].iter().map(|&n| run(&exp, n, dt)).collect();
    let e: Vec<f64> = runs.iter().map(|r| evp(r, &reference)).collect();
    let order = (e[0] / e[1]).log2();
    // Richardson: from the three meshes alone, the differences of successive refinements
    let (d1, d2) = (evp(&runs[0], &runs[1]), evp(&runs[1], &runs[2]));
    let richardson = (d1 / d2).log2();
    eprintln!("mesh: errors {e:?} %, order {order:.2}; differences {d1:.4} / {d2:.4} %, order {richardson:.2}");
    // measured 0.135 / 0.025 / 0.0092 % (the last mostly the step error of 3.125e-5 s against
    // the reference's 1.5625e-5 s, which the differences cancel), order 2.42; differences
    // 0.112 / 0.0225 %, order 2.32. The pointwise tangent row before Eq. S9 gave 0.449 / 0.171 /
    // 0.063 % against 2400 elements, order 1.4
    assert!(e[1] < 0.04, "300 elements: {} %", e[1]);
    assert!((1.8..=3.5).contains(&order), "order against the reference {order}");
    assert!((1.8..=3.5).contains(&richardson), "Richardson order {richardson}");
}

#[test]
fn step_converges_at_the_order_of_the_scheme() {
    let exp = experiment();
    let reference = reference();
    // on a mesh fine enough that the step error dominates (mesh error 0.004 %)
    let runs: Vec<Response> = [2.5e-4, 1.25e-4].iter().map(|&dt| run(&exp, 600, Some(dt))).collect();
    let e: Vec<f64> = runs.iter().map(|r| evp(r, &reference)).collect();
    let order = (e[0] / e[1]).log2();
    eprintln!("step: errors {e:?} %, order {order:.2}");
    // measured 0.259 / 0.089 %, order 1.54 (1.7 from 1.25e-4 to 6.25e-5 s): second order,
    // pre-asymptotic; a first-order scheme would give 1
    assert!((1.4..=2.6).contains(&order), "step order {order}");
}
