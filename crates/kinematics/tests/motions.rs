//! Feasibility of the trajectory kinds of `docs/motions.md` (1.6): an infeasible table
//! row or via point is named, and so is a limit reached between two points.

use flexstar_kinematics::{check_configuration, check_trajectory, Violation};
use flexstar_model::{RobotParams, TableMotion, TableSpace, Trajectory, ViaMotion, ViaPoint};

fn via(points: &[[f64; 4]], rest: bool) -> Trajectory {
    let points = points
        .iter()
        .map(|p| ViaPoint {
            t: p[0],
            gx: p[1],
            gy: p[2],
            theta: p[3],
        })
        .collect();
    Trajectory::Via(ViaMotion::new(points, rest))
}

#[test]
fn a_spline_that_overshoots_between_points_is_refused_there() {
    // G goes 8 cm in 0.1 s and stays for 0.4 s: as rest-to-rest segments it stays feasible; the
    // clamped spline overshoots past point 2 (it does not stop there) and a sleeve reaches G
    let p = RobotParams::paper();
    let points = [[0.0, 0.0, 0.0, 0.0], [0.1, 0.08, 0.0, 0.0], [0.5, 0.08, 0.0, 0.0]];
    assert!(check_trajectory(&p, &via(&points, true), 0.6, 1e-3).is_ok());
    let err = check_trajectory(&p, &via(&points, false), 0.6, 1e-3).unwrap_err();
    assert!(err.t > 0.1 && err.t < 0.5, "{err}");
    match &err.violation {
        Violation::Located { at, violation } => {
            assert_eq!(at, "between points 2 and 3");
            assert!(matches!(**violation, Violation::SleeveAtJunction { .. }), "{err}");
        }
        other => panic!("{other:?}"),
    }
    // the time found is where the limit is reached: feasible just before, not at it
    let s = |t: f64| via(&points, false).s(&p, t).unwrap();
    assert!(check_configuration(&p, s(err.t - 1e-6)).is_ok());
    assert!(check_configuration(&p, s(err.t + 1e-6)).is_err());
}

#[test]
fn an_infeasible_table_row_or_via_point_is_named() {
    let p = RobotParams::paper();
    // slider 1 beyond sqrt(3) d = 0.3118 m at row 3
    let t = vec![0.0, 0.01, 0.02, 0.03];
    let rows = vec![[0.0; 3], [0.0; 3], [0.35, 0.0, 0.0], [0.0; 3]];
    let table = TableMotion::from_rows("rows.csv".into(), TableSpace::Slider, t, rows, &p).unwrap();
    let err = check_trajectory(&p, &Trajectory::Table(table), 0.1, 1e-3).unwrap_err();
    let msg = err.to_string();
    assert!(
        err.t == 0.02 && msg.contains("trajectory.file: rows.csv: row 3 (s1 = 0.35, s2 = 0, s3 = 0)"),
        "{msg}"
    );
    assert!(msg.contains("slider 1 leaves its side of the base"), "{msg}");
    // a via point whose pose the inverse kinematics reaches but a sleeve slides off its beam
    let points = [[0.0, 0.0, 0.0, 0.0], [0.3, 0.0, -0.2, 0.0]];
    let err = check_trajectory(&p, &via(&points, true), 0.5, 1e-3).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("trajectory.points: point 2 (Gx = 0, Gy = -0.2, theta = 0)"),
        "{msg}"
    );
}
