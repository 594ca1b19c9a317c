//! Single-beam self-checks of the co-rotational element against outside references.

// the single-beam models are test code: they live in the test tree
#[path = "support/beam.rs"]
mod beam;

use beam::{bending_frequencies, end_moment_static, BeamSupport};
use flexstar_model::RobotParams;

/// beta L of the first four bending modes (Blevins 1979, Formulas for Natural Frequency and Mode
/// Shape, table 8-1; Rao, Vibration of Continuous Systems, table 11.2).
const CLAMPED_FREE: [f64; 4] = [1.875104, 4.694091, 7.854757, 10.995541];
const FREE_FREE: [f64; 4] = [4.730041, 7.853205, 10.995608, 14.137165];

fn check(support: BeamSupport, beta_l: [f64; 4]) {
    let p = RobotParams::paper();
    let got = bending_frequencies(&p, 100, support, 4).unwrap();
    assert_eq!(got.len(), 4);
    let scale = (p.ei() / (p.rho * p.l.powi(4))).sqrt();
    for (k, (w, bl)) in got.iter().zip(beta_l).enumerate() {
        let exact = bl * bl * scale;
        let rel = (w - exact).abs() / exact;
        // beta L is tabulated to 7 digits: 5e-7 relative in beta L, 1e-6 in omega; the
        // discretisation error at 100 cubic elements is below that (measured 5e-8 to 3.5e-7)
        assert!(
            rel < 1e-6,
            "{support:?} mode {}: {w} rad/s vs {exact} rad/s (rel {rel:.2e})",
            k + 1
        );
        eprintln!(
            "{support:?} mode {}: omega = {w:.6} rad/s, textbook {exact:.6}, rel {rel:.2e}",
            k + 1
        );
    }
}

#[test]
fn clamped_free_frequencies_match_textbook() {
    check(BeamSupport::ClampedFree, CLAMPED_FREE);
}

#[test]
fn free_free_frequencies_match_textbook() {
    check(BeamSupport::FreeFree, FREE_FREE);
}

#[test]
fn end_moment_rolls_cantilever_into_full_circle() {
    // Pure bending: the exact curvature is M / EI everywhere; with M = 2 pi EI / L the beam closes
    // into a circle of radius L / (2 pi) (e.g. Battini & Pacoste 2002; Simo & Vu-Quoc 1986).
    let p = RobotParams::paper();
    let n = 40;
    let m = 2.0 * std::f64::consts::PI * p.ei() / p.l;
    let q = end_moment_static(&p, n, m, 20).unwrap();
    let tip = q[n];
    let gap = (tip[0] * tip[0] + tip[1] * tip[1]).sqrt();
    assert!(gap < 1e-9 * p.l, "tip is {gap} m from the root");
    assert!(
        (tip[2] - 2.0 * std::f64::consts::PI).abs() < 1e-9,
        "tip rotation {}",
        tip[2]
    );
    // the point at mid-span is diametrically opposite the root: distance 2 R = L / pi
    // (nodes lie on the circle circumscribing a regular n-gon of side L/n: 2R_n = (L/n)/sin(pi/n))
    let mid = q[n / 2];
    let dia = (mid[0] * mid[0] + mid[1] * mid[1]).sqrt();
    let exact_polygon = (p.l / n as f64) / (std::f64::consts::PI / n as f64).sin();
    assert!((dia - exact_polygon).abs() < 1e-9, "diameter {dia} vs {exact_polygon}");
    assert!((dia - p.l / std::f64::consts::PI).abs() < 1e-3 * p.l);
    // half the moment, pi EI / L, bends it into a half circle of radius L / pi: the tip sits at
    // (0, 2 L / pi) turned by pi (polygon of 2n sides: diameter (L/n) / sin(pi / (2n)))
    let q = end_moment_static(&p, n, m / 2.0, 10).unwrap();
    let tip = q[n];
    let half = (p.l / n as f64) / (std::f64::consts::PI / (2 * n) as f64).sin();
    assert!(
        tip[0].abs() < 1e-9 && (tip[1] - half).abs() < 1e-9,
        "half circle tip {tip:?}, expected (0, {half})"
    );
    assert!((tip[2] - std::f64::consts::PI).abs() < 1e-9);
}
