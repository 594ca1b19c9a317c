//! `[amm] frames`, `[fem] frames` and `flexstar animate` through the built binary
//! (`docs/motions.md` section 5): both solvers' frames of 0.2 s of case 3 drawn in one page with
//! no external URL; the frames' rigid points checked against `flexstar kinematics` (the rigid
//! direct kinematics, written independently of the solvers), their elastic part at G against the
//! `w_iG` of the run's own table; no frames file without `frames`; bad values refused.

use std::collections::HashMap;
use std::path::Path;

use crate::common;
use common::{flexstar, stderr};

/// Case 3 of the paper over 0.2 s, default (enriched) AMM, with `extra` appended.
fn config(dir: &Path, file: &str, amm_frames: usize, fem_frames: usize, t_end: f64) -> String {
    let case3 = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/case3.toml")).unwrap();
    let mut text = String::new();
    for line in case3.lines() {
        match line.split_whitespace().next() {
            Some("t_end") => text.push_str(&format!("t_end = {t_end}\n")),
            Some("family" | "modes" | "model") => {}
            Some("[amm]") => text.push_str(&format!("[amm]\nframes = {amm_frames}\n")),
            Some("elements") => text.push_str(&format!("{line}\nframes = {fem_frames}\n")),
            _ => text.push_str(&format!("{line}\n")),
        }
    }
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

/// A CSV file with a header, as columns by name.
fn columns(path: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut cols: HashMap<String, Vec<f64>> = header.iter().map(|h| (h.to_string(), Vec::new())).collect();
    for l in lines {
        for (h, v) in header.iter().zip(l.split(',')) {
            cols.get_mut(*h).unwrap().push(v.parse().unwrap());
        }
    }
    cols
}

/// The row of `t` in a table whose `t` column is `ts`.
fn row_of(ts: &[f64], t: f64) -> usize {
    ts.iter()
        .position(|x| (x - t).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no row at t = {t}"))
}

fn run(cfg: &str, solver: &str, out: &Path) {
    let o = flexstar(&["run", cfg, "--solver", solver, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{solver}: {}", stderr(&o));
}

/// The frames of one run against the kinematics and the run's table.
fn check_frames(dir: &Path, stem: &str, kin: &HashMap<String, Vec<f64>>, n_frames: usize) {
    let f = columns(&dir.join(format!("{stem}-frames.csv")));
    let main = columns(&dir.join(format!("{stem}.csv")));
    let pose = columns(&dir.join(format!("{stem}-frames-pose.csv")));
    assert_eq!(pose["t"].len(), n_frames, "{stem}");
    let mut worst_g = 0.0f64;
    let mut worst_dg = 0.0f64;
    let mut peak_dg = 0.0f64;
    for r in (0..f["t"].len()).filter(|&r| f["x"][r] == 0.0) {
        let t = f["t"][r];
        let k = row_of(&kin["t"], t);
        // the rigid point at x = 0 is the rigid G of the direct kinematics
        let g = [kin["Gx"][k], kin["Gy"][k]];
        worst_g = worst_g.max((f["Xr"][r] - g[0]).hypot(f["Yr"][r] - g[1]));
        let p = row_of(&pose["t"], t);
        assert!((pose["Gx"][p] - g[0]).abs() < 1e-12 && (pose["theta"][p] - kin["theta"][k]).abs() < 1e-12);
        // X - Xr at x = 0: the elastic displacement of G, |dG|^2 = 2/3 sum w_iG^2 (docs/motions.md 2.1)
        let dg2 = (f["X"][r] - f["Xr"][r]).powi(2) + (f["Y"][r] - f["Yr"][r]).powi(2);
        let m = row_of(&main["t"], t);
        let w2: f64 = ["w1G", "w2G", "w3G"].iter().map(|c| main[*c][m].powi(2)).sum();
        let want = (2.0 / 3.0 * w2).sqrt();
        worst_dg = worst_dg.max((dg2.sqrt() - want).abs());
        peak_dg = peak_dg.max(want);
    }
    eprintln!("{stem}: |Xr - G_kin| <= {worst_g:.2e} m, ||dG| - sqrt(2/3 sum w_iG^2)| <= {worst_dg:.2e} m (peak {peak_dg:.2e} m)");
    assert!(worst_g < 1e-12, "{stem}: rigid G off by {worst_g}");
    assert!(peak_dg > 1e-5, "{stem}: G hardly moves elastically ({peak_dg})");
    assert!(
        worst_dg < 1e-3 * peak_dg,
        "{stem}: |dG| off by {worst_dg} (peak {peak_dg})"
    );
}

/// The JSON data of an animate page.
fn page_data(html: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"frames-data\">";
    let start = html.find(open).expect("data element") + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end]).expect("the page's JSON parses")
}

#[test]
fn both_solvers_frames_drawn_in_one_self_contained_page() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = config(tmp.path(), "c3.toml", 100, 100, 0.2);
    let out = tmp.path().join("out");
    run(&cfg, "amm", &out);
    run(&cfg, "fem", &out);
    let o = flexstar(&["kinematics", &cfg, "--out", tmp.path().join("kin").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let kin = columns(&tmp.path().join("kin/case3/kinematics.csv"));
    let dir = out.join("case3");
    // 0, 0.01, ..., 0.2 s
    for stem in ["amm-enriched", "fem"] {
        check_frames(&dir, stem, &kin, 21);
    }
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(dir.join("animate.html")).unwrap();
    for bad in ["http://", "https://", "src=\"//", "href=\"//"] {
        assert!(!html.contains(bad), "the page holds {bad}");
    }
    let data = page_data(&html);
    let runs = data["runs"].as_array().unwrap();
    let names: Vec<&str> = runs.iter().map(|r| r["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["amm-enriched", "fem"]);
    assert_eq!(data["times"].as_array().unwrap().len(), 21);
    for r in runs {
        assert_eq!(r["rigid"].as_array().unwrap().len(), 21);
        assert_eq!(r["elastic"].as_array().unwrap().len(), 21);
    }
    // default M: the largest elastic displacement is 10 % of L = 0.5 m (rounded down, 2 digits)
    let m = data["magnify"].as_f64().unwrap();
    assert!(m > 1.0, "M = {m}");
}

#[test]
fn no_frames_without_the_key_and_bad_values_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let cfg = config(tmp.path(), "c0.toml", 0, 0, 0.05);
    run(&cfg, "amm", &out);
    let dir = out.join("case3");
    assert!(dir.join("amm-enriched.csv").exists());
    assert!(!dir.join("amm-enriched-frames.csv").exists() && !dir.join("amm-enriched-frames-pose.csv").exists());
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("[amm] frames"), "{}", stderr(&o));
    assert!(!dir.join("animate.html").exists());
    // a rate over 1000, too many frames, a fraction: refused naming file and key, nothing written
    let bad = [
        (config(tmp.path(), "b1.toml", 1001, 0, 0.05), "amm.frames"),
        (config(tmp.path(), "b2.toml", 0, 1000, 25.0), "fem.frames"),
        (config(tmp.path(), "b3.toml", 0, 0, 0.05), ""),
    ];
    for (cfg, key) in &bad[..2] {
        let o = flexstar(&[
            "run",
            cfg,
            "--solver",
            "amm",
            "--out",
            tmp.path().join("bad").to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert!(
            !o.status.success() && err.contains(key) && err.contains(".toml"),
            "{err}"
        );
        assert!(!tmp.path().join("bad/case3").exists());
    }
    let text = std::fs::read_to_string(&bad[2].0)
        .unwrap()
        .replace("frames = 0\n", "frames = 2.5\n");
    std::fs::write(&bad[2].0, text).unwrap();
    let o = flexstar(&[
        "run",
        &bad[2].0,
        "--solver",
        "fem",
        "--out",
        tmp.path().join("bad").to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(
        !o.status.success() && err.contains("frames") && err.contains("b3.toml"),
        "{err}"
    );
}

#[test]
fn runs_with_different_frame_times_are_not_overlaid() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    run(&config(tmp.path(), "a.toml", 100, 50, 0.05), "amm", &out);
    run(&config(tmp.path(), "a.toml", 100, 50, 0.05), "fem", &out);
    let dir = out.join("case3");
    let o = flexstar(&[
        "animate",
        dir.to_str().unwrap(),
        "--out",
        tmp.path().join("p.html").to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(
        !o.status.success() && err.contains("amm-enriched") && err.contains("fem"),
        "{err}"
    );
    assert!(!tmp.path().join("p.html").exists());
}

/// `compare` writes the frames its runs were asked for (`[amm] frames`, `[fem] frames`), and
/// every command replaces or removes the frames of the runs it writes: an animation never shows
/// frames of an earlier run beside a newer run's sidecar (docs/outputs.md, frames files).
#[test]
fn compare_writes_frames_and_no_command_leaves_stale_ones() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let dir = out.join("case3");
    let o = flexstar(&[
        "compare",
        &config(tmp.path(), "f.toml", 100, 100, 0.05),
        "--no-figures",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let kin_cfg = config(tmp.path(), "k.toml", 0, 0, 0.05);
    let o = flexstar(&[
        "kinematics",
        &kin_cfg,
        "--out",
        tmp.path().join("kin").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let kin = columns(&tmp.path().join("kin/case3/kinematics.csv"));
    for stem in ["amm-enriched", "fem"] {
        check_frames(&dir, stem, &kin, 6);
        let side: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(format!("{stem}.json"))).unwrap()).unwrap();
        assert!(side["frames_hash"].is_string(), "{stem}: {side}");
    }
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let data = page_data(&std::fs::read_to_string(dir.join("animate.html")).unwrap());
    let names: Vec<&str> = (data["runs"].as_array().unwrap().iter())
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["amm-enriched", "fem"]);

    // a compare without frames removes the frames of its runs that the first one left
    let o = flexstar(&[
        "compare",
        &config(tmp.path(), "n.toml", 0, 0, 0.05),
        "--no-figures",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for stem in ["amm-enriched", "fem"] {
        for f in [format!("{stem}-frames.csv"), format!("{stem}-frames-pose.csv")] {
            assert!(!dir.join(&f).exists(), "{f} left behind");
        }
    }
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(
        !o.status.success() && stderr(&o).contains("no *-frames.csv"),
        "{}",
        stderr(&o)
    );
}

/// `animate` refuses frames files that the run's sidecar does not vouch for (`frames_hash`):
/// frames of an earlier run put back beside a newer run, or a newer run's sidecar without frames.
#[test]
fn animate_refuses_frames_of_another_run_than_the_sidecar() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let dir = out.join("case3");
    run(&config(tmp.path(), "a.toml", 100, 0, 0.05), "amm", &out);
    let keep = tmp.path().join("old-frames.csv");
    std::fs::copy(dir.join("amm-enriched-frames.csv"), &keep).unwrap();
    // the same run with softer beams: new frames and sidecar
    let heavy = std::fs::read_to_string(tmp.path().join("a.toml"))
        .unwrap()
        .replace("E = 200e9", "E = 150e9");
    assert!(heavy.contains("E = 150e9"));
    std::fs::write(tmp.path().join("h.toml"), heavy).unwrap();
    run(tmp.path().join("h.toml").to_str().unwrap(), "amm", &out);
    assert!(flexstar(&["animate", dir.to_str().unwrap()]).status.success());
    std::fs::remove_file(dir.join("animate.html")).unwrap();
    // the old frames put back: refused, naming the file and the sidecar
    std::fs::copy(&keep, dir.join("amm-enriched-frames.csv")).unwrap();
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(
        !o.status.success() && err.contains("amm-enriched-frames.csv") && err.contains("amm-enriched.json"),
        "{err}"
    );
    assert!(err.contains("frames_hash"), "{err}");
    // a sidecar that records no frames (a run without them) beside frames files: refused
    let side = dir.join("amm-enriched.json");
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    doc.as_object_mut().unwrap().remove("frames_hash");
    std::fs::write(&side, doc.to_string()).unwrap();
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(
        !o.status.success() && stderr(&o).contains("earlier run"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("animate.html").exists());
}

/// Frames of two experiments with the same name (a copied file with softer beams) in one folder
/// are not overlaid: the error names both runs and both files.
#[test]
fn runs_of_different_experiments_are_not_overlaid() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    run(&config(tmp.path(), "a.toml", 100, 100, 0.05), "amm", &out);
    let soft = std::fs::read_to_string(tmp.path().join("a.toml"))
        .unwrap()
        .replace("E = 200e9", "E = 150e9");
    std::fs::write(tmp.path().join("b.toml"), soft).unwrap();
    run(tmp.path().join("b.toml").to_str().unwrap(), "fem", &out);
    let o = flexstar(&["animate", out.join("case3").to_str().unwrap()]);
    let err = stderr(&o);
    assert!(
        !o.status.success()
            && err.contains("different experiments")
            && err.contains("a.toml")
            && err.contains("b.toml"),
        "{err}"
    );
}

/// The page draws the base triangle with its sliders and the payload at G: the data it draws
/// them from are the run's (d, L and the payload from the sidecar's experiment).
#[test]
fn the_page_has_the_base_triangle_and_the_payload() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let cfg = config(tmp.path(), "p.toml", 100, 0, 0.05);
    let mut text = std::fs::read_to_string(&cfg).unwrap();
    text.push_str("\n[payload]\nmass = 0.5\nJ = 1e-4\noffset = [0.01, 0.0]\n");
    std::fs::write(&cfg, text).unwrap();
    run(&cfg, "amm", &out);
    let dir = out.join("case3");
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let data = page_data(&std::fs::read_to_string(dir.join("animate.html")).unwrap());
    assert_eq!(data["payload"]["mass"], 0.5);
    assert_eq!(data["payload"]["offset"], serde_json::json!([10_000, 0]));
    // L from the sidecar: 0.5 m; the base triangle's corners at 2 d = 0.36 m from O
    assert_eq!(data["L_um"], 500_000);
    for c in data["base"].as_array().unwrap() {
        let (x, y) = (c[0].as_f64().unwrap(), c[1].as_f64().unwrap());
        assert!((x.hypot(y) - 360_000.0).abs() <= 1.5, "{c}");
    }
    assert_eq!(data["sliders"].as_array().unwrap().len(), 6);
}

/// A robot as built drawn from its run's sidecar (the route `flexstar run` -> `flexstar animate`):
/// the corners where the drawn axes meet are the uneven base's vertices, so their distances are
/// the file's sides (`[base] sides`, `docs/as-built.md` 2), not the paper's 2 sqrt(3) d.
#[test]
fn the_page_draws_a_robot_as_built_on_its_own_base() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let cfg = config(tmp.path(), "b.toml", 50, 0, 0.05);
    let sides = [0.63, 0.6235, 0.61];
    // the base is given once: its sides instead of the paper's in-radius d
    let mut text: String = std::fs::read_to_string(&cfg)
        .unwrap()
        .lines()
        .filter(|l| l.split_whitespace().next() != Some("d"))
        .map(|l| format!("{l}\n"))
        .collect();
    text.push_str(&format!(
        "\n[base]\nsides = [{}, {}, {}]\n",
        sides[0], sides[1], sides[2]
    ));
    std::fs::write(&cfg, text).unwrap();
    run(&cfg, "amm", &out);
    let dir = out.join("case3");
    let o = flexstar(&["animate", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let data = page_data(&std::fs::read_to_string(dir.join("animate.html")).unwrap());
    let corners: Vec<(f64, f64)> = data["base"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c[0].as_f64().unwrap(), c[1].as_f64().unwrap()))
        .collect();
    assert_eq!(corners.len(), 3);
    let mut drawn: Vec<f64> = (0..3)
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % 3]);
            (a.0 - b.0).hypot(a.1 - b.1) * 1e-6
        })
        .collect();
    drawn.sort_by(f64::total_cmp);
    let mut want = sides.to_vec();
    want.sort_by(f64::total_cmp);
    for (d, w) in drawn.iter().zip(&want) {
        // the page's coordinates are whole micrometres
        assert!((d - w).abs() <= 3e-6, "drawn sides {drawn:?}, file's {want:?}");
    }
}
