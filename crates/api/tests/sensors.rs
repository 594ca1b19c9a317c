//! A run's sensors' file (`docs/sensors.md`, `docs/outputs.md`): `<stem>-sensors.csv` with the
//! header `t,<columns>`, its units in the sidecar's `column_units`, sampled on the DAQ's clock;
//! none without `[[sensors]]`; a sensor where a sleeve passes refused before any work.

use std::path::Path;

use flexstar_api::run::{run_to_dir, RunSettings, Solver};
use flexstar_model::Experiment;

const BASE: &str = r#"
name = "bench"
[time]
t_end = 0.05
dt_out = 0.001
[trajectory]
kind = "quintic"
from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }
to = { Gx = 0.004, Gy = 0.0, theta = 0.0 }
t0 = 0.0
t1 = 0.05
[amm]
family = "free-free"
modes = 12
"#;

const SENSORS: &str = r#"
[[sensors]]
name = "tip"
kind = "accelerometer"
beam = 1
x = 0.5
rate_hz = 500.0
lowpass_hz = 100.0
[[sensors]]
name = "enc1"
kind = "encoder"
slider = 1
"#;

fn load(dir: &Path, text: &str) -> (Experiment, String) {
    let path = dir.join("bench.toml");
    std::fs::write(&path, text).unwrap();
    (Experiment::load(&path).unwrap(), path.display().to_string())
}

#[test]
fn a_run_with_sensors_writes_their_file_and_units_and_one_without_writes_none() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (exp, source) = load(dir.path(), &format!("{BASE}{SENSORS}"));
    let run = run_to_dir(exp, &source, &RunSettings::new(Solver::Amm), &out, |_| {}, None).unwrap();
    let file = out.join("bench/amm-free-free-sensors.csv");
    assert!(run.files.contains(&file), "{:?}", run.files);
    let text = std::fs::read_to_string(&file).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,tip_x,tip_y,enc1"));
    // 500 Hz over 0.05 s: 26 samples, t = k / 500
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 26);
    assert!(rows[1].starts_with("2e-3,"), "{}", rows[1]);
    let sidecar = std::fs::read_to_string(out.join("bench/amm-free-free.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&sidecar).unwrap();
    assert_eq!(doc["column_units"]["tip_x"], "m/s^2");
    assert_eq!(doc["column_units"]["enc1"], "m");
    assert_eq!(doc["experiment"]["sensors"][0]["name"], "tip");

    let (exp, source) = load(dir.path(), BASE);
    let run = run_to_dir(exp, &source, &RunSettings::new(Solver::Amm), &out, |_| {}, None).unwrap();
    assert!(!run.files.iter().any(|f| f.to_string_lossy().contains("sensors")));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench/amm-free-free.json")).unwrap()).unwrap();
    assert!(
        doc["experiment"].get("sensors").is_none(),
        "no sensors key without sensors"
    );
}

#[test]
fn a_sensor_where_the_sleeve_passes_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // the sleeve sits at xp = d = 0.18 m from G, Lp = 0.03 m
    let text = format!("{BASE}[[sensors]]\nname = \"a\"\nkind = \"strain\"\nbeam = 2\nx = 0.19\nc = 0.001\n");
    let (exp, source) = load(dir.path(), &text);
    let e = run_to_dir(exp, &source, &RunSettings::new(Solver::Fem), &out, |_| {}, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bench.toml") && e.contains("sensors[1].x") && e.contains("sleeve"),
        "{e}"
    );
    assert!(!out.join("bench").exists(), "nothing written");
}
