//! Payload, damping and load across the solvers: the accurate AMM against the independent FEM on
//! three motions of `configs/motions/`: the smooth quintic with a payload off G, the brisk quintic
//! with its residual vibration under Kelvin-Voigt damping, the pick-and-place cycle (via points, a
//! dwell) with a load at G, and the brisk one with all three (the targets of `docs/amm.md` 11.5:
//! mean EVP over A, B, C, G at most 0.5 %, no point above 1 %). The command line's handling of the
//! three sections is checked in `tests/attachments.rs`.
//!
//! Measured (N = 53 each): payload on smooth, mean 0.130 % (largest point 0.184 %); damping on
//! brisk, 0.163 % (0.180 %); load on pick-place, 0.430 % (0.783 % at tip C, the cycle's own
//! level: 1.5 s with two stops); all three on brisk, 0.111 % (0.137 %); Rayleigh damping
//! (`zeta = [0.02, 0.03]` at 4 and 12 Hz, so alpha and beta both act) on brisk, 0.076 % (0.168 %
//! at G).

use crate::models;

const SMOOTH: &str = include_str!("../configs/motions/smooth.toml");
const BRISK: &str = include_str!("../configs/motions/brisk.toml");
const PICK_PLACE: &str = include_str!("../configs/motions/pick-place.toml");

const PAYLOAD: &str = "[payload]\nmass = 0.1\nJ = 2e-4\noffset = [0.01, 0.005]\n";
const DAMPING: &str = "[damping]\nzeta = 0.02\nf_hz = 4.0\n";
/// Rayleigh damping fitted to two ratios (docs/amm.md 11.2.1): its mass-proportional part acts
/// on the motion relative to the rigid robot in both models, each by its own construction.
const RAYLEIGH: &str = "[damping]\nzeta = [0.02, 0.03]\nf_hz = [4.0, 12.0]\n";
const LOAD: &str = "[load]\nFx = [0.0, 2.0]\nFy = [0.0, -1.0]\nMz = [0.0, 0.0, 0.5]\n";

/// The accurate AMM against the FEM on the motion `base` with `sections` (docs/amm.md 11.5's
/// targets).
fn check(base: &str, name: &str, sections: &str) {
    models::amm_against_fem(&models::experiment(base, sections, "attached.toml"), name).assert_within(name, 0.5, 1.0);
}

#[test]
fn amm_agrees_with_fem_with_a_payload() {
    check(SMOOTH, "payload", PAYLOAD);
}

#[test]
fn amm_agrees_with_fem_with_damping() {
    check(BRISK, "damping", DAMPING);
}

#[test]
fn amm_agrees_with_fem_with_rayleigh_damping() {
    check(BRISK, "rayleigh", RAYLEIGH);
}

#[test]
fn amm_agrees_with_fem_with_a_load() {
    check(PICK_PLACE, "load", LOAD);
}

#[test]
fn amm_agrees_with_fem_with_payload_damping_and_load() {
    check(BRISK, "all", &format!("{PAYLOAD}{DAMPING}{LOAD}"));
}

/// Gravity (`docs/as-built.md` 5, `docs/fem.md` 9.5): the static sag of the paper's robot held at
/// the centre pose under `g = [0, -9.81]`, each model started in its own static equilibrium (the
/// AMM by its step's refinement, the FEM by Newton), and held there: G and the tips of the two
/// solvers within 5e-3 (measured 4.7e-4 at G, 3.4e-4 at the tips, 1.778 mm at G).
#[test]
fn amm_and_fem_sag_alike_under_gravity() {
    let exp = models::experiment(
        "name = \"sag\"\n[time]\nt_end = 0.05\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
         s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]",
        "[gravity]\ng = [0.0, -9.81]\n",
        "sag.toml",
    );
    let (amm, fem) = models::solve_both(&exp);
    let dgy = |r: &flexstar_model::Response| r.column("dGy").expect("dGy")[0];
    let rel = (dgy(&fem) - dgy(&amm)).abs() / dgy(&amm).abs();
    let tip = |r: &flexstar_model::Response| [0, 1, 2].map(|i| r.w_tip[i][0]);
    let largest = tip(&amm).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tip_rel = (0..3).map(|i| (tip(&fem)[i] - tip(&amm)[i]).abs()).fold(0.0, f64::max) / largest;
    eprintln!(
        "dGy: FEM {:.6e} m, AMM {:.6e} m ({rel:.2e}); tips {:?} / {:?} m ({tip_rel:.2e})",
        dgy(&fem),
        dgy(&amm),
        tip(&fem),
        tip(&amm)
    );
    assert!(
        dgy(&amm) < -1e-3 && rel < 5e-3,
        "FEM {} m against the AMM's {} m",
        dgy(&fem),
        dgy(&amm)
    );
    assert!(
        tip_rel < 5e-3,
        "tips: FEM {:?} m against the AMM's {:?} m",
        tip(&fem),
        tip(&amm)
    );
}
