//! The one error type of `flexstar-measured`: what is wrong and where, never a panic on data.

/// An error of the measured-data functions, naming what (a channel, a sample, an option) and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasuredError {
    /// Input data or options that cannot be used: `what` names the channel, the sample or the
    /// option, `reason` says why (with the values).
    #[error("{what}: {reason}")]
    Input { what: String, reason: String },
    /// The data hold nothing of what was asked (no mode in a free decay), with the reason.
    #[error("{0}")]
    NotFound(String),
    /// A dense linear-algebra step (faer) failed on these data.
    #[error("{step}: {reason}")]
    Numerical { step: &'static str, reason: String },
}

impl MeasuredError {
    /// [`MeasuredError::Input`] from anything printable.
    pub fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        MeasuredError::Input {
            what: what.into(),
            reason: reason.into(),
        }
    }
}
