//! One module per subcommand.

pub mod kinematics;
pub mod modes;
pub mod run;
pub mod sweep;
pub mod verify;

use std::path::{Path, PathBuf};

use anyhow::Context;
use flexstar_model::Experiment;

/// Load and validate an experiment file (errors name the file, the key and the reason).
pub fn load(config: &Path) -> anyhow::Result<Experiment> {
    Ok(Experiment::load(config)?)
}

/// `DIR/<name>/`, created if needed.
pub fn case_dir(out: &Path, exp: &Experiment) -> anyhow::Result<PathBuf> {
    let dir = out.join(&exp.name);
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create output directory {}", dir.display()))?;
    Ok(dir)
}
