//! The table of a validation envelope (`docs/validation.md` sections 8 and 9) from a study's
//! results: which cases lie in the small-deflection range (`flexstar_study::in_range`, the AMM
//! run of each case checked as `flexstar run` checks it), and on those, per motion, the mean EVP
//! (median, 90 %, largest), the largest point EVP and the error estimate over the mean EVP
//! (median, smallest, largest, how many below 1/2 and above 2); then the worst cases by run id.
//!
//! `cargo run --release -p flexstar-study --example envelope_table -- STUDY.toml RESULTS.csv [rows]`
//! (`rows`: also every in-range case, one line each).

use std::path::Path;

use flexstar_study::report::quantile;
use flexstar_study::table::Table;
use flexstar_study::Study;
use rayon::prelude::*;

/// One AMM row of an in-range case.
struct Row {
    id: String,
    motion: String,
    mean: f64,
    largest: f64,
    ratio: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (study, results, all_rows) = match args.as_slice() {
        [_, s, r] => (s, r, false),
        [_, s, r, rows] if rows == "rows" => (s, r, true),
        _ => {
            eprintln!("usage: envelope_table STUDY.toml RESULTS.csv [rows]");
            std::process::exit(2);
        }
    };
    let study = Study::load(Path::new(study)).unwrap_or_else(|e| fail(e.to_string()));
    let table = Table::read(Path::new(results)).unwrap_or_else(|e| fail(e.to_string()));
    let col = |name: &str| {
        table
            .column(name)
            .unwrap_or_else(|| fail(format!("{results}: no column {name}")))
    };
    let (solver, status, motion) = (col("solver"), col("status"), col("derived.motion"));
    let (mean, largest, estimate) = (
        col("evp_percent"),
        col("evp_max_percent"),
        col("error_estimate_percent"),
    );
    let cases = study.cases();
    let amm: Vec<&Vec<String>> = table.rows.iter().filter(|r| r[solver] == "amm").collect();
    let checked: Vec<(Option<Row>, Option<String>)> = amm
        .par_iter()
        .map(|r| {
            let Some(case) = cases.iter().find(|c| c.run_id == r[0]) else {
                return (None, Some(format!("{}: not a case of the study", r[0])));
            };
            if r[status] != "ok" {
                return (None, Some(format!("{}: {}", r[0], r[status])));
            }
            let exp = study.experiment(&case.values).unwrap_or_else(|e| fail(e));
            match flexstar_study::in_range::small_deflection(&exp) {
                Ok(None) => {
                    let num = |c: usize| r[c].parse::<f64>().unwrap_or(f64::NAN);
                    let row = Row {
                        id: r[0].clone(),
                        motion: r[motion].clone(),
                        mean: num(mean),
                        largest: num(largest),
                        ratio: num(estimate) / num(mean),
                    };
                    (Some(row), None)
                }
                Ok(Some(v)) => (
                    None,
                    Some(format!(
                        "out of range: {} peak {:.3} (bound {})",
                        v.quantity, v.peak, v.bound
                    )),
                ),
                Err(e) => (None, Some(format!("{}: {e}", r[0]))),
            }
        })
        .collect();
    let rows: Vec<&Row> = checked.iter().filter_map(|(r, _)| r.as_ref()).collect();
    println!("{} AMM rows, {} in range", amm.len(), rows.len());
    let mut outside: std::collections::BTreeMap<String, usize> = Default::default();
    for why in checked.iter().filter_map(|(_, w)| w.as_ref()) {
        let key = why.split(" peak").next().unwrap_or(why).to_string();
        *outside.entry(key).or_default() += 1;
    }
    for (why, n) in &outside {
        println!("  {n} x {why}");
    }
    println!("| motion (in range) | mean EVP: median / 90 % / largest | largest point | estimate / EVP: median, smallest, largest | below 1/2 | above 2 |");
    for m in ["polynomial", "quintic"] {
        let of: Vec<&&Row> = rows.iter().filter(|r| r.motion == m).collect();
        let total = amm.iter().filter(|r| r[motion] == m).count();
        if of.is_empty() {
            println!("| {m} (0 of {total}) | | | | | |");
            continue;
        }
        let sorted = |f: fn(&Row) -> f64| {
            let mut v: Vec<f64> = of.iter().map(|r| f(r)).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (means, points, ratios) = (sorted(|r| r.mean), sorted(|r| r.largest), sorted(|r| r.ratio));
        println!(
            "| {m} ({} of {total}) | {:.3} / {:.3} / {:.3} % | {:.3} % | {:.2}, {:.2}, {:.2} | {} | {} |",
            of.len(),
            quantile(&means, 0.5),
            quantile(&means, 0.9),
            means[means.len() - 1],
            points[points.len() - 1],
            quantile(&ratios, 0.5),
            ratios[0],
            ratios[ratios.len() - 1],
            ratios.iter().filter(|x| **x < 0.5).count(),
            ratios.iter().filter(|x| **x > 2.0).count()
        );
    }
    if all_rows {
        for r in &rows {
            println!(
                "row {} {} {:.4} {:.4} {:.3}",
                r.id, r.motion, r.mean, r.largest, r.ratio
            );
        }
    }
    let mut by_mean: Vec<&&Row> = rows.iter().collect();
    by_mean.sort_by(|a, b| b.mean.total_cmp(&a.mean));
    println!("worst mean EVP:");
    for r in by_mean.iter().take(5) {
        println!(
            "  {} {}: mean {:.3} %, largest point {:.3} %, ratio {:.2}",
            r.id, r.motion, r.mean, r.largest, r.ratio
        );
    }
    let mut by_ratio: Vec<&&Row> = rows.iter().collect();
    by_ratio.sort_by(|a, b| a.ratio.total_cmp(&b.ratio));
    println!("ratio extremes:");
    for r in by_ratio.iter().take(3).chain(by_ratio.iter().rev().take(3)) {
        println!(
            "  {} {}: mean {:.3} %, largest point {:.3} %, ratio {:.2}",
            r.id, r.motion, r.mean, r.largest, r.ratio
        );
    }
}

fn fail(message: String) -> ! {
    eprintln!("{message}");
    std::process::exit(1)
}
