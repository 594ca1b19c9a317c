//! End-to-end checks of `flexstar modal`, `freqmap` and `linearize` (`docs/modes.md`): file contracts
//! (paths, exact CSV headers, Matrix Market headers), agreement between the commands and with
//! independent references (symmetry of the robot, the FEM), and bad input refused with the reason
//! and no output. Small models (AMM N = 40, FEM 102 elements) keep each run well under a second.

use std::path::{Path, PathBuf};

use crate::common;
use common::{flexstar, stderr};

/// `flexstar` with the arguments `base` then `extra`.
fn flexstar_with(base: &[&str], extra: &[&str]) -> std::process::Output {
    flexstar(&[base, extra].concat())
}

/// A temporary folder (kept alive by the first value) holding the small experiment; its path
/// and the output folder `out` in it.
fn small_case() -> (tempfile::TempDir, String, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = small_config(dir.path());
    let out = dir.path().join("out");
    (dir, cfg, out)
}

/// The paper's robot with case 3's motion and small solver settings, written into `dir`.
fn small_config(dir: &Path) -> String {
    let text = "name = \"small\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"polynomial\"\n\
                s1 = [0.0, 0.0, 1.0]\ns2 = [0.0]\ns3 = [0.0, 0.0, 0.5]\n[amm]\nmodes = 40\n[fem]\nelements = 102\n";
    let p = dir.join("small.toml");
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

fn rows(path: &Path) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    (
        header,
        lines.map(|l| l.split(',').map(String::from).collect()).collect(),
    )
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

/// Files left in `dir` (none when the directory does not exist).
fn files_in(dir: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(dir) {
        Ok(rd) => rd.map(|e| e.unwrap().path()).collect(),
        Err(_) => vec![],
    }
}

/// modal.csv with the exact header; the centre pose's repeated pair (the star's three-fold
/// symmetry) in both models; AMM and FEM within 1.5 % at this small N and mesh; the figures.
#[test]
fn modal_writes_the_contracted_table_and_shapes() {
    let (_dir, cfg, out) = small_case();
    let o = flexstar(&["modal", &cfg, "--pose", "0,0,0", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = out.join("small");
    let (header, r) = rows(&case.join("modal.csv"));
    assert_eq!(header, "mode,f_amm_hz,f_fem_hz,rel_diff");
    assert_eq!(r.len(), 6);
    let f: Vec<[f64; 3]> = r.iter().map(|x| [num(&x[1]), num(&x[2]), num(&x[3])]).collect();
    for (k, [a, fe, rel]) in f.iter().enumerate() {
        assert_eq!(num(&r[k][0]), (k + 1) as f64);
        assert!(
            (rel - (a - fe) / fe).abs() < 1e-12 && rel.abs() < 0.015,
            "mode {}: {a} vs {fe}",
            k + 1
        );
    }
    for col in 0..2 {
        assert!((f[0][col] / f[1][col] - 1.0).abs() < 1e-6, "pair 1-2: {:?}", f);
        assert!((f[3][col] / f[4][col] - 1.0).abs() < 1e-6, "pair 4-5: {:?}", f);
    }
    for ext in ["svg", "png"] {
        let p = case.join(format!("modal-shapes.{ext}"));
        assert!(
            std::fs::metadata(&p).map(|m| m.len() > 1000).unwrap_or(false),
            "{}",
            p.display()
        );
    }
    // free sliders: three rigid modes at 0 Hz first, then K elastic ones (other settings into
    // the same folder: --force replaces the table)
    let o = flexstar(&[
        "modal",
        &cfg,
        "--at",
        "0.25",
        "--sliders",
        "free",
        "--modes",
        "2",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, r) = rows(&case.join("modal.csv"));
    assert_eq!(r.len(), 5);
    assert!(r[..3].iter().all(|x| num(&x[1]) == 0.0 && num(&x[2]) == 0.0));
    assert!(r[3..].iter().all(|x| num(&x[1]) > 1.0 && num(&x[3]).abs() < 0.015));
}

/// The sidecar JSON as a value.
fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// modal.json and freqmap.json beside their tables: provenance, solver(s), pose or grid,
/// sliders, K, the resolved experiment. A rerun with other settings is refused naming the file
/// and what differs, and leaves the files as they were; an identical rerun and `--force`
/// replace them.
#[test]
fn modal_and_freqmap_sidecars_guard_the_tables() {
    let (_dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let case = out.join("small");
    let modal = |extra: &[&str]| flexstar_with(&["modal", &cfg, "--modes", "3", "--out", out_s], extra);
    let o = modal(&["--pose", "0.03,-0.02,0.1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = json(&case.join("modal.json"));
    assert_eq!(m["command"], "modal");
    assert_eq!(m["table"], "modal.csv");
    assert_eq!(m["K"], 3);
    assert_eq!(m["sliders"], "locked");
    assert_eq!(m["pose"]["task"], serde_json::json!([0.03, -0.02, 0.1]));
    // G of the rest pose, from the sliders by the direct kinematics: the pose asked for
    let g: Vec<f64> = m["pose"]["G"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!((g[0] - 0.03).abs() < 1e-12 && (g[1] + 0.02).abs() < 1e-12, "{g:?}");
    assert_eq!(m["pose"]["s"].as_array().map(Vec::len), Some(3));
    assert_eq!(m["solvers"][0]["solver"], "amm");
    assert_eq!(m["solvers"][0]["modes_per_beam"], 40);
    assert_eq!(m["solvers"][1]["elements"], 102);
    assert_eq!(m["experiment"]["name"], "small");
    assert_eq!(m["flexstar_version"], env!("CARGO_PKG_VERSION"));
    assert!(m["date"].as_str().is_some_and(|d| d.ends_with('Z')), "{m}");
    // the same settings again: replaced
    let o = modal(&["--pose", "0.03,-0.02,0.1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(case.join("modal.csv")).unwrap();
    let meta = std::fs::read(case.join("modal.json")).unwrap();
    for (extra, needle) in [
        (vec!["--pose", "0,0,0"], "pose: "),
        (
            vec!["--pose", "0.03,-0.02,0.1", "--sliders", "free"],
            "sliders: \"locked\" -> \"free\"",
        ),
        (vec!["--at", "0.25"], "pose: "),
    ] {
        let o = modal(&extra);
        assert!(!o.status.success(), "{extra:?} replaced the table");
        let e = stderr(&o);
        assert!(
            e.contains("modal.csv") && e.contains("other settings") && e.contains(needle),
            "{e}"
        );
        assert!(e.contains("--force"), "{e}");
        assert_eq!(std::fs::read(case.join("modal.csv")).unwrap(), before, "{extra:?}");
        assert_eq!(std::fs::read(case.join("modal.json")).unwrap(), meta, "{extra:?}");
    }
    let o = modal(&["--pose", "0,0,0", "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        json(&case.join("modal.json"))["pose"]["task"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
    // the map: the grid, solver, sliders, K
    let map = |extra: &[&str]| {
        flexstar_with(
            &["freqmap", &cfg, "--gy", "-0.1:0.1:3", "--modes", "2", "--out", out_s],
            extra,
        )
    };
    let o = map(&["--gx", "-0.1:0.1:3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let f = json(&case.join("freqmap.json"));
    assert_eq!(f["command"], "freqmap");
    assert_eq!(f["grid"]["Gx"], serde_json::json!({ "min": -0.1, "max": 0.1, "n": 3 }));
    assert_eq!(f["grid"]["theta"], 0.0);
    assert_eq!((f["K"].clone(), f["sliders"].clone()), (2.into(), "locked".into()));
    assert_eq!(f["solver"]["solver"], "amm");
    assert_eq!(f["experiment"]["name"], "small");
    let before = std::fs::read(case.join("freqmap.csv")).unwrap();
    for (extra, needle) in [
        (vec!["--gx", "-0.1:0.1:5"], "grid: "),
        (vec!["--gx", "-0.1:0.1:3", "--solver", "fem"], "solver: "),
        (vec!["--gx", "-0.1:0.1:3", "--theta", "0.1"], "grid: "),
    ] {
        let o = map(&extra);
        assert!(!o.status.success(), "{extra:?} replaced the map");
        let e = stderr(&o);
        assert!(e.contains("freqmap.csv") && e.contains(needle), "{e}");
        assert_eq!(std::fs::read(case.join("freqmap.csv")).unwrap(), before, "{extra:?}");
    }
    let o = map(&["--gx", "-0.1:0.1:3"]);
    assert!(o.status.success(), "identical rerun: {}", stderr(&o));
    let o = map(&["--gx", "-0.1:0.1:5", "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(rows(&case.join("freqmap.csv")).1.len(), 15);
    // a table without its sidecar (an older flexstar): its settings cannot be told, refused
    std::fs::remove_file(case.join("freqmap.json")).unwrap();
    let o = map(&["--gx", "-0.1:0.1:5"]);
    assert!(
        !o.status.success() && stderr(&o).contains("freqmap.json"),
        "{}",
        stderr(&o)
    );
}

/// `freqmap --sliders free`: f1 is the first elastic frequency, equal to what `modal --sliders
/// free` reports there (its mode 4, after the three rigid ones); the map is drawn over the
/// experiment's own path G(t), not the paper's four; `modal` prints no negative zero.
#[test]
fn freqmap_with_free_sliders_and_the_experiments_path() {
    let (_dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let case = out.join("small");
    let grid = [
        "--gx",
        "-0.05:0.05:3",
        "--gy",
        "-0.05:0.05:3",
        "--modes",
        "2",
        "--out",
        out_s,
    ];
    let mut args = vec!["freqmap", cfg.as_str(), "--sliders", "free"];
    args.extend(grid);
    let o = flexstar(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, map) = rows(&case.join("freqmap.csv"));
    assert_eq!(header, "Gx,Gy,theta,feasible,f1_hz,f2_hz");
    let centre = &map[4];
    assert_eq!((num(&centre[0]), num(&centre[1])), (0.0, 0.0));
    let svg = std::fs::read_to_string(case.join("freqmap.svg")).unwrap();
    assert!(
        svg.contains("G(t) of small") && svg.contains("sliders free"),
        "no path of the experiment"
    );
    assert!(!svg.contains("case 1"), "the paper's paths are drawn");
    let o = flexstar(&[
        "modal",
        &cfg,
        "--pose",
        "0,0,0",
        "--sliders",
        "free",
        "--modes",
        "2",
        "--out",
        out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        !e.contains("-0.00000") && !e.contains(" -0.000 %"),
        "a negative zero: {e}"
    );
    let (_, m) = rows(&case.join("modal.csv"));
    for k in 0..2 {
        let (map, full) = (num(&centre[4 + k]), num(&m[3 + k][1]));
        assert!(
            map > 1.0 && (map / full - 1.0).abs() < 1e-7,
            "f{}: {map} vs {full}",
            k + 1
        );
    }
}

/// freqmap.csv with the exact header, infeasible poses marked with the reason in the sidecar;
/// the map is mirror-symmetric in Gx at theta = 0 (the robot is); its value at the centre equals
/// what `modal` reports there (the map's values-only solver against the full one).
#[test]
fn freqmap_writes_the_contracted_map() {
    let (_dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let o = flexstar(&[
        "freqmap",
        &cfg,
        "--gx",
        "-0.3:0.3:5",
        "--gy",
        "-0.15:0.15:3",
        "--modes",
        "2",
        "--out",
        out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = out.join("small");
    let (header, r) = rows(&case.join("freqmap.csv"));
    assert_eq!(header, "Gx,Gy,theta,feasible,f1_hz,f2_hz");
    assert_eq!(r.len(), 15);
    let infeasible: Vec<&Vec<String>> = r.iter().filter(|x| x[3] == "false").collect();
    assert!(!infeasible.is_empty() && infeasible.len() < 15, "{r:?}");
    assert!(infeasible.iter().all(|x| x[4].is_empty() && x[5].is_empty()));
    let (h2, reasons) = rows(&case.join("freqmap-infeasible.csv"));
    assert_eq!(h2, "Gx,Gy,theta,reason");
    assert_eq!(reasons.len(), infeasible.len());
    assert!(
        reasons.iter().all(|x| x[3].contains("outside the workspace")),
        "{reasons:?}"
    );
    // mirror symmetry Gx -> -Gx (row-major: Gx fastest)
    for y in 0..3 {
        for x in 0..5 {
            let (a, b) = (&r[5 * y + x], &r[5 * y + 4 - x]);
            assert_eq!(a[3], b[3], "feasibility not mirror-symmetric: {a:?} {b:?}");
            if a[3] == "true" {
                for c in 4..6 {
                    assert!((num(&a[c]) / num(&b[c]) - 1.0).abs() < 1e-7, "{a:?} vs {b:?}");
                }
            }
        }
    }
    for ext in ["svg", "png"] {
        assert!(case.join(format!("freqmap.{ext}")).exists());
    }
    let centre = &r[7];
    assert_eq!((num(&centre[0]), num(&centre[1])), (0.0, 0.0));
    let o = flexstar(&["modal", &cfg, "--pose", "0,0,0", "--modes", "2", "--out", out_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, m) = rows(&case.join("modal.csv"));
    for k in 0..2 {
        assert!(
            (num(&m[k][1]) / num(&centre[4 + k]) - 1.0).abs() < 1e-7,
            "{m:?} vs {centre:?}"
        );
    }
}

/// linear/: the seven Matrix Market files and statespace.json; A holds -omega^2 of the modes
/// `modal --sliders free` reports at the same pose (omega = 2 pi f).
#[test]
fn linearize_writes_the_state_space_files() {
    let (_dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let o = flexstar(&["linearize", &cfg, "--pose", "0.03,-0.02,0.1", "--out", out_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lin = out.join("small").join("linear");
    let mut dims = std::collections::HashMap::new();
    for name in ["A", "B", "C", "D", "M", "K", "Phi_q"] {
        let text = std::fs::read_to_string(lin.join(format!("{name}.mtx"))).unwrap();
        assert!(
            text.starts_with("%%MatrixMarket matrix coordinate real general"),
            "{name}"
        );
        dims.insert(name, mtx_size(&lin.join(format!("{name}.mtx"))));
    }
    let n = dims["A"].0;
    assert_eq!(dims["A"], (n, n));
    assert_eq!(dims["B"], (n, 3));
    assert_eq!(dims["C"], (9, n));
    assert_eq!(dims["D"], (9, 3));
    assert_eq!(dims["M"], dims["K"]);
    assert_eq!(dims["Phi_q"].1, dims["M"].0);
    let json = std::fs::read_to_string(lin.join("statespace.json")).unwrap();
    for key in ["\"inputs\"", "\"outputs\"", "\"Fa1\"", "\"w3G\"", "\"pose\""] {
        assert!(json.contains(key), "{key} missing in statespace.json");
    }
    // A's lower-left block: -omega_j^2 on the diagonal, against modal --sliders free
    let o = flexstar(&[
        "modal",
        &cfg,
        "--pose",
        "0.03,-0.02,0.1",
        "--sliders",
        "free",
        "--modes",
        "4",
        "--out",
        out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, m) = rows(&out.join("small").join("modal.csv"));
    let a = std::fs::read_to_string(lin.join("A.mtx")).unwrap();
    let entries: Vec<(usize, usize, f64)> = a
        .lines()
        .filter(|l| !l.starts_with('%'))
        .skip(1)
        .map(|l| {
            let v: Vec<&str> = l.split_whitespace().collect();
            (v[0].parse().unwrap(), v[1].parse().unwrap(), num(v[2]))
        })
        .collect();
    let nr = n / 2;
    for (j, row) in m.iter().enumerate().take(7).skip(3) {
        let w = 2.0 * std::f64::consts::PI * num(&row[1]);
        let e = entries
            .iter()
            .find(|(r, c, _)| *r == nr + j + 1 && *c == j + 1)
            .expect("A entry");
        assert!(
            (e.2 / -(w * w) - 1.0).abs() < 1e-9,
            "mode {}: {} vs {}",
            j + 1,
            e.2,
            -(w * w)
        );
    }
}

/// Size (rows, columns) of a Matrix Market file.
fn mtx_size(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let size: Vec<usize> = text
        .lines()
        .find(|l| !l.starts_with('%'))
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    (size[0], size[1])
}

fn names(json: &serde_json::Value, key: &str) -> Vec<String> {
    json[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} is not a list"))
        .iter()
        .map(|v| v["name"].as_str().unwrap().to_string())
        .collect()
}

/// Run `linearize` with `extra` flags; returns linear/ and statespace.json.
fn linearize_with(cfg: &str, name: &str, out: &Path, extra: &[&str]) -> (PathBuf, serde_json::Value) {
    let mut args = vec![
        "linearize",
        cfg,
        "--pose",
        "0.03,-0.02,0.1",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = flexstar(&args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    let lin = out.join(name).join("linear");
    let json = std::fs::read_to_string(lin.join("statespace.json")).unwrap();
    (lin, serde_json::from_str(&json).unwrap())
}

/// `--modes K` and `--sliders locked|free` set the model's size and inputs; the JSON
/// names every state, input and output in the order of the matrices (outputs as the run CSVs'
/// columns: `w1tip`, not `w1_tip`); `fem-coordinates.csv` has one row per row of M.mtx, with the
/// slider coordinates last when the sliders are free and none when they are locked.
#[test]
fn linearize_settings_set_the_model_and_name_it() {
    let (_dir, cfg, out) = small_case();
    let (lin, json) = linearize_with(&cfg, "small", &out, &["--modes", "5", "--sliders", "locked"]);
    assert_eq!(mtx_size(&lin.join("A.mtx")), (10, 10));
    assert_eq!(mtx_size(&lin.join("B.mtx")), (10, 3));
    assert_eq!(mtx_size(&lin.join("C.mtx")), (6, 10));
    assert_eq!(mtx_size(&lin.join("D.mtx")), (6, 3));
    let states = names(&json, "states");
    assert_eq!(states.len(), 10);
    assert_eq!(
        (states[0].as_str(), states[4].as_str(), states[5].as_str()),
        ("eta1", "eta5", "etad1")
    );
    assert_eq!(names(&json, "inputs"), ["sdd1", "sdd2", "sdd3"]);
    assert_eq!(
        names(&json, "outputs"),
        ["w1tip", "w2tip", "w3tip", "w1G", "w2G", "w3G"]
    );
    assert_eq!(
        (json["sliders"].as_str(), json["loop"].as_str()),
        (Some("locked"), Some("open"))
    );
    let check_coordinates = |lin: &Path, sliders_free: bool| {
        let (header, rows) = rows(&lin.join("fem-coordinates.csv"));
        assert_eq!(header, "index,node,beam,dof,x_m");
        let (n, _) = mtx_size(&lin.join("M.mtx"));
        assert_eq!(rows.len(), n);
        assert_eq!(mtx_size(&lin.join("Phi_q.mtx")).1, n);
        for (k, r) in rows.iter().enumerate() {
            assert_eq!(num(&r[0]) as usize, k + 1, "1-based index = the Matrix Market row");
        }
        assert_eq!(rows[0][1..4], ["0", "", "ux"], "G first");
        let sliders: Vec<&Vec<String>> = rows.iter().filter(|r| r[3] == "slider").collect();
        if sliders_free {
            assert_eq!(sliders.len(), 3);
            assert_eq!(rows[n - 1][2..4], ["3", "slider"]);
        } else {
            assert!(sliders.is_empty());
        }
        // 102 elements: 103 nodes of 3 coordinates, then the sleeves' 12
        assert_eq!(rows.iter().filter(|r| r[3] == "theta").count(), 103);
        assert_eq!(rows.iter().filter(|r| r[3] == "psi").count(), 3);
    };
    check_coordinates(&lin, false);
    let (lin, json) = linearize_with(&cfg, "small", &out, &["--modes", "4"]);
    assert_eq!(mtx_size(&lin.join("A.mtx")), (14, 14));
    assert_eq!(names(&json, "inputs"), ["Fa1", "Fa2", "Fa3"]);
    let outputs = names(&json, "outputs");
    assert_eq!(
        outputs,
        ["s1", "s2", "s3", "w1tip", "w2tip", "w3tip", "w1G", "w2G", "w3G"]
    );
    assert!(!std::fs::read_to_string(lin.join("statespace.json"))
        .unwrap()
        .contains("w1_tip"));
    assert_eq!(names(&json, "states").len(), 14);
    check_coordinates(&lin, true);
}

/// A servo experiment: the loop is closed by default (inputs the references, their rates and the
/// feedforward forces; outputs with the tracking errors; the gains in the JSON), `--loop open`
/// gives the force-input model; `--loop closed` is refused without a servo or with locked sliders.
#[test]
fn linearize_closes_the_servo_loop_of_a_servo_experiment() {
    let dir = tempfile::tempdir().unwrap();
    let text = "name = \"servo\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"polynomial\"\n\
                s1 = [0.0, 0.0, 1.0]\ns2 = [0.0]\ns3 = [0.0, 0.0, 0.5]\n[amm]\nfamily = \"enriched\"\nmodes = 40\n[fem]\nelements = 102\n\
                [drive]\nkind = \"servo\"\nbandwidth_hz = 20.0\ndamping_ratio = 0.7\n";
    let cfg = dir.path().join("servo.toml");
    std::fs::write(&cfg, text).unwrap();
    let cfg = cfg.to_string_lossy().into_owned();
    let out = dir.path().join("out");
    let (lin, json) = linearize_with(&cfg, "servo", &out, &["--modes", "4"]);
    assert_eq!(json["loop"].as_str(), Some("closed"));
    let kp = json["servo"]["kp"].as_f64().unwrap();
    let want = 0.2 * (2.0 * std::f64::consts::PI * 20.0f64).powi(2);
    assert!((kp / want - 1.0).abs() < 1e-12, "kp {kp} vs {want}");
    assert_eq!(names(&json, "inputs").len(), 9);
    assert_eq!(names(&json, "outputs")[9..], ["e1", "e2", "e3"]);
    assert_eq!(mtx_size(&lin.join("D.mtx")), (12, 9));
    let (_, json) = linearize_with(&cfg, "servo", &out, &["--modes", "4", "--loop", "open"]);
    assert_eq!(names(&json, "inputs"), ["Fa1", "Fa2", "Fa3"]);
    let out2 = dir.path().join("out2");
    let small = small_config(dir.path());
    for (c, extra, needle) in [
        (&small, vec!["--loop", "closed"], "servo"),
        (
            &cfg,
            vec!["--loop", "closed", "--sliders", "locked"],
            "--sliders locked",
        ),
        (&cfg, vec!["--modes", "0"], "--modes"),
    ] {
        let mut args = vec!["linearize", c.as_str(), "--at", "0.1", "--out", out2.to_str().unwrap()];
        args.extend(extra);
        let o = flexstar(&args);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(files_in(&out2).is_empty(), "{args:?} wrote {:?}", files_in(&out2));
    }
}

/// Bad input: non-zero exit, the reason on stderr, no file written.
#[test]
fn bad_input_is_refused_before_any_output() {
    let (_dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["modal", &cfg, "--pose", "0.3,0,0"], "outside the workspace"),
        (vec!["modal", &cfg, "--pose", "0,0,1.2"], "outside the workspace"),
        (vec!["modal", &cfg, "--pose", "0,0"], "GX,GY,THETA"),
        (vec!["modal", &cfg, "--at", "0.6"], "span"),
        (vec!["modal", &cfg, "--at", "-0.1"], "span"),
        (vec!["modal", &cfg, "--at", "0.1", "--modes", "0"], "--modes"),
        (vec!["modal", &cfg, "--at", "0.1", "--modes", "51"], "--modes"),
        (
            vec!["modal", &cfg, "--at", "0.1", "--pose", "0,0,0"],
            "cannot be used with",
        ),
        (vec!["modal", &cfg], "required"),
        (
            vec!["freqmap", &cfg, "--gx", "0:0.1:1", "--gy", "0:0.1:3"],
            "N must be at least 2",
        ),
        (
            vec!["freqmap", &cfg, "--gx", "0:0.1:400", "--gy", "0:0.1:400"],
            "100000",
        ),
        (vec!["freqmap", &cfg, "--gx", "0.1:0:3", "--gy", "0:0.1:3"], "MIN < MAX"),
        (
            vec!["freqmap", &cfg, "--gx", "0:0.1:3", "--gy", "0:0.1:3", "--modes", "99"],
            "--modes",
        ),
        (vec!["linearize", &cfg, "--pose", "0,0.4,0"], "outside the workspace"),
        (vec!["linearize", &cfg, "--at", "7"], "span"),
    ];
    for (mut args, needle) in cases {
        args.extend(["--out", out_s]);
        let o = flexstar(&args);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        let left = files_in(&out.join("small"));
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
}

#[test]
fn the_modal_commands_have_help() {
    for sub in ["modal", "freqmap", "linearize"] {
        let o = flexstar(&[sub, "--help"]);
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains("Usage"), "{sub}");
    }
}

/// Payload, damping and load through the commands: with `[damping]` `modal.csv` gains `zeta_amm,zeta_fem` after
/// today's columns (`beta omega / 2` of each model's frequency, here zeta = 0.01 at 4 Hz), the
/// sidecar records the sections, and the payload lowers the frequencies; with `[load]` the linear
/// model's inputs end with `Fx`, `Fy`, `Mz`, B gaining three columns, and `statespace.json`
/// records the damping. A bad section is refused naming the file and key, with nothing written.
#[test]
fn payload_damping_and_load_reach_modal_and_linearize() {
    let (dir, cfg, out) = small_case();
    let out_s = out.to_str().unwrap();
    let base = std::fs::read_to_string(&cfg).unwrap();
    let attached = base.replace("name = \"small\"", "name = \"loaded\"")
        + "[payload]\nmass = 0.3\nJ = 1e-3\n[damping]\nzeta = 0.01\nf_hz = 4.0\n[load]\nFx = [0.0]\n";
    let cfg2 = dir.path().join("loaded.toml");
    std::fs::write(&cfg2, attached).unwrap();
    let cfg2 = cfg2.to_str().unwrap();
    for c in [cfg.as_str(), cfg2] {
        let o = flexstar(&["modal", c, "--pose", "0,0,0", "--modes", "3", "--out", out_s]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (h0, bare) = rows(&out.join("small").join("modal.csv"));
    let (h, damped) = rows(&out.join("loaded").join("modal.csv"));
    assert_eq!(h0, "mode,f_amm_hz,f_fem_hz,rel_diff");
    assert_eq!(h, "mode,f_amm_hz,f_fem_hz,rel_diff,zeta_amm,zeta_fem");
    for (r, r0) in damped.iter().zip(&bare) {
        let (fa, ff) = (num(&r[1]), num(&r[2]));
        assert!((num(&r[4]) - 0.01 * fa / 4.0).abs() < 1e-12, "{r:?}");
        assert!((num(&r[5]) - 0.01 * ff / 4.0).abs() < 1e-12, "{r:?}");
        assert!(fa < num(&r0[1]), "the payload lowers f: {r:?} vs {r0:?}");
    }
    let sidecar = json(&out.join("loaded").join("modal.json"));
    assert_eq!(sidecar["experiment"]["payload"]["mass"], 0.3);
    assert_eq!(sidecar["experiment"]["damping"]["zeta"], 0.01);
    assert!(sidecar["experiment"]["load"]["Fx"].is_array(), "{sidecar}");
    let (lin0, j0) = linearize_with(&cfg, "small", &out, &["--modes", "4"]);
    let (lin, j) = linearize_with(cfg2, "loaded", &out, &["--modes", "4"]);
    let inputs = names(&j, "inputs");
    assert_eq!(inputs[inputs.len() - 3..], ["Fx", "Fy", "Mz"]);
    assert_eq!(inputs.len(), names(&j0, "inputs").len() + 3);
    assert_eq!(mtx_size(&lin.join("B.mtx")).1, mtx_size(&lin0.join("B.mtx")).1 + 3);
    assert!((j["damping"]["beta_s"].as_f64().unwrap() - 0.01 / (std::f64::consts::PI * 4.0)).abs() < 1e-15);
    assert!(j0["damping"].is_null());
    // bad sections: refused before any output
    for (extra, key) in [
        ("[damping]\nbeta = 1e-3\nzeta = 0.01\n", "damping.zeta"),
        ("[payload]\nmass = -1.0\n", "payload.mass"),
        ("[load]\nfile = \"missing.csv\"\n", "load.file"),
    ] {
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, base.replace("name = \"small\"", "name = \"bad\"") + extra).unwrap();
        let o = flexstar(&["modal", bad.to_str().unwrap(), "--pose", "0,0,0", "--out", out_s]);
        assert!(!o.status.success());
        let e = stderr(&o);
        assert!(e.contains("bad.toml") && e.contains(key), "{extra}: {e}");
        assert!(files_in(&out.join("bad")).is_empty());
    }
}
