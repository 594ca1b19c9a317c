//! # flexstar-numerics
//!
//! Small numerical pieces that both solvers (AMM and FEM) use, kept here so neither copies the
//! other: generalized-alpha coefficients and Gauss-Legendre quadrature.

pub mod gen_alpha;
pub mod quadrature;

pub use gen_alpha::GenAlpha;
