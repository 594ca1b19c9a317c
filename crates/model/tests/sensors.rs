//! The sensors' definitions and their data acquisition (`docs/sensors.md` sections 5 and 6):
//! every refusal names the file and the key; the filter's gain against Eq. S12 measured in the
//! time domain; the noise's sample statistics against the requested standard deviation.

use std::f64::consts::PI;
use std::path::Path;

use flexstar_model::sensors::daq::{interpolate, lowpass, lowpass_gain, sample_times};
use flexstar_model::sensors::{Kind, Place, SensorTable};
use flexstar_model::Experiment;

const BASE: &str = r#"
name = "s"
[time]
t_end = 0.2
dt_out = 0.001
[trajectory]
kind = "polynomial"
s1 = [0.0, 0.0, 1.0]
s2 = [0.0, 0.0, 1.0]
s3 = [0.0, 0.0, 1.0]
"#;

fn with(sensors: &str) -> Result<Experiment, flexstar_model::ModelError> {
    Experiment::from_toml_str(&format!("{BASE}{sensors}"), Path::new("bench.toml"))
}

fn refused(sensors: &str, key: &str, why: &str) {
    let e = with(sensors).expect_err(sensors).to_string();
    assert!(e.starts_with("bench.toml"), "{e}");
    assert!(e.contains(key), "{key} not in: {e}");
    assert!(e.contains(why), "{why} not in: {e}");
}

#[test]
fn sensors_parse_into_their_kinds_and_columns() {
    let exp = with(
        r#"
[[sensors]]
name = "acc"
kind = "accelerometer"
beam = 2
x = 0.45
axes = "fixed"
[[sensors]]
name = "g"
kind = "accelerometer"
at = "G"
[[sensors]]
name = "eps"
kind = "strain"
beam = 3
x = 0.01
c = 0.002
[[sensors]]
name = "enc1"
kind = "encoder"
slider = 1
[[sensors]]
name = "load2"
kind = "force"
slider = 2
"#,
    )
    .unwrap();
    let p = exp.problem().unwrap();
    let s = p.sensors();
    assert_eq!(s.columns(), ["acc_x", "acc_y", "g_x", "g_y", "eps", "enc1", "load2"]);
    assert!(matches!(
        s.list()[0].kind,
        Kind::Accelerometer {
            place: Place::Beam { beam: 1, x: 0.45 },
            ..
        }
    ));
    assert!(matches!(s.list()[2].kind, Kind::Strain { beam: 2, .. }));
    let units: Vec<&str> = s.units().iter().map(|(_, u)| *u).collect();
    assert_eq!(units, ["m/s^2", "m/s^2", "m/s^2", "m/s^2", "m/m", "m", "N"]);
}

#[test]
fn bad_sensors_are_refused_naming_the_key() {
    let acc = "[[sensors]]\nname = \"a\"\nkind = \"accelerometer\"\n";
    refused(&format!("{acc}beam = 1\nx = 0.6\n"), "sensors[1].x", "beyond beam 1");
    refused(&format!("{acc}beam = 1\nx = -0.1\n"), "sensors[1].x", "beyond beam 1");
    refused(&format!("{acc}beam = 4\nx = 0.1\n"), "sensors[1].beam", "1, 2 or 3");
    refused(&format!("{acc}at = \"G\"\nc = 0.1\n"), "sensors[1].c", "does not apply");
    refused(
        &format!("{acc}at = \"payload\"\noffset = [0.0, 0.0]\n"),
        "sensors[1].at",
        "no [payload]",
    );
    refused(
        &format!("{acc}at = \"G\"\naxes = \"tilted\"\n"),
        "sensors[1].axes",
        "unknown axes",
    );
    refused(
        &format!("{acc}at = \"G\"\nrate_hz = 0.0\n"),
        "sensors[1].rate_hz",
        "positive",
    );
    refused(
        &format!("{acc}at = \"G\"\nrate_hz = 2000.0\n"),
        "sensors[1].rate_hz",
        "output rate",
    );
    refused(&format!("{acc}at = \"G\"\nnoise = -1.0\n"), "sensors[1].noise", ">= 0");
    refused(
        &format!("{acc}at = \"G\"\nnoise = [0.1, -1.0]\n"),
        "sensors[1].noise",
        ">= 0",
    );
    refused(
        &format!("{acc}at = \"G\"\nlowpass_hz = 600.0\n"),
        "sensors[1].lowpass_hz",
        "Nyquist",
    );
    refused(&format!("{acc}at = \"G\"\ncolour = 1\n"), "colour", "unknown field");
    refused(
        "[[sensors]]\nname = \"a\"\nkind = \"thermometer\"\n",
        "sensors[1].kind",
        "unknown kind",
    );
    refused(
        &format!("{acc}at = \"G\"\n{acc}at = \"G\"\n"),
        "sensors[2].name",
        "unique",
    );
    refused(
        "[[sensors]]\nname = \"Fa1\"\nkind = \"force\"\nslider = 1\n",
        "sensors[1].name",
        "result column",
    );
    refused(
        "[[sensors]]\nname = \"e\"\nkind = \"strain\"\nbeam = 1\nx = 0.1\n",
        "sensors[1].c",
        "needs c",
    );
    refused(
        &format!("{acc}at = \"G\"\nrate_hz = 500.0\n[[sensors]]\nname = \"b\"\nkind = \"encoder\"\nslider = 1\nrate_hz = 250.0\n"),
        "sensors[2].rate_hz",
        "one clock",
    );
}

/// The amplitude of the steady response of [`lowpass`] to a unit sine of `f` [Hz]: the
/// projection on sin and cos over the last whole periods of a long record.
fn measured_gain(f: f64, fc: f64, dt: f64) -> f64 {
    let n = (2.0 / dt) as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let x: Vec<f64> = t.iter().map(|t| (2.0 * PI * f * t).sin()).collect();
    let y = lowpass(&t, &x, fc);
    // the last 1 s holds a whole number of periods for the frequencies below
    let tail = n / 2;
    let (mut a, mut b) = (0.0, 0.0);
    for k in n - tail..n {
        a += y[k] * (2.0 * PI * f * t[k]).sin();
        b += y[k] * (2.0 * PI * f * t[k]).cos();
    }
    2.0 * (a * a + b * b).sqrt() / tail as f64
}

#[test]
fn the_filter_is_3_db_down_at_lowpass_hz_and_follows_its_formula() {
    let (fc, dt) = (50.0, 1e-3);
    let at_fc = measured_gain(fc, fc, dt);
    assert!((at_fc - 0.5f64.sqrt()).abs() < 1e-3, "gain at fc: {at_fc}");
    assert!((lowpass_gain(fc, fc, dt) - 0.5f64.sqrt()).abs() < 1e-12);
    for f in [10.0, 25.0, 100.0, 200.0] {
        let (m, want) = (measured_gain(f, fc, dt), lowpass_gain(f, fc, dt));
        assert!(
            (m - want).abs() < 1e-3 * want.max(1e-3) + 1e-6,
            "f = {f}: {m} vs {want}"
        );
    }
    // a constant passes unchanged from the first sample (steady start)
    let t: Vec<f64> = (0..100).map(|k| k as f64 * dt).collect();
    let y = lowpass(&t, &vec![9.81; 100], fc);
    assert!(y.iter().all(|v| (v - 9.81).abs() < 1e-12), "{y:?}");
}

#[test]
fn the_noise_has_the_requested_standard_deviation_and_its_seed() {
    let text = r#"
[time]
t_end = 20.0
dt_out = 0.001
[[sensors]]
name = "enc"
kind = "encoder"
slider = 1
noise = 0.3
seed = 11
"#;
    let text = BASE.replace("[time]\nt_end = 0.2\ndt_out = 0.001\n", "") + text;
    let exp = Experiment::from_toml_str(&text, Path::new("n.toml")).unwrap();
    let p = exp.problem().unwrap();
    let n = 20_001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let mut raw = SensorTable::new(t);
    raw.push_column("enc".into(), "m", vec![1.0; n]);
    let got = p.sensors().acquire(&raw, 20.0);
    let y = got.column("enc").unwrap();
    let mean = y.iter().sum::<f64>() / n as f64;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    assert!((sd / 0.3 - 1.0).abs() < 0.03, "sample sd {sd}");
    assert!((mean - 1.0).abs() < 4.0 * 0.3 / (n as f64).sqrt(), "mean {mean}");
    assert_eq!(p.sensors().acquire(&raw, 20.0), got, "the same seed, the same noise");
    assert_eq!(got.units, ["m"]);
}

/// The problem of [`BASE`] over `t_end` [s] (outputs every ms) with the `[[sensors]]` of
/// `sensors`.
fn over(t_end: f64, sensors: &str) -> flexstar_model::Problem {
    let text = BASE.replace("[time]\nt_end = 0.2\ndt_out = 0.001\n", "")
        + &format!("[time]\nt_end = {t_end}\ndt_out = 0.001\n")
        + sensors;
    Experiment::from_toml_str(&text, Path::new("s.toml"))
        .unwrap()
        .problem()
        .unwrap()
}

/// `noise = [nx, ny]`: each accelerometer axis gets its own standard deviation (Eq. S13).
#[test]
fn an_accelerometer_takes_one_noise_level_per_axis() {
    let p = over(
        20.0,
        "[[sensors]]\nname = \"acc\"\nkind = \"accelerometer\"\nat = \"G\"\nnoise = [0.1, 0.4]\nseed = 3\n",
    );
    let n = 20_001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let mut raw = SensorTable::new(t);
    raw.push_column("acc_x".into(), "m/s^2", vec![0.0; n]);
    raw.push_column("acc_y".into(), "m/s^2", vec![0.0; n]);
    let got = p.sensors().acquire(&raw, 20.0);
    for (column, want) in [("acc_x", 0.1), ("acc_y", 0.4)] {
        let y = got.column(column).unwrap();
        let sd = (y.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        assert!((sd / want - 1.0).abs() < 0.03, "{column}: sample sd {sd}, asked {want}");
    }
    let enc = "[[sensors]]\nname = \"e\"\nkind = \"encoder\"\nslider = 1\nnoise = [0.1, 0.2]\n";
    let bad = BASE.to_string() + enc;
    let e = Experiment::from_toml_str(&bad, Path::new("n.toml"))
        .and_then(|x| x.problem().map(|_| ()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("sensors[1].noise") && e.contains("one column"), "{e}");
}

#[test]
fn samples_lie_on_one_clock_and_interpolate_linearly() {
    let t = sample_times(250.0, 0.2);
    assert_eq!(t.len(), 51);
    assert!((t[50] - 0.2).abs() < 1e-15);
    let x = [0.0, 1e-3, 2e-3];
    let y = [0.0, 2.0, 6.0];
    assert_eq!(
        interpolate(&x, &y, &[0.0, 0.5e-3, 1.5e-3, 2e-3]),
        vec![0.0, 1.0, 4.0, 6.0]
    );
}

/// The derivative of what the acquisition records (`Sensors::acquire_derivative`, the
/// acquisition without the noise) against the difference of two noisy acquisitions over their
/// step: the filter (Eq. S11) and the sampling are linear and the same seed draws the same
/// noise, so the two agree to round-off.
#[test]
fn the_acquisitions_derivative_is_the_difference_of_two_noisy_ones() {
    let p = over(
        0.5,
        "[[sensors]]\nname = \"acc\"\nkind = \"accelerometer\"\nat = \"G\"\nnoise = [0.1, 0.4]\nseed = 3\n\
         lowpass_hz = 80.0\nrate_hz = 300.0\n",
    );
    let n = 501;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let wave = |a: f64, f: f64| -> Vec<f64> { t.iter().map(|&s| a * (f * s).sin() + 0.3 * s).collect() };
    let table = |x: Vec<f64>, y: Vec<f64>| {
        let mut raw = SensorTable::new(t.clone());
        raw.push_column("acc_x".into(), "m/s^2", x);
        raw.push_column("acc_y".into(), "m/s^2", y);
        raw
    };
    let (d_x, d_y) = (wave(0.7, 90.0), wave(-1.3, 400.0));
    let h = 1e-3;
    let base = table(wave(2.0, 31.0), wave(1.0, 57.0));
    let moved = table(
        base.columns[0]
            .values
            .iter()
            .zip(&d_x)
            .map(|(b, d)| b + h * d)
            .collect(),
        base.columns[1]
            .values
            .iter()
            .zip(&d_y)
            .map(|(b, d)| b + h * d)
            .collect(),
    );
    let (a0, a1) = (p.sensors().acquire(&base, 0.5), p.sensors().acquire(&moved, 0.5));
    let d = p.sensors().acquire_derivative(&table(d_x, d_y), 0.5);
    assert_eq!(d.t, a0.t);
    for (c, col) in d.columns.iter().enumerate() {
        let scale = col.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (k, v) in col.values.iter().enumerate() {
            let diff = (a1.columns[c].values[k] - a0.columns[c].values[k]) / h;
            assert!(
                (v - diff).abs() < 1e-9 * scale,
                "{} at {}: {v} vs {diff}",
                col.name,
                d.t[k]
            );
        }
    }
}
