//! The parts of the accurate model's error estimate and what each stands for (`docs/amm.md`
//! 12.13): `cargo run --release -p flexstar-amm --example estimate_parts -- FILE.toml [...]`.
//!
//! For each experiment: the automatic choice (N, step h, the runs tried, the estimate), split into
//! its geometric part (Eq. G1, from the delivered run), its time part (Eq. T1, the chosen N at 2 h
//! against h on the time check's grid) and the rest, the truncation part; beside them the
//! delivered run's own time error (the same N at h / 16) and its own truncation error (at h
//! against N = 90), both on the time check's grid.
use flexstar_amm::adaptive::{geometric_part, time_check_grid, time_error_estimate};
use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, Response};

/// N of the truncation reference.
const REFERENCE_MODES: usize = 90;

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
        let problem = exp.problem().expect("valid problem");
        let auto =
            flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::motion()).expect("automatic choice");
        let (n, h) = (auto.response.info.modes.expect("N"), auto.response.info.dt);
        let estimate = auto.response.info.error_estimate_percent.expect("an estimate");
        let check = time_check_grid(&problem, h);
        let run = |modes: usize, step: f64| {
            let mut e = exp.clone();
            e.time.dt_out = check as f64 * exp.time.dt_out;
            let s = AmmSettings {
                modes: Some(modes),
                dt: Some(step),
                snapshots: Vec::new(),
                frames: 0,
                ..exp.amm.clone()
            };
            flexstar_amm::solve(&e.problem().unwrap(), &s, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .expect("solve")
        };
        let delivered = run(n, h);
        let geometric = geometric_part(&problem, &auto.response);
        let time = time_error_estimate(evp(&run(n, 2.0 * h), &delivered));
        let own_time = evp(&delivered, &run(n, h / 16.0));
        let own_truncation = evp(&delivered, &run(REFERENCE_MODES.max(n), h));
        println!(
            "{}: N = {n} (runs {:?}), h = {h:.3e} s: estimate {estimate:.4} % = truncation {:.4} + time {time:.4} + geometric {geometric:.4}; own time error {own_time:.4} %, own truncation {own_truncation:.4} %",
            exp.name,
            auto.stats.modes_tried,
            estimate - time - geometric,
        );
    }
}
