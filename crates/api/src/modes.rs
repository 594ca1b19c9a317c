//! `modes`: the assumed modes of a family (Eq. 34-1), rigid modes included.

use flexstar_model::{ModeFamily, RobotParams};

use crate::{ApiError, Result};

/// `beta*L` [-] and the natural frequency [Hz] of each of the first `n` modes of `family` for a
/// beam of `params` (E, I, rho, L).
pub fn mode_table(family: ModeFamily, n: usize, params: &RobotParams) -> Result<(Vec<f64>, Vec<f64>)> {
    let set = flexstar_amm::ModeSet::new(family, n, params).map_err(|e| match &e {
        flexstar_amm::AmmError::InvalidSetting { key, reason } => {
            ApiError::config_text("--modes", Some(key), reason, e.to_string())
        }
        _ => ApiError::Solver { message: e.to_string() },
    })?;
    Ok((set.beta_l(), set.frequencies_hz()))
}
