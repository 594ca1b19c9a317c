//! End-to-end checks of the `flexstar` binary: file contracts (paths, CSV headers) and the
//! handling of bad input (clear message, non-zero exit, no partial output).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{flexstar, run_solver, stderr};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn config(name: &str) -> String {
    root().join("configs").join(name).to_string_lossy().into_owned()
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
            "t,s1,s2,s3,Gx,Gy,theta,xp1,xp2,xp3,aGx,aGy,thetadot,thetaddot,\
             sd1,sd2,sd3,sdd1,sdd2,sdd3,Fa1,Fa2,Fa3"
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        // one row per output step of 1 ms
        let t_end = if case == "case2" { 0.4 } else { 0.5 };
        assert_eq!(rows.len(), (t_end / 0.001f64).round() as usize + 1);
        assert!((rows.last().unwrap()[0] - t_end).abs() < 1e-12);
        assert!(rows.iter().all(|r| r.len() == 23));
        kinematics_rates_and_forces_are_consistent(case, &rows);
    }
}

/// The slider rates of `kinematics.csv` against central differences of its own columns, and the
/// rigid driving forces against the power balance of the rigid robot (paper parameters):
/// `sum Fa_i sd_i = dT/dt`, T = 1/2 m |v_G|^2 + 1/2 (rho L^3 + 3 Jp) theta'^2 + 1/2 (mpp+mpa)
/// sum sd_i^2, with v_G and dT/dt differenced from the file's rows (an independent check of Fa).
fn kinematics_rates_and_forces_are_consistent(case: &str, rows: &[Vec<f64>]) {
    let (rho, l, jp, m_s) = (0.234, 0.5, 2e-4, 0.2);
    let (m, j) = (3.0 * rho * l, rho * l * l * l + 3.0 * jp);
    let h = rows[1][0] - rows[0][0];
    let d = |k: usize, c: usize| (rows[k + 1][c] - rows[k - 1][c]) / (2.0 * h);
    let energy = |k: usize| {
        let (vx, vy) = (d(k, 4), d(k, 5));
        let sd2: f64 = (14..17).map(|c| rows[k][c] * rows[k][c]).sum();
        0.5 * m * (vx * vx + vy * vy) + 0.5 * j * rows[k][12] * rows[k][12] + 0.5 * m_s * sd2
    };
    let scale_f = rows
        .iter()
        .flat_map(|r| r[20..23].iter())
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let scale_p = rows
        .iter()
        .map(|r| (0..3).map(|i| (r[20 + i] * r[14 + i]).abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    assert!(scale_f > 0.0, "{case}: the rigid forces are all zero");
    for (k, row) in rows.iter().enumerate().take(rows.len() - 2).skip(2) {
        for i in 0..3 {
            let (sd, sdd) = (row[14 + i], row[17 + i]);
            assert!(
                (sd - d(k, 1 + i)).abs() < 1e-6 * (1.0 + sd.abs()),
                "{case} row {k}: sd{} {sd}",
                i + 1
            );
            assert!(
                (sdd - d(k, 14 + i)).abs() < 1e-6 * (1.0 + sdd.abs()),
                "{case} row {k}: sdd{}",
                i + 1
            );
        }
        let power: f64 = (0..3).map(|i| row[20 + i] * row[14 + i]).sum();
        let dtdt = (energy(k + 1) - energy(k - 1)) / (2.0 * h);
        assert!(
            (power - dtdt).abs() < 1e-3 * scale_p.max(1e-9),
            "{case} row {k}: power of the rigid forces {power} W, dT/dt {dtdt} W"
        );
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
    // values whose derived quantities overflow: refused before any work, not NaN/inf in the table
    refused(
        &case1_with("L = 0.5", "L = 1e300"),
        &["bad.toml", "robot.L", "1e300", "overflow"],
    );
    refused(
        &case1_with("mpp_mpa = 0.2", "mpp_mpa = 1e308"),
        &["bad.toml", "Fa1", "not finite"],
    );
    // infeasible from the start: slider 1 beyond the base side
    refused(
        &case1_with("s1 = [0.0, 0.0, 1.0]", "s1 = [0.5]"),
        &["t = 0.0000", "slider 1"],
    );
}

/// A slider mass that makes the driving forces overflow is refused by the solvers too, with
/// nothing written (the inverse problem's `Fa = mpp_mpa s'' + ...` is infinite).
#[test]
fn runs_whose_values_overflow_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "heavy.toml",
        &common::TINY.replace("[time]", "[robot]\nmpp_mpa = 1e308\n[time]"),
    );
    let (out, c) = (dir.path().join("out"), cfg.as_str());
    for mut args in [
        vec!["run", c, "--solver", "amm"],
        vec!["run", c, "--solver", "fem", "--elements", "120"],
        vec!["compare", c, "--no-figures"],
    ] {
        args.extend(["--out", out.to_str().unwrap()]);
        let o = flexstar(&args);
        let err = stderr(&o);
        assert!(
            !o.status.success() && err.contains("heavy.toml") && err.contains("Fa1") && err.contains("not finite"),
            "{args:?}: {err}"
        );
        let written: Vec<_> = std::fs::read_dir(out.join("tiny"))
            .map(|d| d.count())
            .into_iter()
            .collect();
        assert!(written.iter().all(|n| *n == 0), "{args:?}: files written");
    }
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
    // stderr says what is solved in words (`N = 12`, `tol = 2 %`), not in Debug forms
    for (args, file, said) in [
        (
            vec!["--solver", "amm", "--family", "slide-free", "--modes", "12"],
            "amm-slide-free.csv",
            "case1: AMM, N = 12, slide-free",
        ),
        // family from the config's [amm] section
        (
            vec!["--solver", "amm"],
            "amm-pinned-free.csv",
            "case1: AMM, N = 25, pinned-free",
        ),
        (
            vec!["--solver", "amm", "--family", "enriched", "--tol", "2"],
            "amm-enriched.csv",
            "case1: AMM, tol = 2 %, enriched",
        ),
        (
            vec!["--solver", "fem", "--elements", "108"],
            "fem.csv",
            "case1: FEM, 108 elements",
        ),
    ] {
        let mut all = vec!["run", cfg.as_str()];
        all.extend(args.iter().copied());
        all.extend(["--out", out_s]);
        let o = flexstar(&all);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(said), "{args:?}: {}", stderr(&o));
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
    // a flag's error names the flag first, with no empty file or key parts
    let cases: [(&[&str], &str); 10] = [
        (&["--solver", "amm", "--family", "hinged-free"], "hinged-free"),
        (&["--solver", "amm", "--modes", "0"], "error: --modes: need 1 <= modes <= 400, got 0"),
        (&["--solver", "amm", "--modes", "100000"], "error: --modes: need 1 <= modes <= 400"),
        (
            &["--solver", "amm", "--dt", "0.01"],
            "error: --dt: the step 0.01 s is larger than the output interval",
        ),
        (&["--solver", "fem", "--dt=-1"], "error: --dt: the step must be positive, got -1"),
        (&["--solver", "fem", "--elements", "301"], "error: --elements: need a multiple of 3"),
        (
            &["--solver", "amm", "--tol=-0.5"],
            "error: --tol: the tolerance must be a positive percentage, got -0.5",
        ),
        (&["--solver", "amm", "--tol", "1e-9"], "error: --tol: the tolerance 0.000000001 % is below"),
        (
            &["--solver", "amm", "--family", "enriched", "--modes", "2"],
            "error: --modes: the enriched family needs N >= 4",
        ),
        // the file refuses `modes` with `tol`; so do the flags, in the same words
        (
            &["--solver", "amm", "--modes", "10", "--tol", "0.5"],
            "error: --modes, --tol: give either --modes (a fixed N) or --tol (N chosen to meet the tolerance), not both",
        ),
    ];
    for (args, needle) in cases {
        let mut all = vec!["run", cfg.as_str()];
        all.extend(args.iter().copied());
        all.extend(["--out", out_s]);
        let o = flexstar(&all);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(
            !stderr(&o).contains(": : ") && !stderr(&o).contains("key ``"),
            "{}",
            stderr(&o)
        );
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
fn direct_runs_write_the_contracted_tables() {
    // an inverse run's output fed back with --forces, and a servo drive in the config
    let dir = tempfile::tempdir().unwrap();
    let cfg = short_case1(dir.path(), "0.05");
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let o = flexstar(&["run", &cfg, "--solver", "amm", "--out", out_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let inverse = out.join("case1").join("amm-pinned-free.csv");
    let o = flexstar(&[
        "run",
        &cfg,
        "--solver",
        "amm",
        "--forces",
        inverse.to_str().unwrap(),
        "--out",
        out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("case1").join("amm-pinned-free-direct.csv")).unwrap();
    let header = text.lines().next().unwrap();
    assert!(
        header.starts_with("t,s1,s2,s3,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3,Gx,Gy,theta,"),
        "{header}"
    );
    assert_eq!(text.lines().count(), 1 + 51);
    // s1 = t^2 comes back (the forces sampled at 1 ms, linearly interpolated)
    let last: Vec<f64> = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((last[1] - 0.05f64 * 0.05).abs() < 1e-5, "s1(0.05) = {}", last[1]);
    assert!(out.join("case1").join("amm-pinned-free-direct.json").exists());
    // the FEM driven by the same forces: the same leading columns
    let o = flexstar(&[
        "run",
        &cfg,
        "--solver",
        "fem",
        "--elements",
        "108",
        "--forces",
        inverse.to_str().unwrap(),
        "--out",
        out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("case1").join("fem-direct.csv")).unwrap();
    assert!(
        text.starts_with("t,s1,s2,s3,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3,Gx,Gy,theta,"),
        "{}",
        text.lines().next().unwrap()
    );
    assert_eq!(text.lines().count(), 1 + 51);
    assert!(out.join("case1").join("fem-direct.json").exists());

    let servo = write(
        dir.path(),
        "servo.toml",
        &case1_with("t_end = 0.5", "t_end = 0.05").replace(
            "[amm]",
            "[drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n\n[amm]",
        ),
    );
    let o = flexstar(&["run", &servo, "--solver", "amm", "--out", out_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("case1").join("amm-pinned-free-direct.csv")).unwrap();
    assert!(
        text.starts_with("t,s1,s2,s3,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3,Gx,Gy,theta,e1,e2,e3,"),
        "{}",
        text.lines().next().unwrap()
    );
}

#[test]
fn direct_runs_refuse_bad_forces_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = short_case1(dir.path(), "0.05");
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    for (name, text, needle) in [
        ("nofa.csv", "t,F1,F2,F3\n0,1,1,1\n0.05,1,1,1\n", "Fa1"),
        (
            "back.csv",
            "t,Fa1,Fa2,Fa3\n0,1,1,1\n0.03,1,1,1\n0.02,1,1,1\n0.05,1,1,1\n",
            "row 3",
        ),
        ("short.csv", "t,Fa1,Fa2,Fa3\n0,1,1,1\n0.04,1,1,1\n", "span"),
    ] {
        let f = write(dir.path(), name, text);
        let o = flexstar(&["run", &cfg, "--solver", "amm", "--forces", &f, "--out", out_s]);
        assert!(!o.status.success(), "{name} accepted");
        let msg = stderr(&o);
        assert!(msg.contains(name) && msg.contains(needle), "{name}: {msg}");
        assert!(!out.join("case1").exists(), "{name}: output created");
    }
}

#[test]
fn modes_lists_textbook_roots() {
    // free-free: two rigid modes, then beta L = 4.730041, 7.853205 (Blevins, table 8-1)
    let o = flexstar(&["modes", "--family", "free-free", "-n", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("4.7300407") && text.contains("7.8532046"), "{text}");
    // the parameters read as a person writes them (E I = 0.5 N m^2, not 0.49999999999999994)
    assert!(
        text.starts_with("# free-free modes, L = 0.5 m, EI = 0.5 N m^2, rho = 0.234 kg/m\n"),
        "{text}"
    );
    // a bad N names the flag, not an empty file
    let o = flexstar(&["modes", "--family", "enriched", "-n", "1"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("error: --modes: the enriched family needs N >= 4"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn every_subcommand_has_help() {
    for sub in [
        vec!["--help"],
        vec!["kinematics", "--help"],
        vec!["run", "--help"],
        vec!["modes", "--help"],
        vec!["verify", "--help"],
        vec!["compare", "--help"],
    ] {
        let o = flexstar(&sub);
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains("Usage"));
    }
}

/// case1 shortened to 0.05 s with a small mesh and N = 12, written into `dir` as `name`.
fn small_case1(dir: &Path, name: &str) -> String {
    let text = case1_with("t_end = 0.5", "t_end = 0.05")
        .replace("elements = 300", "elements = 108")
        .replace("modes = 25", "modes = 12");
    write(dir, name, &text)
}

#[test]
fn compare_writes_its_outputs_for_any_experiment() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = small_case1(dir.path(), "mine.toml");
    let out = dir.path().join("out");
    let o = flexstar(&[
        "compare",
        &cfg,
        "--families",
        "free-free,slide-free",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = out.join("case1");
    let csv = std::fs::read_to_string(case.join("compare.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "model,evp_A,evp_B,evp_C,evp_G,evp_mean");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // the config's own family first, then the families asked
    let models: Vec<&str> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(models, ["amm-pinned-free", "amm-free-free", "amm-slide-free"]);
    for r in &rows {
        // case 1 is symmetric: G does not move in the FEM, so its EVP is n/a as in Table I
        assert_eq!(r[4], "n/a", "{r:?}");
        for v in [r[1], r[2], r[3], r[5]] {
            assert!(v.parse::<f64>().unwrap() >= 0.0, "{r:?}");
        }
    }
    for f in [
        "compare.md",
        "compare.json",
        "report.html",
        "fem.csv",
        "fem.json",
        "amm-slide-free.csv",
        "amm-slide-free.json",
        "figures/case1-tips.svg",
        "figures/case1-forces.png",
    ] {
        assert!(case.join(f).exists(), "{f} missing");
    }
    // a prescribed motion: the dashed force curve is its rigid-body inverse dynamics; no servo
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    assert!(
        md.contains("Actuator forces against the rigid-body inverse dynamics"),
        "{md}"
    );
    assert!(!md.contains("## Servo") && !case.join("figures/case1-sliders.svg").exists());
    let sidecar = std::fs::read_to_string(case.join("fem.json")).unwrap();
    for key in [
        "\"flexstar_version\"",
        "\"commit\"",
        "\"date\"",
        "\"small_deflection\": null",
        "\"wall_s\"",
    ] {
        assert!(sidecar.contains(key), "{key} missing in {sidecar}");
    }
    let html = std::fs::read_to_string(case.join("report.html")).unwrap();
    assert!(
        !html.contains("paper's"),
        "no paper wording in a report of the user's experiment"
    );
    assert!(html.contains("<figcaption>") && html.contains("href=\"fem.csv\""));
}

#[cfg(unix)]
#[test]
fn output_files_have_normal_permissions_and_exact_numbers() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let cfg = small_case1(dir.path(), "mine.toml");
    let out = dir.path().join("out");
    let o = flexstar(&["run", &cfg, "--solver", "amm", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = flexstar(&["kinematics", &cfg, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // what File::create gives in the same place under the test's umask
    let reference = out.join("case1").join("reference");
    std::fs::File::create(&reference).unwrap();
    let want = std::fs::metadata(&reference).unwrap().permissions().mode() & 0o777;
    for f in [
        "amm-pinned-free.csv",
        "amm-pinned-free.json",
        "amm-pinned-free-shapes.csv",
        "kinematics.csv",
    ] {
        let mode = std::fs::metadata(out.join("case1").join(f))
            .unwrap()
            .permissions()
            .mode()
            & 0o777;
        assert_eq!(mode, want, "{f}: {mode:o} instead of {want:o}");
    }
    for f in ["amm-pinned-free.csv", "kinematics.csv"] {
        let text = std::fs::read_to_string(out.join("case1").join(f)).unwrap();
        for field in text.lines().skip(1).flat_map(|l| l.split(',')) {
            assert!(!field.starts_with("-0") || field.starts_with("-0."), "{f}: {field}");
            let v: f64 = field.parse().unwrap();
            assert!(v != 0.0 || field == "0", "{f}: zero written as {field}");
            // shortest exact form: no shorter spelling of the same value
            assert!(
                field.len() <= format!("{v:e}").len() && field.len() <= format!("{v}").len(),
                "{f}: {field}"
            );
        }
    }
}

/// `compare` on a robot as built under a servo (`docs/as-built.md` 6-7): the AMM within the
/// robots-as-built targets of the FEM (mean EVP at most 1 %), and each slider's gains from the
/// bandwidth on its own mass, `kp_i = m_i (2 pi f)^2`, `kd_i = 2 zeta m_i 2 pi f` (formulas
/// written here), in compare.md.
#[test]
fn compare_takes_a_robot_as_built_and_its_servo_per_slider() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("configs/servo/case3-servo.toml"))
        .unwrap()
        .replace(
            "mpp_mpa = 0.2   # kg",
            "mpp_mpa = [0.2, 0.26, 0.17]\nweld_deg = [0, 121.5, 238]",
        )
        .replace("d = 0.18        # m\n", "")
        .replace("t_end = 0.5 ", "t_end = 0.3 ")
        + "[base]\nsides = [0.63, 0.6, 0.64]\n";
    let cfg = dir.path().join("built.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    let o = flexstar(&[
        "compare",
        cfg.to_str().unwrap(),
        "--no-figures",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = out.join("case3-servo");
    let csv = std::fs::read_to_string(case.join("compare.csv")).unwrap();
    let mean: f64 = csv.lines().nth(1).unwrap().split(',').nth(5).unwrap().parse().unwrap();
    assert!(mean <= 1.0, "mean EVP {mean} %");
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    let w = 2.0 * std::f64::consts::PI * 20.0;
    for (i, m) in [0.2, 0.26, 0.17].iter().enumerate() {
        let at = md.find(&format!("slider {}: kp = ", i + 1)).expect("per-slider gains") + 15;
        let number = |from: usize| md[from..].split(' ').next().unwrap().parse::<f64>().unwrap();
        let kp = number(at);
        let kd = number(at + md[at..].find("kd = ").unwrap() + 5);
        // the report prints five significant digits
        assert!((kp / (m * w * w) - 1.0).abs() < 1e-4, "slider {}: kp {kp}", i + 1);
        assert!(
            (kd / (2.0 * 0.7 * m * w) - 1.0).abs() < 1e-4,
            "slider {}: kd {kd}",
            i + 1
        );
    }
}

#[test]
fn compare_refuses_bad_input_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let good = small_case1(dir.path(), "mine.toml");
    let bad_key = write(dir.path(), "bad.toml", &case1_with("Lp = 0.03", "Lp = 0.03\nLq = 1.0"));
    let long2 = write(
        dir.path(),
        "case2-long.toml",
        &std::fs::read_to_string(config("case2.toml"))
            .unwrap()
            .replace("t_end = 0.4", "t_end = 0.5"),
    );
    let cases: [(&[&str], &[&str]); 4] = [
        (&[bad_key.as_str()], &["bad.toml", "Lq"]),
        (
            &[good.as_str(), "--modes", "0"],
            &["mine.toml", "--modes 0", "amm.modes"],
        ),
        (&[long2.as_str()], &["case2-long.toml", "t = 0.43", "sleeve 2"]),
        (&[good.as_str(), "--families", "hinged-free"], &["hinged-free"]),
    ];
    for (args, needles) in cases {
        let mut all = vec!["compare"];
        all.extend(args.iter().copied());
        all.extend(["--out", out_s]);
        let o = flexstar(&all);
        assert!(!o.status.success(), "{args:?} accepted");
        for n in needles {
            assert!(stderr(&o).contains(n), "{args:?}: missing {n:?} in {}", stderr(&o));
        }
        assert!(!out.exists(), "{args:?}: output written");
    }
    // --out names a file: refused before any solve, the file untouched
    let file = write(dir.path(), "not-a-dir", "keep");
    let started = std::time::Instant::now();
    let o = flexstar(&["compare", &good, "--out", &file]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("not-a-dir"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
    let o2 = flexstar(&["run", &good, "--solver", "fem", "--out", &file]);
    assert!(
        !o2.status.success() && stderr(&o2).contains("not-a-dir"),
        "{}",
        stderr(&o2)
    );
    eprintln!("refusals took {:.2} s", started.elapsed().as_secs_f64());
}

#[test]
fn verify_runs_from_any_directory_with_its_built_in_cases() {
    // from an empty directory, with --out naming a file: the built-in cases and thresholds load
    // (no "configs/... not found") and the output check refuses before any solve
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "a-file", "x");
    let o = Command::new(env!("CARGO_BIN_EXE_flexstar"))
        .args(["verify", "--out", &file])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("a-file") && msg.contains("not a directory"), "{msg}");
    assert!(!msg.contains("thresholds.toml: cannot"), "{msg}");
}

#[test]
fn small_deflection_range_is_reported_with_the_time() {
    // s_i = 50 t^2 for 0.07 s: tips reach 40 % of L, far outside linear beam theory
    let dir = tempfile::tempdir().unwrap();
    let text = case1_with("t_end = 0.5", "t_end = 0.07")
        .replace("s1 = [0.0, 0.0, 1.0]", "s1 = [0.0, 0.0, 50.0]")
        .replace("s2 = [0.0, 0.0, 1.0]", "s2 = [0.0, 0.0, 50.0]")
        .replace("s3 = [0.0, 0.0, 1.0]", "s3 = [0.0, 0.0, 50.0]")
        .replace("modes = 25", "modes = 12");
    let cfg = write(dir.path(), "fast.toml", &text);
    let out = dir.path().join("out");
    let o = flexstar(&["run", &cfg, "--solver", "amm", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(
        msg.contains("warning: ") && msg.contains("fast.toml") && msg.contains("small-deflection"),
        "{msg}"
    );
    let sidecar = std::fs::read_to_string(out.join("case1").join("amm-pinned-free.json")).unwrap();
    assert!(
        sidecar.contains("\"quantity\": \"|w1tip| / L\"") && sidecar.contains("\"bound\": 0.05"),
        "{sidecar}"
    );
}

#[test]
fn a_servo_run_with_figures_draws_sliders_tracking_tips_and_forces() {
    let out = tempfile::tempdir().unwrap();
    let cfg = root().join("configs/servo/case4-servo.toml");
    let o = flexstar(&[
        "run",
        cfg.to_str().unwrap(),
        "--solver",
        "amm",
        "--modes",
        "25",
        "--figures",
        "--out",
        out.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let dir = out.path().join("case4-servo");
    let header = std::fs::read_to_string(dir.join("amm-enriched-direct.csv")).unwrap();
    assert!(header.starts_with("t,s1,s2,s3,w1G,w2G,w3G,w1tip,w2tip,w3tip,Fa1,Fa2,Fa3,Gx,Gy,theta,e1,e2,e3"));
    for kind in ["sliders", "tracking", "tips", "forces"] {
        for ext in ["svg", "png"] {
            let f = dir.join(format!("figures/amm-enriched-direct-{kind}.{ext}"));
            assert!(
                f.metadata().map(|m| m.len() > 1000).unwrap_or(false),
                "{} missing",
                f.display()
            );
        }
    }
}

/// The header of a CSV file and its sidecar JSON.
fn csv_and_sidecar(dir: &Path, stem: &str) -> (Vec<String>, serde_json::Value) {
    let csv = std::fs::read_to_string(dir.join(format!("{stem}.csv"))).unwrap();
    let header = csv.lines().next().unwrap().split(',').map(str::to_string).collect();
    let json = std::fs::read_to_string(dir.join(format!("{stem}.json"))).unwrap();
    (header, serde_json::from_str(&json).unwrap())
}

#[test]
fn sidecars_give_every_column_its_unit_and_the_values_used() {
    // AMM and FEM, inverse and direct (a servo); units as in docs/outputs.md
    // (flexstar_model's table is checked against the page in its own tests)
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let inverse = write(dir.path(), "tiny.toml", common::TINY);
    let servo = write(
        dir.path(),
        "servo.toml",
        &format!(
            "{}\n[drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n",
            common::TINY
        ),
    );
    let unit = |name: &str| -> Option<&'static str> {
        let units: &[(&[&str], &str)] = &[
            (&["t"], "s"),
            (
                &["Fa1", "Fa2", "Fa3", "Fix1", "Fw", "Fp2", "FLp3", "FRp1", "Fn1", "Fn3"],
                "N",
            ),
            (&["M1G", "M3G", "Mp2"], "N m"),
            (&["w1G", "w3tip", "s2", "Gx", "dGy", "xp1", "u3", "e1", "e3"], "m"),
            (&["theta", "thp1", "slopeG"], "rad"),
            (&["sd1", "sd3"], "m/s"),
            (&["Ek_star", "U", "W"], "J"),
        ];
        units.iter().find(|(names, _)| names.contains(&name)).map(|(_, u)| *u)
    };
    for (cfg, solver, stem) in [
        (&inverse, "amm", "amm-free-free"),
        (&inverse, "fem", "fem"),
        (&servo, "amm", "amm-free-free-direct"),
        (&servo, "fem", "fem-direct"),
    ] {
        let mut args = vec!["run", cfg.as_str(), "--solver", solver, "--out", out_s];
        if solver == "fem" {
            args.extend(["--elements", "108"]);
        }
        let o = flexstar(&args);
        assert!(o.status.success(), "{stem}: {}", stderr(&o));
        let (header, doc) = csv_and_sidecar(&out.join("tiny"), stem);
        let units = doc["column_units"]
            .as_object()
            .unwrap_or_else(|| panic!("{stem}: {doc}"));
        assert_eq!(units.len(), header.len(), "{stem}: {units:?} for {header:?}");
        for c in &header {
            let u = units.get(c).and_then(|u| u.as_str());
            assert!(u.is_some(), "{stem}: column {c} has no unit");
            if let Some(want) = unit(c) {
                assert_eq!(u, Some(want), "{stem}: {c}");
            }
        }
        // the resolved experiment: the values used, where the file left a default
        let exp = &doc["experiment"];
        assert!(exp["robot"]["EA"].as_f64().unwrap() > 0.0, "{stem}: {exp}");
        if solver == "amm" {
            assert_eq!(exp["amm"]["dt"].as_f64(), doc["dt"].as_f64(), "{stem}");
            assert_eq!(exp["amm"]["modes"], 5, "{stem}");
            assert!(exp["amm"]["tol"].is_null(), "{stem}: a fixed N uses no tolerance");
        } else {
            assert_eq!(exp["fem"]["dt"].as_f64(), doc["dt"].as_f64(), "{stem}");
            assert_eq!(exp["fem"]["elements"], 108, "{stem}");
            assert_eq!(exp["fem"]["rho_inf"].as_f64(), Some(0.7), "{stem}");
        }
    }
}

#[test]
fn compare_of_a_servo_experiment_shows_the_servo_and_its_tracking() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = write(
        dir.path(),
        "servo.toml",
        &format!(
            "{}\n[fem]\nelements = 108\n[drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n",
            common::TINY
        ),
    );
    let o = flexstar(&["compare", &cfg, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    // the table first (as compare.csv), then the servo
    assert!(
        stdout.starts_with("model,evp_A,evp_B,evp_C,evp_G,evp_mean\n"),
        "{stdout}"
    );
    // kp = m (2 pi f)^2 = 0.2 kg (2 pi 20 Hz)^2 = 3158.3 N/m
    assert!(
        stdout.contains("servo: bandwidth 20 Hz, damping ratio 0.7, so kp = 3.1583e3 N/m"),
        "{stdout}"
    );
    let case = out.join("tiny");
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    assert!(
        md.contains("## Servo") && md.contains("| fem |") && md.contains("| amm-free-free |"),
        "{md}"
    );
    // the tracking error against the reference s1 = t^2, s2 = 0, s3 = t^2 / 2, from the FEM's file
    let text = std::fs::read_to_string(case.join("fem.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|c| *c == n).unwrap();
    let (mut max, mut sum2, mut n) = (0.0f64, 0.0, 0.0);
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let t = v[col("t")];
        for (i, s_ref) in [t * t, 0.0, 0.5 * t * t].into_iter().enumerate() {
            let e = s_ref - v[col(&format!("s{}", i + 1))];
            max = max.max(e.abs());
            sum2 += e * e;
            n += 1.0;
        }
    }
    let want = format!(
        "tracking error fem: max {:.4} mm, RMS {:.4} mm",
        max * 1e3,
        (sum2 / n).sqrt() * 1e3
    );
    assert!(stdout.contains(&want), "{want} not in {stdout}");
    assert!(stdout.contains("tracking error amm-free-free: max "), "{stdout}");
    // the reference drawn in the sliders figure; the forces caption says what the dashed line is
    assert!(case.join("figures/tiny-sliders.svg").exists());
    assert!(
        md.contains("rigid-body inverse dynamics of its reference motion"),
        "{md}"
    );
    let html = std::fs::read_to_string(case.join("report.html")).unwrap();
    assert!(
        html.contains("<h3>Servo</h3>") && html.contains("tiny-sliders"),
        "servo missing in the report"
    );
}

#[test]
fn compare_of_a_forces_drive_says_what_its_force_figure_draws() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = write(
        dir.path(),
        "forces.toml",
        &format!(
            "{}\n[fem]\nelements = 108\n[drive]\nkind = \"forces\"\nFa1 = [0.0]\nFa2 = [0.0]\nFa3 = [0.0]\n",
            common::TINY
        ),
    );
    let o = flexstar(&["compare", &cfg, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(!stdout.contains("servo"), "{stdout}");
    let md = std::fs::read_to_string(out.join("tiny/compare.md")).unwrap();
    assert!(md.contains("The forces the [drive] prescribes"), "{md}");
    assert!(
        !md.contains("Actuator forces against the rigid-body inverse dynamics"),
        "{md}"
    );
}

/// The validated envelope (docs/validation.md section 8): an AMM run of the
/// accurate model on the paper's robot, or on another robot inside the envelope's ranges, is
/// inside; the paper's equations, a robot whose sleeve inertia or axial stiffness lies beyond
/// the envelope's range, are outside, with the reasons in the sidecar and a note on stderr (the
/// values of Jp/(rho L^3) and EA L^2 / EI computed here from the robot's own numbers).
#[test]
fn the_sidecar_says_whether_the_run_lies_in_the_validated_envelope() {
    let out = tempfile::tempdir().unwrap();
    let base = "[time]\nt_end = 0.05\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0, 0.0, 1.0]\ns2 = [0.0]\ns3 = [0.0, 0.0, 0.5]\n";
    let cases = [
        ("inside", "", true, None),
        // a heavier beam: Jp/(rho L^3) = 2e-4 / (0.3 * 0.125) = 0.0053, EA = 200e9 * 0.3 / 7800,
        // EA L^2 / EI = 3.8e6, all inside
        ("other-robot", "[robot]\nrho = 0.3\n", true, None),
        // EA L^2 / EI = 1e4 * 0.25 / 0.5 = 5000, below the draw's 5.8e4
        (
            "soft-axis",
            "[robot]\nEA = 1e4\n",
            false,
            Some("EA L^2/EI = 5000 is outside"),
        ),
        (
            "paper-model",
            "[amm]\nfamily = \"free-free\"\nmodel = \"paper\"\nmodes = 10\n",
            false,
            Some("free-free, paper"),
        ),
        // Jp / (rho L^3) = 0.01 / (0.234 * 0.5^3) = 0.342, beyond the range's 0.1
        (
            "heavy-sleeve",
            "[robot]\nJp = 0.01\n",
            false,
            Some("Jp/(rho L^3) = 0.3419"),
        ),
    ];
    for (name, extra, inside, reason) in cases {
        let cfg = out.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, format!("name = \"{name}\"\n{base}{extra}")).unwrap();
        let o = run_solver(&cfg, "amm", out.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let dir = out.path().join(name);
        let json = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|x| x == "json"))
            .unwrap();
        let meta: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
        assert_eq!(meta["validated_envelope"], inside, "{name}: {meta:#}");
        let reasons = meta["validated_envelope_reasons"].to_string();
        assert_eq!(stderr(&o).contains("outside the validated envelope"), !inside, "{name}");
        if let Some(r) = reason {
            assert!(reasons.contains(r), "{name}: {reasons}");
        }
    }
}

/// Two experiment files with the same `name` share `out/<name>/`: a command that replaces results
/// of another experiment there (another file with another hash) says so on stderr, naming the
/// other file (docs/outputs.md, "Whose folder"); the same file again, edited or not, and an
/// identical copy (the same results) pass without a word.
#[test]
fn replacing_results_of_another_experiment_with_the_same_name_is_said() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let out_s = out.to_str().unwrap();
    let (a, b, c) = (tmp.path().join("a"), tmp.path().join("b"), tmp.path().join("c"));
    for d in [&a, &b, &c] {
        std::fs::create_dir_all(d).unwrap();
    }
    let tiny = common::TINY;
    let copied = tiny.replace("[time]", "[robot]\nE = 150e9\n[time]");
    let fa = write(&a, "tiny.toml", tiny);
    let fb = write(&b, "tiny.toml", &copied);
    let fc = write(&c, "copy.toml", &copied);
    let note = "holds results of another experiment named `tiny`";
    let run = |cfg: &str| {
        let o = flexstar(&["run", cfg, "--solver", "amm", "--out", out_s]);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    assert!(!run(&fa).contains(note));
    let err = run(&fb);
    let a_abs = std::fs::canonicalize(&fa).unwrap();
    assert!(err.contains(note) && err.contains(a_abs.to_str().unwrap()), "{err}");
    assert!(err.contains("--out DIR"), "{err}");
    // the same file again: its own results
    assert!(!run(&fb).contains(note));
    // an identical copy elsewhere: the same experiment hash, the same results
    assert!(!run(&fc).contains(note));
    // the first file again: the folder holds the copy's results now
    let err = run(&fa);
    assert!(err.contains(note), "{err}");
    let o = flexstar(&["compare", &fb, "--no-figures", "--out", out_s]);
    assert!(o.status.success() && stderr(&o).contains(note), "{}", stderr(&o));
    let o = flexstar(&["kinematics", &fa, "--out", out_s]);
    assert!(o.status.success() && stderr(&o).contains(note), "{}", stderr(&o));
    // every run sidecar records the experiment file and hash
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("tiny/amm-free-free.json")).unwrap()).unwrap();
    let b_abs = std::fs::canonicalize(&fb).unwrap();
    assert_eq!(side["experiment_file"], b_abs.to_str().unwrap());
    assert_eq!(side["experiment_hash"].as_str().unwrap().len(), 16);
}

/// A damped move cut short is not settled by its `t_end`; the message names the decay rate seen
/// and a `t_end` to set, and a run to that `t_end` (the solver's own measurement, independent of
/// the extrapolation) settles (docs/usage.md, Residual vibration and settling).
#[test]
fn not_settled_says_which_t_end_lets_the_run_settle() {
    let dir = tempfile::tempdir().unwrap();
    let text = |t_end: &str| {
        format!(
            "name = \"damped\"\n[time]\nt_end = {t_end}\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
             from = {{ Gx = 0.0, Gy = 0.0, theta = 0.0 }}\nto = {{ Gx = 0.03, Gy = -0.02, theta = 0.1 }}\n\
             t0 = 0.0\nt1 = 0.25\n[damping]\nzeta = 0.03\nf_hz = 4.0\n"
        )
    };
    let out = dir.path().join("out");
    let short = write(dir.path(), "short.toml", &text("1.5"));
    let o = flexstar(&["run", &short, "--solver", "amm", "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("not settled by t_end = 1.5 s: |dG| decays at"), "{err}");
    let at = err.find("set time.t_end >= ").expect(&err) + "set time.t_end >= ".len();
    let suggested: f64 = err[at..].split(' ').next().unwrap().parse().unwrap();
    assert!(suggested > 1.5 && suggested < 10.0, "{suggested}");
    let long = write(dir.path(), "long.toml", &text(&suggested.to_string()));
    let o = flexstar(&["run", &long, "--solver", "amm", "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(o.status.success() && err.contains("settled at"), "{err}");
    assert!(!err.contains("not settled"), "{err}");
}

/// Numbers on stderr carry the digits that mean something (the files keep every digit), and a
/// servo's run reports its sliders' tracking error after the motion next to the settling time.
#[test]
fn stderr_numbers_are_rounded_and_a_servo_reports_its_sliders_after_the_move() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let quintic = "[trajectory]\nkind = \"quintic\"\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\n\
                   to = { Gx = 0.03, Gy = -0.02, theta = 0.1 }\nt0 = 0.0\n";
    // a ZVD at 3.9 Hz after a 0.3 s quintic ends at t_rest = 0.3 + 1/3.9 = 0.556410256... s
    let shaped = |t_end: &str| {
        format!("name = \"shaped\"\n[time]\nt_end = {t_end}\n{quintic}t1 = 0.3\n[shaper]\nkind = \"zvd\"\nf_hz = 3.9\n")
    };
    let cfg = write(dir.path(), "shaped.toml", &shaped("0.5"));
    let o = flexstar(&["kinematics", &cfg, "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(!o.status.success() && err.contains("t_rest = 0.55641 s"), "{err}");
    assert!(!err.contains("0.5564102"), "unrounded: {err}");
    let at = err.find("at least ").expect(&err) + "at least ".len();
    let bound = err[at..].split(' ').next().unwrap();
    assert!(bound.len() <= 8, "{bound}");
    // the bound shown is enough: a file with t_end = that value is accepted
    let cfg = write(dir.path(), "shaped.toml", &shaped(bound));
    let o = flexstar(&["kinematics", &cfg, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "t_end = {bound}: {}", stderr(&o));

    let servo = format!(
        "name = \"servo-move\"\n[time]\nt_end = 0.6\ndt_out = 0.001\n{quintic}t1 = 0.25\n[drive]\nkind = \"servo\"\n\
         bandwidth_hz = 20.0\ndamping_ratio = 0.7\n"
    );
    let cfg = write(dir.path(), "servo.toml", &servo);
    let o = flexstar(&["run", &cfg, "--solver", "amm", "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("after t_rest = 0.25 s:"), "{err}");
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("servo-move/amm-enriched-direct.json")).unwrap())
            .unwrap();
    // the sidecar's values against the run's own e1..e3 columns after t_rest
    let (h, rows) = common::table(&out.join("servo-move/amm-enriched-direct.csv"));
    let (t, e) = (common::col(&h, "t"), ["e1", "e2", "e3"].map(|c| common::col(&h, c)));
    let after = rows.iter().filter(|r| r[t] >= 0.25 - 1e-12);
    let peak = after.flat_map(|r| e.map(|k| r[k].abs())).fold(0.0f64, f64::max);
    let end = e
        .map(|k| rows.last().unwrap()[k].abs())
        .into_iter()
        .fold(0.0f64, f64::max);
    assert_eq!(side["residual_tracking_peak_m"].as_f64().unwrap(), peak);
    assert_eq!(side["residual_tracking_end_m"].as_f64().unwrap(), end);
    let line = format!(
        "sliders off their reference by up to {} mm after t_rest, {} mm at t_end",
        flexstar_model_fmt(peak * 1e3),
        flexstar_model_fmt(end * 1e3)
    );
    assert!(err.contains(&line), "{line} not in {err}");
}

/// Three significant digits, as a person reads them (written out here, independently of the
/// library's formatter).
fn flexstar_model_fmt(v: f64) -> String {
    let digits = 2 - v.abs().log10().floor() as i32;
    let s = format!("{:.*}", digits.max(0) as usize, v);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A short move in a long run: compare's time figures get a row on the motion and a row on the
/// two periods of the first mode after it, the window the sidecar's `settle_hold_s` (one period,
/// from the modal analysis at the final pose) gives.
#[test]
fn compare_zooms_on_the_motion_and_the_residual_window() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "short.toml",
        "name = \"short-move\"\n[time]\nt_end = 1.2\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
         from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.03, Gy = -0.02, theta = 0.1 }\nt0 = 0.0\nt1 = 0.25\n\
         [fem]\nelements = 120\n",
    );
    let out = dir.path().join("out");
    let o = flexstar(&["compare", &cfg, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = out.join("short-move");
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case.join("fem.json")).unwrap()).unwrap();
    let hold = side["settle_hold_s"].as_f64().unwrap();
    let end = 0.25 + 2.0 * hold;
    let secs = |t: f64| {
        // four significant digits, trailing zeros dropped
        let s = format!("{:.*}", (3 - t.log10().floor() as i32).max(0) as usize, t);
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    for fig in ["wG", "tips", "forces"] {
        let svg = std::fs::read_to_string(case.join(format!("figures/short-move-{fig}.svg"))).unwrap();
        assert!(svg.contains("the motion, 0-0.25 s"), "{fig}");
        let after = format!("after it, 2 periods of mode 1, 0.25-{} s", secs(end));
        assert!(svg.contains(&after), "{fig}: no {after}");
    }
    // the star is not a time figure
    let star = std::fs::read_to_string(case.join("figures/short-move-star.svg")).unwrap();
    assert!(!star.contains("the motion,"));
}
