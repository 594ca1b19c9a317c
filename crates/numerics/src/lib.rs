//! # flexstar-numerics
//!
//! Small numerical pieces that both solvers (AMM and FEM) use, kept here so neither copies the
//! other: generalized-alpha coefficients, Gauss-Legendre quadrature, the measures of time
//! histories (Eq. 45), the modes of a constrained linear system a dot product that uses the
//! processor's fused multiply-add where it has one, and the one-or-four-lanes number type of the
//! FEM's element kernels.

pub mod angle;
pub mod eigen;
pub mod error;
pub mod gen_alpha;
pub mod lanes;
pub mod measures;
pub mod minimax;
pub mod quadrature;
pub mod vector;

pub use error::NumericsError;
pub use gen_alpha::GenAlpha;
