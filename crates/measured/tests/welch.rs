//! Welch's PSD (`docs/measured.md` section 2) against references that do not use it: Parseval
//! (a sinusoid's density integrates to its variance A^2 / 2, a mixture's to the sum), white
//! noise's flat level `sigma^2 / (fs / 2)` and a peak at the sinusoid's frequency.

use flexstar_measured::welch::{welch, WelchOptions};
use flexstar_model::sensors::daq::Normal;

const FS: f64 = 1000.0;

fn sampled(n: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
    (0..n).map(|k| f(k as f64 / FS)).collect()
}

#[test]
fn a_sinusoid_s_density_integrates_to_its_variance_and_peaks_at_its_frequency() {
    let (a, f0) = (0.8, 37.3);
    // an offset of 9.81 (gravity on an accelerometer axis): the mean is no power
    let x = sampled(4000, |t| 9.81 + a * (2.0 * std::f64::consts::PI * f0 * t).sin());
    let psd = welch(&x, FS, &WelchOptions::default(), "x").unwrap();
    assert_eq!((psd.segment, psd.segments), (1000, 7));
    let variance = a * a / 2.0;
    assert!(
        (psd.power() / variance - 1.0).abs() < 0.01,
        "{} vs {variance}",
        psd.power()
    );
    let peak = psd.peak_above(0.0).unwrap();
    assert!((peak - f0).abs() <= psd.df() / 2.0, "peak {peak} Hz, df {}", psd.df());
    // two tones: the integrals over each one's band are their own variances
    let b = 0.3;
    let y = sampled(8192, |t| {
        a * (2.0 * std::f64::consts::PI * 37.3 * t).sin() + b * (2.0 * std::f64::consts::PI * 151.0 * t).cos()
    });
    let opts = WelchOptions {
        segment: Some(1024),
        overlap: 0.5,
    };
    let psd = welch(&y, FS, &opts, "y").unwrap();
    let band = |lo: f64, hi: f64| -> f64 {
        psd.f
            .iter()
            .zip(&psd.p)
            .filter(|(f, _)| **f >= lo && **f <= hi)
            .map(|(_, p)| p)
            .sum::<f64>()
            * psd.df()
    };
    assert!((band(20.0, 60.0) / (a * a / 2.0) - 1.0).abs() < 0.01);
    assert!((band(130.0, 170.0) / (b * b / 2.0) - 1.0).abs() < 0.01);
}

#[test]
fn white_noise_has_the_flat_level_sigma_squared_over_half_the_rate() {
    let sigma = 0.05;
    let mut n = Normal::new(11, 0);
    let x: Vec<f64> = (0..1 << 16).map(|_| sigma * n.draw()).collect();
    let psd = welch(
        &x,
        FS,
        &WelchOptions {
            segment: Some(256),
            overlap: 0.5,
        },
        "noise",
    )
    .unwrap();
    let level = sigma * sigma / (FS / 2.0);
    // interior bins (the zero bin lost the mean of each segment, the Nyquist bin is folded once)
    let inner = &psd.p[2..psd.p.len() - 2];
    let mean = inner.iter().sum::<f64>() / inner.len() as f64;
    assert!((mean / level - 1.0).abs() < 0.02, "{mean} vs {level}");
    // flat: the lower and the upper half agree within the estimate's scatter
    let half = inner.len() / 2;
    let lower = inner[..half].iter().sum::<f64>() / half as f64;
    let upper = inner[half..].iter().sum::<f64>() / (inner.len() - half) as f64;
    assert!((lower / upper - 1.0).abs() < 0.03, "{lower} vs {upper}");
    // each bin's scatter: 511 segments with half overlap, about 1/sqrt(511 / 1.06) = 4.6 %
    let spread = (inner.iter().map(|p| (p / mean - 1.0).powi(2)).sum::<f64>() / inner.len() as f64).sqrt();
    assert!(spread < 0.07, "scatter {spread}");
}
