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

/// case1 shortened to `t_end` seconds, written into `dir`.
fn short_case1(dir: &Path, t_end: &str) -> String {
    write(
        dir,
        "short.toml",
        &case1_with("t_end = 0.5", &format!("t_end = {t_end}")),
    )
}

#[test]
fn run_writes_the_contracted_solver_tables() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = short_case1(dir.path(), "0.05");
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    for (args, file) in [
        (
            vec!["--solver", "amm", "--family", "slide-free", "--modes", "12"],
            "amm-slide-free.csv",
        ),
        (vec!["--solver", "amm"], "amm-pinned-free.csv"), // family from the config's [amm] section
        (vec!["--solver", "fem", "--elements", "108"], "fem.csv"),
    ] {
        let mut all = vec!["run", cfg.as_str()];
        all.extend(args.iter().copied());
        all.extend(["--out", out_s]);
        let o = flexstar(&all);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        let text = std::fs::read_to_string(out.join("case1").join(file)).unwrap();
        let header = text.lines().next().unwrap();
        assert!(
            header.starts_with("t,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3"),
            "{file}: {header}"
        );
        assert_eq!(text.lines().count(), 1 + 51, "{file}: one row per 1 ms output step");
    }
}

#[test]
fn run_refuses_bad_settings_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = short_case1(dir.path(), "0.05");
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["--solver", "amm", "--family", "hinged-free"], "hinged-free"),
        (&["--solver", "amm", "--modes", "0"], "amm.modes"),
        (&["--solver", "amm", "--modes", "100000"], "amm.modes"),
        (&["--solver", "amm", "--dt", "0.01"], "output interval"),
        (&["--solver", "fem", "--elements", "301"], "fem.elements"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["run", cfg.as_str()];
        all.extend(args.iter().copied());
        all.extend(["--out", out_s]);
        let o = flexstar(&all);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(!out.join("case1").exists() || std::fs::read_dir(out.join("case1")).unwrap().count() == 0);
    }
    // a trajectory that leaves the feasible range: refused with the time, nothing written
    let text = std::fs::read_to_string(config("case2.toml"))
        .unwrap()
        .replace("t_end = 0.4", "t_end = 0.5");
    let cfg2 = write(dir.path(), "case2-long.toml", &text);
    for solver in ["amm", "fem"] {
        let o = flexstar(&["run", &cfg2, "--solver", solver, "--out", out_s]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("sleeve 2"), "{solver}: {}", stderr(&o));
        assert!(!out.join("case2").join(format!("{solver}.csv")).exists());
    }
}

#[test]
fn modes_lists_textbook_roots() {
    // free-free: two rigid modes, then beta L = 4.730041, 7.853205 (Blevins, table 8-1)
    let o = flexstar(&["modes", "--family", "free-free", "-n", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("4.7300407") && text.contains("7.8532046"), "{text}");
}

#[test]
fn every_subcommand_has_help() {
    for sub in [
        vec!["--help"],
        vec!["kinematics", "--help"],
        vec!["run", "--help"],
        vec!["modes", "--help"],
        vec!["verify", "--help"],
    ] {
        let o = flexstar(&sub);
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains("Usage"));
    }
}
