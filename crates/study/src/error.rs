//! The one error type of the study crate: every message names the file, the key and the reason.

use std::path::PathBuf;

use flexstar_model::ModelError;

/// Errors raised before or around a study's runs. A case that fails while running is not an error
/// of the study: it becomes a row whose `status` says why.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The study was stopped on request ([`flexstar_model::cancel`]) between cases; the rows of
    /// the cases finished are in `results` (a rerun resumes).
    #[error("{results}: cancelled after {done} of {total} cases")]
    Cancelled {
        results: PathBuf,
        done: usize,
        total: usize,
    },
    /// A file could not be read.
    #[error("{file}: cannot read: {source}")]
    Read {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// TOML syntax error, unknown key or wrong type in the study file.
    #[error("{file}: {message}")]
    Parse { file: PathBuf, message: String },
    /// A value of the study file that parsed but cannot be used.
    #[error("{file}: key `{key}`: {reason}")]
    Invalid { file: PathBuf, key: String, reason: String },
    /// A `[[vary]]` key that the experiment format does not accept, or a value of the wrong type.
    #[error("{file}: [[vary]] key `{key}`: {reason}")]
    VaryKey { file: PathBuf, key: String, reason: String },
    /// The base experiment does not load.
    #[error("{study}: base experiment: {source}")]
    Base {
        study: PathBuf,
        #[source]
        source: ModelError,
    },
    /// A results table or its sidecar is unreadable or belongs to another study.
    #[error("{file}: {reason}")]
    Results { file: PathBuf, reason: String },
    /// A result file could not be written.
    #[error(transparent)]
    Write(#[from] ModelError),
    /// `--shard K/N` that is not 1 <= K <= N.
    #[error("--shard {given}: {reason}")]
    Shard { given: String, reason: String },
    /// Shards that cannot be merged (different studies, different splits, none found).
    #[error("merge {dir}: {reason}")]
    Merge { dir: PathBuf, reason: String },
    /// A plot could not be drawn.
    #[error("plot {name}: {reason}")]
    Plot { name: String, reason: String },
}

impl StudyError {
    pub(crate) fn invalid(file: &std::path::Path, key: impl Into<String>, reason: impl Into<String>) -> Self {
        StudyError::Invalid {
            file: file.to_path_buf(),
            key: key.into(),
            reason: reason.into(),
        }
    }
}

impl From<flexstar_io::WriteError> for StudyError {
    /// A result file that could not be written, as the model's `ModelError::Write` (same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        flexstar_model::ModelError::from(e).into()
    }
}
