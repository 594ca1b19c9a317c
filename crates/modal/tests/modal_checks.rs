//! Checks of the modal analyses (`docs/modes.md`): AMM against FEM at three poses, Matrix Market round trip, bad input.

use flexstar_modal::freqmap::{check_grid, Axis};
use flexstar_modal::linear::{dense, read_mtx, write_mtx};
use flexstar_modal::pose::{pose_at_time, pose_from_task};
use flexstar_model::{Experiment, Sliders};

fn paper() -> Experiment {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
    Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap()
}

/// Margins of a configuration to each limit of the feasible range (docs/conventions.md), in
/// metres (the Fermat angle's as `(120 deg - angle) Lp`, as the kinematics crate scales it), with
/// the limit's name; smallest first.
fn margins(exp: &Experiment, pose: &flexstar_model::RestPose) -> Vec<(f64, String)> {
    let p = &exp.robot;
    let mut out = Vec::new();
    for i in 0..3 {
        out.push((
            pose.xp[i] - p.lp / 2.0,
            format!("sleeve {} at the junction (xp > Lp/2)", i + 1),
        ));
        out.push((
            p.l - p.lp / 2.0 - pose.xp[i],
            format!("sleeve {} off the tip (xp < L - Lp/2)", i + 1),
        ));
        out.push((
            p.half_side() - pose.s[i].abs(),
            format!("slider {} off the base", i + 1),
        ));
    }
    let pts = [0, 1, 2].map(|i| flexstar_model::geometry::revolute_point(i, p.d, pose.s[i]));
    let (angle, _) = flexstar_kinematics::direct::largest_angle(&pts);
    out.push(((120f64.to_radians() - angle) * p.lp, "Fermat angle of IJK".into()));
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The two independent models agree within 1 % on the first six modes at three poses: the
/// centre, an off-centre turned pose, and one near the workspace edge: at G = (-0.175, 0),
/// sleeve 3 sits at xp3 = 28.4 mm, 13.4 mm from its limit Lp/2 = 15 mm (the junction G), i.e.
/// 2.9 % of the sleeve's travel 0 < xp - Lp/2 < L - Lp, and the largest angle of IJK is
/// 108.7 deg, 11.3 deg from the 120 deg where the Fermat point ceases to exist; the margins are
/// computed and checked here. Measured: AMM (N = 60) above FEM (300 elements) by 0.005 % to
/// 0.11 % at that pose.
#[test]
fn amm_and_fem_agree_within_one_percent() {
    let exp = paper();
    let edge = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), -0.175, 0.0, 0.0).unwrap();
    let m = margins(&exp, &edge);
    // nearest limits: the Fermat angle (108.7 deg, 11.3 deg from 120) and sleeve 3 (13.4 mm)
    assert_eq!(m[0].1, "Fermat angle of IJK", "{m:?}");
    assert!(m[0].0 > 0.0 && m[0].0 / exp.robot.lp < 12f64.to_radians(), "{m:?}");
    assert!(m[1].1.starts_with("sleeve 3 at the junction"), "{m:?}");
    assert!(m[1].0 > 0.0 && m[1].0 < 0.015, "{m:?}");
    assert!(m[1].0 / (exp.robot.l - exp.robot.lp) < 0.03, "{m:?}");
    for (gx, gy, th) in [(0.0, 0.0, 0.0), (0.03, -0.02, 0.1), (-0.175, 0.0, 0.0)] {
        let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), gx, gy, th).unwrap();
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
    let e = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.0, 0.0, 1.2)
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside the workspace"), "{e}");
    let e = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.3, 0.0, 0.0)
        .unwrap_err()
        .to_string();
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
