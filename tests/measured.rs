//! A recording laid over a run (`docs/measured.md` section 1) with a solver's own sensors as the
//! recording: an AMM run's sensor table written on a clock 7.3 ms behind the run's, read back
//! with `offset = "auto"`, recovers the shift to a fraction of the sample step and, laid onto
//! the run's times, the run's own channels; `[measured]` is checked against the experiment's
//! sensors when the file is read.

use std::path::Path;

use flexstar_measured::Recording;
use flexstar_model::{AmmSettings, Experiment, SensorTable};
use flexstar_solve::Settings;

const SMOOTH: &str = include_str!("../configs/motions/smooth.toml");

const SENSORS: &str = r#"
[[sensors]]
name = "tip"
kind = "accelerometer"
beam = 1
x = 0.45
[[sensors]]
name = "eps"
kind = "strain"
beam = 2
x = 0.05
c = 0.001
"#;

fn experiment(extra: &str) -> Result<Experiment, String> {
    Experiment::from_toml_str(&format!("{SMOOTH}\n{SENSORS}\n{extra}"), Path::new("smooth.toml"))
        .map_err(|e| e.to_string())
}

/// `table` written as a recording whose clock reads `t - lag` at run time `t`, its columns
/// renamed by `rename`.
fn write_shifted(path: &Path, table: &SensorTable, lag: f64, rename: &[(&str, &str)]) {
    let name = |c: &str| rename.iter().find(|(a, _)| *a == c).map_or(c, |(_, b)| *b).to_string();
    let mut text = std::iter::once("t".to_string())
        .chain(table.columns.iter().map(|c| name(&c.name)))
        .collect::<Vec<_>>()
        .join(",");
    for (k, t) in table.t.iter().enumerate() {
        text.push_str(&format!("\n{:.17e}", t - lag));
        for c in &table.columns {
            text.push_str(&format!(",{:.17e}", c.values[k]));
        }
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn the_automatic_offset_recovers_a_known_shift_of_a_run_s_own_sensors() {
    let exp = experiment("[measured]\noffset = \"auto\"\nmax_lag = 0.03\ncolumns = { eps = \"gauge\" }").unwrap();
    let problem = exp.problem().unwrap();
    let run = flexstar_solve::response(&problem, Settings::Amm(&AmmSettings::accurate()), None, None).unwrap();
    let table = run.sensors.expect("sensors");
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("rec.csv");
    let lag = 7.3e-3;
    write_shifted(&file, &table, lag, &[("eps", "gauge")]);
    let mut rec = Recording::read(&file, exp.measured.as_ref().unwrap(), problem.sensors()).unwrap();
    let shift = rec.align(&table).unwrap();
    let step = table.t[1] - table.t[0];
    eprintln!(
        "offset: {shift} s for {lag} s (error {:.3} of a step)",
        (shift - lag).abs() / step
    );
    assert!((shift - lag).abs() < 0.05 * step, "offset {shift} s, want {lag} s");
    // laid back onto the run's times: the run's own channels, but for the interpolation of a
    // clock shifted by a fraction of a step (last sample: the recording ends before the run)
    let laid = rec.on_times(&table.t).unwrap();
    let range = rec.span_in(&table.t).unwrap();
    assert!(range.start == 0 && range.end >= table.t.len() - 1, "{range:?}");
    for c in &table.columns {
        let want = &c.values[range.clone()];
        let got = laid.column(&c.name).unwrap();
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = want.iter().zip(got).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst < 0.02 * scale, "{}: {worst} of {scale}", c.name);
    }
}

#[test]
fn the_measured_section_is_checked_against_the_sensors() {
    experiment("[measured]\ncolumns = { tip_x = \"ax\" }\nscale = { eps = 1e-6 }").unwrap();
    let e = experiment("[measured]\nscale = { tip_z = 2.0 }").unwrap_err();
    assert!(
        e.contains("smooth.toml") && e.contains("measured.scale.tip_z") && e.contains("tip_x, tip_y, eps"),
        "{e}"
    );
    let e = experiment("[measured]\nwindow = 2.0").unwrap_err();
    assert!(e.contains("smooth.toml") && e.contains("window"), "{e}");
    let bare = Experiment::from_toml_str(&format!("{SMOOTH}\n[measured]\noffset = 0.1\n"), Path::new("bare.toml"))
        .unwrap_err()
        .to_string();
    assert!(bare.contains("bare.toml") && bare.contains("no [[sensors]]"), "{bare}");
}
