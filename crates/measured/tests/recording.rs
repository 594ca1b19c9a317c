//! The recording reader (`docs/measured.md` section 1): each bad input refused before any work
//! with the file, the row or column and the reason; the mapping, scale and offset of Eqs.
//! M1-M2 checked against values written by hand; the resampling of Eq. M4 against the exact
//! values of a linear signal.

use std::path::{Path, PathBuf};

use flexstar_measured::{MeasuredError, Recording};
use flexstar_model::measured_section::{MeasuredSection, Offset};

/// The sensor columns of an experiment with an accelerometer `acc` and an encoder `enc`.
fn units() -> Vec<(String, String)> {
    [("acc_x", "m/s^2"), ("acc_y", "m/s^2"), ("enc", "m")]
        .map(|(c, u)| (c.to_string(), u.to_string()))
        .to_vec()
}

fn section(text: &str) -> MeasuredSection {
    toml::from_str(text).unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn read(text: &str, measured: &str) -> Result<Recording, MeasuredError> {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "rec.csv", text);
    Recording::read_columns(&p, &section(measured), &units())
}

fn error(text: &str, measured: &str) -> String {
    read(text, measured).unwrap_err().to_string()
}

#[test]
fn each_bad_input_names_the_file_the_row_or_column_and_the_reason() {
    let good = "t,acc_x,enc\n0.0,1.0,0.1\n0.001,2.0,0.2\n0.002,3.0,0.3\n";
    read(good, "").unwrap();
    for (text, measured, wants) in [
        (
            "time,acc_x\n0,1\n1,2\n",
            "",
            vec!["rec.csv", "no time column \"t\"", "time,acc_x"],
        ),
        (
            "t,acc_x\n0,1\n1,2\n",
            "columns = { t = \"time\" }",
            vec!["rec.csv", "no time column \"time\"", "measured.columns.t"],
        ),
        (
            "t,acc_x\n0,1\n0.5,2\n0.5,3\n",
            "",
            vec!["rec.csv", "row 3 (line 4)", "repeats", "0.5"],
        ),
        (
            "t,acc_x\n0,1\n0.5,2\n0.4,3\n",
            "",
            vec!["rec.csv", "row 3", "before", "increase"],
        ),
        (
            "t,acc_x\n0,1\n0.5,nan\n",
            "",
            vec!["rec.csv", "row 2 (line 3), column acc_x", "finite"],
        ),
        (
            "t,acc_x\n0,1\n0.5,\n",
            "",
            vec!["rec.csv", "row 2", "column acc_x", "empty cell"],
        ),
        (
            "t,acc_x\n0,1\n0.5,1.2.3\n",
            "",
            vec!["rec.csv", "row 2", "column acc_x", "\"1.2.3\" is not a number"],
        ),
        (
            "t,acc_x\n0,1\n0.5,2,7\n",
            "",
            vec!["rec.csv", "row 2", "3 cells", "2 columns"],
        ),
        (
            "t,acc_z\n0,1\n1,2\n",
            "",
            vec![
                "rec.csv",
                "column acc_z",
                "matches no sensor column",
                "acc_x, acc_y, enc",
            ],
        ),
        (
            "t,acc_x\n0,1\n1,2\n",
            "columns = { acc_x = \"ax\" }",
            vec!["rec.csv", "column ax", "measured.columns.acc_x", "no such column"],
        ),
        (
            "t,acc_x\n0,1\n1,2\n",
            "scale = { enc = 2.0 }",
            vec!["rec.csv", "column enc", "measured.scale.enc", "no such column"],
        ),
        (
            "t,acc_x,acc_x\n0,1,1\n1,2,2\n",
            "",
            vec!["rec.csv", "column acc_x", "twice"],
        ),
        ("t,acc_x\n0,1\n", "", vec!["rec.csv", "1 data rows", "at least two"]),
        ("t\n0\n1\n", "", vec!["rec.csv", "no column besides the time"]),
    ] {
        let e = error(text, measured);
        for w in wants {
            assert!(e.contains(w), "{text:?} / {measured:?}: {e:?} lacks {w:?}");
        }
    }
    // no sensors in the experiment; a file that is not there
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "rec.csv", good);
    let e = Recording::read_columns(&p, &section(""), &[]).unwrap_err().to_string();
    assert!(e.contains("rec.csv") && e.contains("no [[sensors]]"), "{e}");
    let e = Recording::read_columns(&dir.path().join("none.csv"), &section(""), &units())
        .unwrap_err()
        .to_string();
    assert!(e.contains("none.csv") && e.contains("cannot read"), "{e}");
}

#[test]
fn mapping_scale_and_offset_lay_the_recording_onto_the_run() {
    // the recording's own names, a scale of g on one axis, mm on the encoder, a 0.25 s shift
    let text = "# bench 3, take 2\ntime_s,ay_g,enc_mm,acc_x\n0.0,1.0,10.0,5.0\n1.0,2.0,20.0,6.0\n2.0,4.0,30.0,7.0\n";
    let measured = "columns = { t = \"time_s\", acc_y = \"ay_g\", enc = \"enc_mm\" }\n\
                    scale = { acc_y = 9.81, enc = 0.001 }\noffset = 0.25\n";
    let rec = read(text, measured).unwrap();
    assert_eq!(rec.offset(), Offset::Seconds(0.25));
    let names: Vec<&str> = rec.channels().iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["acc_x", "acc_y", "enc"], "the sensors' order");
    assert_eq!(rec.channel("acc_y").unwrap().values, [9.81, 2.0 * 9.81, 4.0 * 9.81]);
    assert_eq!(rec.channel("enc").unwrap().source, "enc_mm");
    assert_eq!(rec.span().unwrap(), [0.25, 2.25]);
    // the run's times: 0 .. 2.5 by 0.25; within the span 0.25 .. 2.25
    let run_t: Vec<f64> = (0..=10).map(|k| k as f64 * 0.25).collect();
    assert_eq!(rec.span_in(&run_t).unwrap(), 1..10);
    let laid = rec.on_times(&run_t).unwrap();
    assert_eq!(laid.t, run_t[1..10]);
    assert_eq!(laid.unit("enc"), Some("m"));
    // run time 1.0 is recording time 0.75: acc_x = 5.75, enc = 17.5 mm, acc_y between 1 g and 2 g
    let at = |c: &str, t: f64| laid.column(c).unwrap()[laid.t.iter().position(|x| *x == t).unwrap()];
    assert!((at("acc_x", 1.0) - 5.75).abs() < 1e-12);
    assert!((at("enc", 1.0) - 0.0175).abs() < 1e-15);
    assert!((at("acc_y", 1.0) - 1.75 * 9.81).abs() < 1e-12);
    assert!((at("acc_y", 2.25) - 4.0 * 9.81).abs() < 1e-12);
    // a run that ends before the shifted recording starts
    let early: Vec<f64> = (0..=4).map(|k| k as f64 * 0.05).collect();
    let e = rec.on_times(&early).unwrap_err().to_string();
    assert!(
        e.contains("rec.csv") && e.contains("does not overlap") && e.contains("[0, 0.2]"),
        "{e}"
    );
}

#[test]
fn an_automatic_offset_waits_for_a_run() {
    let rec = read("t,enc\n0,1\n1,2\n", "offset = \"auto\"").unwrap();
    assert_eq!(rec.shift(), None);
    let e = rec.on_times(&[0.0, 0.5, 1.0]).unwrap_err().to_string();
    assert!(e.contains("auto") && e.contains("align"), "{e}");
}
