//! The junction shapes of the enriched family (`docs/amm.md` section 7).
//!
//! Free-free modes have `w'' = w''' = 0` at G, so no combination of them carries the bending moment
//! and shear that the weld at G transmits: the AMM reaches those forces only as N grows (a natural
//! boundary condition that the true solution violates). The enriched family adds two functions that
//! leave the tip free but not G, `(1 - xi)^4` and `(1 - xi)^5` (xi = x/L), to the first N - 2
//! free-free modes, and diagonalises mass and stiffness over the span by Rayleigh-Ritz:
//!
//! - the free-free modes are exact eigenfunctions of the free beam, so they are Ritz vectors of the
//!   enlarged space unchanged (for any v in the span, `v^T K phi = lambda v^T M phi`);
//! - the two new Ritz vectors are M-orthogonal (hence K-orthogonal, same argument) to every kept
//!   mode: the polynomials minus their projections on the kept modes (projected twice, classical
//!   Gram-Schmidt with reorthogonalisation, so orthogonality holds to round-off even when the
//!   remainder is 1e-7 of the polynomial, as at N = 200), combined by the 2 x 2 generalized
//!   eigenproblem of their mass and stiffness Gram matrices.
//!
//! So the solver keeps its structure (unit mass, diagonal stiffness per beam). Integrals are
//! computed with a composite 5-point Gauss-Legendre rule on panels of width at most a sixth of the
//! shortest half-wavelength of the kept modes.

/// One junction shape on the unit interval:
/// `H(xi) = p[0] (1 - xi)^4 + p[1] (1 - xi)^5 - sum_k c[k] Phi_k(xi)`, unit L2 norm on [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JunctionShape {
    /// Coefficients of `(1 - xi)^4` and `(1 - xi)^5`.
    pub(crate) p: [f64; 2],
    /// Coefficients of the kept modes subtracted (projection).
    pub(crate) c: Vec<f64>,
    /// Dimensionless stiffness `int H''^2 dxi` (Ritz value; lambda = EI/rho * mu / L^4).
    pub(crate) mu: f64,
}

/// Exponents of the two enrichment polynomials in (1 - xi).
const POWERS: [i32; 2] = [4, 5];

/// `d^k/dxi^k (1 - xi)^n` for k = 0..=3.
pub(crate) fn poly_derivatives(n: i32, xi: f64) -> [f64; 4] {
    let y = 1.0 - xi;
    let nf = n as f64;
    [
        y.powi(n),
        -nf * y.powi(n - 1),
        nf * (nf - 1.0) * y.powi(n - 2),
        -nf * (nf - 1.0) * (nf - 2.0) * y.powi(n - 3),
    ]
}

/// `[H, H', H'', H''']` of a junction shape at xi, given the kept modes' derivatives there
/// (`kept[k] = [Phi_k, Phi_k', Phi_k'', Phi_k''']`).
pub(crate) fn eval(shape: &JunctionShape, xi: f64, kept: &[[f64; 4]]) -> [f64; 4] {
    let mut out = [0.0; 4];
    for (pa, n) in shape.p.iter().zip(POWERS) {
        let d = poly_derivatives(n, xi);
        for k in 0..4 {
            out[k] += pa * d[k];
        }
    }
    for (ck, v) in shape.c.iter().zip(kept) {
        for k in 0..4 {
            out[k] -= ck * v[k];
        }
    }
    out
}

/// Polynomial part `p[0] (1 - xi)^4 + p[1] (1 - xi)^5` and its first derivative.
#[inline]
pub(crate) fn poly_value_slope(p: [f64; 2], xi: f64) -> (f64, f64) {
    let y = 1.0 - xi;
    let (y3, y4) = (y * y * y, y * y * y * y);
    (p[0] * y4 + p[1] * y4 * y, -4.0 * p[0] * y3 - 5.0 * p[1] * y4)
}

/// Second derivative of the polynomial part.
#[inline]
pub(crate) fn poly_curvature(p: [f64; 2], xi: f64) -> f64 {
    let y = 1.0 - xi;
    12.0 * p[0] * y * y + 20.0 * p[1] * y * y * y
}

/// Points per panel of [`composite_rule`].
const PANEL_POINTS: usize = 10;

/// Nodes and weights of the composite 10-point Gauss-Legendre rule on [0, 1] with `panels` panels.
pub(crate) fn composite_rule(panels: usize) -> (Vec<f64>, Vec<f64>) {
    let (pts, wts) = flexstar_numerics::quadrature::gauss_legendre_rule(PANEL_POINTS);
    let h = 1.0 / panels as f64;
    let mut x = Vec::with_capacity(PANEL_POINTS * panels);
    let mut w = Vec::with_capacity(PANEL_POINTS * panels);
    for k in 0..panels {
        let a = k as f64 * h;
        for (p, wt) in pts.iter().zip(&wts) {
            x.push(a + 0.5 * h * (p + 1.0));
            w.push(0.5 * h * wt);
        }
    }
    (x, w)
}

/// Panels for products of functions up to the dimensionless wavenumber `b_max` (wavenumber
/// `2 b_max`): panels of width `h` with `2 b_max h <= 1.5 pi`. The n-point Gauss error on a panel
/// is `f^(2n) h^(2n+1) (n!)^4 / ((2n + 1) ((2n)!)^3)`; for `e^(i k x)` with `k h = 1.5 pi` and
/// n = 10 that is `(k h)^20 * 5.8e-31 = 2e-17` of the panel's integral. At least four panels.
pub(crate) fn panels_for(b_max: f64) -> usize {
    ((b_max / (0.75 * std::f64::consts::PI)).ceil() as usize).max(4)
}

/// Build the two junction shapes against the `nk` kept modes, given their values `phi` and
/// second derivatives `phi2` at the nodes `x` (weights `w`; row-major, row q = node q) of a rule
/// that integrates products of them exactly to round-off.
pub(crate) fn build(x: &[f64], w: &[f64], phi: &[f64], phi2: &[f64], nk: usize) -> [JunctionShape; 2] {
    let nq = x.len();
    let (phi, phi2): (Vec<&[f64]>, Vec<&[f64]>) = (
        phi.chunks_exact(nk.max(1)).take(nq).collect(),
        phi2.chunks_exact(nk.max(1)).take(nq).collect(),
    );
    // remainders r_a at the nodes (value and second derivative), and their total projections
    let mut r = [vec![0.0; nq], vec![0.0; nq]];
    let mut r2 = [vec![0.0; nq], vec![0.0; nq]];
    let mut coef = [vec![0.0; nk], vec![0.0; nk]];
    for a in 0..2 {
        for q in 0..nq {
            let d = poly_derivatives(POWERS[a], x[q]);
            r[a][q] = d[0];
            r2[a][q] = d[2];
        }
        for _pass in 0..2 {
            let mut c = vec![0.0; nk];
            for q in 0..nq {
                let wr = w[q] * r[a][q];
                for (ck, pk) in c.iter_mut().zip(phi[q]) {
                    *ck += wr * pk;
                }
            }
            for q in 0..nq {
                r[a][q] -= super::dot(&c, phi[q]);
                r2[a][q] -= super::dot(&c, phi2[q]);
            }
            for (t, ck) in coef[a].iter_mut().zip(&c) {
                *t += ck;
            }
        }
    }
    // mass and stiffness Gram matrices of the remainders
    let gram = |u: &[Vec<f64>; 2]| {
        let mut g = [[0.0; 2]; 2];
        for a in 0..2 {
            for b in 0..2 {
                g[a][b] = (0..nq).map(|q| w[q] * u[a][q] * u[b][q]).sum();
            }
        }
        g
    };
    let (m, k) = (gram(&r), gram(&r2));
    let (t, mu) = ritz_2x2(m, k);
    std::array::from_fn(|j| JunctionShape {
        p: [t[0][j], t[1][j]],
        c: (0..nk)
            .map(|kk| t[0][j] * coef[0][kk] + t[1][j] * coef[1][kk])
            .collect(),
        mu: mu[j],
    })
}

/// Generalized symmetric 2 x 2 eigenproblem `K v = mu M v`, M positive definite: columns of `t`
/// are the eigenvectors with `t^T M t = I`, ascending `mu`.
fn ritz_2x2(m: [[f64; 2]; 2], k: [[f64; 2]; 2]) -> ([[f64; 2]; 2], [f64; 2]) {
    // Cholesky M = L L^T
    let l11 = m[0][0].sqrt();
    let l21 = m[1][0] / l11;
    let l22 = (m[1][1] - l21 * l21).sqrt();
    // C = L^-1 K L^-T
    let li = [[1.0 / l11, 0.0], [-l21 / (l11 * l22), 1.0 / l22]];
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            let mut s = 0.0;
            for a in 0..2 {
                for b in 0..2 {
                    s += li[i][a] * k[a][b] * li[j][b];
                }
            }
            c[i][j] = s;
        }
    }
    let c01 = 0.5 * (c[0][1] + c[1][0]);
    // Jacobi rotation
    let (theta, mu) = if c01 == 0.0 {
        (0.0, [c[0][0], c[1][1]])
    } else {
        let th = 0.5 * (2.0 * c01).atan2(c[0][0] - c[1][1]);
        let (s, co) = th.sin_cos();
        let a = co * co * c[0][0] + 2.0 * s * co * c01 + s * s * c[1][1];
        let b = s * s * c[0][0] - 2.0 * s * co * c01 + co * co * c[1][1];
        (th, [a, b])
    };
    let (s, co) = theta.sin_cos();
    let v = [[co, -s], [s, co]]; // columns: eigenvectors of C for mu[0], mu[1]
    let mut t = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            t[i][j] = li[0][i] * v[0][j] + li[1][i] * v[1][j];
        }
    }
    if mu[0] <= mu[1] {
        (t, mu)
    } else {
        ([[t[0][1], t[0][0]], [t[1][1], t[1][0]]], [mu[1], mu[0]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ritz_2x2_diagonalises() {
        let m = [[2.0, 0.3], [0.3, 1.0]];
        let k = [[5.0, -1.0], [-1.0, 3.0]];
        let (t, mu) = ritz_2x2(m, k);
        for i in 0..2 {
            for j in 0..2 {
                let (mut tm, mut tk) = (0.0, 0.0);
                for a in 0..2 {
                    for b in 0..2 {
                        tm += t[a][i] * m[a][b] * t[b][j];
                        tk += t[a][i] * k[a][b] * t[b][j];
                    }
                }
                let want_m = if i == j { 1.0 } else { 0.0 };
                let want_k = if i == j { mu[i] } else { 0.0 };
                assert!((tm - want_m).abs() < 1e-14 && (tk - want_k).abs() < 1e-13, "{i}{j}");
            }
        }
        // det(K - mu M) = 0 for both (characteristic polynomial, independent of the rotation)
        for &x in &mu {
            let det = (k[0][0] - x * m[0][0]) * (k[1][1] - x * m[1][1]) - (k[0][1] - x * m[0][1]).powi(2);
            assert!(det.abs() < 1e-12, "{det}");
        }
        assert!(mu[0] < mu[1]);
    }

    #[test]
    fn poly_derivatives_match_finite_differences() {
        for n in POWERS {
            for xi in [0.0, 0.3, 0.9] {
                let d = poly_derivatives(n, xi);
                let h = 1e-5;
                for k in 0..3 {
                    let fd = (poly_derivatives(n, xi + h)[k] - poly_derivatives(n, xi - h)[k]) / (2.0 * h);
                    assert!(
                        (fd - d[k + 1]).abs() < 1e-6 * (1.0 + d[k + 1].abs()),
                        "n={n} xi={xi} k={k}"
                    );
                }
            }
        }
    }
}
