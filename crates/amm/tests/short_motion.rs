//! The accurate model's error estimate on motions too short for the estimate's coarse grid
//! (`docs/amm.md` 12.13): there the pairs run at the delivered step, and the estimate must still
//! carry the delivered run's time error (the time check at 2 h, Eq. T1). Reference independent of
//! the estimate: the same model refined, N = 80 at a sixteenth of the delivered step, against
//! which the delivered run's own discretisation error (truncation and step) is measured.

use flexstar_amm::adaptive::{estimate_grid, geometric_part};
use flexstar_drive::SolveRequest;
use flexstar_metrics::evp::point_evps;
use flexstar_model::{catalogue, AmmSettings, Experiment, Problem, Response};

/// The two envelope cases of `tests/short_motions/` (robots as built, polynomial motions of
/// 6.5 and 53 ms) and the paper's case 3 cut to 50 ms (the paper's robot, no gravity).
fn experiments() -> Vec<Experiment> {
    let read = |name: &str, text: &str| Experiment::from_toml_str(text, std::path::Path::new(name)).unwrap();
    let mut case3 = catalogue::paper_case(3);
    case3.time.t_end = 0.05;
    case3.amm = AmmSettings::default();
    vec![
        read(
            "stiff-light-6ms.toml",
            include_str!("short_motions/stiff-light-6ms.toml"),
        ),
        read("light-53ms.toml", include_str!("short_motions/light-53ms.toml")),
        case3,
    ]
}

fn solve(problem: &Problem, settings: &AmmSettings) -> Response {
    flexstar_amm::solve(problem, settings, SolveRequest::motion())
        .unwrap()
        .response
}

#[test]
fn the_estimate_of_a_short_motion_carries_the_delivered_steps_error() {
    for exp in experiments() {
        let problem = exp.problem().unwrap();
        let delivered = solve(&problem, &exp.amm);
        let (n, h) = (delivered.info.modes.unwrap(), delivered.info.dt);
        assert_eq!(
            estimate_grid(&problem, h),
            None,
            "{}: the span must be too short for the coarse grid",
            exp.name
        );
        let refined = AmmSettings {
            modes: Some(80.max(n)),
            dt: Some(h / 16.0),
            ..exp.amm.clone()
        };
        let truth = point_evps(&delivered, &solve(&problem, &refined))
            .unwrap()
            .mean
            .unwrap();
        // the estimate's discretisation parts (truncation and step); Eq. G1 is the model error
        // against the FEM, which the refined AMM does not see
        let estimate = delivered.info.error_estimate_percent.unwrap() - geometric_part(&problem, &delivered);
        let ratio = estimate / truth;
        eprintln!(
            "{}: N = {n}, h = {h:.3e} s: own error {truth:.4} %, estimate {estimate:.4} %, ratio {ratio:.2}",
            exp.name
        );
        assert!(
            truth > 0.01,
            "{}: the step must matter in this test: {truth} %",
            exp.name
        );
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{}: {estimate} % against {truth} %",
            exp.name
        );
    }
}
