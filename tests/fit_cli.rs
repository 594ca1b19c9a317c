//! `flexstar fit` through the built binary (`docs/measured.md` sections 4 and 5): the worked
//! example's record-then-fit writes the calibrated experiment, which `flexstar run` then runs;
//! a recording the reader refuses exits with status 1 and the file, column and reason on
//! stderr, writing nothing.

use std::path::{Path, PathBuf};

use crate::common;
use common::{flexstar, stderr};

fn config(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/measured")
        .join(name)
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Section 5, steps 1 and 3: the FEM's recording of the truth, the fit of the drawn robot to it
/// (its files, `fit.json`'s verdict), and the calibrated experiment run by `flexstar run`.
#[test]
fn record_fit_and_run_the_calibrated_experiment() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = flexstar(&[
        "run",
        path(&config("truth.toml")),
        "--solver",
        "fem",
        "--out",
        path(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rec = out.join("truth/fem-sensors.csv");
    let o = flexstar(&[
        "fit",
        path(&config("nominal.toml")),
        "--measured",
        path(&rec),
        "--out",
        path(&out),
    ]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("fit: converged") && err.contains("payload.mass"), "{err}");
    assert!(err.contains("identifiability: identifiable"), "{err}");
    assert!(!err.contains("warning:"), "no channel is left above its noise: {err}");
    for f in [
        "fit.toml",
        "fit.json",
        "fit.md",
        "report.html",
        "nominal-fit-overlay.svg",
        "nominal-fit-errors.svg",
    ] {
        assert!(out.join("nominal").join(f).exists(), "{f} missing");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("nominal/fit.json")).unwrap()).unwrap();
    assert_eq!(json["calibrated"], true);
    assert_eq!(json["identifiability"]["verdict"], "identifiable");
    let o = flexstar(&[
        "run",
        path(&out.join("nominal/fit.toml")),
        "--solver",
        "amm",
        "--out",
        path(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A recording with a column that is no sensor's: status 1, the recording and the column named
/// by the reader (`docs/measured.md` 1.1), nothing written.
#[test]
fn a_recording_with_a_foreign_column_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec.csv");
    let rows: String = (0..=1300).map(|k| format!("{},0,0,0\n", k as f64 / 1000.0)).collect();
    std::fs::write(&rec, format!("t,accG_x,accG_y,accZ_x\n{rows}")).unwrap();
    let out = dir.path().join("out");
    let o = flexstar(&[
        "fit",
        path(&config("nominal.toml")),
        "--measured",
        path(&rec),
        "--out",
        path(&out),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("rec.csv") && err.contains("accZ_x"), "{err}");
    assert!(!out.join("nominal/fit.json").exists());
}
