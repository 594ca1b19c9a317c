//! Direct dynamics of the AMM (`docs/amm.md` section 10) against independent references: the inverse run it must
//! invert (round trip), and the prescribed-motion run a very stiff servo must reproduce.

use crate::rigid_forward;

use crate::common;

use common::paper_case;
use flexstar_amm::DEFAULT_DT;
use flexstar_drive::{ForceTable, Servo};
use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, Response};

/// Paper case `k` cut to `t_end` [s], with output step `dt_out` [s].
fn case(k: usize, t_end: f64, dt_out: f64) -> Experiment {
    let mut exp = paper_case(k);
    exp.time.t_end = t_end;
    exp.time.dt_out = dt_out;
    exp
}

/// The forces of an inverse run as a table.
fn table(r: &Response) -> ForceTable {
    let fa = (0..r.len()).map(|k| [r.fa[0][k], r.fa[1][k], r.fa[2][k]]).collect();
    ForceTable::new(r.t.clone(), fa).unwrap()
}

/// Largest |s_direct - s_trajectory| [m] over the output times.
fn slider_error(exp: &Experiment, direct: &Response) -> f64 {
    let mut worst = 0.0f64;
    for (k, &t) in direct.t.iter().enumerate() {
        let s = exp.trajectory.s(&exp.robot, t).unwrap();
        for i in 0..3 {
            let col = direct.column(["s1", "s2", "s3"][i]).unwrap();
            worst = worst.max((col[k] - s[i]).abs());
        }
    }
    worst
}

/// Round trip of one case: inverse run with output every `dt_fa`, its Fa fed back.
fn round_trip(k: usize, settings: &AmmSettings, t_end: f64, dt_fa: f64) -> (f64, f64) {
    round_trip_exp(&case(k, t_end, 1e-3), settings, dt_fa)
}

#[test]
fn round_trip_gives_the_motion_back_in_every_paper_case() {
    // an inverse run's Fa with output at every solver step, fed back, gives s(t) within
    // 1e-6 m and the tips and G within an EVP of 0.1 %
    for k in 1..=4 {
        let settings = paper_case(k).amm;
        let (ds, evp) = round_trip(k, &settings, 0.2, DEFAULT_DT);
        eprintln!("case {k}: |s - s_ref| <= {ds:.3e} m, worst point EVP {evp:.2e} %");
        // (s'' is constant in the paper's cases, which the scheme integrates exactly)
        assert!(ds < 1e-6, "case {k}: {ds:e} m");
        assert!(evp < 0.1, "case {k}: {evp} %");
    }
}
/// Round trip of an arbitrary experiment.
fn round_trip_exp(exp: &Experiment, settings: &AmmSettings, dt_fa: f64) -> (f64, f64) {
    let mut fine = exp.clone();
    fine.time.dt_out = dt_fa;
    let inverse_fine = common::motion_response(&fine, settings).unwrap();
    let inverse = common::motion_response(exp, settings).unwrap();
    let problem = exp.problem().unwrap();
    let direct = flexstar_amm::solve(
        &problem,
        settings,
        flexstar_drive::SolveRequest::law(&table(&inverse_fine)),
    )
    .map(|s| s.response)
    .unwrap();
    let ds = slider_error(exp, &direct);
    let evp = point_evps(&direct, &inverse).unwrap();
    let worst = evp.points.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
    (ds, worst)
}

#[test]
fn round_trip_of_a_varying_acceleration_both_models() {
    // a rest-to-rest quintic: s'' changes every step, so the coupled step's linearisation about
    // the predicted s'' is exercised (the paper's cases have constant s'')
    use flexstar_model::{AmmModel, ModeFamily};
    let exp = common::quintic(flexstar_model::RobotParams::paper(), 0.15);
    for (family, model, n) in [
        (ModeFamily::FreeFree, AmmModel::Paper, 25),
        (ModeFamily::Enriched, AmmModel::Full, 40),
    ] {
        let settings = AmmSettings {
            modes: Some(n),
            model,
            ..AmmSettings::paper(family, n)
        };
        // the difference shrinks as the inverse run's output step (the table's sampling) shrinks
        let mut prev = (f64::INFINITY, f64::INFINITY);
        for dt_fa in [1e-3, 5e-4, DEFAULT_DT] {
            let (ds, evp) = round_trip_exp(&exp, &settings, dt_fa);
            eprintln!("{family} {model} dt_fa {dt_fa:.2e}: |s - s_ref| <= {ds:.3e} m, worst EVP {evp:.2e} %");
            assert!(ds < 0.5 * prev.0 && evp < 0.5 * prev.1, "{dt_fa}: {ds:e} m, {evp} %");
            prev = (ds, evp);
        }
        assert!(prev.0 < 1e-6 && prev.1 < 0.1, "{family} {model}: {prev:?}");
    }
}

#[test]
fn stiff_servo_reproduces_the_prescribed_motion() {
    // a servo of 1 kHz bandwidth (damping ratio 0.7, rigid feedforward) on each slider
    // tracks the trajectory closely enough that the star vibrates as under the ideal motion: tips
    // within an EVP of 1 % of the inverse run (paper cases, their own settings, 0.2 s)
    for k in 1..=4 {
        let exp = case(k, 0.2, 1e-3);
        let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 1000.0, 0.7);
        let servo = Servo {
            kp: [kp; 3],
            kd: [kd; 3],
            rigid_feedforward: true,
            reference: exp.trajectory.clone(),
            params: exp.robot,
            attached: Default::default(),
        };
        let inverse = common::motion_response(&exp, &exp.amm).unwrap();
        let problem = exp.problem().unwrap();
        let direct = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::law(&servo))
            .map(|s| s.response)
            .unwrap();
        let ds = slider_error(&exp, &direct);
        let evp = point_evps(&direct, &inverse).unwrap();
        let tips = evp.points[..3].iter().flatten().fold(0.0f64, |m, v| m.max(*v));
        eprintln!(
            "case {k}: tracking error <= {ds:.3e} m, worst tip EVP {tips:.3} %, points {:?}",
            evp.points
        );
        assert!(tips < 1.0, "case {k}: {tips} %");
    }
}

#[test]
fn round_trip_error_is_the_sliders_second_order_integration_error() {
    // with s'' varying, the direct run integrates s by the generalized-alpha scheme where the
    // inverse run takes s exactly: the round-trip difference must fall as h^2 (ratio 4 per halving),
    // which also shows that the coupled step's linearisation adds nothing visible
    use flexstar_model::ModeFamily;
    let exp = common::quintic(flexstar_model::RobotParams::paper(), 0.15);
    let run = |dt: f64| {
        let settings = AmmSettings {
            dt: Some(dt),
            ..AmmSettings::paper(ModeFamily::FreeFree, 25)
        };
        round_trip_exp(&exp, &settings, dt).0
    };
    let (e1, e2) = (run(DEFAULT_DT), run(DEFAULT_DT / 2.0));
    eprintln!(
        "h = {DEFAULT_DT:.3e} s: {e1:.3e} m; h/2: {e2:.3e} m; ratio {:.3}",
        e1 / e2
    );
    assert!(e1 < 1e-6, "{e1:e}");
    assert!((e1 / e2 - 4.0).abs() < 0.3, "ratio {}", e1 / e2);
}

#[test]
fn leaving_the_feasible_range_stops_with_time_and_reason() {
    // 50 N on slider 1 alone from rest: it runs off its side of the base (|s1| < sqrt(3) d =
    // 0.312 m) or drags a sleeve into G well before 0.5 s; the run must stop there, not panic
    let exp = case(1, 0.5, 1e-3);
    let push = flexstar_drive::ForcePolynomials {
        coefficients: [vec![50.0], vec![0.0], vec![0.0]],
    };
    let problem = exp.problem().unwrap();
    let err = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::law(&push))
        .map(|s| s.response)
        .unwrap_err();
    let msg = err.to_string();
    eprintln!("{msg}");
    match err {
        flexstar_amm::AmmError::DirectInfeasible { t, .. } => assert!(t > 0.01 && t < 0.5, "{msg}"),
        other => panic!("expected an infeasible motion, got {other}"),
    }
    assert!(msg.contains("direct run left the feasible range at t = 0."), "{msg}");
}

#[test]
fn automatic_n_runs_the_direct_problem_too() {
    // tol mode (the accurate defaults: enriched, full, tol 0.5 %): the direct run driven by the
    // inverse run's forces (every solver step) picks the same N and gives the same vibration
    let mut exp = case(3, 0.1, DEFAULT_DT);
    exp.amm = AmmSettings::accurate();
    let inverse = common::motion_response(&exp, &exp.amm).unwrap();
    let problem = exp.problem().unwrap();
    let direct = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::law(&table(&inverse)))
        .map(|s| s.response)
        .unwrap();
    assert_eq!(direct.info.modes, inverse.info.modes);
    assert!(direct.info.error_estimate_percent.is_some());
    assert_eq!(direct.info.solver, "amm-direct");
    let evp = point_evps(&direct, &inverse).unwrap();
    let worst = evp.points.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
    eprintln!("N = {:?}, worst point EVP {worst:.2e} %", direct.info.modes);
    assert!(worst < 0.1, "{worst} %");
    assert!(slider_error(&exp, &direct) < 1e-6);
}

#[test]
fn stiff_limit_matches_the_rigid_forward_dynamics() {
    // EI x 1e4: under the rigid inverse dynamics' forces of each paper motion, the AMM's sliders
    // must move as the rigid robot's forward dynamics says (flexstar-drive: virtual power on the
    // Fermat-point Jacobians, RK4 at 1e-4 s; no AMM code). Paper model, free-free modes: the
    // family whose rigid modes let G move freely (docs/amm.md section 4). Measured: 5.5e-8 to
    // 1.1e-7 m over travels of 0.16-0.25 m.
    use flexstar_drive::RigidInverseForces;
    use rigid_forward::rigid_forward_dynamics;
    for k in 1..=4 {
        let mut exp = paper_case(k);
        exp.robot.i *= 1e4;
        let robot = exp.robot;
        let law = RigidInverseForces {
            trajectory: exp.trajectory.clone(),
            params: robot,
            attached: Default::default(),
        };
        let settings = AmmSettings::paper(flexstar_model::ModeFamily::FreeFree, 25);
        let problem = exp.problem().unwrap();
        let r = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&law))
            .map(|s| s.response)
            .unwrap();
        let s0 = exp.trajectory.s(&robot, 0.0).unwrap();
        let v0 = exp.trajectory.jets(&robot, 0.0).unwrap().map(|j| j.d1);
        let reference = rigid_forward_dynamics(&robot, s0, v0, &law, exp.time.t_end, exp.time.dt_out, 1e-4).unwrap();
        assert_eq!(reference.len(), r.len());
        let (mut worst, mut travel) = (0.0f64, 0.0f64);
        for (n, rs) in reference.iter().enumerate() {
            for i in 0..3 {
                let s = r.column(["s1", "s2", "s3"][i]).unwrap()[n];
                worst = worst.max((s - rs.s[i]).abs());
                travel = travel.max((s - s0[i]).abs());
            }
        }
        eprintln!("case {k} stiff limit: largest |s_amm - s_rigid| {worst:.2e} m over a travel of {travel:.3} m");
        assert!(travel > 1e-2, "case {k}: the motion must be visible");
        assert!(
            worst < 1e-6,
            "case {k}: stiff AMM {worst:e} m off the rigid forward dynamics"
        );
    }
}
