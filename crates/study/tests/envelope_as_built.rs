//! A subset of the validation envelope on robots as built (`configs/studies/envelope-as-built.toml`,
//! the seed-31 draw of `docs/validation.md` section 9) run in the test suite with that section's
//! targets.
//!
//! The cases are drawn by the study file itself (same Latin hypercube, same run ids): robots whose
//! beams differ by up to +-15 %, welds off by up to 3 degrees, an uneven base and gravity in the
//! plane, each run by the accurate AMM and by the refined FEM (`fem_reference = "refined"`, at the
//! stiffest beam's step), the independent reference. Nine of the 84 in-range cases of the draw:
//! eight polynomial motions, the cheapest of their kind, spanning gravity from none to 0.94 of its
//! cap, and the cheapest quintic. The draw's cases that miss the estimate's target (9 of 84: under
//! gravity near its cap, very short polynomial motions, and over-estimates where the deviations
//! lower the true error) are in `docs/validation.md` 9 with what was found; these nine meet all
//! three targets, and guard them.

use std::path::Path;

use flexstar_study::run::run_case;
use flexstar_study::Study;
use rayon::prelude::*;

/// Run ids of the chosen cases (`docs/validation.md` 9 gives the measured numbers).
const CHOSEN: [&str; 9] = [
    "40609f2caabd4f62", // polynomial, g share 0.52
    "3fe77fa6212b2b84", // polynomial, g share 0.01
    "0b3aec9660b0b7bf", // polynomial, g share 0.78
    "229228da07f207be", // polynomial, g share 0.58
    "1fb89761001721f3", // polynomial, g share 0.29
    "d81a765f7dabaf81", // polynomial, g share 0.80
    "cb18405d34220f24", // polynomial, g share 0.43
    "494513de1821a0de", // polynomial, g share 0.94
    "4cf8b271ed1287a4", // quintic, g share 0.86
];

#[test]
fn nine_as_built_cases_meet_the_evp_bounds_and_their_estimates_are_within_a_factor_two() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/studies/envelope-as-built.toml");
    let study = Study::load(&file).expect("the as-built envelope study loads");
    let cases: Vec<_> = study
        .cases()
        .into_iter()
        .filter(|c| CHOSEN.contains(&c.run_id.as_str()))
        .collect();
    assert_eq!(cases.len(), CHOSEN.len(), "every chosen run id is in the draw");
    let results: Vec<String> = cases
        .par_iter()
        .map(|case| {
            let exp = study.experiment(&case.values).expect("a valid case");
            let built = exp.robot.as_built.expect("a robot as built");
            assert!(
                built.beams[0].length != built.beams[1].length,
                "{}: beams differ",
                case.run_id
            );
            let range = flexstar_study::in_range::small_deflection(&exp).expect("the AMM run");
            assert!(
                range.is_none(),
                "{}: in the small-deflection range: {range:?}",
                case.run_id
            );
            let rows = run_case(&study, case);
            let row = rows.iter().find(|r| r.solver == "amm").expect("an AMM row");
            assert_eq!(row.status, "ok", "{}", case.run_id);
            let mean = row.evp_percent.expect("mean EVP against the refined FEM");
            let largest = row.evp_max_percent.expect("largest point EVP");
            let estimate = row.error_estimate_percent.expect("the automatic N's estimate");
            let ratio = estimate / mean;
            let line = format!(
                "{}: g = {:?}, mean {mean:.3} %, largest {largest:.3} %, estimate {estimate:.3} % ({ratio:.2})",
                case.run_id, exp.gravity.g
            );
            assert!(mean <= 1.0 && largest <= 2.0, "{line}");
            assert!((0.5..=2.0).contains(&ratio), "{line}");
            line
        })
        .collect();
    for line in results {
        eprintln!("{line}");
    }
}
