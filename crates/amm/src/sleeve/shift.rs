//! The material point in the sleeve, drawn out by the beam's foreshortening (full model;
//! `docs/amm.md` 12.11, Eqs. S1-S4).
//!
//! An inextensible beam that bends draws its material towards G: the material point x sits at
//! `x + u - f(x)` along `e_x`, `f(x) = 1/2 int_0^x w'^2 ds` (the same f as the u row's
//! foreshortening inertia, `foreshortening.rs`). The point held at the pin, at `xp` along `e_x`,
//! is therefore
//!
//! ```text
//! x_c = xp - u + f(x_c) ~ xp - u + f(xp - u)                                        (S1)
//! f(x) = 1/2 alpha^T F(x) alpha,   F(x)_ab = int_0^x phi_a' phi_b' ds                  (S2)
//! ```
//!
//! and each sleeve row `r(x_c)` gains the alpha gradient `r'(x_c) g`, `g = F(x_c) alpha`
//! (Eq. S3): the axial components `-F_k w'` of the sleeve forces, acting on the foreshortening,
//! the geometric stiffness of the sleeve forces. `F` is tabulated at `PANELS + 1` points and
//! interpolated linearly, on the modes of the foreshortening's velocity part
//! ([`crate::foreshortening::KEPT_ANALYTIC`] = 10 analytic modes and the junction shapes): the
//! modes left out resolve the sleeve locally and add to `int w'^2` only at second order in their
//! small coordinates (on the worst envelope cases of `docs/amm.md` 12.11 the responses move by
//! EVP 0.001-0.002 % against 16 analytic modes, 0.002-0.007 % with 6). The table is shared
//! between the clones of a system (the automatic choice clones one per run).

use std::sync::Arc;

use crate::modes::ModeSet;

/// Panels of the table of `F(x)` along the beam; linear interpolation between its ends is
/// within `(L / PANELS)^2 beta_max / (4 x)` of F: 1.2 % at x = 0.15 L for the kept modes'
/// beta_max L = 30 (the shift is itself a 0.1-0.4 % correction of the response).
const PANELS: usize = 64;

/// `F(x)` on the kept modes and, per beam, the shift `f(x_c)` and its gradient `g` at the last
/// [`SleeveShift::evaluate`].
#[derive(Debug, Clone)]
pub(crate) struct SleeveShift {
    /// Indices of the kept modes in a beam's coordinates.
    kept: Vec<usize>,
    /// Panel width [m].
    h: f64,
    /// `F(n h)`, n = 0..=PANELS, k x k each, row-major [1/m].
    table: Arc<[f64]>,
    /// Kept coordinates of the beam being evaluated (scratch, k).
    alpha: Vec<f64>,
    /// Per beam: `g = F(x_c) alpha` on the kept modes [-].
    grad: [Vec<f64>; 3],
}

impl SleeveShift {
    /// The table for `modes`, on the kept modes `kept` (indices into a beam's coordinates).
    pub(crate) fn new(modes: &ModeSet, kept: &[usize]) -> Self {
        let k = kept.len();
        SleeveShift {
            kept: kept.to_vec(),
            h: modes.length() / PANELS as f64,
            table: modes.slope_gram_table(kept, PANELS).into(),
            alpha: vec![0.0; k],
            grad: std::array::from_fn(|_| vec![0.0; k]),
        }
    }

    /// The kept modes' indices.
    pub(crate) fn kept(&self) -> &[usize] {
        &self.kept
    }

    /// Eqs. S1-S2 for beam `beam` with modal coordinates `alpha` at the material point `x` [m]:
    /// returns `f(x)` [m] and keeps `g = F(x) alpha` ([`SleeveShift::gradient`]).
    pub(crate) fn evaluate(&mut self, beam: usize, x: f64, alpha: &[f64]) -> f64 {
        let k = self.kept.len();
        for (a, &j) in self.alpha.iter_mut().zip(&self.kept) {
            *a = alpha[j];
        }
        let (lo, hi, t) = Self::panel(&self.table, k, self.h, x);
        let g = &mut self.grad[beam];
        for ((ga, rl), rh) in g.iter_mut().zip(lo.chunks_exact(k)).zip(hi.chunks_exact(k)) {
            let (mut sl, mut sh) = (0.0, 0.0);
            for ((&fl, &fh), &a) in rl.iter().zip(rh).zip(&self.alpha) {
                sl += fl * a;
                sh += fh * a;
            }
            *ga = (1.0 - t) * sl + t * sh;
        }
        0.5 * g.iter().zip(&self.alpha).map(|(a, b)| a * b).sum::<f64>()
    }

    /// The table's two nodes around `x` [m] (k x k each) and the weight `t` of the upper one.
    fn panel(table: &[f64], k: usize, h: f64, x: f64) -> (&[f64], &[f64], f64) {
        let z = (x / h).clamp(0.0, PANELS as f64);
        let n = (z.floor() as usize).min(PANELS - 1);
        let lo = &table[n * k * k..(n + 1) * k * k];
        let hi = &table[(n + 1) * k * k..(n + 2) * k * k];
        (lo, hi, z - n as f64)
    }

    /// `f(x)` of Eq. S2 [m] for a beam's coordinates `alpha`, as [`SleeveShift::evaluate`] gives
    /// it but keeping nothing (the sleeves' sliding coordinates of `docs/friction.md` 9.1, Eq. F11).
    pub(crate) fn value(&self, x: f64, alpha: &[f64]) -> f64 {
        let k = self.kept.len();
        let (lo, hi, t) = Self::panel(&self.table, k, self.h, x);
        let mut two_f = 0.0;
        for ((rl, rh), &jr) in lo.chunks_exact(k).zip(hi.chunks_exact(k)).zip(&self.kept) {
            let (mut sl, mut sh) = (0.0, 0.0);
            for ((&fl, &fh), &jc) in rl.iter().zip(rh).zip(&self.kept) {
                sl += fl * alpha[jc];
                sh += fh * alpha[jc];
            }
            two_f += ((1.0 - t) * sl + t * sh) * alpha[jr];
        }
        0.5 * two_f
    }

    /// `g = F(x_c) alpha` of beam `beam` on the kept modes at its last evaluation (Eq. S3).
    pub(crate) fn gradient(&self, beam: usize) -> &[f64] {
        &self.grad[beam]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::{ModeFamily, RobotParams};

    #[test]
    fn the_shift_is_half_the_integral_of_the_squared_slope() {
        // against a brute-force Gauss quadrature of 1/2 int_0^x w'^2 over every mode of the set,
        // for a deflection on the kept modes (the table's own modes), at points between its nodes
        let params = RobotParams::paper();
        let modes = ModeSet::new(ModeFamily::Enriched, 40, &params).unwrap();
        let kept = crate::geometric::GeometricStiffness::kept_modes(&modes, crate::foreshortening::KEPT_ANALYTIC);
        let mut shift = SleeveShift::new(&modes, &kept);
        let mut alpha = vec![0.0; modes.len()];
        for (r, &j) in kept.iter().enumerate() {
            alpha[j] = 1e-3 / (1.0 + r as f64);
        }
        let l = modes.length();
        for x in [0.07 * l, 0.3137 * l, 0.55 * l, 0.861 * l] {
            let exact = modes.half_squared_slope_integral(&alpha, x);
            let f = shift.evaluate(1, x, &alpha);
            assert!(
                (shift.value(x, &alpha) - f).abs() <= 1e-15 * f.abs().max(1e-30),
                "value against evaluate"
            );
            eprintln!("x = {x}: table {f:e}, quadrature {exact:e}");
            assert!((f - exact).abs() < 1e-2 * exact, "x = {x}: {f} against {exact}");
            // g is the gradient of f: central differences of the table's own f in each kept
            // coordinate (f is quadratic, so they are exact to round-off)
            let g = shift.gradient(1).to_vec();
            for (r, &j) in kept.iter().enumerate() {
                let e = 1e-6;
                let mut a = alpha.clone();
                a[j] += e;
                let up = shift.evaluate(0, x, &a);
                a[j] -= 2.0 * e;
                let down = shift.evaluate(0, x, &a);
                let fd = (up - down) / (2.0 * e);
                assert!(
                    (fd - g[r]).abs() <= 1e-6 * g.iter().fold(0.0f64, |m, v| m.max(v.abs())),
                    "x = {x}, mode {j}: {fd} against {}",
                    g[r]
                );
            }
        }
    }
}
