//! The trajectory kinds of `docs/motions.md` section 1 through `Trajectory::jets`, the
//! dual-number path every solver uses, against independent references: the closed-form quintic
//! `10 tau^3 - 15 tau^4 + 6 tau^5`, the inverse kinematics of the given poses, and finite
//! differences of the left and right limits at the knots.

use std::path::Path;

use flexstar_model::geometry::inverse_kinematics;
use flexstar_model::trajectory::Jet;
use flexstar_model::{Experiment, Pose, RobotParams, Trajectory};

const HEAD: &str = "name = \"m\"\n[time]\nt_end = 1.5\n[trajectory]\n";

const CYCLE: &str = "kind = \"via\"\npoints = [\n\
  { t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n\
  { t = 0.4, Gx = 0.03, Gy = -0.02, theta = 0.2 },\n\
  { t = 0.7, Gx = 0.03, Gy = -0.02, theta = 0.2 },\n\
  { t = 1.1, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n]\n";

fn load(traj: &str) -> Result<Experiment, String> {
    Experiment::from_toml_str(&format!("{HEAD}{traj}"), Path::new("m.toml")).map_err(|e| e.to_string())
}

fn jets(e: &Experiment, t: f64) -> [Jet; 3] {
    e.trajectory.jets(&e.robot, t).unwrap()
}

/// The closed-form rest-to-rest blend and its two derivatives in tau.
fn blend(tau: f64) -> [f64; 3] {
    let t = tau.clamp(0.0, 1.0);
    [
        t * t * t * (10.0 - 15.0 * t + 6.0 * t * t),
        30.0 * t * t * (1.0 - t) * (1.0 - t),
        60.0 * t * (1.0 - t) * (1.0 - 2.0 * t),
    ]
}

#[test]
fn via_with_rest_stops_at_every_point_and_dwells() {
    let e = load(CYCLE).unwrap();
    assert_eq!(e.trajectory.t_rest(), Some(1.1));
    for t in [0.0, 0.4, 0.7, 1.1, 1.3] {
        for j in jets(&e, t) {
            assert!(j.d1.abs() < 1e-12 && j.d2.abs() < 1e-9, "t = {t}: {j:?}");
        }
    }
    // the dwell holds still at the pose of points 2 and 3
    let p = RobotParams::paper();
    let s2 = inverse_kinematics(&p, [0.03, -0.02], 0.2).unwrap();
    for t in [0.45, 0.55, 0.69] {
        let j = jets(&e, t);
        for i in 0..3 {
            assert!(
                (j[i].v - s2[i]).abs() < 1e-15 && j[i].d1 == 0.0 && j[i].d2 == 0.0,
                "t = {t}"
            );
        }
    }
    assert!(jets(&e, 0.2).iter().any(|j| j.d1.abs() > 1e-2));
}

#[test]
fn two_via_points_are_the_quintic_for_either_rest() {
    let quintic = Trajectory::Quintic {
        from: Pose {
            gx: 0.0,
            gy: 0.01,
            theta: 0.0,
        },
        to: Pose {
            gx: 0.02,
            gy: -0.01,
            theta: 0.1,
        },
        t0: 0.1,
        t1: 0.5,
    };
    let p = RobotParams::paper();
    for rest in ["true", "false"] {
        let e = load(&format!(
            "kind = \"via\"\nrest = {rest}\npoints = [{{ t = 0.1, Gx = 0.0, Gy = 0.01, theta = 0.0 }}, \
             {{ t = 0.5, Gx = 0.02, Gy = -0.01, theta = 0.1 }}]\n"
        ))
        .unwrap();
        for k in 0..=60 {
            let t = k as f64 * 0.01;
            let (a, b) = (jets(&e, t), quintic.jets(&p, t).unwrap());
            for i in 0..3 {
                assert!((a[i].v - b[i].v).abs() < 1e-14, "rest = {rest}, t = {t}");
                assert!((a[i].d1 - b[i].d1).abs() < 1e-11 && (a[i].d2 - b[i].d2).abs() < 1e-8);
            }
        }
    }
}

#[test]
fn via_spline_interpolates_its_points_and_is_c2() {
    let e = load(&CYCLE.replace("kind = \"via\"", "kind = \"via\"\nrest = false")).unwrap();
    let p = RobotParams::paper();
    let points = [
        (0.0, [0.0, 0.0], 0.0),
        (0.4, [0.03, -0.02], 0.2),
        (0.7, [0.03, -0.02], 0.2),
        (1.1, [0.0, 0.0], 0.0),
    ];
    for (t, g, th) in points {
        let s = inverse_kinematics(&p, g, th).unwrap();
        let j = jets(&e, t);
        for i in 0..3 {
            assert!((j[i].v - s[i]).abs() < 1e-15, "t = {t}");
        }
    }
    // at rest at both ends
    for t in [0.0, 1.1] {
        for j in jets(&e, t) {
            assert!(j.d1.abs() < 1e-12 && j.d2.abs() < 1e-9, "t = {t}: {j:?}");
        }
    }
    // s'' continuous at the interior knots: left and right limits 1e-8 s away agree to the
    // change expected from a bounded s''' (1e-8 s x O(10) m/s^3); s''' itself from finite
    // differences of s'' on each side is finite (it may jump only at the two ends)
    for t in [0.4, 0.7] {
        let (l, r) = (jets(&e, t - 1e-8), jets(&e, t + 1e-8));
        for i in 0..3 {
            assert!((l[i].d2 - r[i].d2).abs() < 1e-5, "t = {t}: {:?} {:?}", l[i], r[i]);
        }
    }
    // the spline does not stop between points 2 and 3 (equal poses are no dwell for rest = false)
    assert!(jets(&e, 0.48).iter().any(|j| j.d1.abs() > 1e-3));
    // s''' jumps at the ends: s'' grows linearly from 0 just after t = 0
    let a = jets(&e, 1e-4)[0].d2 / 1e-4;
    assert!(a.abs() > 1.0, "s''' at 0+ = {a}");
}

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn load_in(dir: &Path, traj: &str) -> Result<Experiment, String> {
    Experiment::from_toml_str(&format!("{HEAD}{traj}"), &dir.join("exp.toml")).map_err(|e| e.to_string())
}

/// A table of `t,s1,s2,s3` rows sampling `s_i(t) = c_i b((t - 0.1) / 0.5)` every 2 ms from
/// `first` to 0.8 s.
fn slider_csv(c: [f64; 3], first: usize) -> String {
    let mut csv = String::from("t,s1,s2,s3\n");
    for k in first..=400 {
        let t = k as f64 * 0.002;
        let b = blend((t - 0.1) / 0.5)[0];
        csv += &format!("{t},{},{},{}\n", c[0] * b, c[1] * b, c[2] * b);
    }
    csv
}

/// Largest errors of s, s', s'' of `e` against `c_i b((t - 0.1) / 0.5)` over [0, 0.9] s.
fn slider_errors(e: &Experiment, c: [f64; 3]) -> [f64; 3] {
    let mut err = [0.0f64; 3];
    for k in 0..=900 {
        let t = k as f64 * 0.001 + 0.0003;
        let b = blend((t - 0.1) / 0.5);
        let j = jets(e, t);
        for i in 0..3 {
            err[0] = err[0].max((j[i].v - c[i] * b[0]).abs());
            err[1] = err[1].max((j[i].d1 - c[i] * b[1] / 0.5).abs());
            err[2] = err[2].max((j[i].d2 - c[i] * b[2] / 0.25).abs());
        }
    }
    err
}

#[test]
fn slider_table_reproduces_a_fine_sampled_quintic() {
    let dir = tempfile::tempdir().unwrap();
    let c = [0.02, -0.015, 0.01];
    // rows over the move alone (0.1 to 0.6 s): one quintic polynomial, which the clamped quintic
    // spline reproduces exactly (docs/motions.md 1.3); rests before and after are the table's
    let only_move: String = slider_csv(c, 0)
        .lines()
        .enumerate()
        .filter(|(k, l)| {
            *k == 0
                || l.split(',')
                    .next()
                    .unwrap()
                    .parse::<f64>()
                    .is_ok_and(|t| (0.1 - 1e-12..=0.6 + 1e-12).contains(&t))
        })
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    write(dir.path(), "move.csv", &only_move);
    let e = load_in(dir.path(), "kind = \"table\"\nfile = \"move.csv\"\n").unwrap();
    assert_eq!(e.input_files(), vec![dir.path().join("move.csv")]);
    let err = slider_errors(&e, c);
    assert!(err[0] < 1e-12 && err[1] < 1e-9 && err[2] < 1e-6, "{err:?}");
    // rows through the rests too: zero, quintic and constant pieces joined C2 (s''' jumps by
    // 60 c / T^3 at t0 and t1) are not one C4 spline, so the spline rounds the kinks of s''
    // there (measured: s'' within 4.6e-4 m/s^2 of a peak 0.46 m/s^2, 1e-3 relative, at 2 ms
    // rows; s, s' within 1.6e-10 m, 2.5e-7 m/s)
    write(dir.path(), "q.csv", &slider_csv(c, 0));
    let e = load_in(dir.path(), "kind = \"table\"\nfile = \"q.csv\"\n").unwrap();
    assert_eq!(e.trajectory.t_rest(), Some(0.8));
    let err = slider_errors(&e, c);
    let peak = 0.02 * 5.7735 / 0.25;
    assert!(err[0] < 1e-9 && err[1] < 1e-6 && err[2] < 2e-3 * peak, "{err:?}");
}

#[test]
fn task_table_reproduces_the_quintic_kind() {
    let dir = tempfile::tempdir().unwrap();
    let (from, to) = ([0.0, 0.01, 0.0], [0.025, -0.01, 0.15]);
    // rows over the move only, at 4 ms, with an extra column that is ignored
    let mut csv = String::from("t,Gx,Gy,theta,other\n");
    for k in 50..=200 {
        let t = k as f64 * 0.004;
        let b = blend((t - 0.2) / 0.6)[0];
        let p: Vec<String> = (0..3).map(|i| format!("{}", from[i] + (to[i] - from[i]) * b)).collect();
        csv += &format!("{t},{},9\n", p.join(","));
    }
    write(dir.path(), "task.csv", &csv);
    let e = load_in(dir.path(), "kind = \"table\"\nfile = \"task.csv\"\n").unwrap();
    let pose = |p: [f64; 3]| Pose {
        gx: p[0],
        gy: p[1],
        theta: p[2],
    };
    let quintic = Trajectory::Quintic {
        from: pose(from),
        to: pose(to),
        t0: 0.2,
        t1: 0.8,
    };
    for k in 0..=1000 {
        let t = k as f64 * 0.0011;
        let (a, b) = (jets(&e, t), quintic.jets(&e.robot, t).unwrap());
        for i in 0..3 {
            assert!((a[i].v - b[i].v).abs() < 1e-12, "t = {t}");
            assert!(
                (a[i].d1 - b[i].d1).abs() < 1e-9 && (a[i].d2 - b[i].d2).abs() < 1e-6,
                "t = {t}"
            );
        }
    }
}

#[test]
fn bad_via_lists_name_the_key_and_point() {
    let one = "kind = \"via\"\npoints = [{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }]\n";
    let same = "kind = \"via\"\npoints = [{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }, \
                { t = 0.3, Gx = 0.01, Gy = 0.0, theta = 0.0 }, { t = 0.3, Gx = 0.0, Gy = 0.0, theta = 0.0 }]\n";
    let neg = "kind = \"via\"\npoints = [{ t = -0.1, Gx = 0.0, Gy = 0.0, theta = 0.0 }, \
               { t = 0.3, Gx = 0.01, Gy = 0.0, theta = 0.0 }]\n";
    let nan = "kind = \"via\"\npoints = [{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }, \
               { t = 0.3, Gx = 0.01, Gy = nan, theta = 0.0 }]\n";
    let far = "kind = \"via\"\npoints = [{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }, \
               { t = 0.3, Gx = 0.0, Gy = 0.0, theta = 1.6 }]\n";
    let late = CYCLE.replace("t = 1.1", "t = 1.6");
    for (traj, want) in [
        (one, "at least two points, got 1"),
        (same, "point 3 at t = 0.3 s does not come after point 2 at t = 0.3 s"),
        (neg, "point 1 at t = -0.1 s: times must be >= 0"),
        (nan, "point 2: Gy must be finite, got NaN"),
        (far, "point 2 (Gx = 0, Gy = 0, theta = 1.6) is outside the workspace"),
        (
            late.as_str(),
            "t_rest = 1.6 s (the time of point 4), after time.t_end = 1.5 s",
        ),
    ] {
        let e = load(traj).unwrap_err();
        assert!(
            e.contains("m.toml") && e.contains("trajectory.points") && e.contains(want),
            "{want}: {e}"
        );
    }
    // an unknown key in a point, a missing one, keys of another kind
    let e = load(&CYCLE.replace("theta = 0.2 },\n{ t = 0.7", "theta = 0.2, z = 1 },\n{ t = 0.7")).unwrap_err();
    assert!(e.contains("m.toml") && e.contains("`z`"), "{e}");
    let e = load(&CYCLE.replace(
        "Gx = 0.03, Gy = -0.02, theta = 0.2 },\n{ t = 0.7",
        "Gx = 0.03, theta = 0.2 },\n{ t = 0.7",
    ))
    .unwrap_err();
    assert!(e.contains("Gy"), "{e}");
    let e = load(&format!("{CYCLE}t1 = 0.3\n")).unwrap_err();
    assert!(
        e.contains("trajectory.t1") && e.contains("kind = \"via\"") && e.contains("points, rest"),
        "{e}"
    );
    let e = load("kind = \"table\"\nfile = \"x.csv\"\nrest = true\n").unwrap_err();
    assert!(e.contains("trajectory.rest") && e.contains("file, columns"), "{e}");
    let e = load("kind = \"via\"\n").unwrap_err();
    assert!(e.contains("trajectory.points"), "{e}");
}

#[test]
fn bad_tables_name_the_file_key_and_row() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rows = |extra: &str| format!("t,s1,s2,s3\n0,0,0,0\n0.01,0,0,0\n0.02,0,0,0\n{extra}");
    write(d, "nan.csv", &rows("0.03,nan,0,0\n"));
    write(d, "back.csv", &rows("0.02,0,0,0\n"));
    write(d, "gap.csv", &rows("0.03,0,0,0\n0.5,0,0,0\n"));
    write(d, "far.csv", "t,Gx,Gy,theta\n0,0,0,0\n0.01,0,0,0\n0.02,0,0,1.6\n");
    write(
        d,
        "both.csv",
        "t,Gx,Gy,theta,s1,s2,s3\n0,0,0,0,0,0,0\n0.01,0,0,0,0,0,0\n",
    );
    write(d, "none.csv", "t,a,b,c\n0,0,0,0\n0.01,0,0,0\n");
    write(d, "neg.csv", "t,s1,s2,s3\n-0.01,0,0,0\n0.01,0,0,0\n");
    write(d, "late.csv", "t,s1,s2,s3\n0,0,0,0\n1.0,0,0,0\n2.0,0,0,0\n");
    for (file, want) in [
        ("nan.csv", "row 4: non-finite value"),
        ("back.csv", "row 4: time 0.02 s does not increase"),
        ("gap.csv", "rows 4-5: a gap of"),
        (
            "far.csv",
            "row 3 (Gx = 0, Gy = 0, theta = 1.6) is outside the workspace",
        ),
        ("both.csv", "say columns = \"task\" or \"slider\""),
        ("none.csv", "hold Gx, Gy, theta or s1, s2, s3"),
        ("neg.csv", "row 1: time -0.01 s"),
        ("missing.csv", "cannot read"),
        ("late.csv", "t_rest = 2 s"),
    ] {
        let e = load_in(d, &format!("kind = \"table\"\nfile = \"{file}\"\n")).unwrap_err();
        assert!(
            e.contains("exp.toml") && e.contains("trajectory.file") && e.contains(want),
            "{file}: {e}"
        );
        if file != "late.csv" {
            assert!(e.contains(file), "{file}: {e}");
        }
    }
    // with columns named, a file holding both is read in that space
    let e = load_in(d, "kind = \"table\"\nfile = \"both.csv\"\ncolumns = \"slider\"\n").unwrap();
    assert_eq!(e.trajectory.t_rest(), Some(0.01));
}
