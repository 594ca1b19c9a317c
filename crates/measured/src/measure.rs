//! The error of a model's channel against the recorded one (`docs/measured.md` 1.5): the EVP of
//! Eq. M5 (the paper's Eq. 45 with the recording as the reference) and the RMS of Eq. M6.

use flexstar_numerics::measures::evp;
use serde::Serialize;

/// Eqs. M5 and M6 of one channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChannelError {
    /// `int |model - measured| dt / int |measured| dt * 100` [%]; `None` where the recorded
    /// channel is zero throughout.
    pub evp: Option<f64>,
    /// `sqrt(int (model - measured)^2 dt / T)` [the channel's unit].
    pub rms: f64,
}

/// Eqs. M5, M6 of `model` against `measured`, both at the times `t` [s] (increasing).
pub fn channel_error(t: &[f64], model: &[f64], measured: &[f64]) -> ChannelError {
    let diff: Vec<f64> = model.iter().zip(measured).map(|(a, b)| a - b).collect();
    ChannelError {
        evp: evp(t, model, measured),
        rms: rms(t, &diff),
    }
}

/// Eq. M6: the root mean square of `y` over the times `t` [s] by the trapezoidal rule; 0 for
/// fewer than two samples.
pub fn rms(t: &[f64], y: &[f64]) -> f64 {
    let span = match (t.first(), t.last()) {
        (Some(a), Some(b)) if b > a => b - a,
        _ => return 0.0,
    };
    let integral: f64 = t
        .windows(2)
        .zip(y.windows(2))
        .map(|(tt, yy)| 0.5 * (tt[1] - tt[0]) * (yy[0] * yy[0] + yy[1] * yy[1]))
        .sum();
    (integral / span).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_of_a_sine_and_evp_of_a_scaled_copy() {
        // over whole periods the RMS of A sin is A / sqrt 2
        let t: Vec<f64> = (0..=2000).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|x| 3.0 * (2.0 * std::f64::consts::PI * 5.0 * x).sin())
            .collect();
        assert!((rms(&t, &y) - 3.0 / 2f64.sqrt()).abs() < 1e-6);
        let m: Vec<f64> = y.iter().map(|v| 1.2 * v).collect();
        let e = channel_error(&t, &m, &y);
        assert!((e.evp.unwrap() - 20.0).abs() < 1e-9);
        assert!((e.rms - 0.2 * 3.0 / 2f64.sqrt()).abs() < 1e-6);
        assert_eq!(channel_error(&t, &y, &vec![0.0; t.len()]).evp, None);
    }
}
