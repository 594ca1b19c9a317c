//! The residual vibration of every run per dwell (`docs/motions.md` 2.5): each run's
//! `<stem>-dwells.csv` and sidecar key `dwells`, the table "Residual vibration per dwell" of
//! `compare.md` and `report.html`, the figure of |dG| against time with the settling band and
//! each dwell's settling instant, and the zoom rows on each move and its dwell.

use std::fmt::Write as _;

use flexstar_metrics::residual::dg_magnitude;
use flexstar_model::{DwellKeys, Experiment, ModeFamily, Response};
use flexstar_plot::{Figure, Panel, Series, Style, Zoom, MARK_STYLE, RIGID_STYLE};

use crate::case_output::runs_of;
use crate::figures::Run;
use crate::runs::CaseResults;
use crate::Error;

/// One run's dwells (file stem, the entries of its sidecar's `dwells`).
#[derive(Debug, Clone)]
pub struct RunDwells {
    pub run: String,
    pub dwells: Vec<DwellKeys>,
}

/// Every run's dwells, in the order of [`runs_of`] (FEM first); empty when no move of the
/// motion ends before `t_end`. A pinned-free AMM run has its G measures null.
pub fn case_dwells(exp: &Experiment, case: &CaseResults) -> Result<Vec<RunDwells>, Error> {
    let pinned = std::iter::once(false).chain(
        case.amm
            .iter()
            .map(|(run, _)| run.settings.family == ModeFamily::PinnedFree),
    );
    let mut out = Vec::new();
    for ((run, r), g_pinned) in runs_of(case).into_iter().zip(pinned) {
        let dwells = flexstar_modal::settle::run_dwells(exp, r, g_pinned).map_err(|e| Error::Input {
            file: exp.source.display().to_string(),
            reason: format!("settling per dwell: {e}"),
        })?;
        if let Some(dwells) = dwells {
            out.push(RunDwells { run, dwells });
        }
    }
    Ok(out)
}

/// The table of `compare.md` and `report.html`: one row per run and dwell; empty when every run
/// has at most one dwell (the single residual table says it all then).
pub fn dwells_markdown(runs: &[RunDwells]) -> String {
    if runs.iter().all(|r| r.dwells.len() < 2) {
        return String::new();
    }
    let mut s = String::from(
        "## Residual vibration per dwell\n\nEach dwell runs from the end of a move (the sliders at rest) to the \
         start of the next move, or to t_end after the last (docs/motions.md 2.5); the measures of the table \
         above within it. Settled: the last time dG exceeds settle_tol, when the dwell then ends with at least \
         one period of the first mode at its pose below it. Also in each run's `<stem>-dwells.csv`.\n\n",
    );
    s.push_str(
        "| run | dwell | move [s] | dwell [s] | peak dG [mm] | RMS dG [mm] | peak tip [mm] | RMS tip [mm] | \
         settled at | note |\n",
    );
    s.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    let mm = |v: Option<f64>| v.map_or("n/a".to_string(), |x| format!("{:.4}", x * 1e3));
    let secs = |t: f64| flexstar_io::output::fmt_sig(t, 4);
    for r in runs {
        for d in &r.dwells {
            let settle = match (d.settle_s, d.settled) {
                (Some(t), _) => format!("{t:.3} s"),
                (None, Some(false)) => "not settled".to_string(),
                _ => "n/a".to_string(),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {}-{} | {}-{} | {} | {} | {} | {} | {settle} | {} |",
                r.run,
                d.dwell,
                secs(d.move_start),
                secs(d.move_end),
                secs(d.t_start),
                secs(d.t_end),
                mm(d.g_peak_m),
                mm(d.g_rms_m),
                mm(d.tip_peak_m),
                mm(d.tip_rms_m),
                d.note.as_deref().unwrap_or("").replace('|', "/"),
            );
        }
    }
    s.push('\n');
    s
}

/// The zoom rows of a time figure on the dwells `dwells` of a run to `t_end` [s]: with several
/// dwells, one row per move and its dwell, `move_start .. t_end of the dwell`, labelled `move k
/// and its dwell`; with one, the rows of [`crate::residual::time_zooms`] (the motion and the two
/// periods after it, when the motion fills at most half the run).
pub fn dwell_zooms(dwells: &[DwellKeys], t_end: f64) -> Vec<Zoom> {
    match dwells {
        [] => Vec::new(),
        [d] => d
            .settle_hold_s
            .map_or_else(Vec::new, |hold| crate::residual::time_zooms(d.move_end, hold, t_end)),
        _ => dwells
            .iter()
            .map(|d| Zoom {
                label: format!("move {} and its dwell", d.dwell),
                windows: vec![(d.move_start, d.t_end.max(d.move_end))],
            })
            .collect(),
    }
}

/// |dG| [m] of `r` at every output time, about the static sag at the final pose under gravity
/// (`Response::w_g_about_rest`, what the residual measures).
pub fn dg_series(r: &Response) -> Vec<f64> {
    (0..r.len())
        .map(|k| dg_magnitude([0, 1, 2].map(|i| r.w_g_about_rest(i, k))))
        .collect()
}

/// The figure `<name>-dG` (`docs/outputs.md`): |dG| [mm] of every run against time, the band
/// `settle_tol` [m] (grey dashed), the end of each move (blue-grey dashed) and each dwell's
/// settling instant in the run's colour (thin dashed); `dwells[k]` are the dwells of `runs[k]`
/// (the same windows for every run). Zoom rows by [`dwell_zooms`] over `[0, t_end]` [s].
pub fn figure_dg(
    name: &str,
    title: &str,
    runs: &[Run],
    dwells: &[&[DwellKeys]],
    settle_tol: f64,
    t_end: f64,
) -> Figure {
    let mut series: Vec<Series> = runs
        .iter()
        .map(|r| Series {
            label: r.label.clone(),
            x: r.response.t.clone(),
            y: dg_series(r.response).iter().map(|v| v * 1e3).collect(),
            style: r.style,
        })
        .collect();
    // the band as a curve on the output times, so that a zoom keeps it
    if let Some(r) = runs.first() {
        series.push(Series {
            label: format!(
                "band settle_tol = {} mm",
                flexstar_io::output::fmt_sig(settle_tol * 1e3, 3)
            ),
            x: r.response.t.clone(),
            y: vec![settle_tol * 1e3; r.response.len()],
            style: RIGID_STYLE,
        });
    }
    let first = dwells.first().copied().unwrap_or_default();
    for (k, d) in first.iter().enumerate() {
        series.push(Series {
            label: if k == 0 { "end of a move".into() } else { String::new() },
            x: vec![d.move_end, d.move_end],
            y: vec![0.0, settle_tol * 1e3],
            style: MARK_STYLE,
        });
    }
    for (r, ds) in runs.iter().zip(dwells) {
        let style = Style {
            color: r.style.color,
            width: 1,
            dashed: true,
        };
        let mut named = false;
        for t in ds.iter().filter_map(|d| d.settle_s) {
            series.push(Series {
                label: if named {
                    String::new()
                } else {
                    format!("settled, {}", r.label)
                },
                x: vec![t, t],
                y: vec![0.0, settle_tol * 1e3],
                style,
            });
            named = true;
        }
    }
    Figure {
        name: name.to_string(),
        title: title.to_string(),
        caption: format!(
            "The length of G's elastic displacement against time (about the static sag at the final pose under \
             gravity), with the settling band settle_tol = {} m (grey dashed). Each move ends at a blue-grey dashed \
             line; a thin dashed line in a run's colour marks where it settled in a dwell: the last time |dG| left \
             the band, the dwell then ending with at least one period of the first mode at its pose inside it \
             (docs/motions.md 2.5). A dwell without such a line did not settle. The rows below zoom on each move \
             and its dwell.",
            flexstar_io::output::fmt_display(settle_tol)
        ),
        panels: vec![Panel {
            title: "|dG|".into(),
            x_label: "t [s]".into(),
            y_label: "|dG| [mm]".into(),
            series,
            equal_axes: false,
            min_y_span: 1e-3,
        }],
        zooms: dwell_zooms(first, t_end),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dwell(k: usize, move_start: f64, move_end: f64, t_end: f64) -> DwellKeys {
        DwellKeys {
            dwell: k,
            move_start,
            move_end,
            t_start: move_end,
            t_end,
            g_peak_m: Some(1e-4),
            g_rms_m: Some(5e-5),
            tip_peak_m: Some(1e-3),
            tip_rms_m: Some(5e-4),
            settle_s: None,
            settled: Some(false),
            settle_hold_s: Some(0.25),
            note: None,
        }
    }

    #[test]
    fn several_moves_get_a_row_each_and_one_move_the_rows_of_the_residual() {
        let two = [dwell(1, 0.0, 0.4, 0.7), dwell(2, 0.7, 1.1, 1.5)];
        let z = dwell_zooms(&two, 1.5);
        assert_eq!(z.len(), 2);
        assert_eq!(z[0].windows, vec![(0.0, 0.7)]);
        assert_eq!(z[1].windows, vec![(0.7, 1.5)]);
        assert_eq!(z[1].label, "move 2 and its dwell");
        assert_eq!(dwell_zooms(&two[..1], 6.0), crate::residual::time_zooms(0.4, 0.25, 6.0));
        assert!(dwell_zooms(&[], 1.0).is_empty());
        // the table only for several dwells
        let one = RunDwells {
            run: "fem".into(),
            dwells: two[..1].to_vec(),
        };
        assert!(dwells_markdown(&[one]).is_empty());
        let md = dwells_markdown(&[RunDwells {
            run: "fem".into(),
            dwells: two.to_vec(),
        }]);
        assert!(md.contains("| fem | 2 | 0.7-1.1 | 1.1-1.5 | 0.1000 | 0.0500 |"), "{md}");
    }
}
