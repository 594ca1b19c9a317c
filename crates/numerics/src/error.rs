//! The one error type of the numerics crate: what failed in a constrained eigenproblem, with the
//! row, size or factorisation that says why (callers add when and where).

use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::evd::EvdError;

/// Why [`crate::eigen::constrained_modes`] (or a solver built like it) found no modes.
#[derive(Debug, Clone, Copy, thiserror::Error)]
pub enum NumericsError {
    /// The matrices' lengths do not fit `n` coordinates and `rows` constraint rows.
    #[error("inconsistent sizes: n = {n}, M {m}, K {k}, C {c} with {rows} rows")]
    Sizes {
        n: usize,
        m: usize,
        k: usize,
        c: usize,
        rows: usize,
    },
    /// A non-finite entry in M, K or C, or a shift that is negative or NaN.
    #[error("non-finite entry in M, K or C, or a negative shift")]
    NonFinite,
    /// Constraint row `row` (1-based, of `rows`) is numerically a combination of the rows before
    /// it: the norm left after the projection is `norm`.
    #[error("constraint row {row} of {rows} is a combination of the others (norm left after the projection {norm:e})")]
    DependentRow { row: usize, rows: usize, norm: f64 },
    /// `K + shift M` has a pivot that is not positive on the constrained motions.
    #[error("K + {shift:e} M is not positive definite on the constrained motions ({source:?}): a mechanism, or too small a shift")]
    NotPositiveDefinite { shift: f64, source: LltError },
    /// The symmetric eigensolver (`what` names the problem) did not converge.
    #[error("{what} failed ({cause:?})")]
    Eigensolver { what: &'static str, cause: EvdError },
}
