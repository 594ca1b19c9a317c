//! The truncation flexibility of the sleeves (`docs/amm.md` section 12), isolated on the first robot
//! of that section (short, light, sleeve-heavy; `tests/other_robots/robot1.toml`).
//!
//! Both runs take the FEM's step (1e-4 s), so the AMM's time error is out of the comparison and
//! what is left is its modal truncation and its model. Without the truncation flexibility the
//! accurate model at N = 46 was 1.20 % from this FEM and still 0.29 % at N = 100 (the slope under
//! the sleeve's couple converges like 1/N, Eq. R1); with it N = 33 and N = 100 agree to 0.001 %
//! and both are 0.035 % from the FEM (which is itself 0.047 % from 2400 elements at 5e-5 s).

use std::path::Path;

use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment};

const ROBOT1: &str = include_str!("other_robots/robot1.toml");

fn accurate_at(exp: &Experiment, n: usize) -> flexstar_model::Response {
    let settings = AmmSettings {
        modes: Some(n),
        dt: Some(1e-4),
        ..AmmSettings::accurate()
    };
    let problem = exp.problem().unwrap();
    flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap()
}

#[test]
fn truncation_flexibility_removes_the_truncation_at_the_sleeves() {
    let exp = Experiment::from_toml_str(ROBOT1, Path::new("robot1.toml")).unwrap();
    let problem = exp.problem().unwrap();
    let fem = flexstar_fem::solve(&problem, &exp.fem, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let (coarse, fine) = (accurate_at(&exp, 33), accurate_at(&exp, 100));
    let between = point_evps(&coarse, &fine).unwrap().mean.unwrap();
    let e33 = point_evps(&coarse, &fem).unwrap();
    let e100 = point_evps(&fine, &fem).unwrap();
    eprintln!(
        "N = 33 vs 100: {between:.4} %; vs FEM: N = 33 {:?}, N = 100 {:?}",
        e33, e100
    );
    // truncation: N = 46 and 100 differed by 0.9 % without the term
    assert!(between < 0.01, "N = 33 against N = 100: {between} %");
    for e in [e33, e100] {
        assert!(e.mean.unwrap() < 0.1, "mean EVP against the FEM {:?}", e.mean);
        assert!(e.points.iter().flatten().all(|p| *p < 0.15), "{:?}", e.points);
    }
}
