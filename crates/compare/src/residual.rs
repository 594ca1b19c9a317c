//! The residual vibration of every run of a case after its motion has come to rest
//! (`docs/motions.md` 2.4): `residual.csv`, its table in `compare.md` and `report.html`,
//! and the mark of `t_rest` on the time plots.

use std::fmt::Write as _;

use flexstar_io::output::fmt_number;
use flexstar_metrics::residual::{residual_after, settle_text, Residual};
use flexstar_model::{Experiment, ModeFamily};
use flexstar_plot::{Figure, Series, Zoom, MARK_STYLE};

use crate::case_output::runs_of;
use crate::runs::CaseResults;
use crate::Error;

/// Header of `residual.csv` (a file contract, `docs/motions.md` 2.4).
pub const RESIDUAL_CSV_HEADER: &str =
    "run,t_rest,residual_G_peak_m,residual_G_rms_m,residual_tip_peak_m,residual_tip_rms_m,settle_s";

/// Each run's residual (file stem, measures), in the order of [`runs_of`]. `g_pinned`: the run's
/// family pins G (pinned-free), so it has no residual of G.
#[derive(Debug, Clone)]
pub struct RunResidual {
    pub run: String,
    pub residual: Residual,
    pub g_pinned: bool,
}

/// The residuals of a case, computed once (one modal analysis for the settling hold of
/// motions.md 2.3); `None` when the motion does not rest before `t_end`.
pub fn case_residuals(exp: &Experiment, case: &CaseResults) -> Result<Option<Vec<RunResidual>>, Error> {
    let hold = flexstar_modal::settle::settle_hold_s(exp).map_err(|e| Error::Input {
        file: exp.source.display().to_string(),
        reason: format!("settling time: {e}"),
    })?;
    let (Some(t_rest), Some(hold)) = (flexstar_modal::settle::motion_end(exp), hold) else {
        return Ok(None);
    };
    let pinned: Vec<bool> = std::iter::once(false)
        .chain(
            case.amm
                .iter()
                .map(|(run, _)| run.settings.family == ModeFamily::PinnedFree),
        )
        .collect();
    let runs = runs_of(case)
        .into_iter()
        .zip(pinned)
        .filter_map(|((run, r), g_pinned)| {
            residual_after(r, t_rest, exp.report.settle_tol, hold).map(|residual| RunResidual {
                run,
                residual,
                g_pinned,
            })
        })
        .collect();
    Ok(Some(runs))
}

/// The sidecar's residual keys of one compared run, as `flexstar run` writes them.
pub fn sidecar_keys_of(r: &RunResidual) -> flexstar_model::ResidualKeys {
    flexstar_metrics::residual::sidecar_keys(Some(&r.residual), r.residual.settle_tol, r.g_pinned)
}

fn g_value(r: &RunResidual, v: f64) -> Option<f64> {
    (!r.g_pinned).then_some(v)
}

/// `residual.csv`: one row per run; empty fields where a measure does not exist (G pinned by
/// the family; `settle_s` when not settled by `t_end`).
pub fn residual_csv(runs: &[RunResidual]) -> String {
    let num = |v: Option<f64>| v.map(fmt_number).unwrap_or_default();
    let mut s = String::from(RESIDUAL_CSV_HEADER);
    s.push('\n');
    for r in runs {
        let m = &r.residual;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{}",
            r.run,
            fmt_number(m.t_rest),
            num(g_value(r, m.g_peak_m)),
            num(g_value(r, m.g_rms_m)),
            num(Some(m.tip_peak_m)),
            num(Some(m.tip_rms_m)),
            num(m.settle_s.filter(|_| !r.g_pinned)),
        );
    }
    s
}

/// The table of `compare.md` (and, through its HTML form, of `report.html`).
pub fn residual_markdown(runs: &[RunResidual]) -> String {
    let Some(first) = runs.first() else {
        return String::new();
    };
    let m0 = &first.residual;
    let mut s = format!(
        "## Residual vibration after the motion (t_rest = {} s)\n\ndG is the length of G's elastic displacement, \
         sqrt(2/3 sum w_iG^2); tips: the largest of w_i(L) in magnitude, RMS of the three. Settled: the last time \
         dG exceeds settle_tol = {:e} m, when the run then stays below it for at least one period of the first \
         mode at the final pose ({:.3} s).\n\n",
        flexstar_io::output::fmt_sig(m0.t_rest, 5),
        m0.settle_tol,
        m0.hold_s
    );
    s.push_str("| run | peak dG [mm] | RMS dG [mm] | peak tip [mm] | RMS tip [mm] | settled at |\n");
    s.push_str("|---|---|---|---|---|---|\n");
    let mm = |v: Option<f64>| v.map_or("n/a (G pinned)".to_string(), |x| format!("{:.4}", x * 1e3));
    for r in runs {
        let m = &r.residual;
        let settle = if r.g_pinned { "n/a".into() } else { settle_text(m) };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.4} | {:.4} | {settle} |",
            r.run,
            mm(g_value(r, m.g_peak_m)),
            mm(g_value(r, m.g_rms_m)),
            m.tip_peak_m * 1e3,
            m.tip_rms_m * 1e3,
        );
    }
    s.push('\n');
    let mut notes = Vec::new();
    for r in runs {
        let m = &r.residual;
        if let (Some(peak), Some(end)) = (m.tracking_peak_m, m.tracking_end_m) {
            notes.push(format!(
                "- {}: {}.",
                r.run,
                flexstar_metrics::residual::tracking_text(peak, end)
            ));
        }
        if let Some(hint) = flexstar_metrics::residual::not_settled_hint(m).filter(|_| !r.g_pinned) {
            notes.push(format!("- {}: {hint}.", r.run));
        }
    }
    if !notes.is_empty() {
        s.push_str(&notes.join("\n"));
        s.push_str("\n\n");
    }
    s
}

/// The zoom rows of a time figure whose motion comes to rest at `t_rest` [s] within the first
/// half of a run to `t_end` [s] (else none: the whole run shows the motion well enough): the
/// motion, `0..t_rest`, and the residual window after it, `t_rest .. t_rest + 2 hold` (two
/// periods of the first mode at the final pose, the window the planner judges a motion by,
/// docs/motions.md 4), cut at `t_end`.
pub fn time_zooms(t_rest: f64, hold: f64, t_end: f64) -> Vec<Zoom> {
    if !(t_rest > 0.0 && t_rest <= 0.5 * t_end && hold > 0.0) {
        return Vec::new();
    }
    vec![
        Zoom {
            label: "the motion".into(),
            windows: vec![(0.0, t_rest)],
        },
        Zoom {
            label: "after it, 2 periods of mode 1".into(),
            windows: vec![(t_rest, (t_rest + 2.0 * hold).min(t_end))],
        },
    ]
}

/// Mark `t_rest` [s] on every panel of a time figure: a dashed vertical line over the panel's
/// data range, named once in the legend.
pub fn mark_t_rest(fig: &mut Figure, t_rest: f64) {
    for (k, panel) in fig.panels.iter_mut().enumerate() {
        let ys = panel
            .series
            .iter()
            .flat_map(|s| s.y.iter().copied())
            .filter(|v| v.is_finite());
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if !lo.is_finite() {
            continue;
        }
        panel.series.push(Series {
            label: if k == 0 { "t_rest".into() } else { String::new() },
            x: vec![t_rest, t_rest],
            y: vec![lo, hi],
            style: MARK_STYLE,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zooms_cover_the_motion_and_two_periods_after_it() {
        let z = time_zooms(0.3, 0.2167, 6.0);
        assert_eq!(z.len(), 2);
        assert_eq!(z[0].windows, vec![(0.0, 0.3)]);
        assert_eq!(z[1].windows, vec![(0.3, 0.3 + 2.0 * 0.2167)]);
        // cut at t_end; none when the motion fills more than half the run
        assert_eq!(time_zooms(0.3, 0.2, 0.6)[1].windows, vec![(0.3, 0.6)]);
        assert!(time_zooms(0.4, 0.2, 0.6).is_empty());
    }
}
