//! Welch's power spectral density (`docs/measured.md` section 2, Eqs. W1-W4): a signal cut into
//! segments of L samples overlapping by half, each mean-removed and weighted by a periodic Hann
//! window, their periodograms averaged and scaled one-sided, in unit^2/Hz.

use rustfft::num_complex::Complex;
use rustfft::FftPlannerScalar;

use crate::error::MeasuredError;

/// The fewest samples a segment may have.
pub const MIN_SEGMENT: usize = 8;

/// How the signal is cut (Eq. W1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WelchOptions {
    /// Samples per segment L; `None`: a quarter of the signal ([`default_segment`]).
    pub segment: Option<usize>,
    /// Overlap of consecutive segments, a fraction in `[0, 1)`; 0.5 by default.
    pub overlap: f64,
}

impl Default for WelchOptions {
    fn default() -> Self {
        WelchOptions {
            segment: None,
            overlap: 0.5,
        }
    }
}

/// A one-sided power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Frequencies `k fs / L` [Hz], k = 0 .. L/2.
    pub f: Vec<f64>,
    /// The density at each frequency [unit^2/Hz] (Eq. W3).
    pub p: Vec<f64>,
    /// Samples per segment L.
    pub segment: usize,
    /// Segments averaged K.
    pub segments: usize,
}

impl Psd {
    /// The frequency step `fs / L` [Hz].
    pub fn df(&self) -> f64 {
        self.f.get(1).copied().unwrap_or(0.0)
    }

    /// The frequency [Hz] of the largest density above `f_min` [Hz], if any.
    pub fn peak_above(&self, f_min: f64) -> Option<f64> {
        self.f
            .iter()
            .zip(&self.p)
            .filter(|(f, _)| **f > f_min)
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(f, _)| *f)
    }

    /// The integral of the density over frequency (the rectangle rule on the bins): the
    /// signal's variance by Parseval (Eq. W4).
    pub fn power(&self) -> f64 {
        self.p.iter().sum::<f64>() * self.df()
    }
}

/// The default segment length for `n` samples: `n / 4` (with half overlap, 7 segments), at
/// least [`MIN_SEGMENT`].
pub fn default_segment(n: usize) -> usize {
    (n / 4).max(MIN_SEGMENT)
}

/// Welch's estimate of the one-sided PSD of `x` sampled at `fs` [Hz] (Eqs. W1-W3). `what`
/// names the signal in errors: fewer samples than a segment, a segment below [`MIN_SEGMENT`],
/// an overlap outside `[0, 1)`, a non-finite sample or rate.
pub fn welch(x: &[f64], fs: f64, opts: &WelchOptions, what: &str) -> Result<Psd, MeasuredError> {
    let l = opts.segment.unwrap_or_else(|| default_segment(x.len()));
    check(x, fs, l, opts.overlap, what)?;
    let hop = ((l as f64) * (1.0 - opts.overlap)).round().max(1.0) as usize;
    let window = hann(l);
    let w2: f64 = window.iter().map(|w| w * w).sum();
    let fft = FftPlannerScalar::new().plan_fft_forward(l);
    let half = l / 2;
    let mut sum = vec![0.0; half + 1];
    let mut segments = 0;
    let mut buf = vec![Complex::new(0.0, 0.0); l];
    for start in (0..=x.len() - l).step_by(hop) {
        windowed(&x[start..start + l], &window, &mut buf);
        fft.process(&mut buf);
        for (k, s) in sum.iter_mut().enumerate() {
            *s += buf[k].norm_sqr();
        }
        segments += 1;
    }
    let p = sum
        .iter()
        .enumerate()
        .map(|(k, s)| one_sided(k, l) * s / (segments as f64 * fs * w2))
        .collect();
    Ok(Psd {
        f: (0..=half).map(|k| k as f64 * fs / l as f64).collect(),
        p,
        segment: l,
        segments,
    })
}

/// The periodic Hann window of L samples, `w_n = (1 - cos(2 pi n / L)) / 2` (Eq. W2).
pub fn hann(l: usize) -> Vec<f64> {
    (0..l)
        .map(|n| 0.5 * (1.0 - (2.0 * std::f64::consts::PI * n as f64 / l as f64).cos()))
        .collect()
}

/// Eq. W1's segment: its mean removed, times the window, into `buf`.
fn windowed(seg: &[f64], window: &[f64], buf: &mut [Complex<f64>]) {
    let mean = seg.iter().sum::<f64>() / seg.len() as f64;
    for ((b, x), w) in buf.iter_mut().zip(seg).zip(window) {
        *b = Complex::new((x - mean) * w, 0.0);
    }
}

/// The one-sided fold of Eq. W3: bins 1 .. ceil(L/2) - 1 carry their negative twin too (2); the
/// zero frequency and, for even L, the Nyquist bin have none (1).
fn one_sided(k: usize, l: usize) -> f64 {
    if k == 0 || (l.is_multiple_of(2) && k == l / 2) {
        1.0
    } else {
        2.0
    }
}

/// The inputs of [`welch`], or the error naming `what`.
fn check(x: &[f64], fs: f64, l: usize, overlap: f64, what: &str) -> Result<(), MeasuredError> {
    let bad = |reason: String| Err(MeasuredError::input(what, reason));
    if !(fs.is_finite() && fs > 0.0) {
        return bad(format!("need a positive sampling rate, got {fs} Hz"));
    }
    if !(0.0..1.0).contains(&overlap) {
        return bad(format!("the overlap must lie in [0, 1), got {overlap}"));
    }
    if l < MIN_SEGMENT {
        return bad(format!("a segment needs at least {MIN_SEGMENT} samples, got {l}"));
    }
    if x.len() < l {
        return bad(format!("{} samples, fewer than one segment of {l}", x.len()));
    }
    if let Some(k) = x.iter().position(|v| !v.is_finite()) {
        return bad(format!("sample {} is not finite ({})", k + 1, x[k]));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_is_periodic_and_its_power_is_three_eighths() {
        let w = hann(16);
        assert_eq!(w[0], 0.0);
        assert!((w[8] - 1.0).abs() < 1e-15 && (w[4] - 0.5).abs() < 1e-15);
        // sum w^2 = 3 L / 8 exactly for the periodic window
        let w2: f64 = hann(64).iter().map(|v| v * v).sum();
        assert!((w2 - 24.0).abs() < 1e-12);
    }

    #[test]
    fn bad_inputs_name_the_signal() {
        let x = vec![0.0; 100];
        for (fs, opts, want) in [
            (0.0, WelchOptions::default(), "sampling rate"),
            (
                1.0,
                WelchOptions {
                    overlap: 1.0,
                    segment: None,
                },
                "overlap",
            ),
            (
                1.0,
                WelchOptions {
                    overlap: 0.5,
                    segment: Some(4),
                },
                "at least 8",
            ),
            (
                1.0,
                WelchOptions {
                    overlap: 0.5,
                    segment: Some(200),
                },
                "fewer than one segment",
            ),
        ] {
            let e = welch(&x, fs, &opts, "tip_x").unwrap_err().to_string();
            assert!(e.contains("tip_x") && e.contains(want), "{e}");
        }
        let mut y = x.clone();
        y[10] = f64::NAN;
        let e = welch(&y, 1.0, &WelchOptions::default(), "eps").unwrap_err().to_string();
        assert!(e.contains("sample 11"), "{e}");
    }
}
