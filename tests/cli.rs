//! End-to-end checks of the `flexstar` binary: file contracts (paths, CSV headers) and the
//! handling of bad input (clear message, non-zero exit, no partial output).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexstar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexstar"))
        .args(args)
        .output()
        .expect("flexstar runs")
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn config(name: &str) -> String {
    root().join("configs").join(name).to_string_lossy().into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn kinematics_writes_the_contracted_table() {
    let out = tempfile::tempdir().unwrap();
    for case in ["case1", "case2", "case3", "case4"] {
        let o = flexstar(&[
            "kinematics",
            &config(&format!("{case}.toml")),
            "--out",
            out.path().to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{case}: {}", stderr(&o));
        let text = std::fs::read_to_string(out.path().join(case).join("kinematics.csv")).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next().unwrap(),
            "t,s1,s2,s3,Gx,Gy,theta,xp1,xp2,xp3,aGx,aGy,thetadot,thetaddot"
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        // one row per output step of 1 ms
        let t_end = if case == "case2" { 0.4 } else { 0.5 };
        assert_eq!(rows.len(), (t_end / 0.001f64).round() as usize + 1);
        assert!((rows.last().unwrap()[0] - t_end).abs() < 1e-12);
        assert!(rows.iter().all(|r| r.len() == 14));
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

fn case1_with(old: &str, new: &str) -> String {
    let text = std::fs::read_to_string(config("case1.toml")).unwrap();
    assert!(text.contains(old), "{old}");
    text.replace(old, new)
}

/// Run `kinematics` on a bad file: non-zero exit, every `needles` in the message, no output.
fn refused(file_text: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "bad.toml", file_text);
    let out = dir.path().join("out");
    let o = flexstar(&["kinematics", &cfg, "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    for n in needles {
        assert!(msg.contains(n), "missing {n:?} in {msg}");
    }
    assert!(
        !out.join("case1").join("kinematics.csv").exists(),
        "partial output left behind"
    );
}

#[test]
fn bad_input_is_refused_with_file_key_and_reason() {
    refused(&case1_with("Lp = 0.03", "Lp = 0.03\nLq = 1.0"), &["bad.toml", "Lq"]);
    refused(&case1_with("rho = 0.234", "rho = nan"), &["bad.toml", "robot.rho"]);
    refused(&case1_with("E = 200e9", "E = -200e9"), &["bad.toml", "robot.E"]);
    refused(&case1_with("t_end = 0.5", "t_end = 0.0"), &["bad.toml", "time.t_end"]);
    refused(
        &case1_with("kind = \"polynomial\"", "kind = \"spline\""),
        &["bad.toml", "spline"],
    );
    // infeasible from the start: slider 1 beyond the base side
    refused(
        &case1_with("s1 = [0.0, 0.0, 1.0]", "s1 = [0.5]"),
        &["t = 0.0000", "slider 1"],
    );
}

#[test]
fn case2_beyond_its_span_is_refused_with_the_time() {
    let text = std::fs::read_to_string(config("case2.toml"))
        .unwrap()
        .replace("t_end = 0.4", "t_end = 0.5");
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "case2-long.toml", &text);
    let out = dir.path().join("out");
    let o = flexstar(&["kinematics", &cfg, "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    let t: f64 = msg
        .split("t = ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .expect(&msg);
    assert!(t > 0.40 && t < 0.44, "{msg}");
    assert!(msg.contains("sleeve 2"), "{msg}");
    assert!(!out.join("case2").join("kinematics.csv").exists());
}

#[test]
fn every_subcommand_has_help() {
    for sub in [vec!["--help"], vec!["kinematics", "--help"]] {
        let o = flexstar(&sub);
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains("Usage"));
    }
}
