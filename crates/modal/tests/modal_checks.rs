//! Issue 11 checks: AMM against FEM at three poses, Matrix Market round trip, bad input.

use flexstar_modal::freqmap::{check_grid, Axis};
use flexstar_modal::linear::{dense, read_mtx, write_mtx};
use flexstar_modal::pose::{pose_at_time, pose_from_task};
use flexstar_model::{Experiment, Sliders};

fn paper() -> Experiment {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
    Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap()
}

/// The two independent models agree within 1 % on the first six modes at three poses: the
/// centre, an off-centre turned pose, and one near the workspace edge (sleeve 1 near the tip).
#[test]
fn amm_and_fem_agree_within_one_percent() {
    let exp = paper();
    for (gx, gy, th) in [(0.0, 0.0, 0.0), (0.03, -0.02, 0.1), (-0.12, 0.0, 0.0)] {
        let pose = pose_from_task(&exp.robot, gx, gy, th).unwrap();
        let m = flexstar_modal::analysis::modal(&exp, &pose, Sliders::Locked, 6).unwrap();
        for (mode, a, f, rel) in m.rows() {
            assert!(
                rel.abs() < 0.01,
                "pose ({gx}, {gy}, {th}) xp {:?} mode {mode}: AMM {a} Hz FEM {f} Hz",
                pose.xp
            );
        }
    }
}

#[test]
fn matrix_market_round_trip_is_identical() {
    let v: Vec<f64> = (0..12)
        .map(|k| if k % 3 == 0 { 0.0 } else { 1.0 / (k as f64 + 0.1) * 1e-7 })
        .collect();
    let m = dense(3, 4, &v);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("X.mtx");
    write_mtx(&p, &m).unwrap();
    assert_eq!(read_mtx(&p).unwrap(), m);
}

#[test]
fn bad_input_is_refused_with_the_reason() {
    let exp = paper();
    let e = pose_from_task(&exp.robot, 0.0, 0.0, 1.2).unwrap_err().to_string();
    assert!(e.contains("outside the workspace"), "{e}");
    let e = pose_from_task(&exp.robot, 0.3, 0.0, 0.0).unwrap_err().to_string();
    assert!(
        e.contains("limit") || e.contains("Fermat") || e.contains("points away"),
        "{e}"
    );
    assert!(pose_at_time(&exp, 0.6).unwrap_err().to_string().contains("span"));
    assert!(Axis::parse("--gx", "0:1:1").is_err());
    let big = Axis::parse("--gx", "0:1:1000").unwrap();
    assert!(check_grid(&big, &big).unwrap_err().to_string().contains("100000"));
    assert!(flexstar_modal::check_k(0).is_err() && flexstar_modal::check_k(51).is_err());
}
