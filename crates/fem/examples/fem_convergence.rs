//! Convergence study of docs/fem.md: for each paper case, the EVP (Eq. 45, docs/validation.md) of
//! every tip and G response of a run (dt, N) against runs with the step halved, the mesh doubled,
//! and both. Usage: `fem_convergence DT N RHO_INF [CASES]`, e.g. `fem_convergence 5e-4 300 0.9 1234`.

use std::time::Instant;

use flexstar_model::{catalogue, Experiment, FemSettings, Response};
use flexstar_numerics::measures::{self, integral_abs};

fn case(c: usize) -> Experiment {
    catalogue::paper_case(c)
}

/// EVP (Eq. 45); None where the reference is identically ~0 (symmetry).
fn evp(t: &[f64], a: &[f64], b: &[f64]) -> Option<f64> {
    (integral_abs(t, b) > 1e-9 * t[t.len() - 1])
        .then(|| measures::evp(t, a, b))
        .flatten()
}

fn run(exp: &Experiment, n: usize, dt: f64, rho: f64) -> (Response, f64) {
    let s = FemSettings {
        elements: n,
        dt: Some(dt),
        rho_inf: Some(rho),
        snapshots: vec![],
        frames: 0,
    };
    let t0 = Instant::now();
    let r = flexstar_fem::solve(&exp.problem().unwrap(), &s, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    (r, t0.elapsed().as_secs_f64())
}

fn fmt(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.3}")).unwrap_or_else(|| "n/a".into())
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let dt: f64 = a[1].parse().unwrap();
    let n: usize = a[2].parse().unwrap();
    let rho: f64 = a[3].parse().unwrap();
    let cases: Vec<usize> = a
        .get(4)
        .map(|s| s.chars().map(|c| c.to_digit(10).unwrap() as usize).collect())
        .unwrap_or(vec![1, 2, 3, 4]);
    for c in cases {
        let exp = case(c);
        let (base, tb) = run(&exp, n, dt, rho);
        let (fine_t, tt) = run(&exp, n, dt / 2.0, rho);
        let (fine_n, tn) = run(&exp, 2 * n, dt, rho);
        let (both, t2) = run(&exp, 2 * n, dt / 2.0, rho);
        for (label, r) in [("dt/2", &fine_t), ("2N", &fine_n), ("dt/2+2N", &both)] {
            let mut cells = Vec::new();
            let mut worst: f64 = 0.0;
            for i in 0..3 {
                let e = evp(&base.t, &base.w_tip[i], &r.w_tip[i]);
                worst = worst.max(e.unwrap_or(0.0));
                cells.push(fmt(e));
            }
            for i in 0..3 {
                cells.push(fmt(evp(&base.t, &base.w_g[i], &r.w_g[i])));
            }
            for i in 0..3 {
                cells.push(fmt(evp(&base.t, &base.fa[i], &r.fa[i])));
            }
            println!(
                "| {c} | {dt:e} | {n} | {rho} | {label} | {} | {worst:.3} |",
                cells.join(" | ")
            );
        }
        eprintln!("case {c}: run times base {tb:.2} s, dt/2 {tt:.2} s, 2N {tn:.2} s, both {t2:.2} s");
    }
}
