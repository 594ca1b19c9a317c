//! Factorisation of the Schur complement `A = C S^-1 C^T` of the constrained step (`system`;
//! `docs/amm.md` section 2): block elimination of its structure, with nalgebra's LU for the
//! blocks, and nalgebra's dense LU of the whole matrix where a block is too close to singular
//! (in storage sized once, `dense_lu`).
//!
//! Rows: the `nj` junction rows (Eqs. 38-40) first, then the four sleeve rows (Eqs. 41-43) of
//! each beam in turn. S is block diagonal over the beams, so a sleeve row of beam i couples only
//! with the junction rows and with the other sleeve rows of beam i:
//!
//! ```text
//!     [ A_JJ  A_J1  A_J2  A_J3 ]
//! A = [ A_1J  A_11             ]      A_ii: 4 x 4, A_JJ: nj x nj (nj <= 6)
//!     [ A_2J        A_22       ]
//!     [ A_3J              A_33 ]
//! ```
//!
//! Eliminating the sleeve blocks leaves the junction Schur complement
//! `Z = A_JJ - sum_i A_Ji A_ii^-1 A_iJ`. A factorisation is three 4 x 4 inverses (nalgebra's
//! closed form, each checked by `A_ii A_ii^-1 = I` to 1e-9), their products with the junction
//! columns and the LU of Z (about 900 multiply-adds, against 1900 for the LU of the
//! whole 18 x 18); a solve is three 4 x 4 products, one solve with Z and three back-substitutions. Z is
//! held in a 6 x 6 matrix padded with the identity, so that every size is fixed.
//!
//! Without pivoting across the blocks this is stable for A dominated by its symmetric positive
//! part (the Gram matrix of the rows through the mass; the gyroscopic border of S is O(h) of it).
//! A sleeve block whose inverse fails its check, or a pivot of Z below [`BLOCK_PIVOT_RATIO`] of
//! Z's largest entry, hands the step to the dense LU with partial pivoting, whose own test
//! ([`PIVOT_RATIO`]) decides rank deficiency.

use nalgebra::{Matrix4, Matrix6, SMatrix, Vector4, Vector6, LU, U6};

use crate::dense_lu::DenseLu;

use crate::error::RankError;
use crate::sleeve::SLEEVE_ROWS;
/// Largest number of junction rows (three Fix, Fw, two slope equalities).
pub(crate) const MAX_JUNCTION_ROWS: usize = 6;
/// A pivot of the dense LU at or below this fraction of the largest entry of A is rank deficiency.
pub(crate) const PIVOT_RATIO: f64 = 1e-13;
/// A junction pivot at or below this fraction of Z's largest entry: factor A densely instead.
pub(crate) const BLOCK_PIVOT_RATIO: f64 = 1e-10;
/// Largest entry of `A_ii A_ii^-1 - I` accepted for a sleeve block's inverse; above it the
/// block is too close to singular for the closed form and A is factored densely.
pub(crate) const INVERSE_CHECK: f64 = 1e-9;

/// Factors of A for [`ConstraintLu::solve`].
#[derive(Debug, Clone)]
pub(crate) struct ConstraintLu {
    m: usize,
    nj: usize,
    blocks: Option<Blocks>,
    /// The dense factors (valid when `blocks` is `None` after a successful factorisation).
    dense: DenseLu,
}

/// The block elimination's factors.
#[derive(Debug, Clone)]
struct Blocks {
    /// Inverse of each sleeve block A_ii (nalgebra's closed form for 4 x 4, checked).
    sleeve: [Matrix4<f64>; 3],
    /// `A_ii^-1 A_iJ` (4 x 6, columns past nj zero).
    x: [SMatrix<f64, 4, 6>; 3],
    /// `A_Ji` (6 x 4, rows past nj zero).
    coupling: [SMatrix<f64, 6, 4>; 3],
    /// LU of the junction Schur complement Z (padded with the identity past nj).
    junction: LU<f64, U6, U6>,
}

/// Largest |entry| of a matrix.
fn largest<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>) -> f64 {
    a.iter().fold(0.0f64, |s, v| s.max(v.abs()))
}

/// nalgebra's inverse of a sleeve block, accepted when `block * inverse` is the identity to
/// [`INVERSE_CHECK`] (a block too close to singular for the closed form gives `None`).
fn checked_inverse(block: &Matrix4<f64>) -> Option<Matrix4<f64>> {
    let inverse = block.try_inverse()?;
    let error = largest(&(block * inverse - Matrix4::identity()));
    (error <= INVERSE_CHECK).then_some(inverse)
}

/// Every pivot (`u_diagonal`) above [`BLOCK_PIVOT_RATIO`] of the block's largest entry `scale`.
fn pivots_hold(mut u_diagonal: impl Iterator<Item = f64>, scale: f64) -> bool {
    scale.is_finite() && scale > 0.0 && u_diagonal.all(|d| d.abs() > BLOCK_PIVOT_RATIO * scale)
}

impl ConstraintLu {
    /// For an m x m system with `nj = m - 12` junction rows first.
    pub(crate) fn new(m: usize) -> Self {
        ConstraintLu {
            m,
            nj: m.saturating_sub(3 * SLEEVE_ROWS),
            blocks: None,
            dense: DenseLu::new(m),
        }
    }

    /// For an m x m system factored densely whatever its structure (with the stick rows of
    /// friction, `docs/friction.md` 9, the rows no longer have the block structure).
    pub(crate) fn dense(m: usize) -> Self {
        ConstraintLu {
            m,
            nj: m,
            blocks: None,
            dense: DenseLu::new(m),
        }
    }

    /// Factor A (`a`, m x m, row-major). Fails with the reason when A is rank deficient.
    pub(crate) fn factor(&mut self, a: &[f64]) -> Result<(), RankError> {
        self.blocks = self.block_factor(a);
        if self.blocks.is_none() {
            self.dense_factor(a)?;
        }
        Ok(())
    }

    /// The block elimination, or `None` when a block pivot is too small (or the rows do not have
    /// the structure).
    fn block_factor(&self, a: &[f64]) -> Option<Blocks> {
        let (m, nj) = (self.m, self.nj);
        if m != nj + 3 * SLEEVE_ROWS || nj > MAX_JUNCTION_ROWS {
            return None;
        }
        let at = |r: usize, c: usize| a[r * m + c];
        let mut z = Matrix6::<f64>::identity();
        for r in 0..nj {
            for c in 0..nj {
                z[(r, c)] = at(r, c);
            }
        }
        let mut sleeve = [Matrix4::<f64>::zeros(); 3];
        let mut x = [SMatrix::<f64, 4, 6>::zeros(); 3];
        let mut coupling = [SMatrix::<f64, 6, 4>::zeros(); 3];
        for i in 0..3 {
            let s = nj + SLEEVE_ROWS * i;
            let block = Matrix4::from_fn(|r, c| at(s + r, s + c));
            sleeve[i] = checked_inverse(&block)?;
            let a_ij = SMatrix::<f64, 4, 6>::from_fn(|r, c| if c < nj { at(s + r, c) } else { 0.0 });
            x[i] = sleeve[i] * a_ij;
            coupling[i] = SMatrix::<f64, 6, 4>::from_fn(|r, c| if r < nj { at(r, s + c) } else { 0.0 });
            z -= coupling[i] * x[i];
        }
        let scale = largest(&z);
        let junction = z.lu();
        if !pivots_hold(junction.u().diagonal().iter().copied(), scale) {
            return None;
        }
        Some(Blocks {
            sleeve,
            x,
            coupling,
            junction,
        })
    }

    /// nalgebra's LU with partial pivoting of the whole A ([`DenseLu`]), its rank checked.
    fn dense_factor(&mut self, a: &[f64]) -> Result<(), RankError> {
        let m = self.m;
        for r in 0..m {
            let row = &a[r * m..(r + 1) * m];
            if row.iter().all(|v| *v == 0.0) || row.iter().any(|v| !v.is_finite()) {
                return Err(RankError::NoCoupling { row: r });
            }
        }
        let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        self.dense.factor(a);
        let pivot = |k: usize| self.dense.pivot(k).abs();
        if let Some(k) = (0..m).find(|&k| pivot(k).is_nan() || pivot(k) <= PIVOT_RATIO * scale) {
            return Err(RankError::RankDeficient {
                step: k,
                size: m,
                ratio: pivot(k) / scale,
            });
        }
        Ok(())
    }

    /// Solve `A x = b` in place with the last factors.
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        let Some(f) = &self.blocks else {
            self.dense.solve(b);
            return;
        };
        let nj = self.nj;
        let mut rj = Vector6::<f64>::zeros();
        for r in 0..nj {
            rj[r] = b[r];
        }
        let y = [0, 1, 2].map(|i| {
            let s = nj + SLEEVE_ROWS * i;
            let y = f.sleeve[i] * Vector4::from_fn(|r, _| b[s + r]);
            rj -= f.coupling[i] * y;
            y
        });
        f.junction.solve_mut(&mut rj);
        for r in 0..nj {
            b[r] = rj[r];
        }
        for (i, (yi, xi)) in y.iter().zip(&f.x).enumerate() {
            let s = nj + SLEEVE_ROWS * i;
            let lam = yi - xi * rj;
            b[s..s + SLEEVE_ROWS].copy_from_slice(lam.as_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A matrix with the structure of A: SPD-dominated, junction rows coupled to every sleeve
    /// block, the sleeve blocks not to each other.
    fn structured(nj: usize, seed: u64) -> Vec<f64> {
        let m = nj + 12;
        let mut state = seed;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let block_of = |r: usize| if r < nj { None } else { Some((r - nj) / 4) };
        let mut a = vec![0.0; m * m];
        for r in 0..m {
            for c in 0..m {
                let coupled = match (block_of(r), block_of(c)) {
                    (Some(p), Some(q)) => p == q,
                    _ => true,
                };
                if coupled {
                    a[r * m + c] = rnd();
                }
            }
            a[r * m + r] += 4.0;
        }
        a
    }

    fn residual(a: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let m = b.len();
        (0..m)
            .map(|r| ((0..m).map(|c| a[r * m + c] * x[c]).sum::<f64>() - b[r]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn block_elimination_solves_the_structured_system() {
        // against the definition A x = b, for every junction size the families produce
        for nj in 3..=MAX_JUNCTION_ROWS {
            let a = structured(nj, nj as u64);
            let m = nj + 12;
            let mut lu = ConstraintLu::new(m);
            lu.factor(&a).unwrap();
            assert!(lu.blocks.is_some(), "nj = {nj}: block path expected");
            let b: Vec<f64> = (0..m).map(|k| (k as f64 * 0.7).sin()).collect();
            let mut x = b.clone();
            lu.solve(&mut x);
            assert!(
                residual(&a, &x, &b) < 1e-13,
                "nj = {nj}: residual {:e}",
                residual(&a, &x, &b)
            );
        }
    }

    #[test]
    fn a_singular_block_falls_back_to_the_dense_lu() {
        // a sleeve block with a zero pivot (its first row moved to the junction coupling only):
        // A itself is regular, the block elimination cannot start, the dense LU solves it
        let nj = 6;
        let m = nj + 12;
        let mut a = structured(nj, 7);
        let s = nj;
        for c in 0..4 {
            a[s * m + s + c] = 0.0;
            a[(s + c) * m + s] = 0.0;
        }
        let mut lu = ConstraintLu::new(m);
        lu.factor(&a).unwrap();
        assert!(lu.blocks.is_none());
        let b: Vec<f64> = (0..m).map(|k| 1.0 + k as f64).collect();
        let mut x = b.clone();
        lu.solve(&mut x);
        assert!(residual(&a, &x, &b) < 1e-12, "{:e}", residual(&a, &x, &b));
    }

    #[test]
    fn rank_deficiency_is_reported() {
        // two equal rows: no factorisation, a reason that names the step
        let nj = 3;
        let m = nj + 12;
        let mut a = structured(nj, 3);
        let (r0, r1) = (nj, nj + 1);
        for c in 0..m {
            a[r1 * m + c] = a[r0 * m + c];
        }
        let err = ConstraintLu::new(m).factor(&a).unwrap_err();
        assert!(
            matches!(err, RankError::RankDeficient { size, .. } if size == m),
            "{err}"
        );
        assert!(err.to_string().contains("rank-deficient"), "{err}");
        let zero_row = {
            let mut z = structured(nj, 4);
            z[2 * m..3 * m].iter_mut().for_each(|v| *v = 0.0);
            z
        };
        let err = ConstraintLu::new(m).factor(&zero_row).unwrap_err();
        assert!(matches!(err, RankError::NoCoupling { row: 2 }), "{err}");
        assert!(err.to_string().contains("row 2 has no coupling"), "{err}");
    }
}
