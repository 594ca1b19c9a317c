//! Per-beam keys of a study (`docs/studies.md`, "Per-beam keys"; `crates/study/src/key.rs`):
//! errors before any run, the three columns of a `per_beam` draw in a Latin hypercube, ties beam by
//! beam, a draw whose beams differ, and equal beams that are the paper's robot bit for bit.

use std::path::{Path, PathBuf};

use flexstar_model::{Experiment, RobotParams};
use flexstar_solve::Settings;
use flexstar_study::Study;

use crate::tiny_study;
use tiny_study::{write_study, BASE};

fn setup(top: &str, vary: &str) -> (tempfile::TempDir, PathBuf) {
    write_study(&format!(
        "name = \"s\"\nbase = \"base.toml\"\nsolvers = [\"amm\"]\n{top}{vary}"
    ))
}

fn load_err(top: &str, vary: &str) -> String {
    let (_d, p) = setup(top, vary);
    Study::load(&p).unwrap_err().to_string()
}

const RANDOM: &str = "sampling = \"random\"\nsamples = 4\n";

#[test]
fn per_beam_mistakes_are_refused_naming_the_file_and_the_key() {
    for (top, vary, needles) in [
        ("", "[[vary]]\nkey = \"robot.L[4]\"\nvalues = [0.5]\n", vec!["study.toml", "robot.L[4]", "beam index 4 is out of 1..3"]),
        ("", "[[vary]]\nkey = \"robot.L[0]\"\nvalues = [0.5]\n", vec!["robot.L[0]", "out of 1..3"]),
        ("", "[[vary]]\nkey = \"gravity.g[3]\"\nvalues = [1.0]\n", vec!["gravity.g[3]", "component index 3 is out of 1..2"]),
        ("", "[[vary]]\nkey = \"robot.d[2]\"\nvalues = [0.2]\n", vec!["robot.d[2]", "robot.d takes no index"]),
        ("", "[[vary]]\nkey = \"time.t_end[1]\"\nvalues = [0.2]\n", vec!["time.t_end takes no index"]),
        (RANDOM, "[[vary]]\nkey = \"gravity.g\"\nper_beam = true\nuniform = [0.0, 1.0]\n", vec!["study.toml", "gravity.g", "per_beam"]),
        (RANDOM, "[[vary]]\nkey = \"base.sides\"\nper_beam = true\nuniform = [0.6, 0.7]\n", vec!["base.sides", "per_beam"]),
        (RANDOM, "[[vary]]\nkey = \"robot.weld_deg\"\nper_beam = true\nuniform = [0.0, 1.0]\n", vec!["robot.weld_deg", "per_beam"]),
        (RANDOM, "[[vary]]\nkey = \"robot.L[2]\"\nper_beam = true\nuniform = [0.4, 0.5]\n", vec!["robot.L[2]", "without an index"]),
        (RANDOM, "[[vary]]\nkey = \"robot.L\"\nper_beam = true\nnormal = [0.5, 0.0]\n", vec!["robot.L", "sd > 0"]),
        (RANDOM, "[[vary]]\nkey = \"robot.L\"\nper_beam = true\nuniform = [0.5, 0.4]\n", vec!["robot.L", "lo < hi"]),
        (
            "",
            "[[vary]]\nkey = \"robot.L\"\nvalues = [0.5]\n[[vary]]\nkey = \"robot.L[2]\"\nvalues = [0.45]\n",
            vec!["robot.L[2]", "robot.L is also varied"],
        ),
        (
            "",
            "[[vary]]\nkey = \"base.sides[1]\"\nvalues = [0.6]\n[[vary]]\nkey = \"derived.d_share\"\nvalues = [0.5]\n",
            vec!["derived.d_share", "base.sides[1]", "derived.dev.sides"],
        ),
        // no default for the other beams to keep
        ("", "[[vary]]\nkey = \"robot.EA[2]\"\nvalues = [6e6]\n", vec!["robot.EA[2]", "sets no robot.EA"]),
        // ties: an unknown beam, a beam out of range, a whole key read while drawn per beam
        (
            RANDOM,
            "[[vary]]\nkey = \"robot.Lp[2]\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Jp[2]\"\nformula = \"robot.Lq[2] * 2\"\n",
            vec!["robot.Jp[2]", "robot.Lq[2]"],
        ),
        (
            RANDOM,
            "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Jp\"\nformula = \"robot.Lp[5]\"\n",
            vec!["robot.Jp", "robot.Lp[5]", "out of 1..3"],
        ),
        (
            RANDOM,
            "[[vary]]\nkey = \"robot.Lp\"\nper_beam = true\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"time.t_end\"\nformula = \"robot.Lp * 2\"\n",
            vec!["time.t_end", "name the beam, robot.Lp[1]"],
        ),
        (
            RANDOM,
            "[[vary]]\nkey = \"robot.Jp\"\nper_beam = true\nuniform = [1e-4, 2e-4]\n[[tie]]\nkey = \"robot.Jp\"\nformula = \"2e-4\"\n",
            vec!["robot.Jp", "both varied"],
        ),
        (
            RANDOM,
            "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Jp\"\nformula = \"robot.mpp_mpa[1]\"\n\
             [[tie]]\nkey = \"robot.mpp_mpa\"\nformula = \"robot.Jp * 1e3\"\n",
            vec!["cycle"],
        ),
    ] {
        let msg = load_err(top, vary);
        for n in needles {
            assert!(msg.contains(n), "{vary}: missing {n:?} in {msg}");
        }
    }
}

/// `per_beam = true` in a Latin hypercube: three columns `robot.L[1..3]`, each using every stratum
/// of its range once, on its own (the columns are not the same permutation), each beam's length in
/// the experiment the value of its column.
#[test]
fn a_per_beam_hypercube_stratifies_each_beam_on_its_own() {
    let n = 40;
    let (_d, p) = setup(
        &format!("sampling = \"lhs\"\nsamples = {n}\nseed = 3\n"),
        "[[vary]]\nkey = \"robot.L\"\nper_beam = true\nuniform = [0.45, 0.55]\n",
    );
    let study = Study::load(&p).unwrap();
    assert_eq!(study.keys(), ["robot.L[1]", "robot.L[2]", "robot.L[3]"]);
    let cases = study.cases();
    let strata = |j: usize| -> Vec<usize> {
        cases
            .iter()
            .map(|c| ((c.values[j].as_float().unwrap() - 0.45) / 0.1 * n as f64) as usize)
            .collect()
    };
    for j in 0..3 {
        let mut s = strata(j);
        s.sort();
        assert_eq!(s, (0..n).collect::<Vec<_>>(), "beam {}", j + 1);
    }
    assert!(
        strata(0) != strata(1) && strata(1) != strata(2),
        "independent permutations"
    );
    let c = &cases[0];
    let exp = study.experiment(&c.values).unwrap();
    let beams = exp.robot.as_built.expect("beams of their own").beams;
    for (b, v) in beams.iter().zip(&c.values) {
        assert_eq!(b.length, v.as_float().unwrap());
    }
}

/// A per-beam draw makes a robot whose beams differ, and a tie on the whole `robot.Jp` follows
/// each beam's drawn sleeve (the formula evaluated here per beam); the case runs and its row is
/// `ok`. Three equal entries are the paper's robot: the compact form, and the same response bit
/// for bit as the base experiment itself.
#[test]
fn per_beam_draws_differ_and_equal_entries_are_the_paper_robot_bit_for_bit() {
    let (_d, p) = setup(
        RANDOM,
        "[[vary]]\nkey = \"robot.Lp\"\nper_beam = true\nuniform = [0.025, 0.035]\n\
         [[vary]]\nkey = \"robot.weld_deg[2]\"\nuniform = [119.0, 121.0]\n\
         [[tie]]\nkey = \"robot.Jp\"\nformula = \"2e-4 * (robot.Lp / 0.03)^3\"\n",
    );
    let study = Study::load(&p).unwrap();
    for c in study.cases() {
        let exp = study.experiment(&c.values).unwrap();
        let a = exp.robot.as_built.expect("a robot as built");
        let lp = a.beams.map(|b| b.sleeve_length);
        assert!(lp[0] != lp[1] && lp[1] != lp[2], "{lp:?}");
        for b in a.beams {
            let want = 2e-4 * (b.sleeve_length / 0.03f64).powi(3);
            assert!(
                (b.sleeve_inertia / want - 1.0).abs() < 1e-10,
                "{} vs {want}",
                b.sleeve_inertia
            );
        }
        assert_eq!(a.beams[1].weld_angle, c.values[3].as_float().unwrap().to_radians());
        let rows = flexstar_study::run::run_case(&study, &c);
        assert_eq!(rows[0].status, "ok", "{:?}", rows[0]);
        assert!(rows[0].peak_tip_m.is_some_and(|t| t > 0.0));
    }

    let (_d, p) = setup(
        "",
        "[[vary]]\nkey = \"robot.L[1]\"\nvalues = [0.5]\n[[vary]]\nkey = \"robot.L[2]\"\nvalues = [0.5]\n\
         [[vary]]\nkey = \"robot.L[3]\"\nvalues = [0.5]\n[[vary]]\nkey = \"robot.weld_deg[3]\"\nvalues = [240.0]\n",
    );
    let study = Study::load(&p).unwrap();
    let case = &study.cases()[0];
    let exp = study.experiment(&case.values).unwrap();
    assert_eq!(exp.robot, RobotParams::paper(), "the compact form of the paper's robot");
    let base = Experiment::from_toml_str(BASE, Path::new("base.toml")).unwrap();
    let solve =
        |e: &Experiment| flexstar_solve::response(&e.problem().unwrap(), Settings::Amm(&e.amm), None, None).unwrap();
    let (a, b) = (solve(&exp), solve(&base));
    let bits = |r: &flexstar_model::Response| -> Vec<u64> {
        r.w_tip
            .iter()
            .chain(&r.w_g)
            .chain(&r.fa)
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
}
