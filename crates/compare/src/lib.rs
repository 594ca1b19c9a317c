//! # flexstar-compare
//!
//! Judging the AMM against the FEM reference (paper, section 9; MODEL-NOTES section 5):
//! the error variance parameter ([`evp`], Eq. 45), the behaviour of G and the correctness of each
//! mode family ([`behaviour`]), the regenerated Table I ([`table`]) beside the paper's
//! ([`paper`]), figures ([`figures`]), the HTML report ([`report`]) and the threshold checks of
//! `flexstar verify` ([`thresholds`]).

pub mod behaviour;
pub mod evp;
pub mod figures;
pub mod paper;
pub mod report;
pub mod table;
pub mod thresholds;
pub mod verify;

pub use behaviour::Behaviour;
pub use evp::{point_evps, CompareError, Point, PointEvps};
pub use table::{CaseResults, TableI, TableRow};
