//! # flexstar-metrics
//!
//! How a run is measured and judged, the same code for every solver: the EVP of a response
//! against a reference (Eq. 45, [`evp`]), the residual vibration and settling after a motion
//! ([`residual`], `docs/motions.md` section 2; per dwell, [`dwell`], 2.5), the small-deflection range the AMM assumes
//! ([`validity`]) and the validated envelope of the accurate model ([`envelope`],
//! `docs/validation.md` section 8). Data in, numbers and verdicts out: no files, no solver.

pub mod dwell;
pub mod envelope;
pub mod evp;
pub mod friction_rest;
pub mod residual;
pub mod validity;

pub use residual::Residual;
pub use validity::small_deflection_check;
