//! The accurate AMM against the independent FEM (default settings) on one experiment, judged by
//! the EVPs of Eq. 45 over A, B, C and G: shared by the cross-model tests.

use std::path::Path;

use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, FemSettings, Response};
use flexstar_solve::Settings;

/// Mean EVP [%] over the points and each point's EVP [%] (A, B, C, G; `None` where a point does
/// not move).
pub struct Agreement {
    pub mean: f64,
    pub points: [Option<f64>; 4],
}

impl Agreement {
    /// Assert the mean at most `mean_max` [%] and no point above `point_max` [%].
    pub fn assert_within(&self, name: &str, mean_max: f64, point_max: f64) {
        assert!(self.mean <= mean_max, "{name}: mean EVP {} %", self.mean);
        for (p, v) in ["A", "B", "C", "G"].iter().zip(self.points) {
            if let Some(v) = v {
                assert!(v <= point_max, "{name}: point {p}: EVP {v} %");
            }
        }
    }
}

/// Solve `exp` with the FEM's defaults and the accurate AMM, and print the agreement with the
/// AMM's N and error estimate (labelled `name`).
pub fn amm_against_fem(exp: &Experiment, name: &str) -> Agreement {
    let (amm, fem) = solve_both(exp);
    let e = point_evps(&amm, &fem).unwrap();
    let mean = e.mean.expect("the tips move");
    eprintln!(
        "{name}: N = {:?}, estimate {:?} %, EVP A/B/C/G = {:?}, mean {mean:.3} %",
        amm.info.modes, amm.info.error_estimate_percent, e.points
    );
    Agreement { mean, points: e.points }
}

/// `exp` solved by the accurate AMM and by the FEM at its defaults: `(amm, fem)`.
pub fn solve_both(exp: &Experiment) -> (Response, Response) {
    let problem = exp.problem().unwrap();
    let fem = flexstar_solve::response(&problem, Settings::Fem(&FemSettings::default()), None, None).unwrap();
    let amm = flexstar_solve::response(&problem, Settings::Amm(&AmmSettings::accurate()), None, None).unwrap();
    (amm, fem)
}

/// The experiment of a motion file's text `base` followed by the sections `sections`.
pub fn experiment(base: &str, sections: &str, source: &str) -> Experiment {
    Experiment::from_toml_str(&format!("{base}\n{sections}"), Path::new(source)).unwrap()
}
