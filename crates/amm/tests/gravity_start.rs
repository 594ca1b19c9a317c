//! The start of a run under gravity (`docs/as-built.md` 5, Eq. G4): the robot rests before the
//! motion, in the static equilibrium of gravity alone at the start pose, whatever the motion's
//! initial acceleration. A polynomial motion starts accelerating (`s = a/2 t^2`); its initial
//! inertia is a load of the motion, not of the sag it starts from.
//!
//! Checked two ways: the deflections at t = 0 are those of the same pose held still (a motion with
//! no acceleration, whose start is the static equilibrium by definition), and the run follows the
//! FEM's, which starts from gravity alone (`docs/fem.md` 9.5). The robot and motion are a case of
//! `configs/studies/envelope-as-built.toml` (a short, brisk polynomial motion under a mostly
//! horizontal gravity), where the start from the quasi-static equilibrium with the initial
//! inertia put the AMM 73 % (mean EVP) from the FEM.

use flexstar_model::{AmmSettings, Experiment, FemSettings, Response};

fn amm(exp: &Experiment, settings: &AmmSettings) -> Response {
    flexstar_amm::solve(
        &exp.problem().unwrap(),
        settings,
        flexstar_drive::SolveRequest::motion(),
    )
    .unwrap()
    .response
}

/// Eq. 45 on the output grid: `int |a - b| dt / int |b| dt` [%].
fn evp(t: &[f64], a: &[f64], b: &[f64]) -> f64 {
    flexstar_numerics::measures::evp(t, a, b).unwrap()
}

const ROBOT: &str = "[robot]\nI = 2.70404455976e-12\nJp = 2.22029057929e-4\nL = 0.367571088858\n\
                     Lp = 0.0197631146118\nd = 0.166149002737\nmpp_mpa = 0.14799538573\nrho = 0.225543425742\n\
                     [gravity]\ng = [8.51628497405, -2.5350931033]\n";

fn experiment(s1: &str, s3: &str) -> Experiment {
    let text = format!(
        "name = \"start\"\n{ROBOT}[time]\nt_end = 0.0585320015431\ndt_out = 0.001\n\
         [trajectory]\nkind = \"polynomial\"\ns1 = {s1}\ns2 = [0.0]\ns3 = {s3}\n"
    );
    Experiment::from_toml_str(&text, std::path::Path::new("start.toml")).unwrap()
}

#[test]
fn a_motion_that_starts_accelerating_starts_from_the_sag_of_gravity_alone() {
    let settings = AmmSettings {
        modes: Some(30),
        ..AmmSettings::accurate()
    };
    let moving = experiment("[0.0, 0.0, 10.7288850948]", "[0.0, 0.0, 5.36444254738]");
    let still = experiment("[0.0]", "[0.0]");
    let r = amm(&moving, &settings);
    let rest = amm(&still, &settings);
    let scale = (0..3).map(|i| rest.w_tip[i][0].abs()).fold(0.0, f64::max);
    assert!(scale > 1e-3, "gravity sags the tips: {scale} m");
    for i in 0..3 {
        let (start, held) = (r.w_tip[i][0], rest.w_tip[i][0]);
        assert!(
            (start - held).abs() <= 1e-9 * scale,
            "tip {}: {start} m at t = 0, {held} m held still",
            i + 1
        );
        assert!((r.w_g[i][0] - rest.w_g[i][0]).abs() <= 1e-9 * scale);
    }
    let fem = flexstar_fem::solve(
        &moving.problem().unwrap(),
        &FemSettings::default(),
        flexstar_drive::SolveRequest::motion(),
    )
    .unwrap()
    .response;
    for i in 0..3 {
        let e = evp(&r.t, &r.w_tip[i], &fem.w_tip[i]);
        eprintln!("tip {}: EVP against the FEM {e:.3} %", i + 1);
        assert!(e < 1.0, "tip {}: EVP {e} % against the FEM", i + 1);
    }
}
