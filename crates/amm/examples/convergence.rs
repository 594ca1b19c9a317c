//! Convergence study of `docs/amm.md`: EVP (Eq. 45) between step h and h/2, and between N and 2N,
//! for the paper's four cases and three families.
//!
//! `cargo run --release -p flexstar-amm --example convergence [step|modes|paper-n|amplitudes]`
//! (`AMM_N` sets N for the step study, `AMM_STEPS` a comma-separated list of steps.)
#[path = "../tests/common/mod.rs"]
mod common;

use flexstar_model::{ModeFamily, Response};

/// EVP of every tip and of w_iG between two responses; "-" where the reference is ~0 by symmetry.
fn row(a: &Response, b: &Response) -> (Vec<String>, f64) {
    let scale = (0..3).map(|i| common::max_abs(&b.w_tip[i])).fold(0.0, f64::max);
    let mut cells = Vec::new();
    let mut worst = 0.0f64;
    for (x, y) in a.w_tip.iter().zip(&b.w_tip).chain(a.w_g.iter().zip(&b.w_g)) {
        if common::max_abs(y) < 1e-6 * scale {
            cells.push("~0".to_string());
        } else {
            let e = common::evp(x, y);
            worst = worst.max(e);
            cells.push(format!("{e:.4}"));
        }
    }
    (cells, worst)
}

fn main() {
    let what = std::env::args().nth(1).unwrap_or_else(|| "step".into());
    if what == "step" {
        let steps: Vec<f64> = std::env::var("AMM_STEPS")
            .ok()
            .map(|s| s.split(",").map(|x| x.parse().unwrap()).collect())
            .unwrap_or(vec![1e-3, 5e-4, 2.5e-4, 2e-4, 1e-3 / 6.0, 1e-4]);
        println!("| case | family | h [s] | EVP tipA | tipB | tipC | w1G | w2G | w3G |");
        println!("|---|---|---|---|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            for fam in ModeFamily::PAPER {
                let n = std::env::var("AMM_N").ok().and_then(|s| s.parse().ok()).unwrap_or(25);
                for &h in &steps {
                    let a = common::motion_response(&exp, &common::settings(fam, n, Some(h))).unwrap();
                    let b = common::motion_response(&exp, &common::settings(fam, n, Some(h / 2.0))).unwrap();
                    let (cells, _) = row(&a, &b);
                    println!("| {case} | {fam} | {h:.3e} | {} |", cells.join(" | "));
                }
            }
        }
    } else if what == "accurate-step" {
        // the accurate model (enriched, full) at N = AMM_N (default 53): EVP(h, h/2) per point and
        // mean over A, B, C, G as in Table I (flexstar_metrics::evp), the four cases
        let steps: Vec<f64> = std::env::var("AMM_STEPS")
            .ok()
            .map(|s| s.split(",").map(|x| x.parse().unwrap()).collect())
            .unwrap_or(vec![1e-3, 5e-4, 2.5e-4, 1e-3 / 6.0]);
        let n = std::env::var("AMM_N").ok().and_then(|s| s.parse().ok()).unwrap_or(53);
        println!("| case | h [s] | A | B | C | G | mean |");
        println!("|---|---|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            for &h in &steps {
                let at = |dt: f64| {
                    let s = flexstar_model::AmmSettings {
                        modes: Some(n),
                        dt: Some(dt),
                        ..flexstar_model::AmmSettings::accurate()
                    };
                    common::motion_response(&exp, &s).unwrap()
                };
                let p = flexstar_metrics::evp::point_evps(&at(h), &at(h / 2.0)).unwrap();
                let cells: Vec<String> = p
                    .points
                    .iter()
                    .map(|v| v.map_or("n/a".into(), |x| format!("{x:.3}")))
                    .collect();
                println!(
                    "| {case} | {h:.3e} | {} | {:.3} |",
                    cells.join(" | "),
                    p.mean.unwrap_or(f64::NAN)
                );
            }
        }
    } else if what == "truncation" {
        // the accurate model at the accurate default step: mean EVP (Table I rule) of N against
        // N = 150, and the estimate of the automatic choice (the previous N of the sequence)
        let at = |exp: &flexstar_model::Experiment, n: usize| {
            let s = flexstar_model::AmmSettings {
                modes: Some(n),
                dt: Some(flexstar_amm::TOLERANCE_DT),
                ..flexstar_model::AmmSettings::accurate()
            };
            common::motion_response(exp, &s).unwrap()
        };
        let mean = |a: &Response, b: &Response| flexstar_metrics::evp::point_evps(a, b).unwrap().mean.unwrap();
        println!("| case | N | true truncation (vs N = 150) [%] | estimate (vs previous N) [%] | ratio |");
        println!("|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            let reference = at(&exp, 150);
            let ns = [40, 46, 53, 61, 71];
            let runs: Vec<Response> = ns.iter().map(|&n| at(&exp, n)).collect();
            for k in 1..ns.len() {
                let truth = mean(&runs[k], &reference);
                let est = mean(&runs[k - 1], &runs[k]);
                println!("| {case} | {} | {truth:.3} | {est:.3} | {:.2} |", ns[k], est / truth);
            }
        }
    } else if what == "amplitudes" {
        // largest |w| over time [mm] per point, N = 25, 50, 100 (default step)
        println!("| case | family | N | tip A | tip B | tip C | w1G | w2G | w3G | max Fa [N] |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            for fam in ModeFamily::PAPER {
                for n in [25, 50, 100] {
                    let r = common::motion_response(&exp, &common::settings(fam, n, None)).unwrap();
                    let mm = |v: &[f64]| format!("{:.3}", common::max_abs(v) * 1e3);
                    let cells: Vec<String> = r.w_tip.iter().chain(r.w_g.iter()).map(|v| mm(v)).collect();
                    let fa = r.fa.iter().map(|v| common::max_abs(v)).fold(0.0, f64::max);
                    println!("| {case} | {fam} | {n} | {} | {fa:.3} |", cells.join(" | "));
                }
            }
        }
    } else if what == "paper-n" {
        // how far the paper's N = 25 (and N = 50) is from N = 100
        println!("| case | family | N vs 100 | EVP tipA | tipB | tipC | w1G | w2G | w3G |");
        println!("|---|---|---|---|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            for fam in ModeFamily::PAPER {
                let reference = common::motion_response(&exp, &common::settings(fam, 100, None)).unwrap();
                for n in [25, 50] {
                    let r = common::motion_response(&exp, &common::settings(fam, n, None)).unwrap();
                    let (cells, _) = row(&r, &reference);
                    println!("| {case} | {fam} | {n} | {} |", cells.join(" | "));
                }
            }
        }
    } else {
        let ns = [10, 20, 40, 80];
        println!("| case | family | N vs 2N | EVP tipA | tipB | tipC | w1G | w2G | w3G | max tip [mm] |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for case in 1..=4 {
            let exp = common::paper_case(case);
            for fam in ModeFamily::PAPER {
                let runs: Vec<Response> = ns
                    .iter()
                    .map(|&n| common::motion_response(&exp, &common::settings(fam, n, None)).unwrap())
                    .collect();
                for k in 0..ns.len() - 1 {
                    let (cells, _) = row(&runs[k], &runs[k + 1]);
                    let amp = (0..3).map(|i| common::max_abs(&runs[k].w_tip[i])).fold(0.0, f64::max) * 1e3;
                    println!(
                        "| {case} | {fam} | {} vs {} | {} | {amp:.3} |",
                        ns[k],
                        ns[k + 1],
                        cells.join(" | ")
                    );
                }
            }
        }
    }
}
