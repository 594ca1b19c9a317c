//! Convergence study of docs/fem.md: for each paper case, the EVP (MODEL-NOTES section 5) of
//! every tip and G response of a run (dt, N) against runs with the step halved, the mesh doubled,
//! and both. Usage: `fem_convergence DT N RHO_INF [CASES]`, e.g. `fem_convergence 5e-4 300 0.9 1234`.

use std::time::Instant;

use flexstar_model::{Experiment, FemSettings, Response, TimeSpan, Trajectory};

fn case(c: usize) -> Experiment {
    let (k, t_end) = match c {
        1 => ([1.0, 1.0, 1.0], 0.5),
        2 => ([1.0, -0.5, -0.5], 0.4),
        3 => ([1.0, 0.0, 0.5], 0.5),
        _ => ([1.0, -1.0, 0.0], 0.5),
    };
    Experiment {
        name: format!("case{c}"),
        description: String::new(),
        robot: Default::default(),
        time: TimeSpan { t_end, dt_out: 1e-3 },
        trajectory: Trajectory::quadratic(k),
        amm: Default::default(),
        fem: Default::default(),
        source: Default::default(),
    }
}

/// EVP = int |a - b| dt / int |b| dt * 100 (trapezoidal rule); None where b is identically ~0.
fn evp(t: &[f64], a: &[f64], b: &[f64]) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for k in 1..t.len() {
        let h = t[k] - t[k - 1];
        num += 0.5 * h * ((a[k] - b[k]).abs() + (a[k - 1] - b[k - 1]).abs());
        den += 0.5 * h * (b[k].abs() + b[k - 1].abs());
    }
    (den > 1e-9 * t[t.len() - 1]).then(|| num / den * 100.0)
}

fn run(exp: &Experiment, n: usize, dt: f64, rho: f64) -> (Response, f64) {
    let s = FemSettings {
        elements: n,
        dt: Some(dt),
        rho_inf: Some(rho),
        snapshots: vec![],
    };
    let t0 = Instant::now();
    let r = flexstar_fem::solve(exp, &s, None).unwrap();
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
