//! How the delivered run's time error falls with the step (`docs/amm.md` 12.10).
//!
//! `cargo run --release -p flexstar-amm --example time_order -- FILE.toml [FILE.toml ...]`
//! For each experiment: the automatic choice (its N and step h), then that N at k h for
//! k = 1/16, 1, 2, 4, 8, and prints e(h) (against h/16) and E(2 h, h) on the time check's grid
//! (the finest the 2 h run allows, as the automatic choice measures them), E(k h, h) for k = 4, 8
//! with their own e(h) on the grid of the 8 h run, the ratios E(k h, h) / e(h), and the error
//! estimate the automatic choice reported. A span too short for the estimate's grid (`docs/amm.md`
//! 12.13) reports the check grid only.
use flexstar_amm::adaptive::{estimate_grid, time_check_grid};
use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, Response};

/// Mean EVP (Eq. 45) of `a` against `b`.
fn evp(a: &Response, b: &Response) -> f64 {
    point_evps(a, b)
        .expect("same times")
        .mean
        .expect("a point with a reference")
}

fn main() {
    for file in std::env::args().skip(1) {
        let path = std::path::Path::new(&file);
        let text = std::fs::read_to_string(path).expect("readable file");
        let exp = Experiment::from_toml_str(&text, path).expect("valid experiment");
        let problem = exp.problem().unwrap();
        let auto = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .expect("automatic choice");
        let (n, h) = (auto.info.modes.expect("N"), auto.info.dt);
        let problem = exp.problem().expect("valid problem");
        // spans too short for the estimate's grid (docs/amm.md 12.13) report the check grid only,
        // and so do runs with friction, whose coarse pairs are the frictionless robot's (12.16)
        let coarse = estimate_grid(&problem, h).filter(|_| exp.friction.is_none());
        let run = |step: f64, every: usize| {
            let mut e = exp.clone();
            e.time.dt_out = every as f64 * exp.time.dt_out;
            let s = AmmSettings {
                modes: Some(n),
                dt: Some(step),
                snapshots: Vec::new(),
                frames: 0,
                ..exp.amm.clone()
            };
            flexstar_amm::solve(&e.problem().unwrap(), &s, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .expect("solve")
        };
        let check = time_check_grid(&problem, h);
        let [e_check, e2] = {
            let delivered = run(h, check);
            [
                evp(&delivered, &run(h / 16.0, check)),
                evp(&run(2.0 * h, check), &delivered),
            ]
        };
        let Some(coarse) = coarse else {
            println!(
                "{}: N = {n}, h = {h:.3e} s, check grid {check}: e(h) = {e_check:.4} %, E(2h, h) = {e2:.4} %, ratio {:.2}; no coarse grid; estimate {:.4} %",
                exp.name,
                e2 / e_check,
                auto.info.error_estimate_percent.unwrap_or(f64::NAN)
            );
            continue;
        };
        let delivered = run(h, coarse);
        let e_coarse = evp(&delivered, &run(h / 16.0, coarse));
        let big: Vec<f64> = [4.0, 8.0]
            .iter()
            .map(|k| evp(&run(k * h, coarse), &delivered))
            .collect();
        println!(
            "{}: N = {n}, h = {h:.3e} s, check grid {check}: e(h) = {e_check:.4} %, E(2h, h) = {e2:.4} %, ratio {:.2}; coarse grid {coarse}: e(h) = {e_coarse:.4} %, E(4h, 8h; h) = {:.4} / {:.4} %, ratios {:.1} / {:.1}; estimate {:.4} %",
            exp.name,
            e2 / e_check,
            big[0],
            big[1],
            big[0] / e_coarse,
            big[1] / e_coarse,
            auto.info.error_estimate_percent.unwrap_or(f64::NAN)
        );
    }
}
