//! What a robot as built costs the AMM against the paper's robot (`docs/amm.md` 13: a mode set
//! and an arrowhead per beam instead of one shared).
//!
//! `cargo run --release -p flexstar-amm --example as_built_cost [-- REPEATS]`
//! Paper case 3 (0.5 s) on the paper's robot, on three equal beams welded at 0, 117, 243.5
//! degrees on an uneven base (one shared mode set, the general weld), and on three different
//! beams there (three mode sets), at N = 25 (free-free, paper model) and N = 53 (enriched, full
//! model), the accurate model's step; the best wall time of REPEATS runs (default 7) of each.
use flexstar_drive::SolveRequest;
use flexstar_model::catalogue::paper_case;
use flexstar_model::{ActuatorAxis, AmmSettings, Beam, ModeFamily, Problem, Robot, RobotParams};

fn robot(unequal: bool) -> Robot {
    let p = RobotParams::paper();
    let welds = [0.0, 117f64.to_radians(), 243.5f64.to_radians()];
    let k = |v: [f64; 3], i: usize| if unequal { v[i] } else { 1.0 };
    let beams = std::array::from_fn(|i| Beam {
        youngs_modulus: p.e * k([1.0, 1.2, 0.85], i),
        second_moment: p.i * k([1.0, 0.9, 1.1], i),
        axial_stiffness: p.ea() * k([1.0, 1.1, 0.95], i),
        mass_per_length: p.rho * k([1.0, 1.15, 0.9], i),
        length: p.l * k([1.0, 0.92, 1.06], i),
        sleeve_length: p.lp * k([1.0, 1.2, 0.9], i),
        sleeve_mass: p.mpp_mpa * k([1.0, 1.3, 0.8], i),
        sleeve_inertia: p.jp * k([1.0, 0.7, 1.4], i),
        weld_angle: welds[i],
    });
    Robot::new(
        beams,
        ActuatorAxis::from_sides([0.626, 0.618, 0.631]).expect("a triangle"),
    )
    .expect("a robot")
}

fn best(problem: &Problem, settings: &AmmSettings, repeats: usize) -> f64 {
    (0..repeats)
        .map(|_| {
            let t = std::time::Instant::now();
            flexstar_amm::solve(problem, settings, SolveRequest::motion()).expect("a run");
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let repeats = std::env::args().nth(1).map_or(7, |a| a.parse().expect("a count"));
    let paper = paper_case(3).problem().expect("case 3");
    let equal = paper.with_robot(robot(false)).expect("equal beams as built");
    let unequal = paper.with_robot(robot(true)).expect("a robot as built");
    for (name, settings) in [
        (
            "free-free, paper, N = 25",
            AmmSettings {
                dt: Some(flexstar_amm::TOLERANCE_DT),
                ..AmmSettings::paper(ModeFamily::FreeFree, 25)
            },
        ),
        (
            "enriched, full, N = 53",
            AmmSettings {
                modes: Some(53),
                dt: Some(flexstar_amm::TOLERANCE_DT),
                ..AmmSettings::accurate()
            },
        ),
    ] {
        let a = best(&paper, &settings, repeats);
        let b = best(&equal, &settings, repeats);
        let c = best(&unequal, &settings, repeats);
        println!(
            "{name}: paper {:.2} ms, equal beams as built {:.2} ms ({:.2}x), unequal {:.2} ms ({:.2}x)",
            a * 1e3,
            b * 1e3,
            b / a,
            c * 1e3,
            c / a
        );
    }
}
