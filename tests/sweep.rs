//! `flexstar sweep`: four shards run as separate processes and merged give the unsharded
//! study's table row for row (all but wall_s); merging refuses shards of another study and
//! reports missing ones; bad input is refused before any run.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{flexstar, stderr};

const BASE: &str = common::TINY;

const STUDY: &str = r#"
name = "shards"
base = "base.toml"
solvers = ["amm"]
[[vary]]
key = "robot.Lp"
values = [0.02, 0.03, 0.04, 0.7]
[[vary]]
key = "robot.Jp"
linspace = [1e-4, 4e-4, 4]
[[vary]]
key = "robot.E"
values = [150e9, 200e9]
"#;

fn setup(study: &str) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.toml"), BASE).unwrap();
    let p = dir.path().join("study.toml");
    std::fs::write(&p, study).unwrap();
    (dir, p.to_string_lossy().into_owned())
}

/// The rows of a results table without the wall_s column.
fn rows_without_wall(path: &Path) -> Vec<Vec<String>> {
    let t = flexstar_study::table::Table::read(path).unwrap();
    let wall = t.column("wall_s").unwrap();
    t.rows
        .iter()
        .map(|r| {
            r.iter()
                .enumerate()
                .filter(|(i, _)| *i != wall)
                .map(|(_, v)| v.clone())
                .collect()
        })
        .collect()
}

fn out_dir(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

#[test]
fn four_shards_merged_equal_the_unsharded_study() {
    let (d, study) = setup(STUDY);
    let whole = out_dir(d.path(), "whole");
    let o = flexstar(&["sweep", &study, "--out", whole.to_str().unwrap(), "--jobs", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sharded = out_dir(d.path(), "sharded");
    let children: Vec<_> = (1..=4)
        .map(|k| {
            Command::new(env!("CARGO_BIN_EXE_flexstar"))
                .args(["sweep", &study, "--out", sharded.to_str().unwrap(), "--jobs", "1"])
                .args(["--shard", &format!("{k}/4")])
                .output_async()
        })
        .collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let dir = sharded.join("shards");
    for k in 1..=4 {
        assert!(dir.join(format!("results.shard-{k}-of-4.csv")).exists());
    }
    let o = flexstar(&["sweep", "merge", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let merged = rows_without_wall(&dir.join("results.csv"));
    let reference = rows_without_wall(&whole.join("shards").join("results.csv"));
    assert_eq!(merged.len(), 4 * 4 * 2);
    assert_eq!(merged, reference);
    assert!(dir.join("study.html").exists());
    // the failed cases (Lp = 0.7 > L) are rows, not errors
    assert_eq!(merged.iter().filter(|r| r[1] == "0.7").count(), 8);
    assert!(merged
        .iter()
        .filter(|r| r[1] == "0.7")
        .all(|r| r[5].contains("robot.Lp")));

    // a shard of another study (base changed) is refused, and nothing is written
    std::fs::write(d.path().join("base.toml"), BASE.replace("modes = 5", "modes = 4")).unwrap();
    let other = out_dir(d.path(), "other");
    let o = flexstar(&["sweep", &study, "--out", other.to_str().unwrap(), "--shard", "2/4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(dir.join("results.csv")).unwrap();
    for ext in ["csv", "meta.json"] {
        std::fs::copy(
            other.join("shards").join(format!("results.shard-2-of-4.{ext}")),
            dir.join(format!("results.shard-2-of-4.{ext}")),
        )
        .unwrap();
    }
    let o = flexstar(&["sweep", "merge", dir.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("different study"), "{}", stderr(&o));
    assert!(!dir.join("results.csv").exists());

    // a missing shard is reported with its cases; the rows present are still merged
    for ext in ["csv", "meta.json"] {
        std::fs::remove_file(dir.join(format!("results.shard-2-of-4.{ext}"))).unwrap();
    }
    let o = flexstar(&["sweep", "merge", dir.to_str().unwrap()]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("[2]") && msg.contains("8 cases"), "{msg}");
    assert_eq!(rows_without_wall(&dir.join("results.csv")).len(), 24);
}

trait OutputAsync {
    fn output_async(&mut self) -> std::process::Child;
}

impl OutputAsync for Command {
    fn output_async(&mut self) -> std::process::Child {
        self.stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("flexstar starts")
    }
}

#[test]
fn bad_input_is_refused_before_any_run() {
    let (d, study) = setup(STUDY);
    let out = d.path().join("out");
    let o = flexstar(&["sweep", &study, "--out", out.to_str().unwrap(), "--shard", "5/4"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("5/4"), "{}", stderr(&o));
    let (d2, bad) = setup(&STUDY.replace("robot.E", "robot.e"));
    let o = flexstar(&["sweep", &bad, "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("study.toml") && msg.contains("robot.e"), "{msg}");
    assert!(!out.exists(), "nothing written before the checks");
    drop(d2);
}

/// A `results.csv` of another study is refused by `merge` (and kept byte for
/// byte), and the rows of a whole-study rerun already in `results.csv` survive a later merge of
/// the shards.
#[test]
fn merge_keeps_earlier_rows_and_refuses_a_foreign_table() {
    let (d, study) = setup(STUDY);
    let out = out_dir(d.path(), "out");
    let o_str = out.to_str().unwrap();
    for k in [1, 2] {
        let o = flexstar(&[
            "sweep",
            &study,
            "--out",
            o_str,
            "--jobs",
            "1",
            "--shard",
            &format!("{k}/4"),
            "--no-plots",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    // the gaps (shards 3 and 4) filled by a whole-study run into the same folder
    let o = flexstar(&["sweep", &study, "--out", o_str, "--jobs", "2", "--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let dir = out.join("shards");
    let whole = rows_without_wall(&dir.join("results.csv"));
    assert_eq!(whole.len(), 32);
    let o = flexstar(&["sweep", "merge", dir.to_str().unwrap(), "--no-plots"]);
    assert!(
        o.status.success(),
        "the earlier table covers shards 3 and 4: {}",
        stderr(&o)
    );
    assert_eq!(
        rows_without_wall(&dir.join("results.csv")),
        whole,
        "no row lost, order kept"
    );

    // a results.csv of another study (base changed) in the folder: merge refuses, writes nothing
    std::fs::write(d.path().join("base.toml"), BASE.replace("modes = 5", "modes = 4")).unwrap();
    let other = out_dir(d.path(), "other");
    let o = flexstar(&[
        "sweep",
        &study,
        "--out",
        other.to_str().unwrap(),
        "--shard",
        "4/4",
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for ext in ["csv", "meta.json"] {
        std::fs::copy(
            other.join("shards").join(format!("results.shard-4-of-4.{ext}")),
            other.join("shards").join(format!("results.{ext}")),
        )
        .unwrap();
        for k in [1, 2] {
            std::fs::copy(
                dir.join(format!("results.shard-{k}-of-4.{ext}")),
                other.join("shards").join(format!("results.shard-{k}-of-4.{ext}")),
            )
            .unwrap();
        }
        std::fs::remove_file(other.join("shards").join(format!("results.shard-4-of-4.{ext}"))).unwrap();
    }
    let foreign = std::fs::read(other.join("shards/results.csv")).unwrap();
    let o = flexstar(&["sweep", "merge", other.join("shards").to_str().unwrap(), "--no-plots"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("another study"), "{}", stderr(&o));
    assert_eq!(std::fs::read(other.join("shards/results.csv")).unwrap(), foreign);
}

/// `--jobs` beyond what can be given is refused before anything is written.
#[test]
fn too_many_jobs_write_nothing() {
    let (d, study) = setup(STUDY);
    let out = d.path().join("out");
    let o = flexstar(&["sweep", &study, "--out", out.to_str().unwrap(), "--jobs", "10000"]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("--jobs") && msg.contains("10000"), "{msg}");
    assert!(!out.join("shards").join("results.csv").exists(), "no header-only table");
}

/// A grid of 1e8 cases (the documented maximum), one shard of 10 cases: the
/// shard's cases are made from their indices, so the run starts at once in little memory.
#[test]
fn a_shard_of_the_largest_study_runs_at_once() {
    let huge = r#"
name = "huge"
base = "base.toml"
[[vary]]
key = "robot.E"
linspace = [150e9, 200e9, 10000]
[[vary]]
key = "robot.Jp"
linspace = [1e-4, 4e-4, 10000]
"#;
    let (d, study) = setup(huge);
    let out = d.path().join("out");
    let o = flexstar(&[
        "sweep",
        &study,
        "--out",
        out.to_str().unwrap(),
        "--shard",
        "3/10000000",
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("100000000 cases"), "{}", stderr(&o));
    let t = flexstar_study::table::Table::read(&out.join("huge/results.shard-3-of-10000000.csv")).unwrap();
    assert_eq!(t.rows.len(), 10);
    // case 2 + 1e7 j: E at level j, Jp at level 2 (the second key varies fastest)
    assert_eq!(t.rows[0][1], "150000000000");
    assert_eq!(t.rows[0][2], "0.000100060006001"); // 1e-4 + 3e-4 * 2/9999 to 12 digits
}
