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

use crate::envelope_cases;
use envelope_cases::assert_chosen_meet_the_targets;

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
    assert_chosen_meet_the_targets("envelope-as-built.toml", &CHOSEN, |id, exp| {
        let built = exp.robot.as_built.as_ref().expect("a robot as built");
        assert!(built.beams[0].length != built.beams[1].length, "{id}: beams differ");
        format!("g = {:?}, ", exp.gravity.g)
    });
}
