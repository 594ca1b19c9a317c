//! Measures of time histories: the trapezoidal integral of |f|, the error variance parameter of
//! the paper (Eq. 45) and the peak magnitude. One implementation for the comparison crate, the
//! solvers' convergence studies and their tests.

/// Trapezoidal integral of |f| over the samples t (non-uniform steps allowed).
pub fn integral_abs(t: &[f64], f: &[f64]) -> f64 {
    t.windows(2)
        .zip(f.windows(2))
        .map(|(tt, ff)| 0.5 * (tt[1] - tt[0]) * (ff[0].abs() + ff[1].abs()))
        .sum()
}

/// Eq. 45: `EVP = int |test - reference| dt / int |reference| dt * 100` [%]; `None` when the
/// reference integral vanishes.
pub fn evp(t: &[f64], test: &[f64], reference: &[f64]) -> Option<f64> {
    let diff: Vec<f64> = test.iter().zip(reference).map(|(a, b)| a - b).collect();
    evp_of_error(t, &diff, reference)
}

/// Eq. 45 from the error history itself: `int |error| dt / int |reference| dt * 100` [%], for a
/// caller whose error is not a plain difference (the norm of G's displacement difference,
/// `flexstar_metrics::evp`); `None` when the reference integral vanishes. The one implementation of
/// the ratio.
pub fn evp_of_error(t: &[f64], error: &[f64], reference: &[f64]) -> Option<f64> {
    let den = integral_abs(t, reference);
    (den > 0.0).then(|| integral_abs(t, error) / den * 100.0)
}

/// Largest |v|.
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evp_of_a_scaled_copy_is_the_scale_error() {
        // test = 1.1 reference everywhere: EVP = 10 % exactly, whatever the signal.
        let t: Vec<f64> = (0..=1000).map(|k| k as f64 * 1e-3).collect();
        let f = |t: f64| (20.0 * t).sin() * t;
        let a: Vec<f64> = t.iter().map(|&x| 1.1 * f(x)).collect();
        let b: Vec<f64> = t.iter().map(|&x| f(x)).collect();
        assert!((evp(&t, &a, &b).unwrap() - 10.0).abs() < 1e-10);
        assert_eq!(evp(&t, &a, &vec![0.0; t.len()]), None);
    }

    #[test]
    fn trapezoid_integral_of_sine() {
        // int_0^pi |sin| = 2; trapezoid error ~ pi h^2 / 12 with h = pi/1000
        let t: Vec<f64> = (0..=1000).map(|k| k as f64 * std::f64::consts::PI / 1000.0).collect();
        let f: Vec<f64> = t.iter().map(|x| x.sin()).collect();
        assert!((integral_abs(&t, &f) - 2.0).abs() < 2e-6);
        assert_eq!(max_abs(&[1.0, -3.0, 2.0]), 3.0);
    }
}
