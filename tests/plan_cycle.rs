//! `flexstar plan` of a whole cycle through the built binary (`docs/motions.md` 4.12). The
//! planner trusts the accurate AMM; the cycle is judged here by the FEM, an independent model:
//! the residual of G in each dwell is computed from the FEM's own CSV columns
//! (`|dG| = sqrt(2/3 sum w_iG^2)` over the dwell's samples), not by the command's dwell code.

use std::path::{Path, PathBuf};

use crate::common;
use common::{col, flexstar, stderr, table};

/// Peak of `|dG|` [m] over `t_from <= t <= t_to` of a run CSV.
fn peak_between(csv: &Path, t_from: f64, t_to: f64) -> f64 {
    let (h, rows) = table(csv);
    let (t, w) = (col(&h, "t"), [col(&h, "w1G"), col(&h, "w2G"), col(&h, "w3G")]);
    rows.iter()
        .filter(|r| r[t] >= t_from - 1e-9 && r[t] <= t_to + 1e-9)
        .map(|r| (2.0 / 3.0 * w.iter().map(|&c| r[c] * r[c]).sum::<f64>()).sqrt())
        .fold(0.0, f64::max)
}

/// `flexstar plan cfg --out out`, asserting success; the plan folder `out/<name>`.
fn plan(cfg: &Path, out: &Path, name: &str) -> PathBuf {
    let o = flexstar(&["plan", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    out.join(name)
}

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions")
}

/// The pick-and-place cycle: in each dwell the planned cycle's FEM residual peak of G is at most
/// 1/20 of the plain quintic cycle's at the same timing (the target of 4.12), and the command's
/// per-dwell table of the planned FEM run says the same as the CSV.
#[test]
fn a_planned_cycle_leaves_a_twentieth_of_the_plain_residual_in_each_dwell_on_the_fem() {
    let out = tempfile::tempdir().unwrap();
    let dir = plan(&configs().join("plan-pick-place.toml"), out.path(), "plan-pick-place");
    // dwell windows of C1: [0.4, 0.7] and [1.1, 1.5]
    for (t0, t1) in [(0.4, 0.7), (1.1, 1.5)] {
        let plain = peak_between(&dir.join("plain/fem.csv"), t0, t1);
        let planned = peak_between(&dir.join("planned/fem.csv"), t0, t1);
        eprintln!(
            "dwell [{t0}, {t1}]: FEM peak plain {plain:.4e} m, planned {planned:.4e} m, ratio {:.4}",
            planned / plain
        );
        assert!(plain > 1e-4, "the plain cycle must shake: {plain}");
        assert!(planned <= plain / 20.0, "dwell [{t0}, {t1}]: {planned} > {plain} / 20");
    }
    // the command's table (text cells too: settled, note) against the CSV
    let text = std::fs::read_to_string(dir.join("planned/fem-dwells.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let peak = header.iter().position(|h| *h == "G_peak_m").unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2, "one row per dwell");
    for (row, (t0, t1)) in rows.iter().zip([(0.4, 0.7), (1.1, 1.5)]) {
        let listed: f64 = row[peak].parse().unwrap();
        let from_csv = peak_between(&dir.join("planned/fem.csv"), t0, t1);
        assert!((listed - from_csv).abs() <= 1e-9 * from_csv, "{listed} vs {from_csv}");
    }
    let md = std::fs::read_to_string(dir.join("plan.md")).unwrap();
    assert!(md.contains("per dwell"), "{md}");
}

/// A cycle of one move is the single-move plan of its two points: the same `plan.csv` rows.
#[test]
fn a_cycle_of_one_move_is_the_single_move_plan() {
    let out = tempfile::tempdir().unwrap();
    let head = "[time]\nt_end = 1.5\ndt_out = 0.001\n[plan]\nt_move = 0.4\nbudget_s = 60\n";
    let single = out.path().join("single.toml");
    std::fs::write(
        &single,
        format!("name = \"single\"\n{head}from = {{ Gx = 0.0, Gy = 0.0, theta = 0.0 }}\nto = {{ Gx = 0.03, Gy = -0.02, theta = 0.2 }}\n"),
    )
    .unwrap();
    let cycle = out.path().join("cycle.toml");
    std::fs::write(
        &cycle,
        format!(
            "name = \"cycle\"\n{head}points = [{{ Gx = 0.0, Gy = 0.0, theta = 0.0 }}, {{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = 1.1 }}]\n"
        ),
    )
    .unwrap();
    let a = table(&plan(&single, &out.path().join("o"), "single").join("plan.csv"));
    let b = table(&plan(&cycle, &out.path().join("o"), "cycle").join("plan.csv"));
    assert_eq!(a.0, b.0);
    assert_eq!(a.1.len(), b.1.len());
    for (ra, rb) in a.1.iter().zip(&b.1) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{ra:?} vs {rb:?}");
        }
    }
}

/// Bad cycles are refused before any work, naming the file and the key; nothing is written.
#[test]
fn bad_cycles_are_refused_with_the_key_and_nothing_is_written() {
    let out = tempfile::tempdir().unwrap();
    let head = "name = \"bad\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n[plan]\nt_move = 0.4\n";
    let p0 = "{ Gx = 0.0, Gy = 0.0, theta = 0.0 }";
    let p1 = "{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = 0.3 }";
    let back = "{ Gx = 0.0, Gy = 0.0, theta = 0.0, dwell = 0.4 }";
    let cases = [
        (format!("points = [{p0}]\n"), "at least two points"),
        (format!("points = [{p0}, {p1}]\nfrom = {p0}\n"), "plan.points"),
        (
            format!("points = [{p0}, {{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = 0.0 }}]\n"),
            "plan.points[1].dwell",
        ),
        (
            format!("points = [{p0}, {{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = -0.1 }}]\n"),
            "plan.points[1].dwell",
        ),
        (
            format!("points = [{p0}, {{ Gx = 0.03, Gy = -0.02, theta = 0.2 }}]\n"),
            "plan.points[1].dwell",
        ),
        (
            format!("points = [{{ Gx = 0.0, Gy = 0.0, theta = 0.0, dwell = 0.2 }}, {p1}]\n"),
            "plan.points[0]",
        ),
        (
            format!("points = [{p0}, {p1}, {{ Gx = 0.5, Gy = 0.0, theta = 0.0, dwell = 0.1 }}]\n"),
            "plan.points[2]",
        ),
        (
            format!("points = [{p0}, {p1}, {{ Gx = 0.0, Gy = 0.0, theta = 0.0, dwell = 0.5 }}]\n"),
            "time.t_end",
        ),
        (
            format!("points = [{p0}, {p1}, {{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = 0.1 }}]\n"),
            "plan.points[2]",
        ),
        (
            format!("points = [{p0}, {p1}, {back}]\nobjective = \"time\"\n"),
            "plan.objective",
        ),
        (
            format!("points = [{p0}, {p1}, {back}]\n[robust]\n\"payload.mass\" = [0.0, 0.5]\n"),
            "robust",
        ),
    ];
    for (body, needle) in cases {
        let cfg = out.path().join("bad.toml");
        std::fs::write(&cfg, format!("{head}{body}")).unwrap();
        let o = flexstar(&[
            "plan",
            cfg.to_str().unwrap(),
            "--out",
            out.path().join("o").to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert!(!o.status.success(), "accepted: {body}");
        assert!(err.contains("bad.toml") && err.contains(needle), "{needle}: {err}");
        let written = out.path().join("o/bad");
        let files = std::fs::read_dir(&written).map(|d| d.count()).unwrap_or(0);
        assert_eq!(files, 0, "{needle}: files written in {}", written.display());
    }
}
