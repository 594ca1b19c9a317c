//! Residual vibration and settling after a rest-to-rest motion through the built binary
//! (`docs/motions.md` section 2): the AMM's new `dGx, dGy` columns against the FEM's,
//! which the FEM computes independently (`G_fem - G_rigid`, not from the projections `w_iG`); the
//! sidecar's settling time against the last excursion of the FEM's own |dG| read from its CSV; a
//! damped run settles, the same run undamped does not; a band above the peak settles at
//! `t_rest`; a bad band is refused before anything is written; `compare` writes `residual.csv`.

use std::path::Path;

use crate::common;
use common::{flexstar, stderr};

/// The brisk quintic (rest at 0.2 s) over 1.5 s, with extra TOML appended.
fn write_config(dir: &Path, name: &str, extra: &str) -> String {
    let brisk = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions/brisk.toml");
    let text = std::fs::read_to_string(brisk).unwrap();
    let text = text
        .replace("name = \"brisk\"", &format!("name = \"{name}\""))
        .replace("t_end = 0.4", "t_end = 1.5");
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{text}\n{extra}\n")).unwrap();
    path.to_string_lossy().into_owned()
}

fn run(cfg: &str, solver: &str, out: &Path) {
    let o = flexstar(&["run", cfg, "--solver", solver, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{cfg} {solver}: {}", stderr(&o));
}

fn sidecar(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Columns `t`, `dGx`, `dGy` of a run's CSV.
fn dg_columns(path: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (t, x, y) = (at("t"), at("dGx"), at("dGy"));
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
            [v[t], v[x], v[y]]
        })
        .collect()
}

#[test]
fn the_amm_writes_the_elastic_displacement_of_g_as_the_fem_does() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), "resid", "");
    run(&cfg, "amm", dir.path());
    run(&cfg, "fem", dir.path());
    let amm = dg_columns(&dir.path().join("resid/amm-enriched.csv"));
    let fem = dg_columns(&dir.path().join("resid/fem.csv"));
    assert_eq!(amm.len(), fem.len());
    let peak = fem.iter().map(|r| r[1].hypot(r[2])).fold(0.0, f64::max);
    let worst = amm
        .iter()
        .zip(&fem)
        .map(|(a, f)| (a[1] - f[1]).hypot(a[2] - f[2]))
        .fold(0.0, f64::max);
    // the accurate AMM is within 0.2-0.5 % of the FEM on this motion (docs/validation.md);
    // allow 3 % of the peak pointwise
    assert!(peak > 1e-4 && worst < 0.03 * peak, "worst {worst:e} of peak {peak:e}");
    // undamped: the residual never falls below the band for a period, so it is not settled
    for file in ["amm-enriched.json", "fem.json"] {
        let doc = sidecar(&dir.path().join("resid").join(file));
        assert_eq!(doc["t_rest"], 0.2, "{file}");
        assert_eq!(doc["settled"], false, "{file}");
        assert!(doc["settle_s"].is_null(), "{file}");
        let g_peak = doc["residual_G_peak_m"].as_f64().unwrap();
        // the FEM's own |dG| after t_rest, from its CSV
        let fem_peak = fem
            .iter()
            .filter(|r| r[0] >= 0.2)
            .map(|r| r[1].hypot(r[2]))
            .fold(0.0, f64::max);
        assert!(
            (g_peak - fem_peak).abs() < 0.03 * fem_peak,
            "{file}: {g_peak} vs {fem_peak}"
        );
    }
}

#[test]
fn a_damped_run_settles_where_the_fem_csv_says_and_both_solvers_agree() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), "damped", "[damping]\nzeta = 0.05\nf_hz = 3.95");
    run(&cfg, "amm", dir.path());
    run(&cfg, "fem", dir.path());
    let fem_doc = sidecar(&dir.path().join("damped/fem.json"));
    let amm_doc = sidecar(&dir.path().join("damped/amm-enriched.json"));
    assert_eq!(fem_doc["settled"], true);
    let settle = fem_doc["settle_s"].as_f64().unwrap();
    // the last output time after t_rest with |dG| > 1e-4 m, read from the FEM's own dG columns
    let fem = dg_columns(&dir.path().join("damped/fem.csv"));
    let last = fem
        .iter()
        .filter(|r| r[0] >= 0.2 && r[1].hypot(r[2]) > 1e-4)
        .map(|r| r[0])
        .fold(0.2, f64::max);
    assert!((settle - last).abs() < 1.5e-3, "{settle} vs {last}");
    // the decay of the first mode alone bounds it from above: exp(-zeta w1 tau) from the peak
    let peak = fem_doc["residual_G_peak_m"].as_f64().unwrap();
    let bound = 0.2 + (peak / 1e-4).ln() / (0.05 * 2.0 * std::f64::consts::PI * 3.95);
    assert!(settle > 0.2 && settle < bound + 0.05, "{settle} vs bound {bound}");
    let amm_settle = amm_doc["settle_s"].as_f64().unwrap();
    assert!((amm_settle - settle).abs() < 0.02, "AMM {amm_settle} vs FEM {settle}");
    // the hold is one period of the first mode at the final pose (about 3.95 Hz there)
    let hold = fem_doc["settle_hold_s"].as_f64().unwrap();
    assert!((1.0 / hold - 3.95).abs() < 0.1, "{hold}");
}

#[test]
fn a_band_above_the_peak_settles_at_t_rest_and_a_bad_band_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), "wide", "[report]\nsettle_tol = 0.01");
    run(&cfg, "amm", dir.path());
    let doc = sidecar(&dir.path().join("wide/amm-enriched.json"));
    assert_eq!(doc["settle_s"], 0.2);
    assert_eq!(doc["settle_tol"], 0.01);
    for (name, extra, why) in [
        ("neg", "[report]\nsettle_tol = -1e-4", "report.settle_tol"),
        ("unknown", "[report]\nsettle = 1e-4", "settle"),
    ] {
        let cfg = write_config(dir.path(), name, extra);
        let o = flexstar(&["run", &cfg, "--solver", "amm", "--out", dir.path().to_str().unwrap()]);
        assert!(!o.status.success(), "{name}");
        let e = stderr(&o);
        assert!(e.contains(why) && e.contains(&format!("{name}.toml")), "{name}: {e}");
        assert!(!dir.path().join(name).exists(), "{name}: something was written");
    }
}

#[test]
fn compare_writes_the_residual_table_and_marks_t_rest() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), "cmp", "");
    let o = flexstar(&["compare", &cfg, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.path().join("cmp/residual.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "run,t_rest,residual_G_peak_m,residual_G_rms_m,residual_tip_peak_m,residual_tip_rms_m,settle_s"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2, "{text}");
    assert!(rows[0].starts_with("fem,") && rows[1].starts_with("amm-enriched,"));
    let md = std::fs::read_to_string(dir.path().join("cmp/compare.md")).unwrap();
    assert!(md.contains("Residual vibration after the motion") && md.contains("not settled by t_end"));
    let html = std::fs::read_to_string(dir.path().join("cmp/report.html")).unwrap();
    assert!(html.contains("residual.csv") && html.contains("t_rest"));
    let svg = std::fs::read_to_string(dir.path().join("cmp/figures/cmp-wG.svg")).unwrap();
    assert!(svg.contains("t_rest"), "the t_rest mark is not named in the legend");
}

// ---- per dwell (docs/motions.md 2.5) ----

/// The pick-and-place cycle of `configs/motions/pick-place.toml` (out in 0.4 s, a dwell to 0.7 s,
/// back by 1.1 s) over `t_end`, or its first move alone (`first_only`), with a fixed N so that the
/// AMM's basis does not depend on the span.
fn pick_place(dir: &Path, name: &str, t_end: f64, first_only: bool) -> String {
    let back = if first_only {
        ""
    } else {
        "  { t = 0.7, Gx = 0.03, Gy = -0.02, theta = 0.2 },\n  { t = 1.1, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n"
    };
    let text = format!(
        "name = \"{name}\"\n[time]\nt_end = {t_end}\ndt_out = 0.001\n[trajectory]\nkind = \"via\"\nrest = true\n\
         points = [\n  {{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }},\n  {{ t = 0.4, Gx = 0.03, Gy = -0.02, theta = 0.2 }},\n\
         {back}]\n[amm]\nmodes = 6\n[fem]\nelements = 120\n"
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

fn dwells_of(doc: &serde_json::Value) -> Vec<serde_json::Value> {
    doc["dwells"].as_array().expect("a dwells list").clone()
}

/// `a` and `b` equal to 1e-12 relative, or both null.
fn same(a: &serde_json::Value, b: &serde_json::Value, what: &str) {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-12 * x.abs().max(y.abs()), "{what}: {x} vs {y}"),
        _ => assert!(a.is_null() && b.is_null(), "{what}: {a} vs {b}"),
    }
}

/// A single move lists one dwell whose window and values are the single residual keys', which
/// `flexstar_metrics::residual::residual_after` computes by its own code; the CSV holds the same.
#[test]
fn a_single_move_lists_one_dwell_equal_to_the_residual_keys() {
    let dir = tempfile::tempdir().unwrap();
    // damped, so that it settles and settle_s is a time
    let cfg = write_config(dir.path(), "single", "[damping]\nzeta = 0.05\nf_hz = 3.95");
    run(&cfg, "amm", dir.path());
    let doc = sidecar(&dir.path().join("single/amm-enriched.json"));
    let d = dwells_of(&doc);
    assert_eq!(d.len(), 1);
    let d = &d[0];
    assert_eq!(d["dwell"], 1);
    let t = |v: &serde_json::Value| v.as_f64().unwrap();
    let t_rest = t(&doc["t_rest"]);
    assert_eq!(
        (t(&d["move_start"]), t(&d["move_end"]), t(&d["t_start"])),
        (0.0, t_rest, t_rest)
    );
    assert_eq!(t(&d["t_end"]), 1.5);
    for (mine, single) in [
        ("G_peak_m", "residual_G_peak_m"),
        ("G_rms_m", "residual_G_rms_m"),
        ("tip_peak_m", "residual_tip_peak_m"),
        ("tip_rms_m", "residual_tip_rms_m"),
        ("settle_s", "settle_s"),
        ("settle_hold_s", "settle_hold_s"),
    ] {
        same(&d[mine], &doc[single], mine);
    }
    assert_eq!(doc["settled"], true);
    assert_eq!(d["settled"], doc["settled"]);
    assert!(d["note"].is_null());
    // the CSV: the documented header and the same numbers
    let (header, rows) = {
        let text = std::fs::read_to_string(dir.path().join("single/amm-enriched-dwells.csv")).unwrap();
        let mut lines = text.lines().map(str::to_string).collect::<Vec<_>>().into_iter();
        let header = lines.next().unwrap();
        (header, lines.collect::<Vec<_>>())
    };
    assert_eq!(
        header,
        "dwell,move_start,move_end,t_start,t_end,G_peak_m,G_rms_m,tip_peak_m,tip_rms_m,settle_s,settled,settle_hold_s,note"
    );
    assert_eq!(rows.len(), 1);
    let cells: Vec<&str> = rows[0].split(',').collect();
    assert_eq!(
        cells[5].parse::<f64>().unwrap(),
        doc["residual_G_peak_m"].as_f64().unwrap()
    );
    assert_eq!(cells[9].parse::<f64>().unwrap(), doc["settle_s"].as_f64().unwrap());
    assert_eq!(cells[10], "true");
}

/// The first dwell of the cycle against a second characterisation: a run of the first move alone,
/// the same solver and settings, stopped where the dwell ends (`t_end` = 0.7 s): its single
/// residual (after `t_rest` = 0.4 s, on its own final pose's hold) is the cycle's first dwell.
#[test]
fn the_first_dwell_of_a_cycle_is_the_residual_of_its_first_move_run_alone() {
    let dir = tempfile::tempdir().unwrap();
    let cycle = pick_place(dir.path(), "cycle", 1.5, false);
    let first = pick_place(dir.path(), "first", 0.7, true);
    for (solver, stem) in [("amm", "amm-enriched"), ("fem", "fem")] {
        run(&cycle, solver, dir.path());
        run(&first, solver, dir.path());
        let whole = sidecar(&dir.path().join(format!("cycle/{stem}.json")));
        let alone = sidecar(&dir.path().join(format!("first/{stem}.json")));
        let d = dwells_of(&whole);
        assert_eq!(d.len(), 2, "{solver}");
        assert_eq!(
            (d[0]["t_start"].as_f64(), d[0]["t_end"].as_f64()),
            (Some(0.4), Some(0.7))
        );
        assert_eq!(
            (d[1]["move_start"].as_f64(), d[1]["t_start"].as_f64()),
            (Some(0.7), Some(1.1))
        );
        assert_eq!(alone["t_rest"], 0.4);
        for (mine, single) in [
            ("G_peak_m", "residual_G_peak_m"),
            ("G_rms_m", "residual_G_rms_m"),
            ("tip_peak_m", "residual_tip_peak_m"),
            ("tip_rms_m", "residual_tip_rms_m"),
            ("settle_s", "settle_s"),
            ("settle_hold_s", "settle_hold_s"),
        ] {
            same(&d[0][mine], &alone[single], &format!("{solver} {mine}"));
        }
        assert_eq!(d[0]["settled"], alone["settled"], "{solver}");
        assert!(
            d[0]["G_peak_m"].as_f64().unwrap() > 1e-5,
            "{solver}: a residual to compare"
        );
        // the last dwell is the cycle's single residual
        same(&d[1]["G_peak_m"], &whole["residual_G_peak_m"], "last dwell");
        // the first dwell's pose is another than the final one: another hold
        let (h1, h2) = (
            d[0]["settle_hold_s"].as_f64().unwrap(),
            d[1]["settle_hold_s"].as_f64().unwrap(),
        );
        assert!((h1 - h2).abs() > 1e-6, "{h1} {h2}");
    }
}

fn is_png(path: &Path) -> bool {
    let bytes = std::fs::read(path).unwrap_or_default();
    // signature, then the IHDR chunk with a non-zero width and height
    bytes.len() > 33
        && bytes.starts_with(b"\x89PNG\r\n\x1a\n")
        && &bytes[12..16] == b"IHDR"
        && u32::from_be_bytes(bytes[16..20].try_into().unwrap()) > 0
        && u32::from_be_bytes(bytes[20..24].try_into().unwrap()) > 0
}

fn svg_text(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        text.contains("<svg") && text.trim_end().ends_with("</svg>"),
        "{}: not a whole SVG document",
        path.display()
    );
    text
}

/// `flexstar run --figures` of the cycle: a line per dwell, the dwells file, the |dG| figure with
/// the band and a zoom row per move and dwell, the tips and forces zoomed the same way.
#[test]
fn a_cycle_prints_each_dwell_and_draws_its_moves_and_dwells() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = pick_place(dir.path(), "drawn", 1.5, false);
    let o = flexstar(&[
        "run",
        &cfg,
        "--solver",
        "amm",
        "--figures",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("drawn: dwell 1, 0.4-0.7 s (after the move from 0 s): peak |dG| = "),
        "{e}"
    );
    assert!(
        e.contains("drawn: dwell 2, 1.1-1.5 s (after the move from 0.7 s)"),
        "{e}"
    );
    let case = dir.path().join("drawn");
    let text = std::fs::read_to_string(case.join("amm-enriched-dwells.csv")).unwrap();
    assert_eq!(text.lines().count(), 3, "{text}");
    let figs = case.join("figures");
    let dg = svg_text(&figs.join("amm-enriched-dG.svg"));
    assert!(is_png(&figs.join("amm-enriched-dG.png")));
    for title in [
        "move 1 and its dwell, 0-0.7 s",
        "move 2 and its dwell, 0.7-1.5 s",
        "band settle_tol = 0.1 mm",
    ] {
        assert!(dg.contains(title), "no {title} in the dG figure");
    }
    for kind in ["tips", "forces"] {
        let svg = svg_text(&figs.join(format!("amm-enriched-{kind}.svg")));
        assert!(svg.contains("move 2 and its dwell, 0.7-1.5 s"), "{kind}");
        assert!(is_png(&figs.join(format!("amm-enriched-{kind}.png"))), "{kind}");
    }
}

/// `compare` of the cycle: every run's dwells file and sidecar list, the per-dwell table in
/// `compare.md` and `report.html`, the |dG| figure with both runs' settling marks named.
#[test]
fn compare_reports_each_dwell_of_every_run() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = pick_place(dir.path(), "cmpdwell", 1.5, false);
    let o = flexstar(&["compare", &cfg, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = dir.path().join("cmpdwell");
    for stem in ["fem", "amm-enriched"] {
        let doc = sidecar(&case.join(format!("{stem}.json")));
        assert_eq!(dwells_of(&doc).len(), 2, "{stem}");
        assert!(case.join(format!("{stem}-dwells.csv")).exists(), "{stem}");
    }
    let md = std::fs::read_to_string(case.join("compare.md")).unwrap();
    assert!(md.contains("## Residual vibration per dwell"), "{md}");
    assert!(
        md.contains("| fem | 1 | 0-0.4 | 0.4-0.7 |") && md.contains("| amm-enriched | 2 | 0.7-1.1 | 1.1-1.5 |"),
        "{md}"
    );
    let html = std::fs::read_to_string(case.join("report.html")).unwrap();
    assert!(html.contains("Residual vibration per dwell"));
    let dg = svg_text(&case.join("figures/cmpdwell-dG.svg"));
    assert!(dg.contains("move 1 and its dwell") && dg.contains("end of a move"));
    assert!(is_png(&case.join("figures/cmpdwell-dG.png")));
}

/// A dwell shorter than the output step is listed with a note, not measured, and the run goes on.
#[test]
fn a_dwell_shorter_than_the_output_step_is_reported_not_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blink.toml");
    std::fs::write(
        &path,
        "name = \"blink\"\n[time]\nt_end = 0.8\ndt_out = 0.001\n[trajectory]\nkind = \"via\"\nrest = true\npoints = [\n\
         { t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n{ t = 0.2, Gx = 0.01, Gy = 0.0, theta = 0.0 },\n\
         { t = 0.2005, Gx = 0.01, Gy = 0.0, theta = 0.0 },\n{ t = 0.4, Gx = 0.0, Gy = 0.0, theta = 0.0 },\n]\n",
    )
    .unwrap();
    let o = flexstar(&[
        "run",
        path.to_str().unwrap(),
        "--solver",
        "amm",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("blink: dwell 1, 0.2-0.2005 s (after the move from 0 s): the dwell lasts 0.0005 s, less than the output step 0.001 s"), "{e}");
    let doc = sidecar(&dir.path().join("blink/amm-enriched.json"));
    let d = dwells_of(&doc);
    assert_eq!(d.len(), 2);
    assert!(d[0]["G_peak_m"].is_null() && d[0]["settled"].is_null());
    assert!(d[1]["G_peak_m"].as_f64().unwrap() > 0.0);
}
