//! The noise level of a recorded channel, estimated from the recording alone
//! (`docs/measured.md` 4.2, Eqs. LS2-LS3): the robust spread of its fourth differences.
//!
//! White noise of standard deviation sigma has fourth differences of variance
//! `C(8, 4) sigma^2 = 70 sigma^2`; a smooth signal's fourth difference is `h^4` times its fourth
//! derivative, a sinusoid of frequency f is scaled by `(2 sin(pi f h))^4` (Eq. LS3): 1e-4 at a
//! tenth of the Nyquist frequency. The median of the absolute values, divided by 0.6745 (the
//! median of |z| for a standard normal z), ignores the few samples where a fast transient leaks.

/// The fourth-difference order of Eq. LS2.
pub const ORDER: usize = 4;
/// `C(2 ORDER, ORDER)`: the variance of the fourth difference of unit white noise.
const VARIANCE_GAIN: f64 = 70.0;
/// The median of |z|, z standard normal.
const MEDIAN_ABS_NORMAL: f64 = 0.674_489_750_196_081_7;
/// A noise level below this share of the channel's RMS is raised to it (a noiseless recording,
/// a channel of model output): weights stay finite.
pub const FLOOR: f64 = 1e-9;

/// Eq. LS2: the noise standard deviation of the samples `x` (uniformly sampled), in their unit;
/// `None` for fewer than `ORDER + 1` samples. Never below [`FLOOR`] times the RMS of `x`; 1 for a
/// channel that is zero throughout (it then carries nothing and weighs nothing).
pub fn level(x: &[f64]) -> Option<f64> {
    if x.len() <= ORDER {
        return None;
    }
    let mut d: Vec<f64> = x
        .windows(ORDER + 1)
        .map(|w| (w[0] - 4.0 * w[1] + 6.0 * w[2] - 4.0 * w[3] + w[4]).abs())
        .collect();
    let mid = d.len() / 2;
    let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    let sigma = *median / MEDIAN_ABS_NORMAL / VARIANCE_GAIN.sqrt();
    let rms = rms(x);
    if rms == 0.0 {
        return Some(1.0);
    }
    Some(sigma.max(FLOOR * rms))
}

/// Root mean square of `x` (0 for none).
pub fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Eq. LS17: the one-sided power spectral density [unit^2/Hz] of white noise of standard
/// deviation `sigma` sampled at `fs` [Hz]: `2 sigma^2 / fs`, flat from 0 to `fs / 2`, so that it
/// integrates to `sigma^2` (Parseval).
pub fn white_psd(sigma: f64, fs: f64) -> f64 {
    2.0 * sigma * sigma / fs
}

/// Eq. LS3: the gain of the fourth difference on a sinusoid of frequency `f` [Hz] sampled every
/// `h` [s], relative to its amplitude.
pub fn leakage(f: f64, h: f64) -> f64 {
    (2.0 * (std::f64::consts::PI * f * h).sin()).powi(ORDER as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform draw in (0, 1] from a SplitMix64 stream.
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// Box-Muller normal draws.
    fn normal(state: &mut u64) -> f64 {
        let (u1, u2) = (uniform(state), uniform(state));
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// A decaying 3 Hz oscillation of amplitude 1 plus a 30 Hz one of 0.3 at 1 kHz, with white
    /// noise of 0.02 or 0.002: the estimate finds the noise within its sampling spread (the
    /// median of 4000 |differences| has a relative spread of about 2 %); by Eq. LS3 the 30 Hz
    /// part leaks 1.25e-3 of 0.3 = 3.7e-4 into differences of spread 8.4 sigma >= 0.017.
    #[test]
    fn finds_white_noise_under_a_smooth_signal() {
        let h = 1e-3;
        let mut seed = 7u64;
        for sigma in [0.02, 0.002] {
            let x: Vec<f64> = (0..4000)
                .map(|k| {
                    let t = k as f64 * h;
                    let two_pi = 2.0 * std::f64::consts::PI;
                    (-0.5 * t).exp() * (two_pi * 3.0 * t).sin()
                        + 0.3 * (two_pi * 30.0 * t).cos()
                        + sigma * normal(&mut seed)
                })
                .collect();
            let est = level(&x).unwrap();
            assert!((est / sigma - 1.0).abs() < 0.06, "sigma {sigma}: estimated {est}");
        }
        assert!((leakage(30.0, h) - 1.25e-3).abs() < 1e-5 && leakage(3.0, h) < 1e-6);
        assert_eq!(level(&[1.0; 4]), None);
        assert_eq!(level(&[0.0; 10]), Some(1.0));
        // noiseless: the floor
        let smooth: Vec<f64> = (0..100).map(|k| 2.0 + k as f64).collect();
        assert!(level(&smooth).unwrap() > 0.0);
    }
}
