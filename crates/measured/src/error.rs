//! Errors of the measured data: every message names the file, the row or column, and why.

use std::path::PathBuf;

/// Why a recording, or an analysis of measured data, cannot be used. Rows are the data rows,
/// 1-based (the header is not a row); `line` is the line of the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasuredError {
    /// The file as a whole: cannot be read, no time column, too few rows, no sensors.
    #[error("{file}: {reason}")]
    File { file: PathBuf, reason: String },
    /// One column of the recording (or a `[measured]` key naming one).
    #[error("{file}: column {column}: {reason}")]
    Column {
        file: PathBuf,
        column: String,
        reason: String,
    },
    /// One row of the recording.
    #[error("{file}: row {row} (line {line}): {reason}")]
    Row {
        file: PathBuf,
        row: usize,
        line: u64,
        reason: String,
    },
    /// One cell of the recording.
    #[error("{file}: row {row} (line {line}), column {column}: {reason}")]
    Cell {
        file: PathBuf,
        row: usize,
        line: u64,
        column: String,
        reason: String,
    },
    /// Data handed to an analysis (a spectrum, an identification) that it cannot take: `what`
    /// names the input.
    #[error("{what}: {reason}")]
    Input { what: String, reason: String },
    /// The data hold nothing of what was asked (no mode in a free decay), with the reason.
    #[error("{0}")]
    NotFound(String),
    /// A dense linear-algebra step (faer) failed on these data.
    #[error("{step}: {reason}")]
    Numerical { step: &'static str, reason: String },
}

impl MeasuredError {
    /// The file concerned, if the error is about one.
    pub fn path(&self) -> Option<&std::path::Path> {
        match self {
            MeasuredError::File { file, .. }
            | MeasuredError::Column { file, .. }
            | MeasuredError::Row { file, .. }
            | MeasuredError::Cell { file, .. } => Some(file),
            MeasuredError::Input { .. } | MeasuredError::NotFound(_) | MeasuredError::Numerical { .. } => None,
        }
    }

    /// A [`MeasuredError::File`] error.
    pub fn file(file: &std::path::Path, reason: impl Into<String>) -> Self {
        MeasuredError::File {
            file: file.to_path_buf(),
            reason: reason.into(),
        }
    }

    /// A [`MeasuredError::Column`] error.
    pub fn column(file: &std::path::Path, column: &str, reason: impl Into<String>) -> Self {
        MeasuredError::Column {
            file: file.to_path_buf(),
            column: column.to_string(),
            reason: reason.into(),
        }
    }

    /// A [`MeasuredError::Input`] error.
    pub fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        MeasuredError::Input {
            what: what.into(),
            reason: reason.into(),
        }
    }
}
