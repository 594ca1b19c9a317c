//! `[damping]`: Rayleigh damping of the elastic motion, `C = alpha M + beta K`
//! (`docs/amm.md` 11.2, `docs/fem.md` 9.2, Eqs. D1-D5, D14-D20).
//!
//! ```toml
//! [damping]
//! beta = 8e-4          # s, stiffness-proportional: EI (kappa + beta kappa'), EA (eps + beta eps')
//! alpha = 0.5          # 1/s, mass-proportional, on the motion relative to the rigid robot
//! # or zeta = 0.015               the ratio of the first mode (at f_hz; default: the first
//! #                               frequency at the start pose), stiffness-proportional (Eq. D5)
//! # or zeta = [0.015, 0.02]       the ratios of the first two modes (at f_hz = [f1, f2];
//! #                               default: the first two frequencies at the start pose), Eq. D15
//! ```
//! A mode of angular frequency omega has the ratio `alpha / (2 omega) + beta omega / 2` (Eq. D14).

use std::f64::consts::PI;
use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::error::ModelError;

/// A `zeta` or `f_hz` of `[damping]`: one value (the first mode) or two (the first two modes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeValues {
    /// At the first mode.
    One(f64),
    /// At the first and the second mode.
    Two([f64; 2]),
}

impl ModeValues {
    /// The values, first mode first.
    pub fn values(&self) -> &[f64] {
        match self {
            ModeValues::One(v) => std::slice::from_ref(v),
            ModeValues::Two(v) => v,
        }
    }
}

impl Serialize for ModeValues {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            ModeValues::One(v) => s.serialize_f64(*v),
            ModeValues::Two(v) => v.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for ModeValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ModeValues;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number (the first mode) or a list of two numbers (the first two modes)")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<ModeValues, E> {
                Ok(ModeValues::One(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ModeValues, E> {
                Ok(ModeValues::One(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<ModeValues, E> {
                Ok(ModeValues::One(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ModeValues, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                match v.as_slice() {
                    [a] => Ok(ModeValues::One(*a)),
                    [a, b] => Ok(ModeValues::Two([*a, *b])),
                    _ => Err(de::Error::invalid_length(
                        v.len(),
                        &"one value or two (the first two modes)",
                    )),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// `[damping]` (see the module doc). Every key defaults to none: no damping.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Damping {
    /// Mass-proportional coefficient alpha [1/s] on the elastic motion (Eq. D14); with or without
    /// `beta`, not with `zeta`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
    /// Stiffness-proportional coefficient (Kelvin-Voigt retardation time) beta [s] (Eq. D1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// Damping ratio [-] of the first mode, or of the first two (exclusive with alpha, beta).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub zeta: Option<ModeValues>,
    /// The frequencies [Hz] at which `zeta` holds, as many as `zeta` has; without them, the
    /// robot's first (two) elastic frequencies at the start pose, computed by the explicit step
    /// `flexstar_shaping::shape` (pending until then, [`Damping::pending`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub f_hz: Option<ModeValues>,
}

impl Damping {
    /// A Kelvin-Voigt damping of retardation time `beta` [s].
    pub fn with_beta(beta: f64) -> Self {
        Damping {
            beta: Some(beta),
            ..Damping::default()
        }
    }

    /// Rayleigh damping of coefficients `alpha` [1/s] and `beta` [s].
    pub fn rayleigh(alpha: f64, beta: f64) -> Self {
        Damping {
            alpha: Some(alpha),
            beta: Some(beta),
            ..Damping::default()
        }
    }

    /// No damping at all (the default).
    pub fn is_none(&self) -> bool {
        self.alpha() == 0.0 && self.beta() == 0.0
    }

    /// `zeta` is given without `f_hz`: it waits for the first frequencies at the start pose
    /// (`flexstar_shaping::shape`); a problem is not built before.
    pub fn pending(&self) -> bool {
        self.zeta.is_some() && self.f_hz.is_none()
    }

    /// How many of the first frequencies at the start pose [`Damping::resolve`] needs: 0 when
    /// none. Two ratios take the first two *distinct* modes ([`DISTINCT`]), which on a symmetric
    /// star lie beyond a double first frequency: six cover the pairs of the paper's star.
    pub fn frequencies_needed(&self) -> usize {
        match (self.zeta, self.f_hz, self.alpha()) {
            (Some(ModeValues::One(_)), None, _) => 1,
            (Some(ModeValues::Two(_)), None, _) => 6,
            // mode 1's ratio is checked below 1 (the mass-proportional part is largest there)
            (None, _, a) if a > 0.0 => 1,
            _ => 0,
        }
    }

    /// `(alpha [1/s], beta [s])`: as given, or fitted to `zeta` at `f_hz` (Eqs. D5, D15), or 0.
    /// A validated damping's fit is non-negative.
    pub fn coefficients(&self) -> (f64, f64) {
        match (self.zeta, self.f_hz) {
            (Some(ModeValues::One(z)), Some(ModeValues::One(f))) => (0.0, z / (PI * f)),
            (Some(ModeValues::Two(z)), Some(ModeValues::Two(f))) => rayleigh_fit(z, f),
            (Some(_), _) => (0.0, 0.0),
            (None, _) => (self.alpha.unwrap_or(0.0), self.beta.unwrap_or(0.0)),
        }
    }

    /// Mass-proportional coefficient alpha [1/s] (Eq. D14).
    pub fn alpha(&self) -> f64 {
        self.coefficients().0
    }

    /// Stiffness-proportional coefficient beta [s] (Eqs. D1, D5).
    pub fn beta(&self) -> f64 {
        self.coefficients().1
    }

    /// The damping ratio of a mode of natural frequency `f` [Hz] (Eq. D14):
    /// `alpha / (2 omega) + beta omega / 2`, `omega = 2 pi f`; 0 for `f = 0` without alpha.
    pub fn zeta_at(&self, f: f64) -> f64 {
        let (alpha, beta) = self.coefficients();
        let omega = 2.0 * PI * f;
        let mass = if alpha == 0.0 { 0.0 } else { alpha / (2.0 * omega) };
        mass + beta * omega / 2.0
    }

    /// Set the frequencies a pending `zeta` holds at, from the first elastic frequencies at the
    /// start pose `first` [Hz], ascending (as many as [`Damping::frequencies_needed`]): mode 1,
    /// and for two ratios the first mode distinct from it ([`DISTINCT`]); then check mode 1's
    /// ratio: below 1, and the fit of two ratios non-negative. Errors under `damping.zeta` or
    /// `damping.alpha`, naming the mode.
    pub fn resolve(&mut self, first: &[f64]) -> Result<(), ModelError> {
        if let (Some(z), None) = (self.zeta, self.f_hz) {
            let f1 = first.first().copied().filter(|f| f.is_finite() && *f > 0.0);
            let f2 = f1.and_then(|f1| first.iter().copied().find(|f| *f > f1 * (1.0 + DISTINCT)));
            self.f_hz = Some(match (z, f1, f2) {
                (ModeValues::One(_), Some(f1), _) => ModeValues::One(f1),
                (ModeValues::Two(_), Some(f1), Some(f2)) => ModeValues::Two([f1, f2]),
                _ => {
                    return Err(ModelError::invalid(
                        "damping.zeta",
                        format!(
                            "needs the first {} distinct elastic frequencies at the start pose, got {first:?} Hz",
                            z.values().len()
                        ),
                    ))
                }
            });
            self.validate()?;
        }
        if let Some(&f1) = first.first() {
            let z1 = self.zeta_at(f1);
            if z1 >= 1.0 {
                let key = if self.zeta.is_some() {
                    "damping.zeta"
                } else {
                    "damping.alpha"
                };
                return Err(ModelError::invalid(
                    key,
                    format!("makes mode 1 ({f1:.4} Hz at the start pose) critically damped or more: ratio {z1:.3}"),
                ));
            }
        }
        Ok(())
    }

    /// Check the values and their combination (keys named `damping.<key>`).
    pub fn validate(&self) -> Result<(), ModelError> {
        let list = |v: Option<ModeValues>| v.map(|v| v.values().to_vec()).unwrap_or_default();
        for (key, values) in [
            ("damping.alpha", self.alpha.into_iter().collect::<Vec<_>>()),
            ("damping.beta", self.beta.into_iter().collect()),
            ("damping.zeta", list(self.zeta)),
            ("damping.f_hz", list(self.f_hz)),
        ] {
            if let Some(v) = values.iter().find(|v| !v.is_finite() || **v < 0.0) {
                return Err(ModelError::invalid(key, format!("must be finite and >= 0, got {v}")));
            }
        }
        if self.zeta.is_some() && (self.alpha.is_some() || self.beta.is_some()) {
            return Err(ModelError::invalid(
                "damping.zeta",
                "give either the coefficients alpha [1/s] and beta [s], or zeta (with f_hz), not both",
            ));
        }
        let Some(zeta) = self.zeta else {
            if self.f_hz.is_some() {
                return Err(ModelError::invalid(
                    "damping.f_hz",
                    "f_hz is where a zeta holds: give zeta too, or alpha [1/s] and beta [s] alone",
                ));
            }
            return Ok(());
        };
        if let Some((k, z)) = zeta.values().iter().enumerate().find(|(_, z)| **z >= 1.0) {
            return Err(ModelError::invalid(
                "damping.zeta",
                format!(
                    "the ratio of mode {} must be below 1 (critical damping), got {z}",
                    k + 1
                ),
            ));
        }
        let Some(f) = self.f_hz else { return Ok(()) };
        if f.values().len() != zeta.values().len() {
            return Err(ModelError::invalid(
                "damping.f_hz",
                format!(
                    "give as many frequencies as ratios: zeta has {}, f_hz {}",
                    zeta.values().len(),
                    f.values().len()
                ),
            ));
        }
        if let Some(f) = f.values().iter().find(|f| **f <= 0.0) {
            return Err(ModelError::invalid(
                "damping.f_hz",
                format!("the frequency must be positive, got {f}"),
            ));
        }
        if let (ModeValues::Two(z), ModeValues::Two(f)) = (zeta, f) {
            check_fit(z, f)?;
        }
        Ok(())
    }
}

/// Two frequencies closer than this relative gap are one mode for `zeta = [z1, z2]`: a
/// symmetric star has double frequencies, and on a measured spectrum with a few per cent of
/// damping two peaks this close merge into one (half-power bandwidth `2 zeta f`).
pub const DISTINCT: f64 = 0.05;

/// Eq. D15: the Rayleigh coefficients `(alpha, beta)` whose ratios are `z` at the frequencies `f`
/// [Hz]: `alpha = 2 w1 w2 (z1 w2 - z2 w1) / (w2^2 - w1^2)`, `beta = 2 (z2 w2 - z1 w1) / (w2^2 - w1^2)`.
/// Equal frequencies with equal ratios give the stiffness-proportional damping of Eq. D5.
fn rayleigh_fit(z: [f64; 2], f: [f64; 2]) -> (f64, f64) {
    let [w1, w2] = f.map(|f| 2.0 * PI * f);
    if w1 == w2 {
        return (0.0, 2.0 * z[0] / w1);
    }
    let den = w2 * w2 - w1 * w1;
    (
        2.0 * w1 * w2 * (z[0] * w2 - z[1] * w1) / den,
        2.0 * (z[1] * w2 - z[0] * w1) / den,
    )
}

/// A fit with a negative coefficient makes some mode's ratio negative (below mode 1 for alpha,
/// above mode 2 for beta): refused, with the range of `z2` that keeps both non-negative.
fn check_fit(z: [f64; 2], f: [f64; 2]) -> Result<(), ModelError> {
    if f[0] == f[1] {
        return if z[0] == z[1] {
            Ok(())
        } else {
            Err(ModelError::invalid(
                "damping.zeta",
                format!("two different ratios {z:?} at one frequency {} Hz", f[0]),
            ))
        };
    }
    let (alpha, beta) = rayleigh_fit(z, f);
    if alpha >= 0.0 && beta >= 0.0 {
        return Ok(());
    }
    let (lo, hi) = (
        z[0] * f[0].min(f[1]) / f[0].max(f[1]),
        z[0] * f[0].max(f[1]) / f[0].min(f[1]),
    );
    let (coef, which) = if alpha < 0.0 {
        (format!("alpha = {alpha:.4e} 1/s"), "the modes below mode 1")
    } else {
        (format!("beta = {beta:.4e} s"), "the modes above mode 2")
    };
    Err(ModelError::invalid(
        "damping.zeta",
        format!(
            "{z:?} at {f:?} Hz needs {coef} < 0, a negative damping ratio for {which}: with these \
             frequencies the second ratio must lie in [{lo:.4}, {hi:.4}]"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Experiment;
    use std::path::Path;

    fn load(extra: &str) -> Result<Experiment, String> {
        crate::attachments::tests::load(extra, Path::new("bad.toml"))
    }

    #[test]
    fn one_ratio_gives_the_kelvin_voigt_time() {
        let e = load("[damping]\nzeta = 0.02\nf_hz = 4.0").unwrap();
        // Eq. D5: beta = zeta / (pi f); the ratio at f_hz is zeta again
        assert!((e.damping.beta() - 0.02 / (PI * 4.0)).abs() < 1e-18);
        assert_eq!(e.damping.alpha(), 0.0);
        assert!((e.damping.zeta_at(4.0) - 0.02).abs() < 1e-15);
    }

    #[test]
    fn two_ratios_are_met_at_their_frequencies() {
        let e = load("[damping]\nzeta = [0.015, 0.02]\nf_hz = [3.0, 11.0]").unwrap();
        let (a, b) = e.damping.coefficients();
        assert!(a > 0.0 && b > 0.0);
        // the fit solves the two equations of Eq. D14
        assert!((e.damping.zeta_at(3.0) - 0.015).abs() < 1e-15);
        assert!((e.damping.zeta_at(11.0) - 0.02).abs() < 1e-15);
        // a constant ratio is not Rayleigh's: in between it dips below both (minimum at
        // omega = sqrt(alpha / beta), ratio sqrt(alpha beta))
        let f_min = (a / b).sqrt() / (2.0 * PI);
        assert!((e.damping.zeta_at(f_min) - (a * b).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn pending_ratios_resolve_at_the_given_frequencies() {
        let mut e = load("[damping]\nzeta = [0.01, 0.02]").unwrap();
        assert!(e.damping.pending());
        assert_eq!(e.damping.frequencies_needed(), 6);
        // a double first frequency (the symmetric star) counts once
        e.damping.resolve(&[4.0, 4.01, 9.0, 30.0]).unwrap();
        assert_eq!(e.damping.f_hz, Some(ModeValues::Two([4.0, 9.0])));
        assert!((e.damping.zeta_at(9.0) - 0.02).abs() < 1e-15);
        // alpha alone: mode 1's ratio alpha / (2 omega_1) must stay below 1
        let mut e = load("[damping]\nalpha = 30.0").unwrap();
        assert_eq!(e.damping.frequencies_needed(), 1);
        let err = e.damping.resolve(&[2.0]).unwrap_err().to_string();
        assert!(err.contains("damping.alpha") && err.contains("mode 1"), "{err}");
        e.damping.resolve(&[4.0]).unwrap();
        // a pending pair whose fit at the robot's frequencies is negative is refused there
        let mut e = load("[damping]\nzeta = [0.01, 0.05]").unwrap();
        let err = e.damping.resolve(&[4.0, 5.0]).unwrap_err().to_string();
        assert!(err.contains("damping.zeta") && err.contains("alpha"), "{err}");
    }

    #[test]
    fn bad_damping_names_file_and_key() {
        for (extra, key, why) in [
            ("[damping]\nbeta = -1e-3", "damping.beta", ">= 0"),
            ("[damping]\nalpha = nan", "damping.alpha", "finite"),
            ("[damping]\nbeta = 1e-3\nzeta = 0.01", "damping.zeta", "not both"),
            (
                "[damping]\nalpha = 1.0\nzeta = [0.01, 0.02]",
                "damping.zeta",
                "not both",
            ),
            ("[damping]\nzeta = 1.0", "damping.zeta", "mode 1"),
            ("[damping]\nzeta = [0.01, 1.2]", "damping.zeta", "mode 2"),
            ("[damping]\nzeta = [0.01, 0.02, 0.03]", "zeta", "two"),
            ("[damping]\nzeta = 0.01\nf_hz = 0.0", "damping.f_hz", "positive"),
            ("[damping]\nzeta = 0.01\nf_hz = inf", "damping.f_hz", "finite"),
            ("[damping]\nzeta = [0.01, 0.02]\nf_hz = 4.0", "damping.f_hz", "as many"),
            ("[damping]\nf_hz = 4.0", "damping.f_hz", "zeta"),
            ("[damping]\nbeta = 1e-3\nf_hz = 4.0", "damping.f_hz", "zeta"),
            // z2 / z1 above f2 / f1: alpha < 0 (mode 1's side); below f1 / f2: beta < 0
            (
                "[damping]\nzeta = [0.01, 0.05]\nf_hz = [4.0, 8.0]",
                "damping.zeta",
                "alpha",
            ),
            (
                "[damping]\nzeta = [0.01, 0.004]\nf_hz = [4.0, 8.0]",
                "damping.zeta",
                "beta",
            ),
            (
                "[damping]\nzeta = [0.01, 0.02]\nf_hz = [4.0, 4.0]",
                "damping.zeta",
                "one frequency",
            ),
            ("[damping]\ngamma = 1.0", "gamma", "unknown"),
        ] {
            let e = load(extra).unwrap_err();
            assert!(
                e.contains("bad.toml") && e.contains(key) && e.contains(why),
                "{extra}: {e}"
            );
        }
    }
}
