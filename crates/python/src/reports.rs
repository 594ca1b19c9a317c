//! `compare`, `verify` and `freqmap`: the library's commands that write reports, with their
//! main numbers returned as dicts.

use std::path::PathBuf;

use flexstar_api::study::{compare as compare_api, verify as verify_api, CompareOptions, Progress, VerifyOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{convert, interrupt, py_err, ConfigError, PyExperiment};

/// Compare the AMM with the FEM on an experiment file (as `flexstar compare`): writes
/// `out/<name>/`; returns `{"dir", "behaviour", "most_accurate", "compare_csv"}`. `measured`: a
/// recording laid over the runs (as `--measured`, `docs/measured.md`).
#[pyfunction]
#[pyo3(signature = (config, out, families = Vec::new(), modes = None, figures = false, progress = false, measured = None))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments, one per flag of `flexstar compare`
pub fn compare<'py>(
    py: Python<'py>,
    config: PathBuf,
    out: PathBuf,
    families: Vec<String>,
    modes: Option<usize>,
    figures: bool,
    progress: bool,
    measured: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let families = families
        .iter()
        .map(|f| convert::parse("families", f))
        .collect::<PyResult<Vec<_>>>()?;
    let opts = CompareOptions {
        config,
        families,
        modes,
        out,
        figures,
        provenance: flexstar_api::provenance(),
        measured,
    };
    let o = interrupt::interruptible(py, "flexstar.compare", progress, |report| {
        let tick = |p: Progress| report(p.fraction);
        compare_api(&opts, Some(&tick))
    })?
    .map_err(py_err)?;
    for note in &o.notes {
        let text = std::ffi::CString::new(note.trim_start_matches("note: ")).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
    }
    let d = PyDict::new(py);
    d.set_item("dir", o.dir.display().to_string())?;
    d.set_item("compare_csv", o.dir.join("compare.csv").display().to_string())?;
    d.set_item("behaviour", o.row.behaviour.name())?;
    d.set_item("most_accurate", o.row.most_accurate.clone())?;
    Ok(d)
}

/// Reproduce and check Table I (as `flexstar verify`): returns `{"table_md", "checks",
/// "failures"}`; the files go to `out`.
#[pyfunction]
#[pyo3(signature = (out, figures = false, n_study = false, progress = false))]
pub fn verify<'py>(
    py: Python<'py>,
    out: PathBuf,
    figures: bool,
    n_study: bool,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = VerifyOptions {
        configs: None,
        thresholds: None,
        out,
        figures,
        n_study,
        provenance: flexstar_api::provenance(),
    };
    let o = interrupt::interruptible(py, "flexstar.verify", progress, |report| {
        let tick = |p: Progress| report(p.fraction);
        verify_api(&opts, Some(&tick))
    })?
    .map_err(py_err)?;
    let d = PyDict::new(py);
    d.set_item("table_md", o.table.to_markdown())?;
    d.set_item("checks", o.checks.len())?;
    d.set_item("failures", o.failures.clone())?;
    Ok(d)
}

/// The first `modes` elastic frequencies over a grid of poses: `gx`, `gy` as `(min, max, n)`
/// [m], `theta` [rad], the sliders `locked` or `free`; returns `{"Gx", "Gy", "theta", "f_hz",
/// "reason"}` lists (`f_hz` None and `reason` given for an infeasible pose).
#[pyfunction]
#[pyo3(signature = (exp, gx, gy, theta = 0.0, modes = 6, solver = "amm", sliders = "locked"))]
#[allow(clippy::too_many_arguments)]
pub fn freqmap<'py>(
    py: Python<'py>,
    exp: &PyExperiment,
    gx: (f64, f64, usize),
    gy: (f64, f64, usize),
    theta: f64,
    modes: usize,
    solver: &str,
    sliders: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let axis =
        |flag: &str, (a, b, n): (f64, f64, usize)| flexstar_api::modal::parse_axis(flag, &format!("{a}:{b}:{n}"));
    let solver = convert::solver(solver)?;
    let s = flexstar_api::modal::FreqmapSettings {
        gx: axis("gx", gx).map_err(py_err)?,
        gy: axis("gy", gy).map_err(py_err)?,
        theta,
        k: modes,
        solver,
        sliders: convert::sliders(sliders)?,
        // nothing is written from Python, so nothing can be replaced
        force: false,
    };
    let doc = &exp.inner;
    let source = doc.source.display().to_string();
    let fig = py
        .detach(|| flexstar_api::modal::freqmap(&doc.exp, &source, s, None, |_, _| {}))
        .map_err(py_err)?;
    if fig.points.is_empty() {
        return Err(ConfigError::new_err("gx, gy: empty grid"));
    }
    let d = PyDict::new(py);
    d.set_item("Gx", fig.points.iter().map(|p| p.gx).collect::<Vec<_>>())?;
    d.set_item("Gy", fig.points.iter().map(|p| p.gy).collect::<Vec<_>>())?;
    d.set_item("theta", fig.points.iter().map(|p| p.theta).collect::<Vec<_>>())?;
    d.set_item(
        "f_hz",
        fig.points.iter().map(|p| p.result.clone().ok()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "reason",
        fig.points.iter().map(|p| p.result.clone().err()).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// Plan a rest-to-rest motion (as `flexstar plan`, docs/motions.md section 4): writes
/// `out/<name>/` (plan.toml, plan.csv, plan.json, plan.md, the runs, the figures); returns
/// `{"dir", "plan_toml", "plan_csv", "t_move", "evaluations", "reason", "warnings",
/// "residual_G_peak_m"}`: `warnings` the planner's notes of peaks above the plain quintic's
/// (docs/motions.md 4.10), the last a dict of `plain`, `zvd`, `planned` to `(AMM, FEM)` residual
/// peaks of |dG| [m].
#[pyfunction]
#[pyo3(signature = (config, out))]
pub fn plan<'py>(py: Python<'py>, config: PathBuf, out: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    if flexstar_api::plan_cycle::is_cycle(&config).map_err(py_err)? {
        return plan_cycle(py, config, out);
    }
    let o = interrupt::interruptible(py, "flexstar.plan", false, |_| {
        flexstar_api::plan::plan_to_dir(&config, &out, |_| {})
    })?
    .map_err(py_err)?;
    warn_notes(py, &o.notes)?;
    let d = PyDict::new(py);
    d.set_item("dir", o.dir.display().to_string())?;
    d.set_item("plan_toml", o.dir.join("plan.toml").display().to_string())?;
    d.set_item("plan_csv", o.dir.join("plan.csv").display().to_string())?;
    d.set_item("t_move", o.planned.t_move)?;
    d.set_item("evaluations", o.planned.evaluations)?;
    d.set_item("tangent_columns", o.planned.tangent_directions)?;
    d.set_item("reason", o.planned.reason.clone())?;
    d.set_item("warnings", o.planned.warnings.clone())?;
    d.set_item("residual_G_peak_m", motion_peaks(py, &o.motions)?)?;
    Ok(d)
}

/// A whole cycle (`[plan] points`, `docs/motions.md` 4.12), as `flexstar plan` plans it: the
/// dict of a single move's plan with per-move lists (`moves`: `t_start`, `t_move`,
/// `evaluations`, `reason`, `warnings`) and the residual per dwell (`dwells`: `dwell`,
/// `t_start`, `t_end`, `plain` and `planned` as `(AMM, FEM)` residual peaks of |dG| [m],
/// `ratio_fem`).
fn plan_cycle<'py>(py: Python<'py>, config: PathBuf, out: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let o = interrupt::interruptible(py, "flexstar.plan", false, |_| {
        flexstar_api::plan_cycle::plan_cycle_to_dir(&config, &out, |_| {})
    })?
    .map_err(py_err)?;
    warn_notes(py, &o.notes)?;
    let d = PyDict::new(py);
    d.set_item("dir", o.dir.display().to_string())?;
    d.set_item("plan_toml", o.dir.join("plan.toml").display().to_string())?;
    d.set_item("plan_csv", o.dir.join("plan.csv").display().to_string())?;
    let moves = pyo3::types::PyList::empty(py);
    for m in &o.planned.moves {
        let e = PyDict::new(py);
        e.set_item("t_start", m.span.t_start)?;
        e.set_item("t_move", m.planned.t_move)?;
        e.set_item("evaluations", m.planned.evaluations)?;
        e.set_item("reason", m.planned.reason.clone())?;
        e.set_item("warnings", m.planned.warnings.clone())?;
        moves.append(e)?;
    }
    d.set_item("moves", moves)?;
    let dwells = pyo3::types::PyList::empty(py);
    for w in &o.dwells {
        let e = PyDict::new(py);
        e.set_item("dwell", w.dwell)?;
        e.set_item("t_start", w.t_start)?;
        e.set_item("t_end", w.t_end)?;
        e.set_item("plain", (w.plain_amm_m, w.plain_fem_m))?;
        e.set_item("planned", (w.planned_amm_m, w.planned_fem_m))?;
        e.set_item("ratio_fem", w.ratio_fem)?;
        dwells.append(e)?;
    }
    d.set_item("dwells", dwells)?;
    d.set_item("residual_G_peak_m", motion_peaks(py, &o.motions)?)?;
    Ok(d)
}

/// The notes of a plan as Python warnings.
fn warn_notes(py: Python<'_>, notes: &[String]) -> PyResult<()> {
    for note in notes {
        let text = std::ffi::CString::new(note.trim_start_matches("note: ")).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
    }
    Ok(())
}

/// `{motion: (AMM, FEM)}`: each motion's residual peak of |dG| after its rest [m].
fn motion_peaks<'py>(py: Python<'py>, motions: &[flexstar_api::plan::MotionRuns]) -> PyResult<Bound<'py, PyDict>> {
    let peaks = PyDict::new(py);
    for m in motions {
        let peak = |r: &flexstar_api::RunOutcome| r.residual_g_peak_m();
        peaks.set_item(m.key, (peak(&m.amm), peak(&m.fem)))?;
    }
    Ok(peaks)
}

/// Calibrate the parameters of `[fit]` on a recording (as `flexstar fit`; docs/measured.md
/// section 4): writes `out/<name>/`; returns `{"dir", "fit_json", "fit_toml", "calibrated"}`:
/// the text of fit.json, the path of fit.toml and the calibrated experiment (both `None` when
/// the fit is no calibration).
#[pyfunction]
#[pyo3(signature = (config, measured, out))]
pub fn fit<'py>(py: Python<'py>, config: PathBuf, measured: PathBuf, out: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let o = interrupt::interruptible(py, "flexstar.fit", false, |_| {
        flexstar_api::fit::fit_to_dir(&config, &measured, &out, &|_| {})
    })?
    .map_err(py_err)?;
    for note in &o.notes {
        let text = std::ffi::CString::new(note.trim_start_matches("note: ")).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
    }
    let json = serde_json::to_string(&flexstar_api::fit_report::fit_json(&o))
        .map_err(|e| crate::SolverError::new_err(format!("fit.json: {e}")))?;
    let d = PyDict::new(py);
    d.set_item("dir", o.dir.display().to_string())?;
    d.set_item("fit_json", json)?;
    let calibrated = o.fitted.calibrated.clone();
    d.set_item(
        "fit_toml",
        calibrated
            .as_ref()
            .map(|_| o.dir.join("fit.toml").display().to_string()),
    )?;
    d.set_item("calibrated", calibrated.map(|inner| PyExperiment { inner }))?;
    Ok(d)
}
