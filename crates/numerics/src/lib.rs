//! # flexstar-numerics
//!
//! Small numerical pieces that both solvers (AMM and FEM) use, kept here so neither copies the
//! other: generalized-alpha coefficients, Gauss-Legendre quadrature and the measures of time
//! histories (Eq. 45).

pub mod gen_alpha;
pub mod measures;
pub mod quadrature;

pub use gen_alpha::GenAlpha;
