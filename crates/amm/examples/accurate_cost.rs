//! One paper case with the accurate model's defaults (`docs/amm.md` section 9), for instruction counts
//! that the load of a shared machine does not disturb:
//!
//! ```sh
//! cargo build --release -p flexstar-amm --example accurate_cost
//! valgrind --tool=callgrind target/release/examples/accurate_cost CASE [N [DT]]
//! ```
//! runs `flexstar_amm::solve` once with `AmmSettings::accurate()` (automatic N), or at a fixed N
//! (and step DT [s]: `5e-4` is the step the automatic choice delivers at its default tolerance).
use flexstar_model::catalogue::paper_case;
use flexstar_model::AmmSettings;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: accurate_cost CASE [N [DT]]";
    let Some(case) = args.get(1).and_then(|c| c.parse().ok()) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let settings = AmmSettings {
        modes: args.get(2).map(|n| n.parse().expect(usage)),
        dt: args.get(3).map(|h| h.parse().expect(usage)),
        ..AmmSettings::accurate()
    };
    let r = flexstar_amm::solve(
        &paper_case(case).problem().unwrap(),
        &settings,
        flexstar_drive::SolveRequest::motion(),
    )
    .map(|s| s.response)
    .expect("solve");
    println!(
        "case {case}: N = {:?}, estimate {:?} %, {} output rows",
        r.info.modes,
        r.info.error_estimate_percent,
        r.len()
    );
}
