//! Wall time of one paper case at a given mesh, the minimum over repeated runs
//! (docs/fem.md section 6): on a shared machine the minimum is the figure least disturbed by other
//! work, and the work counters (steps, Newton iterations) turn it into a time per step and per
//! iteration. The criterion bench `paper_case` gives the distribution.
//!
//! ```text
//! fem_speed CASE ELEMENTS [RUNS]     # e.g. fem_speed 2 3000 5
//! ```

use std::process::ExitCode;
use std::time::Instant;

use flexstar_model::{catalogue, FemSettings};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parsed = (|| -> Option<(usize, usize, usize)> {
        let case = args.first()?.parse().ok()?;
        let elements = args.get(1)?.parse().ok()?;
        let runs = args.get(2).map_or(Some(3), |r| r.parse().ok())?;
        (1..=4).contains(&case).then_some((case, elements, runs.max(1)))
    })();
    let Some((case, elements, runs)) = parsed else {
        eprintln!("usage: fem_speed CASE(1-4) ELEMENTS [RUNS]");
        return ExitCode::from(2);
    };
    let exp = catalogue::paper_case(case);
    let settings = FemSettings {
        elements,
        ..exp.fem.clone()
    };
    let mut best = f64::INFINITY;
    let mut stats = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        let problem = exp.problem().unwrap();
        match flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
            .map(|s| (s.response, s.stats))
        {
            Ok((_, s)) => stats = Some(s),
            Err(e) => {
                eprintln!("case {case}, {elements} elements: {e}");
                return ExitCode::FAILURE;
            }
        }
        best = best.min(t0.elapsed().as_secs_f64());
    }
    let s = stats.expect("at least one run");
    println!(
        "case {case}, {elements} elements: min of {runs} runs {best:.4} s, {} steps ({:.1} us/step), {} Newton iterations ({:.1} us/iteration), {} factorisations, {} sparsity patterns",
        s.steps,
        1e6 * best / s.steps as f64,
        s.newton_iterations,
        1e6 * best / s.newton_iterations as f64,
        s.factorisations,
        s.symbolic_factorisations
    );
    ExitCode::SUCCESS
}
