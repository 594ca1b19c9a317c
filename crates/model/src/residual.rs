//! Residual vibration and settling after a rest-to-rest motion
//! (`docs/motions.md` sections 2.1-2.3), computed from the fixed columns every solver writes, so
//! that the AMM and the FEM are measured by the same code.
//!
//! The elastic displacement of G is one vector `dG` of the fixed frame whose projections on the
//! three rigid beam frames are `w_iG = dG . e_wi` (`docs/conventions.md`). The three unit vectors
//! `e_wi` are 120 degrees apart, so `sum_i (dG . e_wi)^2 = 3/2 |dG|^2` for every vector:
//! `|dG| = sqrt(2/3 (w_1G^2 + w_2G^2 + w_3G^2))` [m], needing no frame (Eq. R1 of motions.md 2.1).

use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::response::Response;

/// Default `[report] settle_tol` [m]: the settling band on |dG| (`docs/motions.md` 2.3).
pub const DEFAULT_SETTLE_TOL: f64 = 1e-4;

/// The `[report]` section: how reports measure the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReportSettings {
    /// Settling band on the elastic displacement of G, |dG| [m] (default 1e-4).
    #[serde(default = "default_settle_tol")]
    pub settle_tol: f64,
}

fn default_settle_tol() -> f64 {
    DEFAULT_SETTLE_TOL
}

impl Default for ReportSettings {
    fn default() -> Self {
        ReportSettings {
            settle_tol: DEFAULT_SETTLE_TOL,
        }
    }
}

impl ReportSettings {
    /// `settle_tol` must be positive and finite.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.settle_tol.is_finite() && self.settle_tol > 0.0) {
            return Err(ModelError::invalid(
                "report.settle_tol",
                format!("need a positive, finite band in m, got {}", self.settle_tol),
            ));
        }
        Ok(())
    }
}

/// |dG| [m] from the projections `w_iG` [m] on the three rigid beam frames (Eq. R1).
pub fn dg_magnitude(w_g: [f64; 3]) -> f64 {
    (2.0 / 3.0 * (w_g[0] * w_g[0] + w_g[1] * w_g[1] + w_g[2] * w_g[2])).sqrt()
}

/// `dG = 2/3 (w_1G e_w1 + w_2G e_w2 + w_3G e_w3)` [m, fixed frame]: the vector whose projections
/// on the `e_wi` are the `w_iG` (motions.md 2.1; exact when the `w_iG` are projections of one
/// vector, which the junction rows of Eq. 38-39 make them in the AMM).
pub fn dg_vector(w_g: [f64; 3], e_w: [[f64; 2]; 3]) -> [f64; 2] {
    let mut d = [0.0; 2];
    for i in 0..3 {
        d[0] += 2.0 / 3.0 * w_g[i] * e_w[i][0];
        d[1] += 2.0 / 3.0 * w_g[i] * e_w[i][1];
    }
    d
}

/// What is left of the vibration after the motion has come to rest (motions.md 2.2-2.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Residual {
    /// End of the motion [s] (`Trajectory::t_rest`).
    pub t_rest: f64,
    /// Largest |dG| at the output times `t >= t_rest` [m].
    pub g_peak_m: f64,
    /// RMS of |dG| over `[t_rest, t_end]`, trapezoidal rule [m].
    pub g_rms_m: f64,
    /// Largest |w_i(L)| over the three tips at `t >= t_rest` [m].
    pub tip_peak_m: f64,
    /// RMS over `[t_rest, t_end]` of `sqrt(1/3 sum_i w_i(L)^2)` [m].
    pub tip_rms_m: f64,
    /// The last output time `>= t_rest` with |dG| above the band (`t_rest` when none) [s,
    /// absolute]; `None` when not settled by `t_end`.
    pub settle_s: Option<f64>,
    /// The band used [m].
    pub settle_tol: f64,
    /// The quiet time the run must end with to count as settled [s] (motions.md 2.3).
    pub hold_s: f64,
}

impl Residual {
    /// Settled by `t_end`?
    pub fn settled(&self) -> bool {
        self.settle_s.is_some()
    }
}

/// The residual of `r` after `t_rest` [s]: peaks and RMS of |dG| and of the tips, and the
/// settling time in the band `settle_tol` [m]. Settled when the run ends with at least `hold_s`
/// [s] below the band after its last excursion (one period of the first elastic mode at the final
/// pose: an undamped oscillation above the band leaves it at least twice a period, so it never
/// counts as settled). `None` when fewer than two output times lie at or after `t_rest`.
pub fn residual_after(r: &Response, t_rest: f64, settle_tol: f64, hold_s: f64) -> Option<Residual> {
    let first = r.t.partition_point(|&t| t < t_rest - 1e-12);
    if r.t.len() < first + 2 {
        return None;
    }
    let t = &r.t[first..];
    let dg: Vec<f64> = (first..r.t.len())
        .map(|k| dg_magnitude([r.w_g[0][k], r.w_g[1][k], r.w_g[2][k]]))
        .collect();
    let tip_mean: Vec<f64> = (first..r.t.len())
        .map(|k| (r.w_tip.iter().map(|w| w[k] * w[k]).sum::<f64>() / 3.0).sqrt())
        .collect();
    let tip_peak_m = r
        .w_tip
        .iter()
        .flat_map(|w| &w[first..])
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let t_end = *t.last().unwrap_or(&t_rest);
    let last_out = t
        .iter()
        .zip(&dg)
        .filter(|(_, d)| **d > settle_tol)
        .map(|(t, _)| *t)
        .next_back();
    let t_last = last_out.unwrap_or(t_rest);
    let settled = t_end - t_last >= hold_s - 1e-12;
    Some(Residual {
        t_rest,
        g_peak_m: dg.iter().fold(0.0, |m: f64, v| m.max(*v)),
        g_rms_m: rms(t, &dg),
        tip_peak_m,
        tip_rms_m: rms(t, &tip_mean),
        settle_s: settled.then_some(t_last),
        settle_tol,
        hold_s,
    })
}

/// `sqrt(1/(t_n - t_0) int f^2 dt)`, trapezoidal rule over the samples (the rule of the EVP).
fn rms(t: &[f64], f: &[f64]) -> f64 {
    let span = t[t.len() - 1] - t[0];
    if span <= 0.0 {
        return f.first().map_or(0.0, |v| v.abs());
    }
    let integral: f64 = t
        .windows(2)
        .zip(f.windows(2))
        .map(|(tt, ff)| 0.5 * (tt[1] - tt[0]) * (ff[0] * ff[0] + ff[1] * ff[1]))
        .sum();
    (integral / span).sqrt()
}

/// The sidecar's top-level keys of a residual (`docs/outputs.md`): `t_rest`,
/// `residual_G_peak_m`, `residual_G_rms_m`, `residual_tip_peak_m`, `residual_tip_rms_m`,
/// `settle_s` (null when not settled), `settled`, `settle_tol`, `settle_hold_s`. Without a
/// residual (no rest before `t_end`) every key is null but `settle_tol`. `g_pinned`: the run's
/// modes pin G (the AMM's pinned-free family, `phi(0) = 0`), so it has no residual of G: those
/// keys are null, with `residual_note`.
pub fn sidecar_fields(
    res: Option<&Residual>,
    settle_tol: f64,
    g_pinned: bool,
) -> serde_json::Map<String, serde_json::Value> {
    use serde_json::Value;
    let num = |v: f64| serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number);
    let mut m = serde_json::Map::new();
    let get = |f: fn(&Residual) -> f64| res.map_or(Value::Null, |r| num(f(r)));
    m.insert("t_rest".into(), get(|r| r.t_rest));
    m.insert("residual_G_peak_m".into(), get(|r| r.g_peak_m));
    m.insert("residual_G_rms_m".into(), get(|r| r.g_rms_m));
    m.insert("residual_tip_peak_m".into(), get(|r| r.tip_peak_m));
    m.insert("residual_tip_rms_m".into(), get(|r| r.tip_rms_m));
    let settle = res.and_then(|r| r.settle_s).map_or(Value::Null, num);
    m.insert("settle_s".into(), settle);
    m.insert("settled".into(), res.map_or(Value::Null, |r| Value::Bool(r.settled())));
    m.insert("settle_tol".into(), num(settle_tol));
    m.insert("settle_hold_s".into(), get(|r| r.hold_s));
    if g_pinned && res.is_some() {
        for key in ["residual_G_peak_m", "residual_G_rms_m", "settle_s", "settled"] {
            m.insert(key.into(), Value::Null);
        }
        m.insert("residual_note".into(), "G is pinned in this family".into());
    }
    m
}

/// The words a report prints for a settling time: `0.532 s`, or `not settled by t_end`.
pub fn settle_text(res: &Residual) -> String {
    match res.settle_s {
        Some(t) => format!("{t:.3} s"),
        None => "not settled by t_end".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A response whose elastic displacement of G is the vector `d(t)` (projected on the three
    /// frames of theta = 0.3) and whose tip 1 is `tip(t)`.
    fn response(ts: &[f64], d: impl Fn(f64) -> [f64; 2], tip: impl Fn(f64) -> f64) -> Response {
        let mut r = Response::with_capacity("x", ts.len());
        let e_w = frames(0.3);
        for &t in ts {
            let v = d(t);
            let w_g = e_w.map(|e| v[0] * e[0] + v[1] * e[1]);
            r.push(t, w_g, [tip(t), 0.0, 0.0], [0.0; 3]);
        }
        r
    }

    fn frames(theta: f64) -> [[f64; 2]; 3] {
        std::array::from_fn(|i| {
            let phi = theta + i as f64 * 2.0 * std::f64::consts::PI / 3.0;
            [-phi.sin(), phi.cos()]
        })
    }

    fn grid(t_end: f64, dt: f64) -> Vec<f64> {
        (0..=(t_end / dt).round() as usize).map(|k| k as f64 * dt).collect()
    }

    #[test]
    fn the_magnitude_and_vector_of_dg_come_back_from_its_projections() {
        let e_w = frames(-0.7);
        let v = [3e-4, -1.2e-4];
        let w_g = e_w.map(|e| v[0] * e[0] + v[1] * e[1]);
        assert!((dg_magnitude(w_g) - (v[0] * v[0] + v[1] * v[1]).sqrt()).abs() < 1e-18);
        let back = dg_vector(w_g, e_w);
        assert!((back[0] - v[0]).abs() < 1e-18 && (back[1] - v[1]).abs() < 1e-18);
    }

    #[test]
    fn a_circular_vibration_has_its_amplitude_as_peak_and_rms() {
        // |dG| = A exactly for a circular orbit; an axis-aligned sine has RMS A / sqrt 2
        let (a, f) = (2e-4, 5.0);
        let w = 2.0 * std::f64::consts::PI * f;
        let ts = grid(2.0, 1e-3);
        let r = response(
            &ts,
            |t| [a * (w * t).cos(), a * (w * t).sin()],
            |t| 1e-2 * (w * t).sin(),
        );
        let res = residual_after(&r, 1.0, 1e-4, 0.2).unwrap();
        assert!((res.g_peak_m - a).abs() < 1e-12 * a);
        assert!((res.g_rms_m - a).abs() < 1e-12 * a);
        assert!((res.tip_peak_m - 1e-2).abs() < 1e-6);
        // tip RMS: sqrt(1/3) of the one tip's RMS 1e-2 / sqrt 2, over 5 whole periods
        let expect = 1e-2 / 2f64.sqrt() / 3f64.sqrt();
        assert!((res.tip_rms_m - expect).abs() < 1e-4 * expect, "{}", res.tip_rms_m);
        // an undamped vibration above the band never settles
        assert!(!res.settled() && res.settle_s.is_none());
    }

    #[test]
    fn a_decaying_vibration_settles_when_its_envelope_crosses_the_band() {
        // |dG| = A exp(-s (t - t_rest)) on a circle: above the band until
        // t* = t_rest + ln(A / tol) / s, exactly
        let (a, s, tol, t_rest) = (1e-3, 3.0, 1e-4, 0.5);
        let w = 2.0 * std::f64::consts::PI * 4.0;
        let ts = grid(3.0, 1e-3);
        let env = |t: f64| if t < t_rest { a } else { a * (-s * (t - t_rest)).exp() };
        let r = response(&ts, |t| [env(t) * (w * t).cos(), env(t) * (w * t).sin()], |_| 0.0);
        let res = residual_after(&r, t_rest, tol, 0.25).unwrap();
        let t_star = t_rest + (a / tol).ln() / s;
        let settle = res.settle_s.unwrap();
        assert!(
            settle <= t_star && t_star - settle < 1e-3 + 1e-12,
            "{settle} vs {t_star}"
        );
        assert!((res.g_peak_m - a).abs() < 1e-15);
        // the same run with a hold longer than the quiet end: not settled
        assert!(residual_after(&r, t_rest, tol, 3.0 - t_star + 0.01)
            .unwrap()
            .settle_s
            .is_none());
    }

    #[test]
    fn a_residual_below_the_band_settles_at_t_rest_and_a_late_rest_has_none() {
        let ts = grid(1.0, 1e-3);
        let r = response(&ts, |t| [1e-5 * t, 0.0], |_| 0.0);
        let res = residual_after(&r, 0.4, 1e-4, 0.1).unwrap();
        assert_eq!(res.settle_s, Some(0.4));
        assert!(residual_after(&r, 1.0, 1e-4, 0.1).is_none());
        let keys = sidecar_fields(None, 1e-4, false);
        assert!(keys["t_rest"].is_null() && keys["settled"].is_null() && keys["settle_tol"] == 1e-4);
        let keys = sidecar_fields(Some(&res), 1e-4, false);
        assert_eq!(keys["settle_s"], 0.4);
        assert_eq!(keys["settled"], true);
        let keys = sidecar_fields(Some(&res), 1e-4, true);
        assert!(keys["settle_s"].is_null() && keys["residual_G_peak_m"].is_null());
        assert_eq!(keys["residual_note"], "G is pinned in this family");
    }

    #[test]
    fn settle_tol_must_be_positive() {
        for bad in [0.0, -1e-4, f64::NAN, f64::INFINITY] {
            let e = ReportSettings { settle_tol: bad }.validate().unwrap_err().to_string();
            assert!(e.contains("report.settle_tol"), "{e}");
        }
        ReportSettings::default().validate().unwrap();
    }
}
