//! The recording of `flexstar fit` (`docs/measured.md` sections 1 and 4.2): read and laid onto
//! the run's sensor times by `flexstar_measured::Recording`, then its channels in the order of
//! the experiment's sensor columns with their weights.

use std::ops::Range;
use std::path::Path;

use flexstar_measured::{MeasuredError, Recording};
use flexstar_model::{FitSection, SensorTable, Sensors};

use crate::{ApiError, Result};

/// Read `path` as the experiment's `[measured]` maps it (section 1: every check of the reader,
/// before any run).
pub(crate) fn read(path: &Path, exp: &flexstar_model::Experiment, sensors: &Sensors) -> Result<Recording> {
    let section = exp.measured.clone().unwrap_or_default();
    Recording::read(path, &section, sensors).map_err(|e| measured_error(path, e))
}

/// The recording on the run's sensor times `run` (its offset estimated against them when
/// `offset = "auto"`, Eq. M3; resampled by Eq. M4).
pub(crate) fn on_run_times(rec: &mut Recording, run: &SensorTable) -> Result<SensorTable> {
    let path = rec.file().to_path_buf();
    rec.align(run).map_err(|e| measured_error(&path, e))?;
    rec.on_times(&run.t).map_err(|e| measured_error(&path, e))
}

/// A reader's error as bad input: its own message (file, row, column, reason); an error of
/// another kind (the reader has none) as the recording's.
fn measured_error(path: &Path, e: MeasuredError) -> ApiError {
    let message = e.to_string();
    let (file, key, reason) = match e {
        MeasuredError::File { file, reason } => (file.display().to_string(), None, reason),
        MeasuredError::Column { file, column, reason } => (file.display().to_string(), Some(column), reason),
        MeasuredError::Row { file, reason, .. } | MeasuredError::Cell { file, reason, .. } => {
            (file.display().to_string(), None, reason)
        }
        other => (path.display().to_string(), None, other.to_string()),
    };
    ApiError::config_text(file, key.as_deref(), &reason, message)
}

/// The fitted data: the recorded channels in the order of the experiment's sensor columns with
/// their units and weights, and the sensor columns the recording does not hold (not fitted).
pub(crate) struct Channels {
    pub table: SensorTable,
    pub weights: Vec<f64>,
    pub missing: Vec<String>,
}

/// The channels of `rec` (a recording on a run's sensor times, named `name`) for `sensors`; an
/// error when it holds none of the fitted columns.
pub(crate) fn channels(sensors: &Sensors, section: &FitSection, rec: &SensorTable, name: &str) -> Result<Channels> {
    let mut table = SensorTable::new(rec.t.clone());
    let (mut weights, mut missing) = (Vec::new(), Vec::new());
    for s in sensors.list() {
        for column in s.columns() {
            let w = section.weight(&s.name, &column);
            match rec.column(&column) {
                Some(v) => {
                    table.push_column(column, s.unit(), v.to_vec());
                    weights.push(w);
                }
                None => missing.push(column),
            }
        }
    }
    if !weights.iter().any(|&w| w > 0.0) {
        return Err(ApiError::config(
            name,
            None,
            format!(
                "the recording holds none of the fitted sensor columns (it holds {}; not recorded: {})",
                if rec.columns.is_empty() {
                    "none".to_string()
                } else {
                    rec.header()[1..].join(", ")
                },
                missing.join(", ")
            ),
        ));
    }
    Ok(Channels {
        table,
        weights,
        missing,
    })
}

/// The rows of the run's sensor times `run_t` that the recording's times `t` are (contiguous:
/// what [`Recording::on_times`] returns); an error names the first time that is none of them.
pub(crate) fn window(run_t: &[f64], t: &[f64], name: &str) -> Result<Range<usize>> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
    let start = t
        .first()
        .and_then(|&t0| run_t.iter().position(|&r| same(t0, r)))
        .unwrap_or(usize::MAX);
    let end = start.saturating_add(t.len());
    let bad = if t.len() < 2 || end > run_t.len() {
        Some(0)
    } else {
        t.iter().zip(&run_t[start..end]).position(|(a, b)| !same(*a, *b))
    };
    match bad {
        None => Ok(start..end),
        Some(k) => Err(ApiError::config(
            name,
            Some("t"),
            format!(
                "the recording is not on the run's sensor times ({} samples from {} s to {} s, every {} s): \
                 sample {} at t = {} s is none of them; lay it onto them first (docs/measured.md section 1)",
                run_t.len(),
                run_t.first().copied().unwrap_or(f64::NAN),
                run_t.last().copied().unwrap_or(f64::NAN),
                run_t.get(1).zip(run_t.first()).map_or(f64::NAN, |(a, b)| a - b),
                k + 1,
                t.get(k).copied().unwrap_or(f64::NAN)
            ),
        )),
    }
}

/// The run's sensor times of `exp` (`k / rate_hz` up to `t_end`, or the output times;
/// `docs/sensors.md` section 6), known before any run.
pub(crate) fn sensor_times(exp: &flexstar_model::Experiment, sensors: &Sensors) -> Vec<f64> {
    match sensors.rate_hz() {
        Some(rate) => flexstar_model::sensors::daq::sample_times(rate, exp.time.t_end),
        None => exp.time.output_times(),
    }
}
