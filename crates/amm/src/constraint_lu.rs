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
//!
//! **Bordered rows** (friction's stick rows, `docs/friction.md` 9, one per sleeve after all
//! others): a stick row of beam i couples with the junction rows and beam i's rows only, and the
//! friction terms keep the structure of the rows above them, so A is bordered,
//!
//! ```text
//! A = [ A_0  B ]      A_0: the structure above (m - 3 rows), D: 3 x 3
//!     [ C    D ]
//! ```
//!
//! and is factored by block elimination of A_0 (above), `Y = A_0^-1 B` (three solves) and the
//! inverse of the 3 x 3 Schur complement `D - C Y` (nalgebra's closed form, checked like a
//! sleeve block); anything that fails its check hands the step to the dense LU of the whole A
//! (`docs/friction.md` 6, "Speed"). While no sleeve sticks, the stick rows are the identity and B
//! and C are zero: then `Y = 0` is not computed and a solve is `A_0`'s and `D^-1`'s alone (the
//! same numbers).

use nalgebra::{Matrix3, Matrix4, Matrix6, SMatrix, Vector3, Vector4, Vector6, LU, U6};

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
    /// The block elimination's factors, written in place by each factorisation.
    blocks: Blocks,
    /// Whether `blocks` (and `border`) hold the last factorisation (else `dense` does).
    structured: bool,
    /// With bordered rows: their factors (valid when `structured`).
    border: Option<Border>,
    /// The dense factors (valid when not `structured` after a successful factorisation).
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

impl Blocks {
    /// Storage for the factors, filled by each factorisation.
    fn new() -> Self {
        Blocks {
            sleeve: [Matrix4::zeros(); 3],
            x: [SMatrix::zeros(); 3],
            coupling: [SMatrix::zeros(); 3],
            junction: Matrix6::<f64>::identity().lu(),
        }
    }
}

/// Bordered rows' count (friction's three stick rows).
pub(crate) const BORDER_ROWS: usize = 3;
/// Most rows of `A_0`.
const MAX_INNER_ROWS: usize = MAX_JUNCTION_ROWS + 3 * SLEEVE_ROWS;

/// The factors of the bordered rows (module docs).
#[derive(Debug, Clone)]
struct Border {
    /// `Y = A_0^-1 B` (rows past m0 zero).
    y: SMatrix<f64, MAX_INNER_ROWS, BORDER_ROWS>,
    /// `C` (columns past m0 zero).
    c: SMatrix<f64, BORDER_ROWS, MAX_INNER_ROWS>,
    /// `(D - C Y)^-1`.
    schur_inverse: Matrix3<f64>,
    /// B and C are zero (no sleeve stuck): Y is zero and the rows decouple.
    decoupled: bool,
}

/// Largest |entry| of a matrix.
fn largest<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>) -> f64 {
    a.iter().fold(0.0f64, |s, v| s.max(v.abs()))
}

/// nalgebra's inverse of a sleeve block or of the bordered rows' Schur complement, accepted when
/// `block * inverse` is the identity to [`INVERSE_CHECK`] (a block too close to singular for
/// the closed form gives `None`).
fn checked_inverse<const N: usize>(block: &SMatrix<f64, N, N>) -> Option<SMatrix<f64, N, N>> {
    let inverse = block.try_inverse()?;
    let error = largest(&(block * inverse - SMatrix::<f64, N, N>::identity()));
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
            blocks: Blocks::new(),
            structured: false,
            border: None,
            dense: DenseLu::new(m),
        }
    }

    /// For an m x m system whose last [`BORDER_ROWS`] rows border the structure (friction's stick
    /// rows, `docs/friction.md` 9; module docs).
    pub(crate) fn bordered(m: usize) -> Self {
        let m0 = m.saturating_sub(BORDER_ROWS);
        ConstraintLu {
            m,
            nj: m0.saturating_sub(3 * SLEEVE_ROWS),
            blocks: Blocks::new(),
            structured: false,
            border: Some(Border {
                y: SMatrix::zeros(),
                c: SMatrix::zeros(),
                schur_inverse: Matrix3::zeros(),
                decoupled: false,
            }),
            dense: DenseLu::new(m),
        }
    }

    /// Factor A (`a`, m x m, row-major). Fails with the reason when A is rank deficient.
    pub(crate) fn factor(&mut self, a: &[f64]) -> Result<(), RankError> {
        let (m, nj) = (self.m, self.nj);
        self.structured = match self.border.as_mut() {
            None => block_factor(a, (m, m, nj), &mut self.blocks),
            Some(border) => bordered_factor(a, (m, nj), &mut self.blocks, border),
        };
        if !self.structured {
            self.dense_factor(a)?;
        }
        Ok(())
    }
}

/// The bordered factorisation (module docs) of the m x m `a` with `nj` junction rows into
/// `blocks` and `border`; false when a check fails.
fn bordered_factor(a: &[f64], (m, nj): (usize, usize), blocks: &mut Blocks, border: &mut Border) -> bool {
    let m0 = m - BORDER_ROWS;
    if m0 > MAX_INNER_ROWS {
        return false;
    }
    // A_0 is the leading m0 x m0 part of A, read in place (row stride m)
    if !block_factor(a, (m0, m, nj), blocks) {
        return false;
    }
    border.decoupled =
        (0..BORDER_ROWS).all(|k| (0..m0).all(|r| a[r * m + m0 + k] == 0.0 && a[(m0 + k) * m + r] == 0.0));
    let d = Matrix3::from_fn(|r, c| a[(m0 + r) * m + m0 + c]);
    // decoupled: Y = 0, and the Schur complement is D itself
    let schur = if border.decoupled {
        d
    } else {
        let mut column = [0.0; MAX_INNER_ROWS];
        for k in 0..BORDER_ROWS {
            for (r, v) in column[..m0].iter_mut().enumerate() {
                *v = a[r * m + m0 + k];
            }
            block_solve(blocks, nj, &mut column[..m0]);
            for (r, v) in column.iter().enumerate() {
                border.y[(r, k)] = if r < m0 { *v } else { 0.0 };
            }
            for c in 0..MAX_INNER_ROWS {
                border.c[(k, c)] = if c < m0 { a[(m0 + k) * m + c] } else { 0.0 };
            }
        }
        d - border.c * border.y
    };
    checked_inverse(&schur)
        .map(|inverse| border.schur_inverse = inverse)
        .is_some()
}

/// The block elimination of the leading `m` x `m` part of `a` (row-major, row stride `stride`,
/// `nj` junction rows) into `f`; false when a block pivot is too small (or the rows do not have
/// the structure).
fn block_factor(a: &[f64], (m, stride, nj): (usize, usize, usize), f: &mut Blocks) -> bool {
    if m != nj + 3 * SLEEVE_ROWS || nj > MAX_JUNCTION_ROWS {
        return false;
    }
    let at = |r: usize, c: usize| a[r * stride + c];
    let mut z = Matrix6::<f64>::identity();
    for r in 0..nj {
        for c in 0..nj {
            z[(r, c)] = at(r, c);
        }
    }
    for i in 0..3 {
        let s = nj + SLEEVE_ROWS * i;
        let block = Matrix4::from_fn(|r, c| at(s + r, s + c));
        let Some(inverse) = checked_inverse(&block) else {
            return false;
        };
        f.sleeve[i] = inverse;
        let a_ij = SMatrix::<f64, 4, 6>::from_fn(|r, c| if c < nj { at(s + r, c) } else { 0.0 });
        f.x[i] = f.sleeve[i] * a_ij;
        f.coupling[i] = SMatrix::<f64, 6, 4>::from_fn(|r, c| if r < nj { at(r, s + c) } else { 0.0 });
        z -= f.coupling[i] * f.x[i];
    }
    let scale = largest(&z);
    f.junction = z.lu();
    pivots_hold(f.junction.u().diagonal().iter().copied(), scale)
}

impl ConstraintLu {
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
        if !self.structured {
            self.dense.solve(b);
            return;
        }
        let f = &self.blocks;
        let Some(border) = &self.border else {
            block_solve(f, self.nj, b);
            return;
        };
        // y = A_0^-1 b_0; x_1 = (D - C Y)^-1 (b_1 - C y); x_0 = y - Y x_1
        let m0 = self.m - BORDER_ROWS;
        let (head, tail) = b.split_at_mut(m0);
        block_solve(f, self.nj, head);
        if border.decoupled {
            let x1 = border.schur_inverse * Vector3::from_fn(|k, _| tail[k]);
            tail.copy_from_slice(x1.as_slice());
            return;
        }
        let mut cy = Vector3::<f64>::zeros();
        for k in 0..BORDER_ROWS {
            cy[k] = (0..m0).map(|c| border.c[(k, c)] * head[c]).sum::<f64>();
        }
        let x1 = border.schur_inverse * (Vector3::from_fn(|k, _| tail[k]) - cy);
        for (r, v) in head.iter_mut().enumerate() {
            *v -= (0..BORDER_ROWS).map(|k| border.y[(r, k)] * x1[k]).sum::<f64>();
        }
        tail.copy_from_slice(x1.as_slice());
    }
}

/// Solve `A x = b` in place with the block factors `f` of a structure with `nj` junction rows.
fn block_solve(f: &Blocks, nj: usize, b: &mut [f64]) {
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
            assert!(lu.structured, "nj = {nj}: block path expected");
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
        assert!(!lu.structured);
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
    /// The structure bordered by three rows coupled to every row (friction's stick rows): the
    /// bordered factorisation is taken and solves `A x = b` to its definition, and agrees with
    /// the dense LU of the same matrix; a border whose Schur complement is singular (a stick row
    /// equal to a sleeve row) falls back to the dense LU, which reports the rank deficiency.
    #[test]
    fn bordered_rows_solve_the_system_and_fall_back_when_singular() {
        for nj in 3..=MAX_JUNCTION_ROWS {
            let m0 = nj + 12;
            let m = m0 + BORDER_ROWS;
            let inner = structured(nj, 7 + nj as u64);
            let mut state = nj as u64;
            let mut rnd = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            };
            let mut a = vec![0.0; m * m];
            for r in 0..m {
                for c in 0..m {
                    a[r * m + c] = if r < m0 && c < m0 { inner[r * m0 + c] } else { rnd() };
                }
            }
            for k in m0..m {
                a[k * m + k] += 4.0;
            }
            let b: Vec<f64> = (0..m).map(|k| (k as f64 * 0.3).cos()).collect();
            let mut lu = ConstraintLu::bordered(m);
            lu.factor(&a).unwrap();
            assert!(lu.structured, "nj = {nj}: bordered path expected");
            let mut x = b.clone();
            lu.solve(&mut x);
            assert!(residual(&a, &x, &b) < 1e-12, "nj = {nj}: {:e}", residual(&a, &x, &b));
            let mut dense = DenseLu::new(m);
            dense.factor(&a);
            let mut y = b.clone();
            dense.solve(&mut y);
            let gap = x.iter().zip(&y).fold(0.0f64, |g, (p, q)| g.max((p - q).abs()));
            assert!(gap < 1e-12, "nj = {nj}: bordered and dense differ by {gap:e}");

            let mut singular = a.clone();
            for c in 0..m {
                singular[m0 * m + c] = singular[nj * m + c];
            }
            let err = ConstraintLu::bordered(m).factor(&singular).unwrap_err();
            assert!(matches!(err, RankError::RankDeficient { .. }), "nj = {nj}: {err}");
        }
    }
}
