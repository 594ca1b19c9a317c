//! Undamped vibration modes of a constrained linear system, shared by the AMM and the FEM:
//!
//! ```text
//! M q'' + K q = 0,   C q = 0        (M, K symmetric n x n; C r x n of full row rank)
//! ```
//!
//! The constraints are eliminated on their null space (Householder QR of `C^T`:
//! `C^T = Q [R; 0]`, `q = Z y` with `Z` the last `n - r` columns of `Q`), which leaves the
//! generalised symmetric problem `Z^T K Z y = omega^2 Z^T M Z y` (massless coordinates are
//! allowed as long as the constraints fix them), reduced to a standard one with the Cholesky
//! factor of the shifted stiffness (see [`constrained_modes`]) and solved densely with faer.

use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Mat, MatRef, Par, Side};

use crate::NumericsError;

/// Modes of the star at a pose, from either solver (`S`: the solver's assembled system).
#[derive(Debug, Clone)]
pub struct PoseModes<S> {
    /// Natural frequencies [Hz], ascending (rigid modes set to 0, see `rigid`).
    pub freq_hz: Vec<f64>,
    /// `omega^2` [1/s^2] of the same modes (rigid ones set to 0).
    pub omega2: Vec<f64>,
    /// Mass-normalised shapes in the coordinates of the system.
    pub shapes: Vec<Vec<f64>>,
    /// Number of leading rigid (zero-frequency) modes: 3 with free sliders, 0 locked.
    pub rigid: usize,
    /// The system they belong to.
    pub system: S,
}

impl<S> PoseModes<S> {
    /// From `omega^2` and shapes: frequencies in Hz, the first `rigid` modes (round-off size
    /// by construction) set to exactly 0.
    pub fn new(mut omega2: Vec<f64>, shapes: Vec<Vec<f64>>, rigid: usize, system: S) -> Self {
        omega2.iter_mut().take(rigid).for_each(|w| *w = 0.0);
        let freq_hz = omega2
            .iter()
            .map(|w| w.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        PoseModes {
            freq_hz,
            omega2,
            shapes,
            rigid,
            system,
        }
    }
}

/// Modes of a constrained system, lowest first.
#[derive(Debug, Clone)]
pub struct ConstrainedModes {
    /// Squared circular frequencies `omega^2` [rad^2/s^2], ascending; zero-energy (rigid) modes
    /// come out at round-off size and may be slightly negative.
    pub omega2: Vec<f64>,
    /// Shapes in the full coordinates (`C x = 0`), mass-normalised (`x^T M x = 1`), one per
    /// requested mode.
    pub shapes: Vec<Vec<f64>>,
    /// Number of independent constraint rows eliminated.
    pub rank: usize,
}

impl ConstrainedModes {
    /// Natural frequencies [Hz] of the first modes (`sqrt(max(omega^2, 0)) / 2 pi`).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega2
            .iter()
            .map(|w| w.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }
}

/// The shift for [`constrained_modes`] in the robot's modal analyses: 0 with locked sliders (no
/// rigid mode), `(2 pi 0.1 Hz)^2` with free sliders (below the first elastic frequency of any
/// sensible robot; the rigid modes then come out at round-off size).
pub fn rigid_shift(sliders_free: bool) -> f64 {
    if sliders_free {
        (2.0 * std::f64::consts::PI * 0.1).powi(2)
    } else {
        0.0
    }
}

/// One Householder reflector `H = I - 2 v v^T` (`|v| = 1`) acting on coordinates `start..n`.
struct Reflector {
    start: usize,
    v: Vec<f64>,
}

impl Reflector {
    /// `x <- H x`.
    fn apply_vec(&self, x: &mut [f64]) {
        let tail = &mut x[self.start..];
        let s: f64 = tail.iter().zip(&self.v).map(|(a, b)| a * b).sum();
        for (a, b) in tail.iter_mut().zip(&self.v) {
            *a -= 2.0 * s * b;
        }
    }

    /// `A <- H A H` for a symmetric dense `A` (both sides, so `A` stays symmetric).
    fn apply_both(&self, a: &mut Mat<f64>) {
        let (s, m) = (self.start, self.v.len());
        let v = faer::ColRef::from_slice(&self.v);
        // left: rows s.. -= 2 v (v^T A[s.., :])
        let w: faer::Row<f64> = v.transpose() * a.as_ref().subrows(s, m);
        let mut rows = a.as_mut().subrows_mut(s, m);
        rows -= (2.0 * v) * &w;
        // right: cols s.. -= 2 (A[:, s..] v) v^T
        let z: faer::Col<f64> = a.as_ref().subcols(s, m) * v;
        let mut cols = a.as_mut().subcols_mut(s, m);
        cols -= &z * (2.0 * v.transpose());
    }
}

/// Householder QR of `C^T` (`c`: r x n, row-major): the reflectors, and the number of rows
/// kept. Fails when a row is (numerically) a combination of the others.
fn null_space_reflectors(n: usize, c: &[f64], rows: usize) -> Result<Vec<Reflector>, NumericsError> {
    // columns of C^T = rows of C
    let mut cols: Vec<Vec<f64>> = c.chunks_exact(n).map(|r| r.to_vec()).collect();
    let scale = cols
        .iter()
        .map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0f64, f64::max);
    let mut refl = Vec::with_capacity(rows);
    for j in 0..rows {
        let x = &cols[j][j..];
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 1e-11 * scale {
            return Err(NumericsError::DependentRow { row: j + 1, rows, norm });
        }
        let alpha = if x[0] > 0.0 { -norm } else { norm };
        let mut v = x.to_vec();
        v[0] -= alpha;
        let vn = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        v.iter_mut().for_each(|a| *a /= vn);
        let h = Reflector { start: j, v };
        for col in cols.iter_mut().skip(j) {
            h.apply_vec(col);
        }
        refl.push(h);
    }
    Ok(refl)
}

/// The first `count` modes (all if `count` exceeds the free coordinates) of `M q'' + K q = 0`
/// with `C q = 0`. `m`, `k`: n x n row-major (symmetrised here); `c`: `rows` x n row-major.
///
/// `shift` (sigma [1/s^2], >= 0) must make `K + sigma M` positive definite on the constrained
/// motions: 0 when K alone is (no rigid modes), otherwise a value of the order of the first
/// nonzero `omega^2` or below. The problem is solved in its inverse form
/// `L^-1 M L^-T z = mu z` with `K + sigma M = L L^T` and `omega^2 = 1/mu - sigma`: the lowest modes
/// are the largest `mu`, computed to a precision relative to the fundamental (the direct form
/// `L_M^-1 K L_M^-T` loses them when M is ill-conditioned, as a FEM mass matrix with rotational
/// degrees of freedom is). Coordinates are scaled by `1/sqrt(M_ii)` (Jacobi) first.
///
/// Errors ([`NumericsError`], the caller adds when and where): dependent constraint rows, `K + sigma M` not
/// positive definite on the constrained motions, an eigensolver failure, non-finite input.
pub fn constrained_modes(
    n: usize,
    m: &[f64],
    k: &[f64],
    c: &[f64],
    rows: usize,
    count: usize,
    shift: f64,
) -> Result<ConstrainedModes, NumericsError> {
    check_inputs(n, m, k, c, rows, shift)?;
    // Jacobi scaling q = D q~ (massless coordinates keep scale 1)
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let mii = m[i * n + i];
            if mii > 0.0 {
                1.0 / mii.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let cs: Vec<f64> = c.iter().enumerate().map(|(idx, v)| v * d[idx % n]).collect();
    let refl = null_space_reflectors(n, &cs, rows)?;
    let scaled = |a: &[f64]| Mat::from_fn(n, n, |i, j| 0.5 * (a[i * n + j] + a[j * n + i]) * d[i] * d[j]);
    let (mut mq, mut kq) = (scaled(m), scaled(k));
    for h in &refl {
        h.apply_both(&mut mq);
        h.apply_both(&mut kq);
    }
    let p = n - rows;
    let mr = mq.as_ref().submatrix(rows, rows, p, p).to_owned();
    let kr = kq.as_ref().submatrix(rows, rows, p, p);
    let ks = Mat::from_fn(p, p, |i, j| kr[(i, j)] + shift * mr[(i, j)]);
    let llt = ks
        .llt(Side::Lower)
        .map_err(|source| NumericsError::NotPositiveDefinite { shift, source })?;
    let l = llt.L();
    let (mu, z) = inverse_form_modes(l, mr, count.min(p))?;
    let omega2: Vec<f64> = mu.iter().map(|&mu| 1.0 / mu - shift).collect();
    // shapes: x_r = L^-T z / sqrt(mu) (mass-normalised), x = D Q [0; x_r]
    let mut y = z;
    solve_upper_triangular_in_place(l.transpose(), y.as_mut(), Par::Seq);
    let shapes = mu
        .iter()
        .enumerate()
        .map(|(j, &mu)| {
            let scale = 1.0 / mu.sqrt();
            let mut x = vec![0.0; n];
            for (r, xr) in x[rows..].iter_mut().enumerate() {
                *xr = y[(r, j)] * scale;
            }
            for h in refl.iter().rev() {
                h.apply_vec(&mut x);
            }
            x.iter_mut().zip(&d).for_each(|(a, b)| *a *= b);
            x
        })
        .collect();
    Ok(ConstrainedModes {
        omega2,
        shapes,
        rank: rows,
    })
}

/// The sizes and finiteness of [`constrained_modes`]' input.
fn check_inputs(n: usize, m: &[f64], k: &[f64], c: &[f64], rows: usize, shift: f64) -> Result<(), NumericsError> {
    if m.len() != n * n || k.len() != n * n || c.len() != rows * n || rows >= n {
        return Err(NumericsError::Sizes {
            n,
            m: m.len(),
            k: k.len(),
            c: c.len(),
            rows,
        });
    }
    if m.iter().chain(k).chain(c).any(|v| !v.is_finite()) || shift.is_nan() || shift < 0.0 {
        return Err(NumericsError::NonFinite);
    }
    Ok(())
}

/// The `count` largest eigenvalues mu (largest first) and their eigenvectors z (columns) of the
/// inverse form `S = L^-1 Mr L^-T` (symmetrised), with `L` the Cholesky factor of `K + sigma M`.
fn inverse_form_modes(l: MatRef<'_, f64>, mr: Mat<f64>, count: usize) -> Result<(Vec<f64>, Mat<f64>), NumericsError> {
    let p = mr.nrows();
    let mut s = mr;
    solve_lower_triangular_in_place(l, s.as_mut(), Par::Seq);
    let mut st = s.transpose().to_owned();
    solve_lower_triangular_in_place(l, st.as_mut(), Par::Seq);
    let sym = Mat::from_fn(p, p, |i, j| 0.5 * (st[(i, j)] + st[(j, i)]));
    let eig = sym
        .self_adjoint_eigen(Side::Lower)
        .map_err(|cause| NumericsError::Eigensolver {
            what: "symmetric eigensolver",
            cause,
        })?;
    // largest mu first
    let order: Vec<usize> = (0..count).map(|j| p - 1 - j).collect();
    let mu = order.iter().map(|&j| eig.S()[j]).collect();
    let z = Mat::from_fn(p, count, |r, j| eig.U()[(r, order[j])]);
    Ok((mu, z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixed-fixed chain of `n` unit masses and unit springs, written as a free-free chain of
    /// n + 2 masses with the two end masses held by constraints: the textbook frequencies are
    /// `omega_j = 2 sin(j pi / (2 (n + 1)))`, j = 1..n.
    #[test]
    fn constrained_chain_matches_textbook() {
        let n = 12;
        let nt = n + 2;
        let mut k = vec![0.0; nt * nt];
        for e in 0..nt - 1 {
            for (a, b, v) in [(e, e, 1.0), (e + 1, e + 1, 1.0), (e, e + 1, -1.0), (e + 1, e, -1.0)] {
                k[a * nt + b] += v;
            }
        }
        let mut m = vec![0.0; nt * nt];
        for i in 0..nt {
            m[i * nt + i] = 1.0;
        }
        // constraints written as mixtures (q0 + q_last = 0, q0 - q_last = 0): same null space
        let mut c = vec![0.0; 2 * nt];
        c[0] = 1.0;
        c[nt - 1] = 1.0;
        c[nt] = 1.0;
        c[2 * nt - 1] = -1.0;
        let modes = constrained_modes(nt, &m, &k, &c, 2, n, 0.0).unwrap();
        for (j, w2) in modes.omega2.iter().enumerate() {
            let exact = 2.0 * ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0))).sin();
            assert!((w2.sqrt() - exact).abs() < 1e-12, "mode {j}: {} vs {exact}", w2.sqrt());
        }
        // shapes satisfy the constraints and are mass-normalised
        for x in &modes.shapes {
            assert!(x[0].abs() < 1e-13 && x[nt - 1].abs() < 1e-13);
            let mass: f64 = x.iter().map(|v| v * v).sum();
            assert!((mass - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn dependent_constraints_are_refused() {
        let n = 3;
        let m = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let k = m;
        let c = [1.0, 1.0, 0.0, 2.0, 2.0, 0.0];
        let err = constrained_modes(n, &m, &k, &c, 2, 1, 0.0).unwrap_err();
        assert!(
            matches!(err, NumericsError::DependentRow { row: 2, rows: 2, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("combination"), "{err}");
    }
}
