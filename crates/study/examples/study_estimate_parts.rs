//! The accurate AMM's error estimate on every case of a study, split into its parts, beside the
//! features its model-error part may be read from (`docs/validation.md` 9):
//! `cargo run --release -p flexstar-study --example study_estimate_parts -- STUDY.toml IDS > parts.csv`,
//! IDS a file of run ids (or unique prefixes), one per line.
//!
//! Per case (one CSV row): the automatic choice's N, delivered step h and estimate; the time part
//! (Eq. T1 of `docs/amm.md` 12.10, the chosen N at 2 h against h), the geometric part (Eq. G1,
//! 12.9), the truncation part the estimate took (the rest); the direct truncation pair, N
//! against N + 25, at the estimate's coarse step (the delivered step where the span is too short
//! for its grid), at the time check's step 2 h and at h (both on the time check's grid); the
//! chosen N at 4 h against 2 h and 2 h against h on the 4 h run's grid (`e42`, `e21`: the time
//! error's observed order), and at h against h / 16 on the time check's grid (`own_time`); the
//! chosen N at h with gravity 1e-9 m/s^2 along X against none (`third`: the beams' third-order
//! terms, which only a run under gravity carries, on and off; `docs/amm.md` 12.14); and per
//! beam the largest elastic tip or junction displacement over its length,
//! `A_i / L_i`, its sleeve ratio `Lp_i / L_i` and its sleeve's inertia over its own about the
//! junction, `Jp_i / (rho_i L_i^3 / 3)`. The true error comes from the study's results.
use flexstar_amm::adaptive::{
    estimate_grid, geometric_part, time_check_grid, time_error_estimate, ESTIMATE_STEP_FACTOR,
};
use flexstar_metrics::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, Response};
use rayon::prelude::*;
use std::path::Path;

/// Modes the direct pair adds to the chosen N.
const PAIR_MODES: usize = 25;

/// Mean EVP (Eq. 45) of `a` against `b`, NaN where it has none.
fn evp(a: &Response, b: &Response) -> f64 {
    point_evps(a, b).ok().and_then(|e| e.mean).unwrap_or(f64::NAN)
}

/// The accurate AMM of `exp` at N = `modes` and step `step` [s], every `every`-th output time.
fn run(exp: &Experiment, modes: usize, step: f64, every: usize) -> Result<Response, String> {
    let mut e = exp.clone();
    e.time.dt_out = every as f64 * exp.time.dt_out;
    let settings = AmmSettings {
        modes: Some(modes),
        dt: Some(step),
        snapshots: Vec::new(),
        frames: 0,
        ..exp.amm.clone()
    };
    let problem = e.problem().map_err(|e| e.to_string())?;
    flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .map_err(|e| e.to_string())
}

/// One CSV row of `exp` (see the module docs).
fn parts(id: &str, exp: &Experiment) -> Result<String, String> {
    let problem = exp.problem().map_err(|e| e.to_string())?;
    let auto = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::motion())
        .map_err(|e| e.to_string())?
        .response;
    let n = auto.info.modes.ok_or("no N")?;
    let h = auto.info.dt;
    let estimate = auto.info.error_estimate_percent.ok_or("no estimate")?;
    let g1 = geometric_part(&problem, &auto);
    let check = time_check_grid(&problem, h);
    let delivered = run(exp, n, h, check)?;
    let at_check = run(exp, n, 2.0 * h, check)?;
    let time = time_error_estimate(evp(&at_check, &delivered));
    let direct_check = evp(&at_check, &run(exp, n + PAIR_MODES, 2.0 * h, check)?);
    let direct_h = evp(&delivered, &run(exp, n + PAIR_MODES, h, check)?);
    // the time error's order: the chosen N at 4 h, 2 h and h on the 4 h run's grid, and the
    // delivered run against h / 16 (its own time error) on the time check's grid
    let coarse = ((4.0 * h / exp.time.dt_out) - 1e-9).ceil().max(1.0) as usize;
    let (at_4h, at_2h, at_h) = (
        run(exp, n, 4.0 * h, coarse)?,
        run(exp, n, 2.0 * h, coarse)?,
        run(exp, n, h, coarse)?,
    );
    let (e42, e21) = (evp(&at_4h, &at_2h), evp(&at_2h, &at_h));
    let own_time = evp(&delivered, &run(exp, n, h / 16.0, check)?);
    let third = {
        let with_gravity = |g: [f64; 2]| {
            let mut e = exp.clone();
            e.gravity = flexstar_model::Gravity::new(g);
            run(&e, n, h, check)
        };
        evp(&with_gravity([1e-9, 0.0])?, &with_gravity([0.0, 0.0])?)
    };
    let (step, every) = match estimate_grid(&problem, h) {
        Some(every) => (ESTIMATE_STEP_FACTOR * h, every),
        None => (h, 1),
    };
    let direct = evp(&run(exp, n, step, every)?, &run(exp, n + PAIR_MODES, step, every)?);
    let largest = |h: &Vec<f64>| h.iter().fold(0.0f64, |m, w| m.max(w.abs()));
    let beams = problem.robot().beams();
    let per_beam: Vec<String> = (0..3)
        .map(|i| {
            let a = largest(&auto.w_tip[i]).max(largest(&auto.w_g[i])) / beams[i].length;
            let b = &beams[i];
            let own_inertia = b.mass_per_length * b.length.powi(3) / 3.0;
            format!(
                "{a:.6e},{:.5},{:.5}",
                b.sleeve_length / b.length,
                b.sleeve_inertia / own_inertia
            )
        })
        .collect();
    let g = problem.gravity();
    Ok(format!(
        "{id},{n},{h:.4e},{estimate:.6e},{time:.6e},{g1:.6e},{:.6e},{direct:.6e},{direct_check:.6e},{direct_h:.6e},{third:.6e},{e42:.6e},{e21:.6e},{own_time:.6e},{:.4},{}",
        estimate - time - g1,
        g[0].hypot(g[1]),
        per_beam.join(",")
    ))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, study, ids] = args.as_slice() else {
        eprintln!("usage: study_estimate_parts STUDY.toml IDS");
        std::process::exit(2);
    };
    let study = flexstar_study::Study::load(Path::new(study)).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let ids: Vec<String> = std::fs::read_to_string(ids)
        .unwrap_or_else(|e| {
            eprintln!("{ids}: {e}");
            std::process::exit(1)
        })
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(String::from)
        .collect();
    let cases: Vec<_> = study
        .cases()
        .into_iter()
        .filter(|c| ids.iter().any(|i| c.run_id.starts_with(i.as_str())))
        .collect();
    let base = study.file.parent().unwrap_or(Path::new(".")).join("case.toml");
    let rows: Vec<String> = cases
        .par_iter()
        .map(|case| {
            let row = study
                .case_toml(&case.values)
                .map_err(|e| e.to_string())
                .and_then(|text| Experiment::from_toml_str(&text, &base).map_err(|e| e.to_string()))
                .and_then(|exp| parts(&case.run_id, &exp));
            row.unwrap_or_else(|e| format!("{},error: {}", case.run_id, e.replace(',', ";")))
        })
        .collect();
    println!("id,n,h,estimate,time,g1,truncation,direct,direct_check,direct_h,third,e42,e21,own_time,g,a1,r1,j1,a2,r2,j2,a3,r3,j3");
    for row in rows {
        println!("{row}");
    }
}
