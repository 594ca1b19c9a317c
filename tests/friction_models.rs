//! Friction in the rigid limit (`docs/friction.md` 4): the beams stiffened, both solvers'
//! actuator forces with Coulomb friction in the sleeves should tend to those of an independent
//! rigid-body model with friction (`support/rigid_friction.rs`: Newton-Euler with the normal
//! forces as unknowns), on the smooth quintic (`configs/motions/smooth.toml`: a step of jerk, whose
//! vibration's force falls as the stiffness rises) in a vertical plane (the sleeves carry the
//! star's weight, so friction is a large share of the forces). Without friction the reference
//! equals the rigid inverse dynamics of `flexstar_kinematics` to the last digits (checked while
//! writing it).

use std::path::Path;

use flexstar_kinematics::RigidState;
use flexstar_model::{AmmSettings, Experiment, FemSettings};
use flexstar_solve::Settings;

#[path = "support/rigid_friction.rs"]
mod rigid_friction;

const SMOOTH: &str = include_str!("../configs/motions/smooth.toml");

/// The sleeves' coefficient.
const MU: f64 = 0.3;

/// `(gap, friction share)`: the largest |Fa - Fa_rigid| over the sliders and the output times
/// where every sleeve slides (|xp_i'| > 1 mm/s), relative to the largest |Fa_rigid| there; and
/// the largest change friction makes to the rigid forces, relative to the same, for the beams'
/// E times `stiff`.
fn gap(solver: &str, stiff: f64) -> (f64, f64) {
    let text = format!(
        "{SMOOTH}\n[robot]\nE = {}\n[friction]\nmu = {MU}\n[gravity]\ng = [0.0, -9.81]\n",
        200e9 * stiff
    );
    let exp = Experiment::from_toml_str(&text, Path::new("stiff.toml")).unwrap();
    let problem = exp.problem().unwrap();
    let r = match solver {
        "amm" => {
            let settings = AmmSettings {
                modes: Some(12),
                dt: Some(1e-4),
                ..AmmSettings::accurate()
            };
            flexstar_solve::response(&problem, Settings::Amm(&settings), None, None).unwrap()
        }
        _ => {
            let settings = FemSettings {
                elements: 120,
                dt: Some(1e-4),
                ..FemSettings::default()
            };
            flexstar_solve::response(&problem, Settings::Fem(&settings), None, None).unwrap()
        }
    };
    let g = [0.0, -9.81];
    let (mut worst, mut scale, mut share) = (0.0f64, 0.0f64, 0.0f64);
    for (k, &t) in r.t.iter().enumerate() {
        let st = RigidState::at(&exp.robot, problem.trajectory(), t).unwrap();
        if st.xp.iter().any(|x| x.d1.abs() < 1e-3) {
            continue;
        }
        let Some(rigid) = rigid_friction::rigid_forces_with_friction(&exp.robot, &st, g, MU) else {
            continue;
        };
        let bare = rigid_friction::rigid_forces_with_friction(&exp.robot, &st, g, 0.0).unwrap();
        for i in 0..3 {
            worst = worst.max((r.fa[i][k] - rigid[i]).abs());
            scale = scale.max(rigid[i].abs());
            share = share.max((rigid[i] - bare[i]).abs());
        }
    }
    (worst / scale, share / scale)
}

/// Fails today in both solvers (`docs/friction.md` 6, "the rigid limit"): measured 2026-12-06,
/// the FEM's gap grows with the stiffness, 0.22, 0.73 and 2.8 for E x 1, 10, 100 (friction's
/// share 0.16): the stiff star chatters between stick and slip (40-70 switches per sleeve in
/// 0.4 s), its sleeves' sliding speed reaching metres per second with the robot at rest, the
/// same at a tenth of the step; the AMM alike, and singular at E x 1e4. Run it with
/// `cargo test --release -p flexstar-tests --test friction_models -- --ignored`.
#[test]
#[ignore = "the stiff limit with friction is not reached by either solver yet: docs/friction.md 6"]
fn stiff_beams_with_friction_tend_to_the_rigid_model_with_friction() {
    for solver in ["amm", "fem"] {
        let gaps: Vec<(f64, f64)> = [1.0, 1e1, 1e2].iter().map(|&s| gap(solver, s)).collect();
        eprintln!("{solver}: E x 1, 10, 1e2: (gap, friction's share) {gaps:?}");
        let (last, share) = gaps[2];
        assert!(share > 0.05, "{solver}: friction must matter here: {share}");
        assert!(last < 0.1 * share, "{solver}: {gaps:?}");
        assert!(
            gaps[2].0 < gaps[0].0,
            "{solver}: shrinking with the stiffness: {gaps:?}"
        );
    }
}
