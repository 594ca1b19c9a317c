//! What a study records of each run: peaks of the response, vibration left after a rest-to-rest
//! motion, and the AMM's accuracy against the FEM (Eq. 45).

use flexstar_model::{Experiment, Response};
use flexstar_numerics::measures::max_abs;

/// Peak magnitudes of one response over the whole time span.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peaks {
    /// Largest |w_i(L)| over the three tips A, B, C [m].
    pub tip_m: f64,
    /// Largest |w_iG| over the three rigid beam frames [m].
    pub w_g_m: f64,
    /// Largest |Fa_i| over the three actuators [N] (Eq. 33).
    pub fa_n: f64,
}

/// Largest magnitude over three histories.
fn peak3(h: &[Vec<f64>; 3]) -> f64 {
    h.iter().map(|v| max_abs(v)).fold(0.0, f64::max)
}

/// The peaks of `r`.
pub fn peaks(r: &Response) -> Peaks {
    Peaks {
        tip_m: peak3(&r.w_tip),
        w_g_m: peak3(&r.w_g),
        fa_n: peak3(&r.fa),
    }
}

/// End of the motion [s]: the `t_rest` of a rest-to-rest trajectory (quintic, via, table;
/// [`flexstar_model::Trajectory::t_rest`]) that ends before `time.t_end`; `None` for polynomial
/// motions (they never come to rest).
pub fn motion_end(exp: &Experiment) -> Option<f64> {
    exp.trajectory.t_rest().filter(|&t| t < exp.time.t_end)
}

/// Residual vibration: largest |w_i(L)| over the tips at the output times `t >= t_motion_end` [m].
pub fn residual_tip(r: &Response, t_motion_end: f64) -> f64 {
    let first = r.t.partition_point(|&t| t < t_motion_end - 1e-12);
    r.w_tip.iter().map(|v| max_abs(&v[first..])).fold(0.0, f64::max)
}

/// Mean EVP [%] of the AMM against the FEM of the same case over the points A, B, C, G that have
/// one (Eq. 45, the mean of Table I; `flexstar_compare::point_evps`).
pub fn mean_evp(amm: &Response, fem: &Response) -> Option<f64> {
    flexstar_compare::point_evps(amm, fem).ok().and_then(|e| e.mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn residual_is_taken_after_the_motion_only() {
        let mut r = Response::with_capacity("x", 5);
        for (k, tip) in [0.0, 5.0, -3.0, 0.5, -0.25].into_iter().enumerate() {
            r.push(k as f64 * 0.1, [0.0; 3], [tip, 0.0, 0.0], [0.0; 3]);
        }
        assert_eq!(residual_tip(&r, 0.3), 0.5);
        assert_eq!(residual_tip(&r, 0.2), 3.0);
        assert_eq!(peaks(&r).tip_m, 5.0);
    }
}
