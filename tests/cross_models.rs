//! Cross-model check on two motions of our own (`docs/amm.md` sections 8-9), away from the paper's four cases:
//!
//! - `smooth`: a slow rest-to-rest task-space quintic (G moves 14 mm and turns 0.06 rad in 0.3 s,
//!   then rests), tips ~ 3 mm: the small-deflection regime in which the linear AMM holds, with a
//!   general behaviour of G (it translates and turns), where no paper family is right;
//! - `brisk`: a faster quintic turning the other way (G moves 10 mm and turns -0.06 rad in 0.2 s)
//!   followed by 0.2 s of free vibration: the residual vibration after a stop, which is what an
//!   input shaper or a trajectory planner cares about. Its amplitude keeps the tips below ~1 cm
//!   (2 % of L), like the paper's cases; scaled up (2, 2.5, 4, 6 times: tips 22 to 82 mm) the AMM
//!   stays 0.14-0.85 % off on average and 0.2-1.0 % at G since the full model carries the
//!   foreshortening inertia of the bent beams (`docs/amm.md` section 8; without it, 8.6 % at G at
//!   2.5 times). The test at twice the amplitude guards that term.
//!
//! On both, flexstar's accurate reduced model (enriched family, full model, automatic N at the
//! default tolerance) must agree with the independent FEM within the targets (mean EVP over
//! A, B, C, G at most 1 %, no point above 2 %), its own error estimate must be within a factor of
//! two of that true EVP, and the driving forces must agree while the robot moves.

use flexstar_solve::Settings;
use std::path::Path;

use flexstar_compare::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, FemSettings};

/// The two motions, as in `configs/motions/` (runnable with `flexstar run`).
const SMOOTH: &str = include_str!("../configs/motions/smooth.toml");
const BRISK: &str = include_str!("../configs/motions/brisk.toml");

/// Bounds of one check: mean EVP, largest point EVP, largest ratio between estimate and truth.
struct Bounds {
    mean: f64,
    point: f64,
    ratio: f64,
}

/// The accurate model's targets (`docs/validation.md` section 1).
const TARGETS: Bounds = Bounds {
    mean: 1.0,
    point: 2.0,
    ratio: 2.0,
};

fn check(text: &str, t_move: f64, bounds: Bounds) {
    let exp = Experiment::from_toml_str(text, Path::new("own.toml")).unwrap();
    let problem = exp.problem().unwrap();
    let fem = flexstar_solve::response(&problem, Settings::Fem(&FemSettings::default()), None, None).unwrap();
    let amm = flexstar_solve::response(&problem, Settings::Amm(&AmmSettings::accurate()), None, None).unwrap();
    let e = point_evps(&amm, &fem).unwrap();
    let mean = e.mean.expect("the tips move");
    let estimate = amm
        .info
        .error_estimate_percent
        .expect("automatic N reports an estimate");
    eprintln!(
        "{}: N = {:?}, estimate {estimate:.3} %, EVP A/B/C/G = {:?}, mean {mean:.3} %",
        exp.name, amm.info.modes, e.points
    );
    assert!(mean <= bounds.mean, "{}: mean EVP {mean} %", exp.name);
    for (p, v) in ["A", "B", "C", "G"].iter().zip(&e.points) {
        if let Some(v) = v {
            assert!(*v <= bounds.point, "{}: point {p}: EVP {v} %", exp.name);
        }
    }
    assert!(
        estimate <= bounds.ratio * mean && mean <= bounds.ratio * estimate,
        "{}: estimate {estimate} % against the true {mean} %",
        exp.name
    );
    // driving forces while the robot moves: RMS difference below 2 % of the largest RMS force
    let moving = fem.t.iter().filter(|t| **t <= t_move + 1e-12).count();
    let rms = |v: &mut dyn Iterator<Item = f64>| (v.map(|x| x * x).sum::<f64>() / moving as f64).sqrt();
    let scale = (0..3)
        .map(|i| rms(&mut fem.fa[i][..moving].iter().copied()))
        .fold(0.0, f64::max);
    for i in 0..3 {
        let d = rms(&mut amm.fa[i][..moving].iter().zip(&fem.fa[i][..moving]).map(|(a, b)| a - b));
        eprintln!(
            "{}: Fa{} RMS difference {:.2} % of {scale:.3} N",
            exp.name,
            i + 1,
            d / scale * 100.0
        );
        assert!(
            d < 0.02 * scale,
            "{}: Fa{}: RMS difference {d:.4} N against {scale:.4} N",
            exp.name,
            i + 1
        );
    }
}

#[test]
fn accurate_amm_agrees_with_fem_on_a_smooth_motion() {
    check(SMOOTH, 0.3, TARGETS);
}

#[test]
fn accurate_amm_agrees_with_fem_on_a_brisk_motion_and_its_residual_vibration() {
    // Measured (defaults, tolerance step 5e-4 s): mean 0.17 %, tips 0.16-0.17 %, G 0.19 %,
    // estimate 0.21 % (ratio 1.24). Before the foreshortening inertia of the full model
    // (docs/amm.md section 8): G 2.36 %, estimate 2.2 times too small.
    check(BRISK, 0.2, TARGETS);
}

#[test]
fn foreshortening_inertia_holds_at_twice_brisks_amplitude() {
    // Isolates the full model's foreshortening term: a model error linear in the deflection keeps
    // its relative size when the motion is scaled, a second-order one grows with it. `brisk` with
    // its displacement doubled (tips 22 mm, 4.4 % of L): without the term the AMM is 5.7 % off
    // the FEM at G (0.35 / 0.99 / 2.35 / 5.7 % at scales 1/4, 1/2, 1, 2); with it 0.34 % (flat in
    // the scale: 0.35 / 0.36 / 0.24 / 0.34 %). Bound: the point target, at N = 53 (the N
    // the default tolerance chooses for brisk) to keep the test short.
    let mut exp = Experiment::from_toml_str(BRISK, Path::new("brisk.toml")).unwrap();
    if let flexstar_model::Trajectory::Quintic { to, .. } = &mut exp.trajectory {
        to.gx *= 2.0;
        to.gy *= 2.0;
        to.theta *= 2.0;
    } else {
        panic!("brisk is a quintic");
    }
    let problem = exp.problem().unwrap();
    let fem = flexstar_solve::response(&problem, Settings::Fem(&FemSettings::default()), None, None).unwrap();
    let settings = AmmSettings {
        modes: Some(53),
        ..AmmSettings::accurate()
    };
    let amm = flexstar_solve::response(&problem, Settings::Amm(&settings), None, None).unwrap();
    let e = point_evps(&amm, &fem).unwrap();
    eprintln!("brisk x 2: EVP A/B/C/G = {:?}", e.points);
    let g = e.points[3].expect("G moves");
    assert!(g <= 1.0, "G: {g} %");
    assert!(e.mean.unwrap() <= TARGETS.mean, "mean {:?}", e.mean);
}
