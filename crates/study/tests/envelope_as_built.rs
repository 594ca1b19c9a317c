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

/// A sleeve that leaves its beam (`docs/validation.md` 9): case `407257b1` of the file's first
/// draw (seed 31), where sleeve 3's right edge reaches the tip of beam 3 during the motion. Both
/// solvers, each with its own model of the sleeve (the AMM's material point `xp - u + f`, the
/// FEM's contact coordinates), stop with the same sleeve and contact point just past the tip:
/// converged (the AMM at N = 60, the FEM at 1200 elements, both at 6.25e-5 s) within a few steps
/// of each other (the same 0.218188 s and 0.55274 m since the sleeve's slope row of Eq. S5,
/// `docs/amm.md` 12.17); at their defaults within the coarse steps of the AMM's automatic choice,
/// which may be the first of its runs to reach the tip (0.220 s against the FEM's 0.2183 s).
#[test]
fn both_solvers_stop_where_a_sleeve_leaves_its_beam() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/studies");
    let study = flexstar_study::Study::load(&path.join("envelope-as-built.toml")).expect("the study loads");
    let case = study
        .cases()
        .into_iter()
        .find(|c| c.run_id.starts_with("407257b1"))
        .expect("the case is in the seed-31 draw");
    let exp = study.experiment(&case.values).expect("a valid case");
    let problem = exp.problem().expect("a valid problem");
    let converged = (
        flexstar_model::AmmSettings {
            modes: Some(60),
            dt: Some(6.25e-5),
            ..flexstar_model::AmmSettings::accurate()
        },
        flexstar_model::FemSettings {
            elements: 1200,
            dt: Some(6.25e-5),
            ..flexstar_model::FemSettings::default()
        },
    );
    let defaults = (
        flexstar_model::AmmSettings::accurate(),
        flexstar_model::FemSettings::default(),
    );
    for ((amm, fem), (within_s, past_m)) in [(converged, (2e-4, 1e-4)), (defaults, (2.5e-3, 2e-3))] {
        let stop = |settings| match flexstar_solve::response(&problem, settings, None, None) {
            Err(flexstar_solve::SolveError::Amm(flexstar_amm::AmmError::SleeveOffBeam(off)))
            | Err(flexstar_solve::SolveError::Fem(flexstar_fem::FemError::SleeveOffBeam(off))) => off,
            other => panic!("a sleeve off its beam, not {other:?}"),
        };
        let (a, f) = (
            stop(flexstar_solve::Settings::Amm(&amm)),
            stop(flexstar_solve::Settings::Fem(&fem)),
        );
        eprintln!("AMM: {a}\nFEM: {f}");
        for off in [a, f] {
            assert_eq!((off.sleeve, off.point), (3, "right edge"), "{off}");
            assert!(off.xi > off.l && off.xi < off.l + past_m, "{off}");
        }
        assert!((a.t - f.t).abs() < within_s, "AMM at {} s, FEM at {} s", a.t, f.t);
        assert_eq!(a.l, f.l, "the same beam");
    }
}
