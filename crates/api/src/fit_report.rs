//! The files of `flexstar fit` (`docs/measured.md` 4.9): `fit.json`, `fit.md`, `report.html`, the
//! figures and, for a calibration only, `fit.toml`; published together (a `RunSet`), so that a
//! reader sees the old set or the new one. A fit that is no calibration removes an older
//! `fit.toml`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use flexstar_io::run_set::RunSet;
use flexstar_plot::RenderedFigure;

use crate::fit::{FitOutcome, Fitted};
use crate::{ApiError, Result};

/// Write every file of the outcome into its folder; the paths written.
pub(crate) fn write(o: &FitOutcome) -> Result<Vec<PathBuf>> {
    let f = &o.fitted;
    let figures = render_figures(f)?;
    let mut set = RunSet::begin(&o.dir)?;
    let mut names = Vec::new();
    match &f.calibrated {
        Some(_) => {
            set.text("fit.toml", &fit_toml(f)?)?;
            names.push("fit.toml".to_string());
        }
        None => {
            set.remove("fit.toml")?;
        }
    }
    let json = fit_json(o);
    set.text(
        "fit.json",
        &flexstar_model::response::sidecar_text(&o.dir.join("fit.json"), &json)?,
    )?;
    let md = fit_markdown(o);
    set.text("fit.md", &md)?;
    set.text("report.html", &report_html(o, &md, &figures))?;
    names.extend(["fit.json", "fit.md", "report.html"].map(String::from));
    for fig in &figures {
        let name = format!("{}.svg", fig.name);
        set.text(&name, &fig.svg)?;
        names.push(name);
    }
    set.commit()?;
    Ok(names.iter().map(|n| o.dir.join(n)).collect())
}

/// The figures drawn once (SVG), for their files and the report.
fn render_figures(f: &Fitted) -> Result<Vec<RenderedFigure>> {
    crate::fit_figures::figures(f)
        .iter()
        .map(|fig| fig.render().map_err(|e| ApiError::Output(e.to_string())))
        .collect()
}

/// `fit.toml`: the input document with the estimates patched in, relative file names made
/// absolute (the file lives in another folder); runnable by every command.
pub fn fit_toml(f: &Fitted) -> Result<String> {
    let Some(cal) = &f.calibrated else {
        return Err(ApiError::Output("fit.toml: the fit is no calibration".into()));
    };
    let mut table = cal.doc.clone();
    absolute_files(&mut table, &f.input.source);
    let body = toml::to_string(&table).map_err(|e| ApiError::Output(format!("fit.toml: {e}")))?;
    let estimates: Vec<String> = f
        .fit
        .estimates
        .iter()
        .map(|e| format!("#   {} = {}", e.key, e.estimate))
        .collect();
    Ok(format!(
        "# Written by `flexstar fit {} --measured {}`: the experiment with the estimates patched in\n\
         # (fit.json: their standard errors, 95 % intervals and correlations); runnable by every command.\n{}\n{body}",
        f.input.source.display(),
        f.recording,
        estimates.join("\n")
    ))
}

/// The keys of a document that name files, relative to the experiment's folder.
const FILE_KEYS: [(&str, &str); 3] = [("trajectory", "file"), ("drive", "file"), ("load", "file")];

/// Make the relative file names of `table` absolute against the folder of `source`.
fn absolute_files(table: &mut toml::Table, source: &Path) {
    let dir = source.parent().unwrap_or_else(|| Path::new("."));
    for (section, key) in FILE_KEYS {
        let Some(toml::Value::Table(t)) = table.get_mut(section) else {
            continue;
        };
        if let Some(toml::Value::String(f)) = t.get(key).cloned() {
            if Path::new(&f).is_relative() {
                let joined = dir.join(&f);
                let abs = std::fs::canonicalize(&joined).unwrap_or(joined);
                t.insert(key.into(), toml::Value::String(abs.display().to_string()));
            }
        }
    }
}

/// `fit.json`: the estimates with their statistics, the channels before and after, the search,
/// the identifiability verdict (`docs/measured.md` 4.9).
pub fn fit_json(o: &FitOutcome) -> Value {
    let f = &o.fitted;
    let fit = &f.fit;
    let st = &fit.statistics;
    json!({
        "provenance": crate::provenance(),
        "experiment": f.input.exp.name,
        "config": f.input.source.display().to_string(),
        "recording": f.recording,
        "converged": fit.converged(),
        "calibrated": fit.calibrated(),
        "reason": fit.reason,
        "stop": fit.stop,
        "parameters": fit.estimates.iter().map(|e| json!({
            "key": e.key,
            "lo": e.lo,
            "hi": e.hi,
            "start": e.start,
            "estimate": e.estimate,
            "standard_error": e.standard_error,
            "standard_error_correlated": e.standard_error_correlated,
            "interval_95": e.interval,
            "at_bound": e.at_bound,
        })).collect::<Vec<_>>(),
        "correlation": st.correlation,
        "covariance": st.covariance,
        "residual": {
            "n": st.n,
            "dof": st.dof,
            "s2": st.s2,
            "t_quantile": st.t_quantile,
            "correlation_samples": st.bandwidth,
        },
        "not_recorded": f.not_recorded,
        "starts": fit.starts,
        "fem_check": match &f.fem_check {
            None => serde_json::Value::Null,
            Some(Ok(rows)) => json!({ "channels": rows }),
            Some(Err(reason)) => json!({ "error": reason }),
        },
        "channels": fit.channels.iter().map(|c| json!({
            "column": c.column,
            "unit": c.unit,
            "weight": c.weight,
            "noise": c.noise,
            "rms_before": c.rms_before,
            "rms_after": c.rms_after,
            "misfit": c.misfit(),
        })).collect::<Vec<_>>(),
        "identifiability": fit.identifiability,
        "iterations": fit.iterations,
        "evaluations": fit.evaluations,
        "jacobians": { "total": fit.jacobians, "by_tangent": fit.tangent_jacobians },
        "fit_wall_s": fit.wall_s,
        "wall_s": o.wall_s,
        "amm": { "modes": f.modes, "dt": f.dt },
        "fit_toml": f.calibrated.as_ref().map(|_| "fit.toml"),
        "trace": fit.trace,
    })
}

fn sig(v: f64) -> String {
    flexstar_io::output::fmt_sig(v, 5)
}

fn opt(v: Option<f64>) -> String {
    v.map_or("n/a".into(), sig)
}

/// `fit.md`: the verdict, the estimates, the correlations, the channels, the search.
pub fn fit_markdown(o: &FitOutcome) -> String {
    let f = &o.fitted;
    let fit = &f.fit;
    let mut s = format!(
        "# {}: fit to {}\n\n**{}.** {}\n\nIdentifiability: {}\n\nModel: the accurate AMM at N = {} modes per beam and step {} s (frozen at the start's); \
         {} iterations, {} model evaluations ({} of {} Jacobians from the tangent-linear AMM), {:.2} s for the fit, {:.2} s in all.\n\n",
        f.input.exp.name,
        f.recording,
        if fit.calibrated() {
            "Calibrated: fit.toml holds the experiment with the estimates"
        } else {
            "Not calibrated: no fit.toml written"
        },
        fit.reason,
        fit.identifiability.message,
        f.modes,
        sig(f.dt),
        fit.iterations,
        fit.evaluations,
        fit.tangent_jacobians,
        fit.jacobians,
        fit.wall_s,
        o.wall_s,
    );
    if !f.not_recorded.is_empty() {
        let _ = writeln!(
            s,
            "Not in the recording, so not fitted: {}.\n",
            f.not_recorded.join(", ")
        );
    }
    estimates_table(&mut s, f);
    correlation_table(&mut s, f);
    channels_table(&mut s, f);
    fem_check_table(&mut s, f);
    starts_table(&mut s, f);
    trace_table(&mut s, f);
    s.push_str(HOW_TO_READ);
    s
}

fn estimates_table(s: &mut String, f: &Fitted) {
    s.push_str(
        "## Estimates\n\n| parameter | start | estimate | standard error, noise (LS12) | standard error, correlated (LS18) \
         | 95 % interval (LS19) | box |\n|---|---|---|---|---|---|---|\n",
    );
    for e in &f.fit.estimates {
        let interval = e
            .interval
            .map_or("n/a".into(), |[a, b]| format!("{} .. {}", sig(a), sig(b)));
        let _ = writeln!(
            s,
            "| `{}` | {} | {}{} | {} | {} | {} | {} .. {} |",
            e.key,
            sig(e.start),
            sig(e.estimate),
            if e.at_bound { " (at a bound)" } else { "" },
            opt(e.standard_error),
            opt(e.standard_error_correlated),
            interval,
            sig(e.lo),
            sig(e.hi)
        );
    }
    let st = &f.fit.statistics;
    let _ = writeln!(
        s,
        "\nResidual variance s^2 = {} over n = {} residuals, {} degrees of freedom (about 1 when the model \
         explains everything but the noise); t quantile {}; residuals taken as correlated over {} samples \
         (Eq. LS18).\n",
        sig(st.s2),
        st.n,
        st.dof,
        sig(st.t_quantile),
        st.bandwidth
    );
}

fn correlation_table(s: &mut String, f: &Fitted) {
    let keys: Vec<&str> = f.fit.estimates.iter().map(|e| e.key.as_str()).collect();
    let _ = writeln!(
        s,
        "## Correlations of the estimates\n\n| | {} |\n|---|{}",
        keys.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(" | "),
        "---|".repeat(keys.len())
    );
    for (k, row) in f.fit.statistics.correlation.iter().enumerate() {
        let cells: Vec<String> = row
            .iter()
            .map(|c| c.map_or("n/a".into(), |v| format!("{v:+.3}")))
            .collect();
        let _ = writeln!(s, "| `{}` | {} |", keys[k], cells.join(" | "));
    }
    s.push('\n');
}

/// The FEM of the calibrated experiment against the recording and the AMM (4.9).
fn fem_check_table(s: &mut String, f: &Fitted) {
    match &f.fem_check {
        None => {}
        Some(Err(reason)) => {
            let _ = writeln!(
                s,
                "## The FEM's check\n\nThe FEM of the calibrated experiment did not run: {reason}\n"
            );
        }
        Some(Ok(rows)) => {
            s.push_str(
                "## The FEM's check: RMS against the recording at the estimates\n\nThe calibrated experiment run on the \
                 FEM, an independent model (docs/measured.md 4.9): where the FEM's error is the AMM's, the estimates \
                 do not rest on the AMM's own error; where the two models differ by a good share of the noise, the \
                 correlated standard errors (Eq. LS18) are the ones to read.\n\n\
                 | column | unit | noise (Eq. LS2) | AMM - recording | FEM - recording | FEM - AMM | (FEM - AMM) / noise |\n\
                 |---|---|---|---|---|---|---|\n",
            );
            for c in rows {
                let _ = writeln!(
                    s,
                    "| `{}` | {} | {} | {} | {} | {} | {:.3} |",
                    c.column,
                    c.unit,
                    sig(c.noise),
                    sig(c.rms_amm),
                    sig(c.rms_fem),
                    sig(c.rms_fem_amm),
                    c.rms_fem_amm / c.noise
                );
            }
            s.push('\n');
        }
    }
}

/// Every start's search when there were several (docs/measured.md 4.6).
fn starts_table(s: &mut String, f: &Fitted) {
    let starts = &f.fit.starts;
    if starts.len() < 2 {
        return;
    }
    let keys: Vec<&str> = f.fit.estimates.iter().map(|e| e.key.as_str()).collect();
    let _ = writeln!(
        s,
        "## Starts\n\n{} starts (the given one, then Halton points of the boxes); the estimates are the chosen \
         search's: converged before not, then the lowest cost. Parameters in the order {}.\n\n\
         | start | from | to | cost (Eq. LS4) | stop | chosen |\n|---|---|---|---|---|---|",
        starts.len(),
        keys.join(", ")
    );
    let list = |v: &[f64]| v.iter().map(|x| sig(*x)).collect::<Vec<_>>().join(", ");
    for (k, o) in starts.iter().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} |",
            k + 1,
            list(&o.start),
            list(&o.end),
            sig(o.cost),
            o.reason,
            if o.chosen { "yes" } else { "" }
        );
    }
    s.push('\n');
}

fn channels_table(s: &mut String, f: &Fitted) {
    s.push_str(
        "## Channels: RMS of model - recording\n\n| column | unit | weight | noise (Eq. LS2) | before | after | after / noise |\n|---|---|---|---|---|---|---|\n",
    );
    for c in &f.fit.channels {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {} | {} | {:.3}{} |",
            c.column,
            c.unit,
            sig(c.weight),
            sig(c.noise),
            sig(c.rms_before),
            sig(c.rms_after),
            c.rms_after / c.noise,
            if c.misfit() { " **misfit**" } else { "" }
        );
    }
    let misfits: Vec<&str> = f
        .fit
        .channels
        .iter()
        .filter(|c| c.misfit())
        .map(|c| c.column.as_str())
        .collect();
    if !misfits.is_empty() {
        let _ = writeln!(
            s,
            "\n**Misfit** (an error after the fit above {} times the noise level): {}. The model misses something \
             these channels record, or the sensor is not what the experiment says.",
            flexstar_fit::outcome::MISFIT,
            misfits.join(", ")
        );
    }
    s.push('\n');
}

fn trace_table(s: &mut String, f: &Fitted) {
    let keys: Vec<String> = f.fit.estimates.iter().map(|e| format!("`{}`", e.key)).collect();
    let _ = writeln!(
        s,
        "## The search\n\n| iteration | evaluations | cost | relative offset | damping | wall [s] | {} |\n|---|---|---|---|---|---|{}",
        keys.join(" | "),
        "---|".repeat(keys.len())
    );
    for r in &f.fit.trace {
        let theta: Vec<String> = r.theta.iter().map(|v| sig(*v)).collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2e} | {:.1e} | {:.2} | {} |",
            r.iteration,
            r.evaluations,
            sig(r.cost),
            r.offset,
            r.damping,
            r.wall_s,
            theta.join(" | ")
        );
    }
    s.push('\n');
}

const HOW_TO_READ: &str = "## How to read this\n\n\
Each residual is a sensor column's model - recording divided by that column's noise level (estimated from the recording, Eq. LS2) and \
multiplied by its sensor's weight (Eq. LS1). The search stops when the relative offset (Eq. LS10) is below 1e-3: what is left to gain \
is a thousandth of the estimates' own uncertainty. The noise's standard errors (Eqs. LS11-LS13) hold when the model is right and the \
noise white; the correlated ones (Eq. LS18) let the residuals stay correlated over one period of the first mode, as the model's own \
error does, and the 95 % intervals take the wider of the two (Eq. LS19). s^2 well above 1, or an error figure with oscillation left \
in it, says the model misses something the recording has. A correlation near -1 or +1 and an ill-conditioned verdict say that the data \
hardly separate two parameters (Eqs. LS15-LS16). docs/measured.md section 4 has the derivation.\n";

/// The report: the markdown's sections and the figures inline.
fn report_html(o: &FitOutcome, md: &str, figures: &[RenderedFigure]) -> String {
    let f = &o.fitted;
    let title = format!("flexstar fit: {}", f.input.exp.name);
    let p = crate::provenance();
    let mut h = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>{STYLE}</style></head><body>\n\
         <p class=\"meta\">flexstar {}{}, {}.</p>\n",
        escape(&title),
        escape(&p.version),
        p.commit.as_deref().map(|c| format!(", commit {}", escape(c))).unwrap_or_default(),
        escape(&p.date)
    );
    h.push_str(&flexstar_compare::report::markdown_to_html(md));
    h.push_str("<h2>Figures</h2>\n");
    for fig in figures {
        let _ = writeln!(
            h,
            "<figure>{}<figcaption><b>{}</b> {}</figcaption></figure>",
            fig.svg_element(),
            escape(&fig.title),
            escape(&fig.caption)
        );
    }
    h.push_str("</body></html>\n");
    h
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1600px;margin:2em auto;padding:0 1em;color:#222}\
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:3px 7px}th{background:#eee}\
svg{max-width:100%;height:auto}.meta{color:#555}";

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
