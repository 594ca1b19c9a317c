//! Cost of a direct AMM run against the inverse run of the same case (`docs/amm.md` section 10), for
//! instruction counts that the load of a shared machine does not disturb:
//!
//! ```sh
//! cargo build --release -p flexstar-amm --example direct_cost
//! perf stat -e instructions:u target/release/examples/direct_cost CASE paper|accurate setup|inverse|forces|servo
//! ```
//! (or `valgrind --tool=callgrind`) runs one solve of that kind after a common set-up (the inverse
//! run whose forces the `forces` kind feeds back is run in every kind; kind `setup` runs only
//! that), so the counts minus that of `setup` are the solve alone.

use flexstar_drive::{ForceTable, Servo};
use flexstar_model::catalogue::paper_case;
use flexstar_model::AmmSettings;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: direct_cost CASE paper|accurate setup|inverse|forces|servo";
    let (Some(case), Some(model), Some(kind)) = (args.get(1), args.get(2), args.get(3)) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let exp = paper_case(case.parse().expect(usage));
    let settings = match model.as_str() {
        "paper" => AmmSettings {
            modes: Some(25),
            ..exp.amm.clone()
        },
        _ => AmmSettings {
            modes: Some(53),
            ..AmmSettings::accurate()
        },
    };
    let problem = exp.problem().unwrap();
    let inverse = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let fa = (0..inverse.len())
        .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
        .collect();
    let table = ForceTable::new(inverse.t.clone(), fa).unwrap();
    let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 20.0, 0.7);
    let servo = Servo {
        kp: [kp; 3],
        kd: [kd; 3],
        rigid_feedforward: true,
        reference: exp.trajectory.clone(),
        params: exp.robot,
        attached: Default::default(),
    };
    let r = match kind.as_str() {
        "setup" => Ok(inverse),
        "inverse" => flexstar_amm::solve(
            &exp.problem().unwrap(),
            &settings,
            flexstar_drive::SolveRequest::motion(),
        )
        .map(|s| s.response),
        "forces" => flexstar_amm::solve(
            &exp.problem().unwrap(),
            &settings,
            flexstar_drive::SolveRequest::law(&table),
        )
        .map(|s| s.response),
        _ => flexstar_amm::solve(
            &exp.problem().unwrap(),
            &settings,
            flexstar_drive::SolveRequest::law(&servo),
        )
        .map(|s| s.response),
    }
    .unwrap();
    eprintln!("{} rows", r.len());
}
