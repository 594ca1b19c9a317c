//! The paper's four experiments and the thresholds, built into the binary so that `flexstar
//! verify` runs from any directory (`--configs` and `--thresholds` read other files).

use flexstar_model::{catalogue, Experiment};

pub use crate::thresholds::BUILTIN_THRESHOLDS;

/// The paper's cases 1-4 (section 8) exactly as in `configs/case1.toml` .. `case4.toml`; their
/// source is shown as `configs/caseK.toml (built in)`.
pub fn paper_experiments() -> Vec<Experiment> {
    (1..=4)
        .map(|k| {
            let mut e = catalogue::paper_case(k);
            e.source = format!("configs/case{k}.toml (built in)").into();
            e
        })
        .collect()
}
