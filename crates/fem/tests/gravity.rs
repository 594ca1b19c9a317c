//! Gravity in the FEM (`docs/fem.md` 9.5, Eqs. G6-G8) against references independent of it (the
//! AMM's static sag is compared in the workspace's `tests/attachment_models.rs`): the textbook
//! cantilever `q a^4 / (8 EI)` of each beam's overhang, the Newton-Euler rigid inverse dynamics
//! with the weights (`flexstar_kinematics::rigid_inverse_dynamics_with`, Eq. G3) and the energy
//! balance with the weights' potential. Meshes: 108 elements, as in `tests/star.rs`.

#![allow(clippy::needless_range_loop)]

use flexstar_drive::SolveRequest;
use flexstar_kinematics::{rigid_inverse_dynamics_with, RigidState};
use flexstar_model::{
    catalogue, Attachments, Damping, Experiment, FemSettings, Gravity, Payload, Response, RobotParams, Trajectory,
};
use flexstar_numerics::measures::max_abs;

const DOWN: [f64; 2] = [0.0, -9.81];

use crate::fit;
use crate::run;
use fit::quartic_at;
use run::{coarse, col};

fn fem(exp: &Experiment, settings: &FemSettings, request: SolveRequest) -> Response {
    flexstar_fem::solve(&exp.problem().unwrap(), settings, request)
        .map(|s| s.response)
        .unwrap()
}

/// The paper's robot under `g` [m/s^2], the sliders held at `s` [m] (a constant polynomial: no
/// rest time) until `t_end` [s].
fn held(s: [f64; 3], g: [f64; 2], t_end: f64) -> Experiment {
    let traj = Trajectory::Polynomial {
        s1: vec![s[0]],
        s2: vec![s[1]],
        s3: vec![s[2]],
    };
    let mut exp = catalogue::experiment("held", RobotParams::paper(), traj, t_end, 1e-3);
    exp.gravity = Gravity::new(g);
    exp
}

#[test]
fn a_star_at_rest_keeps_its_static_sag() {
    // the centre pose held still (a quintic from the origin to itself: it rests from t = 0.05 s)
    let mut exp = catalogue::experiment(
        "rest",
        RobotParams::paper(),
        catalogue::quintic_from_origin(catalogue::ORIGIN, 0.05),
        0.3,
        1e-3,
    );
    exp.gravity = Gravity::new(DOWN);
    let r = fem(&exp, &coarse(), SolveRequest::motion());
    // the run stays in its start, the static equilibrium of Eq. G8
    let dgy = col(&r, "dGy");
    let drift = dgy.iter().map(|v| (v - dgy[0]).abs()).fold(0.0, f64::max);
    let tips = [0, 1, 2].map(|i| r.w_tip[i][0]);
    let tip_drift = (0..3)
        .map(|i| r.w_tip[i].iter().map(|v| (v - tips[i]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    eprintln!(
        "FEM at rest: dGy {:.6e} m, drift {drift:.2e} m; tips {tips:?} m, drift {tip_drift:.2e} m",
        dgy[0]
    );
    assert!(dgy[0] < -1e-3, "G must sag: dGy = {} m", dgy[0]);
    assert!(drift < 1e-9 * dgy[0].abs() + 1e-12, "dGy drifts by {drift} m");
    assert!(
        tip_drift < 1e-9 + 1e-9 * max_abs(&tips),
        "a tip drifts by {tip_drift} m"
    );
    // the residual's reference at the rest pose is the same equilibrium
    let offset = r.rest_offset.expect("a rest within the run under gravity");
    for i in 0..3 {
        assert!((offset.w_g[i] - r.w_g[i][0]).abs() < 1e-10, "w{}G", i + 1);
        assert!((offset.w_tip[i] - tips[i]).abs() < 1e-10, "w{}tip", i + 1);
    }
}

/// One loaded overhang under gravity: the tip's departure from the tangent at the sleeve's outer
/// edge [m], the textbook `q a^4 / (8 EI)` [m], and the overhang's axial weight `p a` [N]
/// (positive when it compresses the overhang, pulling it towards G).
struct Overhang {
    sag: f64,
    textbook: f64,
    compression: f64,
    a: f64,
}

/// The loaded overhangs of the paper's robot held at an off-centre pose under `g` [m/s^2] (beam
/// 1, along -Y there under -Y gravity, carries no normal load and is left out), from the FEM's
/// nodes at t = 0 (its static start, Eq. G8).
fn overhangs(g: [f64; 2]) -> Vec<Overhang> {
    let exp = held([0.02, -0.03, 0.01], g, 0.002);
    let settings = FemSettings {
        snapshots: vec![0.0],
        ..coarse()
    };
    let r = fem(&exp, &settings, SolveRequest::motion());
    let p = exp.robot;
    let st = RigidState::at(&p, &exp.trajectory, 0.0).unwrap();
    let shape = &r.shapes[0];
    assert_eq!(shape.t, 0.0);
    let mut out = vec![];
    for i in 0..3 {
        let (ex, ew) = (st.e_x(i), st.e_w(i));
        let (normal, axial) = (
            p.rho * (g[0] * ew[0] + g[1] * ew[1]),
            p.rho * (g[0] * ex[0] + g[1] * ex[1]),
        );
        if normal.abs() < 1e-3 * p.rho * g[0].hypot(g[1]) {
            continue;
        }
        // the outer edge at the FEM's own sleeve position (material coordinate)
        let xr = col(&r, &format!("xp{}", i + 1))[0] + 0.5 * p.lp;
        let b = &shape.beams[i];
        let (w, slope) = quartic_at(&b.x, &b.w, xr);
        let a = p.l - xr;
        // the load normal to the overhang's own axis (turned by the slope at the edge)
        let q = normal * slope.cos() - axial * slope.sin();
        out.push(Overhang {
            sag: b.w[b.w.len() - 1] - (w + slope * a),
            textbook: q * a.powi(4) / (8.0 * p.ei()),
            compression: -axial * a,
            a,
        });
        eprintln!(
            "g = {g:?}, beam {}: a = {a:.4} m, tip off the edge's tangent {:.6e} m, cantilever {:.6e} m",
            i + 1,
            out.last().unwrap().sag,
            out.last().unwrap().textbook
        );
    }
    out
}

#[test]
fn the_overhangs_sag_as_cantilevers() {
    // g / 100: the linear theory of the formula. At g the overhangs' axial weight (compressing
    // both loaded overhangs at this pose) softens them, a second-order effect the FEM has: the
    // sag grows by about P / (P_cr - P), P = p a, P_cr = 7.837 EI / a^2 (a cantilever buckling
    // under its own distributed axial load, Timoshenko & Gere 2.10), 0.6-0.9 % here
    let ei = RobotParams::paper().ei();
    for o in overhangs([0.0, -0.0981]) {
        let rel = (o.sag - o.textbook).abs() / o.textbook.abs();
        eprintln!("g / 100: departure {rel:.2e} of the sag");
        assert!(rel < 2e-4, "{rel:.2e} of q a^4 / (8 EI) at g / 100");
    }
    for o in overhangs(DOWN) {
        let rel = o.sag / o.textbook - 1.0;
        let p_cr = 7.837 * ei / (o.a * o.a);
        let estimate = o.compression / (p_cr - o.compression);
        eprintln!("g: sag {rel:.3e} above the linear formula, buckling estimate {estimate:.3e}");
        assert!(estimate > 1e-3, "the test wants compressed overhangs");
        assert!((rel / estimate - 1.0).abs() < 0.25, "{rel:.3e} against {estimate:.3e}");
    }
}

#[test]
fn stiff_limit_under_gravity_follows_the_rigid_inverse_dynamics() {
    // E x 1e4: practically rigid, so Fa must be the Newton-Euler inverse dynamics with the
    // weights of the star, the payload, sleeves and sliders (Eq. G3), whatever g's direction
    let mut robot = RobotParams::paper();
    robot.e *= 1e4;
    let settings = FemSettings {
        dt: Some(flexstar_fem::DEFAULT_DT),
        ..coarse()
    };
    let payload = Payload {
        mass: 0.3,
        j: 1e-3,
        offset: [0.02, -0.01],
    };
    for (g, with_payload) in [(DOWN, false), ([9.81, 0.0], true), ([-6.94, -6.94], false)] {
        let traj = catalogue::quintic_from_origin(catalogue::GENERAL_TARGET, 0.3);
        let mut exp = catalogue::experiment("stiff", robot, traj, 0.35, 1e-3);
        exp.gravity = Gravity::new(g);
        if with_payload {
            exp.payload = payload;
        }
        let r = fem(&exp, &settings, SolveRequest::motion());
        let attached = Attachments::of(&exp);
        let mut rigid = [vec![], vec![], vec![]];
        for &t in &r.t {
            let st = RigidState::at(&robot, &exp.trajectory, t).unwrap();
            let f = rigid_inverse_dynamics_with(&robot, &attached, &st);
            for i in 0..3 {
                rigid[i].push(f.fa[i]);
            }
        }
        let peak = rigid.iter().map(|f| max_abs(f)).fold(0.0, f64::max);
        for i in 0..3 {
            let err = r.fa[i]
                .iter()
                .zip(&rigid[i])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let num: f64 = r.fa[i].iter().zip(&rigid[i]).map(|(a, b)| (a - b).abs()).sum();
            let den: f64 = rigid[i].iter().map(|b| b.abs()).sum();
            let evp = num / den * 100.0;
            eprintln!(
                "g = {g:?}, payload {with_payload}: Fa{} largest difference {err:.2e} N ({:.3} % of {peak:.3} N), EVP {evp:.3} %",
                i + 1,
                err / peak * 100.0
            );
            assert!(
                err < 5e-3 * peak,
                "g = {g:?}: Fa{} off by {err} N (peak {peak} N)",
                i + 1
            );
            assert!(evp < 0.5, "g = {g:?}: Fa{} EVP {evp} %", i + 1);
        }
    }
}

/// Worst defect of Eq. C6 with the weights, `W + W_load - Delta(T + U + V_g) - E_d`, over the
/// output times, as a fraction of the largest work of the drivers.
fn energy_defect(r: &Response) -> f64 {
    let names = ["Ek_star", "Ek_sleeves", "Ek_sliders", "Ek_payload", "U", "V_g"];
    let e = |k: usize| names.iter().map(|c| col(r, c)[k]).sum::<f64>();
    let (w, ed) = (col(r, "W"), col(r, "E_d"));
    let scale = max_abs(w);
    let worst = (0..r.len())
        .map(|k| (w[k] - (e(k) - e(0)) - ed[k]).abs())
        .fold(0.0, f64::max);
    worst / scale
}

#[test]
fn energy_balance_with_the_weights() {
    // the paper's stiffness, the quintic with a payload and damping under an oblique g, inverse
    // and direct (the inverse run's forces fed back: open loop, the weights would otherwise pull
    // the robot off its path)
    let traj = catalogue::quintic_from_origin(catalogue::GENERAL_TARGET, 0.3);
    let mut exp = catalogue::experiment("energy", RobotParams::paper(), traj, 0.5, 5e-4);
    exp.gravity = Gravity::new([3.0, -9.81]);
    exp.payload = Payload {
        mass: 0.5,
        j: 2e-3,
        offset: [0.02, -0.01],
    };
    exp.damping = Damping::with_beta(2e-3);
    let inverse = fem(&exp, &coarse(), SolveRequest::motion());
    let rows = (0..inverse.len())
        .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
        .collect();
    let table = flexstar_drive::ForceTable::new(inverse.t.clone(), rows).unwrap();
    let direct = fem(&exp, &coarse(), SolveRequest::law(&table));
    let drift = (0..3)
        .map(|i| {
            let (a, b) = (
                col(&inverse, &format!("xp{}", i + 1)),
                col(&direct, &format!("xp{}", i + 1)),
            );
            a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    eprintln!("direct run off the inverse run's sleeves by {drift:.2e} m");
    let v_g = col(&inverse, "V_g");
    let change = v_g[v_g.len() - 1] - v_g[0];
    let (d_inv, d_dir) = (energy_defect(&inverse), energy_defect(&direct));
    eprintln!(
        "Eq. C6 with V_g: defect {d_inv:.2e} (inverse), {d_dir:.2e} (direct) of the work; Delta V_g {change:.3e} J, W {:.3e} J",
        col(&inverse, "W")[inverse.len() - 1]
    );
    assert!(
        change.abs() > 1e-2,
        "the weights must be a real part of the balance: {change} J"
    );
    assert!(d_inv < 1e-4, "inverse: Eq. C6 off by {d_inv:.2e} of the work");
    assert!(d_dir < 1e-4, "direct: Eq. C6 off by {d_dir:.2e} of the work");
}
