//! How far the refined FEM, the reference of the validation envelopes, is from a finer one, on
//! chosen cases of a study (`docs/validation.md` 9): `cargo run --release -p flexstar-study
//! --example reference_check -- STUDY.toml ID [ID ...]` (run ids or unique prefixes).
//!
//! Per case: the accurate AMM's delivered run and its estimate; the refined FEM
//! (`flexstar_solve::reference_fem`: 4 x the elements, 1/8 of the step) and a finer FEM (twice
//! those elements, half that step); the mean EVP (Eq. 45) of the AMM against each, of the refined
//! FEM against the finer, and the estimate over the AMM's EVP against each.
use flexstar_metrics::evp::point_evps;
use flexstar_model::{Experiment, FemSettings, Response};
use flexstar_solve::Settings;
use std::path::Path;

/// Mean EVP (Eq. 45) of `a` against `b`, NaN where it has none.
fn evp(a: &Response, b: &Response) -> f64 {
    point_evps(a, b).ok().and_then(|e| e.mean).unwrap_or(f64::NAN)
}

/// One line of `exp` (see the module docs).
fn check(id: &str, exp: &Experiment) -> Result<String, String> {
    let problem = exp.problem().map_err(|e| e.to_string())?;
    let solve =
        |settings: Settings| flexstar_solve::response(&problem, settings, None, None).map_err(|e| e.to_string());
    let amm = solve(Settings::Amm(&exp.amm))?;
    let estimate = amm.info.error_estimate_percent.unwrap_or(f64::NAN);
    let refined = flexstar_solve::reference_fem(exp);
    let finer = FemSettings {
        elements: 2 * refined.elements,
        dt: refined.dt.map(|dt| dt / 2.0),
        ..refined.clone()
    };
    let (fem, fine) = (solve(Settings::Fem(&refined))?, solve(Settings::Fem(&finer))?);
    let (e_ref, e_fine) = (evp(&amm, &fem), evp(&amm, &fine));
    Ok(format!(
        "{id}: N = {:?}, estimate {estimate:.4} %; AMM against the refined FEM ({} elements) {e_ref:.4} % (ratio {:.2}), against {} elements at half its step {e_fine:.4} % (ratio {:.2}); refined against finer {:.4} %",
        amm.info.modes,
        refined.elements,
        estimate / e_ref,
        finer.elements,
        estimate / e_fine,
        evp(&fem, &fine)
    ))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, study, ids @ ..] = args.as_slice() else {
        eprintln!("usage: reference_check STUDY.toml ID [ID ...]");
        std::process::exit(2);
    };
    let study = flexstar_study::Study::load(Path::new(study)).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let base = study.file.parent().unwrap_or(Path::new(".")).join("case.toml");
    for case in study.cases() {
        let Some(id) = ids.iter().find(|i| case.run_id.starts_with(i.as_str())) else {
            continue;
        };
        let line = study
            .case_toml(&case.values)
            .map_err(|e| e.to_string())
            .and_then(|text| Experiment::from_toml_str(&text, &base).map_err(|e| e.to_string()))
            .and_then(|exp| check(&case.run_id, &exp));
        match line {
            Ok(l) => println!("{l}"),
            Err(e) => println!("{id}: {e}"),
        }
    }
}
