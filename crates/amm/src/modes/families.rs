//! The four mode families: boundary conditions at G, characteristic equations and their roots,
//! and the stable-basis shape of each mode.

use super::*;

/// Boundary conditions at G as derivative orders (Eq. 34-1).
pub(super) fn orders_at_g(family: ModeFamily) -> [usize; 2] {
    match family {
        ModeFamily::ClampedFree => [0, 1],
        ModeFamily::PinnedFree => [0, 2],
        ModeFamily::SlideFree => [1, 3],
        ModeFamily::FreeFree | ModeFamily::Enriched => [2, 3],
    }
}

/// Rigid modes of a family on the unit interval, orthonormal: `(a, b)` of `Phi = a + b xi`.
pub(super) fn rigid_modes(family: ModeFamily) -> &'static [(f64, f64)] {
    const S3: f64 = 1.732_050_807_568_877_2;
    match family {
        ModeFamily::ClampedFree => &[],
        ModeFamily::PinnedFree => &[(0.0, S3)],
        ModeFamily::SlideFree => &[(1.0, 0.0)],
        ModeFamily::FreeFree | ModeFamily::Enriched => &[(1.0, 0.0), (-S3, 2.0 * S3)],
    }
}

pub(super) fn sech(b: f64) -> f64 {
    if b > 700.0 {
        0.0
    } else {
        2.0 * (-b).exp() / (1.0 + (-2.0 * b).exp())
    }
}

/// Characteristic function of the family in a form with O(1) terms (no cancellation).
pub(super) fn characteristic(family: ModeFamily, b: f64) -> f64 {
    let (s, c) = b.sin_cos();
    match family {
        ModeFamily::ClampedFree => c + sech(b),
        ModeFamily::FreeFree | ModeFamily::Enriched => c - sech(b),
        ModeFamily::PinnedFree => s - c * b.tanh(),
        ModeFamily::SlideFree => s + c * b.tanh(),
    }
}

/// Asymptotic estimate of the n-th elastic root b_n (n = 1, 2, ...).
pub(super) fn asymptote(family: ModeFamily, n: usize) -> f64 {
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
pub(super) fn elastic_root(family: ModeFamily, n: usize) -> Result<f64, AmmError> {
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
pub(super) fn basis_row(bl: f64, xi: f64, k: usize) -> [f64; 4] {
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

pub(super) fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Null vector of a 4x4 matrix of rank 3: the generalized cross product of the three rows whose
/// product is largest (cofactor expansion; the rows are O(1), so this is accurate to round-off).
pub(super) fn null_vector(a: [[f64; 4]; 4]) -> [f64; 4] {
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
pub(super) fn gram(bl: f64) -> [[f64; 4]; 4] {
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
    pub(super) fn eval(&self, xi: f64) -> [f64; 4] {
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
    pub(super) fn eval_from(&self, trig: [f64; 4], xi: f64) -> [f64; 4] {
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

/// The inputs of [`ModeSet::new`]: `1 <= n <= MAX_MODES` (`n >= 4` for the enriched family)
/// and positive finite EI, rho and L; the error names the key.
pub(super) fn check_inputs(family: ModeFamily, n: usize, params: &RobotParams) -> Result<(), AmmError> {
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
    if family == ModeFamily::Enriched && n < 4 {
        return Err(AmmError::invalid(
            "amm.modes",
            format!("the enriched family needs N >= 4 (two rigid modes, at least two elastic modes or junction shapes), got {n}"),
        ));
    }
    Ok(())
}

/// The first `n_analytic` shapes of `family` on the unit interval: its rigid modes, then the
/// elastic ones in the order of their roots.
pub(super) fn analytic_shapes(family: ModeFamily, n_analytic: usize) -> Result<Vec<Shape>, AmmError> {
    let mut shapes = Vec::with_capacity(n_analytic);
    for &(a, b) in rigid_modes(family).iter().take(n_analytic) {
        shapes.push(Shape::Rigid { a, b });
    }
    let orders = orders_at_g(family);
    let mut k = 1;
    while shapes.len() < n_analytic {
        shapes.push(elastic_shape(elastic_root(family, k)?, orders));
        k += 1;
    }
    Ok(shapes)
}

/// The elastic mode of root `bl = beta L` in the stable basis: the null vector of the boundary
/// conditions at G (derivative `orders`) and of the free tip, scaled to unit norm on the unit
/// interval and a positive tip value.
fn elastic_shape(bl: f64, orders: [usize; 2]) -> Shape {
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
    Shape::Elastic { bl, c, e }
}

impl Shape {
    /// `(beta L, int_0^1 Phi dxi, int_0^1 xi Phi dxi)`; for elastic modes from the ODE and the
    /// free tip: `int Phi = -Phi'''(0)/b^4`, `int xi Phi = Phi''(0)/b^4`.
    pub(super) fn unit_integrals(&self) -> (f64, f64, f64) {
        match *self {
            Shape::Rigid { a, b } => (0.0, a + 0.5 * b, 0.5 * a + b / 3.0),
            Shape::Elastic { bl, .. } => {
                let v = self.eval(0.0);
                let b4 = bl.powi(4);
                (bl, -v[3] / b4, v[2] / b4)
            }
        }
    }
}
