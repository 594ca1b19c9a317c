//! The validation envelope's subset runner, shared by the envelope tests: chosen cases of a study
//! file (drawn by the file itself: same Latin hypercube, same run ids), each run by the accurate
//! AMM and by the study's reference FEM, asserting the targets of `docs/validation.md` 8-9: mean
//! EVP at most 1 %, largest point at most 2 %, the AMM's error estimate within [0.5, 2] of its
//! true mean EVP.

use std::path::Path;

use flexstar_model::Experiment;
use flexstar_study::run::run_case;
use flexstar_study::Study;
use rayon::prelude::*;

/// Runs the cases `chosen` (run ids) of `configs/studies/<file>` in parallel and asserts, for
/// each, that it lies in the small-deflection range (the program's own check,
/// `flexstar_study::in_range`) and meets the three targets. `describe` checks what the case must
/// be (a robot as built, ...) and names it for the line printed per case.
pub fn assert_chosen_meet_the_targets(
    file: &str,
    chosen: &[&str],
    describe: impl Fn(&str, &Experiment) -> String + Sync,
) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/studies")
        .join(file);
    let study = Study::load(&path).expect("the study loads");
    let cases: Vec<_> = study
        .cases()
        .into_iter()
        .filter(|c| chosen.contains(&c.run_id.as_str()))
        .collect();
    assert_eq!(cases.len(), chosen.len(), "every chosen run id is in the draw");
    let lines: Vec<String> = cases
        .par_iter()
        .map(|case| {
            let exp = study.experiment(&case.values).expect("a valid case");
            let what = describe(&case.run_id, &exp);
            let range = flexstar_study::in_range::small_deflection(&exp).expect("the AMM run");
            assert!(
                range.is_none(),
                "{}: in the small-deflection range: {range:?}",
                case.run_id
            );
            let rows = run_case(&study, case);
            let row = rows.iter().find(|r| r.solver == "amm").expect("an AMM row");
            assert_eq!(row.status, "ok", "{}", case.run_id);
            let mean = row.evp_percent.expect("mean EVP against the reference FEM");
            let largest = row.evp_max_percent.expect("largest point EVP");
            let estimate = row.error_estimate_percent.expect("the automatic N's estimate");
            let ratio = estimate / mean;
            let line = format!(
                "{}: {what}mean {mean:.3} %, largest {largest:.3} %, estimate {estimate:.3} % ({ratio:.2})",
                case.run_id
            );
            assert!(mean <= 1.0 && largest <= 2.0, "{line}");
            assert!((0.5..=2.0).contains(&ratio), "{line}");
            line
        })
        .collect();
    for line in lines {
        eprintln!("{line}");
    }
}
