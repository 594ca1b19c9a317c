//! Shared helpers of the workspace-level CLI tests: run the built `flexstar` binary.
#![allow(dead_code)]

use std::path::Path;
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

/// `flexstar run CONFIG --solver SOLVER --out OUT`.
pub fn run_solver(config: &Path, solver: &str, out: &Path) -> Output {
    flexstar(&[
        "run",
        config.to_str().unwrap(),
        "--solver",
        solver,
        "--out",
        out.to_str().unwrap(),
    ])
}

/// The run's standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Rows of a CSV file with a header, by column name.
pub fn table(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// Position of column `name` in a header.
pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no {name}"))
}
