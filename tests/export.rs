//! `flexstar export`: the setpoint table of a run (header, rows, its JSON header) and the
//! refusals of bad input (clear message, non-zero exit, nothing written).

use std::path::{Path, PathBuf};

use crate::common;
use common::{flexstar, run_solver, stderr, table, TINY};

const HEADER: &str = "t,s1,s2,s3,v1,v2,v3,a1,a2,a3,j1,j2,j3,F1,F2,F3";

/// `tiny.toml` (30 ms of a polynomial motion, `docs` of tests/data) with `extra` appended, run
/// on the AMM into `dir/out`; the run's folder.
fn tiny_run(dir: &Path, extra: &str) -> PathBuf {
    let cfg = dir.join("tiny.toml");
    std::fs::write(&cfg, format!("{TINY}{extra}")).unwrap();
    let out = dir.join("out");
    let o = run_solver(&cfg, "amm", &out);
    assert!(o.status.success(), "{}", stderr(&o));
    out.join("tiny")
}

fn export(folder: &Path, rate: &str) -> std::process::Output {
    // `--rate=X`: a negative rate is a value, not a flag
    flexstar(&["export", folder.to_str().unwrap(), &format!("--rate={rate}")])
}

fn no_setpoints(folder: &Path) -> bool {
    !folder.join("setpoints.csv").exists() && !folder.join("setpoints.json").exists()
}

#[test]
fn export_writes_the_setpoint_table_and_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let folder = tiny_run(dir.path(), "");
    let o = export(&folder, "2000");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(folder.join("setpoints.csv")).unwrap();
    assert_eq!(text.lines().next().unwrap(), HEADER);
    let (_, rows) = table(&folder.join("setpoints.csv"));
    // a polynomial never rests: 0 to t_end = 0.03 s every 0.5 ms
    assert_eq!(rows.len(), 61);
    assert!(rows.iter().all(|r| r.len() == 16));
    assert!((rows[60][0] - 0.03).abs() < 1e-15 && (rows[1][0] - 5e-4).abs() < 1e-18);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("setpoints.json")).unwrap()).unwrap();
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("amm-free-free.json")).unwrap()).unwrap();
    assert_eq!(doc["rows"], 61);
    assert_eq!(doc["rate_hz"], 2000.0);
    assert_eq!(doc["experiment"], "tiny");
    assert_eq!(doc["experiment_hash"], run["experiment_hash"]);
    assert_eq!(doc["column_units"]["j2"], "m/s^3");
    assert_eq!(doc["column_units"]["F3"], "N");
    for key in [
        "peaks",
        "interpolation_bounds",
        "flexstar_version",
        "commit",
        "f1_hz",
        "source_dir",
    ] {
        assert!(doc.get(key).is_some(), "{key} missing: {doc}");
    }
    assert!(stderr(&o).contains("a_max h^2/8"), "{}", stderr(&o));
}

#[test]
fn export_refuses_bad_input_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let folder = tiny_run(dir.path(), "");
    for (rate, needle) in [("1", "below twice"), ("200000", "above 100 kHz"), ("-5", "positive")] {
        let o = export(&folder, rate);
        assert!(!o.status.success(), "--rate {rate} accepted");
        assert!(stderr(&o).contains(needle), "--rate {rate}: {}", stderr(&o));
        assert!(stderr(&o).contains("--rate"), "{}", stderr(&o));
        assert!(no_setpoints(&folder), "--rate {rate} left a file");
    }
    // a servo run has no prescribed motion to send
    let servo_dir = tempfile::tempdir().unwrap();
    let servo = tiny_run(
        servo_dir.path(),
        "[drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n",
    );
    let o = export(&servo, "2000");
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("drive.kind") && msg.contains("prescribed motion"), "{msg}");
    assert!(no_setpoints(&servo));
    // a folder without a run or a plan
    let o = export(dir.path(), "2000");
    assert!(!o.status.success());
    assert!(stderr(&o).contains("neither a run's sidecar"), "{}", stderr(&o));
    assert!(no_setpoints(dir.path()));
}
