//! A mode's continuous-time pole and the quantities read from it (`docs/measured.md` Eqs. I2,
//! I12): undamped natural frequency [Hz], damping ratio [-], and their first-order uncertainty.

use std::f64::consts::PI;

use faer::c64;

/// Undamped natural frequency [Hz] of the pole `s` [1/s] (Eq. I2): `|s| / (2 pi)`.
pub(crate) fn frequency_hz(s: c64) -> f64 {
    s.norm() / (2.0 * PI)
}

/// Damping ratio [-] of the pole `s` (Eq. I2): `-Re(s) / |s|`.
pub(crate) fn damping_ratio(s: c64) -> f64 {
    -s.re / s.norm()
}

/// The upper pole of a mode of frequency `f_hz` [Hz] and ratio `zeta` < 1 (Eq. I2).
pub(crate) fn from_frequency(f_hz: f64, zeta: f64) -> c64 {
    let omega = 2.0 * PI * f_hz;
    c64::new(-zeta * omega, omega * (1.0 - zeta * zeta).sqrt())
}

/// Standard deviations `(f [Hz], zeta [-])` of the pole `s = sigma + i omega_d` whose parameters
/// `(sigma, omega_d)` have the covariance `cov` [1/s^2] (Eq. I12, first order).
pub(crate) fn standard_deviations(s: c64, cov: [[f64; 2]; 2]) -> (f64, f64) {
    let (sigma, omega) = (s.re, s.im);
    let r = s.norm();
    let grad_f = [sigma / (2.0 * PI * r), omega / (2.0 * PI * r)];
    let grad_z = [-omega * omega / r.powi(3), sigma * omega / r.powi(3)];
    let quad = |g: [f64; 2]| {
        let v = g[0] * (cov[0][0] * g[0] + cov[0][1] * g[1]) + g[1] * (cov[1][0] * g[0] + cov[1][1] * g[1]);
        v.max(0.0).sqrt()
    };
    (quad(grad_f), quad(grad_z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequency_and_ratio_round_trip() {
        let s = from_frequency(6.27, 0.0426);
        assert!((frequency_hz(s) - 6.27).abs() < 1e-12);
        assert!((damping_ratio(s) - 0.0426).abs() < 1e-14);
    }

    /// Eq. I12 against central differences of Eq. I2 in sigma and omega_d.
    #[test]
    fn gradients_match_differences() {
        let s = from_frequency(3.24, 0.022);
        let h = 1e-6;
        let d = |ds: c64| {
            (
                frequency_hz(s + ds) - frequency_hz(s - ds),
                damping_ratio(s + ds) - damping_ratio(s - ds),
            )
        };
        let (fs, zs) = d(c64::new(h, 0.0));
        let (fw, zw) = d(c64::new(0.0, h));
        // a covariance with one unit variance at a time gives |gradient component|
        let (f1, z1) = standard_deviations(s, [[1.0, 0.0], [0.0, 0.0]]);
        let (f2, z2) = standard_deviations(s, [[0.0, 0.0], [0.0, 1.0]]);
        assert!((f1 - (fs / (2.0 * h)).abs()).abs() < 1e-8 * f1.max(1e-3));
        assert!((z1 - (zs / (2.0 * h)).abs()).abs() < 1e-8);
        assert!((f2 - (fw / (2.0 * h)).abs()).abs() < 1e-8);
        assert!((z2 - (zw / (2.0 * h)).abs()).abs() < 1e-8);
    }
}
