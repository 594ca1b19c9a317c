//! The linear systems of a robot whose sleeves stick (`docs/modes.md`, stuck sleeves: Eqs. S1-S3),
//! each against a reference independent of the code under test: the other solver (the AMM's
//! stick springs of Eq. S1 against the FEM's held contact coordinate of Eq. S2), Rayleigh's
//! theorem on an added constraint (mode by mode against the sliding system), and the clamped
//! cantilever of an overhang.

use flexstar_modal::analysis::{modal, modal_held, Modal};
use flexstar_modal::linear::{linearize_with, Holding, LinearSettings};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Experiment, RestPose, Sleeves, Sliders};

const MOTION: &str = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
                      s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";

fn experiment(extra: &str) -> Experiment {
    Experiment::from_toml_str(&format!("{MOTION}{extra}"), std::path::Path::new("t.toml")).unwrap()
}

fn pose(exp: &Experiment, [gx, gy, th]: [f64; 3]) -> RestPose {
    pose_from_task(&flexstar_modal::robot(exp).unwrap(), gx, gy, th).unwrap()
}

/// Two off-centre turned poses of the paper's robot (no symmetry to hide an error).
const POSES: [[f64; 3]; 2] = [[0.03, -0.02, 0.1], [-0.06, 0.04, -0.12]];

/// AMM (enriched, N = 60, the stick springs `EA / xp` of Eq. S1) against the FEM (300 elements,
/// axially elastic beams, `xi_c` held: Eq. S2), sleeves stuck, sliders locked and free: the first
/// six frequencies within 1 % (the tolerance of the sliding systems in `modal_checks.rs`).
#[test]
fn stuck_modes_of_the_amm_and_the_fem_agree() {
    let exp = experiment("");
    for p in POSES {
        let pose = pose(&exp, p);
        for sliders in [Sliders::Locked, Sliders::Free] {
            let m = modal_held(&exp, &pose, sliders, Sleeves::Stuck, 6).unwrap();
            assert_eq!((m.amm.rigid, m.fem.rigid), (0, 0), "stuck sleeves leave no rigid mode");
            for (mode, a, f, rel) in m.rows() {
                eprintln!(
                    "{p:?} {sliders:?} stuck mode {mode}: AMM {a:.5} Hz, FEM {f:.5} Hz, {:+.4} %",
                    100.0 * rel
                );
                assert!(
                    rel.abs() < 0.01,
                    "{p:?} {sliders:?} mode {mode}: AMM {a} Hz against FEM {f} Hz"
                );
            }
        }
    }
}

/// Rayleigh's theorem (Courant-Fischer): a constraint added (the FEM's row of Eq. S2) or a
/// stiffness added (the AMM's spring of Eq. S1, positive semi-definite) raises every eigenvalue,
/// `omega_k(stuck) >= omega_k(sliding)` mode by mode, the sliding system's rigid zeros included.
/// Checked in each solver at both poses and both holdings, to 1e-9 relative (round-off of the
/// eigensolvers); the stuck system also changes the spectrum (some mode moves by > 1 %).
#[test]
fn stuck_frequencies_are_at_least_the_sliding_ones_mode_by_mode() {
    let exp = experiment("");
    for p in POSES {
        let pose = pose(&exp, p);
        for sliders in [Sliders::Locked, Sliders::Free] {
            let sliding = modal(&exp, &pose, sliders, 9).unwrap();
            let stuck = modal_held(&exp, &pose, sliders, Sleeves::Stuck, 12).unwrap();
            for (name, a, b) in [
                ("AMM", &sliding.amm.freq_hz, &stuck.amm.freq_hz),
                ("FEM", &sliding.fem.freq_hz, &stuck.fem.freq_hz),
            ] {
                let mut moved: f64 = 0.0;
                for (k, (fs, fk)) in a.iter().zip(b).enumerate().take(12) {
                    eprintln!(
                        "{p:?} {sliders:?} {name} mode {}: sliding {fs:.5} Hz, stuck {fk:.5} Hz",
                        k + 1
                    );
                    assert!(
                        *fk >= fs * (1.0 - 1e-9),
                        "{name} {p:?} {sliders:?} mode {}: stuck {fk} < sliding {fs}",
                        k + 1
                    );
                    if *fs > 0.0 {
                        moved = moved.max(fk / fs - 1.0);
                    }
                }
                assert!(
                    moved > 0.01,
                    "{name} {p:?} {sliders:?}: sticking changed no mode by 1 % ({moved})"
                );
            }
        }
    }
}

/// A stuck sleeve's overhang against the clamped cantilever `f = (1.875^2 / (2 pi a^2)) sqrt(EI /
/// rho)`, `a = L - xp - Lp / 2` (the set-up of the FEM's time-domain check in
/// `crates/fem/tests/friction.rs`): a small base (d = 0.03 m) puts the sleeves 0.03 m from G, so the
/// short inner spans are far stiffer than the 0.455 m overhangs, and the first three modes of the
/// stuck star are the three overhangs' first modes. The sleeve's rotation is held by the short
/// span, which lowers the frequency by about `(1 + 3 xp / (4 a))^(-1/2)` = 0.976 (a cantilever on
/// the rotational spring `4 EI / xp`; G's own rotation and the sleeve's inertia change it
/// somewhat): each solver's f1..f3 within 5 % of the clamped cantilever and below it, and within
/// 1.5 % of the spring-corrected estimate (the FEM's time-domain check measured 0.973 and 0.997).
#[test]
fn a_stuck_overhang_is_a_clamped_cantilever() {
    let exp = experiment("[robot]\nd = 0.03\n");
    let pose = pose(&exp, [0.0, 0.0, 0.0]);
    let m: Modal = modal_held(&exp, &pose, Sliders::Locked, Sleeves::Stuck, 4).unwrap();
    let r = exp.robot;
    let xp = pose.xp[0];
    let a = r.l - xp - 0.5 * r.lp;
    let f_clamped = 1.875_104_068_711_961f64.powi(2) / (a * a) * (r.ei() / r.rho).sqrt() / (2.0 * std::f64::consts::PI);
    let spring = (1.0 + 3.0 * xp / (4.0 * a)).powf(-0.5);
    for (mode, fa, ff, _) in m.rows().into_iter().take(3) {
        for (name, f) in [("AMM", fa), ("FEM", ff)] {
            let ratio = f / f_clamped;
            eprintln!(
                "mode {mode} {name}: {f:.5} Hz, clamped cantilever {f_clamped:.5} Hz (a = {a:.4} m), ratio {ratio:.4}, to the spring-corrected {:.4}",
                ratio / spring
            );
            assert!(
                (0.95..=1.0).contains(&ratio),
                "mode {mode} {name}: {ratio} of the clamped cantilever"
            );
            assert!(
                (ratio / spring - 1.0).abs() < 0.015,
                "mode {mode} {name}: {} of the estimate",
                ratio / spring
            );
        }
    }
}

/// The linear model with stuck sleeves (free sliders, open loop): the eigenvalues of A are the
/// stuck modes' `+-i omega` (its frequencies are the FEM's within 1 %, the first test); locked
/// sliders with stuck sleeves are refused, naming the flags.
#[test]
fn linearize_takes_stuck_sleeves_with_free_sliders() {
    let exp = experiment("");
    let pose = pose(&exp, POSES[0]);
    let settings = LinearSettings {
        modes: 6,
        holding: Holding::Free,
        sleeves: Sleeves::Stuck,
    };
    let ss = linearize_with(&exp, &pose, &settings).unwrap();
    let fem = modal_held(&exp, &pose, Sliders::Free, Sleeves::Stuck, 6)
        .unwrap()
        .fem
        .freq_hz;
    assert_eq!(ss.modes.rigid, 0);
    assert_eq!(ss.a.rows(), 12);
    let a = ss.a.to_dense();
    // A = [0 I; -Omega^2 0] without damping: omega_k^2 = -A[6 + k][k]
    for k in 0..6 {
        let f = (-a[[6 + k, k]]).sqrt() / (2.0 * std::f64::consts::PI);
        eprintln!("linear stuck mode {}: {f:.5} Hz, FEM {:.5} Hz", k + 1, fem[k]);
        assert!((f / fem[k] - 1.0).abs() < 0.01);
    }
    let locked = LinearSettings {
        holding: Holding::Locked,
        ..settings
    };
    let Err(e) = linearize_with(&exp, &pose, &locked) else {
        panic!("stuck sleeves with locked sliders must be refused")
    };
    let e = e.to_string();
    assert!(e.contains("--sleeves stuck") && e.contains("--sliders"), "{e}");
}
