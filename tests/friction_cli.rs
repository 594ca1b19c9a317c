//! `[friction]` through the `flexstar` binary (`docs/friction.md` 6-7, 9): both solvers write
//! the friction columns and the sidecar's summary; bad coefficients are refused with the file
//! and the key, nothing written.

mod common;
use common::{col, run_solver, stderr, table, TINY};

/// `tiny.toml` with `extra` appended, written to `dir`.
fn config(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    let path = dir.join("rub.toml");
    std::fs::write(
        &path,
        format!("{}\n{extra}", TINY.replace("name = \"tiny\"", "name = \"rub\"")),
    )
    .unwrap();
    path
}

#[test]
fn both_solvers_write_the_friction_columns_and_summary() {
    for (solver, stem) in [("fem", "fem"), ("amm", "amm-")] {
        writes_the_friction_columns(solver, stem);
    }
}

/// `solver`'s run writes the friction columns into its CSV (the file whose name starts with
/// `stem`) and the summary into its sidecar.
fn writes_the_friction_columns(solver: &str, stem: &str) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "[friction]\nmu = 0.2\n[friction.rails]\nFc = 0.5\n");
    let out = dir.path().join("out");
    let o = run_solver(&cfg, solver, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_dir(out.join("rub"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            name.starts_with(stem) && name.ends_with(".csv") && !name.contains("shapes")
        })
        .expect("the run's CSV");
    let (header, rows) = table(&csv);
    for name in ["Ff1", "vs2", "stick3", "E_f"] {
        col(&header, name);
    }
    let stick = col(&header, "stick1");
    assert!(rows.iter().all(|r| r[stick] == 0.0 || r[stick] == 1.0));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(csv.with_extension("json")).unwrap()).unwrap();
    assert!(json["friction"]["stuck_s"].is_array(), "{json}");
    assert_eq!(json["experiment"]["friction"]["mu"], 0.2);
    assert_eq!(json["experiment"]["friction"]["rails"]["Fc"], 0.5);
}

#[test]
fn bad_coefficients_are_refused_with_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    for (extra, solver, want) in [
        (
            "[friction]\nmu = 0.2\nmu_static = 0.1\n",
            "fem",
            ["rub.toml", "friction.mu_static", "mu_static >= mu"],
        ),
        (
            "[friction]\nmu = -1.0\n",
            "fem",
            ["rub.toml", "friction.mu", "non-negative"],
        ),
        ("[friction]\nmodel = \"rim\"\n", "fem", ["rub.toml", "model", "rim"]),
    ] {
        let cfg = config(dir.path(), extra);
        let out = dir.path().join(format!("out-{solver}"));
        let o = run_solver(&cfg, solver, &out);
        let e = stderr(&o);
        assert!(!o.status.success(), "{extra}: accepted");
        assert!(want.iter().all(|w| e.contains(w)), "{extra}: {e}");
        assert!(!out.join("rub").exists(), "{extra}: something was written");
    }
}
