//! Errors of the model crate: every message names where (file, key, time) and why.

use std::path::PathBuf;

/// Errors raised while reading, validating or writing model data.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Read {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// TOML syntax error, unknown key or wrong type (the message names the key and line).
    #[error("{file}: {message}")]
    Parse { file: PathBuf, message: String },
    /// A value that parsed but is physically or numerically meaningless.
    #[error("{file}: key `{key}`: {reason}")]
    Invalid { file: PathBuf, key: String, reason: String },
    /// The inverse kinematics of a task-space pose has no solution (a beam parallel to its slider).
    #[error("inverse kinematics: {0}")]
    InverseKinematics(String),
    /// A robot the solvers' equal-beam models do not take (`docs/architecture.md`, "The robot
    /// description"): `what` names the datum that makes it other than the paper's.
    #[error(
        "{what}: {by} takes only the paper's robot so far (three equal beams welded 120 degrees apart on an \
         equilateral base; docs/as-built.md 6)"
    )]
    Unsupported { what: String, by: String },
    /// A result file could not be written (nothing is left behind).
    #[error("{file}: cannot write: {reason}")]
    Write { file: PathBuf, reason: String },
}

impl ModelError {
    /// An [`ModelError::Invalid`] with the file left empty (filled in by the config loader).
    pub fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Self {
        ModelError::Invalid {
            file: PathBuf::new(),
            key: key.into(),
            reason: reason.into(),
        }
    }

    /// The message without the file, for a caller that names the file itself: key and reason of
    /// an [`ModelError::Invalid`], the message of a [`ModelError::Parse`], the whole message
    /// otherwise.
    pub fn detail(&self) -> String {
        match self {
            ModelError::Invalid { key, reason, .. } => format!("key `{key}`: {reason}"),
            ModelError::Parse { message, .. } => message.clone(),
            other => other.to_string(),
        }
    }

    /// Attach the file name to an error raised before it was known.
    pub fn in_file(self, path: &std::path::Path) -> Self {
        match self {
            ModelError::Invalid { key, reason, .. } => ModelError::Invalid {
                file: path.to_path_buf(),
                key,
                reason,
            },
            other => other,
        }
    }
}

/// Why a table of force samples (`[drive] file`, a force table) cannot be used; rows are 1-based.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// Times and force rows differ in number.
    #[error("{times} times but {rows} force rows")]
    Lengths { times: usize, rows: usize },
    /// Fewer than two samples.
    #[error("need at least two samples, got {0}")]
    TooFew(usize),
    /// A NaN or infinite time or force in row `row`.
    #[error("row {row}: non-finite value")]
    NonFinite { row: usize },
    /// The time of row `row` [s] is not above the previous one.
    #[error("row {row}: time {t} s does not increase (previous {previous} s)")]
    NotIncreasing { row: usize, t: f64, previous: f64 },
    /// The samples span `[first, last]` [s] but the run needs `[t0, t1]` [s].
    #[error("samples span [{first}, {last}] s but the run needs [{t0}, {t1}] s")]
    Span { first: f64, last: f64, t0: f64, t1: f64 },
}

impl From<flexstar_io::WriteError> for ModelError {
    /// A result file that could not be written, as [`ModelError::Write`] (the same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        ModelError::Write {
            file: e.file,
            reason: e.reason,
        }
    }
}
