//! Residual vibration and settling after a rest-to-rest motion
//! (`docs/motions.md` sections 2.1-2.3), computed from the fixed columns every solver writes, so
//! that the AMM and the FEM are measured by the same code.
//!
//! The elastic displacement of G is one vector `dG` of the fixed frame whose projections on the
//! three rigid beam frames are `w_iG = dG . e_wi` (`docs/conventions.md`). The three unit vectors
//! `e_wi` are 120 degrees apart, so `sum_i (dG . e_wi)^2 = 3/2 |dG|^2` for every vector:
//! `|dG| = sqrt(2/3 (w_1G^2 + w_2G^2 + w_3G^2))` [m], needing no frame (Eq. R1 of motions.md 2.1).

use serde::Serialize;

use flexstar_model::sidecar::ResidualKeys;
use flexstar_model::Response;

use crate::friction_rest::{friction_rest, FrictionRest};

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
    /// The last output time [s].
    pub t_end: f64,
    /// The decay rate `sigma` [1/s] of the envelope `A exp(-sigma t)` of |dG| after `t_rest`
    /// ([`envelope_decay`]); `None` when fewer than three periods of the first mode follow
    /// `t_rest`.
    pub decay_per_s: Option<f64>,
    /// Not settled, |dG| decaying: the time [s] the fitted envelope enters the band (not before
    /// the last excursion seen); the run settles when `t_end` is at least this plus `hold_s`.
    /// `None` when settled or when |dG| does not decay ([`DECAY_SEEN`]).
    pub settle_predicted_s: Option<f64>,
    /// A servo's run (columns `e1..e3`): the largest tracking error `|s_ref,i - s_i|` of the
    /// three sliders at `t >= t_rest` [m]; `None` for other runs.
    pub tracking_peak_m: Option<f64>,
    /// A servo's run: the largest of the three tracking errors at `t_end` [m]: how far the
    /// sliders still are from where the motion put them.
    pub tracking_end_m: Option<f64>,
    /// A run with friction: the rest state the measures above are taken about, or the sleeve
    /// still slipping at the end (the measures then about the rest state without friction, to
    /// which the star still relaxes; `docs/friction.md` 5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_rest: Option<FrictionRest>,
}

impl Residual {
    /// Settled by `t_end`?
    pub fn settled(&self) -> bool {
        self.settle_s.is_some()
    }
}

/// The residual of `r` after `t_rest` [s]: peaks and RMS of |dG| and of the tips (about the
/// static equilibrium of the rest pose, `Response::rest_offset`, under gravity; with friction
/// about the rest state the run ends in once every sleeve has stuck, [`friction_rest`],
/// `docs/friction.md` 5), and the settling time in the band `settle_tol` [m]. Settled when the run
/// ends with at least `hold_s` [s] below the band after its last excursion (one period of the
/// first elastic mode at the final pose: an undamped oscillation above the band leaves it at
/// least twice a period, so it never counts as settled). `None` when fewer than two output times
/// lie at or after `t_rest`.
pub fn residual_after(r: &Response, t_rest: f64, settle_tol: f64, hold_s: f64) -> Option<Residual> {
    let first = r.t.partition_point(|&t| t < t_rest - 1e-12);
    if r.t.len() < first + 2 {
        return None;
    }
    let t = &r.t[first..];
    // about the static equilibrium where the motion rests (under gravity; else zero), or with
    // friction about the rest state the run ends in
    let rest = friction_rest(r, hold_s);
    let offset = match rest {
        Some(FrictionRest::Stuck(o)) => o,
        _ => r.rest_offset.unwrap_or_default(),
    };
    let w_g = |i: usize, k: usize| r.w_g[i][k] - offset.w_g[i];
    let w_tip = |i: usize, k: usize| r.w_tip[i][k] - offset.w_tip[i];
    let dg: Vec<f64> = (first..r.t.len())
        .map(|k| dg_magnitude([w_g(0, k), w_g(1, k), w_g(2, k)]))
        .collect();
    let tip_mean: Vec<f64> = (first..r.t.len())
        .map(|k| ((0..3).map(|i| w_tip(i, k) * w_tip(i, k)).sum::<f64>() / 3.0).sqrt())
        .collect();
    let tip_peak_m = (0..3)
        .flat_map(|i| (first..r.t.len()).map(move |k| (i, k)))
        .fold(0.0f64, |m, (i, k)| m.max(w_tip(i, k).abs()));
    let t_end = *t.last().unwrap_or(&t_rest);
    let last_out = t
        .iter()
        .zip(&dg)
        .filter(|(_, d)| **d > settle_tol)
        .map(|(t, _)| *t)
        .next_back();
    let t_last = last_out.unwrap_or(t_rest);
    let settled = t_end - t_last >= hold_s - 1e-12;
    let decay = envelope_decay(t, &dg, hold_s);
    let tracking = tracking_after(r, first);
    let settle_predicted_s = match decay {
        Some((sigma, a)) if !settled && sigma * (t_end - t_rest) >= DECAY_SEEN => {
            Some(((a - settle_tol.ln()) / sigma).max(t_last))
        }
        _ => None,
    };
    Some(Residual {
        t_rest,
        g_peak_m: dg.iter().fold(0.0, |m: f64, v| m.max(*v)),
        g_rms_m: rms(t, &dg),
        tip_peak_m,
        tip_rms_m: rms(t, &tip_mean),
        settle_s: settled.then_some(t_last),
        settle_tol,
        hold_s,
        t_end,
        decay_per_s: decay.map(|(sigma, _)| sigma),
        settle_predicted_s,
        tracking_peak_m: tracking.map(|(peak, _)| peak),
        tracking_end_m: tracking.map(|(_, end)| end),
        friction_rest: rest,
    })
}

/// The tracking errors `e1..e3` of a servo's run after index `first`: (largest |e_i| from there
/// on, largest |e_i| at the last output time) [m]; `None` without the columns.
fn tracking_after(r: &Response, first: usize) -> Option<(f64, f64)> {
    let cols: Vec<&[f64]> = ["e1", "e2", "e3"].iter().map(|c| r.column(c)).collect::<Option<_>>()?;
    let peak = cols
        .iter()
        .flat_map(|c| c.get(first..).unwrap_or_default())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let end = cols.iter().filter_map(|c| c.last()).fold(0.0f64, |m, v| m.max(v.abs()));
    Some((peak, end))
}

/// The least decay counted as decay: the fitted envelope falls by at least this much of its log
/// (5 %) over the window after `t_rest`; below it a longer run is not predicted to settle.
pub const DECAY_SEEN: f64 = 0.05;

/// The envelope of a vibration `dg` >= 0 sampled at `t` (from `t_rest` on): the largest value in
/// each whole window of length `window` [s] (one period of the first mode), at the time it occurs,
/// over the later half of the windows (at least three), fitted by least squares as
/// `ln dg = a - sigma t`; `(sigma [1/s], a)`. `None` with fewer than
/// three whole windows or a window whose largest value is 0.
pub fn envelope_decay(t: &[f64], dg: &[f64], window: f64) -> Option<(f64, f64)> {
    let (t0, t_end) = (*t.first()?, *t.last()?);
    if window.is_nan() || window <= 0.0 {
        return None;
    }
    let n = ((t_end - t0) / window + 1e-9).floor() as usize;
    if n < 3 {
        return None;
    }
    let mut peaks: Vec<(f64, f64)> = vec![(f64::NAN, 0.0); n];
    for (ti, v) in t.iter().zip(dg) {
        let k = ((ti - t0) / window).floor() as usize;
        if k < n && *v > peaks[k].1 {
            peaks[k] = (*ti, *v);
        }
    }
    if peaks.iter().any(|p| p.1 <= 0.0) {
        return None;
    }
    // the later half of the windows (at least three): higher modes, damped faster, have died
    // out there, and the slowest decay, which decides the settling, is left
    let peaks = &peaks[n - (n / 2).max(3)..];
    let m = peaks.len() as f64;
    let (mx, my) = peaks
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / m, b + y.ln() / m));
    let (sxy, sxx) = peaks.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y.ln() - my), b + (x - mx) * (x - mx))
    });
    let sigma = -sxy / sxx;
    Some((sigma, my + sigma * mx))
}

/// The share of the extrapolated time still to run that the suggested `t_end` adds as a margin.
/// A rate fitted over a short run is too fast when higher modes, damped faster, still take part:
/// on the damped move of `tests/cli.rs` (Kelvin-Voigt, zeta = 0.03 at 4 Hz) 1.5 s give
/// 0.78 1/s against 0.66 1/s over 4.2 s, and the band is entered at 3.94 s predicted, 4.30 s
/// run; 25 % more of the 2.4 s still to run covers it.
pub const PREDICTION_MARGIN: f64 = 0.25;

/// The `t_end` [s] a run that stopped at `t_end` needs to see |dG| settle, from the predicted
/// entry into the band `predicted` [s]: the extrapolation, [`PREDICTION_MARGIN`] more of the time
/// still to run, and the hold `hold` [s].
pub fn suggested_t_end(t_end: f64, predicted: f64, hold: f64) -> f64 {
    predicted + PREDICTION_MARGIN * (predicted - t_end).max(0.0) + hold
}

/// What a report says of a run that did not settle by `t_end` [s]: the decay rate `decay` [1/s]
/// seen after `t_rest` [s] and, when |dG| decays, the `t_end` it needs ([`suggested_t_end`]);
/// when it does not, that a longer run will not help.
pub fn not_settled_text(t_rest: f64, t_end: f64, decay: Option<f64>, predicted: Option<f64>, hold: f64) -> String {
    let head = format!("not settled by t_end = {} s", flexstar_io::output::fmt_display(t_end));
    match (decay, predicted) {
        (Some(sigma), Some(t_in)) => format!(
            "{head}: |dG| decays at {sigma:.3} 1/s (halves every {:.3} s), so at that rate it enters the band \
             near t = {t_in:.2} s; set time.t_end >= {:.2} s to see it settle (that time, {:.0} % more of the time \
             still to run, and one period of the first mode, {hold:.3} s)",
            std::f64::consts::LN_2 / sigma,
            suggested_t_end(t_end, t_in, hold),
            100.0 * PREDICTION_MARGIN
        ),
        (Some(sigma), None) => format!(
            "{head}: |dG| does not decay (fitted rate {sigma:.2e} 1/s over the {:.3} s after t_rest), so a \
             longer t_end will not help: add [damping] (docs/usage.md)",
            t_end - t_rest
        ),
        (None, _) => format!(
            "{head}: fewer than three periods of the first mode ({hold:.3} s) after t_rest, too short to \
             see a decay; set time.t_end >= {:.2} s to measure it",
            t_rest + 3.0 * hold
        ),
    }
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

/// The words a report prints for a settling time: `0.532 s`, or `not settled by t_end`
/// ([`not_settled_text`] says more).
pub fn settle_text(res: &Residual) -> String {
    match res.settle_s {
        Some(t) => format!("{t:.3} s"),
        None => "not settled by t_end".to_string(),
    }
}

/// What a servo's sliders still do after the motion, next to the settling time: `sliders off
/// their reference by up to 0.3 mm after t_rest, 0.075 mm at t_end` (errors `peak`, `end` [m]).
pub fn tracking_text(peak: f64, end: f64) -> String {
    format!(
        "sliders off their reference by up to {} mm after t_rest, {} mm at t_end",
        flexstar_io::output::fmt_sig(peak * 1e3, 3),
        flexstar_io::output::fmt_sig(end * 1e3, 3)
    )
}

/// [`not_settled_text`] of a residual that did not settle; `None` when it settled.
pub fn not_settled_hint(res: &Residual) -> Option<String> {
    res.settle_s.is_none().then(|| {
        not_settled_text(
            res.t_rest,
            res.t_end,
            res.decay_per_s,
            res.settle_predicted_s,
            res.hold_s,
        )
    })
}

/// The sidecar keys ([`ResidualKeys`]) of a residual (`None`: the motion does not rest before `t_end`) measured in the
/// band `settle_tol` [m]. `g_pinned`: the run's modes pin G (the AMM's pinned-free family,
/// `phi(0) = 0`), so it has no residual of G: those keys are null, with `residual_note`.
pub fn sidecar_keys(res: Option<&Residual>, settle_tol: f64, g_pinned: bool) -> ResidualKeys {
    let get = |f: fn(&Residual) -> f64| res.map(f);
    let opt = |f: fn(&Residual) -> Option<f64>| res.and_then(f);
    let tracking = res.filter(|r| r.tracking_peak_m.is_some());
    let mut keys = ResidualKeys {
        t_rest: get(|r| r.t_rest),
        g_peak_m: get(|r| r.g_peak_m),
        g_rms_m: get(|r| r.g_rms_m),
        tip_peak_m: get(|r| r.tip_peak_m),
        tip_rms_m: get(|r| r.tip_rms_m),
        settle_s: opt(|r| r.settle_s),
        settled: res.map(Residual::settled),
        settle_tol: Some(settle_tol),
        settle_hold_s: get(|r| r.hold_s),
        g_decay_per_s: opt(|r| r.decay_per_s),
        settle_predicted_s: opt(|r| r.settle_predicted_s),
        tracking_peak_m: tracking.map(|r| r.tracking_peak_m),
        tracking_end_m: tracking.map(|r| r.tracking_end_m),
        residual_note: None,
        dwells: None,
        friction: res.and_then(|r| r.friction_rest).map(friction_keys),
    };
    if g_pinned && res.is_some() {
        keys.g_peak_m = None;
        keys.g_rms_m = None;
        keys.settle_s = None;
        keys.settled = None;
        keys.g_decay_per_s = None;
        keys.settle_predicted_s = None;
        keys.residual_note = Some("G is pinned in this family".into());
    }
    keys
}

/// The sidecar's `residual_friction` of a run with friction (`docs/friction.md` 5).
fn friction_keys(rest: FrictionRest) -> flexstar_model::FrictionRestKeys {
    match rest {
        FrictionRest::Stuck(o) => flexstar_model::FrictionRestKeys {
            rest_g_m: Some(dg_magnitude(o.w_g)),
            rest_w_g_m: Some(o.w_g),
            slipping_sleeve: None,
            slipping_t: None,
        },
        FrictionRest::Slipping { sleeve, t } => flexstar_model::FrictionRestKeys {
            rest_g_m: None,
            rest_w_g_m: None,
            slipping_sleeve: Some(sleeve),
            slipping_t: Some(t),
        },
    }
}

/// What a report adds for a run with friction (`docs/friction.md` 5): the rest offset the
/// residual is measured about, or the sleeve that keeps the run from settling.
pub fn friction_rest_text(keys: &flexstar_model::FrictionRestKeys) -> String {
    match (keys.rest_g_m, keys.slipping_sleeve, keys.slipping_t) {
        (Some(g), _, _) => format!("about the rest state friction holds (|dG| = {g:.3e} m, every sleeve stuck)"),
        (None, Some(i), Some(t)) => format!(
            "sleeve {i} still slips at t = {t:.3} s: measured about the rest state without friction, to which the \
             star still relaxes"
        ),
        _ => "no rest state".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sidecar keys of a residual, as written ([`flexstar_model::sidecar::ResidualKeys`]).
    fn keys_of(res: Option<&Residual>, tol: f64, pinned: bool) -> serde_json::Value {
        serde_json::to_value(sidecar_keys(res, tol, pinned)).unwrap()
    }

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
    fn a_run_cut_short_predicts_the_t_end_at_which_it_settles() {
        // a damped sine |dG| = A exp(-s (t - t_rest)) |sin(w t)| along one axis: the fitted rate
        // is s, and the predicted entry into the band is where the envelope crosses it,
        // t* = t_rest + ln(A / tol) / s (analytic), to within a period
        let (a, s, tol, t_rest, f) = (1e-3, 0.8, 1e-4, 0.5, 4.0);
        let w = 2.0 * std::f64::consts::PI * f;
        let env = |t: f64| if t < t_rest { a } else { a * (-s * (t - t_rest)).exp() };
        let ts = grid(2.5, 1e-3);
        let r = response(&ts, |t| [env(t) * (w * t).sin(), 0.0], |_| 0.0);
        let res = residual_after(&r, t_rest, tol, 1.0 / f).unwrap();
        assert!(!res.settled());
        let sigma = res.decay_per_s.unwrap();
        assert!((sigma - s).abs() < 0.01 * s, "rate {sigma} vs {s}");
        let t_star = t_rest + (a / tol).ln() / s;
        let predicted = res.settle_predicted_s.unwrap();
        assert!((predicted - t_star).abs() < 1.0 / f, "{predicted} vs {t_star}");
        let hint = not_settled_hint(&res).unwrap();
        assert!(
            hint.contains("not settled by t_end = 2.5 s") && hint.contains("decays at 0.80"),
            "{hint}"
        );
        let suggested = suggested_t_end(2.5, predicted, 0.25);
        assert!((suggested - (predicted + 0.25 * (predicted - 2.5) + 0.25)).abs() < 1e-12);
        assert!(hint.contains(&format!("time.t_end >= {suggested:.2}")), "{hint}");
        // and a run to that t_end settles, within a period of the predicted time
        let ts = grid(suggested, 1e-3);
        let r = response(&ts, |t| [env(t) * (w * t).sin(), 0.0], |_| 0.0);
        let long = residual_after(&r, t_rest, tol, 1.0 / f).unwrap();
        let settle = long.settle_s.expect("settles with the predicted t_end");
        assert!((settle - t_star).abs() < 1.0 / f, "{settle} vs {t_star}");
        assert!(not_settled_hint(&long).is_none());
        // undamped: no decay, the hint says a longer run will not help
        let r = response(&ts, |t| [a * (w * t).sin(), 0.0], |_| 0.0);
        let flat = residual_after(&r, t_rest, tol, 1.0 / f).unwrap();
        assert!(flat.decay_per_s.unwrap().abs() < 1e-3 && flat.settle_predicted_s.is_none());
        assert!(not_settled_hint(&flat).unwrap().contains("add [damping]"));
    }

    #[test]
    fn a_servo_run_reports_its_sliders_tracking_error_after_the_motion() {
        // e1 = 3e-4 exp(-20 (t - 0.5)) after t_rest = 0.5 (1 mm before), e2 = -7.5e-5, e3 = 0: the
        // peak after t_rest is e1 at t_rest, the largest at t_end the constant e2
        let ts = grid(1.0, 1e-3);
        let mut r = response(&ts, |_| [0.0, 0.0], |_| 0.0);
        let e1: Vec<f64> = ts
            .iter()
            .map(|t| {
                if *t < 0.5 {
                    1e-3
                } else {
                    3e-4 * (-20.0 * (t - 0.5)).exp()
                }
            })
            .collect();
        r.set_extra(
            &["e1", "e2", "e3"],
            vec![e1, vec![-7.5e-5; ts.len()], vec![0.0; ts.len()]],
        );
        let res = residual_after(&r, 0.5, 1e-4, 0.1).unwrap();
        assert_eq!(res.tracking_peak_m, Some(3e-4));
        assert_eq!(res.tracking_end_m, Some(7.5e-5));
        let keys = keys_of(Some(&res), 1e-4, false);
        assert_eq!(keys["residual_tracking_end_m"], 7.5e-5);
        assert_eq!(
            tracking_text(3e-4, 7.5e-5),
            "sliders off their reference by up to 0.3 mm after t_rest, 0.075 mm at t_end"
        );
        // a run without servo columns has neither value nor key
        let plain = residual_after(&response(&ts, |_| [0.0, 0.0], |_| 0.0), 0.5, 1e-4, 0.1).unwrap();
        assert!(plain.tracking_peak_m.is_none());
        assert!(keys_of(Some(&plain), 1e-4, false)
            .get("residual_tracking_end_m")
            .is_none());
    }

    #[test]
    fn a_residual_below_the_band_settles_at_t_rest_and_a_late_rest_has_none() {
        let ts = grid(1.0, 1e-3);
        let r = response(&ts, |t| [1e-5 * t, 0.0], |_| 0.0);
        let res = residual_after(&r, 0.4, 1e-4, 0.1).unwrap();
        assert_eq!(res.settle_s, Some(0.4));
        assert!(residual_after(&r, 1.0, 1e-4, 0.1).is_none());
        let keys = keys_of(None, 1e-4, false);
        assert!(keys["t_rest"].is_null() && keys["settled"].is_null() && keys["settle_tol"] == 1e-4);
        let keys = keys_of(Some(&res), 1e-4, false);
        assert_eq!(keys["settle_s"], 0.4);
        assert_eq!(keys["settled"], true);
        let keys = keys_of(Some(&res), 1e-4, true);
        assert!(keys["settle_s"].is_null() && keys["residual_G_peak_m"].is_null());
        assert_eq!(keys["residual_note"], "G is pinned in this family");
    }

    /// `docs/as-built.md` 5.5: under gravity the residual is measured about the static
    /// equilibrium where the motion rests: a vibration about a sag has the vibration's peak, and
    /// a sag alone settles at t_rest.
    #[test]
    fn under_gravity_the_residual_is_measured_about_the_rest_sag() {
        let ts = grid(1.0, 1e-3);
        let sag = [2e-4, -3e-3];
        let w = 2.0 * std::f64::consts::PI * 4.0;
        let e_w = frames(0.3);
        let offset = flexstar_model::RestOffset {
            t_rest: 0.4,
            w_g: e_w.map(|e| sag[0] * e[0] + sag[1] * e[1]),
            w_tip: [-2e-3, 0.0, 0.0],
        };
        let mut r = response(&ts, |t| [sag[0] + 5e-4 * (w * t).cos(), sag[1]], |_| -2e-3);
        r.rest_offset = Some(offset);
        let res = residual_after(&r, 0.4, 1e-4, 0.1).unwrap();
        assert!((res.g_peak_m - 5e-4).abs() < 1e-9 && res.tip_peak_m < 1e-15, "{res:?}");
        let mut still = response(&ts, |_| sag, |_| -2e-3);
        still.rest_offset = Some(offset);
        let res = residual_after(&still, 0.4, 1e-4, 0.1).unwrap();
        assert!(res.g_peak_m < 1e-15 && res.settle_s == Some(0.4), "{res:?}");
    }
}
