//! Results-unchanged check of the FEM's speed work (docs/fem.md section 6): runs the four
//! paper cases at the default settings, with timings and work counters, and either writes their
//! responses to a baseline directory or compares them with one, column by column by EVP (Eq. 45).
//!
//! ```text
//! fem_check write   DIR   # DIR/case1.csv .. case4.csv from this build
//! fem_check compare DIR   # EVP of every tip, w_G and Fa column against DIR; exit 1 above 0.01 %
//! ```
//!
//! Columns whose reference is identically zero by symmetry (w_G of case 1, beam 3 of case 4: at
//! round-off level, below 1e-6 of the largest displacement, resp. force, column) have no EVP; for those the
//! largest absolute value of both runs is printed and must stay below that level.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use flexstar_model::response::RESPONSE_HEADER;
use flexstar_model::{catalogue, Experiment, Response};
use flexstar_numerics::measures::{evp, max_abs};

/// Largest EVP [%] allowed between a run and its baseline (docs/fem.md section 6).
const EVP_LIMIT: f64 = 0.01;
/// A column is "zero by symmetry" below this fraction of the largest column of its group.
const ZERO_LIMIT: f64 = 1e-6;

fn run(k: usize) -> (Experiment, Response, flexstar_fem::Stats, f64) {
    let exp = catalogue::paper_case(k);
    let t0 = Instant::now();
    let problem = exp.problem().unwrap();
    let (r, stats) = flexstar_fem::solve(&problem, &exp.fem, flexstar_drive::SolveRequest::motion())
        .map(|s| (s.response, s.stats))
        .unwrap_or_else(|e| panic!("case {k}: {e}"));
    (exp, r, stats, t0.elapsed().as_secs_f64())
}

/// The ten fixed columns of a response CSV written by [`Response::write_csv`].
fn read_fixed(path: &Path) -> Result<Vec<Vec<f64>>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or(format!("{}: empty", path.display()))?
        .split(',')
        .collect();
    if header.len() < RESPONSE_HEADER.len() || header[..RESPONSE_HEADER.len()] != RESPONSE_HEADER {
        return Err(format!("{}: not a response CSV (header {:?})", path.display(), header));
    }
    let mut cols = vec![Vec::new(); RESPONSE_HEADER.len()];
    for (n, line) in lines.enumerate() {
        for (c, cell) in line.split(',').take(RESPONSE_HEADER.len()).enumerate() {
            let v = cell
                .parse::<f64>()
                .map_err(|e| format!("{}: line {}, column {}: {e}", path.display(), n + 2, c + 1))?;
            cols[c].push(v);
        }
    }
    Ok(cols)
}

fn fixed(r: &Response) -> Vec<&[f64]> {
    let mut v: Vec<&[f64]> = vec![&r.t];
    for group in [&r.w_g, &r.w_tip, &r.fa] {
        v.extend(group.iter().map(|c| c.as_slice()));
    }
    v
}

/// Compare one case with its baseline; returns the worst EVP [%] and whether every check passed.
fn compare(k: usize, r: &Response, base: &[Vec<f64>]) -> (f64, bool) {
    let cols = fixed(r);
    let mut ok = base[0].len() == r.len() && base[0].iter().zip(&r.t).all(|(a, b)| (a - b).abs() < 1e-12);
    if !ok {
        println!("case {k}: output times differ from the baseline");
        return (f64::INFINITY, false);
    }
    let mut worst: f64 = 0.0;
    let mut cells = Vec::new();
    for c in 1..RESPONSE_HEADER.len() {
        let (test, reference) = (cols[c], &base[c]);
        let t = &base[0];
        // groups: displacements (w_G and tips), forces
        let group = if c <= 6 { 1..7 } else { 7..10 };
        let scale = group.map(|g| max_abs(&base[g])).fold(0.0, f64::max);
        let zero = ZERO_LIMIT * scale;
        if max_abs(reference) > zero {
            let e = evp(t, test, reference).unwrap_or(f64::INFINITY);
            worst = worst.max(e);
            ok &= e <= EVP_LIMIT;
            cells.push(format!("{e:.2e}"));
        } else {
            let m = max_abs(test).max(max_abs(reference));
            ok &= m <= zero;
            cells.push(format!("0 ({m:.0e})"));
        }
    }
    println!("| {k} | {} | {worst:.2e} |", cells.join(" | "));
    (worst, ok)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: fem_check write|compare DIR";
    let (mode, dir) = match (args.get(1).map(String::as_str), args.get(2)) {
        (Some(m @ ("write" | "compare")), Some(d)) => (m, PathBuf::from(d)),
        _ => {
            eprintln!("{usage}");
            return ExitCode::from(2);
        }
    };
    if mode == "compare" {
        println!("EVP [%] against {} (limit {EVP_LIMIT} %):", dir.display());
        println!("| case | {} | worst |", RESPONSE_HEADER[1..].join(" | "));
        println!("|---|{}---|", "---|".repeat(RESPONSE_HEADER.len() - 1));
    } else if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("{}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let mut all_ok = true;
    let mut timing = Vec::new();
    for k in 1..=4 {
        let (_, r, stats, secs) = run(k);
        let path = dir.join(format!("case{k}.csv"));
        if mode == "write" {
            if let Err(e) = r.write_csv(&path) {
                eprintln!("{e}");
                return ExitCode::FAILURE;
            }
        } else {
            match read_fixed(&path) {
                Ok(base) => all_ok &= compare(k, &r, &base).1,
                Err(e) => {
                    eprintln!("{e}");
                    return ExitCode::FAILURE;
                }
            }
        }
        timing.push((k, stats, secs));
    }
    println!("| case | time [s] | steps | Newton it. | it./step | ms/step | us/iteration | factorisations | symbolic | fallbacks |");
    for (k, s, secs) in timing {
        println!(
            "| {k} | {secs:.3} | {} | {} | {:.2} | {:.3} | {:.1} | {} | {} | {} |",
            s.steps,
            s.newton_iterations,
            s.newton_iterations as f64 / s.steps as f64,
            1e3 * secs / s.steps as f64,
            1e6 * secs / s.newton_iterations as f64,
            s.factorisations,
            s.symbolic_factorisations,
            s.sparse_fallbacks,
        );
    }
    if mode == "compare" {
        println!("{}", if all_ok { "PASS" } else { "FAIL" });
        if !all_ok {
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
