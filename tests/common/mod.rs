//! Shared helpers of the workspace-level CLI tests: run the built `flexstar` binary.
#![allow(dead_code)]

use std::process::{Command, Output};

/// `tests/data/tiny.toml`: 30 ms of case 3 with 5 free-free modes, a fast case.
pub const TINY: &str = include_str!("../data/tiny.toml");

/// Run `flexstar` with `args` and wait for it.
pub fn flexstar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexstar"))
        .args(args)
        .output()
        .expect("flexstar runs")
}

/// The run's standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
