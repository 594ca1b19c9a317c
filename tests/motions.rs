//! The trajectory kinds of `docs/motions.md` section 1 through the built binary: both
//! solvers take a via and a table config, `kinematics` gives back a table's poses at its rows, a
//! `kinematics.csv` read back as a slider-space table reproduces its own motion, and a bad table
//! is refused before anything is written.

use std::path::{Path, PathBuf};

use crate::common;
use common::{col, flexstar, stderr, table};

fn config(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/motions")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

#[test]
fn both_solvers_run_a_via_and_a_table_config() {
    let out = tempfile::tempdir().unwrap();
    let out_s = out.path().to_str().unwrap();
    for (cfg, name, rows) in [
        ("pick-place.toml", "pick-place", 1501),
        ("arc-table.toml", "arc-table", 801),
    ] {
        for (solver, file) in [("amm", "amm-enriched.csv"), ("fem", "fem.csv")] {
            let o = flexstar(&["run", &config(cfg), "--solver", solver, "--out", out_s]);
            assert!(o.status.success(), "{cfg} {solver}: {}", stderr(&o));
            let (header, data) = table(&out.path().join(name).join(file));
            assert_eq!(data.len(), rows, "{cfg} {solver}");
            // the motion moved the star: the tips vibrate
            let tip = col(&header, "w1tip");
            assert!(data.iter().any(|r| r[tip].abs() > 1e-4), "{cfg} {solver}");
        }
    }
}

/// `kinematics` of `cfg` into a fresh folder; the table of `name`.
fn kinematics(cfg: &str, name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let out = tempfile::tempdir().unwrap();
    let o = flexstar(&["kinematics", cfg, "--out", out.path().to_str().unwrap()]);
    assert!(o.status.success(), "{cfg}: {}", stderr(&o));
    table(&out.path().join(name).join("kinematics.csv"))
}

#[test]
fn kinematics_of_a_table_gives_back_its_poses_at_its_rows() {
    let (th, trows) = table(Path::new(&config("arc-table.csv")));
    let (kh, krows) = kinematics(&config("arc-table.toml"), "arc-table");
    // rows every 5 ms, output every 1 ms: row k is output 5 k; after the last row, rest
    for (k, r) in trows.iter().enumerate() {
        let out = &krows[5 * k];
        assert!((out[0] - r[0]).abs() < 1e-12);
        for name in ["Gx", "Gy", "theta"] {
            let (a, b) = (out[col(&kh, name)], r[col(&th, name)]);
            assert!((a - b).abs() < 1e-12, "row {}: {name} {a} vs {b}", k + 1);
        }
    }
    let last = trows.last().unwrap();
    for out in &krows[500..] {
        assert!((out[col(&kh, "Gx")] - last[1]).abs() < 1e-12 && out[col(&kh, "sd1")] == 0.0);
    }
}

#[test]
fn a_kinematics_table_read_as_sliders_reproduces_its_motion() {
    // the via cycle's kinematics.csv (t, s1..s3, Gx.. at 1 ms) as a slider-space table
    let (kh, krows) = kinematics(&config("pick-place.toml"), "pick-place");
    let dir = tempfile::tempdir().unwrap();
    let mut csv = kh.join(",") + "\n";
    for r in &krows {
        csv += &(r.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(",") + "\n");
    }
    std::fs::write(dir.path().join("k.csv"), csv).unwrap();
    let cfg: PathBuf = dir.path().join("sliders.toml");
    let text = "name = \"sliders\"\n[time]\nt_end = 1.5\n[trajectory]\nkind = \"table\"\nfile = \"k.csv\"\n";
    // the file holds both sets: refused until columns says which
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    let o = flexstar(&["kinematics", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(
        !o.status.success() && stderr(&o).contains("columns = \"task\" or \"slider\""),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing written");
    std::fs::write(&cfg, format!("{text}columns = \"slider\"\n")).unwrap();
    let (h2, rows2) = kinematics(cfg.to_str().unwrap(), "sliders");
    assert_eq!(h2, kh);
    for (a, b) in rows2.iter().zip(&krows) {
        for name in ["s1", "s2", "s3", "Gx", "Gy", "theta"] {
            let c = col(&kh, name);
            assert!((a[c] - b[c]).abs() < 1e-12, "t = {}: {name}", a[0]);
        }
        // velocities and accelerations of the interpolated rows: close to the via motion's
        // (the spline through 1 ms rows rounds the kinks of s'' at the points, where s''' jumps)
        for name in ["sd1", "sdd1"] {
            let c = col(&kh, name);
            let tol = if name == "sd1" { 1e-5 } else { 2e-2 };
            assert!((a[c] - b[c]).abs() < tol, "t = {}: {name} {} vs {}", a[0], a[c], b[c]);
        }
    }
}

#[test]
fn a_table_with_a_gap_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("gap.csv"),
        "t,s1,s2,s3\n0,0,0,0\n0.01,0,0,0\n0.02,0,0,0\n0.5,0,0,0\n",
    )
    .unwrap();
    let cfg = dir.path().join("gap.toml");
    std::fs::write(
        &cfg,
        "name = \"gap\"\n[time]\nt_end = 0.6\n[trajectory]\nkind = \"table\"\nfile = \"gap.csv\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    for args in [
        vec!["run", "--solver", "amm"],
        vec!["run", "--solver", "fem"],
        vec!["kinematics"],
    ] {
        let mut all = vec![args[0], cfg.to_str().unwrap()];
        all.extend(&args[1..]);
        all.extend(["--out", out.to_str().unwrap()]);
        let o = flexstar(&all);
        let e = stderr(&o);
        assert!(!o.status.success(), "{args:?}");
        assert!(
            e.contains("gap.toml") && e.contains("trajectory.file") && e.contains("gap.csv") && e.contains("rows 3-4"),
            "{e}"
        );
        assert!(!out.exists(), "{args:?}: nothing written");
    }
}
