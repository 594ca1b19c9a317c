//! Mesh and step convergence of the FEM against a refined run of itself whose values are
//! committed (`reference_values/case2_refined.csv`, provenance in `reference_values/README.md`):
//! case 2 of the paper (the asymmetric one: all three tips and G move), tip and G deflections.
//!
//! Error of a run: for each of the six histories `w1tip..w3tip, w1G..w3G`, the largest
//! difference from the reference over the committed samples divided by the reference's peak
//! `max |w_ref|`; the worst history. Measured (this test): 1.05 % at (150 elements, 1 ms), 0.367 %
//! at the default (300, 0.5 ms), observed order 1.52; since Eq. S9 of the tangent rows
//! (`docs/fem.md` section 2.1; the reference is from before it, whose own mesh error at 4800
//! elements is first order) 1.08 %, 0.407 % and 1.40. Further down the sequence (elements and
//! step refined together, `reference_values/README.md`) the orders are 1.09, 1.65, 1.91:
//! pre-asymptotic, tending to the second order of the generalized-alpha scheme (Chung & Hulbert
//! 1993) and of the mesh (elements alone: order 2.3 at a fine step).
//!
//! The second test pins the exact work of the four paper cases at the defaults (the way russell
//! pins its solvers' work) with what it buys: cases 2 and 3 against their refined runs, cases 1
//! and 4 against their exact symmetries.

use flexstar_model::{catalogue, FemSettings, Response};

/// A committed reference (`reference_values/`): rows of `t, w1tip, w2tip, w3tip, w1G, w2G, w3G`.
fn reference(text: &str) -> Vec<[f64; 7]> {
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

const CASE2: &str = include_str!("reference_values/case2_refined.csv");
const CASE3: &str = include_str!("reference_values/case3_refined.csv");

fn run(elements: usize, dt: f64) -> Response {
    let settings = FemSettings {
        elements,
        dt: Some(dt),
        rho_inf: Some(flexstar_fem::DEFAULT_RHO_INF),
        snapshots: vec![],
        frames: 0,
    };
    flexstar_fem::solve(
        &catalogue::paper_case(2).problem().unwrap(),
        &settings,
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| s.response)
    .expect("FEM run")
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
    let reference = reference(CASE2);
    let default = error(&run(300, flexstar_fem::DEFAULT_DT), &reference);
    let coarse = error(&run(150, 2.0 * flexstar_fem::DEFAULT_DT), &reference);
    let order = (coarse / default).log2();
    eprintln!("error vs the refined reference: (150, 1 ms) {coarse:.3e}, default (300, 0.5 ms) {default:.3e}, order {order:.2}");
    // the default meets the 0.5 % target (docs/fem.md section 4), measured 0.407 %
    assert!(default < 5e-3, "default error {default:e}");
    // halving elements and step together: measured order 1.40 here (module docs); below 1.25
    // the scheme has lost its accuracy, above 2.5 the measure would be suspicious
    assert!(
        (1.25..=2.5).contains(&order),
        "order {order} ({coarse:e} -> {default:e})"
    );
}

#[test]
fn paper_cases_work_counts_and_accuracy() {
    // exact work of the four paper cases at the defaults (300 elements, 0.5 ms, rho_inf 0.7;
    // docs/fem.md section 6): one factorisation per step, 2.0-2.2 Newton iterations per step
    // [steps, Newton iterations, factorisations, sparse fallbacks, sparsity patterns]
    // (Eq. S9 of the tangent rows, docs/fem.md 2.1, took the iterations from 2188 / 1805 / 2113 / 2311)
    let pinned = [
        (1, [1000, 2124, 1000, 0, 13]),
        (2, [800, 1679, 800, 0, 13]),
        (3, [1000, 2044, 1000, 0, 14]),
        (4, [1000, 2158, 1000, 0, 25]),
    ];
    for (case, want) in pinned {
        let exp = catalogue::paper_case(case);
        let problem = exp.problem().unwrap();
        let (r, s) = flexstar_fem::solve(&problem, &exp.fem, flexstar_drive::SolveRequest::motion())
            .map(|s| (s.response, s.stats))
            .expect("FEM run");
        let got = [
            s.steps,
            s.newton_iterations,
            s.factorisations,
            s.sparse_fallbacks,
            s.symbolic_factorisations,
        ];
        assert_eq!(got, want, "case {case}: {s:?}");
        // and what that work buys, against outside references
        match case {
            // s_i all equal: the symmetry of the star, exactly
            1 => {
                let w = &r.w_tip;
                let peak = w[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(peak > 1e-4);
                for k in 0..r.t.len() {
                    assert!((w[1][k] - w[0][k]).abs() < 1e-9 * peak && (w[2][k] - w[0][k]).abs() < 1e-9 * peak);
                    assert!(r.w_g.iter().all(|g| g[k].abs() < 1e-12));
                }
            }
            2 | 3 => {
                let text = if case == 2 { CASE2 } else { CASE3 };
                let e = error(&r, &reference(text));
                eprintln!("case {case}: {e:.3e} of the peak off the refined run");
                // the 0.5 % target (docs/fem.md section 4); measured 0.407 % and 0.237 %
                assert!(e < 5e-3, "case {case}: {e:e}");
            }
            // s3 = 0, s2 = -s1: mirror symmetry about beam 3 (its deflection stays zero, beams
            // 1 and 2 deflect oppositely); measured 1e-15 m against tips of 7e-3 m
            _ => {
                let m = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let mirrored = |a: &[f64], b: &[f64]| a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x + y).abs()));
                assert!(m(&r.w_tip[0]) > 1e-3);
                assert!(m(&r.w_tip[2]) < 1e-12 && m(&r.w_g[2]) < 1e-12);
                assert!(mirrored(&r.w_tip[0], &r.w_tip[1]) < 1e-12 && mirrored(&r.w_g[0], &r.w_g[1]) < 1e-12);
            }
        }
    }
}
