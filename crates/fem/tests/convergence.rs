//! Mesh and step convergence of the FEM against a refined run of itself whose values are
//! committed (`reference_values/case2_refined.csv`, provenance in `reference_values/README.md`):
//! case 2 of the paper (the asymmetric one: all three tips and G move), tip and G deflections.
//!
//! Error of a run: for each of the six histories `w1tip..w3tip, w1G..w3G`, the largest
//! difference from the reference over the committed samples divided by the reference's peak
//! `max |w_ref|`; the worst history. Measured (this test): 1.05 % at (150 elements, 1 ms), 0.367 %
//! at the default (300, 0.5 ms), observed order 1.52. Further down the sequence (elements and
//! step refined together, `reference_values/README.md`) the orders are 1.09, 1.65, 1.91:
//! pre-asymptotic, tending to the second order of the generalized-alpha scheme (Chung & Hulbert
//! 1993) and of the
//! mesh (elements alone: order 2.3 at a fine step).

use flexstar_model::{catalogue, FemSettings, Response};

/// The committed reference: rows of `t, w1tip, w2tip, w3tip, w1G, w2G, w3G`.
fn reference() -> Vec<[f64; 7]> {
    let text = include_str!("reference_values/case2_refined.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,w1tip,w2tip,w3tip,w1G,w2G,w3G"));
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("a number")).collect();
            v.try_into().expect("seven columns")
        })
        .collect()
}

/// Every `STRIDE`-th output time is a reference row (the `fem_reference` argument).
const STRIDE: usize = 5;

fn run(elements: usize, dt: f64) -> Response {
    let settings = FemSettings {
        elements,
        dt: Some(dt),
        rho_inf: Some(flexstar_fem::DEFAULT_RHO_INF),
        snapshots: vec![],
    };
    flexstar_fem::solve(&catalogue::paper_case(2), &settings, None).expect("FEM run")
}

/// Worst relative max-norm error of the six histories of `r` against `reference` (module docs).
fn error(r: &Response, reference: &[[f64; 7]]) -> f64 {
    assert_eq!((r.t.len() - 1) / STRIDE + 1, reference.len(), "rows");
    let mut worst: f64 = 0.0;
    for c in 0..6 {
        let got = |k: usize| if c < 3 { r.w_tip[c][k] } else { r.w_g[c - 3][k] };
        let peak = reference.iter().fold(0.0f64, |m, row| m.max(row[c + 1].abs()));
        assert!(peak > 1e-4, "history {c}: the reference moves ({peak} m)");
        let mut diff: f64 = 0.0;
        for (i, row) in reference.iter().enumerate() {
            let k = i * STRIDE;
            assert!((r.t[k] - row[0]).abs() < 1e-12, "time {} vs {}", r.t[k], row[0]);
            diff = diff.max((got(k) - row[c + 1]).abs());
        }
        worst = worst.max(diff / peak);
    }
    worst
}

#[test]
fn default_mesh_and_step_converge_to_the_refined_reference() {
    let reference = reference();
    let default = error(&run(300, flexstar_fem::DEFAULT_DT), &reference);
    let coarse = error(&run(150, 2.0 * flexstar_fem::DEFAULT_DT), &reference);
    let order = (coarse / default).log2();
    eprintln!("error vs the refined reference: (150, 1 ms) {coarse:.3e}, default (300, 0.5 ms) {default:.3e}, order {order:.2}");
    // the default meets the 0.5 % target of issue 5 (docs/fem.md section 4), measured 0.367 %
    assert!(default < 5e-3, "default error {default:e}");
    // halving elements and step together: measured order 1.52 here (module docs); below 1.25
    // the scheme has lost its accuracy, above 2.5 the measure would be suspicious
    assert!(
        (1.25..=2.5).contains(&order),
        "order {order} ({coarse:e} -> {default:e})"
    );
}
