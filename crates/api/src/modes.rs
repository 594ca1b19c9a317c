//! `modes`: the assumed modes of a family (Eq. 34-1), rigid modes included.

use flexstar_io::output::fmt_display;
use flexstar_model::{ModeFamily, RobotParams};

use crate::{ApiError, Result};

/// `beta*L` [-] and the natural frequency [Hz] of each of the first `n` modes of `family` for a
/// beam of `params` (E, I, rho, L).
pub fn mode_table(family: ModeFamily, n: usize, params: &RobotParams) -> Result<(Vec<f64>, Vec<f64>)> {
    let set = flexstar_amm::ModeSet::new(family, n, params).map_err(|e| match &e {
        flexstar_amm::AmmError::InvalidSetting { reason, .. } => ApiError::flag("--modes", reason.clone()),
        _ => ApiError::Solver { message: e.to_string() },
    })?;
    Ok((set.beta_l(), set.frequencies_hz()))
}

/// The first line of the table of `flexstar modes`: the family and the beam's parameters, each
/// rounded for reading (`EI = 0.5 N m^2`, not `0.49999999999999994`).
pub fn header(family: ModeFamily, params: &RobotParams) -> String {
    format!(
        "# {family} modes, L = {} m, EI = {} N m^2, rho = {} kg/m",
        fmt_display(params.l),
        fmt_display(params.ei()),
        fmt_display(params.rho)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_shows_rounded_parameters() {
        let p = RobotParams::paper();
        // E I of the paper's beam is 0.5 N m^2 but 0.49999999999999994 in floating point
        assert_ne!(p.ei(), 0.5);
        assert_eq!(
            header(ModeFamily::FreeFree, &p),
            "# free-free modes, L = 0.5 m, EI = 0.5 N m^2, rho = 0.234 kg/m"
        );
    }
}
