//! The one error type of the library entry point: fronts tell bad input (file, key, reason), a
//! motion that leaves the workspace (time, reason), a failed solve and a stop on request apart.
//! Every message is the one the command line prints (the file or argument first).

use std::path::Path;

use flexstar_model::ModelError;

/// Everything that stops a command of [`crate`]. `message` is the whole text shown to the user.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// Bad input: a file that cannot be read or parsed, an unknown key, a meaningless value, a
    /// setting that does not apply. `file` is the experiment file or the argument (`--dt`).
    #[error("{message}")]
    Config {
        file: String,
        key: Option<String>,
        reason: String,
        message: String,
    },
    /// The motion leaves the feasible range at time `t` [s] (found before any work for a
    /// prescribed motion, as it goes for a direct run).
    #[error("{message}")]
    Infeasible { t: f64, reason: String, message: String },
    /// The solver failed (singular system, Newton failure, non-finite solution, ...).
    #[error("{message}")]
    Solver { message: String },
    /// The progress callback asked the solver to stop (e.g. Ctrl-C in Python) at time `t` [s].
    #[error("{file}: cancelled at t = {t} s")]
    Cancelled { file: String, t: f64 },
    /// A result file could not be written (nothing is left behind).
    #[error("{0}")]
    Output(String),
}

impl ApiError {
    /// Bad input in `file` (or an argument), with the key when known.
    pub fn config(file: impl std::fmt::Display, key: Option<&str>, reason: impl Into<String>) -> Self {
        let (file, reason) = (file.to_string(), reason.into());
        let message = match key {
            Some(k) => format!("{file}: key `{k}`: {reason}"),
            None => format!("{file}: {reason}"),
        };
        ApiError::Config {
            file,
            key: key.map(str::to_string),
            reason,
            message,
        }
    }

    /// Bad value of a command-line flag (or a Python keyword): `--tol: the tolerance must be a
    /// positive percentage, got -1`. The flag stands in the error's `file`; there is no key.
    pub fn flag(flag: &str, reason: impl Into<String>) -> Self {
        let reason = reason.into();
        ApiError::Config {
            file: flag.to_string(),
            key: None,
            message: format!("{flag}: {reason}"),
            reason,
        }
    }

    /// A model error raised by the value of `flag`: its reason after the flag ([`ApiError::flag`]);
    /// other model errors as [`ApiError::from_model`].
    pub fn from_flag(flag: &str, e: ModelError) -> Self {
        match e {
            ModelError::Invalid { key, reason, .. } => Self::flag_at(flag, &key, reason),
            other => Self::from_model(other),
        }
    }

    /// [`ApiError::flag`] for a flag that sets the experiment key `key` (`--elements` sets
    /// `fem.elements`): the message names the flag, the error's `key` field the key (Python's
    /// `ConfigError.key`).
    pub fn flag_at(flag: &str, key: &str, reason: impl Into<String>) -> Self {
        match Self::flag(flag, reason) {
            ApiError::Config {
                file, reason, message, ..
            } => ApiError::Config {
                file,
                key: Some(key.to_string()),
                reason,
                message,
            },
            other => other,
        }
    }

    /// A config error whose text is given whole (the library's own wording kept).
    pub fn config_text(file: impl std::fmt::Display, key: Option<&str>, reason: &str, message: String) -> Self {
        ApiError::Config {
            file: file.to_string(),
            key: key.map(str::to_string),
            reason: reason.to_string(),
            message,
        }
    }

    /// An infeasible motion in `file` at time `t` [s]; `reason` is the library's message.
    pub fn infeasible(file: impl std::fmt::Display, t: f64, reason: impl std::fmt::Display) -> Self {
        let reason = reason.to_string();
        ApiError::Infeasible {
            t,
            message: format!("{file}: {reason}"),
            reason,
        }
    }

    /// A solver failure on `file`.
    pub fn solver(file: impl std::fmt::Display, e: impl std::fmt::Display) -> Self {
        ApiError::Solver {
            message: format!("{file}: {e}"),
        }
    }

    /// For a command `by` that does not model friction yet (`docs/friction.md` 6): a config error
    /// naming the file, the key `friction` and the command when `exp` has friction.
    pub fn frictionless(
        exp: &flexstar_model::Experiment,
        file: impl std::fmt::Display,
        by: &str,
    ) -> std::result::Result<(), ApiError> {
        exp.frictionless(by)
            .map_err(|e| Self::model_in(&file, Path::new(&file.to_string()), e))
    }

    /// A model error: reading and validation are config errors, writing an output error.
    pub fn from_model(e: ModelError) -> Self {
        let message = e.to_string();
        match e {
            ModelError::Read { file, source } => {
                Self::config_text(file.display(), None, &format!("cannot read: {source}"), message)
            }
            ModelError::Parse { file, message: m } => Self::config_text(file.display(), None, &m, message),
            ModelError::Invalid { file, key, reason } => {
                Self::config_text(file.display(), Some(&key), &reason, message)
            }
            ModelError::InverseKinematics(r) => Self::config_text("", None, &r, message),
            ModelError::Unsupported { what, .. } => Self::config_text("", Some("robot"), &what, message),
            ModelError::Write { .. } => ApiError::Output(message),
        }
    }

    /// A model error about `file` with `context` before the reason (`case3.toml with the
    /// command-line flags`).
    pub fn model_in(context: impl std::fmt::Display, file: &Path, e: ModelError) -> Self {
        match e {
            ModelError::Invalid { key, reason, .. } => {
                let message = format!("{context}: key `{key}`: {reason}");
                Self::config_text(file.display(), Some(&key), &reason, message)
            }
            other => Self::from_model(other.in_file(file)),
        }
    }
}

impl From<ModelError> for ApiError {
    fn from(e: ModelError) -> Self {
        ApiError::from_model(e)
    }
}

impl From<flexstar_plot::FigureError> for ApiError {
    fn from(e: flexstar_plot::FigureError) -> Self {
        ApiError::Output(e.to_string())
    }
}

/// The result of every command of [`crate`].
pub type Result<T> = std::result::Result<T, ApiError>;

impl From<flexstar_io::WriteError> for ApiError {
    /// A result file that could not be written, as the model's `ModelError::Write` (same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        flexstar_model::ModelError::from(e).into()
    }
}
