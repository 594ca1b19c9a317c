//! The report of a robust plan (`docs/motions.md` 4.11): `plan.json`'s `robust` block, the
//! section of `plan.md`, the robustness curves `figures/<name>-robust.{svg,png}`.

use serde_json::{json, Value};

use flexstar_plan::robust::RobustInfo;
use flexstar_plot::{Figure, Panel, Series};

use crate::plan_robust::{RobustCheck, Summary};

/// `plan.json`'s `robust`: the uncertainty, the sample and its choice, the search's objective,
/// the shaper over the uncertainty, and the checks (sample on the AMM, fresh draws on the model
/// of `[robust] check`).
pub fn robust_json(info: &RobustInfo, c: &RobustCheck) -> Value {
    let shaper = info.shaped.exp.shaper.as_ref();
    json!({
        "uncertainty": info.uncertainty,
        "sample": info.sample,
        "candidates": info.candidates.iter().map(|(v, f)| json!({"values": v, "f1_hz": f})).collect::<Vec<_>>(),
        "t_move_s": {
            "plan": info.nominal.t_move,
            "robust_plan": info.t_move_s,
        },
        "objective_m": {
            "plain": info.objective_plain_m,
            "plain_at_robust_t_move": info.objective_plain_robust_m,
            "nominal_plan": info.objective_nominal_m,
            "robust_plan": info.objective_m,
            "start": info.start,
        },
        "nominal_plan": {
            "x": info.nominal.x,
            "evaluations": info.nominal.evaluations,
            "reason": info.nominal.reason,
        },
        "shaper": {
            "nominal_hz": info.shaped.nominal_hz,
            "bands_hz": info.shaped.bands,
            "insensitivity_percent": info.shaped.half_width_percent,
            "frequencies_hz": shaper.map(|s| s.frequencies_hz.clone()),
            "penalty_s": shaper.map(|s| s.penalty_s),
        },
        "check": c,
    })
}

fn mm(v: f64) -> String {
    format!("{:.4}", 1e3 * v)
}

/// The section of `plan.md`.
pub fn robust_markdown(info: &RobustInfo, c: &RobustCheck, name: &str) -> String {
    let u = &info.uncertainty;
    let mut s = String::from("\n## Robustness (docs/motions.md 4.11)\n\nUncertainty: ");
    s += &u
        .ranges
        .iter()
        .map(|r| format!("{} in [{}, {}] (nominal {})", r.key, r.lo, r.hi, r.nominal))
        .collect::<Vec<_>>()
        .join(", ");
    s += &format!(
        "; quantile {}. The search held over {} sample models (first frequency at the final pose {} Hz) and minimised \
         their {} residual: RMS over each model's window {:.3e} m for the plain quintic, {:.3e} m for the nominal plan, \
         {:.3e} m for the robust plan (started from the {}). The plain quintic and the nominal plan take t_move = {} s, \
         the robust plan {:.4} s{}.\n\n",
        u.quantile,
        info.sample.len(),
        info.sample.iter().map(|m| format!("{:.3}", m.f1_hz)).collect::<Vec<_>>().join(", "),
        if u.quantile >= 1.0 { "worst" } else { "quantile" },
        info.objective_plain_m,
        info.objective_nominal_m,
        info.objective_m,
        info.start,
        info.nominal.t_move,
        info.t_move_s,
        match u.t_move {
            flexstar_plan::uncertainty::RobustDuration::Zvd => " (the ZVD-shaped quintic's: [robust] t_move = \"zvd\")",
            _ => "",
        }
    );
    if let Some(v) = info.objective_plain_robust_m {
        s += &format!(
            "The plain quintic of the robust plan's duration ({:.4} s) leaves {v:.3e} m by the same measure.\n\n",
            info.t_move_s
        );
    }
    s += &format!(
        "The shaper over the uncertainty covers the bands {} Hz (si, +-{} %); its residual is measured below, not predicted.\n\n",
        info.shaped
            .bands
            .iter()
            .map(|(lo, hi)| format!("{lo:.3}-{hi:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
        info.shaped.half_width_percent
    );
    s += &format!(
        "Residual peak of abs(dG) after each motion's t_rest over {:.3} s, in mm: on the {} sample models (AMM) and on {} \
         fresh models drawn uniformly in the box ({m}, seed {}):\n\n| motion | sample worst | sample q-quantile | draws worst ({m}) | draws q-quantile ({m}) | draws worst / plain's |\n|---|---|---|---|---|---|\n",
        c.window_s,
        c.sample.len(),
        c.draws.len(),
        u.seed,
        m = c.draws_model,
    );
    let plain = c.draws_summary.first().map_or(f64::NAN, |p| p.worst_m);
    for (a, d) in c.sample_summary.iter().zip(&c.draws_summary) {
        s += &row(a, d, plain);
    }
    if !c.failures.is_empty() {
        s += &format!("\nRuns that failed: {}.\n", c.failures.join("; "));
    }
    s += &format!("\n![robustness curves](figures/{name}-robust.svg)\n");
    s
}

fn row(a: &Summary, d: &Summary, plain: f64) -> String {
    format!(
        "| {} | {} | {} | {} | {} | {:.4} |\n",
        a.motion,
        mm(a.worst_m),
        mm(a.quantile_m),
        mm(d.worst_m),
        mm(d.quantile_m),
        d.worst_m / plain
    )
}

/// The robustness curves: one panel per uncertain key, `log10` of the AMM residual peak of G
/// against the key over its range (the others nominal), one line per motion.
pub fn curves_figure(name: &str, c: &RobustCheck) -> Figure {
    let panels = c
        .curves
        .iter()
        .enumerate()
        .map(|(j, curve)| Panel {
            title: curve.key.clone(),
            x_label: curve.key.clone(),
            y_label: "log10 residual peak of |dG| [m]".into(),
            series: c
                .motions
                .iter()
                .enumerate()
                .map(|(k, m)| {
                    let points: Vec<(f64, f64)> = curve
                        .values
                        .iter()
                        .zip(&curve.residual_m[k])
                        .filter_map(|(x, y)| y.filter(|y| *y > 0.0).map(|y| (*x, y.log10())))
                        .collect();
                    Series {
                        label: if j == 0 { m.clone() } else { String::new() },
                        x: points.iter().map(|p| p.0).collect(),
                        y: points.iter().map(|p| p.1).collect(),
                        style: crate::plan_report::style(k, false),
                    }
                })
                .collect(),
            equal_axes: false,
            min_y_span: 0.1,
        })
        .collect();
    Figure {
        name: format!("{name}-robust"),
        title: format!("{name}: residual against each uncertain key (robustness curves)"),
        caption: "The AMM's residual peak of G after each motion's rest against one uncertain key over its range, the \
                  others at their nominal values; lower and flatter is more robust."
            .into(),
        panels,
        zooms: Vec::new(),
    }
}
