//! # flexstar-measured
//!
//! What a researcher brings from the real robot, and what can be read from it without a model
//! (`docs/measured.md`). Data in, numbers out: no solver, no files written.

pub mod error;
pub mod identify;

pub use error::MeasuredError;
