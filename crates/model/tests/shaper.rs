//! `[shaper]` on an experiment (docs/motions.md 3.4, 3.7): the shaped motion's
//! pose is the impulse-weighted sum of the unshaped one's, its t_rest is later by the shaper's
//! duration, and bad sections are refused by key.

use std::path::Path;

use flexstar_model::{Experiment, Trajectory};
use num_dual::Dual2;

const BASE: &str = r#"
name = "brisk"
[time]
t_end = 0.6
dt_out = 0.001
[trajectory]
kind = "quintic"
from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }
to = { Gx = -0.008, Gy = 0.006, theta = -0.06 }
t0 = 0.0
t1 = 0.2
"#;

fn load(shaper: &str) -> Result<Experiment, String> {
    Experiment::from_toml_str(&format!("{BASE}{shaper}"), Path::new("x.toml")).map_err(|e| e.to_string())
}

#[test]
fn shaped_pose_is_the_weighted_sum_and_rests_later() {
    let plain = load("").unwrap();
    let e = load("[shaper]\nkind = \"zv\"\nf_hz = 4.0\n").unwrap();
    let Trajectory::Shaped(sh) = &e.trajectory else {
        panic!("not shaped")
    };
    assert_eq!(sh.impulses.len(), 2);
    assert!((e.trajectory.t_rest().unwrap() - (0.2 + 0.125)).abs() < 1e-12);
    let sec = e.shaper.as_ref().unwrap();
    assert!((sec.penalty_s - 0.125).abs() < 1e-12 && sec.frequencies_hz == vec![4.0]);
    for t in [0.05, 0.13, 0.2, 0.27, 0.31] {
        let d = Dual2::from_re(t).derivative();
        let got = e.trajectory.pose(d).unwrap().unwrap();
        for (c, got_c) in got.iter().enumerate() {
            let want: f64 = sh
                .impulses
                .iter()
                .map(|i| {
                    i.a * plain
                        .trajectory
                        .pose(Dual2::from_re(t - i.t).derivative())
                        .unwrap()
                        .unwrap()[c]
                        .v2
                })
                .sum();
            assert!((got_c.v2 - want).abs() < 1e-12, "t = {t}");
        }
    }
    let end = e.trajectory.jets(&e.robot, 0.33).unwrap();
    let fin = plain.trajectory.jets(&e.robot, 0.5).unwrap();
    for (a, b) in end.iter().zip(&fin) {
        assert!((a.v - b.v).abs() < 1e-14 && a.d1.abs() < 1e-14 && a.d2.abs() < 1e-12);
    }
}

#[test]
fn bad_sections_are_refused_by_key() {
    for (section, words) in [
        ("kind = \"zvdd\"\nf_hz = 4.0", "zvdd"),
        ("kind = \"zv\"\nf_hz = -3.0", "shaper.f_hz"),
        ("kind = \"zv\"\nf_hz = []", "shaper.f_hz"),
        ("kind = \"zv\"\nf_hz = 4.0\nzeta = 1.0", "shaper.zeta"),
        ("kind = \"zv\"\nf_hz = 4.0\nv_tol = 0.1", "shaper.v_tol"),
        ("kind = \"zvd\"\nf_hz = 1.0", "t_rest"),
    ] {
        let err = load(&format!("[shaper]\n{section}\n")).unwrap_err();
        assert!(err.contains(words), "{section}: {err}");
    }
    let poly = "name = \"p\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0, 0.0, 0.1]\ns2 = [0.0]\ns3 = [0.0]\n[shaper]\nkind = \"zv\"\nf_hz = 4.0\n";
    let err = Experiment::from_toml_str(poly, Path::new("p.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("rest-to-rest"), "{err}");
}

/// Reading a file never runs a solver: `f_hz = "auto"` is checked (with a servo it is refused by
/// key) and left pending, the motion unshaped, for the explicit step `flexstar_shaping::shape`.
#[test]
fn auto_is_left_pending_when_read() {
    let plain = load("").unwrap();
    let e = load("[shaper]\nkind = \"zvd\"\nf_hz = \"auto\"\n").unwrap();
    assert!(e.shaper_pending());
    assert_eq!(e.trajectory, plain.trajectory);
    assert!(!plain.shaper_pending());
    assert!(!load("[shaper]\nkind = \"zv\"\nf_hz = 4.0\n").unwrap().shaper_pending());
    let err = load("[shaper]\nkind = \"zvd\"\nf_hz = \"auto\"\nv_tol = 0.1\n").unwrap_err();
    assert!(err.contains("shaper.v_tol"), "{err}");
}
