//! Payload, damping and load at a pose: the payload, the damping and the load in the modal analysis and the linear
//! model, against references independent of both solvers' assembly (docs/amm.md 11.5, Eqs.
//! C1-C4; docs/modes.md, Eqs. D11-D13, L4).

// its saddle-point matrix only
#[allow(dead_code)]
use crate::inertia_relief;

use flexstar_modal::analysis::{amm_pose_model, fem_pose_modes, modal};
use flexstar_modal::linear::{linearize_with, Holding, LinearSettings};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Damping, Experiment, LoadSettings, Payload, Sliders};

fn paper() -> Experiment {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
    Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap()
}

/// Eqs. C1-C4 of docs/amm.md 11.5: the payload on three elastic supports at the centre pose
/// (xp = d), each beam guided at G (translation) or held at G (rotation), pinned at its sleeve;
/// the beams' participating mass by Rayleigh's quotient. Returns `(f_trans, f_rot)` [Hz] for a
/// payload of mass `m` [kg] and inertia `j` [kg m^2].
fn supported_payload_frequencies(exp: &Experiment, m: f64, j: f64) -> (f64, f64) {
    let p = &exp.robot;
    let (ei, rho, l, lp, jp, xp) = (p.ei(), p.rho, p.l, p.lp, p.jp, p.d);
    let den = xp.powi(3) - lp.powi(3) / 32.0;
    let (k, k_t) = (3.0 * ei / den, 3.0 * ei * xp * xp / den);
    let overhang = rho * (l - xp).powi(3) / 3.0 + jp;
    let m_b = 1.5 * (rho * l + 17.0 / 35.0 * rho * xp + overhang * 9.0 / (4.0 * xp * xp));
    let j_b = 3.0 * (2.0 / 105.0 * rho * xp.powi(3) + overhang / 4.0);
    let two_pi = 2.0 * std::f64::consts::PI;
    (
        (1.5 * k / (m + m_b)).sqrt() / two_pi,
        (3.0 * k_t / (j + j_b)).sqrt() / two_pi,
    )
}

/// A heavy payload at G, sliders locked, centre pose: the translational pair and the rotation
/// against Eqs. C3-C4 within 1 % (`docs/amm.md` 11.5), for both the AMM (enriched, N = 60) and the FEM
/// (300 elements). The references were confirmed on a one-beam Hermite model to 2e-4
/// (docs/derivations/payload_supports.py). Measured: AMM +1.6e-5 (pair) and +2.8e-5 (rotation),
/// FEM +7e-6 and +8e-6.
#[test]
fn heavy_payload_frequencies_match_the_elastic_supports() {
    let pose = pose_from_task(&flexstar_modal::robot(&paper()).unwrap(), 0.0, 0.0, 0.0).unwrap();
    for (m, j) in [(100.0, 0.0), (0.0, 1.0)] {
        let mut exp = paper();
        exp.payload = Payload {
            mass: m,
            j,
            offset: [0.0, 0.0],
        };
        let (f_trans, f_rot) = supported_payload_frequencies(&exp, m, j);
        let amm = amm_pose_model(&exp)
            .unwrap()
            .modes_at(&pose, Sliders::Locked, 3)
            .unwrap();
        let fem = fem_pose_modes(&exp, &pose, Sliders::Locked, 3).unwrap();
        for (name, f) in [("AMM", &amm.freq_hz), ("FEM", &fem.freq_hz)] {
            let rel = |got: f64, want: f64| (got / want - 1.0).abs();
            if m > 0.0 {
                // the pair of translations is the first two modes
                for (k, got) in f[..2].iter().enumerate() {
                    eprintln!("{name} m = {m} kg: f{} = {got} Hz, Eq. C3-C4 {f_trans} Hz", k + 1);
                    assert!(rel(*got, f_trans) < 0.01, "{name} f{}: {got} vs {f_trans}", k + 1);
                }
            } else {
                eprintln!("{name} J = {j} kg m^2: f1 = {} Hz, Eq. C3-C4 {f_rot} Hz", f[0]);
                assert!(rel(f[0], f_rot) < 0.01, "{name} f1: {} vs {f_rot}", f[0]);
            }
        }
    }
}

/// With the payload off G, the AMM and the FEM still agree (the payload's mass matrix about G,
/// Eq. P2 on the junction rows against Eq. P11 on node G): first four locked modes within 1 % at
/// an off-centre turned pose (measured: 2.2e-4 at most; the bare robot's are 10-28 % higher).
#[test]
fn an_offset_payload_moves_both_models_alike() {
    let mut exp = paper();
    exp.payload = Payload {
        mass: 0.5,
        j: 2e-3,
        offset: [0.04, -0.03],
    };
    let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.03, -0.02, 0.1).unwrap();
    let both = modal(&exp, &pose, Sliders::Locked, 4).unwrap();
    let bare = modal(&paper(), &pose, Sliders::Locked, 4).unwrap();
    for ((_, a, f, rel), (_, a0, _, _)) in both.rows().into_iter().zip(bare.rows()) {
        eprintln!("AMM {a} Hz, FEM {f} Hz ({rel:+.2e}); bare AMM {a0} Hz");
        assert!(rel.abs() < 0.01, "AMM {a} vs FEM {f}");
        assert!(a < a0 * 0.99, "the payload must lower the frequency: {a} vs bare {a0}");
    }
}

/// Eq. D13: with Kelvin-Voigt damping the eigenvalues of A (faer's general eigensolver) are
/// `-zeta_k omega_k +- i omega_k sqrt(1 - zeta_k^2)` with `zeta_k = beta omega_k / 2` (Eq. D12)
/// of the undamped modal frequencies, the same ratios `modal.csv` reports (Eq. D11); the rigid
/// modes (free sliders) stay at 0: a rigid motion is not damped.
#[test]
fn damped_poles_leave_the_imaginary_axis_by_zeta_omega() {
    let mut exp = paper();
    exp.damping = Damping {
        zeta: Some(flexstar_model::ModeValues::One(0.02)),
        f_hz: Some(flexstar_model::ModeValues::One(4.0)),
        ..Damping::default()
    };
    let beta = exp.damping.beta();
    let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.03, -0.02, 0.1).unwrap();
    let settings = LinearSettings {
        modes: 8,
        holding: Holding::Free,
        ..Default::default()
    };
    let ss = linearize_with(&exp, &pose, &settings).unwrap();
    let d = ss.a.to_dense();
    let a = faer::Mat::from_fn(d.nrows(), d.ncols(), |r, c| d[[r, c]]);
    let ev = a.eigenvalues().unwrap();
    let two_pi = 2.0 * std::f64::consts::PI;
    let wmax = ss.modes.freq_hz.iter().fold(0.0f64, |m, f| m.max(two_pi * f));
    let zero_tol = (f64::EPSILON * wmax * wmax).sqrt() * 10.0;
    assert_eq!(ev.iter().filter(|z| z.norm() < zero_tol).count(), 6, "{ev:?}");
    for f in &ss.modes.freq_hz[3..] {
        let w = two_pi * f;
        let zeta = beta * w / 2.0;
        assert!(zeta < 1.0, "mode at {f} Hz overdamped");
        let pole = (-zeta * w, w * (1.0 - zeta * zeta).sqrt());
        let found = ev
            .iter()
            .any(|z| (z.re - pole.0).abs() < 1e-7 * w && (z.im - pole.1).abs() < 1e-7 * w);
        assert!(found, "pole {pole:?} of {f} Hz (zeta {zeta}) not among {ev:?}");
    }
    // modal.csv's ratios: beta omega / 2 of each model's own frequency, 2 % at 4 Hz
    let m = modal(&exp, &pose, Sliders::Locked, 3).unwrap();
    for ((_, fa, ff, _), (za, zf)) in m.rows().into_iter().zip(m.damping_ratios().unwrap()) {
        assert!((za - 0.02 * fa / 4.0).abs() < 1e-12 && (zf - 0.02 * ff / 4.0).abs() < 1e-12);
    }
    assert!(modal(&paper(), &pose, Sliders::Locked, 3)
        .unwrap()
        .damping_ratios()
        .is_none());
}

/// Eqs. D13-D15: Rayleigh damping fitted to two ratios. With the sliders locked the eigenvalues
/// of A (faer's general eigensolver) are `-zeta_k omega_k +- i omega_k sqrt(1 - zeta_k^2)` with
/// `zeta_k = alpha / (2 omega_k) + beta omega_k / 2` of every mode, and the fitted law gives back
/// the two ratios at their frequencies; with the sliders free the mass-proportional part acts on
/// the elastic coordinates only, so the six rigid eigenvalues stay at 0.
#[test]
fn rayleigh_poles_follow_the_two_ratio_law() {
    let mut exp = paper();
    exp.damping = Damping {
        zeta: Some(flexstar_model::ModeValues::Two([0.02, 0.015])),
        f_hz: Some(flexstar_model::ModeValues::Two([4.0, 9.0])),
        ..Damping::default()
    };
    let (alpha, beta) = exp.damping.coefficients();
    assert!(alpha > 0.0 && beta > 0.0);
    let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.03, -0.02, 0.1).unwrap();
    let two_pi = 2.0 * std::f64::consts::PI;
    let eigen = |holding| {
        let ss = linearize_with(
            &exp,
            &pose,
            &LinearSettings {
                modes: 8,
                holding,
                ..Default::default()
            },
        )
        .unwrap();
        let d = ss.a.to_dense();
        let a = faer::Mat::from_fn(d.nrows(), d.ncols(), |r, c| d[[r, c]]);
        (a.eigenvalues().unwrap(), ss)
    };
    let (ev, ss) = eigen(Holding::Locked);
    for (f, z) in ss.modes.freq_hz.iter().zip(&ss.damping_ratios) {
        let w = two_pi * f;
        let zeta = alpha / (2.0 * w) + beta * w / 2.0;
        assert!(
            (z - zeta).abs() < 1e-9 * zeta,
            "statespace.json's ratio {z} vs the law {zeta}"
        );
        let pole = (-zeta * w, w * (1.0 - zeta * zeta).sqrt());
        let found = ev
            .iter()
            .any(|z| (z.re - pole.0).abs() < 1e-7 * w && (z.im - pole.1).abs() < 1e-7 * w);
        assert!(found, "pole {pole:?} of {f} Hz (zeta {zeta}) not among {ev:?}");
    }
    assert!((exp.damping.zeta_at(4.0) - 0.02).abs() < 1e-12 && (exp.damping.zeta_at(9.0) - 0.015).abs() < 1e-12);
    let (ev, ss) = eigen(Holding::Free);
    let wmax = ss.modes.freq_hz.iter().fold(0.0f64, |m, f| m.max(two_pi * f));
    let zero_tol = (f64::EPSILON * wmax * wmax).sqrt() * 10.0;
    assert_eq!(ev.iter().filter(|z| z.norm() < zero_tol).count(), 6, "{ev:?}");
}

/// Eq. L4: the load channel's static gain (sliders locked, `sum_k C_k B_k / omega_k^2`) against
/// the FEM's static deflection under a unit force and moment at G (150 elements, the saddle-point
/// system of K and the sleeves' rows solved directly): G's deflection along each `e_wi` and the
/// tips', per unit Fx, Fy, Mz. Measured with K = 40 locked modes: 2.6e-6 m/N at worst of
/// 1.2e-2 (2e-4 of the largest gain).
#[test]
fn load_channel_static_gain_matches_the_fem_static_deflection() {
    use faer::linalg::solvers::Solve;
    let mut exp = paper();
    exp.load = LoadSettings::polynomials(Some(vec![0.0]), None, None);
    let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.03, -0.02, 0.1).unwrap();
    let settings = LinearSettings {
        modes: 40,
        holding: Holding::Locked,
        ..Default::default()
    };
    let ss = linearize_with(&exp, &pose, &settings).unwrap();
    let names: Vec<&str> = ss.inputs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["sdd1", "sdd2", "sdd3", "Fx", "Fy", "Mz"]);
    let (a, b, c) = (ss.a.to_dense(), ss.b.to_dense(), ss.c.to_dense());
    let nr = ss.a.rows() / 2;
    let gain = |r: usize, k: usize| -> f64 { (0..nr).map(|j| c[[r, j]] * b[[nr + j, k]] / -a[[nr + j, j]]).sum() };
    let sys = flexstar_fem::pose_modes::pose_system(&exp.robot, &pose, Sliders::Locked, 150).unwrap();
    let (n, rows) = (sys.n, sys.rows);
    let size = n + rows;
    let kkt = inertia_relief::saddle_matrix(&sys, 0);
    let lu = kkt.partial_piv_lu();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for k in 0..3 {
        // node G's (x, y, phi) are the FEM's first three coordinates
        let mut rhs = faer::Mat::<f64>::zeros(size, 1);
        rhs[(k, 0)] = 1.0;
        lu.solve_in_place(rhs.as_mut());
        let u: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
        for i in 0..3 {
            let w = sys.deflections(&u, i);
            for (row, fem_v) in [(i, w[sys.ne]), (3 + i, w[0])] {
                let lin = gain(row, 3 + k);
                eprintln!("{} -> output {row}: linear {lin:.6e}, FEM {fem_v:.6e}", names[3 + k]);
                worst = worst.max((lin - fem_v).abs());
                scale = scale.max(fem_v.abs());
            }
        }
    }
    assert!(scale > 0.0);
    assert!(worst < 2e-3 * scale, "largest difference {worst:e} of {scale:e}");
}
