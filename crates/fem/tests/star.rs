//! Whole-robot checks of the FEM against independent references: symmetry, the rigid-body limit
//! (rigid kinematics and rigid inverse dynamics of flexstar-kinematics), the energy balance, and
//! the bad-input errors.
//!
//! Meshes are coarser than the default (108 elements, 36 per beam: the coarsest that holds a
//! sleeve with 2 elements across Lp is 34 per beam) to keep the test run short; every check here
//! is mesh-independent to far better than its tolerance (docs/fem.md, convergence study).

#![allow(clippy::needless_range_loop)]

use flexstar_fem::FemError;
use flexstar_kinematics::{rigid_inverse_dynamics, RigidState};
use flexstar_model::{catalogue, Experiment, FemSettings, Pose, RobotParams, Trajectory};
use flexstar_numerics::measures::max_abs;

fn experiment(robot: RobotParams, trajectory: Trajectory, t_end: f64) -> Experiment {
    catalogue::experiment("test", robot, trajectory, t_end, 1e-3)
}

use crate::run;
use run::{coarse, col};

/// Rest-to-rest task-space quintic (zero velocity and acceleration at both ends), general motion.
fn quintic() -> Trajectory {
    catalogue::quintic_from_origin(
        Pose {
            gx: 0.03,
            gy: -0.02,
            theta: 0.25,
        },
        0.3,
    )
}

#[test]
fn case1_is_symmetric() {
    // Case 1 (s_i = t^2, 0.5 s): in-place rotation; by symmetry G does not move and the three
    // tips vibrate identically (paper, section 8.1). Paper mesh (300 elements), default step.
    let exp = experiment(RobotParams::paper(), Trajectory::quadratic([1.0, 1.0, 1.0]), 0.5);
    let problem = exp.problem().unwrap();
    let (r, stats) = flexstar_fem::solve(
        &problem,
        &FemSettings::default(),
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| (s.response, s.stats))
    .unwrap();
    // work counts at the defaults (dt = 5e-4 s): 1000 steps, about 3 Newton iterations each, and
    // a new symbolic factorisation each time a contact point leaves its window of elements
    eprintln!("{stats:?}");
    assert_eq!(stats.steps, 1000);
    assert!(
        stats.newton_iterations >= 2 * stats.steps && stats.newton_iterations <= 4 * stats.steps,
        "{stats:?}"
    );
    assert!(
        stats.symbolic_factorisations > 1 && stats.symbolic_factorisations < 100,
        "{stats:?}"
    );
    assert_eq!(r.len(), 501);
    assert_eq!(r.label, "fem");
    let tip = max_abs(&r.w_tip[0]);
    assert!(tip > 1e-3, "the tips must vibrate visibly, max |w1tip| = {tip}");
    for i in 0..3 {
        assert!(max_abs(&r.w_g[i]) < 1e-12, "w{}G = {}", i + 1, max_abs(&r.w_g[i]));
        for k in 0..r.len() {
            assert!(
                (r.w_tip[i][k] - r.w_tip[0][k]).abs() < 1e-9 * tip,
                "tip {} at t = {}",
                i + 1,
                r.t[k]
            );
            assert!(
                (r.fa[i][k] - r.fa[0][k]).abs() < 1e-7 * max_abs(&r.fa[0]),
                "Fa{} at t = {}",
                i + 1,
                r.t[k]
            );
        }
    }
    // snapshot at t_end: three identical beams
    let s = r.shapes.last().unwrap();
    assert!((s.t - 0.5).abs() < 1e-12);
    for i in 1..3 {
        for (a, b) in s.beams[i].w.iter().zip(&s.beams[0].w) {
            assert!((a - b).abs() < 1e-9 * tip);
        }
    }
}

#[test]
fn stiff_limit_follows_rigid_kinematics_and_inverse_dynamics() {
    // EI x 1e4: the star is practically rigid, so G must follow the Fermat-point kinematics and Fa
    // the rigid-body inverse dynamics (both computed independently in flexstar-kinematics).
    let mut robot = RobotParams::paper();
    robot.i *= 1e4;
    let exp = experiment(robot, quintic(), 0.35);
    // at the paper robot's step (the robot-dependent default, Eq. S10 of docs/fem.md 4.1, would
    // resolve the stiff star's kHz modes, which this limit wants damped)
    let settings = FemSettings {
        dt: Some(flexstar_fem::DEFAULT_DT),
        ..coarse()
    };
    let problem = exp.problem().unwrap();
    let r = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let (dgx, dgy) = (col(&r, "dGx"), col(&r, "dGy"));
    let mut fa_rigid = [vec![], vec![], vec![]];
    for (k, &t) in r.t.iter().enumerate() {
        let dg = dgx[k].hypot(dgy[k]);
        assert!(dg < 1e-5, "|G_fem - G_rigid| = {dg} m at t = {t}");
        let st = RigidState::at(&robot, &exp.trajectory, t).unwrap();
        let f = rigid_inverse_dynamics(&robot, &st);
        for i in 0..3 {
            fa_rigid[i].push(f.fa[i]);
        }
    }
    // Relative to the largest rigid driving force (each Fa passes through zero at rest and at
    // reversal), pointwise, and as the EVP of Eq. 45 (docs/validation.md) per actuator. What is left is
    // the star's own vibration: the quintic's jerk jumps at t0 and t1 excite the first bending
    // mode of the outboard beam parts (about 900 Hz at EI x 1e4), which the default
    // rho_inf = 0.7 damps at the default step (docs/fem.md, "stiff limit").
    let peak = fa_rigid.iter().map(|f| max_abs(f)).fold(0.0, f64::max);
    assert!(peak > 0.5, "the quintic must need a visible force, peak {peak} N");
    for i in 0..3 {
        let err = r.fa[i]
            .iter()
            .zip(&fa_rigid[i])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let num: f64 = r.fa[i].iter().zip(&fa_rigid[i]).map(|(a, b)| (a - b).abs()).sum();
        let den: f64 = fa_rigid[i].iter().map(|b| b.abs()).sum();
        let evp = num / den * 100.0;
        eprintln!(
            "Fa{}: largest difference {err:.2e} N ({:.3} % of {peak:.3} N), EVP {evp:.3} %",
            i + 1,
            err / peak * 100.0
        );
        assert!(
            err < 5e-3 * peak,
            "Fa{}: largest difference {err} N against a peak of {peak} N",
            i + 1
        );
        assert!(evp < 0.5, "Fa{}: EVP {evp} % against the rigid inverse dynamics", i + 1);
    }
}

#[test]
fn energy_balance_holds_at_paper_stiffness() {
    // Work of the drivers = kinetic energy of sliders, sleeves and star + strain energy. No
    // damping: only the integrator's numerical dissipation (rho_inf < 1) may spoil it.
    // Third run: a start with nonzero actuator speeds (the star starts moving rigidly, E(0) > 0).
    let moving = Trajectory::Polynomial {
        s1: vec![0.0, 0.3, 1.0],
        s2: vec![0.0, 0.1, -0.5],
        s3: vec![0.0, 0.2, 0.0],
    };
    for (traj, t_end) in [
        (quintic(), 0.4),
        (Trajectory::quadratic([1.0, 0.0, 0.5]), 0.5),
        (moving, 0.3),
    ] {
        let exp = experiment(RobotParams::paper(), traj, t_end);
        let problem = exp.problem().unwrap();
        let r = flexstar_fem::solve(&problem, &coarse(), flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .unwrap();
        let w = col(&r, "W");
        let wmax = max_abs(w);
        assert!(wmax > 1e-3, "the drivers must do work");
        let energy =
            |k: usize| col(&r, "Ek_star")[k] + col(&r, "Ek_sleeves")[k] + col(&r, "Ek_sliders")[k] + col(&r, "U")[k];
        // the error is bounded against the strain energy, the smallest part of the balance (0.2-1 %
        // of the work), so that a defect in the elastic terms cannot hide in the rigid ones
        let umax = max_abs(col(&r, "U"));
        assert!(
            umax > 1e-4 * wmax,
            "the elastic energy must be a real part of the balance"
        );
        let mut worst: f64 = 0.0;
        for k in 0..r.len() {
            worst = worst.max((energy(k) - energy(0) - w[k]).abs());
        }
        eprintln!(
            "energy balance: worst |E - W| = {:.2e} of max W, {:.2e} of max U",
            worst / wmax,
            worst / umax
        );
        assert!(
            worst < 1e-2 * umax,
            "energy balance off by {:.3} % of the strain energy",
            worst / umax * 100.0
        );
    }
}

#[test]
fn bad_input_stops_with_time_and_reason() {
    let exp = experiment(RobotParams::paper(), Trajectory::quadratic([1.0, 1.0, 1.0]), 0.1);
    // mesh too coarse: 10 elements per beam, h = 5 cm > Lp / 2
    let problem = exp.problem().unwrap();
    let err = flexstar_fem::solve(
        &problem,
        &FemSettings {
            elements: 30,
            ..Default::default()
        },
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| s.response)
    .unwrap_err();
    assert!(matches!(err, FemError::MeshTooCoarse { per_beam: 10, .. }), "{err}");
    let problem = exp.problem().unwrap();
    let err = flexstar_fem::solve(
        &problem,
        &FemSettings {
            elements: 100,
            ..Default::default()
        },
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| s.response)
    .unwrap_err();
    assert!(
        matches!(err, FemError::Elements { elements: 100, .. }) && err.to_string().contains("multiple of 3"),
        "{err}"
    );
    let problem = exp.problem().unwrap();
    let err = flexstar_fem::solve(
        &problem,
        &FemSettings {
            dt: Some(-1.0),
            ..coarse()
        },
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| s.response)
    .unwrap_err();
    assert!(matches!(err, FemError::Input(_)), "{err}");
    // case 2 past its end of travel: sleeve 2 (J) runs into G shortly after 0.4 s; refused by
    // the feasibility scan before any step (docs/conventions.md, feasible range), with the time and the sleeve
    let exp = experiment(RobotParams::paper(), Trajectory::quadratic([1.0, -0.5, -0.5]), 0.5);
    let problem = exp.problem().unwrap();
    match flexstar_fem::solve(&problem, &coarse(), flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap_err()
    {
        FemError::Scan(infeasible) => {
            let msg = infeasible.to_string();
            assert!(msg.contains("sleeve 2 reaches the junction G"), "{msg}");
            assert!(infeasible.t > 0.4 && infeasible.t < 0.5, "t = {}", infeasible.t);
        }
        e => panic!("expected the feasibility scan to refuse, got: {e}"),
    }
}

#[test]
fn progress_reaches_one_and_rows_match_output_times() {
    use std::sync::Mutex;
    let exp = experiment(RobotParams::paper(), Trajectory::quadratic([1.0, -0.5, -0.5]), 0.02);
    let seen = Mutex::new(Vec::new());
    let cb = |f: f64| seen.lock().unwrap().push(f);
    let problem = exp.problem().unwrap();
    let r = flexstar_fem::solve(
        &problem,
        &FemSettings {
            snapshots: vec![0.01],
            ..coarse()
        },
        flexstar_drive::SolveRequest::motion().with_progress(Some(&cb)),
    )
    .map(|s| s.response)
    .unwrap();
    assert_eq!(r.t, exp.time.output_times());
    let seen = seen.into_inner().unwrap();
    assert!(seen.windows(2).all(|w| w[1] >= w[0]) && (seen.last().unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(r.shapes.iter().map(|s| s.t).collect::<Vec<_>>(), vec![0.01, 0.02]);
    assert_eq!(
        r.header()[..10],
        ["t", "w1G", "w2G", "w3G", "w1tip", "w2tip", "w3tip", "Fa1", "Fa2", "Fa3"]
    );
}

#[test]
fn a_set_cancel_token_stops_the_run_at_the_first_output_time() {
    let exp = experiment(RobotParams::paper(), Trajectory::quadratic([1.0, -0.5, -0.5]), 0.02);
    let token = flexstar_model::Cancel::new();
    token.cancel();
    let r = flexstar_model::cancel::with_cancel(Some(&token), || {
        let problem = exp.problem().unwrap();
        flexstar_fem::solve(&problem, &coarse(), flexstar_drive::SolveRequest::motion()).map(|s| s.response)
    });
    match r {
        Err(FemError::Cancelled { t }) => assert_eq!(t, exp.time.dt_out),
        other => panic!("expected Cancelled, got {:?}", other.map(|r| r.t.len())),
    }
}
