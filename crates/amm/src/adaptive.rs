//! Error estimate and automatic number of modes (issue 9; `docs/amm.md` section 9).
//!
//! The solver estimates the EVP (Eq. 45, mean over A, B, C and G with the n/a rule of
//! `flexstar_model::evp`) of its own modal truncation from two runs: N_prev and N = ~1.15 N_prev.
//! If the error falls like N^-p, the difference d between the two runs is
//! `e(N_prev) - e(N) = e(N) ((N / N_prev)^p - 1)`, so `e(N) = d / ((N / N_prev)^p - 1)`
//! (Richardson). The rate [`RATE`] is measured: between N = 46 and 53 the truncation EVP of the
//! paper's four cases against N = 150 falls by 2.4-2.9 times, p = 6.1-7.6 (`docs/amm.md`
//! section 9; `cargo run --release -p flexstar-amm --example convergence -- truncation`).
//! N starts where the modes first resolve the sleeve (wavelength 2L/N below Lp, `docs/amm.md`
//! section 3, plus a margin) and grows by 15 % until the estimate is below the tolerance, up to
//! [`MAX_AUTO_MODES`].

use flexstar_model::evp::point_evps;
use flexstar_model::{Experiment, Response};

use crate::error::AmmError;

/// Largest N the automatic choice tries (issue 9: stable to N = 200).
pub const MAX_AUTO_MODES: usize = 200;

/// Growth of N between two runs of the automatic choice.
pub const GROWTH: f64 = 1.15;

/// Convergence rate p of the truncation EVP, `e(N) ~ N^-p`, that turns the difference of two
/// runs into the estimate (module docs): the median of the rates measured on the paper's cases
/// between N = 46 and 53 (6.1, 6.8, 7.2, 7.6).
pub const RATE: f64 = 7.0;

/// Modes beyond the sleeve resolution `2 L / Lp` with which the automatic choice starts: at
/// `2 L / Lp + 6` the paper's cases are still 1.6-2.1 % off the FEM, at `+ 12` about 1 %
/// (`docs/amm.md` section 8), so a start below `+ 12` buys a run that no useful tolerance accepts.
pub const START_MARGIN: usize = 12;

/// First N of the automatic choice: the modes resolve the sleeve (`2 L / Lp`) plus
/// [`START_MARGIN`], at least 8 and at most [`MAX_AUTO_MODES`].
pub fn first_modes(exp: &Experiment) -> usize {
    let resolve = (2.0 * exp.robot.l / exp.robot.lp).ceil();
    let n = if resolve.is_finite() {
        resolve as usize
    } else {
        MAX_AUTO_MODES
    };
    (n + START_MARGIN).clamp(8, MAX_AUTO_MODES)
}

/// The N after `n` in the automatic sequence.
pub fn next_modes(n: usize) -> usize {
    ((n as f64 * GROWTH).ceil() as usize).max(n + 2).min(MAX_AUTO_MODES)
}

/// Estimated truncation EVP [%] of `fine` (N = `n_fine`) from the coarser run `coarse`
/// (N = `n_coarse`): the mean point EVP of `coarse` against `fine` divided by
/// `(n_fine / n_coarse)^RATE - 1` (see the module docs). `None` when no point has a reference.
pub fn truncation_estimate(coarse: &Response, fine: &Response, n_coarse: usize, n_fine: usize) -> Option<f64> {
    let richardson = (n_fine as f64 / n_coarse as f64).powf(RATE) - 1.0;
    point_evps(coarse, fine)
        .ok()
        .and_then(|e| e.mean)
        .map(|d| d / richardson)
}

/// Raise N from [`first_modes`] until the estimate is below `tol` [%]; `run(n)` solves at N = n.
/// Returns the last run with `info.modes`, `info.error_estimate_percent` and `info.tol_percent`
/// set, its wall time the sum over the runs. Fails with the estimate reached when the tolerance
/// is not met at [`MAX_AUTO_MODES`].
pub(crate) fn solve_to_tolerance<F>(exp: &Experiment, tol: f64, mut run: F) -> Result<Response, AmmError>
where
    F: FnMut(usize) -> Result<Response, AmmError>,
{
    let mut n = first_modes(exp);
    let mut prev = run(n)?;
    let mut wall = prev.info.wall_s;
    loop {
        let n_next = next_modes(n);
        if n_next == n {
            let reached = prev.info.error_estimate_percent.unwrap_or(f64::NAN);
            return Err(AmmError::invalid(
                "amm.tol",
                format!(
                    "the tolerance {tol} % is not reached with N = {MAX_AUTO_MODES} modes: the estimated truncation EVP there is {reached:.3} %; raise tol"
                ),
            ));
        }
        let mut next = run(n_next)?;
        wall += next.info.wall_s;
        let estimate = truncation_estimate(&prev, &next, n, n_next).unwrap_or(0.0);
        next.info.error_estimate_percent = Some(estimate);
        next.info.tol_percent = Some(tol);
        next.info.wall_s = wall;
        if estimate <= tol {
            return Ok(next);
        }
        n = n_next;
        prev = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::catalogue::paper_case;

    #[test]
    fn sequence_starts_at_the_sleeve_resolution_and_ends_at_the_cap() {
        // paper robot: 2 L / Lp = 2 * 0.5 / 0.03 = 33.3 -> 34 modes resolve the sleeve
        let exp = paper_case(1);
        assert_eq!(first_modes(&exp), 34 + START_MARGIN);
        let mut n = first_modes(&exp);
        let mut steps = 0;
        while next_modes(n) != n {
            assert!(next_modes(n) > n);
            n = next_modes(n);
            steps += 1;
        }
        assert_eq!(n, MAX_AUTO_MODES);
        assert!(steps < 20, "{steps}");
    }
}
