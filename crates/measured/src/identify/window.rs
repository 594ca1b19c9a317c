//! The free-decay window of a record (`docs/measured.md` 3.1, 3.5): the samples and times
//! checked, the sampling interval, the samples from `t_start` to `t_end`.

use crate::error::MeasuredError;

use super::IdentifyOptions;

/// Largest relative deviation of one time step from the mean step (3.5): room for times written
/// with a few significant digits, far below a missing sample (a step of 2 dt).
pub(crate) const STEP_TOLERANCE: f64 = 1e-3;

/// A window needs at least this many samples per unit of the largest ERA order (3.5).
pub(crate) const SAMPLES_PER_ORDER: usize = 4;

/// The samples of the free decay.
#[derive(Debug, Clone)]
pub(crate) struct Window {
    /// Sampling interval [s] (the mean step of the record).
    pub dt: f64,
    /// Time of the window's first sample [s]: the origin of Eq. I1.
    pub t0: f64,
    /// The channels over the window, one vector per channel, in the channel's own unit.
    pub y: Vec<Vec<f64>>,
}

impl Window {
    /// Samples per channel.
    pub fn len(&self) -> usize {
        self.y[0].len()
    }

    /// Each channel's RMS about its mean over the window, in its unit (the first weights, 3.4;
    /// positive: a constant channel is refused).
    pub fn rms(&self) -> Vec<f64> {
        self.y
            .iter()
            .map(|y| {
                let n = y.len() as f64;
                let mean = y.iter().sum::<f64>() / n;
                (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt()
            })
            .collect()
    }
}

/// The window of `channels` (each sampled at `t` [s]) that `opts` asks for, after the checks of
/// 3.5: equal lengths, finite uniform increasing times, finite non-constant samples in the
/// window, enough of them for the largest order.
pub(crate) fn select(t: &[f64], channels: &[&[f64]], opts: &IdentifyOptions) -> Result<Window, MeasuredError> {
    check_lengths(t, channels)?;
    let dt = uniform_step(t)?;
    let (first, last) = window_range(t, opts)?;
    let n = last - first + 1;
    let needed = SAMPLES_PER_ORDER * opts.orders[1];
    if n < needed {
        return Err(MeasuredError::input(
            "window",
            format!(
                "{n} samples from t = {} s to {} s, fewer than {needed} ({SAMPLES_PER_ORDER} x the largest order {}): \
                 a longer window or smaller orders",
                t[first], t[last], opts.orders[1]
            ),
        ));
    }
    let y = channels
        .iter()
        .enumerate()
        .map(|(c, ch)| window_channel(c, &ch[first..=last], &t[first..=last]))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Window { dt, t0: t[first], y })
}

/// At least one channel, each as long as `t`, and at least two samples.
fn check_lengths(t: &[f64], channels: &[&[f64]]) -> Result<(), MeasuredError> {
    if channels.is_empty() {
        return Err(MeasuredError::input("channels", "none given"));
    }
    if t.len() < 2 {
        return Err(MeasuredError::input(
            "t",
            format!("{} samples, at least 2 needed", t.len()),
        ));
    }
    for (c, ch) in channels.iter().enumerate() {
        if ch.len() != t.len() {
            return Err(MeasuredError::input(
                format!("channel {c}"),
                format!("{} samples, but t has {}", ch.len(), t.len()),
            ));
        }
    }
    Ok(())
}

/// The mean step of finite, increasing, uniformly spaced times (within [`STEP_TOLERANCE`]).
fn uniform_step(t: &[f64]) -> Result<f64, MeasuredError> {
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(MeasuredError::input(
            format!("t[{k}]"),
            format!("not finite ({})", t[k]),
        ));
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if dt <= 0.0 {
        return Err(MeasuredError::input("t", "times do not increase"));
    }
    for k in 1..t.len() {
        let step = t[k] - t[k - 1];
        if (step - dt).abs() > STEP_TOLERANCE * dt {
            return Err(MeasuredError::input(
                format!("t[{k}] = {} s", t[k]),
                format!(
                    "sampling not uniform: step {step} s against the mean {dt} s (more than {STEP_TOLERANCE} of it off)"
                ),
            ));
        }
    }
    Ok(dt)
}

/// Indices of the first and the last sample within `[t_start, t_end]`.
fn window_range(t: &[f64], opts: &IdentifyOptions) -> Result<(usize, usize), MeasuredError> {
    let (t_lo, t_hi) = (t[0], t[t.len() - 1]);
    let start = opts.t_start.unwrap_or(t_lo);
    let end = opts.t_end.unwrap_or(t_hi);
    for (key, v) in [("t_start", start), ("t_end", end)] {
        if !v.is_finite() {
            return Err(MeasuredError::input(key, format!("not finite ({v})")));
        }
    }
    if start >= end || start > t_hi || end < t_lo {
        return Err(MeasuredError::input(
            "window",
            format!("[t_start, t_end] = [{start}, {end}] s holds no samples of the record [{t_lo}, {t_hi}] s"),
        ));
    }
    let first = t.partition_point(|&x| x < start);
    let last = t.partition_point(|&x| x <= end) - 1;
    Ok((first, last))
}

/// One channel's window: finite samples, not constant.
fn window_channel(c: usize, y: &[f64], t: &[f64]) -> Result<Vec<f64>, MeasuredError> {
    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
        return Err(MeasuredError::input(
            format!("channel {c} at t = {} s", t[k]),
            format!("sample not finite ({})", y[k]),
        ));
    }
    if y.iter().all(|&v| v == y[0]) {
        return Err(MeasuredError::input(
            format!("channel {c}"),
            "constant over the window: it carries no mode (an encoder of held sliders?)",
        ));
    }
    Ok(y.to_vec())
}
