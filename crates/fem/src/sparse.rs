//! Sparse LU of the Newton iteration matrix with a fixed pattern: the pattern and faer's
//! symbolic factorisation are built once (per pattern), the numeric factorisation is redone
//! every iteration into reused workspaces (faer `SymbolicLu::factorize_numeric_lu`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, Par};

use crate::error::LinearError;

/// A square sparse matrix given as a fixed list of (row, col) slots (duplicates are summed),
/// with its LU factorisation.
pub struct SparseLu {
    n: usize,
    /// CSC value index of every slot.
    map: Vec<usize>,
    symbolic: SymbolicSparseColMat<usize>,
    lu_symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    values: Vec<f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    factored: bool,
}

impl SparseLu {
    /// Build the pattern of an `n x n` matrix from its slots, and its symbolic factorisation.
    pub fn new(n: usize, slots: &[(usize, usize)]) -> Result<Self, LinearError> {
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &(r, c) in slots {
            if r >= n || c >= n {
                return Err(LinearError::SlotOutside { row: r, col: c, n });
            }
            cols[c].push(r);
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(slots.len());
        col_ptr.push(0usize);
        for c in cols.iter_mut() {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let map = slots
            .iter()
            .map(|&(r, c)| {
                let lo = col_ptr[c];
                lo + row_idx[lo..col_ptr[c + 1]].binary_search(&r).expect("slot in pattern")
            })
            .collect();
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let lu_symbolic =
            factorize_symbolic_lu(symbolic.as_ref(), Default::default()).map_err(LinearError::Symbolic)?;
        let factor_mem = MemBuffer::new(lu_symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()));
        let solve_mem = MemBuffer::new(lu_symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(SparseLu {
            n,
            map,
            symbolic,
            lu_symbolic,
            numeric: NumericLu::new(),
            values: vec![0.0; nnz],
            factor_mem,
            solve_mem,
            factored: false,
        })
    }

    /// Numeric factorisation of the matrix whose slot values are `slot_values` (same order as
    /// the slots given to [`SparseLu::new`]).
    pub fn factor(&mut self, slot_values: &[f64]) -> Result<(), LinearError> {
        debug_assert_eq!(slot_values.len(), self.map.len());
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (k, &v) in slot_values.iter().enumerate() {
            self.values[self.map[k]] += v;
        }
        if let Some(bad) = self.values.iter().position(|v| !v.is_finite()) {
            return Err(LinearError::NonFiniteEntry { index: bad });
        }
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.values);
        self.factored = false;
        self.lu_symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.factor_mem),
                Default::default(),
            )
            .map_err(LinearError::Numeric)?;
        self.factored = true;
        Ok(())
    }

    /// Solve `A X = B` in place for `ncols` right-hand sides stored column-major in `rhs`
    /// (`n x ncols`) with the last factorisation.
    pub fn solve_many(&mut self, rhs: &mut [f64], ncols: usize) {
        assert!(self.factored, "solve before factor");
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.lu_symbolic, &self.numeric);
        let mut mem = MemBuffer::new(self.lu_symbolic.solve_in_place_scratch::<f64>(ncols, Par::Seq));
        let m = MatMut::from_column_major_slice_mut(rhs, self.n, ncols);
        lu.solve_in_place_with_conj(faer::Conj::No, m, Par::Seq, MemStack::new(&mut mem));
    }

    /// Solve `A x = rhs` in place with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        assert!(self.factored, "solve before factor");
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.lu_symbolic, &self.numeric);
        let m = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        lu.solve_in_place_with_conj(faer::Conj::No, m, Par::Seq, MemStack::new(&mut self.solve_mem));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_unsymmetric_system_with_zero_diagonal() {
        // [[0, 2, 1], [2, 1, 0], [1, 0, 0]] x = [3, 3, 1] -> x = [1, 1, 1]; slot (1,1) given twice.
        let slots = [(0, 1), (0, 2), (1, 0), (1, 1), (1, 1), (2, 0)];
        let vals = [2.0, 1.0, 2.0, 0.5, 0.5, 1.0];
        let mut lu = SparseLu::new(3, &slots).unwrap();
        lu.factor(&vals).unwrap();
        let mut b = [3.0, 3.0, 1.0];
        lu.solve(&mut b);
        for x in b {
            assert!((x - 1.0).abs() < 1e-14);
        }
    }
}
