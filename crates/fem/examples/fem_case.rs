//! Run one paper case with the FEM and print a few numbers (used for the convergence study in
//! docs/fem.md). Usage: `fem_case CASE ELEMENTS DT RHO_INF [T_END] [CSV]`.

use std::path::Path;
use std::time::Instant;

use flexstar_model::{Experiment, FemSettings, TimeSpan, Trajectory};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let case: usize = a.get(1).map(|s| s.parse().unwrap()).unwrap_or(1);
    let elements: usize = a.get(2).map(|s| s.parse().unwrap()).unwrap_or(300);
    let dt: f64 = a.get(3).map(|s| s.parse().unwrap()).unwrap_or(flexstar_fem::DEFAULT_DT);
    let rho: f64 = a
        .get(4)
        .map(|s| s.parse().unwrap())
        .unwrap_or(flexstar_fem::DEFAULT_RHO_INF);
    let (k, t_end) = match case {
        1 => ([1.0, 1.0, 1.0], 0.5),
        2 => ([1.0, -0.5, -0.5], 0.4),
        3 => ([1.0, 0.0, 0.5], 0.5),
        _ => ([1.0, -1.0, 0.0], 0.5),
    };
    let t_end: f64 = a.get(5).map(|s| s.parse().unwrap()).unwrap_or(t_end);
    let exp = Experiment {
        name: format!("case{case}"),
        description: String::new(),
        robot: Default::default(),
        time: TimeSpan { t_end, dt_out: 1e-3 },
        trajectory: Trajectory::quadratic(k),
        amm: Default::default(),
        fem: Default::default(),
        source: Default::default(),
    };
    let settings = FemSettings {
        elements,
        dt: Some(dt),
        rho_inf: Some(rho),
        snapshots: vec![],
    };
    let t0 = Instant::now();
    match flexstar_fem::solve_with_stats(&exp, &settings, None) {
        Ok((r, st)) => {
            let el = t0.elapsed().as_secs_f64();
            let n = r.len() - 1;
            println!("case {case} elements {elements} dt {dt:e} rho {rho}: {el:.2} s, {st:?}");
            println!("t = {}: wG {:?}", r.t[n], [r.w_g[0][n], r.w_g[1][n], r.w_g[2][n]]);
            println!("tip {:?}", [r.w_tip[0][n], r.w_tip[1][n], r.w_tip[2][n]]);
            println!("Fa {:?}", [r.fa[0][n], r.fa[1][n], r.fa[2][n]]);
            let col = |name: &str| r.extra.iter().find(|c| c.name == name).unwrap().values[n];
            let e = col("Ek_star") + col("Ek_sleeves") + col("Ek_sliders") + col("U");
            println!(
                "energy {e:.6e} work {:.6e} rel {:.3e}",
                col("W"),
                (e - col("W")) / col("W")
            );
            if let Some(path) = a.get(6) {
                r.write_csv(Path::new(path)).unwrap();
            }
        }
        Err(e) => println!("error: {e}"),
    }
}
