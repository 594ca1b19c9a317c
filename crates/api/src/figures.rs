//! A run's figures (`flexstar run --figures`): a direct run's four, or the tips and forces of a
//! prescribed motion.

use std::path::{Path, PathBuf};

use flexstar_compare::direct_figures::{direct_figures, run_style};
use flexstar_compare::figures::{figure_forces, figure_tips, Run};
use flexstar_model::{Experiment, Response};

use crate::{ApiError, Result};

/// Draw a run's figures into `dir/figures/`; returns the SVG and PNG files written.
pub fn run_figures(exp: &Experiment, stem: &str, r: &Response, direct: bool, dir: &Path) -> Result<Vec<PathBuf>> {
    let figs = if direct {
        direct_figures(exp, stem, r)
    } else {
        let runs = [Run {
            label: stem.to_string(),
            response: r,
            style: run_style(r),
        }];
        let mut v = vec![figure_tips(&exp.name, &runs), figure_forces(&exp.name, &runs, None)];
        for (f, kind) in v.iter_mut().zip(["tips", "forces"]) {
            f.name = format!("{stem}-{kind}");
        }
        v
    };
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
