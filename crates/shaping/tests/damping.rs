//! `[damping] zeta` without `f_hz` (`docs/usage.md`, damping): the explicit step sets `f_hz` to the
//! robot's first frequency at the start pose, and a free decay shows the damping law it gives.

use flexstar_model::{AmmSettings, Experiment};

const MOVE: &str = "name = \"damped\"\n[time]\nt_end = 3.0\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
                    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.03, Gy = -0.02, theta = 0.2 }\n\
                    t0 = 0.0\nt1 = 0.42\n[damping]\nzeta = 0.015\n";

/// Loading keeps the zeta pending (reading never runs a solver) and a problem is not built from
/// it; the step resolves it to the first frequency at the start pose. Then the free decay after
/// the move: |dG| of the accurate AMM decays at a rate between those of the two first modes at
/// the final pose under the resolved Kelvin-Voigt law, `zeta_k omega_k = beta omega_k^2 / 2` with
/// `beta = zeta / (pi f_hz)` (a measurement of the run against the law, within 5 %).
#[test]
fn zeta_alone_holds_at_the_first_frequency_and_the_run_decays_by_it() {
    let mut exp = Experiment::from_toml_str(MOVE, std::path::Path::new("damped.toml")).unwrap();
    assert!(exp.damping.pending());
    let e = exp.problem().unwrap_err().to_string();
    assert!(e.contains("damping.f_hz"), "{e}");
    flexstar_shaping::shape(&mut exp).unwrap();
    let f_start = flexstar_modal::analysis::start_pose_frequencies(&exp, 1).unwrap()[0];
    assert_eq!(exp.damping.f_hz, Some(flexstar_model::ModeValues::One(f_start)));
    assert!((exp.damping.zeta_at(f_start) - 0.015).abs() < 1e-15);

    let problem = exp.problem().unwrap();
    let r = flexstar_solve::response(
        &problem,
        flexstar_solve::Settings::Amm(&AmmSettings::accurate()),
        None,
        None,
    )
    .unwrap();
    let res = flexstar_modal::settle::run_residual(&exp, &r)
        .unwrap()
        .expect("the move rests");
    let decay = res.decay_per_s.expect("a measured decay");
    let f = flexstar_modal::analysis::final_pose_frequencies(&exp, 2)
        .unwrap()
        .unwrap();
    let rate = |f: f64| exp.damping.beta() * (2.0 * std::f64::consts::PI * f).powi(2) / 2.0;
    let (lo, hi) = (rate(f[0]), rate(f[1]));
    eprintln!(
        "decay {decay:.4} 1/s, modes 1-2 at the final pose {:.3}/{:.3} Hz: {lo:.4}..{hi:.4} 1/s",
        f[0], f[1]
    );
    assert!(
        decay > 0.95 * lo && decay < 1.05 * hi,
        "decay {decay} outside [{lo}, {hi}]"
    );
}

/// A ratio of critical damping or more is refused when the file is read.
#[test]
fn a_ratio_of_one_or_more_is_refused() {
    let text = MOVE.replace("zeta = 0.015", "zeta = 1.2");
    let e = Experiment::from_toml_str(&text, std::path::Path::new("damped.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("damping.zeta"), "{e}");
}

/// `zeta = [z1, z2]` without `f_hz` holds at the first two distinct frequencies at the start
/// pose (the modal analysis computed apart here: the centre pose of the symmetric star has a
/// double first frequency), through the Rayleigh fit of Eq. D15; `alpha` alone is
/// checked against mode 1's critical damping at the start pose (`alpha < 2 omega_1`).
#[test]
fn two_ratios_hold_at_the_first_two_frequencies() {
    let text = MOVE.replace("zeta = 0.015", "zeta = [0.015, 0.02]");
    let mut exp = Experiment::from_toml_str(&text, std::path::Path::new("damped.toml")).unwrap();
    assert!(exp.damping.pending());
    flexstar_shaping::shape(&mut exp).unwrap();
    let f = flexstar_modal::analysis::start_pose_frequencies(&exp, 6).unwrap();
    assert!((f[1] / f[0] - 1.0).abs() < 1e-6, "a double first frequency: {f:?}");
    let f2 = f[2..].iter().copied().find(|x| *x > 1.05 * f[0]).unwrap();
    assert_eq!(exp.damping.f_hz, Some(flexstar_model::ModeValues::Two([f[0], f2])));
    assert!((exp.damping.zeta_at(f[0]) - 0.015).abs() < 1e-12);
    assert!((exp.damping.zeta_at(f2) - 0.02).abs() < 1e-12);
    exp.problem().unwrap();

    let w1 = 2.0 * std::f64::consts::PI * f[0];
    for (alpha, ok) in [(1.9 * w1, true), (2.1 * w1, false)] {
        let text = MOVE.replace("zeta = 0.015", &format!("alpha = {alpha}"));
        let mut exp = Experiment::from_toml_str(&text, std::path::Path::new("damped.toml")).unwrap();
        let r = flexstar_shaping::shape(&mut exp);
        assert_eq!(r.is_ok(), ok, "alpha = {alpha}: {r:?}");
        if let Err(e) = r {
            assert!(
                e.to_string().contains("damping.alpha") && e.to_string().contains("mode 1"),
                "{e}"
            );
        }
    }
}
