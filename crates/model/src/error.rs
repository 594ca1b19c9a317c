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
