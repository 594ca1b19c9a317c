//! Cost of the payload, damping and load (docs/amm.md 11.7): `attachments_cost bare|loaded K` solves paper
//! case 3 with the accurate model at N = 53 K times, bare or with a payload off G, damping and a
//! load (for instruction counts, e.g. `perf stat -e instructions:u`, on a shared machine where
//! wall times are noisy).
use flexstar_model::{AmmSettings, Damping, LoadSettings, Payload};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let loaded = args.get(1).map(String::as_str) == Some("loaded");
    let k: usize = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(10);
    let mut exp = flexstar_model::catalogue::paper_case(3);
    if loaded {
        exp.payload = Payload {
            mass: 0.8,
            j: 3e-3,
            offset: [0.04, 0.02],
        };
        exp.damping = Damping::with_beta(8e-4);
        exp.load = LoadSettings::polynomials(Some(vec![0.0, 0.0, 12.0]), Some(vec![0.0, -4.0]), Some(vec![0.0, 0.5]));
    }
    let settings = AmmSettings {
        modes: Some(53),
        ..AmmSettings::accurate()
    };
    let mut sum = 0.0;
    for _ in 0..k {
        let problem = exp.problem().unwrap();
        let r = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .expect("solve");
        sum += r.w_tip[0].iter().sum::<f64>();
    }
    println!("{sum:e}");
}
