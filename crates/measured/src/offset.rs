//! The recording's clock against the run's, estimated by cross-correlation (`docs/measured.md`
//! 1.3, Eq. M3): the shift that best correlates the recorded channels with the run's, searched
//! over the lags `k h` of the run's sample step h within a bounded window, then refined between
//! the neighbouring lags.

use flexstar_model::sensors::daq::interpolate;

/// Channels sampled on one clock: times [s] (increasing) and one value slice per channel.
#[derive(Debug, Clone)]
pub struct Channels<'a> {
    pub t: &'a [f64],
    pub values: Vec<&'a [f64]>,
}

/// The lags searched: `[-max_lag, max_lag]` [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagWindow {
    pub max_lag: f64,
}

/// The estimate of Eq. M3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lag {
    /// The shift [s] to add to the recording's times.
    pub offset: f64,
    /// The mean correlation coefficient of the channels at that shift (1: a perfect match).
    pub correlation: f64,
    /// The step h [s] of the lag grid (the run's median sample step).
    pub step: f64,
}

/// The shortest overlap of recording and run for a lag to be scored, as a fraction of the
/// run's span.
const MIN_OVERLAP: f64 = 0.5;

/// Golden-section iterations of the refinement: the bracket of two steps shrinks by
/// 0.618^60, far below any clock's resolution.
const REFINE_ITERATIONS: usize = 60;

/// Eq. M3: the shift `delta` [s] that maximises the mean over channels of the correlation
/// coefficient between the recording `r(tau_k)` and the run's channel `y(tau_k + delta)`
/// (interpolated linearly), over the recorded samples whose shifted time lies within the run,
/// an overlap of at least half the run's span. The lags `k h`, |k h| <= `max_lag`, are scored
/// first; the best one is refined by golden-section search between its neighbours. Errors: no
/// channel varies on both sides, no lag keeps half the run, or the best lag lies at the edge
/// of the window (the true one may lie beyond it).
pub fn estimate_offset(recorded: &Channels<'_>, run: &Channels<'_>, window: LagWindow) -> Result<Lag, String> {
    let h = median_step(run.t).ok_or("the run has fewer than two sensor samples")?;
    if recorded.values.is_empty() {
        return Err("no recorded column is a column of the run".into());
    }
    let k_max = (window.max_lag / h).floor() as i64;
    let scores: Vec<(i64, f64)> = (-k_max..=k_max)
        .filter_map(|k| score(recorded, run, k as f64 * h).map(|c| (k, c)))
        .collect();
    let &(best, _) = scores
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| no_lag_message(window.max_lag))?;
    if best.abs() == k_max && k_max > 0 {
        return Err(format!(
            "the best lag, {} s, lies at the edge of the window +-{} s (measured.max_lag): the clocks may \
             differ by more; widen max_lag or give the offset",
            best as f64 * h,
            window.max_lag
        ));
    }
    let offset = refine(
        |d| score(recorded, run, d),
        (best as f64 - 1.0) * h,
        (best as f64 + 1.0) * h,
    );
    let correlation = score(recorded, run, offset).unwrap_or(f64::NAN);
    Ok(Lag {
        offset,
        correlation,
        step: h,
    })
}

/// The message when no lag keeps enough of the run.
fn no_lag_message(max_lag: f64) -> String {
    format!(
        "at no lag within +-{max_lag} s does the recording overlap half of the run's span with a varying \
         channel: the spans may not overlap, or every channel is constant"
    )
}

/// The mean correlation coefficient at the shift `delta` [s] between the recorded samples
/// `r_c(tau_k)` and the run interpolated at `tau_k + delta`, over the recorded samples whose
/// shifted time lies within the run; `None` when that overlap spans less than [`MIN_OVERLAP`]
/// of the run or no channel varies on both sides. The run, not the recording, is interpolated:
/// interpolating a noisy recording between its samples would lower its noise's variance (by
/// `w^2 + (1 - w)^2` at the fraction w) and pull the estimate towards half-sample lags.
fn score(recorded: &Channels<'_>, run: &Channels<'_>, delta: f64) -> Option<f64> {
    let (t0, t1) = (run.t[0], run.t[run.t.len() - 1]);
    let lo = recorded.t.partition_point(|&x| x + delta < t0);
    let hi = recorded.t.partition_point(|&x| x + delta <= t1);
    if hi < lo + 3 || recorded.t[hi - 1] - recorded.t[lo] < MIN_OVERLAP * (t1 - t0) {
        return None;
    }
    let at: Vec<f64> = recorded.t[lo..hi].iter().map(|x| x + delta).collect();
    let coefficients: Vec<f64> = recorded
        .values
        .iter()
        .zip(&run.values)
        .filter_map(|(r, y)| pearson(&r[lo..hi], &interpolate(run.t, y, &at)))
        .collect();
    (!coefficients.is_empty()).then(|| coefficients.iter().sum::<f64>() / coefficients.len() as f64)
}

/// The correlation coefficient of two equally long series; `None` when either is constant.
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        let (da, db) = (a - mx, b - my);
        sxy += da * db;
        sxx += da * da;
        syy += db * db;
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// The maximum of `f` on `[a, b]` by golden-section search (a lag whose overlap is too short
/// scores minus infinity).
fn refine(f: impl Fn(f64) -> Option<f64>, mut a: f64, mut b: f64) -> f64 {
    let g = |x: f64| f(x).unwrap_or(f64::NEG_INFINITY);
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (g(c), g(d));
    for _ in 0..REFINE_ITERATIONS {
        if fc >= fd {
            (b, d, fd) = (d, c, fc);
            c = b - r * (b - a);
            fc = g(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + r * (b - a);
            fd = g(d);
        }
    }
    0.5 * (a + b)
}

/// The median of the steps of `t` [s], if it has two samples.
pub fn median_step(t: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    Some(steps[steps.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chirp recorded on a clock 7.3 ms behind the run's, at another rate: the estimate
    /// recovers the shift to a small fraction of the run's step.
    #[test]
    fn a_known_shift_is_recovered_between_samples() {
        let signal = |t: f64| (2.0 * std::f64::consts::PI * (3.0 + 20.0 * t) * t).sin() * (-t).exp();
        let run_t: Vec<f64> = (0..=1000).map(|k| k as f64 * 1e-3).collect();
        let run_y: Vec<f64> = run_t.iter().map(|&t| signal(t)).collect();
        let shift = 7.3e-3;
        // the recording's clock reads t - shift at run time t; sampled at 1.6 kHz from -0.05 s
        let rec_t: Vec<f64> = (0..=1700).map(|k| -0.05 + k as f64 / 1600.0).collect();
        let rec_y: Vec<f64> = rec_t.iter().map(|&s| signal(s + shift)).collect();
        let lag = estimate_offset(
            &Channels {
                t: &rec_t,
                values: vec![&rec_y],
            },
            &Channels {
                t: &run_t,
                values: vec![&run_y],
            },
            LagWindow { max_lag: 0.05 },
        )
        .unwrap();
        assert!((lag.offset - shift).abs() < 0.05e-3, "{lag:?}");
        assert!(lag.correlation > 0.999, "{lag:?}");
        // a window that stops short of the shift: refused, naming the edge
        let e = estimate_offset(
            &Channels {
                t: &rec_t,
                values: vec![&rec_y],
            },
            &Channels {
                t: &run_t,
                values: vec![&run_y],
            },
            LagWindow { max_lag: 0.004 },
        )
        .unwrap_err();
        assert!(e.contains("edge") && e.contains("max_lag"), "{e}");
    }

    #[test]
    fn pearson_of_a_scaled_copy_is_one_and_of_a_negated_minus_one() {
        let x = [1.0, 3.0, 2.0, 5.0];
        let y: Vec<f64> = x.iter().map(|v| 2.5 * v + 1.0).collect();
        let z: Vec<f64> = x.iter().map(|v| -v).collect();
        assert!((pearson(&x, &y).unwrap() - 1.0).abs() < 1e-15);
        assert!((pearson(&x, &z).unwrap() + 1.0).abs() < 1e-15);
        assert_eq!(pearson(&x, &[1.0; 4]), None);
    }
}
