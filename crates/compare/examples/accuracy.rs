//! Accuracy of AMM settings against the FEM on the paper's four cases and the two motions of our
//! own (`configs/motions/`, `tests/cross_models.rs`): mean and largest point EVP (Eq. 45) per case, and the AMM's wall time.
//!
//! `cargo run --release -p flexstar-compare --example accuracy -- FAMILY MODEL N [N ...]`
//! (N = 0: automatic N at the default tolerance; `tol=P` for another tolerance). The environment
//! variable `AMM_DT` sets the AMM's step [s] (default: the solver's).

use flexstar_compare::evp::point_evps;
use flexstar_model::catalogue::paper_case;
use flexstar_model::{AmmSettings, Experiment, ModeFamily};
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: accuracy FAMILY MODEL N|tol=P [...]");
        std::process::exit(2);
    }
    let family: ModeFamily = args[0].parse().expect("family");
    let model = args[1].parse().expect("model");
    let mut cases: Vec<Experiment> = (1..=4).map(paper_case).collect();
    // the two motions of our own (tests/cross_models.rs)
    for (file, text) in [
        ("smooth.toml", include_str!("../../../configs/motions/smooth.toml")),
        ("brisk.toml", include_str!("../../../configs/motions/brisk.toml")),
    ] {
        cases.push(Experiment::from_toml_str(text, std::path::Path::new(file)).expect("own motion"));
    }
    let fems: Vec<_> = cases
        .par_iter()
        .map(|e| {
            flexstar_fem::solve(&e.problem().unwrap(), &e.fem, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .expect("fem")
        })
        .collect();
    for spec in &args[2..] {
        let mut settings = AmmSettings {
            family,
            model,
            dt: std::env::var("AMM_DT").ok().map(|v| v.parse().expect("AMM_DT")),
            ..AmmSettings::default()
        };
        if let Some(p) = spec.strip_prefix("tol=") {
            settings.tol = Some(p.parse().expect("tol"));
        } else {
            let n: usize = spec.parse().expect("N");
            if n > 0 {
                settings.modes = Some(n);
            }
        }
        for (e, fem) in cases.iter().zip(&fems) {
            let started = std::time::Instant::now();
            let amm =
                match flexstar_amm::solve(&e.problem().unwrap(), &settings, flexstar_drive::SolveRequest::motion())
                    .map(|s| s.response)
                {
                    Ok(r) => r,
                    Err(err) => {
                        println!("{} {spec}: {err}", e.name);
                        continue;
                    }
                };
            let wall = started.elapsed().as_secs_f64();
            let p = point_evps(&amm, fem).expect("evp");
            let pts: Vec<String> = p
                .points
                .iter()
                .map(|v| v.map_or("n/a".into(), |x| format!("{x:.2}")))
                .collect();
            let worst = p.points.iter().flatten().fold(0.0f64, |a, b| a.max(*b));
            println!(
                "{} {family} {model} {spec}: N = {:?} est = {:?} | A B C G = {} | mean {:.2} max {:.2} | {:.1} ms",
                e.name,
                amm.info.modes,
                amm.info.error_estimate_percent.map(|x| (x * 100.0).round() / 100.0),
                pts.join(" "),
                p.mean.unwrap_or(f64::NAN),
                worst,
                wall * 1e3
            );
        }
    }
}
