//! `flexstar compare CONFIG --measured FILE.csv` through the built binary (`docs/measured.md`):
//! a recording made from the FEM's own `fem-sensors.csv` of a run with sensor noise, renamed,
//! partly in g, on a clock 7.3 ms behind, is laid over the same experiment without noise. The
//! estimated offset is the shift; the FEM's error is the noise (its RMS the sensors' `noise`,
//! its EVP Eq. M7 computed here from the recording); the AMM's RMS is the noise and the AMM's
//! own distance from the FEM, computed here from the two runs' files. A bad recording stops the
//! command before any output.

use std::path::Path;

use crate::common;
use common::{col, flexstar, stderr, table};

const LAG: f64 = 7.3e-3;
const NOISE_TIP: f64 = 0.02;
const NOISE_EPS: f64 = 2e-7;

/// The cross-model motion (`configs/motions/smooth.toml`) on a light mesh, named `name`, with an
/// accelerometer and a gauge whose noise is `noisy` or none, plus `extra`.
fn write_case(dir: &Path, name: &str, noisy: bool, extra: &str) -> String {
    let smooth = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions/smooth.toml");
    let text = std::fs::read_to_string(smooth)
        .unwrap()
        .replace("name = \"smooth\"", &format!("name = \"{name}\""));
    let (nt, ne) = if noisy { (NOISE_TIP, NOISE_EPS) } else { (0.0, 0.0) };
    let sensors = format!(
        "[fem]\nelements = 102\n[[sensors]]\nname = \"tip\"\nkind = \"accelerometer\"\nbeam = 1\nx = 0.45\n\
         noise = {nt}\nseed = 3\n[[sensors]]\nname = \"eps\"\nkind = \"strain\"\nbeam = 2\nx = 0.05\nc = 0.001\n\
         noise = {ne:e}\nseed = 5\n"
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{text}\n{sensors}{extra}\n")).unwrap();
    path.to_string_lossy().into_owned()
}

/// Column `name` of a CSV file with a header.
fn column(path: &Path, name: &str) -> Vec<f64> {
    let (header, rows) = table(path);
    let k = col(&header, name);
    rows.iter().map(|r| r[k]).collect()
}

/// Trapezoidal mean of `f` over `t`.
fn mean_over(t: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    let s: f64 = (1..t.len()).map(|k| 0.5 * (t[k] - t[k - 1]) * (f(k - 1) + f(k))).sum();
    s / (t[t.len() - 1] - t[0])
}

/// The bench's recording: the noisy FEM's sensors on a clock `LAG` behind, `tip_y` in g.
fn write_recording(noisy_fem: &Path, path: &Path) {
    let (t, tx, ty, eps) = (
        column(noisy_fem, "t"),
        column(noisy_fem, "tip_x"),
        column(noisy_fem, "tip_y"),
        column(noisy_fem, "eps"),
    );
    let mut text = String::from("time,ax,ay_g,eps\n");
    for k in 0..t.len() {
        text.push_str(&format!(
            "{:e},{:e},{:e},{:e}\n",
            t[k] - LAG,
            tx[k],
            ty[k] / 9.81,
            eps[k]
        ));
    }
    std::fs::write(path, text).unwrap();
}

const MEASURED: &str = "[measured]\ncolumns = { t = \"time\", tip_x = \"ax\", tip_y = \"ay_g\" }\n\
                        scale = { tip_y = 9.81 }\noffset = \"auto\"\n";

#[test]
fn a_recording_of_the_fem_s_noisy_sensors_gives_the_noise_as_the_fem_s_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let bench = write_case(dir.path(), "bench", true, "");
    let o = flexstar(&["compare", &bench, "--out", out, "--no-figures"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rec = dir.path().join("rec.csv");
    write_recording(&dir.path().join("bench/fem-sensors.csv"), &rec);
    let cfg = write_case(dir.path(), "model", false, MEASURED);
    let o = flexstar(&["compare", &cfg, "--out", out, "--measured", rec.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = dir.path().join("model");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case.join("compare.json")).unwrap()).unwrap();
    let m = &json["measured"];
    let offset = m["offset_s"].as_f64().unwrap();
    eprintln!("offset {offset} s");
    assert!((offset - LAG).abs() < 0.1e-3, "offset {offset} s, want {LAG}");
    assert_eq!(m["offset_estimated"], true);
    let error = |run: &str, channel: &str, key: &str| {
        m["errors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["run"] == run && e["channel"] == channel)
            .unwrap_or_else(|| panic!("no {run} {channel}"))[key]
            .as_f64()
            .unwrap()
    };
    let (fem, amm) = (case.join("fem-sensors.csv"), case.join("amm-enriched-sensors.csv"));
    let t = column(&fem, "t");
    let recorded = |c: &str| {
        let v = column(&dir.path().join("bench/fem-sensors.csv"), c);
        mean_over(&t, |k| v[k].abs())
    };
    for (channel, sigma) in [("tip_x", NOISE_TIP), ("tip_y", NOISE_TIP), ("eps", NOISE_EPS)] {
        // the FEM: what is left is the noise
        let rms = error("fem", channel, "rms");
        let evp = error("fem", channel, "evp");
        let m7 = 100.0 * sigma * (2.0 / std::f64::consts::PI).sqrt() / recorded(channel);
        // the AMM: the noise and its own distance from the FEM, in quadrature
        let (a, f) = (column(&amm, channel), column(&fem, channel));
        let own = mean_over(&t, |k| (a[k] - f[k]).powi(2)).sqrt();
        let want = (sigma * sigma + own * own).sqrt();
        let amm_rms = error("amm-enriched", channel, "rms");
        eprintln!(
            "{channel}: FEM RMS {rms:.4e} (noise {sigma:e}), EVP {evp:.3} % (Eq. M7 {m7:.3} %); \
             AMM RMS {amm_rms:.4e} (want {want:.4e}, AMM-FEM {own:.3e})"
        );
        assert!(
            (rms / sigma - 1.0).abs() < 0.12,
            "{channel}: FEM RMS {rms} vs noise {sigma}"
        );
        assert!((evp / m7 - 1.0).abs() < 0.15, "{channel}: FEM EVP {evp} vs Eq. M7 {m7}");
        assert!(
            (amm_rms / want - 1.0).abs() < 0.15,
            "{channel}: AMM RMS {amm_rms} vs {want}"
        );
    }
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    assert!(
        md.contains("## Measured") && md.contains("rec.csv") && md.contains("Hz"),
        "{md}"
    );
    let html = std::fs::read_to_string(case.join("report.html")).unwrap();
    assert!(html.contains("Measured"));
    for channel in ["tip_x", "tip_y", "eps"] {
        let svg = case.join(format!("figures/model-measured-{channel}.svg"));
        let text = std::fs::read_to_string(&svg).unwrap_or_else(|e| panic!("{}: {e}", svg.display()));
        assert!(text.contains("measured") && text.contains("PSD"), "{channel}");
    }
    assert!(m["modes_hz"].as_array().is_some_and(|f| !f.is_empty()), "{m}");
    // 0.1 s of rest is too short a free decay for the identification: it says so
    assert!(
        m["identified_note"].as_str().is_some_and(|n| n.contains("fewer than")),
        "{m}"
    );
}

/// The bench of docs/measured.md 3.6 (`configs/measured/truth.toml`: 1 s of rest after the
/// move, accelerometers at G and on beam 2 with 2 % noise): its FEM's noisy sensors laid over
/// the same experiment's runs.
#[test]
fn the_recorded_free_decay_is_identified_at_the_model_s_frequencies() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let truth = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/measured/truth.toml");
    let truth = truth.to_str().unwrap();
    let o = flexstar(&["run", truth, "--solver", "fem", "--out", out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rec = dir.path().join("truth/fem-sensors.csv");
    let cmp = dir.path().join("cmp");
    let o = flexstar(&[
        "compare",
        truth,
        "--out",
        cmp.to_str().unwrap(),
        "--no-figures",
        "--measured",
        rec.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("truth/compare.json")).unwrap()).unwrap();
    the_free_decay_s_modes_are_the_model_s(&json["measured"], 3);
    let md = std::fs::read_to_string(cmp.join("truth/compare.md")).unwrap();
    assert!(md.contains("Modes identified from the recorded free decay"), "{md}");
}

/// The model-free identification of the recorded free decay (ERA and maximum likelihood on the
/// noisy FEM's channels, docs/measured.md 3) against the accurate AMM's natural frequencies at
/// the final pose, a second model computed without the recording: each of the first `n`
/// identified modes lies within 0.5 % of a model frequency (the two models agree to about 0.02 %
/// at a pose: docs/measured.md 3.6), and its 95 % interval is reported.
fn the_free_decay_s_modes_are_the_model_s(m: &serde_json::Value, n: usize) {
    let model: Vec<f64> = m["modes_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .collect();
    let identified = m["identified"]
        .as_array()
        .unwrap_or_else(|| panic!("no identification: {m}"));
    eprintln!(
        "identified {identified:?}; model {model:?}; note {}",
        m["identified_note"]
    );
    assert!(identified.len() >= n, "{m}");
    for mode in &identified[..n] {
        let f = mode["f_hz"].as_f64().unwrap();
        let nearest = model.iter().map(|g| (f / g - 1.0).abs()).fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 5e-3,
            "identified {f} Hz is {:.3} % from the model's {model:?}",
            100.0 * nearest
        );
        assert!(mode["f_std_hz"].as_f64().unwrap() > 0.0 && mode["zeta_std"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn a_bad_recording_stops_compare_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let cfg = write_case(dir.path(), "bad", false, MEASURED);
    for (text, wants) in [
        (
            "time,ax,ay_g,az\n0,1,2,3\n0.1,1,2,3\n",
            vec!["rec.csv", "column az", "no sensor column"],
        ),
        ("time,ax,ay_g\n0,1,2\n0,2,2\n", vec!["rec.csv", "row 2", "repeats"]),
        (
            "time,ax,ay_g\n0,1,2\n0.1,x,2\n",
            vec!["rec.csv", "row 2", "column ax", "not a number"],
        ),
        (
            "time,ax\n0,1\n0.1,2\n",
            vec!["rec.csv", "column ay_g", "measured.columns.tip_y"],
        ),
        (
            "t,ax,ay_g\n0,1,2\n0.1,2,2\n",
            vec!["rec.csv", "no time column \"time\""],
        ),
    ] {
        let rec = dir.path().join("rec.csv");
        std::fs::write(&rec, text).unwrap();
        let o = flexstar(&["compare", &cfg, "--out", out, "--measured", rec.to_str().unwrap()]);
        let e = stderr(&o);
        assert!(!o.status.success(), "{text}");
        for w in wants {
            assert!(e.contains(w), "{text:?}: {e}");
        }
        assert!(!dir.path().join("bad").exists(), "nothing written for {text:?}");
    }
    // a given offset that puts the recording after the run: refused before the solves
    let late = write_case(dir.path(), "late", false, "[measured]\noffset = 5.0\n");
    let rec = dir.path().join("late.csv");
    std::fs::write(&rec, "t,tip_x\n0,1\n0.2,2\n").unwrap();
    let o = flexstar(&["compare", &late, "--out", out, "--measured", rec.to_str().unwrap()]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("late.csv") && e.contains("does not overlap"),
        "{e}"
    );
    assert!(!dir.path().join("late").exists());
    // an experiment without sensors
    let bare = dir.path().join("bare.toml");
    let smooth = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions/smooth.toml");
    std::fs::copy(smooth, &bare).unwrap();
    let o = flexstar(&[
        "compare",
        bare.to_str().unwrap(),
        "--out",
        out,
        "--measured",
        rec.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("late.csv") && e.contains("no [[sensors]]"),
        "{e}"
    );
}
