//! What the FEM's integration tests share: the coarse mesh they run on and a column by name.
#![allow(dead_code)]

use flexstar_model::{FemSettings, Response};

/// 108 elements (36 per beam): coarse enough for a test, fine enough for its checks.
pub fn coarse() -> FemSettings {
    FemSettings {
        elements: 108,
        ..Default::default()
    }
}

/// Column `name` of a response (a test's own columns, named as in the CSV).
pub fn col<'a>(r: &'a Response, name: &str) -> &'a [f64] {
    r.column(name).unwrap_or_else(|| panic!("no column {name}"))
}
