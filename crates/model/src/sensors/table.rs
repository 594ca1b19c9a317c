//! The sensors' readings as a table, and its file `<stem>-sensors.csv` (header `t,<columns>`,
//! `docs/outputs.md`).

use std::path::Path;

use flexstar_io::output::{fmt_number, Dest};
use flexstar_io::run_set::RunSet;

use crate::error::ModelError;
use crate::response::Column;

/// Sensor readings: one row per sample time, one column per sensor channel
/// ([`super::Sensors::columns`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorTable {
    /// Sample times [s].
    pub t: Vec<f64>,
    /// The channels, in the order of the sensors.
    pub columns: Vec<Column>,
    /// The unit of each channel (`m/s^2`, `m/m`, `m`, `N`), as `columns`.
    pub units: Vec<String>,
}

impl SensorTable {
    /// A table of the times `t` [s] without channels.
    pub fn new(t: Vec<f64>) -> Self {
        SensorTable {
            t,
            ..SensorTable::default()
        }
    }

    /// An empty table with the channels `(name, unit)` of `units`, room for `n` rows.
    pub fn with_columns(units: &[(String, &str)], n: usize) -> Self {
        SensorTable {
            t: Vec::with_capacity(n),
            columns: units
                .iter()
                .map(|(name, _)| Column {
                    name: name.clone(),
                    values: Vec::with_capacity(n),
                })
                .collect(),
            units: units.iter().map(|(_, u)| u.to_string()).collect(),
        }
    }

    /// Append one row: time `t` [s] and one value per channel.
    pub fn push_row(&mut self, t: f64, row: &[f64]) {
        self.t.push(t);
        for (c, v) in self.columns.iter_mut().zip(row) {
            c.values.push(*v);
        }
    }

    /// Append a channel of unit `unit`.
    pub fn push_column(&mut self, name: String, unit: &str, values: Vec<f64>) {
        self.columns.push(Column { name, values });
        self.units.push(unit.to_string());
    }

    /// The unit of channel `name`, if present.
    pub fn unit(&self, name: &str) -> Option<&str> {
        let k = self.columns.iter().position(|c| c.name == name)?;
        self.units.get(k).map(String::as_str)
    }

    /// The channel `name`, if present.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// The header `t,<columns>`.
    pub fn header(&self) -> Vec<String> {
        std::iter::once("t".to_string())
            .chain(self.columns.iter().map(|c| c.name.clone()))
            .collect()
    }

    /// Write the table as CSV, whole or not at all.
    pub fn write_csv(&self, path: &Path) -> Result<(), ModelError> {
        self.emit_csv(Dest::File(path))
    }

    /// [`SensorTable::write_csv`] into file `name` of a run set.
    pub fn stage_csv(&self, set: &mut RunSet, name: &str) -> Result<(), ModelError> {
        self.emit_csv(Dest::Set(set, name))
    }

    fn emit_csv(&self, dest: Dest<'_>) -> Result<(), ModelError> {
        if let Some(c) = self.columns.iter().find(|c| c.values.len() != self.t.len()) {
            return Err(ModelError::Write {
                file: dest.path(),
                reason: format!(
                    "sensor column {} has {} rows, expected {}",
                    c.name,
                    c.values.len(),
                    self.t.len()
                ),
            });
        }
        dest.write(|w| {
            let mut out = csv::Writer::from_writer(w);
            out.write_record(self.header())?;
            for k in 0..self.t.len() {
                let row = std::iter::once(self.t[k]).chain(self.columns.iter().map(|c| c.values[k]));
                out.write_record(row.map(fmt_number))?;
            }
            out.flush()?;
            Ok(())
        })
        .map_err(ModelError::from)
    }
}
