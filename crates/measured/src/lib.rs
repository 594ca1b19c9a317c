//! # flexstar-measured
//!
//! What a researcher brings from the real robot, and what can be read from it without a model
//! (`docs/measured.md`). Data in, numbers out: no solver, no files written.
//!
//! - [`recording`]: a CSV recording read, mapped onto the experiment's sensor columns, scaled,
//!   shifted onto the run's clock (given or estimated, [`offset`]) and resampled onto the run's
//!   sensor times (section 1).
//! - [`welch`]: Welch's power spectral density (section 2).
//! - [`identify`]: the model-free identification of a free decay (section 3).

pub mod csv_table;
pub mod error;
pub mod identify;
pub mod offset;
pub mod recording;
pub mod welch;

pub use error::MeasuredError;
pub use recording::{Channel, Recording};
pub use welch::{welch, Psd, WelchOptions};
