//! How the delivered run's time error falls with the step (issue 21, `docs/amm.md` 12.10).
//!
//! `cargo run --release -p flexstar-amm --example time_order -- FILE.toml [FILE.toml ...]`
//! For each experiment: the automatic choice (its N and step h), then that N at k h for
//! k = 1/16, 1, 2, 4, 8, and prints e(h) (against h/16), E(k h, h) for k = 2, 4, 8 on the grid of
//! the 8 h run, the ratios E(k h, h) / e(h), and the error estimate the automatic choice reported.
use flexstar_amm::adaptive::estimate_grid;
use flexstar_amm::solve;
use flexstar_model::evp::point_evps;
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
        let auto = solve(&exp, &exp.amm).expect("automatic choice");
        let (n, h) = (auto.info.modes.expect("N"), auto.info.dt);
        let every = estimate_grid(&exp, h).expect("a span long enough for the estimate's grid");
        let run = |step: f64| {
            let mut e = exp.clone();
            e.time.dt_out = every as f64 * exp.time.dt_out;
            let s = AmmSettings {
                modes: Some(n),
                dt: Some(step),
                snapshots: Vec::new(),
                frames: 0,
                ..exp.amm.clone()
            };
            solve(&e, &s).expect("solve")
        };
        let fine = run(h / 16.0);
        let delivered = run(h);
        let e_h = evp(&delivered, &fine);
        let big: Vec<f64> = [2.0, 4.0, 8.0].iter().map(|k| evp(&run(k * h), &delivered)).collect();
        println!(
            "{}: N = {n}, h = {h:.3e} s, e(h) = {e_h:.4} %, E(2h, 4h, 8h; h) = {:.4} / {:.4} / {:.4} %, ratios {:.1} / {:.1} / {:.1}, estimate {:.4} %",
            exp.name,
            big[0],
            big[1],
            big[2],
            big[0] / e_h,
            big[1] / e_h,
            big[2] / e_h,
            auto.info.error_estimate_percent.unwrap_or(f64::NAN)
        );
    }
}
