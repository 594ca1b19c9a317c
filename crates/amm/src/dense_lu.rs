//! The dense LU with partial pivoting of the Schur complement (`constraint_lu`; `docs/amm.md`
//! 2.1, "Cost of a step") in storage sized once: nalgebra's `LU::new` and `LU::solve_mut`
//! step by step (the same pivot search, row swaps, Gauss steps and triangular solves, in the same
//! order), so the factors and solutions are nalgebra's bit for bit, without the matrix, the
//! permutation and the right-hand side that nalgebra allocates per factorisation and per solve.

use nalgebra::linalg::{gauss_step, gauss_step_swap};
use nalgebra::{DMatrix, DVector};

/// `P A = L U` of an m x m matrix (dimensionless: the factors carry A's units), L unit lower
/// and U upper triangular in one matrix as nalgebra stores them, P the row swaps in order.
#[derive(Debug, Clone)]
pub(crate) struct DenseLu {
    /// L below the diagonal (unit diagonal implied), U on and above it.
    lu: DMatrix<f64>,
    /// The row swaps `(i, piv)` of the elimination, in order; `swaps` of them are valid.
    swaps: Vec<(usize, usize)>,
    n_swaps: usize,
    /// Workspace of the solve (m).
    rhs: DVector<f64>,
}

impl DenseLu {
    /// Storage for an m x m matrix.
    pub(crate) fn new(m: usize) -> Self {
        DenseLu {
            lu: DMatrix::zeros(m, m),
            swaps: vec![(0, 0); m],
            n_swaps: 0,
            rhs: DVector::zeros(m),
        }
    }

    /// Factor `a` (m x m, row-major), as nalgebra's `LU::new` does: for each column the entry
    /// of largest modulus on and below the diagonal is the pivot (a zero column is skipped).
    pub(crate) fn factor(&mut self, a: &[f64]) {
        let m = self.lu.nrows();
        let lu = &mut self.lu;
        for r in 0..m {
            for c in 0..m {
                lu[(r, c)] = a[r * m + c];
            }
        }
        self.n_swaps = 0;
        for i in 0..m {
            let piv = lu.view_range(i.., i).icamax() + i;
            let diag = lu[(piv, i)];
            if diag == 0.0 {
                continue;
            }
            if piv != i {
                self.swaps[self.n_swaps] = (i, piv);
                self.n_swaps += 1;
                lu.columns_range_mut(..i).swap_rows(i, piv);
                gauss_step_swap(lu, diag, i, piv);
            } else {
                gauss_step(lu, diag, i);
            }
        }
    }

    /// The diagonal of U, `k`-th entry (the pivots, for the rank test).
    pub(crate) fn pivot(&self, k: usize) -> f64 {
        self.lu[(k, k)]
    }

    /// Solve `A x = b` in place, as nalgebra's `LU::solve_mut`: the row swaps, then the unit
    /// lower and the upper triangular solves (an exactly zero pivot leaves b as nalgebra does).
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        self.rhs.as_mut_slice().copy_from_slice(b);
        for &(i, piv) in &self.swaps[..self.n_swaps] {
            self.rhs.swap_rows(i, piv);
        }
        self.lu.solve_lower_triangular_with_diag_mut(&mut self.rhs, 1.0);
        self.lu.solve_upper_triangular_mut(&mut self.rhs);
        b.copy_from_slice(self.rhs.as_slice());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random m x m matrix (row-major) whose elimination swaps rows, and one with a zero column.
    fn matrix(m: usize, seed: u64, zero_column: Option<usize>) -> Vec<f64> {
        let mut state = seed;
        let mut a: Vec<f64> = (0..m * m)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect();
        if let Some(c) = zero_column {
            (0..m).for_each(|r| a[r * m + c] = 0.0);
        }
        a
    }

    #[test]
    fn factors_and_solutions_are_nalgebras_bit_for_bit() {
        // against nalgebra's own LU::new and solve_mut, reused storage across sizes of the
        // friction's Schur complement (21) and the plain one (18), and a singular matrix
        for (m, seed, zero) in [(21, 1, None), (18, 2, None), (21, 3, Some(5)), (7, 4, None)] {
            let a = matrix(m, seed, zero);
            let reference = DMatrix::from_row_slice(m, m, &a).lu();
            let mut lu = DenseLu::new(m);
            lu.factor(&matrix(m, seed + 100, None));
            lu.factor(&a);
            let u = reference.u();
            for k in 0..m {
                assert_eq!(lu.pivot(k).to_bits(), u[(k, k)].to_bits(), "m {m}: pivot {k}");
            }
            let b: Vec<f64> = (0..m).map(|k| (0.3 * k as f64).cos()).collect();
            let mut want = DVector::from_column_slice(&b);
            reference.solve_mut(&mut want);
            let mut got = b.clone();
            lu.solve(&mut got);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(want.as_slice()), "m {m}");
            if zero.is_none() {
                // and it solves the system (the reference is not merely copied)
                let res = (0..m)
                    .map(|r| ((0..m).map(|c| a[r * m + c] * got[c]).sum::<f64>() - b[r]).abs())
                    .fold(0.0, f64::max);
                assert!(res < 1e-12, "m {m}: residual {res:e}");
            }
        }
    }
}
