//! Assumed-mode families of one beam (Eq. 34-1; `docs/amm.md`, Mode families), G at x = 0, free tip at
//! x = L.
//!
//! Each elastic mode solves `(EI/rho) phi'''' = lambda phi` with `lambda = (EI/rho) beta^4`. It is
//! written in the numerically stable basis
//!
//! ```text
//! Phi(xi) = c1 cos(b xi) + c2 sin(b xi) + c3 exp(-b xi) + c4 exp(-b (1 - xi)),   xi = x/L, b = beta L
//! ```
//! (the textbook `cosh - cos - sigma (sinh - sin)` loses every digit above b ~ 20; here no term
//! exceeds 1, so phi and its first three derivatives keep full relative precision for any N).
//! `phi(x) = Phi(x/L) / sqrt(L)`, normalised so that `int_0^L phi_j phi_m dx = delta_jm` [1/sqrt(m)].
//!
//! | family | BC at G | characteristic equation (stable form) | asymptote of b_n | rigid modes |
//! |---|---|---|---|---|
//! | clamped-free | w = w' = 0 | cos b + sech b = 0 | (2n-1) pi/2 | none |
//! | pinned-free | w = w'' = 0 | sin b - cos b tanh b = 0 | (4n+1) pi/4 | sqrt(3) xi |
//! | slide-free | w' = w''' = 0 | sin b + cos b tanh b = 0 | (4n-1) pi/4 | 1 |
//! | free-free | w'' = w''' = 0 | cos b - sech b = 0 | (2n+1) pi/2 | 1, sqrt(3)(2 xi - 1) |
//!
//! N counts every mode, rigid ones first.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use flexstar_model::{ModeFamily, RobotParams};

use crate::error::AmmError;

mod junction;
use junction::JunctionShape;

/// Largest number of modes per beam accepted (beyond it a count is refused as absurdly large).
pub const MAX_MODES: usize = 400;

/// Shape of one mode on the unit interval, `Phi(xi)`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    /// Rigid mode `Phi = a + b xi` (lambda = 0).
    Rigid { a: f64, b: f64 },
    /// Elastic mode in the stable basis; `bl` = beta L, `e` = exp(-beta L).
    Elastic { bl: f64, c: [f64; 4], e: f64 },
}

/// The first N modes of one family for beams of the robot (Eq. 34-1), with the integrals and
/// point values the motion equations need (Eqs. 37, 44).
#[derive(Debug, Clone)]
pub struct ModeSet {
    family: ModeFamily,
    l: f64,
    ei_over_rho: f64,
    shapes: Vec<Shape>,
    /// Number of leading rigid modes.
    rigid: usize,
    lambda: Vec<f64>,
    phi_int: Vec<f64>,
    psi_int: Vec<f64>,
    /// The elastic roots as nominal roots `pi` apart plus small offsets (see [`ModeTrig`]).
    roots: NominalRoots,
    /// Enriched family: the two junction shapes, after the analytic modes in `shapes`.
    junction: Vec<JunctionShape>,
}

mod families;
mod lanes;
mod recurrence;
mod stiffening;

use families::*;
use recurrence::*;

pub(crate) use recurrence::{SleeveBending, Triplet};

impl ModeSet {
    /// The first `n` modes of `family` (rigid ones included) for the beams of `params`.
    ///
    /// Errors: `n = 0` or `n > MAX_MODES`, non-positive EI, rho or L.
    pub fn new(family: ModeFamily, n: usize, params: &RobotParams) -> Result<Self, AmmError> {
        check_inputs(family, n, params)?;
        let enriched = family == ModeFamily::Enriched;
        // the enriched family: N - 2 free-free modes, then two junction shapes
        let n_analytic = if enriched { n - 2 } else { n };
        let l = params.l;
        let rigid = rigid_modes(family);
        let shapes = analytic_shapes(family, n_analytic)?;
        let ei_over_rho = params.ei() / params.rho;
        let sqrt_l = l.sqrt();
        let mut lambda = Vec::with_capacity(n);
        let mut phi_int = Vec::with_capacity(n);
        let mut psi_int = Vec::with_capacity(n);
        for s in &shapes {
            let (bl, i0, i1) = s.unit_integrals();
            lambda.push(ei_over_rho * (bl / l).powi(4));
            phi_int.push(sqrt_l * i0);
            psi_int.push(sqrt_l * l * i1);
        }
        let roots = NominalRoots::new(&shapes);
        let mut set = ModeSet {
            family,
            l,
            ei_over_rho,
            shapes,
            rigid: rigid.len().min(n),
            lambda,
            phi_int,
            psi_int,
            roots,
            junction: Vec::new(),
        };
        if enriched {
            set.add_junction_shapes();
        }
        Ok(set)
    }

    /// Enriched family: build the two junction shapes against the analytic modes (Rayleigh-Ritz,
    /// `junction` module) and append their lambda and integrals.
    fn add_junction_shapes(&mut self) {
        let (x, w) = junction::composite_rule(junction::panels_for(self.analytic_beta_max()));
        // the analytic modes' values and second derivatives at the nodes, row q = node q
        let nk = self.analytic_len();
        let (mut phi, mut phi2) = (vec![0.0; x.len() * nk], vec![0.0; x.len() * nk]);
        for ((&xi, row), row2) in x.iter().zip(phi.chunks_exact_mut(nk)).zip(phi2.chunks_exact_mut(nk)) {
            self.analytic_value_curvature(xi, row, row2);
        }
        let shapes = junction::build(&x, &w, &phi, &phi2, nk);
        let (sqrt_l, l) = (self.l.sqrt(), self.l);
        let na = self.analytic_len();
        for sh in shapes {
            // int_0^1 H dxi and int_0^1 xi H dxi of H = p . (1 - xi)^(4, 5) - sum c_k Phi_k, exactly:
            // int (1 - xi)^n = 1 / (n + 1), int xi (1 - xi)^n = 1 / ((n + 1)(n + 2)), and the
            // analytic modes' integrals (above, in units of sqrt L and L sqrt L)
            let i0 = sh.p[0] / 5.0 + sh.p[1] / 6.0
                - sh.c
                    .iter()
                    .zip(&self.phi_int[..na])
                    .map(|(c, v)| c * v / sqrt_l)
                    .sum::<f64>();
            let i1 = sh.p[0] / 30.0 + sh.p[1] / 42.0
                - sh.c
                    .iter()
                    .zip(&self.psi_int[..na])
                    .map(|(c, v)| c * v / (sqrt_l * l))
                    .sum::<f64>();
            self.lambda.push(self.ei_over_rho * sh.mu / l.powi(4));
            self.phi_int.push(sqrt_l * i0);
            self.psi_int.push(sqrt_l * l * i1);
            self.junction.push(sh);
        }
    }

    /// `Phi(xi)` and `Phi''(xi)` of every analytic mode on the unit interval (into `phi`, `phi2`),
    /// with the trigonometric recurrence of [`ModeSet::values_at`].
    fn analytic_value_curvature(&self, xi: f64, phi: &mut [f64], phi2: &mut [f64]) {
        let mut trig = ModeTrig::new(xi, &self.roots);
        for (m, (sh, (v, v2))) in self.shapes.iter().zip(phi.iter_mut().zip(phi2.iter_mut())).enumerate() {
            (*v, *v2) = match *sh {
                Shape::Rigid { a, b } => (a + b * xi, 0.0),
                Shape::Elastic { bl, c, .. } => {
                    let [sn, cs, e1, e2] = trig.next(m, bl);
                    let (p, q) = (c[0] * cs + c[1] * sn, c[2] * e1 + c[3] * e2);
                    (p + q, bl * bl * (q - p))
                }
            };
        }
    }

    /// Largest beta L of the analytic modes (at least 1): what a quadrature of products of modes
    /// must resolve. The junction shapes are polynomials minus analytic modes, so they add no
    /// faster oscillation (their `mu^(1/4)` can be far larger, but it is not a wavenumber).
    fn analytic_beta_max(&self) -> f64 {
        self.shapes
            .iter()
            .map(|s| if let Shape::Elastic { bl, .. } = s { *bl } else { 0.0 })
            .fold(1.0, f64::max)
    }

    /// Number of analytic modes (all of them but the enriched family's junction shapes).
    pub(crate) fn analytic_len(&self) -> usize {
        self.shapes.len()
    }

    /// `Phi^(k)(xi)`, k = 0..=3, of mode m on the unit interval (analytic or junction shape).
    fn eval_unit(&self, m: usize, xi: f64) -> [f64; 4] {
        match m.checked_sub(self.analytic_len()) {
            None => self.shapes[m].eval(xi),
            Some(j) => {
                let kept: Vec<[f64; 4]> = self.shapes.iter().map(|s| s.eval(xi)).collect();
                junction::eval(&self.junction[j], xi, &kept)
            }
        }
    }

    /// The family of these modes.
    pub fn family(&self) -> ModeFamily {
        self.family
    }

    /// Number of modes N (rigid ones and junction shapes included).
    pub fn len(&self) -> usize {
        self.shapes.len() + self.junction.len()
    }

    /// Always false: a mode set holds at least one mode.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// Number of rigid modes (lambda = 0) among the N.
    pub fn rigid_count(&self) -> usize {
        self.rigid
    }

    /// Beam length L [m].
    pub fn length(&self) -> f64 {
        self.l
    }

    /// Eq. 34-1: dimensionless roots beta_m L, 0 for rigid modes; for the junction shapes of the
    /// enriched family the equivalent `(lambda rho / EI)^(1/4) L` of their Ritz value.
    pub fn beta_l(&self) -> Vec<f64> {
        self.shapes
            .iter()
            .map(|s| match s {
                Shape::Rigid { .. } => 0.0,
                Shape::Elastic { bl, .. } => *bl,
            })
            .chain(self.junction.iter().map(|j| j.mu.powf(0.25)))
            .collect()
    }

    /// Eq. 34-1: `lambda_m = omega_m^2 = (EI/rho) beta_m^4` [1/s^2] (0 for rigid modes).
    pub fn lambda(&self) -> &[f64] {
        &self.lambda
    }

    /// Natural frequencies `f_m = (beta_m L)^2 / (2 pi L^2) sqrt(EI/rho)` [Hz] (0 for rigid modes).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.lambda.iter().map(|l| l.sqrt() / (2.0 * PI)).collect()
    }

    /// Eqs. 37, 44: `Phi_m = int_0^L phi_m dx` [sqrt(m)].
    pub fn phi_integral(&self) -> &[f64] {
        &self.phi_int
    }

    /// Eq. 37: `Psi_m = int_0^L x phi_m dx` [m^1.5].
    pub fn x_phi_integral(&self) -> &[f64] {
        &self.psi_int
    }

    /// `EI / rho` [m^4/s^2].
    pub fn ei_over_rho(&self) -> f64 {
        self.ei_over_rho
    }

    /// Mode m (0-based) and its first three x-derivatives at material coordinate x [m] (0 = G):
    /// `[phi, phi', phi'', phi''']` in `[m^-1/2, m^-3/2, m^-5/2, m^-7/2]`.
    pub fn eval(&self, m: usize, x: f64) -> [f64; 4] {
        let xi = x / self.l;
        let v = self.eval_unit(m, xi);
        let s = 1.0 / self.l.sqrt();
        [
            v[0] * s,
            v[1] * s / self.l,
            v[2] * s / (self.l * self.l),
            v[3] * s / (self.l * self.l * self.l),
        ]
    }
}

/// Dot product (`flexstar_numerics::vector::dot`: fused multiply-add where the processor has it).
pub(crate) use flexstar_numerics::vector::dot;

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use flexstar_numerics::quadrature::integrate;

    fn composite(f: impl Fn(f64) -> f64, panels: usize) -> f64 {
        (0..panels)
            .map(|k| integrate(&f, k as f64 / panels as f64, (k + 1) as f64 / panels as f64, 5))
            .sum()
    }

    #[test]
    fn gram_matrix_matches_quadrature() {
        for bl in [1.875, 4.73, 23.6, 80.1] {
            let g = gram(bl);
            for p in 0..4 {
                for q in 0..4 {
                    let num = composite(|x| basis_row(bl, x, 0)[p] * basis_row(bl, x, 0)[q], 400);
                    assert!(
                        (num - g[p][q]).abs() < 1e-13,
                        "b = {bl}, ({p},{q}): {num} vs {}",
                        g[p][q]
                    );
                }
            }
        }
    }

    #[test]
    fn boundary_conditions_hold_to_round_off() {
        let p = RobotParams::paper();
        for fam in [
            ModeFamily::ClampedFree,
            ModeFamily::PinnedFree,
            ModeFamily::SlideFree,
            ModeFamily::FreeFree,
        ] {
            let ms = ModeSet::new(fam, 100, &p).unwrap();
            let o = orders_at_g(fam);
            for m in ms.rigid_count()..ms.len() {
                let bl = ms.beta_l()[m];
                let v0 = ms.shapes[m].eval(0.0);
                let v1 = ms.shapes[m].eval(1.0);
                // relative to the size of the k-th derivative, b^k
                for k in o {
                    assert!(v0[k].abs() < 1e-12 * bl.powi(k as i32), "{fam} m={m} k={k}: {}", v0[k]);
                }
                for k in [2, 3] {
                    assert!(
                        v1[k].abs() < 1e-12 * bl.powi(k as i32),
                        "{fam} m={m} tip k={k}: {}",
                        v1[k]
                    );
                }
            }
        }
    }

    #[test]
    fn triplet_kernel_matches_eval() {
        let p = RobotParams::paper();
        for fam in ModeFamily::PAPER.into_iter().chain([ModeFamily::ClampedFree]) {
            let n = 400;
            let ms = ModeSet::new(fam, n, &p).unwrap();
            let direct = ms.roots.delta.iter().filter(|d| d.abs() > TAYLOR_DELTA).count();
            assert!(direct <= 2, "{fam}: {direct} modes evaluated directly");
            let tri = ms.triplet(0.015);
            let mut b = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
            for x in [0.015, 0.18, 0.3, 0.485] {
                let [l, m, r, d] = &mut b;
                ms.triplet_at(&tri, x, l, m, r, d, None);
                for k in 0..n {
                    let want = [
                        ms.eval(k, x - 0.015)[0],
                        ms.eval(k, x)[0],
                        ms.eval(k, x + 0.015)[0],
                        ms.eval(k, x)[1],
                    ];
                    // values are O(1/sqrt L), slopes O(beta/sqrt L)
                    let scale = [1.0, 1.0, 1.0, ms.beta_l()[k].max(1.0) / p.l];
                    for ((got, w), sc) in [l[k], m[k], r[k], d[k]].iter().zip(want).zip(scale) {
                        assert!((got - w).abs() < 1e-11 * sc, "{fam} k={k} x={x}: {got} vs {w}");
                    }
                }
            }
        }
    }

    #[test]
    fn fast_kernel_matches_eval() {
        let p = RobotParams::paper();
        let ms = ModeSet::new(ModeFamily::FreeFree, 60, &p).unwrap();
        let (mut v, mut d) = (vec![0.0; 60], vec![0.0; 60]);
        for x in [0.0, 0.013, 0.2, 0.4999, 0.5] {
            ms.values_at(x, &mut v, Some(&mut d));
            for m in 0..60 {
                let e = ms.eval(m, x);
                assert!((e[0] - v[m]).abs() < 1e-12 * (1.0 + e[0].abs()), "m={m} x={x}");
                assert!((e[1] - d[m]).abs() < 1e-12 * (1.0 + e[1].abs()), "m={m} x={x}");
            }
        }
    }
}
