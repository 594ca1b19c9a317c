//! A run's figures (`flexstar run --figures`): a direct run's four, or the tips and forces of a
//! prescribed motion; with a dwell (`docs/motions.md` 2.5) also `<stem>-dG`, |dG| with the
//! settling band and each dwell's settling instant.

use std::path::{Path, PathBuf};

use flexstar_compare::direct_figures::{direct_figures, run_style};
use flexstar_compare::dwells::{dwell_zooms, figure_dg};
use flexstar_compare::figures::{figure_forces, figure_tips, Run};
use flexstar_model::{DwellKeys, Experiment, Response};

use crate::{ApiError, Result};

/// Draw a run's figures into `dir/figures/`; returns the SVG and PNG files written. `dwells`:
/// the run's dwells (its sidecar's `dwells`): with any, the figure `<stem>-dG`; with several, a
/// prescribed motion's tips and forces get one zoom row per move and its dwell.
pub fn run_figures(
    exp: &Experiment,
    stem: &str,
    r: &Response,
    direct: bool,
    dir: &Path,
    dwells: Option<&[DwellKeys]>,
) -> Result<Vec<PathBuf>> {
    let runs = [Run {
        label: stem.to_string(),
        response: r,
        style: run_style(r),
    }];
    let mut figs = if direct {
        direct_figures(exp, stem, r)
    } else {
        let mut v = vec![figure_tips(&exp.name, &runs), figure_forces(&exp.name, &runs, None)];
        for (f, kind) in v.iter_mut().zip(["tips", "forces"]) {
            f.name = format!("{stem}-{kind}");
            if let Some(d) = dwells.filter(|d| d.len() > 1) {
                f.zooms = dwell_zooms(d, exp.time.t_end);
            }
        }
        v
    };
    if let Some(d) = dwells {
        figs.push(figure_dg(
            &format!("{stem}-dG"),
            &format!("{}: |dG| per move and dwell", exp.name),
            &runs,
            &[d],
            exp.report.settle_tol,
            exp.time.t_end,
        ));
    }
    let figdir = dir.join("figures");
    std::fs::create_dir_all(&figdir).map_err(|e| ApiError::Output(format!("{}: {e}", figdir.display())))?;
    let mut files = Vec::new();
    for f in &figs {
        f.write(&figdir)?;
        files.push(figdir.join(format!("{}.svg", f.name)));
        files.push(figdir.join(format!("{}.png", f.name)));
    }
    Ok(files)
}
