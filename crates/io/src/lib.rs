//! # flexstar-io
//!
//! How flexstar writes result files, independent of what they hold: every file whole or not at
//! all ([`output`]: a temporary beside the target renamed over it), the files of one run published
//! as one unit that survives a killed writer ([`run_set`]), and numbers in the shortest form that
//! reads back exactly. The protocol is `docs/outputs.md`; the robot, its experiments and the
//! solvers' responses know nothing of it beyond these calls.

pub mod output;
pub mod run_set;

use std::path::PathBuf;

/// A result file that could not be written; nothing is left behind (an older file is kept).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: cannot write: {reason}")]
pub struct WriteError {
    /// The file (or folder) that could not be written [path].
    pub file: PathBuf,
    /// Why, in words.
    pub reason: String,
}
