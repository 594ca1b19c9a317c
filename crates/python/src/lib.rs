//! `flexstar._flexstar`: the compiled half of the `flexstar` Python package. Every function is
//! a call of `flexstar-api` (the library the CLI calls): no physics or logic here, only the
//! conversion of arguments, results and errors. Solves release the GIL.

mod convert;
mod interrupt;
mod reports;

use std::path::{Path, PathBuf};

use flexstar_api::{ApiError, ExperimentDoc, RunOutcome, RunSettings};
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyException, PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

pyo3::create_exception!(
    flexstar,
    ConfigError,
    PyValueError,
    "Bad input: file or argument, key and reason."
);
pyo3::create_exception!(
    flexstar,
    InfeasibleMotion,
    PyException,
    "The motion leaves the feasible range."
);
pyo3::create_exception!(
    flexstar,
    SolverError,
    PyException,
    "A solver failed (or a file could not be written)."
);

/// The Python exception of a library error, with `file`, `key`, `reason` or `t` as attributes.
fn py_err(e: ApiError) -> PyErr {
    Python::attach(|py| {
        let (err, attrs): (PyErr, Vec<(&str, Option<String>)>) = match &e {
            ApiError::Config {
                file,
                key,
                reason,
                message,
            } => (
                ConfigError::new_err(message.clone()),
                vec![
                    ("file", Some(file.clone())),
                    ("key", key.clone()),
                    ("reason", Some(reason.clone())),
                ],
            ),
            ApiError::Infeasible { reason, message, .. } => (
                InfeasibleMotion::new_err(message.clone()),
                vec![("reason", Some(reason.clone()))],
            ),
            _ => (SolverError::new_err(e.to_string()), vec![]),
        };
        for (name, value) in attrs {
            let _ = err.value(py).setattr(name, value);
        }
        if let ApiError::Infeasible { t, .. } = e {
            let _ = err.value(py).setattr("t", t);
        }
        err
    })
}

/// A checked experiment and its TOML document.
#[pyclass(name = "_Experiment", frozen, module = "flexstar._flexstar")]
#[derive(Clone)]
struct PyExperiment {
    inner: ExperimentDoc,
}

#[pymethods]
impl PyExperiment {
    /// Read and check an experiment file (TOML).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Ok(PyExperiment {
            inner: ExperimentDoc::load(&path).map_err(py_err)?,
        })
    }

    /// Parse and check TOML text; `source` names it in messages and anchors relative paths.
    #[staticmethod]
    #[pyo3(signature = (text, source = "<toml>"))]
    fn from_toml(text: &str, source: &str) -> PyResult<Self> {
        Ok(PyExperiment {
            inner: ExperimentDoc::from_toml(text, Path::new(source)).map_err(py_err)?,
        })
    }

    /// Build from the JSON text of a document (the shape of the TOML file).
    #[staticmethod]
    #[pyo3(signature = (json, source = "<dict>"))]
    fn from_json(json: &str, source: &str) -> PyResult<Self> {
        Ok(PyExperiment {
            inner: ExperimentDoc::from_json(json, Path::new(source)).map_err(py_err)?,
        })
    }

    /// The document as JSON text.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json().map_err(py_err)
    }

    /// A copy with values at dotted keys, given as the JSON text of an object.
    fn with_values_json(&self, json: &str) -> PyResult<Self> {
        let v: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(json).map_err(|e| ConfigError::new_err(format!("values: {e}")))?;
        let pairs: Vec<(String, serde_json::Value)> = v.into_iter().collect();
        Ok(PyExperiment {
            inner: self.inner.with_values(&pairs).map_err(py_err)?,
        })
    }

    /// The experiment's name (`name` key).
    #[getter]
    fn name(&self) -> String {
        self.inner.exp.name.clone()
    }

    /// Where it was read from.
    #[getter]
    fn source(&self) -> String {
        self.inner.source.display().to_string()
    }
}

/// The outcome of a run (see `flexstar.Run`).
#[pyclass(name = "_Run", frozen, module = "flexstar._flexstar")]
struct PyRun {
    inner: RunOutcome,
}

#[pymethods]
impl PyRun {
    /// Column names in the order of the CSV.
    fn columns(&self) -> Vec<String> {
        flexstar_api::run::columns(&self.inner.response)
            .into_iter()
            .map(|(n, _)| n)
            .collect()
    }

    /// One column as a new float64 array.
    fn column<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        flexstar_api::run::columns(&self.inner.response)
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| PyArray1::from_slice(py, v))
            .ok_or_else(|| PyKeyError::new_err(format!("no column `{name}`")))
    }

    /// The sensors' readings (`docs/sensors.md`): `{"t": times, "<column>": channel, ...}` as new
    /// float64 arrays on the sensors' own clock, in the order of `<stem>-sensors.csv`; an empty
    /// dict for a run without `[[sensors]]`.
    fn sensors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        if let Some(table) = &self.inner.response.sensors {
            d.set_item("t", PyArray1::from_slice(py, &table.t))?;
            for c in &table.columns {
                d.set_item(&c.name, PyArray1::from_slice(py, &c.values))?;
            }
        }
        Ok(d)
    }

    /// The sidecar document as JSON text.
    fn meta_json(&self) -> PyResult<String> {
        self.inner.sidecar_json().map(|v| v.to_string()).map_err(py_err)
    }

    /// The file stem (`amm-enriched`, `fem-direct`, ...).
    #[getter]
    fn stem(&self) -> String {
        self.inner.stem.clone()
    }

    /// The small-deflection warning, if any.
    #[getter]
    fn warning(&self) -> Option<String> {
        self.inner.warning.clone()
    }

    /// Write the CLI's files into `out/<name>/`; returns their paths.
    #[pyo3(signature = (out, figures = false))]
    fn save(&self, py: Python<'_>, out: PathBuf, figures: bool) -> PyResult<Vec<String>> {
        let mut o = self.inner.clone();
        // a folder of another experiment with the same name is replaced: say so, as the CLI does
        if let Some(note) = flexstar_model::identity::other_experiment_note(&out.join(&o.exp.name), &o.exp) {
            let text = std::ffi::CString::new(note.trim_start_matches("note: ")).unwrap_or_default();
            PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
        }
        py.detach(|| {
            let dir = flexstar_api::case_dir(&out, &o.exp)?;
            flexstar_api::run::write_run(&mut o, &dir, figures)
        })
        .map_err(py_err)?;
        Ok(o.files.iter().map(|f| f.display().to_string()).collect())
    }
}

/// Solve an experiment (see `flexstar.run`).
#[pyfunction]
#[pyo3(signature = (exp, solver, family = None, modes = None, model = None, tol = None, elements = None, dt = None, forces = None, progress = false))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    exp: &PyExperiment,
    solver: &str,
    family: Option<&str>,
    modes: Option<usize>,
    model: Option<&str>,
    tol: Option<f64>,
    elements: Option<usize>,
    dt: Option<f64>,
    forces: Option<PyReadonlyArray2<'_, f64>>,
    progress: bool,
) -> PyResult<PyRun> {
    let mut s = RunSettings::new(convert::solver(solver)?);
    s.family = family.map(|f| convert::parse("family", f)).transpose()?;
    s.model = model.map(|m| convert::parse("model", m)).transpose()?;
    s.modes = modes;
    s.tol = convert::finite("tol", tol)?;
    s.elements = elements;
    s.dt = convert::finite("dt", dt)?;
    s.forces = forces.map(|f| convert::forces(f.as_array())).transpose()?;
    let doc = exp.inner.clone();
    let source = doc.source.display().to_string();
    let outcome = interrupt::interruptible(py, "flexstar.run", progress, |report| {
        let p = flexstar_api::run::prepare(doc.exp, &source, &s)?;
        flexstar_api::run::run(&p, Some(report))
    })?
    .map_err(py_err)?;
    Ok(PyRun { inner: outcome })
}

/// Modes at a pose, AMM and FEM (see `flexstar.modal`): a dict.
#[pyfunction]
#[pyo3(signature = (exp, at = None, pose = None, sliders = "locked", modes = 6, sleeves = "sliding"))]
fn modal<'py>(
    py: Python<'py>,
    exp: &PyExperiment,
    at: Option<f64>,
    pose: Option<[f64; 3]>,
    sliders: &str,
    modes: usize,
    sleeves: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = convert::pose_spec(at, pose)?;
    let hold = flexstar_api::modal::ModalHold {
        sliders: convert::sliders(sliders)?,
        sleeves: convert::sleeves(sleeves)?,
    };
    let doc = &exp.inner;
    let source = doc.source.display().to_string();
    let o = py
        .detach(|| flexstar_api::modal::modal_held(&doc.exp, &source, &spec, hold, modes, None, false))
        .map_err(py_err)?;
    let d = PyDict::new(py);
    let rows = o.modal.rows();
    d.set_item("mode", rows.iter().map(|r| r.0).collect::<Vec<_>>())?;
    d.set_item("amm_hz", PyArray1::from_vec(py, rows.iter().map(|r| r.1).collect()))?;
    d.set_item("fem_hz", PyArray1::from_vec(py, rows.iter().map(|r| r.2).collect()))?;
    if let Some(z) = o.modal.damping_ratios() {
        d.set_item("zeta_amm", PyArray1::from_vec(py, z.iter().map(|r| r.0).collect()))?;
        d.set_item("zeta_fem", PyArray1::from_vec(py, z.iter().map(|r| r.1).collect()))?;
    }
    d.set_item("rigid", o.modal.amm.rigid)?;
    d.set_item("sleeves", hold.sleeves.name())?;
    d.set_item("pose", convert::pose_dict(py, &o.pose)?)?;
    Ok(d)
}

/// The linear state-space model about a pose (see `flexstar.linearize`): the matrices, the names
/// of the states, inputs and outputs (in the matrices' order) and the settings used.
#[pyfunction]
#[pyo3(signature = (exp, at = None, pose = None, modes = flexstar_modal::linear::ELASTIC_MODES, sliders = "free", r#loop = None, sleeves = "sliding"))]
#[allow(clippy::too_many_arguments)]
fn linearize<'py>(
    py: Python<'py>,
    exp: &PyExperiment,
    at: Option<f64>,
    pose: Option<[f64; 3]>,
    modes: usize,
    sliders: &str,
    r#loop: Option<&str>,
    sleeves: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = convert::pose_spec(at, pose)?;
    let opts = flexstar_api::modal::LinearizeOptions {
        modes: Some(modes),
        sliders: Some(convert::sliders(sliders)?),
        loop_kind: convert::loop_kind(r#loop)?,
        sleeves: Some(convert::sleeves(sleeves)?),
    };
    let doc = &exp.inner;
    let source = doc.source.display().to_string();
    let ss = py
        .detach(|| flexstar_api::modal::linearize(&doc.exp, &source, &spec, &opts, None))
        .map_err(py_err)?;
    let d = PyDict::new(py);
    for (name, m) in [("A", &ss.a), ("B", &ss.b), ("C", &ss.c), ("D", &ss.d)] {
        d.set_item(name, convert::dense(py, m)?)?;
    }
    let names = |v: &[flexstar_modal::linear::Signal]| v.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    let units = |v: &[flexstar_modal::linear::Signal]| v.iter().map(|s| s.unit).collect::<Vec<_>>();
    d.set_item("states", names(&ss.states))?;
    d.set_item("inputs", names(&ss.inputs))?;
    d.set_item("outputs", names(&ss.outputs))?;
    d.set_item("input_units", units(&ss.inputs))?;
    d.set_item("output_units", units(&ss.outputs))?;
    let h = ss.settings.holding;
    d.set_item("sliders", h.sliders().name())?;
    let closed = matches!(h, flexstar_modal::linear::Holding::Servo { .. });
    d.set_item("loop", if closed { "closed" } else { "open" })?;
    d.set_item("modes", ss.settings.modes)?;
    d.set_item("sleeves", ss.settings.sleeves.name())?;
    d.set_item("modal_frequencies_hz", PyArray1::from_slice(py, &ss.modes.freq_hz))?;
    d.set_item("rigid", ss.modes.rigid)?;
    d.set_item("pose", convert::pose_dict(py, &ss.pose)?)?;
    Ok(d)
}

/// Run a design study file into `out` (see `flexstar.sweep`); returns the results CSV path.
#[pyfunction]
#[pyo3(signature = (study, out, jobs = None, progress = false))]
fn sweep(py: Python<'_>, study: PathBuf, out: PathBuf, jobs: Option<usize>, progress: bool) -> PyResult<String> {
    if jobs == Some(0) {
        return Err(ConfigError::new_err("jobs: must be at least 1"));
    }
    let r = interrupt::interruptible(py, "flexstar.sweep", progress, |report| -> Result<PathBuf, String> {
        let st = flexstar_api::study::Study::load(&study).map_err(|e| e.to_string())?;
        let opts = flexstar_api::study::SweepOptions { out, jobs, shard: None };
        let cases = |done: usize, total: usize| report(done as f64 / total.max(1) as f64);
        Ok(flexstar_api::study::run_study(&st, &opts, &cases)
            .map_err(|e| e.to_string())?
            .results)
    })?;
    r.map(|p| p.display().to_string()).map_err(ConfigError::new_err)
}

#[pymodule]
fn _flexstar(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("InfeasibleMotion", py.get_type::<InfeasibleMotion>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add_class::<PyExperiment>()?;
    m.add_class::<PyRun>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(modal, m)?)?;
    m.add_function(wrap_pyfunction!(linearize, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(reports::compare, m)?)?;
    m.add_function(wrap_pyfunction!(reports::verify, m)?)?;
    m.add_function(wrap_pyfunction!(reports::freqmap, m)?)?;
    m.add_function(wrap_pyfunction!(reports::plan, m)?)?;
    m.add_function(wrap_pyfunction!(reports::fit, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
