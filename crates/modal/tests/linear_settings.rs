//! Checks of the linear model's settings (`docs/modes.md`) (`--modes`, `--sliders`, the servo loop), each
//! against a reference independent of the model's assembly: the modal analysis of both solvers
//! (eigenvalues), the free-slider model with very heavy sliders (the locked model's base
//! excitation), the rigid robot's mass matrix with the PD gains (closed-loop poles in the stiff
//! limit) and the static limit of the servo loop.
// the 3 x 3 gain matrices are compared entry by entry, indexed as written in the docs
#![allow(clippy::needless_range_loop)]

use crate::rigid_forward;

use faer::linalg::solvers::Solve;
use flexstar_modal::analysis::modal;
use flexstar_modal::linear::{linearize, linearize_with, Holding, LinearSettings, StateSpace};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Experiment, RestPose, Sliders};

fn paper() -> Experiment {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
                s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n[amm]\nfamily = \"enriched\"\nmodes = 40\n";
    Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap()
}

fn pose(exp: &Experiment) -> RestPose {
    pose_from_task(&flexstar_modal::robot(exp).unwrap(), 0.03, -0.02, 0.1).unwrap()
}

fn to_faer(m: &sprs::CsMat<f64>) -> faer::Mat<f64> {
    let d = m.to_dense();
    faer::Mat::from_fn(m.rows(), m.cols(), |r, c| d[[r, c]])
}

fn build(exp: &Experiment, modes: usize, holding: Holding) -> StateSpace {
    linearize_with(
        exp,
        &pose(exp),
        &LinearSettings {
            modes,
            holding,
            ..Default::default()
        },
    )
    .unwrap()
}

/// `--modes K` and `--sliders`: 2 (rigid + K) states, and the eigenvalues of A are `+- i omega`
/// with omega = 2 pi f of `modal` (the same sliders setting, both solvers' analysis: the AMM to
/// 1e-9, the FEM, an independent model, within 1 % on the first six), plus the six zeros of the
/// rigid modes' Jordan blocks with free sliders.
#[test]
fn eigenvalues_of_a_are_the_modal_frequencies_for_each_sliders_setting() {
    let exp = paper();
    let k = 8;
    for (holding, sliders) in [(Holding::Locked, Sliders::Locked), (Holding::Free, Sliders::Free)] {
        let ss = build(&exp, k, holding);
        let rigid = if sliders == Sliders::Free { 3 } else { 0 };
        assert_eq!(ss.a.rows(), 2 * (rigid + k), "{sliders:?}");
        assert_eq!(ss.states.len(), ss.a.rows());
        assert_eq!(
            (ss.states[0].name.as_str(), ss.states[rigid + k].name.as_str()),
            ("eta1", "etad1")
        );
        let ev = to_faer(&ss.a).eigenvalues().unwrap();
        let wmax = ev.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
        let zero_tol = (f64::EPSILON * wmax * wmax).sqrt() * 10.0;
        let zeros = ev.iter().filter(|z| z.re.hypot(z.im) < zero_tol).count();
        assert_eq!(zeros, 2 * rigid, "{sliders:?}: {ev:?}");
        let mut w: Vec<f64> = ev.iter().filter(|z| z.im > zero_tol).map(|z| z.im).collect();
        w.sort_by(f64::total_cmp);
        assert_eq!(w.len(), k);
        let m = modal(&exp, &ss.pose, sliders, 6).unwrap();
        let two_pi = 2.0 * std::f64::consts::PI;
        for (j, (wj, (_, f_amm, f_fem, _))) in w.iter().zip(m.rows().iter().skip(rigid)).enumerate() {
            eprintln!(
                "{sliders:?} mode {}: A {} Hz, AMM {f_amm} Hz, FEM {f_fem} Hz",
                j + 1,
                wj / two_pi
            );
            assert!((wj / (two_pi * f_amm) - 1.0).abs() < 1e-9, "{sliders:?} mode {j}");
            assert!((wj / (two_pi * f_fem) - 1.0).abs() < 0.01, "{sliders:?} mode {j}");
        }
    }
}

/// Transfer matrix `C (p^2 + Omega^2)^-1 B` (+ D) of a model at a real Laplace point p.
fn gain_at(ss: &StateSpace, p: f64) -> Vec<Vec<f64>> {
    let (b, c, d) = (ss.b.to_dense(), ss.c.to_dense(), ss.d.to_dense());
    let nr = ss.a.rows() / 2;
    let a = to_faer(&ss.a);
    // (p I - A) x = B u, solved densely (no use of the modal structure)
    let n = 2 * nr;
    let m = faer::Mat::from_fn(n, n, |r, k| if r == k { p - a[(r, k)] } else { -a[(r, k)] });
    let rhs = faer::Mat::from_fn(n, b.ncols(), |r, k| b[[r, k]]);
    let x = m.partial_piv_lu().solve(&rhs);
    (0..c.nrows())
        .map(|o| {
            (0..b.ncols())
                .map(|u| (0..n).map(|j| c[[o, j]] * x[(j, u)]).sum::<f64>() + d[[o, u]])
                .collect()
        })
        .collect()
}

/// Locked sliders take the slider accelerations as inputs. Reference: the free-slider model
/// (forces as inputs, built from other modes: the sliders-free analysis) with sliders 1e6 times
/// heavier than the star, driven by `Fa = m a`: its sliders then follow `s'' = a` and its tips and
/// G deflect as on locked sliders moved with that acceleration, up to the star's mass over the
/// sliders' (1e-6). Compared at two real Laplace points (1 and 8 Hz), tips and G to each unit
/// acceleration: measured 6e-7 of the largest gain, tolerance 1e-5.
#[test]
fn locked_model_is_the_free_model_on_very_heavy_sliders() {
    let exp = paper();
    let locked = build(&exp, 12, Holding::Locked);
    assert_eq!(
        locked.inputs.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(),
        ["sdd1", "sdd2", "sdd3"]
    );
    let mut heavy = exp.clone();
    let m = 1e6 * heavy.robot.star_mass();
    heavy.robot.mpp_mpa = m;
    let free = build(&heavy, 12, Holding::Free);
    for f in [1.0, 8.0] {
        let p = 2.0 * std::f64::consts::PI * f;
        let (gl, gf) = (gain_at(&locked, p), gain_at(&free, p));
        let scale = gl.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(scale > 1e-6, "{scale}");
        for (o, name) in locked.outputs.iter().enumerate() {
            // the free model's outputs are s1..s3 then the same six deflections
            assert_eq!(free.outputs[3 + o].name, name.name);
            for u in 0..3 {
                let (a, b) = (gl[o][u], gf[3 + o][u] * m);
                eprintln!(
                    "{f} Hz {} / sdd{}: locked {a:.6e}, heavy free {b:.6e}",
                    name.name,
                    u + 1
                );
                assert!(
                    (a - b).abs() < 1e-5 * scale,
                    "{f} Hz {}/sdd{}: {a} vs {b}",
                    name.name,
                    u + 1
                );
            }
        }
        // and the heavy sliders do follow s'' = a: s / a = 1 / p^2
        for i in 0..3 {
            for u in 0..3 {
                let want = if i == u { 1.0 / (p * p) } else { 0.0 };
                assert!((gf[i][u] * m - want).abs() < 1e-5 / (p * p), "s{} / a{}", i + 1, u + 1);
            }
        }
    }
}

/// The servo loop in the stiff limit (E x 1e4: first elastic mode ~100 times above the loop):
/// the six slowest poles of the closed-loop A are those of the rigid robot held by the PD servo,
/// `det(p^2 M_r + kd p + kp) = 0`, i.e. `mu p^2 + kd p + kp = 0` for each eigenvalue mu of the rigid
/// mass matrix M_r (the inverse of `rigid_forward::rigid_acceleration`'s, exact
/// Fermat-point Jacobians, no modes). Measured: 1e-4 relative (the elastic modes' coupling),
/// tolerance 1e-3. The rest of the spectrum is stable.
#[test]
fn servo_poles_in_the_stiff_limit_are_the_rigid_robots() {
    let mut exp = paper();
    exp.robot.e *= 1e4;
    let (kp, kd) = (
        0.2 * (2.0 * std::f64::consts::PI * 20.0f64).powi(2),
        2.0 * 0.7 * 0.2 * 2.0 * std::f64::consts::PI * 20.0,
    );
    let ss = build(&exp, 8, Holding::Servo { kp, kd });
    let mut ev: Vec<faer::c64> = to_faer(&ss.a).eigenvalues().unwrap();
    assert!(ev.iter().all(|z| z.re < 0.0), "closed loop is stable: {ev:?}");
    ev.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    // M_r^-1 column by column, then its eigenvalues 1/mu
    let inv: Vec<[f64; 3]> = (0..3)
        .map(|k| {
            let mut fa = [0.0; 3];
            fa[k] = 1.0;
            rigid_forward::rigid_acceleration(&exp.robot, ss.pose.s, [0.0; 3], fa).unwrap()
        })
        .collect();
    let minv = faer::Mat::from_fn(3, 3, |r, k| 0.5 * (inv[k][r] + inv[r][k]));
    let mut want: Vec<faer::c64> = Vec::new();
    for l in minv.self_adjoint_eigenvalues(faer::Side::Lower).unwrap() {
        let mu = 1.0 / l;
        let disc = faer::c64::new(kd * kd - 4.0 * mu * kp, 0.0).sqrt();
        for sign in [1.0, -1.0] {
            want.push((faer::c64::new(-kd, 0.0) + disc * sign) / (2.0 * mu));
        }
    }
    want.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    let mut slow: Vec<faer::c64> = ev[..6].to_vec();
    let key = |z: &faer::c64| (z.norm() * 1e6).round() + z.im.signum() * 0.25;
    slow.sort_by(|a, b| key(a).total_cmp(&key(b)));
    want.sort_by(|a, b| key(a).total_cmp(&key(b)));
    for (z, w) in slow.iter().zip(&want) {
        eprintln!("pole {z:?}, rigid robot {w:?}");
        assert!((z - w).norm() < 1e-3 * w.norm(), "{z:?} vs {w:?}");
    }
    assert!(
        ev[6].norm() > 20.0 * want[5].norm(),
        "elastic poles well above: {:?}",
        ev[6]
    );
}

/// The servo model's static limit, an exact property of the loop: a constant reference moves
/// the star rigidly, so s = s_ref, the tracking errors and the deflections vanish (DC gain from
/// `s_ref` = identity on s1..s3, zero elsewhere). Checked on the paper robot (E as given) with
/// the gains of a 20 Hz servo from `[drive]`.
#[test]
fn servo_tracks_a_constant_reference_exactly() {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n\
                [amm]\nfamily = \"enriched\"\nmodes = 40\n[drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n";
    let exp = Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap();
    let holding = Holding::servo_of(&exp).unwrap();
    let ss = build(&exp, 10, holding);
    let names: Vec<&str> = ss.inputs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["s1ref", "s2ref", "s3ref", "sd1ref", "sd2ref", "sd3ref", "ff1", "ff2", "ff3"]
    );
    let outs: Vec<&str> = ss.outputs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(outs[9..], ["e1", "e2", "e3"]);
    let g = gain_at(&ss, 0.0);
    // measured: 3.2e-8 on the tips (the rigid modes' round-off), 1e-15 on s1..s3
    let mut worst = 0.0f64;
    for (o, name) in outs.iter().enumerate() {
        for u in 0..3 {
            let want = if o < 3 && o == u { 1.0 } else { 0.0 };
            worst = worst.max((g[o][u] - want).abs());
            assert!((g[o][u] - want).abs() < 1e-6, "{name} / s{}ref: {}", u + 1, g[o][u]);
        }
    }
    eprintln!("largest DC-gain defect {worst:e}");
    // the open-loop model is unchanged by the settings' default
    let open = linearize(&exp, &ss.pose).unwrap();
    assert_eq!(open.inputs[0].name, "Fa1");
    let plain = paper();
    assert!(Holding::servo_of(&plain).unwrap_err().to_string().contains("servo"));
}
