//! Lowest modes of the constrained FEM at a pose without a dense null-space basis
//! (`docs/modes.md`, speed): shift-invert subspace iteration on the bordered (saddle-point) system
//!
//! ```text
//! [K + sigma M   Phi_q^T] [y]   [M x]
//! [Phi_q            0   ] [l] = [ 0 ]
//! ```
//! factored once by the sparse LU of the time-domain solver ([`crate::sparse::SparseLu`]). Its
//! `y` is `(K + sigma M)^-1 M x` restricted to the constrained motions (`Phi_q y = 0`), the
//! operator whose largest eigenvalues `1 / (omega^2 + sigma)` are the lowest modes: the same
//! inverse form as the dense path ([`flexstar_numerics::eigen::constrained_modes`]).
//!
//! Each iteration (Bathe's subspace iteration with Rayleigh-Ritz): `Y = Op X`, `Y = Q R` with `Q`
//! M-orthonormal (modified Gram-Schmidt, twice), projected stiffness
//! `Q^T (K + sigma M) Q = Q^T M X R^-1` (from `(K + sigma M) Y = M X`: only mass products, none of
//! the stiff axial terms whose cancellation loses the low modes' digits), its symmetric
//! eigenproblem (faer), `X = Q Z`. Once the requested Ritz values change by less than [`TOL`]
//! relative in one iteration (or stagnate at their round-off floor, [`STAGNANT`]), half as many
//! iterations again refine the shapes.

use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, MatRef, Par, Side};
use flexstar_numerics::eigen::ConstrainedModes;

use crate::error::LinearError;
use crate::sparse::SparseLu;

/// Relative change of the requested Ritz values `omega^2 + sigma` in one iteration below which
/// they count as converged: above their round-off floor (1e-9 to 3e-9 relative for the robot at
/// 150 elements, from the bordered system's condition: axial `EA/h` against `rho h omega^2`).
/// Ritz values converge twice as fast as the vectors, so the iteration then runs half as many
/// iterations again (plus one) for the shapes: they then lie in the dense path's span to 1e-10
/// (M-norm; 2e-11 locked, 4e-10 free), their round-off floor (test `sparse_and_dense_paths_agree`).
pub const TOL: f64 = 1e-8;
/// A Ritz value whose change is below this (relative) and no longer decreases geometrically
/// (at least 0.3 of the previous change) has reached its round-off floor: converged. (With a
/// heavy sleeve, Jp = 1e3 kg m^2, the rocking modes at 0.01 Hz never reach [`TOL`].)
pub const STAGNANT: f64 = 1e-6;
/// Iterations allowed before the solver gives up (convergence is geometric, with rate
/// `(omega_k^2 + sigma) / (omega_{p+1}^2 + sigma)`, ~0.02 per iteration for the robot).
pub const MAX_ITER: usize = 200;

/// A sparse matrix as (row, column, value) triplets, duplicates summed.
pub type Triplets = Vec<(usize, usize, f64)>;

/// `y = A x` for a triplet matrix.
fn mul(a: &Triplets, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for &(r, c, v) in a {
        y[r] += v * x[c];
    }
}

/// Block size of the subspace: twice the modes wanted, at least 8 more, at most the free ones.
fn block_size(count: usize, free: usize) -> usize {
    (2 * count).max(count + 8).min(free)
}

/// M-orthonormalise the columns of `y` in place (modified Gram-Schmidt, two passes); returns R
/// (p x p upper triangular) with `Y_in = Q R`, `Q^T M Q = I`.
fn m_orthonormalise(m: &Triplets, y: &mut [Vec<f64>]) -> Result<Mat<f64>, LinearError> {
    let p = y.len();
    let n = y.first().map_or(0, Vec::len);
    let mut r = Mat::<f64>::zeros(p, p);
    let mut my = vec![vec![0.0; n]; p];
    for j in 0..p {
        for _pass in 0..2 {
            for i in 0..j {
                let h: f64 = my[i].iter().zip(&y[j]).map(|(a, b)| a * b).sum();
                r[(i, j)] += h;
                let (lo, hi) = y.split_at_mut(j);
                hi[0].iter_mut().zip(&lo[i]).for_each(|(a, b)| *a -= h * b);
            }
        }
        let mut mj = vec![0.0; n];
        mul(m, &y[j], &mut mj);
        let norm2: f64 = mj.iter().zip(&y[j]).map(|(a, b)| a * b).sum();
        if norm2.is_nan() || norm2 <= 0.0 {
            return Err(LinearError::Massless { vector: j, norm2 });
        }
        let norm = norm2.sqrt();
        r[(j, j)] = norm;
        y[j].iter_mut().for_each(|a| *a /= norm);
        mj.iter_mut().for_each(|a| *a /= norm);
        my[j] = mj;
    }
    Ok(r)
}

/// Deterministic start vectors in [-1, 1) (a linear congruential sequence).
fn start_vectors(n: usize, p: usize) -> Vec<Vec<f64>> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    (0..p)
        .map(|_| {
            (0..n)
                .map(|_| {
                    state = state
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1_442_695_040_888_963_407);
                    (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
                })
                .collect()
        })
        .collect()
}

/// The first `count` modes of `M q'' + K q = 0`, `C q = 0` (n coordinates, `rows` constraint
/// rows; all three matrices as triplets): same contract and output as
/// [`flexstar_numerics::eigen::constrained_modes`] (`shift` makes `K + shift M` positive definite on
/// the constrained motions; shapes mass-normalised), for sparse matrices.
pub fn sparse_constrained_modes(
    n: usize,
    m: &Triplets,
    k: &Triplets,
    c: &Triplets,
    rows: usize,
    count: usize,
    shift: f64,
) -> Result<ConstrainedModes, LinearError> {
    if rows >= n || shift.is_nan() || shift < 0.0 {
        return Err(LinearError::ModalSizes { rows, n, shift });
    }
    let free = n - rows;
    let count = count.min(free);
    let p = block_size(count, free);
    let (d, m, bordered) = scaled_system(n, m, k, c, rows, shift)?;
    let m = &m;
    let mut lu = bordered_lu(n + rows, &bordered)?;
    let np = n + rows;
    // X (n x p), column-major
    let mut x: Vec<f64> = start_vectors(n, p).concat();
    let mut prev: Vec<f64> = vec![f64::INFINITY; count];
    let mut prev_change: Vec<f64> = vec![f64::INFINITY; count];
    let mut stop_at = None;
    for it in 0..MAX_ITER {
        let mut mx = vec![0.0; n * p];
        for (xj, mxj) in x.chunks_exact(n).zip(mx.chunks_exact_mut(n)) {
            mul(m, xj, mxj);
        }
        let y = apply(&mut lu, &bordered, &mx, n, np, p);
        let mut y: Vec<Vec<f64>> = y.chunks_exact(np).map(|c| c[..n].to_vec()).collect();
        if y.iter().flatten().any(|v| !v.is_finite()) {
            return Err(LinearError::BorderedNonFinite);
        }
        let r = m_orthonormalise(m, &mut y)?;
        let q = Mat::from_fn(n, p, |i, j| y[j][i]);
        // (K + sigma M) Q = M X R^-1, transposed: R^T (A Q)^T = (M X)^T
        let mut aq_t = MatRef::from_column_major_slice(&mx, n, p).transpose().to_owned();
        solve_lower_triangular_in_place(r.transpose(), aq_t.as_mut(), Par::Seq);
        // projected stiffness Q^T A Q (p x p), symmetrised
        let kr = &aq_t * &q;
        let kr = Mat::from_fn(p, p, |i, j| 0.5 * (kr[(i, j)] + kr[(j, i)]));
        let eig = kr.self_adjoint_eigen(Side::Lower).map_err(LinearError::Projected)?;
        let theta: Vec<f64> = (0..p).map(|j| eig.S()[j]).collect();
        let xm = &q * eig.U();
        for (j, xj) in x.chunks_exact_mut(n).enumerate() {
            xj.iter_mut().zip(xm.col(j).iter()).for_each(|(a, b)| *a = *b);
        }
        // rigid modes (theta = sigma) are resolved to the precision of the first elastic one
        let floor = TOL * theta.iter().copied().find(|&t| t > 2.0 * shift).unwrap_or(0.0);
        let mut converged = true;
        for j in 0..count {
            let change = (theta[j] - prev[j]).abs();
            // below TOL, or stagnating at the round-off floor (no geometric decrease any more)
            let stagnant = change <= STAGNANT * theta[j].abs() && change >= 0.3 * prev_change[j];
            converged &= change <= (TOL * theta[j].abs()).max(floor) || stagnant;
            prev_change[j] = change;
        }
        prev.copy_from_slice(&theta[..count]);
        if converged && stop_at.is_none() {
            stop_at = Some(it + 1 + it / 2);
        }
        if stop_at == Some(it) {
            let shapes = x
                .chunks_exact(n)
                .take(count)
                .map(|xj| xj.iter().zip(&d).map(|(a, b)| a * b).collect())
                .collect();
            return Ok(ConstrainedModes {
                omega2: theta[..count].iter().map(|t| t - shift).collect(),
                shapes,
                rank: rows,
            });
        }
    }
    Err(LinearError::NoConvergence { iterations: MAX_ITER })
}

/// `Y = Op X` for the p columns of `M X` (`mx`, n x p column-major): the bordered solve with one
/// step of iterative refinement; returns the (n + rows) x p solutions, column-major.
fn apply(lu: &mut SparseLu, bordered: &Triplets, mx: &[f64], n: usize, np: usize, p: usize) -> Vec<f64> {
    let mut b = vec![0.0; np * p];
    for (bj, mxj) in b.chunks_exact_mut(np).zip(mx.chunks_exact(n)) {
        bj[..n].copy_from_slice(mxj);
    }
    let mut y = b.clone();
    lu.solve_many(&mut y, p);
    let mut r = vec![0.0; np * p];
    for ((rj, yj), bj) in r.chunks_exact_mut(np).zip(y.chunks_exact(np)).zip(b.chunks_exact(np)) {
        mul(bordered, yj, rj);
        rj.iter_mut().zip(bj).for_each(|(ri, bi)| *ri = bi - *ri);
    }
    lu.solve_many(&mut r, p);
    y.iter_mut().zip(&r).for_each(|(yi, ri)| *yi += ri);
    y
}

/// Jacobi scaling `q = D q~` (`D_ii = 1/sqrt(M_ii)`, 1 for massless coordinates) and constraint
/// rows scaled to unit norm: returns D, the scaled M, and the scaled bordered matrix
/// `[[D (K + sigma M) D, (S C D)^T], [S C D, 0]]` as triplets.
fn scaled_system(
    n: usize,
    m: &Triplets,
    k: &Triplets,
    c: &Triplets,
    rows: usize,
    shift: f64,
) -> Result<(Vec<f64>, Triplets, Triplets), LinearError> {
    let mut diag = vec![0.0; n];
    for &(r, col, v) in m.iter().chain(k).chain(c) {
        if !v.is_finite() || col >= n || r >= n {
            return Err(LinearError::ModalEntry {
                row: r,
                col,
                value: v,
                n,
            });
        }
    }
    for &(r, col, v) in m {
        if r == col {
            diag[r] += v;
        }
    }
    let d: Vec<f64> = diag
        .iter()
        .map(|&v| if v > 0.0 { 1.0 / v.sqrt() } else { 1.0 })
        .collect();
    let ms: Triplets = m.iter().map(|&(r, col, v)| (r, col, v * d[r] * d[col])).collect();
    let mut row_norm = vec![0.0; rows];
    for &(r, col, v) in c {
        if r >= rows {
            return Err(LinearError::ConstraintRowOutside { row: r, rows });
        }
        row_norm[r] += (v * d[col]).powi(2);
    }
    if let Some(r) = row_norm.iter().position(|v| *v == 0.0) {
        return Err(LinearError::EmptyConstraintRow { row: r + 1 });
    }
    let mut bordered = Triplets::with_capacity(k.len() + m.len() + 2 * c.len());
    bordered.extend(k.iter().map(|&(r, col, v)| (r, col, v * d[r] * d[col])));
    bordered.extend(ms.iter().map(|&(r, col, v)| (r, col, shift * v)));
    for &(r, col, v) in c {
        let v = v * d[col] / row_norm[r].sqrt();
        bordered.push((n + r, col, v));
        bordered.push((col, n + r, v));
    }
    Ok((d, ms, bordered))
}

/// Sparse LU of a square matrix of size `size` given as triplets.
fn bordered_lu(size: usize, a: &Triplets) -> Result<SparseLu, LinearError> {
    let slots: Vec<(usize, usize)> = a.iter().map(|&(r, col, _)| (r, col)).collect();
    let vals: Vec<f64> = a.iter().map(|t| t.2).collect();
    let mut lu = SparseLu::new(size, &slots)?;
    lu.factor(&vals)
        .map_err(|e| LinearError::BorderedSingular { source: Box::new(e) })?;
    Ok(lu)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed-fixed chain of the dense solver's test (n unit masses and springs held by two
    /// constraints at the ends): textbook `omega_j = 2 sin(j pi / (2 (n + 1)))`.
    #[test]
    fn constrained_chain_matches_textbook() {
        let n = 40;
        let nt = n + 2;
        let mut k = Triplets::new();
        for e in 0..nt - 1 {
            k.extend([(e, e, 1.0), (e + 1, e + 1, 1.0), (e, e + 1, -1.0), (e + 1, e, -1.0)]);
        }
        let m: Triplets = (0..nt).map(|i| (i, i, 1.0)).collect();
        let c = vec![(0, 0, 1.0), (0, nt - 1, 1.0), (1, 0, 1.0), (1, nt - 1, -1.0)];
        let modes = sparse_constrained_modes(nt, &m, &k, &c, 2, 5, 0.0).unwrap();
        for (j, w2) in modes.omega2.iter().enumerate() {
            let exact = 2.0 * ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0))).sin();
            assert!(
                (w2.sqrt() / exact - 1.0).abs() < 1e-12,
                "mode {j}: {} vs {exact}",
                w2.sqrt()
            );
        }
        for x in &modes.shapes {
            assert!(x[0].abs() < 1e-12 && x[nt - 1].abs() < 1e-12);
            let mass: f64 = x.iter().map(|v| v * v).sum();
            assert!((mass - 1.0).abs() < 1e-12);
        }
    }
}
