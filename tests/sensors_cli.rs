//! `flexstar compare` with `[[sensors]]` through the built binary (`docs/sensors.md` section 7):
//! one overlay figure per sensor, the per-channel EVP lines of `compare.md` and `compare.json`
//! against Eq. 45 recomputed here (trapezoidal integrals written in this test) from the two runs'
//! `-sensors.csv` files, and no sensor output at all for the same case without sensors.

use std::path::Path;

use crate::common;
use common::{col, flexstar, stderr, table};

/// Paper case 1 (the in-place rotation) cut to 0.1 s, plus `extra` TOML.
fn write_case1(dir: &Path, name: &str, extra: &str) -> String {
    let case1 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/case1.toml");
    let text = std::fs::read_to_string(case1)
        .unwrap()
        .replace("name = \"case1\"", &format!("name = \"{name}\""))
        .replace("t_end = 0.5", "t_end = 0.1");
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{text}\n{extra}\n")).unwrap();
    path.to_string_lossy().into_owned()
}

const SENSORS: &str = r#"
[[sensors]]
name = "tip"
kind = "accelerometer"
beam = 1
x = 0.45
lowpass_hz = 100.0
[[sensors]]
name = "eps"
kind = "strain"
beam = 2
x = 0.05
c = 0.001
"#;

/// Eq. 45 with trapezoidal integrals: `int |a - f| dt / int |f| dt * 100` [%].
fn evp_here(t: &[f64], a: &[f64], f: &[f64]) -> f64 {
    let trap =
        |y: &dyn Fn(usize) -> f64| -> f64 { (1..t.len()).map(|k| 0.5 * (t[k] - t[k - 1]) * (y(k - 1) + y(k))).sum() };
    trap(&|k| (a[k] - f[k]).abs()) / trap(&|k| f[k].abs()) * 100.0
}

/// Column `name` of a CSV file with a header.
fn column(path: &Path, name: &str) -> Vec<f64> {
    let (header, rows) = table(path);
    let k = col(&header, name);
    rows.iter().map(|r| r[k]).collect()
}

#[test]
fn compare_overlays_each_sensor_and_lists_the_evp_of_each_channel() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_case1(dir.path(), "sens", SENSORS);
    let o = flexstar(&["compare", &cfg, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = dir.path().join("sens");
    for sensor in ["tip", "eps"] {
        for ext in ["svg", "png"] {
            let f = case.join(format!("figures/sens-sensor-{sensor}.{ext}"));
            assert!(f.is_file(), "{} missing", f.display());
        }
    }
    let svg = std::fs::read_to_string(case.join("figures/sens-sensor-tip.svg")).unwrap();
    assert!(svg.contains("tip_x") && svg.contains("tip_y") && svg.contains("FEM"));
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case.join("compare.json")).unwrap()).unwrap();
    let listed = json["sensors"].as_array().expect("compare.json: sensors");
    let (fem, amm) = (case.join("fem-sensors.csv"), case.join("amm-pinned-free-sensors.csv"));
    let t = column(&fem, "t");
    assert_eq!(t, column(&amm, "t"), "the two runs' sensor clocks");
    for channel in ["tip_x", "tip_y", "eps"] {
        let want = evp_here(&t, &column(&amm, channel), &column(&fem, channel));
        let entry = listed
            .iter()
            .find(|e| e["channel"] == channel && e["run"] == "amm-pinned-free")
            .unwrap_or_else(|| panic!("compare.json lists no {channel}"));
        let got = entry["evp"].as_f64().unwrap();
        eprintln!("{channel}: EVP {got:.4} % (recomputed {want:.4} %)");
        assert!(
            (got - want).abs() <= 1e-9 * want.max(1.0),
            "{channel}: {got} against {want}"
        );
        let line = md
            .lines()
            .find(|l| l.starts_with(&format!("| amm-pinned-free | {channel} |")))
            .unwrap_or_else(|| panic!("compare.md has no line of {channel}"));
        let shown: f64 = line
            .trim_end_matches(" |")
            .rsplit("| ")
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!((shown - want).abs() <= 0.6e-4, "{line} against {want}");
    }
    let html = std::fs::read_to_string(case.join("report.html")).unwrap();
    assert!(html.contains("Sensors: EVP") && html.contains("sens-sensor-eps.svg"));
}

#[test]
fn compare_without_sensors_writes_no_sensor_output() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_case1(dir.path(), "plain", "");
    let o = flexstar(&["compare", &cfg, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = dir.path().join("plain");
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case.join("compare.json")).unwrap()).unwrap();
    assert!(!md.contains("Sensors") && json.get("sensors").is_none());
    let names: Vec<String> = std::fs::read_dir(case.join("figures"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!names.iter().any(|n| n.contains("-sensor-")), "{names:?}");
    assert!(!case.join("fem-sensors.csv").exists());
}

/// Column `name` of a study's results table, as text.
fn study_column(t: &flexstar_study::table::Table, name: &str) -> Vec<String> {
    let k = t.column(name).unwrap_or_else(|| panic!("no column {name}"));
    t.rows.iter().map(|r| r[k].clone()).collect()
}

/// A study that moves the sleeve over a strain gauge (a longer sleeve: its band of Eq. S10
/// widens) or shortens the beam below it: those cases are refused with the reason, the others
/// run. The gauge sits 25 mm past the farthest point of sleeve 1 over the motion, read from the
/// FEM's `xp1` column of a run without sensors (its contact coordinate: the rigid `xp` within a
/// deflection, micrometres here): outside the band of a 30 mm sleeve (half 15 mm), inside that of
/// an 80 mm one (half 40 mm).
#[test]
fn a_study_refuses_the_cases_whose_sleeve_or_beam_no_longer_holds_a_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let base = write_case1(dir.path(), "base", "");
    let base_text = std::fs::read_to_string(&base)
        .unwrap()
        .replace("t_end = 0.1", "t_end = 0.02");
    std::fs::write(&base, &base_text).unwrap();
    let o = flexstar(&["run", &base, "--solver", "fem", "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let xp1 = column(&dir.path().join("base/fem.csv"), "xp1");
    let far = xp1.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
    let x = far + 0.025;
    let gauge = format!("[[sensors]]\nname = \"eps\"\nkind = \"strain\"\nbeam = 1\nx = {x}\nc = 0.001\n");
    std::fs::write(&base, format!("{base_text}\n{gauge}")).unwrap();
    let short = x - 0.005;
    let study = dir.path().join("study.toml");
    std::fs::write(
        &study,
        format!(
            "name = \"moved\"\nbase = \"base.toml\"\nsolvers = [\"amm\"]\n[[vary]]\nkey = \"robot.Lp\"\n\
             values = [0.03, 0.08]\n[[vary]]\nkey = \"robot.L\"\nvalues = [0.5, {short}]\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("studies");
    let o = flexstar(&[
        "sweep",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = flexstar_study::table::Table::read(&out.join("moved/results.csv")).unwrap();
    let (lp, l, status) = (
        study_column(&t, "robot.Lp"),
        study_column(&t, "robot.L"),
        study_column(&t, "status"),
    );
    for k in 0..status.len() {
        let (lp, l): (f64, f64) = (lp[k].parse().unwrap(), l[k].parse().unwrap());
        eprintln!("Lp = {lp}, L = {l}: {}", status[k]);
        match (lp < 0.05, l > 0.49) {
            (true, true) => assert_eq!(status[k], "ok"),
            (false, true) => assert!(
                status[k].starts_with("invalid") && status[k].contains("sensors[1].x") && status[k].contains("sleeve"),
                "{}",
                status[k]
            ),
            (true, false) => assert!(
                status[k].starts_with("invalid") && status[k].contains("beyond beam 1"),
                "{}",
                status[k]
            ),
            (false, false) => assert!(status[k].starts_with("invalid"), "{}", status[k]),
        }
    }
    assert_eq!(status.len(), 4);
}
