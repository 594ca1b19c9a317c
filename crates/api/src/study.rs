//! `compare`, `verify` and `sweep`: the library functions of the compare and study crates, as
//! both fronts call them (options, progress callbacks and outcomes are theirs).

pub use flexstar_compare::compare::{run_compare, CompareOptions, CompareOutcome};
pub use flexstar_compare::verify::{run_verify, VerifyOptions, VerifyOutcome};
pub use flexstar_compare::{Error as CompareError, Progress};
pub use flexstar_study::{
    merge, run_study, write_report, MergeReport, RunOptions as SweepOptions, RunOutcome as SweepOutcome, Shard, Study,
    StudyError,
};
