//! `flexstar animate RUN_DIR` (`docs/motions.md` section 5): every run's
//! animation frames (`<stem>-frames.csv`, `<stem>-frames-pose.csv`) read back and drawn in one
//! self-contained HTML page: the rigid star, the deformed beams `P_rigid + M (P - P_rigid)` with
//! the elastic part magnified M times, a time slider and a play button. No network: no external
//! URL anywhere in the page.

mod page;
mod read;

use std::path::{Path, PathBuf};

pub use page::{build_page, default_magnification};
pub use read::{read_dir, RunFrames};

/// Why no page was written.
#[derive(Debug, thiserror::Error)]
pub enum AnimateError {
    /// A file of the run folder could not be read or is not what the frames files are.
    #[error("{file}: {reason}")]
    Read { file: PathBuf, reason: String },
    /// The folder has no frames file.
    #[error(
        "{0}: no *-frames.csv here; set `frames` (per second, e.g. `[amm] frames = 100`, \
         likewise `[fem] frames`) in the experiment and run it again"
    )]
    NoFrames(PathBuf),
    /// The runs' frame times differ: they cannot be overlaid.
    #[error("the frame times of the runs differ, they cannot be overlaid: {0}")]
    TimesDiffer(String),
    /// The runs' sidecars record different experiments: they are not one robot's.
    #[error("the runs are of different experiments, they cannot be overlaid: {0}")]
    ExperimentsDiffer(String),
    /// `--magnify` not a positive number.
    #[error("--magnify: need a positive finite magnification, got {0}")]
    Magnify(f64),
    /// The page could not be written.
    #[error(transparent)]
    Write(#[from] flexstar_model::ModelError),
}

/// Read the frames of `dir`, build the page (magnification `magnify`, default
/// [`default_magnification`]) and write it atomically to `out` (default `dir/animate.html`).
/// Returns the path written and the runs drawn.
pub fn animate(dir: &Path, out: Option<&Path>, magnify: Option<f64>) -> Result<(PathBuf, Vec<String>), AnimateError> {
    if let Some(m) = magnify {
        if !(m.is_finite() && m > 0.0) {
            return Err(AnimateError::Magnify(m));
        }
    }
    let runs = read_dir(dir)?;
    let html = build_page(&runs, magnify)?;
    let path = out.map_or_else(|| dir.join("animate.html"), Path::to_path_buf);
    flexstar_io::output::write_string_atomically(&path, &html)?;
    Ok((path, runs.into_iter().map(|r| r.name).collect()))
}

impl From<flexstar_io::WriteError> for AnimateError {
    /// A result file that could not be written, as the model's `ModelError::Write` (same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        flexstar_model::ModelError::from(e).into()
    }
}
