//! One module per subcommand.

pub mod compare;
pub mod kinematics;
pub mod modal;
pub mod modes;
pub mod run;
pub mod sweep;
pub mod verify;

use std::path::{Path, PathBuf};

use flexstar_model::{Experiment, Provenance};

/// Load and validate an experiment file (errors name the file, the key and the reason).
pub fn load(config: &Path) -> anyhow::Result<Experiment> {
    Ok(Experiment::load(config)?)
}

/// `DIR/<name>/`, created and checked writable (before any work is done).
pub fn case_dir(out: &Path, exp: &Experiment) -> anyhow::Result<PathBuf> {
    let dir = out.join(&exp.name);
    flexstar_model::output::ensure_writable_dir(out)?;
    flexstar_model::output::ensure_writable_dir(&dir)?;
    Ok(dir)
}

/// This binary's version, the commit it was built from (when known) and now.
pub fn provenance() -> Provenance {
    Provenance::now(option_env!("FLEXSTAR_GIT_COMMIT"))
}

/// Print the small-deflection warnings of a command on stderr.
pub fn print_warnings<W: std::fmt::Display>(warnings: &[W]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}
