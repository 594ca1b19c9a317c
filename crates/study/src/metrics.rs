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

/// The residual columns of a row (`residual_tip_m`, `residual_G_m`, `settle_s`) for a run `r`
/// of `exp` whose motion rests at `t_rest` [s], with the settling hold `hold_s` [s]
/// ([`flexstar_modal::settle::settle_hold_s`], computed once per case): `settle_s` is `inf` when
/// not settled by `t_end` (it sorts last, plots skip it). `g_pinned`: the run's family pins G
/// (pinned-free AMM), so it has no residual of G.
pub fn residual_columns(
    exp: &Experiment,
    r: &Response,
    (t_rest, hold_s): (f64, f64),
    g_pinned: bool,
) -> (Option<f64>, Option<f64>, Option<f64>) {
    match flexstar_metrics::residual::residual_after(r, t_rest, exp.report.settle_tol, hold_s) {
        Some(res) if g_pinned => (Some(res.tip_peak_m), None, None),
        Some(res) => (
            Some(res.tip_peak_m),
            Some(res.g_peak_m),
            Some(res.settle_s.unwrap_or(f64::INFINITY)),
        ),
        None => (None, None, None),
    }
}

/// Largest point EVP [%] over A, B, C, G of the points that have one (Eq. 45; the "largest
/// point" target of `docs/validation.md` section 8); `None` when no point has one.
pub fn largest_point_evp(e: &flexstar_metrics::evp::PointEvps) -> Option<f64> {
    e.points.iter().flatten().copied().reduce(f64::max)
}
