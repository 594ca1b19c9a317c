//! The results table: `run_id`, the varied keys, then the fixed metric columns; one row per case
//! and solver. Rows are appended as cases finish (one write per case) and the finished table is
//! rewritten in the study's case order.

use std::path::Path;

use crate::error::StudyError;

/// The columns after the varied keys, in this order (a file contract, `docs/studies.md`).
pub const METRIC_COLUMNS: [&str; 7] = [
    "solver",
    "status",
    "peak_tip_m",
    "peak_wG_m",
    "peak_Fa_N",
    "evp_percent",
    "wall_s",
];

/// Further columns: residual tip vibration after a rest-to-rest motion [m], AMM modes per beam,
/// the AMM's own estimate of its truncation error [%], then the residual peak of
/// |dG| after the motion [m] and the settling time [s, absolute; `inf` when not settled by
/// `t_end`] (`docs/motions.md` 2.2-2.4), then the largest point EVP of the AMM
/// against the FEM [%], then the robot's first elastic frequency at the start pose [Hz] (the
/// accurate AMM, sliders locked; the same on every row of a case).
pub const MORE_COLUMNS: [&str; 7] = [
    "residual_tip_m",
    "modes",
    "error_estimate_percent",
    "residual_G_m",
    "settle_s",
    "evp_max_percent",
    "f1_hz",
];

/// Column names that are neither keys nor numbers to plot.
pub const TEXT_COLUMNS: [&str; 3] = ["run_id", "solver", "status"];

/// `status` of a run that completed.
pub const OK: &str = "ok";

/// The full header for the varied `keys`.
pub fn header(keys: &[String]) -> Vec<String> {
    std::iter::once("run_id".to_string())
        .chain(keys.iter().cloned())
        .chain(METRIC_COLUMNS.iter().chain(&MORE_COLUMNS).map(|s| s.to_string()))
        .collect()
}

/// One row of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub run_id: String,
    /// The case's values as written (one per varied key).
    pub values: Vec<String>,
    /// `amm` or `fem`.
    pub solver: String,
    /// `ok`, or why the run failed (`invalid: ...`, `failed: ...`).
    pub status: String,
    /// See [`crate::metrics::Peaks`]: [m].
    pub peak_tip_m: Option<f64>,
    /// [m]
    pub peak_wg_m: Option<f64>,
    /// [N]
    pub peak_fa_n: Option<f64>,
    /// Mean EVP [%] of the AMM against the FEM (AMM rows of studies that run both).
    pub evp_percent: Option<f64>,
    /// Wall-clock time of the solve [s].
    pub wall_s: f64,
    /// Residual tip vibration after a rest-to-rest motion [m].
    pub residual_tip_m: Option<f64>,
    /// AMM modes per beam actually used.
    pub modes: Option<usize>,
    /// The AMM's estimate of its truncation error [%], when it makes one.
    pub error_estimate_percent: Option<f64>,
    /// Residual peak of |dG| after a rest-to-rest motion [m].
    pub residual_g_m: Option<f64>,
    /// Settling time [s, absolute], `inf` when not settled by `t_end`.
    pub settle_s: Option<f64>,
    /// Largest point EVP [%] of the AMM against the FEM over A, B, C, G (AMM rows).
    pub evp_max_percent: Option<f64>,
    /// First elastic frequency at the start pose [Hz] (accurate AMM, sliders locked).
    pub f1_hz: Option<f64>,
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

impl Row {
    /// The row's fields in header order; numbers in shortest round-trip form.
    pub fn record(&self) -> Vec<String> {
        let mut r = Vec::with_capacity(self.values.len() + 12);
        r.push(self.run_id.clone());
        r.extend(self.values.iter().cloned());
        r.push(self.solver.clone());
        r.push(self.status.clone());
        r.extend([self.peak_tip_m, self.peak_wg_m, self.peak_fa_n, self.evp_percent].map(opt));
        r.push(format!("{:.6}", self.wall_s));
        r.extend([
            opt(self.residual_tip_m),
            opt(self.modes),
            opt(self.error_estimate_percent),
            opt(self.residual_g_m),
            opt(self.settle_s),
            opt(self.evp_max_percent),
            opt(self.f1_hz),
        ]);
        r
    }
}

/// A results table read back: header and records as text.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// Position of column `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The varied keys: the columns between `run_id` and `solver`.
    pub fn keys(&self) -> Vec<String> {
        let end = self.column("solver").unwrap_or(1);
        self.header[1..end].to_vec()
    }

    /// Read a table; a last line cut short by an interruption (no final newline) is dropped.
    pub fn read(path: &Path) -> Result<Table, StudyError> {
        let bytes = std::fs::read(path).map_err(|source| StudyError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        let complete = match bytes.iter().rposition(|&b| b == b'\n') {
            Some(i) => &bytes[..=i],
            None => &bytes[..0],
        };
        let bad = |reason: String| StudyError::Results {
            file: path.to_path_buf(),
            reason,
        };
        let mut rd = csv::ReaderBuilder::new().has_headers(false).from_reader(complete);
        let mut records = rd.records();
        let header: Vec<String> = match records.next() {
            Some(h) => h.map_err(|e| bad(e.to_string()))?.iter().map(String::from).collect(),
            None => return Err(bad("no header line".into())),
        };
        let mut rows = Vec::new();
        for r in records {
            let r = r.map_err(|e| bad(e.to_string()))?;
            if r.len() != header.len() {
                return Err(bad(format!(
                    "a row has {} fields, the header {}",
                    r.len(),
                    header.len()
                )));
            }
            rows.push(r.iter().map(String::from).collect());
        }
        Ok(Table { header, rows })
    }

    /// Write the whole table, whole or not at all.
    pub fn write(&self, path: &Path) -> Result<(), StudyError> {
        self.emit(flexstar_io::output::Dest::File(path))
    }

    /// Stage the table as file `name` of a run set (published with its sidecar).
    pub fn stage(&self, set: &mut flexstar_io::run_set::RunSet, name: &str) -> Result<(), StudyError> {
        self.emit(flexstar_io::output::Dest::Set(set, name))
    }

    fn emit(&self, dest: flexstar_io::output::Dest<'_>) -> Result<(), StudyError> {
        dest.write(|w| {
            w.write_all(&records_bytes(std::iter::once(&self.header).chain(&self.rows))?)?;
            Ok(())
        })?;
        Ok(())
    }
}

/// CSV text of some records (one line each, quoted where needed).
pub fn records_bytes<'a, I>(records: I) -> Result<Vec<u8>, csv::Error>
where
    I: IntoIterator<Item = &'a Vec<String>>,
{
    let mut w = csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new());
    for r in records {
        w.write_record(r)?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}
