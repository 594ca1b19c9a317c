//! A recording of the real robot laid onto a run (`docs/measured.md` section 1): its columns
//! mapped onto the experiment's sensor columns and scaled (Eq. M1), its clock shifted onto the
//! run's (Eq. M2, or estimated by Eq. M3) and resampled onto the run's sensor times (Eq. M4).

use std::ops::Range;
use std::path::{Path, PathBuf};

use flexstar_model::measured_section::{MeasuredSection, Offset, TIME_COLUMN};
use flexstar_model::sensors::daq::interpolate;
use flexstar_model::{SensorTable, Sensors};

use crate::csv_table::CsvTable;
use crate::error::MeasuredError;
use crate::offset::{estimate_offset, Channels, LagWindow};

/// Relative tolerance on the ends of a span (a run's last time against a recording's).
const SPAN_TOL: f64 = 1e-9;

/// One recorded channel, in the sensor's unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The sensor column it records (`docs/sensors.md` section 1).
    pub name: String,
    /// The column's name in the recording.
    pub source: String,
    /// The sensor's unit (`m/s^2`, `m/m`, `m`, `N`).
    pub unit: String,
    /// The recorded values times the scale of Eq. M1.
    pub values: Vec<f64>,
}

/// A recording read and mapped onto the sensor columns (Eq. M1), with its clock (Eq. M2).
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    file: PathBuf,
    /// The recording's own times [s], strictly increasing.
    t: Vec<f64>,
    /// The recorded sensor columns, in the order of the experiment's sensors.
    channels: Vec<Channel>,
    /// `offset` as configured.
    offset: Offset,
    /// `max_lag` as configured (`None`: a quarter of the run).
    max_lag: Option<f64>,
    /// The shift [s] added to `t` (Eq. M2): the given offset, or the estimate of Eq. M3 once
    /// [`Recording::align`] has run (`None` until then).
    shift: Option<f64>,
}

impl Recording {
    /// Read the recording `path` for the experiment's `sensors` as `section` maps it
    /// (`docs/measured.md` 1.1-1.2). Every check is made here, before any work: a time column,
    /// strictly increasing times, finite numeric cells, every other column a sensor column
    /// (named so or mapped), every mapped or scaled column present.
    pub fn read(path: &Path, section: &MeasuredSection, sensors: &Sensors) -> Result<Self, MeasuredError> {
        let units: Vec<(String, String)> = sensors.units().into_iter().map(|(c, u)| (c, u.to_string())).collect();
        Self::read_columns(path, section, &units)
    }

    /// [`Recording::read`] for the sensor columns `units` (`(column, unit)`, in order, as
    /// [`Sensors::units`]).
    pub fn read_columns(
        path: &Path,
        section: &MeasuredSection,
        units: &[(String, String)],
    ) -> Result<Self, MeasuredError> {
        if units.is_empty() {
            return Err(MeasuredError::file(
                path,
                "the experiment has no [[sensors]]: a recording is laid over the sensors' columns, define them first",
            ));
        }
        let table = CsvTable::read(path)?;
        let time_name = section.recording_column(TIME_COLUMN);
        let t = table
            .column(time_name)
            .ok_or_else(|| no_time_column(path, time_name, &table))?;
        check_times(path, t, &table.lines)?;
        check_mapping(path, section, units, &table)?;
        let channels = units
            .iter()
            .filter_map(|(name, unit)| {
                let source = section.recording_column(name);
                let values = table.column(source)?;
                let scale = section.scale_of(name);
                Some(Channel {
                    name: name.clone(),
                    source: source.to_string(),
                    unit: unit.clone(),
                    values: values.iter().map(|v| scale * v).collect(),
                })
            })
            .collect::<Vec<_>>();
        if channels.is_empty() {
            return Err(MeasuredError::file(
                path,
                format!(
                    "no column besides the time {time_name:?}: record at least one of the sensor columns ({})",
                    names(units)
                ),
            ));
        }
        Ok(Recording {
            file: path.to_path_buf(),
            t: t.to_vec(),
            channels,
            offset: section.offset,
            max_lag: section.max_lag,
            shift: match section.offset {
                Offset::Seconds(s) => Some(s),
                Offset::Auto => None,
            },
        })
    }

    /// The file read.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The recording's own times [s] (before the shift of Eq. M2).
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// The recorded sensor columns, scaled (Eq. M1), in the order of the sensors.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// The channel recording sensor column `name`, if recorded.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// `offset` as configured.
    pub fn offset(&self) -> Offset {
        self.offset
    }

    /// The shift [s] added to the recording's times (Eq. M2): the given offset, or the estimate
    /// once [`Recording::align`] has run; `None` for `offset = "auto"` before that.
    pub fn shift(&self) -> Option<f64> {
        self.shift
    }

    /// Resolve `offset = "auto"` against the run's sensor table `run` (Eq. M3, within the lag
    /// window `max_lag`, by default a quarter of the run's span) and return the shift [s]; a
    /// given offset is returned as it is. The error names the file when no lag in the window
    /// correlates the recording with the run.
    pub fn align(&mut self, run: &SensorTable) -> Result<f64, MeasuredError> {
        if let Some(s) = self.shift {
            return Ok(s);
        }
        let span = run.t.last().copied().unwrap_or(0.0) - run.t.first().copied().unwrap_or(0.0);
        let max_lag = self.max_lag.unwrap_or_else(|| MeasuredSection::default_max_lag(span));
        let pairs: Vec<(&[f64], &[f64])> = self
            .channels
            .iter()
            .filter_map(|c| Some((c.values.as_slice(), run.column(&c.name)?)))
            .collect();
        let recorded = Channels {
            t: &self.t,
            values: pairs.iter().map(|p| p.0).collect(),
        };
        let model = Channels {
            t: &run.t,
            values: pairs.iter().map(|p| p.1).collect(),
        };
        let lag = estimate_offset(&recorded, &model, LagWindow { max_lag })
            .map_err(|reason| MeasuredError::file(&self.file, format!("offset = \"auto\": {reason}")))?;
        self.shift = Some(lag.offset);
        Ok(lag.offset)
    }

    /// The recording's span on the run's clock, `[t_0 + shift, t_last + shift]` [s].
    pub fn span(&self) -> Result<[f64; 2], MeasuredError> {
        let s = self.resolved_shift()?;
        Ok([self.t[0] + s, self.t[self.t.len() - 1] + s])
    }

    /// The indexes of the times `t` [s] (increasing) that lie within the shifted recording's
    /// span: the rows of a run's table that [`Recording::on_times`] returns.
    pub fn span_in(&self, t: &[f64]) -> Result<Range<usize>, MeasuredError> {
        let [a, b] = self.span()?;
        let tol = SPAN_TOL * (b - a).abs().max(1.0);
        let lo = t.partition_point(|&x| x < a - tol);
        let hi = t.partition_point(|&x| x <= b + tol);
        Ok(lo..hi.max(lo))
    }

    /// The recording resampled onto the run's sensor times `t` [s] (Eq. M4): the recorded
    /// columns, mapped and scaled, interpolated linearly at the times of `t` within the shifted
    /// span ([`Recording::span_in`]; the table's `t` is that part of `t`). The error names the
    /// file and both spans when fewer than two of the run's times lie within it.
    pub fn on_times(&self, t: &[f64]) -> Result<SensorTable, MeasuredError> {
        let range = self.span_in(t)?;
        if range.len() < 2 {
            return Err(self.no_overlap(t));
        }
        let at = &t[range];
        let s = self.resolved_shift()?;
        let own: Vec<f64> = self.t.iter().map(|x| x + s).collect();
        let mut out = SensorTable::new(at.to_vec());
        for c in &self.channels {
            out.push_column(c.name.clone(), &c.unit, interpolate(&own, &c.values, at));
        }
        Ok(out)
    }

    /// The shift, or the error of an `offset = "auto"` not yet aligned.
    fn resolved_shift(&self) -> Result<f64, MeasuredError> {
        self.shift.ok_or_else(|| {
            MeasuredError::file(
                &self.file,
                "offset = \"auto\" is estimated against a run: align the recording first",
            )
        })
    }

    /// The error of a recording whose shifted span misses the run's times `t`.
    fn no_overlap(&self, t: &[f64]) -> MeasuredError {
        let [a, b] = self.span().unwrap_or([f64::NAN, f64::NAN]);
        let (t0, t1) = (
            t.first().copied().unwrap_or(f64::NAN),
            t.last().copied().unwrap_or(f64::NAN),
        );
        MeasuredError::file(
            &self.file,
            format!(
                "the recording spans [{a}, {b}] s on the run's clock (its times plus the offset {} s), \
                 which does not overlap the run's sensor times [{t0}, {t1}] s: check measured.offset",
                self.shift.unwrap_or(f64::NAN)
            ),
        )
    }
}

/// Strictly increasing times, at least two.
fn check_times(path: &Path, t: &[f64], lines: &[u64]) -> Result<(), MeasuredError> {
    if t.len() < 2 {
        return Err(MeasuredError::file(
            path,
            format!("{} data rows: a recording needs at least two", t.len()),
        ));
    }
    match t.windows(2).position(|w| w[1] <= w[0]) {
        None => Ok(()),
        Some(k) => Err(MeasuredError::Row {
            file: path.to_path_buf(),
            row: k + 2,
            line: lines[k + 1],
            reason: format!(
                "time {} s {} the previous row's {} s: times must increase strictly",
                t[k + 1],
                if t[k + 1] == t[k] { "repeats" } else { "is before" },
                t[k]
            ),
        }),
    }
}

/// Every mapped and scaled sensor column is in the file; every header column is the time or a
/// sensor column (named so or mapped).
fn check_mapping(
    path: &Path,
    section: &MeasuredSection,
    units: &[(String, String)],
    table: &CsvTable,
) -> Result<(), MeasuredError> {
    for (column, source) in section.columns.iter().filter(|(c, _)| *c != TIME_COLUMN) {
        if table.column(source).is_none() {
            return Err(MeasuredError::column(
                path,
                source,
                format!("measured.columns.{column} maps it, but the recording has no such column"),
            ));
        }
    }
    for column in section.scale.keys() {
        if table.column(section.recording_column(column)).is_none() {
            return Err(MeasuredError::column(
                path,
                section.recording_column(column),
                format!("measured.scale.{column} scales it, but the recording has no such column"),
            ));
        }
    }
    let time_name = section.recording_column(TIME_COLUMN);
    for h in table.header.iter().filter(|h| *h != time_name) {
        if !units.iter().any(|(c, _)| section.recording_column(c) == h) {
            let mapped = section.columns.get(h.as_str()).map_or(String::new(), |to| {
                format!(" (sensor column {h} is mapped to the recording's {to:?})")
            });
            return Err(MeasuredError::column(
                path,
                h,
                format!(
                    "matches no sensor column ({}) and no measured.columns mapping{mapped}",
                    names(units)
                ),
            ));
        }
    }
    Ok(())
}

/// The error of a recording without its time column `name`.
fn no_time_column(path: &Path, name: &str, table: &CsvTable) -> MeasuredError {
    let how = if name == TIME_COLUMN {
        "name it t or map it with measured.columns.t".to_string()
    } else {
        format!("measured.columns.t names {name:?}")
    };
    MeasuredError::file(
        path,
        format!(
            "no time column {name:?} ({how}); the header is {}",
            table.header.join(",")
        ),
    )
}

/// The sensor columns of `units`, comma-separated.
fn names(units: &[(String, String)]) -> String {
    units.iter().map(|(c, _)| c.as_str()).collect::<Vec<_>>().join(", ")
}
