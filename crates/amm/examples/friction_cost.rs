//! The accurate model's cost with and without sleeve friction on the four paper cases
//! (`docs/friction.md` 6, "Speed"): the runs of the automatic choice (N of each, steps in all)
//! and the wall time per solve, frictionless and with `mu = 0.1`, alternated.
//!
//! ```sh
//! cargo run --release -p flexstar-amm --example friction_cost [REPEATS]
//! ```
use flexstar_model::catalogue::paper_case;
use flexstar_model::AmmSettings;

fn main() {
    let repeats: usize = std::env::args().nth(1).and_then(|r| r.parse().ok()).unwrap_or(10);
    let settings = AmmSettings::accurate();
    for case in [1, 2, 3, 4] {
        let bare = paper_case(case);
        let mut rubbing = bare.clone();
        rubbing.friction = Some(flexstar_model::Friction {
            mu: flexstar_model::robot_section::PerBeam([0.1; 3]),
            ..Default::default()
        });
        let mut line = format!("case {case}:");
        for (label, exp) in [("frictionless", &bare), ("mu = 0.1", &rubbing)] {
            let problem = exp.problem().expect("paper case");
            let solve =
                || flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion()).expect("solve");
            let s = solve().stats;
            let started = std::time::Instant::now();
            for _ in 0..repeats {
                solve();
            }
            let ms = started.elapsed().as_secs_f64() * 1e3 / repeats as f64;
            line += &format!(
                "  {label}: {ms:.1} ms, N tried {:?}, {} steps of which {} delivered",
                s.modes_tried, s.total_steps, s.steps
            );
        }
        println!("{line}");
    }
}
