//! Python arguments to the library's settings, checked: errors are `ConfigError`s naming the
//! argument and the reason.

use flexstar_api::modal::PoseSpec;
use flexstar_api::{Forces, Solver};
use flexstar_model::{ForceSamples, RestPose, Sliders};
use numpy::ndarray::ArrayView2;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::ConfigError;

/// `solver="amm" | "fem"`.
pub fn solver(s: &str) -> PyResult<Solver> {
    match s {
        "amm" => Ok(Solver::Amm),
        "fem" => Ok(Solver::Fem),
        _ => Err(ConfigError::new_err(format!(
            "solver: expected \"amm\" or \"fem\", got {s:?}"
        ))),
    }
}

/// A value parsed by the library's own parser (`family`, `model`).
pub fn parse<T: std::str::FromStr>(arg: &str, s: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    s.parse().map_err(|e| ConfigError::new_err(format!("{arg}: {e}")))
}

/// A float argument that must be finite when given.
pub fn finite(arg: &str, v: Option<f64>) -> PyResult<Option<f64>> {
    match v {
        Some(x) if !x.is_finite() => Err(ConfigError::new_err(format!("{arg}: must be a finite number, got {x}"))),
        other => Ok(other),
    }
}

/// `forces=`: an (n, 4) array of rows `t, Fa1, Fa2, Fa3` [s, N], times strictly increasing.
pub fn forces(a: ArrayView2<'_, f64>) -> PyResult<Forces> {
    if a.ncols() != 4 {
        return Err(ConfigError::new_err(format!(
            "forces: expected an array of shape (n, 4) with columns t, Fa1, Fa2, Fa3, got shape ({}, {})",
            a.nrows(),
            a.ncols()
        )));
    }
    let t: Vec<f64> = a.column(0).to_vec();
    let fa: Vec<[f64; 3]> = a.rows().into_iter().map(|r| [r[1], r[2], r[3]]).collect();
    ForceSamples::check(&t, &fa).map_err(|e| ConfigError::new_err(format!("forces: {e}")))?;
    Ok(Forces::Samples(ForceSamples { t, fa }))
}

/// `at=T` or `pose=(Gx, Gy, theta)`, exactly one.
pub fn pose_spec(at: Option<f64>, pose: Option<[f64; 3]>) -> PyResult<PoseSpec> {
    match (at, pose) {
        (Some(t), None) => Ok(PoseSpec::At(t)),
        (None, Some(p)) if p.iter().all(|x| x.is_finite()) => Ok(PoseSpec::Task {
            pose: p,
            text: format!("{},{},{}", p[0], p[1], p[2]),
        }),
        (None, Some(_)) => Err(ConfigError::new_err(
            "pose: expected three finite numbers (Gx, Gy, theta) [m, m, rad]",
        )),
        _ => Err(ConfigError::new_err(
            "give exactly one of at=T [s] or pose=(Gx, Gy, theta)",
        )),
    }
}

/// `sliders="locked" | "free"`.
pub fn sliders(s: &str) -> PyResult<Sliders> {
    match s {
        "locked" => Ok(Sliders::Locked),
        "free" => Ok(Sliders::Free),
        _ => Err(ConfigError::new_err(format!(
            "sliders: expected \"locked\" or \"free\", got {s:?}"
        ))),
    }
}

/// `sleeves="sliding" | "stuck"` (`docs/modes.md`, stuck sleeves).
pub fn sleeves(s: &str) -> PyResult<flexstar_model::Sleeves> {
    use flexstar_model::Sleeves;
    match s {
        "sliding" => Ok(Sleeves::Sliding),
        "stuck" => Ok(Sleeves::Stuck),
        _ => Err(ConfigError::new_err(format!(
            "sleeves: expected \"sliding\" or \"stuck\", got {s:?}"
        ))),
    }
}

/// `loop="open" | "closed"` (None: the default of `flexstar linearize`).
pub fn loop_kind(s: Option<&str>) -> PyResult<Option<flexstar_api::modal::LoopKind>> {
    use flexstar_api::modal::LoopKind;
    match s {
        None => Ok(None),
        Some("open") => Ok(Some(LoopKind::Open)),
        Some("closed") => Ok(Some(LoopKind::Closed)),
        Some(other) => Err(ConfigError::new_err(format!(
            "loop: expected \"open\" or \"closed\", got {other:?}"
        ))),
    }
}

/// A rest pose as a dict (SI units).
pub fn pose_dict<'py>(py: Python<'py>, p: &RestPose) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("Gx", p.g[0])?;
    d.set_item("Gy", p.g[1])?;
    d.set_item("theta", p.theta)?;
    d.set_item("s", p.s.to_vec())?;
    Ok(d)
}

/// A sparse matrix as a dense float64 array.
pub fn dense<'py>(py: Python<'py>, m: &sprs::CsMat<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (r, c) = (m.rows(), m.cols());
    let mut a = numpy::ndarray::Array2::<f64>::zeros((r, c));
    for (v, (i, j)) in m.iter() {
        a[[i, j]] += *v;
    }
    Ok(numpy::IntoPyArray::into_pyarray(a, py))
}
