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

/// Largest number of modes per beam accepted (issue 4: "absurdly large" beyond this).
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

/// Boundary conditions at G as derivative orders (Eq. 34-1).
fn orders_at_g(family: ModeFamily) -> [usize; 2] {
    match family {
        ModeFamily::ClampedFree => [0, 1],
        ModeFamily::PinnedFree => [0, 2],
        ModeFamily::SlideFree => [1, 3],
        ModeFamily::FreeFree | ModeFamily::Enriched => [2, 3],
    }
}

/// Rigid modes of a family on the unit interval, orthonormal: `(a, b)` of `Phi = a + b xi`.
fn rigid_modes(family: ModeFamily) -> &'static [(f64, f64)] {
    const S3: f64 = 1.732_050_807_568_877_2;
    match family {
        ModeFamily::ClampedFree => &[],
        ModeFamily::PinnedFree => &[(0.0, S3)],
        ModeFamily::SlideFree => &[(1.0, 0.0)],
        ModeFamily::FreeFree | ModeFamily::Enriched => &[(1.0, 0.0), (-S3, 2.0 * S3)],
    }
}

fn sech(b: f64) -> f64 {
    if b > 700.0 {
        0.0
    } else {
        2.0 * (-b).exp() / (1.0 + (-2.0 * b).exp())
    }
}

/// Characteristic function of the family in a form with O(1) terms (no cancellation).
fn characteristic(family: ModeFamily, b: f64) -> f64 {
    let (s, c) = b.sin_cos();
    match family {
        ModeFamily::ClampedFree => c + sech(b),
        ModeFamily::FreeFree | ModeFamily::Enriched => c - sech(b),
        ModeFamily::PinnedFree => s - c * b.tanh(),
        ModeFamily::SlideFree => s + c * b.tanh(),
    }
}

/// Asymptotic estimate of the n-th elastic root b_n (n = 1, 2, ...).
fn asymptote(family: ModeFamily, n: usize) -> f64 {
    let n = n as f64;
    match family {
        ModeFamily::ClampedFree => (2.0 * n - 1.0) * FRAC_PI_2,
        ModeFamily::FreeFree | ModeFamily::Enriched => (2.0 * n + 1.0) * FRAC_PI_2,
        ModeFamily::PinnedFree => (4.0 * n + 1.0) * FRAC_PI_4,
        ModeFamily::SlideFree => (4.0 * n - 1.0) * FRAC_PI_4,
    }
}

/// n-th elastic root beta_n L to full precision: bisection on the stable characteristic function
/// in `[asymptote - 0.6, asymptote + 0.6]` (roots are ~pi apart; the first lies within 0.31 of
/// its asymptote) until the bracket cannot shrink.
fn elastic_root(family: ModeFamily, n: usize) -> Result<f64, AmmError> {
    let a = asymptote(family, n);
    let (mut lo, mut hi) = (a - 0.6, a + 0.6);
    let (flo, fhi) = (characteristic(family, lo), characteristic(family, hi));
    if flo * fhi > 0.0 {
        return Err(AmmError::RootNotFound {
            family: family.name(),
            index: n,
            lo,
            hi,
        });
    }
    let lo_negative = flo < 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let f = characteristic(family, mid);
        if f == 0.0 {
            return Ok(mid);
        }
        if (f < 0.0) == lo_negative {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // the endpoint with the smaller residual
    if characteristic(family, lo).abs() <= characteristic(family, hi).abs() {
        Ok(lo)
    } else {
        Ok(hi)
    }
}

/// Row of the stable basis for the k-th derivative divided by b^k, at xi:
/// `[cos(b xi + k pi/2), sin(b xi + k pi/2), (-1)^k exp(-b xi), exp(-b (1 - xi))]`.
fn basis_row(bl: f64, xi: f64, k: usize) -> [f64; 4] {
    let (s, c) = (bl * xi).sin_cos();
    let (cs, sn) = match k % 4 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    };
    let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    [cs, sn, sign * (-bl * xi).exp(), (-bl * (1.0 - xi)).exp()]
}

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Null vector of a 4x4 matrix of rank 3: the generalized cross product of the three rows whose
/// product is largest (cofactor expansion; the rows are O(1), so this is accurate to round-off).
fn null_vector(a: [[f64; 4]; 4]) -> [f64; 4] {
    let mut best = [0.0; 4];
    let mut best_norm = -1.0;
    for skip in 0..4 {
        let rows: Vec<[f64; 4]> = (0..4).filter(|&r| r != skip).map(|r| a[r]).collect();
        let mut n = [0.0; 4];
        for (col, nc) in n.iter_mut().enumerate() {
            let mut m = [[0.0; 3]; 3];
            for (ri, row) in rows.iter().enumerate() {
                let mut cj = 0;
                for (j, v) in row.iter().enumerate() {
                    if j != col {
                        m[ri][cj] = *v;
                        cj += 1;
                    }
                }
            }
            let sign = if col % 2 == 0 { 1.0 } else { -1.0 };
            *nc = sign * det3(m);
        }
        let norm = n.iter().map(|v| v * v).sum::<f64>();
        if norm > best_norm {
            best_norm = norm;
            best = n;
        }
    }
    best
}

/// Gram matrix `int_0^1 f_a f_b dxi` of the stable basis (closed form).
fn gram(bl: f64) -> [[f64; 4]; 4] {
    let (s, c) = bl.sin_cos();
    let e = (-bl).exp();
    let tb = 2.0 * bl;
    let g11 = 0.5 + s * c / tb;
    let g22 = 0.5 - s * c / tb;
    let g12 = s * s / tb;
    let g33 = (1.0 - e * e) / tb;
    let g34 = e;
    let g13 = (1.0 + e * (s - c)) / tb;
    let g23 = (1.0 - e * (s + c)) / tb;
    let g14 = (c + s - e) / tb;
    let g24 = (s - c + e) / tb;
    [
        [g11, g12, g13, g14],
        [g12, g22, g23, g24],
        [g13, g23, g33, g34],
        [g14, g24, g34, g33],
    ]
}

impl Shape {
    /// `Phi^(k)(xi)` for k = 0..=3 on the unit interval.
    #[inline]
    fn eval(&self, xi: f64) -> [f64; 4] {
        match *self {
            Shape::Rigid { a, b } => [a + b * xi, b, 0.0, 0.0],
            Shape::Elastic { bl, .. } => {
                let (sn, cs) = (bl * xi).sin_cos();
                self.eval_from([sn, cs, (-bl * xi).exp(), (-bl * (1.0 - xi)).exp()], xi)
            }
        }
    }

    /// [`Shape::eval`] from `[sin(b xi), cos(b xi), exp(-b xi), exp(-b (1 - xi))]`.
    #[inline]
    fn eval_from(&self, trig: [f64; 4], xi: f64) -> [f64; 4] {
        match *self {
            Shape::Rigid { a, b } => [a + b * xi, b, 0.0, 0.0],
            Shape::Elastic { bl, c, .. } => {
                // the rows of `basis_row` for k = 0..3 share one sin/cos pair and two exponentials
                let [sn, cs, e1, e2] = trig;
                let rows = [(cs, sn), (-sn, cs), (-cs, -sn), (sn, -cs)];
                let mut out = [0.0; 4];
                let mut bk = 1.0;
                for (k, (o, (rc, rs))) in out.iter_mut().zip(rows).enumerate() {
                    let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                    *o = bk * (c[0] * rc + c[1] * rs + c[2] * sign * e1 + c[3] * e2);
                    bk *= bl;
                }
                out
            }
        }
    }
}

impl ModeSet {
    /// The first `n` modes of `family` (rigid ones included) for the beams of `params`.
    ///
    /// Errors: `n = 0` or `n > MAX_MODES`, non-positive EI, rho or L.
    pub fn new(family: ModeFamily, n: usize, params: &RobotParams) -> Result<Self, AmmError> {
        if n == 0 || n > MAX_MODES {
            return Err(AmmError::invalid(
                "amm.modes",
                format!("need 1 <= modes <= {MAX_MODES}, got {n}"),
            ));
        }
        for (key, v) in [
            ("robot.E * robot.I", params.ei()),
            ("robot.rho", params.rho),
            ("robot.L", params.l),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return Err(AmmError::invalid(
                    key,
                    format!("must be a positive finite number, got {v}"),
                ));
            }
        }
        let enriched = family == ModeFamily::Enriched;
        if enriched && n < 4 {
            return Err(AmmError::invalid(
                "amm.modes",
                format!("the enriched family needs N >= 4 (two rigid modes, at least two elastic modes or junction shapes), got {n}"),
            ));
        }
        // the enriched family: N - 2 free-free modes, then two junction shapes
        let n_analytic = if enriched { n - 2 } else { n };
        let l = params.l;
        let rigid = rigid_modes(family);
        let mut shapes = Vec::with_capacity(n_analytic);
        for &(a, b) in rigid.iter().take(n_analytic) {
            shapes.push(Shape::Rigid { a, b });
        }
        let orders = orders_at_g(family);
        let mut k = 1;
        while shapes.len() < n_analytic {
            let bl = elastic_root(family, k)?;
            let a = [
                basis_row(bl, 0.0, orders[0]),
                basis_row(bl, 0.0, orders[1]),
                basis_row(bl, 1.0, 2),
                basis_row(bl, 1.0, 3),
            ];
            let mut c = null_vector(a);
            let g = gram(bl);
            let mut norm2 = 0.0;
            for p in 0..4 {
                for q in 0..4 {
                    norm2 += c[p] * g[p][q] * c[q];
                }
            }
            let e = (-bl).exp();
            let tip = c[0] * bl.cos() + c[1] * bl.sin() + c[2] * e + c[3];
            let scale = tip.signum() / norm2.sqrt();
            for v in &mut c {
                *v *= scale;
            }
            shapes.push(Shape::Elastic { bl, c, e });
            k += 1;
        }
        let ei_over_rho = params.ei() / params.rho;
        let sqrt_l = l.sqrt();
        let mut lambda = Vec::with_capacity(n);
        let mut phi_int = Vec::with_capacity(n);
        let mut psi_int = Vec::with_capacity(n);
        for s in &shapes {
            // int_0^1 Phi dxi and int_0^1 xi Phi dxi; for elastic modes from the ODE and the free
            // tip: int Phi = -Phi'''(0)/b^4, int xi Phi = Phi''(0)/b^4.
            let (bl, i0, i1) = match *s {
                Shape::Rigid { a, b } => (0.0, a + 0.5 * b, 0.5 * a + b / 3.0),
                Shape::Elastic { bl, .. } => {
                    let v = s.eval(0.0);
                    let b4 = bl.powi(4);
                    (bl, -v[3] / b4, v[2] / b4)
                }
            };
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

    /// All modes at x [m]: `val[m] = phi_m(x)` and, if given, `slope[m] = phi_m'(x)`.
    /// One sin/cos pair and one exponential per elastic mode below beta L = 40, the recurrence of
    /// [`ModeSet::triplet_at`] above; no allocation.
    pub fn values_at(&self, x: f64, val: &mut [f64], mut slope: Option<&mut [f64]>) {
        let xi = x / self.l;
        let s = 1.0 / self.l.sqrt();
        let sd = s / self.l;
        let mut trig = ModeTrig::new(xi, &self.roots);
        for (m, sh) in self.shapes.iter().enumerate() {
            match *sh {
                Shape::Rigid { a, b } => {
                    val[m] = (a + b * xi) * s;
                    if let Some(d) = slope.as_deref_mut() {
                        d[m] = b * sd;
                    }
                }
                Shape::Elastic { bl, c, .. } => {
                    let [sn, cs, e1, e2] = trig.next(m, bl);
                    val[m] = (c[0] * cs + c[1] * sn + c[2] * e1 + c[3] * e2) * s;
                    if let Some(d) = slope.as_deref_mut() {
                        d[m] = bl * (-c[0] * sn + c[1] * cs - c[2] * e1 + c[3] * e2) * sd;
                    }
                }
            }
        }
        let na = self.analytic_len();
        for (j, sh) in self.junction.iter().enumerate() {
            let (p, dp) = junction::poly_value_slope(sh.p, xi);
            val[na + j] = p * s - dot(&sh.c, &val[..na]);
            if let Some(d) = slope.as_deref_mut() {
                d[na + j] = dp * sd - dot(&sh.c, &d[..na]);
            }
        }
    }

    /// The slopes `phi_m'(x)` [1/m^1.5] of every mode at `x` [m], as [`ModeSet::values_at`]
    /// computes them (the set-up of Eq. 23 needs no values).
    fn slopes_at(&self, x: f64, slope: &mut [f64]) {
        let xi = x / self.l;
        let sd = 1.0 / (self.l.sqrt() * self.l);
        let mut trig = ModeTrig::new(xi, &self.roots);
        for (m, (sh, d)) in self.shapes.iter().zip(slope.iter_mut()).enumerate() {
            *d = match *sh {
                Shape::Rigid { b, .. } => b * sd,
                Shape::Elastic { bl, c, .. } => {
                    let [sn, cs, e1, e2] = trig.next(m, bl);
                    bl * (-c[0] * sn + c[1] * cs - c[2] * e1 + c[3] * e2) * sd
                }
            };
        }
        let na = self.analytic_len();
        let (analytic, junction) = slope.split_at_mut(na);
        for (sh, d) in self.junction.iter().zip(junction) {
            let (_, dp) = junction::poly_value_slope(sh.p, xi);
            *d = dp * sd - dot(&sh.c, analytic);
        }
    }
}

/// Largest root offset `|delta|` evaluated by the Taylor series of [`ModeTrig`]: the first
/// neglected terms, `x^5 / 120` (sin, exp) and `x^6 / 720` (cos), stay below 1e-17 for `|x| <= 1e-3`.
const TAYLOR_DELTA: f64 = 1e-3;

/// The elastic roots `beta_k L = nu_k + delta_k` (k the elastic index) about nominal roots
/// `nu_k = c0 + k pi` exactly `pi` apart. Consecutive roots of every family approach `pi` apart
/// up to `exp(-beta L)` terms, so with `c0` taken from the highest root the offsets `delta_k`
/// fall below 1e-3 after the first one or two modes.
#[derive(Debug, Clone)]
struct NominalRoots {
    c0: f64,
    /// `delta` per mode index (0 for the rigid modes, which are not evaluated here).
    delta: Vec<f64>,
}

impl NominalRoots {
    fn new(shapes: &[Shape]) -> Self {
        let elastic: Vec<(usize, f64)> = shapes
            .iter()
            .enumerate()
            .filter_map(|(m, s)| {
                if let Shape::Elastic { bl, .. } = s {
                    Some((m, *bl))
                } else {
                    None
                }
            })
            .collect();
        let c0 = elastic
            .last()
            .map_or(0.0, |&(_, bl)| bl - (elastic.len() - 1) as f64 * PI);
        let mut delta = vec![0.0; shapes.len()];
        for (k, &(m, bl)) in elastic.iter().enumerate() {
            let d = bl - (c0 + k as f64 * PI);
            // offsets at the level of the roots' own rounding are exactly zero (no correction)
            delta[m] = if d.abs() <= 1e-14 * bl { 0.0 } else { d };
        }
        NominalRoots { c0, delta }
    }
}

/// `exp(-x)` for `|x| <= TAYLOR_DELTA`, to round-off.
#[inline]
fn exp_neg_small(x: f64) -> f64 {
    1.0 - x * (1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0))))
}

/// `sin(b xi)`, `cos(b xi)`, `exp(-b xi)`, `exp(-b (1 - xi))` of the elastic modes in order.
/// The nominal roots `nu_k` ([`NominalRoots`]) advance by one rotation by `pi xi` and two products
/// per mode; the offset `delta_k xi` is added by the angle-addition formulas with a Taylor series
/// (to round-off for `|delta| <= TAYLOR_DELTA`), and a mode with a larger offset (the first one
/// or two of some families) is evaluated directly. Two `sin_cos` and four `exp` per point instead
/// of one each per mode; the recurrence's rounding grows like k eps (2e-14 at N = 200, checked
/// against direct evaluation at N = 400 in the tests).
struct ModeTrig<'r> {
    roots: &'r NominalRoots,
    xi: f64,
    rot: (f64, f64),
    q: (f64, f64),
    /// The four values at the next nominal root.
    nominal: [f64; 4],
}

impl<'r> ModeTrig<'r> {
    fn new(xi: f64, roots: &'r NominalRoots) -> Self {
        let c0 = roots.c0;
        let (s0, co) = (c0 * xi).sin_cos();
        ModeTrig {
            roots,
            xi,
            rot: (PI * xi).sin_cos(),
            q: ((-PI * xi).exp(), (-PI * (1.0 - xi)).exp()),
            nominal: [s0, co, (-c0 * xi).exp(), (-c0 * (1.0 - xi)).exp()],
        }
    }

    /// The four values for mode `m` with root `bl`; elastic modes must come in order.
    #[inline]
    fn next(&mut self, m: usize, bl: f64) -> [f64; 4] {
        self.advance(self.roots.delta[m], bl)
    }

    /// [`ModeTrig::next`] for the next elastic mode, given its root offset `d` and root `bl`.
    #[inline(always)]
    fn advance(&mut self, d: f64, bl: f64) -> [f64; 4] {
        let [sn, cs, e1, e2] = self.nominal;
        let (rs, rc) = self.rot;
        let tiny = |e: f64, f: f64| if e > 1e-290 { e * f } else { 0.0 };
        self.nominal = [
            sn * rc + cs * rs,
            cs * rc - sn * rs,
            tiny(e1, self.q.0),
            tiny(e2, self.q.1),
        ];
        if d == 0.0 {
            [sn, cs, e1, e2]
        } else if d.abs() <= TAYLOR_DELTA {
            let x = d * self.xi;
            let x2 = x * x;
            let (sx, cx) = (x * (1.0 - x2 * (1.0 / 6.0)), 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0)));
            [
                sn * cx + cs * sx,
                cs * cx - sn * sx,
                e1 * exp_neg_small(x),
                e2 * exp_neg_small(d * (1.0 - self.xi)),
            ]
        } else {
            let (sn, cs) = (bl * self.xi).sin_cos();
            [sn, cs, (-bl * self.xi).exp(), (-bl * (1.0 - self.xi)).exp()]
        }
    }
}

/// Output slices of [`elastic_triplets`], all of the elastic modes' length.
struct TripletOut<'o> {
    left: &'o mut [f64],
    mid: &'o mut [f64],
    right: &'o mut [f64],
    slope: &'o mut [f64],
}

/// The elastic part of [`ModeSet::triplet_at`]: values at `x - h`, `x`, `x + h` and the slope at
/// `x` (unscaled by `s`, `sd` until stored), and with `BENT` the sums
/// `bend += [sum a_m phi_m'(x - h), sum a_m phi_m'(x + h), sum a_m phi_m''(x)]` over the elastic
/// modes (in units of `sd`, `sd`, `sd / L`). One pass over modes read in order, no bounds checks.
#[inline(never)]
fn elastic_triplets<const BENT: bool>(
    tri: &Triplet,
    mut trig: ModeTrig<'_>,
    out: TripletOut<'_>,
    alpha_eff: &[f64],
    s: f64,
    sd: f64,
    bend: &mut [f64; 3],
) {
    let n = out.mid.len();
    let (bl, c, f, delta) = (&tri.bl[..n], &tri.c[..n], &tri.f[..n], &tri.delta[..n]);
    let (left, mid, right, slope) = (
        &mut out.left[..n],
        &mut out.mid[..n],
        &mut out.right[..n],
        &mut out.slope[..n],
    );
    let alpha_eff = if BENT { &alpha_eff[..n] } else { &[][..] };
    let (mut sl, mut sr, mut cv) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let b = bl[k];
        let [sn, cs, e1, e2] = trig.advance(delta[k], b);
        let [c0, c1, c2, c3] = c[k];
        let [f0, f1, f2, f3] = f[k];
        let p = c0 * cs + c1 * sn;
        let q = c1 * cs - c0 * sn;
        let (g1, g2) = (c2 * e1, c3 * e2);
        mid[k] = (p + g1 + g2) * s;
        slope[k] = b * (q - g1 + g2) * sd;
        let (pc, qs) = (p * f0, q * f1);
        right[k] = (pc + qs + g1 * f2 + g2 * f3) * s;
        left[k] = (pc - qs + g1 * f3 + g2 * f2) * s;
        if BENT {
            let (qc, ps) = (q * f0, p * f1);
            let ba = b * alpha_eff[k];
            sr += ba * (qc - ps - g1 * f2 + g2 * f3);
            sl += ba * (qc + ps - g1 * f3 + g2 * f2);
            cv += b * ba * (g1 + g2 - p);
        }
    }
    bend[0] += sl;
    bend[1] += sr;
    bend[2] += cv;
}

/// Precomputed per-mode factors for evaluating the modes at `x - h`, `x`, `x + h` together
/// (the sleeve points of Eqs. 41-43, `h = Lp/2` fixed): `[cos(beta h), sin(beta h), exp(-beta h), exp(beta h)]`.
#[derive(Debug, Clone)]
pub(crate) struct Triplet {
    h: f64,
    /// Per elastic mode (in order, after the rigid ones): the factors above.
    f: Vec<[f64; 4]>,
    /// Per elastic mode: beta L, the stable-basis coefficients and the root offset (see
    /// [`NominalRoots`]), gathered so that the kernel reads them in order.
    bl: Vec<f64>,
    c: Vec<[f64; 4]>,
    delta: Vec<f64>,
}

impl ModeSet {
    /// Factors for [`ModeSet::triplet_at`] with half-width `h` [m].
    pub(crate) fn triplet(&self, h: f64) -> Triplet {
        let eta = h / self.l;
        let mut tri = Triplet {
            h,
            f: Vec::new(),
            bl: Vec::new(),
            c: Vec::new(),
            delta: Vec::new(),
        };
        for (m, sh) in self.shapes.iter().enumerate() {
            if let Shape::Elastic { bl, c, .. } = *sh {
                let (sn, cs) = (bl * eta).sin_cos();
                tri.f.push([cs, sn, (-bl * eta).exp(), (bl * eta).exp()]);
                tri.bl.push(bl);
                tri.c.push(c);
                tri.delta.push(self.roots.delta[m]);
            }
        }
        tri
    }

    /// `phi_m(x - h)`, `phi_m(x)`, `phi_m(x + h)` and `phi_m'(x)` for every mode [1/sqrt(m),
    /// 1/m^1.5], by angle addition with the factors of `tri`, the sin, cos and exponentials at x
    /// coming from the nominal-root recurrence of [`ModeTrig`] (two `sin_cos` and four `exp` per
    /// call). Needs `0 <= x - h`, `x + h <= L`. With `bent = (alpha, out)`, also the beam's
    /// bending at the sleeve, `w'(x - h)`, `w'(x + h)` and `w''(x)` for `w = sum alpha_m phi_m`
    /// (the full model's gradients of the sleeve rows in u, `docs/amm.md` section 8).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn triplet_at(
        &self,
        tri: &Triplet,
        x: f64,
        left: &mut [f64],
        mid: &mut [f64],
        right: &mut [f64],
        slope: &mut [f64],
        bent: Option<(&[f64], &mut SleeveBending)>,
    ) {
        let xi = x / self.l;
        let eta = tri.h / self.l;
        let s = 1.0 / self.l.sqrt();
        let sd = s / self.l;
        let na = self.analytic_len();
        // the bending outputs are dot products with the beam's modal coordinates; the junction
        // shapes' parts fold into effective coordinates of the analytic modes:
        // sum_m v_m a_m + sum_j v_(na+j) a_(na+j) with v_(na+j) = P_j - c_j . v
        // is sum_m v_m (a_m - sum_j a_(na+j) c_jm) + sum_j a_(na+j) P_j
        let mut bent = bent.map(|(alpha, bn)| {
            bn.alpha_eff.copy_from_slice(&alpha[..na]);
            for (j, sh) in self.junction.iter().enumerate() {
                let aj = alpha[na + j];
                for (e, c) in bn.alpha_eff.iter_mut().zip(&sh.c) {
                    *e -= aj * c;
                }
            }
            (alpha, bn)
        });
        // rigid modes (first), then the elastic ones
        let r0 = self.rigid;
        let mut bend = [0.0; 3];
        for (m, sh) in self.shapes[..r0].iter().enumerate() {
            if let Shape::Rigid { a, b } = *sh {
                mid[m] = (a + b * xi) * s;
                left[m] = (a + b * (xi - eta)) * s;
                right[m] = (a + b * (xi + eta)) * s;
                slope[m] = b * sd;
                if let Some((_, bn)) = bent.as_ref() {
                    bend[0] += b * bn.alpha_eff[m];
                    bend[1] += b * bn.alpha_eff[m];
                }
            }
        }
        let out = TripletOut {
            left: &mut left[r0..na],
            mid: &mut mid[r0..na],
            right: &mut right[r0..na],
            slope: &mut slope[r0..na],
        };
        let trig = ModeTrig::new(xi, &self.roots);
        match bent.as_ref() {
            Some((_, bn)) => elastic_triplets::<true>(tri, trig, out, &bn.alpha_eff[r0..na], s, sd, &mut bend),
            None => elastic_triplets::<false>(tri, trig, out, &[], s, sd, &mut bend),
        }
        let [mut sl, mut sr, mut cv] = bend;
        for (j, sh) in self.junction.iter().enumerate() {
            let c = &sh.c[..];
            let at = |z: f64| junction::poly_value_slope(sh.p, z);
            let ((pl, dl), (pm, dm), (pr, dr)) = (at(xi - eta), at(xi), at(xi + eta));
            left[na + j] = pl * s - dot(c, &left[..na]);
            mid[na + j] = pm * s - dot(c, &mid[..na]);
            right[na + j] = pr * s - dot(c, &right[..na]);
            slope[na + j] = dm * sd - dot(c, &slope[..na]);
            if let Some((alpha, _)) = bent.as_ref() {
                let aj = alpha[na + j];
                sl += aj * dl;
                sr += aj * dr;
                cv += aj * junction::poly_curvature(sh.p, xi);
            }
        }
        if let Some((_, bn)) = bent.as_mut() {
            // the analytic parts carry the factor sd (slopes) and sd / L (curvature) as well
            bn.slope_left = sl * sd;
            bn.slope_right = sr * sd;
            bn.curvature = cv * sd / self.l;
        }
    }

    /// Geometric stiffness of the axial inertia force (Eq. 23, full model; `docs/amm.md`
    /// section 8): with `N(x) = rho [th'^2 (L^2 - x^2)/2 - a_x (L - x)]`, the tension of the part
    /// of the beam between x and the free tip, `int N phi_j' phi_m' dx = rho (th'^2 G1 - a_x G2)`.
    /// Returns `(G1, G2)`, row-major N x N: `G1_jm = int (L^2 - x^2)/2 phi_j' phi_m' dx` [-] and
    /// `G2_jm = int (L - x) phi_j' phi_m' dx` [1/m].
    pub fn axial_stiffening(&self) -> (Vec<f64>, Vec<f64>) {
        let all: Vec<usize> = (0..self.len()).collect();
        self.axial_stiffening_on(&all)
    }

    /// [`ModeSet::axial_stiffening`] on the modes `on` (indices, k of them): `(G1, G2)` k x k,
    /// row-major, entry (a, b) for the modes `on[a]`, `on[b]`.
    pub fn axial_stiffening_on(&self, on: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let n = on.len();
        let (x, w) = junction::composite_rule(junction::panels_for(self.analytic_beta_max()));
        let nq = x.len();
        // slopes at the nodes (column q: the modes `on` at node q), and the same columns weighted
        // by the two axial force profiles: G = D diag(f) D^T, two matrix products
        let mut d = Mat::<f64>::zeros(n, nq);
        let mut d1 = Mat::<f64>::zeros(n, nq);
        let mut d2 = Mat::<f64>::zeros(n, nq);
        let mut slope = vec![0.0; self.len()];
        for (q, (&xi, &wq)) in x.iter().zip(&w).enumerate() {
            let xm = xi * self.l;
            self.slopes_at(xm, &mut slope);
            let col = d.col_mut(q).try_as_col_major_mut().expect("contiguous").as_slice_mut();
            for (c, &m) in col.iter_mut().zip(on) {
                *c = slope[m];
            }
            // dx = L dxi
            let f1 = wq * self.l * 0.5 * (self.l * self.l - xm * xm);
            let f2 = wq * self.l * (self.l - xm);
            let col = d.col(q).try_as_col_major().expect("contiguous").as_slice();
            for (f, dk) in [(f1, &mut d1), (f2, &mut d2)] {
                let out = dk.col_mut(q).try_as_col_major_mut().expect("contiguous").as_slice_mut();
                for (o, v) in out.iter_mut().zip(col) {
                    *o = f * v;
                }
            }
        }
        let product = |weighted: &Mat<f64>| {
            let mut g = Mat::<f64>::zeros(n, n);
            matmul(
                g.as_mut(),
                Accum::Replace,
                d.as_ref(),
                weighted.transpose(),
                1.0,
                Par::Seq,
            );
            // row-major, exactly symmetric
            let mut out = vec![0.0; n * n];
            for j in 0..n {
                for m in 0..n {
                    out[j * n + m] = 0.5 * (g[(j, m)] + g[(m, j)]);
                }
            }
            out
        };
        (product(&d1), product(&d2))
    }
}

/// The full model's bending of one beam at its sleeve (see [`ModeSet::triplet_at`]): with
/// `w = sum alpha_m phi_m`, the slopes `w'(x - h)`, `w'(x + h)` [-] and the curvature `w''(x)`
/// [1/m] (the gradients of the sleeve rows in u, `docs/amm.md` section 8).
#[derive(Debug, Clone, Default)]
pub(crate) struct SleeveBending {
    pub(crate) slope_left: f64,
    pub(crate) slope_right: f64,
    pub(crate) curvature: f64,
    /// Workspace: the modal coordinates of the analytic modes with the junction shapes' parts folded in.
    alpha_eff: Vec<f64>,
}

impl SleeveBending {
    /// Workspace for a set whose analytic modes number `n_analytic`.
    pub(crate) fn new(n_analytic: usize) -> Self {
        SleeveBending {
            alpha_eff: vec![0.0; n_analytic],
            ..SleeveBending::default()
        }
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
