//! # flexstar-numerics
//!
//! Small numerical pieces that both solvers (AMM and FEM) use, kept here so neither copies the
//! other: generalized-alpha coefficients, Gauss-Legendre quadrature, the measures of time
//! histories (Eq. 45) and the modes of a constrained linear system.

pub mod eigen;
pub mod gen_alpha;
pub mod measures;
pub mod quadrature;

pub use gen_alpha::GenAlpha;
