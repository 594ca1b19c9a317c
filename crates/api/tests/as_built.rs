//! The commands on a robot as built (`docs/modes.md`, a robot as built): `run` writes its
//! residual and per-dwell keys, timed by the robot's own modes (checked against the FEM's), and
//! `modal`, `linearize` and `freqmap` take it (their files of its own beams).

use std::path::{Path, PathBuf};

use flexstar_api::modal::{FreqmapSettings, LinearizeOptions, PoseSpec};
use flexstar_api::run::{run_to_dir, RunSettings, Solver};
use flexstar_model::{Experiment, Sliders};

/// Every datum its own (beams, welds, base), as in `crates/modal/tests/as_built.rs`.
const AS_BUILT: &str = "[robot]\nL = [0.52, 0.48, 0.5]\nI = [2.5e-12, 2.8e-12, 2.2e-12]\nrho = [0.25, 0.22, 0.234]\n\
                        Lp = [0.03, 0.033, 0.028]\nJp = [2e-4, 2.2e-4, 1.8e-4]\nmpp_mpa = [0.2, 0.18, 0.22]\n\
                        weld_deg = [0, 121.5, 238.5]\n[base]\nsides = [0.63, 0.6, 0.64]\n";

/// A pick-and-place cycle with a dwell (configs/motions/pick-place.toml, shorter).
const CYCLE: &str = "[time]\nt_end = 1.3\ndt_out = 0.001\n[trajectory]\nkind = \"via\"\nrest = true\npoints = [\n\
                     { t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n\
                     { t = 0.3, Gx = 0.03, Gy = -0.02, theta = 0.2 },\n\
                     { t = 0.6, Gx = 0.03, Gy = -0.02, theta = 0.2 },\n\
                     { t = 0.9, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n]\n";

/// Write `dir/name.toml` of the robot as built with `body` and load it.
fn load(dir: &Path, name: &str, body: &str) -> (Experiment, String) {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, format!("name = \"{name}\"\n{body}{AS_BUILT}")).unwrap();
    let exp = flexstar_api::load(&file).unwrap();
    assert!(exp.robot.as_built.is_some(), "a robot as built");
    (exp, file.display().to_string())
}

/// One period [s] of the FEM's (300 elements) first elastic mode at the pose the motion holds at
/// `t`, sliders locked.
fn fem_period(exp: &Experiment, t: f64) -> f64 {
    let pose = flexstar_modal::pose::pose_at_time(exp, t).unwrap();
    let f = flexstar_modal::analysis::fem_pose_modes(exp, &pose, Sliders::Locked, 1).unwrap();
    1.0 / f.freq_hz[0]
}

/// `run` of the robot as built writes the residual keys: their hold is one period of the first
/// mode at the robot's final pose, the FEM's within 1 % (measured 0.007 %); each dwell's at its
/// own pose likewise, the last dwell's the run's own (the final pose's modes solved once).
#[test]
fn a_run_of_a_robot_as_built_writes_its_residual_keys() {
    let dir = tempfile::tempdir().unwrap();
    let (exp, source) = load(dir.path(), "cycle", CYCLE);
    let out = run_to_dir(
        exp.clone(),
        &source,
        &RunSettings::new(Solver::Amm),
        &dir.path().join("out"),
        |_| {},
        None,
    )
    .unwrap();
    let keys = out.sidecar.residual.as_ref().expect("residual keys");
    let hold = keys.settle_hold_s.expect("a hold");
    let fem = fem_period(&exp, 0.9);
    eprintln!("hold {hold:.6} s, FEM period at the final pose {fem:.6} s");
    assert!((hold / fem - 1.0).abs() < 0.01, "hold {hold} s, FEM {fem} s");
    assert!(keys.g_peak_m.is_some_and(|g| g > 0.0) && keys.t_rest == Some(0.9));
    let dwells = keys.dwells.as_ref().expect("per-dwell keys");
    assert_eq!(dwells.len(), 2);
    let first = dwells[0].settle_hold_s.unwrap();
    let fem_first = fem_period(&exp, 0.3);
    eprintln!("dwell 1: hold {first:.6} s, FEM {fem_first:.6} s");
    assert!(
        (first / fem_first - 1.0).abs() < 0.01,
        "dwell 1: {first} s, FEM {fem_first} s"
    );
    assert_eq!(dwells[1].settle_hold_s, Some(hold));
    let sidecar = std::fs::read_to_string(dir.path().join("out/cycle/amm-enriched.json")).unwrap();
    assert!(sidecar.contains("settle_hold_s"), "{sidecar}");
}

fn files_exist(files: &[PathBuf]) {
    for f in files {
        assert!(f.is_file(), "{}", f.display());
    }
}

/// `modal`, `linearize` and `freqmap` take the robot as built (they refused it before): `modal`
/// writes its table and figure, `linearize` the FEM's coordinates with each sleeve's own length
/// (the contact coordinates `xi_l`, `xi_r` at `xp_i -+ Lp_i / 2`), `freqmap` a map whose points
/// are all feasible about the start pose.
#[test]
fn the_modal_commands_take_a_robot_as_built() {
    let dir = tempfile::tempdir().unwrap();
    let (exp, source) = load(dir.path(), "still", CYCLE);
    let out = dir.path().join("out");
    let at = PoseSpec::At(0.45);
    let m = flexstar_api::modal::modal(&exp, &source, &at, Sliders::Locked, 4, Some(&out), false).unwrap();
    files_exist(&m.files);
    flexstar_api::modal::linearize(&exp, &source, &at, &LinearizeOptions::default(), Some(&out)).unwrap();
    let coords = std::fs::read_to_string(out.join("still/linear/fem-coordinates.csv")).unwrap();
    let lp = [0.03, 0.033, 0.028];
    for (i, lp) in lp.iter().enumerate() {
        let x = |dof: &str| -> f64 {
            let row = coords
                .lines()
                .find(|l| l.split(',').nth(2) == Some(&(i + 1).to_string()) && l.split(',').nth(3) == Some(dof))
                .unwrap();
            row.split(',').nth(4).unwrap().parse().unwrap()
        };
        assert!((x("xi_r") - x("xi_l") - lp).abs() < 1e-12, "beam {}", i + 1);
        assert!((x("xi_c") - m.pose.xp[i]).abs() < 1e-12, "beam {}", i + 1);
    }
    let axis = |v: f64| flexstar_modal::freqmap::Axis {
        min: v - 0.01,
        max: v + 0.01,
        n: 3,
    };
    let map = FreqmapSettings {
        gx: axis(m.pose.g[0]),
        gy: axis(m.pose.g[1]),
        theta: m.pose.theta,
        k: 2,
        solver: flexstar_solve::Solver::Amm,
        sliders: Sliders::Locked,
        force: false,
    };
    let figure = flexstar_api::modal::freqmap(&exp, &source, map, Some(&out), |_, _| {}).unwrap();
    assert!(figure.points.iter().all(|p| p.result.is_ok()));
    assert!(out.join("still/freqmap.csv").is_file());
}
