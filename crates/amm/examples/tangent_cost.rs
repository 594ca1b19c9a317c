//! The cost of forward sensitivities against a plain run (`docs/amm.md` 2.2):
//! `cargo run --release -p flexstar-amm --example tangent_cost -- [K ...]` times paper case 3
//! with the accurate model's equations at N = 53 and the step 5e-4 s it delivers, plain and with
//! K directions of its motion (the coefficients of t^2 in s1 and s3, alternately), the best of
//! five runs each, and prints the ratio to the plain run.
use flexstar_model::catalogue::paper_case;
use flexstar_model::{AmmModel, AmmSettings, Experiment, ModeFamily, Trajectory};
use std::time::Instant;

fn case3(d1: f64, d3: f64) -> Experiment {
    let mut e = paper_case(3);
    e.trajectory = Trajectory::Polynomial {
        s1: vec![0.0, 0.0, 1.0 + d1],
        s2: vec![0.0],
        s3: vec![0.0, 0.0, 0.5 + d3],
    };
    e
}

fn best_of<F: FnMut()>(mut f: F) -> f64 {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let ks: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let ks = if ks.is_empty() { vec![1, 4, 12] } else { ks };
    let settings = AmmSettings {
        family: ModeFamily::Enriched,
        model: AmmModel::Full,
        modes: Some(53),
        tol: None,
        dt: Some(5e-4),
        ..AmmSettings::accurate()
    };
    let base = case3(0.0, 0.0).problem().expect("case 3");
    let plain = best_of(|| {
        flexstar_amm::solve(&base, &settings, flexstar_drive::SolveRequest::motion()).expect("plain run");
    });
    println!("plain run: {:.2} ms", 1e3 * plain);
    let eps = 1e-6;
    for k in ks {
        let moved: Vec<_> = (0..k)
            .map(|j| {
                let d = eps * (1.0 + j as f64 / k as f64);
                let e = if j % 2 == 0 { case3(d, 0.0) } else { case3(0.0, d) };
                e.problem().expect("moved case 3")
            })
            .collect();
        let with = best_of(|| {
            flexstar_amm::solve_with_sensitivities(&base, &settings, &moved, &vec![eps; k]).expect("sensitivities");
        });
        println!(
            "{k} directions: {:.2} ms, {:.2} plain runs ({:.3} per direction)",
            1e3 * with,
            with / plain,
            (with / plain - 1.0) / k as f64
        );
    }
}
