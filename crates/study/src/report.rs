//! The study's report from its results folder alone (`results.csv` and its sidecar): every metric
//! against every varied key, heat maps when exactly two keys are gridded, and `study.html` with
//! the table's summary and every plot inline. Used after a run and after a merge.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use flexstar_io::output::write_string_atomically;

use crate::error::StudyError;
use crate::plots::{solver_color, Heat, Histogram, PointSet, Scatter};
use crate::shard::{meta_file, results_file, Meta};
use crate::table::{Table, OK};
use plotters::style::RGBColor;

/// Most points drawn per plot; larger studies are thinned evenly (every k-th row).
pub const MAX_POINTS: usize = 5000;

/// The plotted metric columns with their axis labels.
pub fn metric_labels() -> Vec<(&'static str, &'static str)> {
    vec![
        ("peak_tip_m", "peak |w_i(L)| over A, B, C [m]"),
        ("peak_wG_m", "peak |w_iG| [m]"),
        ("peak_Fa_N", "peak |Fa_i| [N]"),
        ("evp_percent", "mean EVP of the AMM vs FEM [%]"),
        ("evp_max_percent", "largest point EVP of the AMM vs FEM [%]"),
        ("f1_hz", "first frequency at the start pose [Hz]"),
        ("residual_tip_m", "residual |w_i(L)| after the motion [m]"),
        ("residual_G_m", "residual |dG| after the motion [m]"),
        ("settle_s", "settling time, absolute (not settled: not drawn) [s]"),
        ("error_estimate_percent", "AMM error estimate [%]"),
        ("modes", "AMM modes per beam"),
        ("wall_s", "wall time per solve [s]"),
    ]
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportOutcome {
    pub html: PathBuf,
    /// The SVG files in `plots/`.
    pub plots: Vec<PathBuf>,
}

struct Plot {
    file: String,
    caption: String,
    svg: String,
}

/// Write `dir/plots/*.svg` and `dir/study.html` from `dir/results.csv`.
pub fn write_report(dir: &Path) -> Result<ReportOutcome, StudyError> {
    let results = results_file(dir, None);
    let table = Table::read(&results)?;
    let meta = Meta::read(&meta_file(&results))?;
    let plots = make_plots(&table, &meta)?;
    let plot_dir = dir.join("plots");
    let mut files = Vec::new();
    for p in &plots {
        let f = plot_dir.join(&p.file);
        write_string_atomically(&f, &p.svg)?;
        files.push(f);
    }
    let html = dir.join("study.html");
    write_string_atomically(&html, &html_page(&table, &meta, &plots))?;
    Ok(ReportOutcome { html, plots: files })
}

fn num(s: &str) -> Option<f64> {
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// File-name form of a key (`robot.Lp` -> `robot-Lp`).
fn slug(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '-' })
        .collect()
}

/// The metrics with at least one value in the table.
fn present_metrics(table: &Table) -> Vec<(usize, &'static str, &'static str)> {
    metric_labels()
        .into_iter()
        .filter_map(|(m, label)| {
            let c = table.column(m)?;
            table.rows.iter().any(|r| num(&r[c]).is_some()).then_some((c, m, label))
        })
        .collect()
}

fn make_plots(table: &Table, meta: &Meta) -> Result<Vec<Plot>, StudyError> {
    let keys = table.keys();
    let (solver, status) = (table.column("solver").unwrap_or(0), table.column("status").unwrap_or(0));
    let ok: Vec<&Vec<String>> = table.rows.iter().filter(|r| r[status] == OK).collect();
    let stride = ok.len().div_ceil(MAX_POINTS).max(1);
    let grid = !meta.grid_levels.is_empty();
    let mut plots: Vec<Plot> = estimate_plot(table, &ok, stride)?.into_iter().collect();
    if !grid {
        plots.extend(histograms(table, meta, &ok)?);
    }
    for (mc, metric, label) in present_metrics(table) {
        for (j, key) in keys.iter().enumerate() {
            let kc = j + 1;
            if !ok.iter().all(|r| num(&r[kc]).is_some()) {
                continue; // a key with text values (a mode family) has no axis
            }
            let sets = meta
                .solvers
                .iter()
                .map(|s| PointSet {
                    label: s.clone(),
                    color: solver_color(s),
                    points: ok
                        .iter()
                        .step_by(stride)
                        .filter(|r| &r[solver] == s)
                        .filter_map(|r| Some((num(&r[kc])?, num(&r[mc])?)))
                        .collect(),
                })
                .filter(|s| !s.points.is_empty())
                .collect();
            let scatter = Scatter {
                title: format!("{metric} against {key}"),
                x_label: key.clone(),
                y_label: label.to_string(),
                sets,
                connect: grid && keys.len() == 1,
            };
            plots.push(Plot {
                file: format!("{}-vs-{}.svg", slug(metric), slug(key)),
                caption: format!("{label} against {key}{}", thinned(stride)),
                svg: scatter.to_svg()?,
            });
        }
        if grid && keys.len() == 2 {
            for s in &meta.solvers {
                if let Some(heat) = heat(table, &ok, s, mc, metric) {
                    plots.push(Plot {
                        file: format!("heat-{}-{}.svg", slug(metric), s),
                        caption: format!("{label}, {s}: heat map over {} and {}", keys[0], keys[1]),
                        svg: heat.to_svg()?,
                    });
                }
            }
        }
    }
    Ok(plots)
}

/// The metrics whose distribution a sampled study (a tolerance study) shows as a histogram.
pub const HISTOGRAM_METRICS: [&str; 5] = ["f1_hz", "residual_G_m", "settle_s", "peak_Fa_N", "peak_tip_m"];

/// A histogram of each of [`HISTOGRAM_METRICS`] over the runs, the solvers side by side (a
/// sampled study: Latin hypercube or random draws).
fn histograms(table: &Table, meta: &Meta, ok: &[&Vec<String>]) -> Result<Vec<Plot>, StudyError> {
    let sc = table.column("solver").unwrap_or(0);
    let mut plots = Vec::new();
    for (mc, metric, label) in present_metrics(table)
        .into_iter()
        .filter(|m| HISTOGRAM_METRICS.contains(&m.1))
    {
        let sets: Vec<(String, RGBColor, Vec<f64>)> = meta
            .solvers
            .iter()
            .map(|s| {
                let v: Vec<f64> = ok.iter().filter(|r| &r[sc] == s).filter_map(|r| num(&r[mc])).collect();
                (s.clone(), solver_color(s), v)
            })
            .filter(|s| !s.2.is_empty())
            .collect();
        let runs = sets.iter().map(|s| s.2.len()).max().unwrap_or(0);
        if runs < 2 {
            continue;
        }
        let hist = Histogram {
            title: format!("distribution of {metric}"),
            x_label: label.to_string(),
            bins: (runs as f64).sqrt().ceil().clamp(5.0, 30.0) as usize,
            sets,
        };
        plots.push(Plot {
            file: format!("hist-{}.svg", slug(metric)),
            caption: format!("Distribution of {label} over the study's runs (the quantiles are in the summary)"),
            svg: hist.to_svg()?,
        });
    }
    Ok(plots)
}

/// The quantile `p` in [0, 1] of sorted values, linearly interpolated between order statistics
/// (the value at rank `p (n - 1)`, Hyndman and Fan's definition 7, the default of R and numpy).
pub fn quantile(sorted: &[f64], p: f64) -> f64 {
    let h = p * (sorted.len() - 1) as f64;
    let k = h.floor() as usize;
    match sorted.get(k + 1) {
        Some(next) => sorted[k] + (h - k as f64) * (next - sorted[k]),
        None => sorted[k],
    }
}

/// The AMM's error estimate against its true mean EVP (`docs/validation.md` section 8), both as log10 of the
/// percentage (the runs span decades): one point per AMM run of a study that runs both solvers
/// (positive values), with the guides estimate = EVP / 2, EVP and 2 EVP (the target band) drawn
/// as dotted lines; every `stride`-th row drawn, as in the other plots; `None` when the table
/// has no such runs.
fn estimate_plot(table: &Table, ok: &[&Vec<String>], stride: usize) -> Result<Option<Plot>, StudyError> {
    let (Some(e), Some(est)) = (table.column("evp_percent"), table.column("error_estimate_percent")) else {
        return Ok(None);
    };
    let log = |x: f64| (x > 0.0).then(|| x.log10());
    let points: Vec<(f64, f64)> = ok
        .iter()
        .step_by(stride)
        .filter_map(|r| Some((log(num(&r[e])?)?, log(num(&r[est])?)?)))
        .collect();
    let Some(lo) = points.iter().map(|p| p.0.min(p.1)).reduce(f64::min) else {
        return Ok(None);
    };
    let hi = points.iter().map(|p| p.0.max(p.1)).fold(lo, f64::max);
    let guide = |label: &str, factor: f64, color: RGBColor| PointSet {
        label: label.to_string(),
        color,
        points: (0..=40)
            .map(|k| lo + (hi - lo) * k as f64 / 40.0)
            .map(|x| (x, x + factor.log10()))
            .filter(|&(_, y)| (lo..=hi).contains(&y))
            .collect(),
    };
    let sets = vec![
        guide("estimate = EVP / 2", 0.5, RGBColor(200, 200, 200)),
        guide("estimate = EVP", 1.0, RGBColor(140, 140, 140)),
        guide("estimate = 2 EVP", 2.0, RGBColor(200, 200, 200)),
        PointSet {
            label: "AMM runs".to_string(),
            color: solver_color("amm"),
            points,
        },
    ];
    let scatter = Scatter {
        title: "error estimate against the true mean EVP (log10 of %)".to_string(),
        x_label: "log10 mean EVP against the FEM [%]".to_string(),
        y_label: "log10 error_estimate_percent [%]".to_string(),
        sets,
        connect: false,
    };
    Ok(Some(Plot {
        file: "estimate-vs-evp.svg".to_string(),
        caption: format!("The AMM's error estimate against its mean EVP against the FEM (log10 of the percentages), one point per AMM run; between the outer guides the estimate is within a factor 2 of the truth (the target){}", thinned(stride)),
        svg: scatter.to_svg()?,
    }))
}

fn thinned(stride: usize) -> String {
    if stride > 1 {
        format!(" (every {stride}th run drawn)")
    } else {
        String::new()
    }
}

/// Levels of a key column in the order of first appearance, numbers sorted ascending.
fn levels(rows: &[&Vec<String>], col: usize) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for r in rows {
        if !v.contains(&r[col]) {
            v.push(r[col].clone());
        }
    }
    if v.iter().all(|s| num(s).is_some()) {
        v.sort_by(|a, b| num(a).unwrap_or(0.0).total_cmp(&num(b).unwrap_or(0.0)));
    }
    v
}

fn heat(table: &Table, ok: &[&Vec<String>], solver: &str, mc: usize, metric: &str) -> Option<Heat> {
    let sc = table.column("solver")?;
    let all: Vec<&Vec<String>> = table.rows.iter().collect();
    let (xl, yl) = (levels(&all, 1), levels(&all, 2));
    let mut values = vec![vec![None; xl.len()]; yl.len()];
    let mut any = false;
    for r in ok.iter().filter(|r| r[sc] == solver) {
        let (ix, iy) = (xl.iter().position(|l| *l == r[1])?, yl.iter().position(|l| *l == r[2])?);
        values[iy][ix] = num(&r[mc]);
        any |= values[iy][ix].is_some();
    }
    let keys = table.keys();
    any.then(|| Heat {
        title: format!("{metric} ({solver})"),
        x_label: keys[0].clone(),
        y_label: keys[1].clone(),
        x_levels: xl,
        y_levels: yl,
        values,
    })
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Summary of one metric of one solver: count, min, the 5, 50 and 95 % quantiles ([`quantile`]),
/// max and the cases of the extremes.
fn summary_rows(table: &Table, meta: &Meta) -> String {
    let keys = table.keys();
    let (sc, st) = (table.column("solver").unwrap_or(0), table.column("status").unwrap_or(0));
    let case = |r: &Vec<String>| {
        keys.iter()
            .enumerate()
            .map(|(j, k)| format!("{k} = {}", r[j + 1]))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut h = String::new();
    for s in &meta.solvers {
        for (mc, metric, _) in present_metrics(table) {
            let mut v: Vec<(f64, &Vec<String>)> = table
                .rows
                .iter()
                .filter(|r| &r[sc] == s && r[st] == OK)
                .filter_map(|r| Some((num(&r[mc])?, r)))
                .collect();
            if v.is_empty() {
                continue;
            }
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (lo, hi) = (v[0], v[v.len() - 1]);
            let sorted: Vec<f64> = v.iter().map(|x| x.0).collect();
            let q = |p: f64| quantile(&sorted, p);
            let _ = writeln!(
                h,
                "<tr><td>{s}</td><td>{metric}</td><td>{}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td><td>{}</td><td>{}</td></tr>",
                v.len(),
                lo.0,
                q(0.05),
                q(0.5),
                q(0.95),
                hi.0,
                escape(&case(lo.1)),
                escape(&case(hi.1))
            );
        }
    }
    h
}

fn html_page(table: &Table, meta: &Meta, plots: &[Plot]) -> String {
    let st = table.column("status").unwrap_or(0);
    let failed: Vec<&Vec<String>> = table.rows.iter().filter(|r| r[st] != OK).collect();
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>flexstar study {name}</title>\n<style>\nbody{{font-family:sans-serif;max-width:1600px;margin:2em auto;padding:0 1em;color:#222}}\ntable{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #bbb;padding:3px 7px;text-align:left}}\nth{{background:#eee}}figure{{display:inline-block;margin:0.5em}}svg{{max-width:100%;height:auto}}\n</style></head><body>\n<h1>flexstar study: {name}</h1>\n",
        name = escape(&meta.study)
    );
    let _ = writeln!(
        h,
        "<p>Study file <code>{}</code>, hash <code>{}</code>; {} cases x {} ({}); varied: {}. {} rows, {} ok, {} failed.</p>",
        escape(&meta.study_file),
        meta.hash,
        meta.total_cases,
        meta.solvers.join(" + "),
        if meta.grid_levels.is_empty() { "sampled".to_string() } else { format!("grid {:?}", meta.grid_levels) },
        escape(&meta.keys.join(", ")),
        table.rows.len(),
        table.rows.len() - failed.len(),
        failed.len()
    );
    h.push_str("<h2>Summary</h2>\n<table><tr><th>solver</th><th>metric</th><th>runs</th><th>min</th><th>5 %</th><th>median</th><th>95 %</th><th>max</th><th>case of the min</th><th>case of the max</th></tr>\n");
    h.push_str(&summary_rows(table, meta));
    h.push_str("</table>\n");
    if !failed.is_empty() {
        let _ = writeln!(h, "<h2>Failed runs ({})</h2>\n<table><tr>", failed.len());
        for c in table.header.iter().take(st + 1) {
            let _ = write!(h, "<th>{}</th>", escape(c));
        }
        h.push_str("</tr>\n");
        for r in failed.iter().take(50) {
            h.push_str("<tr>");
            for c in r.iter().take(st + 1) {
                let _ = write!(h, "<td>{}</td>", escape(c));
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
        if failed.len() > 50 {
            let _ = writeln!(h, "<p>... and {} more (see results.csv).</p>", failed.len() - 50);
        }
    }
    h.push_str("<h2>Plots</h2>\n");
    for p in plots {
        let svg = p.svg.find("<svg").map_or(p.svg.as_str(), |i| &p.svg[i..]);
        let _ = writeln!(
            h,
            "<figure id=\"{}\">{svg}<figcaption>{}</figcaption></figure>",
            escape(&p.file),
            escape(&p.caption)
        );
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table of AMM and FEM rows with the given (EVP, estimate) of the AMM rows.
    fn table(amm: &[(&str, &str)]) -> Table {
        let header = crate::table::header(&["robot.L".to_string()]);
        let col = |name: &str| header.iter().position(|h| h == name).unwrap();
        let mut rows = Vec::new();
        for (k, (evp, est)) in amm.iter().enumerate() {
            for solver in ["amm", "fem"] {
                let mut r = vec![String::new(); header.len()];
                r[0] = format!("id{k}");
                r[1] = "0.5".to_string();
                r[col("solver")] = solver.to_string();
                r[col("status")] = OK.to_string();
                if solver == "amm" {
                    r[col("evp_percent")] = evp.to_string();
                    r[col("error_estimate_percent")] = est.to_string();
                }
                rows.push(r);
            }
        }
        Table { header, rows }
    }

    /// Quantiles against numpy's default (`numpy.quantile([1..=101], [0.05, 0.5, 0.95])` = 6, 51,
    /// 96; of [1, 2, 3, 4]: 0.05 -> 1.15, 0.95 -> 3.85).
    #[test]
    fn quantiles_are_numpys_default() {
        let v: Vec<f64> = (1..=101).map(f64::from).collect();
        assert_eq!(
            [quantile(&v, 0.05), quantile(&v, 0.5), quantile(&v, 0.95)],
            [6.0, 51.0, 96.0]
        );
        let w = [1.0, 2.0, 3.0, 4.0];
        assert!((quantile(&w, 0.05) - 1.15).abs() < 1e-12 && (quantile(&w, 0.95) - 3.85).abs() < 1e-12);
        assert_eq!(quantile(&[7.0], 0.3), 7.0);
    }

    #[test]
    fn histogram_counts_put_every_run_in_one_bin() {
        let v = [0.0, 0.1, 0.5, 0.99, 1.0];
        assert_eq!(Histogram::counts(&v, 0.0, 1.0, 2), vec![2, 3]);
    }

    #[test]
    fn the_estimate_plot_draws_every_amm_run_with_an_estimate_and_the_factor_two_guides() {
        let t = table(&[("0.1", "0.15"), ("1.0", "0.4"), ("0.01", "")]);
        let ok: Vec<&Vec<String>> = t.rows.iter().collect();
        let plot = estimate_plot(&t, &ok, 1)
            .unwrap()
            .expect("two AMM runs with both numbers");
        assert_eq!(plot.file, "estimate-vs-evp.svg");
        for label in ["AMM runs", "estimate = EVP / 2", "estimate = 2 EVP"] {
            assert!(plot.svg.contains(label), "{label}");
        }
        // no AMM run with an estimate: no plot
        let none = table(&[("0.1", "")]);
        let ok: Vec<&Vec<String>> = none.rows.iter().collect();
        assert!(estimate_plot(&none, &ok, 1).unwrap().is_none());
    }
}
