//! The error variance parameter, Eq. 45 of the paper, with flexstar's decisions (G norm, n/a rule):
//! defined once in `flexstar_metrics::evp` (the AMM's error estimate uses it too) and re-exported here.

pub use flexstar_metrics::evp::*;
