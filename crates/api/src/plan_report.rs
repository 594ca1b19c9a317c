//! The report of `flexstar plan` (`docs/motions.md` 4.7): the comparison of the plain quintic,
//! the ZVD-shaped quintic and the planned motion, each on the accurate AMM and the FEM, as
//! `plan.json`, `plan.md` and the figures `figures/<name>-plan-{G,tips,sliders,forces,path}`.

use std::path::PathBuf;

use rayon::prelude::*;
use serde_json::{json, Value};

use flexstar_metrics::residual::dg_magnitude;
use flexstar_model::{Experiment, Response};
use flexstar_plan::limits::{kinematic_peaks, KinematicPeaks, Peak};
use flexstar_plan::objective::force_peak;
use flexstar_plan::PlanConfig;
use flexstar_plot::{Figure, Panel, Series, Style, FAMILY_COLORS, FEM_STYLE, MARK_STYLE};

use crate::plan::{MotionRuns, PlanOutcome};
use crate::Result;

/// The measures of one motion that the comparison shows.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MotionRow {
    pub motion: String,
    /// Move time [s] (from `t0` to `t_rest`) and `t_rest` [s].
    pub move_s: f64,
    pub t_rest: f64,
    /// Residual peak and RMS of |dG| and of the tips after `t_rest` [m]; AMM, FEM.
    pub g_peak_m: [Option<f64>; 2],
    pub g_rms_m: [Option<f64>; 2],
    pub tip_peak_m: [Option<f64>; 2],
    pub tip_rms_m: [Option<f64>; 2],
    /// Settling time [s] (None: not settled by `t_end`); AMM, FEM.
    pub settle_s: [Option<f64>; 2],
    /// Peak |Fa_i| [N]; AMM, FEM.
    pub fa_peak_n: [f64; 2],
    /// Peak slider speed [m/s], acceleration [m/s^2] and jerk [m/s^3] (rigid kinematics, exact
    /// jets; `docs/motions.md` 4.10).
    pub v_peak: f64,
    pub a_peak: f64,
    pub j_peak: f64,
    /// (AMM - FEM) / FEM of the residual peak of G [%].
    pub g_peak_diff_percent: Option<f64>,
    /// The shaper's frequencies [Hz] and penalty [s] (the ZVD row).
    pub shaper_hz: Vec<f64>,
    pub penalty_s: Option<f64>,
}

/// The row of one motion.
pub fn motion_row(m: &MotionRuns) -> MotionRow {
    // a value the sidecar writes as null (absent or not finite) reads as absent
    let both = |k: fn(&flexstar_model::ResidualKeys) -> Option<f64>| {
        let key = |o: &crate::run::RunOutcome| o.sidecar.residual.as_ref().and_then(k).filter(|v| v.is_finite());
        [key(&m.amm), key(&m.fem)]
    };
    let t_rest = m.exp.trajectory.t_rest().unwrap_or(f64::NAN);
    let t0 = m.exp.trajectory.t_start();
    let zero = KinematicPeaks {
        v: zero_peak(),
        a: zero_peak(),
        j: zero_peak(),
    };
    let KinematicPeaks { v, a, j } =
        kinematic_peaks(&m.exp.robot, &m.exp.trajectory, (t0, t_rest), m.exp.time.dt_out, &[]).unwrap_or(zero);
    let g = both(|r| r.g_peak_m);
    let shaper = m.exp.shaper.as_ref();
    MotionRow {
        motion: m.label.to_string(),
        move_s: t_rest - t0,
        t_rest,
        g_peak_m: g,
        g_rms_m: both(|r| r.g_rms_m),
        tip_peak_m: both(|r| r.tip_peak_m),
        tip_rms_m: both(|r| r.tip_rms_m),
        settle_s: both(|r| r.settle_s),
        fa_peak_n: [force_peak(&m.amm.response).value, force_peak(&m.fem.response).value],
        v_peak: v.value,
        a_peak: a.value,
        j_peak: j.value,
        g_peak_diff_percent: match g {
            [Some(a), Some(f)] if f > 0.0 => Some(100.0 * (a - f) / f),
            _ => None,
        },
        shaper_hz: shaper.map(|s| s.frequencies_hz.clone()).unwrap_or_default(),
        penalty_s: shaper.map(|s| s.penalty_s),
    }
}

fn zero_peak() -> Peak {
    Peak {
        value: 0.0,
        slider: 1,
        t: 0.0,
    }
}

/// `plan.json`: the problem, the limits, N, the family and its via points, the search, the
/// comparison.
pub fn plan_json(cfg: &PlanConfig, o: &PlanOutcome) -> Value {
    let p = &o.planned;
    let points = p.family.points(&p.x, p.t_move);
    let mut v = json!({
        "provenance": crate::provenance(),
        "experiment": cfg.exp.name,
        "plan": cfg.plan,
        "limits": cfg.limits,
        "planner": p,
        "warnings": p.warnings,
        "via_points": points,
        "via_equivalent": "kind = \"via\", rest = false through via_points: the spline plan.csv samples",
        "plain_r_norm_m": p.plain.norm_g(),
        "planned_r_norm_m": p.eval.norm_g(),
        "comparison": o.motions.iter().map(motion_row).collect::<Vec<_>>(),
        "wall_s": o.wall_s,
    });
    if let (Some(info), Some(check)) = (&p.robust, &o.robust) {
        v["robust"] = crate::plan_robust_report::robust_json(info, check);
    }
    v
}

fn mm(v: Option<f64>) -> String {
    v.map_or("n/a".into(), |v| format!("{:.4}", 1e3 * v))
}

fn secs(v: Option<f64>) -> String {
    v.map_or("not settled".into(), |v| format!("{v:.3}"))
}

/// `plan.md`: what was planned, the comparison table, how to read it, the figures.
pub fn plan_markdown(cfg: &PlanConfig, o: &PlanOutcome) -> String {
    let p = &o.planned;
    let rows: Vec<MotionRow> = o.motions.iter().map(motion_row).collect();
    let mut s = format!(
        "# {}: planned motion\n\n{} from ({}, {}, {}) to ({}, {}, {}), t0 = {} s, move time {:.4} s ({} objective, shape \"{}\", {} interior points).\n\n",
        cfg.exp.name,
        cfg.exp.description,
        cfg.plan.from.gx,
        cfg.plan.from.gy,
        cfg.plan.from.theta,
        cfg.plan.to.gx,
        cfg.plan.to.gy,
        cfg.plan.to.theta,
        cfg.plan.t0,
        p.t_move,
        if cfg.plan.residual_max.is_some() { "time" } else { "residual" },
        cfg.plan.shape.word(),
        p.family.m,
    );
    s += &search_text(p);
    s += &peaks_text(p);
    s += &comparison_table(&rows);
    s += &reading_text(&rows);
    if let (Some(info), Some(check)) = (&p.robust, &o.robust) {
        s += &crate::plan_robust_report::robust_markdown(info, check, &cfg.exp.name);
    }
    s += &format!(
        "\n## Figures\n\n![G](figures/{n}-plan-G.svg)\n\n![tips](figures/{n}-plan-tips.svg)\n\n![sliders](figures/{n}-plan-sliders.svg)\n\n![forces](figures/{n}-plan-forces.svg)\n\n![path](figures/{n}-plan-path.svg)\n",
        n = cfg.exp.name
    );
    s
}

/// The search in words: N, window, evaluations, wall time, why it stopped, the time search.
fn search_text(p: &flexstar_plan::Planned) -> String {
    let mut s = format!(
        "The accurate AMM (N = {} per beam, frozen) judged each candidate by the RMS of |dG| over a window of {:.3} s \
         (two periods of the first mode at the final pose, {:.3} Hz) after the move: {:.3e} m for the plain quintic, \
         {:.3e} m planned ({:.1} % of it), after {} in {:.2} s; stop: {}.\n\n",
        p.modes,
        p.window_s,
        p.f1_hz,
        p.plain.norm_g(),
        p.eval.norm_g(),
        100.0 * p.eval.norm_g() / p.plain.norm_g(),
        p.evaluations_text(),
        p.wall_s,
        p.reason
    );
    if let Some(ts) = &p.time_search {
        s += &format!(
            "Time objective: residual_max = {:.3e} m. The shortest ZVD-shaped quintic at it has the base {:.4} s and lasts {:.4} s \
             (AMM peak {:.3e} m); the planned move lasts {:.4} s, {:.1} % shorter.\n\n",
            ts.residual_max_m, ts.zvd_base_s, ts.zvd_duration_s, ts.zvd_peak_m, p.t_move, ts.shorter_percent
        );
        s += &format!(
            "The search over t_move ({} AMM runs for the ZVD baseline, {} for the planned durations):\n\n\
             | t_move [s] | AMM residual peak [m] | holds | AMM runs | LM RMS of abs(dG) [m] | stop | wall [s] |\n|---|---|---|---|---|---|---|\n",
            ts.zvd_evaluations, ts.search_evaluations
        );
        for st in &ts.steps {
            s += &format!(
                "| {:.4} | {:.3e} | {} | {} | {} | {} | {:.2} |\n",
                st.t_move,
                st.peak_m,
                if st.ok { "yes" } else { "no" },
                st.evaluations,
                st.r_norm_m.map_or("-".into(), |r| format!("{r:.3e}")),
                st.reason,
                st.wall_s
            );
        }
        s += "\n";
    }
    s
}

/// The limits the search enforced, the peaks against the plain quintic's, and the warnings
/// (`docs/motions.md` 4.10).
fn peaks_text(p: &flexstar_plan::Planned) -> String {
    let b = &p.bounds;
    let lim = |v: Option<f64>| v.map_or("none".to_string(), |v| format!("{v:.4}"));
    let (q, n) = (&p.peaks.plain, &p.peaks.planned);
    let mut s = format!(
        "Limits the search enforced (peak factor {}): v_max {} m/s, a_max {} m/s^2, j_max {} m/s^3, Fa_max {} N. \
         Peaks, plain quintic -> planned (AMM search samples): |s''| {:.4} -> {:.4} m/s^2, |s'''| {:.2} -> {:.2} m/s^3, \
         |Fa| {:.4} -> {:.4} N.\n\n",
        p.peak_factor.map_or("off".to_string(), |f| f.to_string()),
        lim(b.v_max),
        lim(b.a_max),
        lim(b.j_max),
        lim(b.fa_max),
        q.a.value,
        n.a.value,
        q.j.value,
        n.j.value,
        q.fa.value,
        n.fa.value
    );
    for w in &p.warnings {
        s += &format!("**Warning:** {w}.\n\n");
    }
    s
}

/// The comparison table (AMM / FEM in each cell).
fn comparison_table(rows: &[MotionRow]) -> String {
    let mut s = String::from(
        "## Comparison (each cell AMM / FEM)\n\n| motion | move [s] | t_rest [s] | residual G peak [mm] | G RMS [mm] | tips peak [mm] | tips RMS [mm] | settle [s] | peak abs(Fa) [N] | peak abs(s') [m/s] | peak abs(s'') [m/s^2] | peak abs(s''') [m/s^3] | AMM-FEM G peak [%] | shaper [Hz], penalty [s] |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let pair = |v: [Option<f64>; 2]| format!("{} / {}", mm(v[0]), mm(v[1]));
        let shaper = match r.penalty_s {
            Some(pen) => format!(
                "{} ; {pen:.4}",
                r.shaper_hz
                    .iter()
                    .map(|f| format!("{f:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            None => "-".into(),
        };
        s += &format!(
            "| {} | {:.4} | {:.4} | {} | {} | {} | {} | {} / {} | {:.3} / {:.3} | {:.4} | {:.3} | {:.1} | {} | {} |\n",
            r.motion,
            r.move_s,
            r.t_rest,
            pair(r.g_peak_m),
            pair(r.g_rms_m),
            pair(r.tip_peak_m),
            pair(r.tip_rms_m),
            secs(r.settle_s[0]),
            secs(r.settle_s[1]),
            r.fa_peak_n[0],
            r.fa_peak_n[1],
            r.v_peak,
            r.a_peak,
            r.j_peak,
            r.g_peak_diff_percent.map_or("n/a".into(), |d| format!("{d:+.1}")),
            shaper
        );
    }
    s
}

/// How to read the table: the ratios to the plain quintic on the FEM.
fn reading_text(rows: &[MotionRow]) -> String {
    let fem = |k: usize| rows.get(k).and_then(|r| r.g_peak_m[1]);
    let (Some(plain), Some(zvd), Some(plan)) = (fem(0), fem(1), fem(2)) else {
        return String::new();
    };
    format!(
        "\nOn the FEM, the residual peak of G after the move is {:.4} of the plain quintic's for the ZVD-shaped quintic \
         (which takes {:.3} s longer) and {:.4} for the planned motion. The residual is measured from t_rest to t_end \
         (docs/motions.md 2.2); the tips' residual is shown, not minimised.\n",
        zvd / plain,
        rows[1].move_s - rows[0].move_s,
        plan / plain
    )
}

/// |dG|(t) [m] of a run.
fn dg_series(r: &Response) -> Vec<f64> {
    (0..r.t.len())
        .map(|k| dg_magnitude([r.w_g[0][k], r.w_g[1][k], r.w_g[2][k]]))
        .collect()
}

/// RMS over the three tips [m] of a run.
fn tip_series(r: &Response) -> Vec<f64> {
    (0..r.t.len())
        .map(|k| (r.w_tip.iter().map(|w| w[k] * w[k]).sum::<f64>() / 3.0).sqrt())
        .collect()
}

/// The colour of motion `k` (plain red, ZVD blue, planned orange; with `[robust]` the nominal
/// plan and the shaper over the uncertainty in the two other colours).
pub fn style(k: usize, dashed: bool) -> Style {
    Style {
        color: FAMILY_COLORS[[0, 1, 4, 2, 3][k % 5]],
        width: 2,
        dashed,
    }
}

/// One panel per motion of `f(run)` [scaled by `scale`], AMM coloured and FEM black, `t_rest`
/// marked.
fn per_motion_panels(o: &PlanOutcome, y_label: &str, scale: f64, f: fn(&Response) -> Vec<f64>) -> Vec<Panel> {
    o.motions
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let curve = |r: &Response, label: String, style: Style| Series {
                label,
                x: r.t.clone(),
                y: f(r).iter().map(|v| v * scale).collect(),
                style,
            };
            let mut series = vec![
                curve(
                    &m.fem.response,
                    if k == 0 { "FEM".into() } else { String::new() },
                    FEM_STYLE,
                ),
                curve(&m.amm.response, format!("AMM, {}", m.key), style(k, false)),
            ];
            let top = series.iter().flat_map(|s| s.y.iter()).fold(0.0f64, |a, b| a.max(*b));
            let t_rest = m.exp.trajectory.t_rest().unwrap_or(0.0);
            series.push(Series {
                label: if k == 0 { "t_rest".into() } else { String::new() },
                x: vec![t_rest, t_rest],
                y: vec![0.0, top],
                style: MARK_STYLE,
            });
            Panel {
                title: m.label.to_string(),
                x_label: "t [s]".into(),
                y_label: y_label.into(),
                series,
                equal_axes: false,
                min_y_span: 1e-6,
            }
        })
        .collect()
}

/// The zoom rows of the per-motion figures: each motion (column) on its own move, `0..t_rest`,
/// and on the planner's window after it, `t_rest .. t_rest + window_s` (two periods of the first
/// mode at the final pose, docs/motions.md 4), cut at `t_end`.
pub(crate) fn plan_zooms(o: &PlanOutcome) -> Vec<flexstar_plot::Zoom> {
    let t_end = o.motions.first().map_or(f64::INFINITY, |m| m.exp.time.t_end);
    let rests: Vec<f64> = o
        .motions
        .iter()
        .map(|m| m.exp.trajectory.t_rest().unwrap_or(t_end))
        .collect();
    vec![
        flexstar_plot::Zoom {
            label: "the move".into(),
            windows: rests.iter().map(|&t| (0.0, t)).collect(),
        },
        flexstar_plot::Zoom {
            label: "the planner's window".into(),
            windows: rests
                .iter()
                .map(|&t| (t, (t + o.planned.window_s).min(t_end)))
                .collect(),
        },
    ]
}

/// The figures of 4.7, written to `dir/figures/`.
pub fn write_figures(exp: &Experiment, o: &PlanOutcome) -> Result<Vec<PathBuf>> {
    let dir = o.dir.join("figures");
    flexstar_io::output::ensure_writable_dir(&dir)?;
    let n = &exp.name;
    let figures = [
        Figure {
            name: format!("{n}-plan-G"),
            title: format!("{n}: elastic displacement of G, |dG|"),
            caption: "The three motions on the AMM (colour) and the FEM (black); after t_rest (dashed) what is left is the residual vibration.".into(),
            panels: per_motion_panels(o, "|dG| [mm]", 1e3, dg_series),
            zooms: plan_zooms(o),
        },
        Figure {
            name: format!("{n}-plan-tips"),
            title: format!("{n}: tip deflection, RMS over the three tips"),
            caption: "The planner minimises the residual at G only; the tips' residual is shown for judgement.".into(),
            panels: per_motion_panels(o, "tips RMS [mm]", 1e3, tip_series),
            zooms: plan_zooms(o),
        },
        crate::plan_figures::sliders_figure(exp, o),
        crate::plan_figures::forces_figure(exp, o),
        crate::plan_figures::path_figure(exp, o),
    ];
    let robust = o
        .robust
        .as_ref()
        .map(|c| crate::plan_robust_report::curves_figure(n, c));
    // each figure drawn and rasterised on its own thread (they share nothing)
    let figures: Vec<_> = figures.into_iter().chain(robust).collect();
    let written: Vec<Vec<PathBuf>> = figures
        .par_iter()
        .map(|fig| {
            fig.write(&dir)?;
            Ok(["svg", "png"].map(|e| dir.join(format!("{}.{e}", fig.name))).to_vec())
        })
        .collect::<Result<_>>()?;
    Ok(written.concat())
}
