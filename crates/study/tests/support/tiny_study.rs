//! The study tests' small base experiment and the folder a study file is written into.

use std::path::PathBuf;

/// A short case-3-like experiment: 50 ms, 10 output steps, 6 free-free modes (fast).
pub const BASE: &str = r#"
name = "tiny"
[time]
t_end = 0.05
dt_out = 0.005
[trajectory]
kind = "polynomial"
s1 = [0.0, 0.0, 1.0]
s2 = [0.0]
s3 = [0.0, 0.0, 0.5]
[amm]
family = "free-free"
model = "paper"
modes = 6
[fem]
elements = 150
"#;

/// A temporary folder holding [`BASE`] as `base.toml` and `study` as `study.toml` (its path).
pub fn write_study(study: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.toml"), BASE).unwrap();
    let p = dir.path().join("study.toml");
    std::fs::write(&p, study).unwrap();
    (dir, p)
}
