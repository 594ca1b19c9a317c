//! The one error type of the modal crate.

/// Errors of the modal analyses; input errors are raised before any work or output.
#[derive(Debug, thiserror::Error)]
pub enum ModalError {
    /// A flag or value that cannot be used (the message names it and the bound).
    #[error("{0}")]
    Input(String),
    /// The pose is outside the workspace (the message names the limit).
    #[error("pose outside the workspace: {0}")]
    Infeasible(String),
    #[error(transparent)]
    Amm(#[from] flexstar_amm::AmmError),
    #[error(transparent)]
    Fem(#[from] flexstar_fem::FemError),
    #[error(transparent)]
    Model(#[from] flexstar_model::ModelError),
}

impl From<flexstar_io::WriteError> for ModalError {
    /// A result file that could not be written, as the model's `ModelError::Write` (same message).
    fn from(e: flexstar_io::WriteError) -> Self {
        flexstar_model::ModelError::from(e).into()
    }
}
