//! # flexstar-numerics
//!
//! Small numerical pieces that both solvers (AMM and FEM) use, kept here so neither copies the
//! other: generalized-alpha coefficients, Gauss-Legendre quadrature, the measures of time
//! histories (Eq. 45), the modes of a constrained linear system and a dot product that uses the
//! processor's fused multiply-add where it has one.

pub mod eigen;
pub mod gen_alpha;
pub mod measures;
pub mod quadrature;
pub mod vector;

pub use gen_alpha::GenAlpha;
