//! One module per subcommand.

pub mod animate;
pub mod compare;
pub mod export;
pub mod fit;
pub mod kinematics;
pub mod modal;
pub mod modes;
pub mod plan;
pub mod run;
pub mod sweep;
pub mod verify;

use std::path::Path;

use flexstar_model::{Experiment, Provenance};
use flexstar_solve::Solver;

/// `--solver amm|fem`: the command line's names of [`Solver`] (the solver crate carries no
/// command-line code).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SolverArg {
    /// The paper's constrained assumed-modes method
    Amm,
    /// The independent finite-element reference
    Fem,
}

impl From<SolverArg> for Solver {
    fn from(s: SolverArg) -> Solver {
        match s {
            SolverArg::Amm => Solver::Amm,
            SolverArg::Fem => Solver::Fem,
        }
    }
}

/// Load and validate an experiment file (errors name the file, the key and the reason).
pub fn load(config: &Path) -> anyhow::Result<Experiment> {
    Ok(flexstar_api::load(config)?)
}

/// The library's version, the commit it was built from (when known) and now.
pub fn provenance() -> Provenance {
    flexstar_api::provenance()
}

/// Say on stderr when `out/<name>/` holds results of another experiment with the same `name`
/// (a copied file): what this command writes there replaces theirs.
pub fn note_other_experiment(out: &Path, exp: &Experiment) {
    if let Some(note) = flexstar_model::identity::other_experiment_note(&out.join(&exp.name), exp) {
        eprintln!("{note}");
    }
}

/// Print the small-deflection warnings of a command on stderr.
pub fn print_warnings<W: std::fmt::Display>(warnings: &[W]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}
