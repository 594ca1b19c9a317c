//! `flexstar plan` through the built binary (`docs/motions.md` sections
//! 4 and 6). The planner trusts the accurate AMM; these tests judge its motions by the FEM, an
//! independent model: the residual of G is computed here from the FEM's own CSV columns
//! (`|dG| = sqrt(2/3 sum w_iG^2)` after `t_rest`), the limits from `flexstar kinematics` of the
//! written `plan.toml`, the reproduction from a fresh `flexstar run` of it.

use std::path::{Path, PathBuf};

use crate::common;
use common::{col, flexstar, stderr, table};

/// Peak of `|dG|` [m] at `t >= t_from` of a run CSV.
fn residual_peak(csv: &Path, t_from: f64) -> f64 {
    let (h, rows) = table(csv);
    let (t, w) = (col(&h, "t"), [col(&h, "w1G"), col(&h, "w2G"), col(&h, "w3G")]);
    rows.iter()
        .filter(|r| r[t] >= t_from - 1e-9)
        .map(|r| (2.0 / 3.0 * w.iter().map(|&c| r[c] * r[c]).sum::<f64>()).sqrt())
        .fold(0.0, f64::max)
}

/// A sidecar's JSON.
fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `flexstar plan cfg --out out`, asserting success; the plan folder.
fn plan(cfg: &Path, out: &Path) -> PathBuf {
    plan_with_stderr(cfg, out).0
}

/// [`plan`], with what the command printed on stderr.
fn plan_with_stderr(cfg: &Path, out: &Path) -> (PathBuf, String) {
    let o = flexstar(&["plan", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let name = std::fs::read_to_string(cfg).unwrap();
    let name = name
        .lines()
        .find_map(|l| l.strip_prefix("name = \""))
        .and_then(|l| l.strip_suffix('"'))
        .unwrap()
        .to_string();
    (out.join(name), stderr(&o))
}

/// A target move's plan file with `lines` added to its `[plan]` (the last section), written
/// into `dir`.
fn variant(dir: &Path, name: &str, lines: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions");
    let text = std::fs::read_to_string(root.join(format!("{name}.toml"))).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{text}\n{lines}\n")).unwrap();
    path
}

/// Peak `|s_i''|` [m/s^2] over `t <= t_rest` of `flexstar kinematics` of `cfg`, and the peak
/// `|s_i'''|` [m/s^3] as one-sided differences of those accelerations: at the `dt_out` = 1 ms
/// grid these underestimate the quintic's jerk jump at its ends by about `3 h / T` (0.6-0.7 %
/// on the three moves: the difference quotient over the first step averages `60 - 180 tau`).
fn kinematic_peaks(cfg: &Path, out: &Path, name: &str, t_rest: f64) -> (f64, f64) {
    let o = flexstar(&["kinematics", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = table(&out.join(name).join("kinematics.csv"));
    let (t, acc) = (col(&h, "t"), ["sdd1", "sdd2", "sdd3"].map(|c| col(&h, c)));
    let rows: Vec<&Vec<f64>> = rows.iter().filter(|r| r[t] <= t_rest + 1e-9).collect();
    let a = rows.iter().flat_map(|r| acc.map(|c| r[c].abs())).fold(0.0, f64::max);
    let j = rows
        .windows(2)
        .flat_map(|w| acc.map(|c| ((w[1][c] - w[0][c]) / (w[1][t] - w[0][t])).abs()))
        .fold(0.0, f64::max);
    (a, j)
}

/// Peak `|Fa_i|` [N] over a run CSV.
fn force_peak(csv: &Path) -> f64 {
    let (h, rows) = table(csv);
    let fa = ["Fa1", "Fa2", "Fa3"].map(|c| col(&h, c));
    rows.iter().flat_map(|r| fa.map(|c| r[c].abs())).fold(0.0, f64::max)
}

/// The FEM residual peaks of the three motions (plain, ZVD, planned) and their `t_rest`.
fn fem_peaks(dir: &Path) -> [(f64, f64); 3] {
    ["plain", "zvd", "planned"].map(|m| {
        let t_rest = json(&dir.join(m).join("fem.json"))["t_rest"].as_f64().unwrap();
        (residual_peak(&dir.join(m).join("fem.csv"), t_rest), t_rest)
    })
}

/// Item 6, second target, on the three target moves with the smoothness of docs/motions.md 4.10
/// lifted (`peak_factor = "off"`, `monotone = false`: the plans of 4.9, as violent as they need
/// to be): the planned motion's FEM residual peak of G is at most 1/20 of the plain quintic's of
/// the same `t_move`, and the AMM agrees with the FEM on it within 10 %.
#[test]
fn planned_moves_leave_a_twentieth_of_the_plain_residual_on_the_fem() {
    let out = tempfile::tempdir().unwrap();
    for name in ["plan-centre", "plan-edge", "plan-turn"] {
        let dir = plan(
            &variant(out.path(), name, "peak_factor = \"off\"\nmonotone = false"),
            out.path(),
        );
        let [(plain, t_plain), _, (planned, t_planned)] = fem_peaks(&dir);
        assert!((t_plain - t_planned).abs() < 1e-12, "{name}: same t_move");
        assert!(
            planned <= plain / 20.0,
            "{name}: planned {planned:.3e} m vs plain {plain:.3e} m"
        );
        let amm = residual_peak(&dir.join("planned/amm-enriched.csv"), t_planned);
        assert!(
            (amm - planned).abs() <= 0.1 * planned,
            "{name}: AMM {amm:.3e} m vs FEM {planned:.3e} m"
        );
    }
}

/// The default plan is smooth (docs/motions.md 4.10), judged outside the planner: its peak
/// `|s''|` and `|s'''|` from `flexstar kinematics` of the written `plan.toml` (the table spline)
/// at most 1.5 times those of `flexstar kinematics` of the plain quintic written here; its peak
/// force on the FEM (an independent model; the planner bounds the AMM's) at most 1.5 times the
/// plain quintic's FEM force, with 0.5 % for the models' difference; the progress along the
/// chord, from `plan.csv`'s poses, never decreasing; a warning on stderr and in `plan.json`
/// whenever a peak exceeds the quintic's; the FEM residual at most 1/20 of the plain quintic's
/// (measured 2.3-2.8 %, 4.10 "The default shape"), and the AMM within 10 % of the FEM on it.
#[test]
fn default_plans_keep_the_quintic_peaks_and_move_forward() {
    let out = tempfile::tempdir().unwrap();
    let moves = [
        ("plan-centre", [0.0, 0.0, 0.0], [0.03, -0.02, 0.2], 0.42, 1.5),
        ("plan-edge", [0.0, 0.0, 0.0], [0.2, -0.11, 0.0], 0.66, 2.0),
        ("plan-turn", [0.12, 0.07, -0.05], [0.12, 0.07, 0.2], 0.5, 1.6),
    ];
    for (name, from, to, t_move, t_end) in moves {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions");
        let (dir, err) = plan_with_stderr(&root.join(format!("{name}.toml")), out.path());
        let quintic = out.path().join(format!("{name}-quintic.toml"));
        let pose = |p: [f64; 3]| format!("{{ Gx = {:?}, Gy = {:?}, theta = {:?} }}", p[0], p[1], p[2]);
        std::fs::write(
            &quintic,
            format!(
                "name = \"{name}-quintic\"\n[time]\nt_end = {t_end:?}\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
                 from = {}\nto = {}\nt0 = 0.0\nt1 = {t_move:?}\n",
                pose(from),
                pose(to)
            ),
        )
        .unwrap();
        let kin = out.path().join("kin");
        let (a_q, j_q) = kinematic_peaks(&quintic, &kin, &format!("{name}-quintic"), t_move);
        let (a_p, j_p) = kinematic_peaks(&dir.join("plan.toml"), &kin, name, t_move);
        assert!(a_p <= 1.5 * a_q * (1.0 + 1e-3), "{name}: |s''| {a_p} vs quintic {a_q}");
        assert!(j_p <= 1.5 * j_q * 1.02, "{name}: |s'''| {j_p} vs quintic {j_q}");
        let (f_q, f_p) = (
            force_peak(&dir.join("plain/fem.csv")),
            force_peak(&dir.join("planned/fem.csv")),
        );
        assert!(f_p <= 1.5 * f_q * 1.005, "{name}: FEM |Fa| {f_p} vs quintic {f_q}");
        let (h, rows) = table(&dir.join("plan.csv"));
        let q = ["Gx", "Gy", "theta"].map(|c| col(&h, c));
        // the progress of docs/motions.md 4.10: the projection on the chord in task coordinates
        // scaled by the move's extent (at least 10 mm, 10 mm, 0.05 rad where one does not move)
        let scale = [0.01, 0.01, 0.05];
        let d: Vec<f64> = (0..3)
            .map(|k| (to[k] - from[k]) / (to[k] - from[k]).abs().max(scale[k]).powi(2))
            .collect();
        let dd: f64 = (0..3).map(|k| d[k] * (to[k] - from[k])).sum();
        let progress: Vec<f64> = rows
            .iter()
            .map(|r| (0..3).map(|k| (r[q[k]] - from[k]) * d[k]).sum::<f64>() / dd)
            .collect();
        assert!(
            progress.windows(2).all(|w| w[1] >= w[0] - 1e-12),
            "{name}: progress goes backwards"
        );
        let record = json(&dir.join("plan.json"));
        let warnings = record["warnings"].as_array().unwrap().len();
        // the bare robot's Jacobians come from the tangent-linear AMM (docs/motions.md 4.9, "The
        // Jacobian from the tangent"): every Jacobian of the search, 12 columns each
        let columns = record["planner"]["tangent_directions"].as_u64().unwrap();
        assert!(
            columns > 0 && columns.is_multiple_of(12),
            "{name}: {columns} columns by the tangent"
        );
        assert!(err.contains("Jacobian columns by the tangent"), "{name}: {err}");
        let above = [a_p > a_q * (1.0 + 1e-3), j_p > j_q * 1.02, f_p > f_q * 1.005];
        if above.iter().any(|b| *b) {
            assert!(
                warnings > 0 && err.contains("warning: the planned motion's peak"),
                "{name}: {err}"
            );
        }
        let [(plain, _), _, (planned, _)] = fem_peaks(&dir);
        assert!(
            planned <= plain / 20.0,
            "{name}: planned {planned:.3e} m vs plain {plain:.3e} m"
        );
        let amm = residual_peak(&dir.join("planned/amm-enriched.csv"), t_move);
        assert!(
            (amm - planned).abs() <= 0.1 * planned,
            "{name}: AMM {amm:.3e} m vs FEM {planned:.3e} m"
        );
    }
}

/// What the plan writes: `plan.csv` with its exact header, from `from` to `to`; `plan.toml`
/// runnable, reproducing the planned AMM run's residual within 1 % (a fresh run through the table
/// spline); the report's table and the figures.
#[test]
fn plan_toml_reruns_the_planned_motion() {
    let out = tempfile::tempdir().unwrap();
    let cfg = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions/plan-centre.toml");
    let dir = plan(&cfg, out.path());
    let text = std::fs::read_to_string(dir.join("plan.csv")).unwrap();
    assert_eq!(text.lines().next(), Some("t,Gx,Gy,theta,s1,s2,s3"));
    let (h, rows) = table(&dir.join("plan.csv"));
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let to = [0.03, -0.02, 0.2];
    for (k, c) in ["Gx", "Gy", "theta"].iter().enumerate() {
        assert!(first[col(&h, c)].abs() < 1e-15 && (last[col(&h, c)] - to[k]).abs() < 1e-12);
    }
    let rerun = out.path().join("rerun");
    let o = flexstar(&[
        "run",
        dir.join("plan.toml").to_str().unwrap(),
        "--solver",
        "amm",
        "--out",
        rerun.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let fresh = json(&rerun.join("plan-centre/amm-enriched.json"))["residual_G_peak_m"]
        .as_f64()
        .unwrap();
    let planned = json(&dir.join("planned/amm-enriched.json"))["residual_G_peak_m"]
        .as_f64()
        .unwrap();
    assert!((fresh / planned - 1.0).abs() < 0.01, "{fresh:.4e} vs {planned:.4e}");
    let md = std::fs::read_to_string(dir.join("plan.md")).unwrap();
    assert!(md.contains("| planned |") && md.contains("| plain quintic |"));
    for f in ["G", "tips", "sliders", "forces", "path"] {
        assert!(dir.join(format!("figures/plan-centre-plan-{f}.svg")).exists(), "{f}");
    }
}

/// A robot as built is planned on its own geometry (`docs/as-built.md` 6): unequal beams, welds
/// off by up to 2 degrees, an uneven base. `plan.toml` carries the robot, the planned motion ends
/// at `to`, and on the FEM (residual computed here from its CSV) the planned move leaves less than
/// the plain quintic, the AMM's planned residual within 10 % of the FEM's.
#[test]
fn a_robot_as_built_is_planned_on_its_own_geometry() {
    let out = tempfile::tempdir().unwrap();
    let robot = "[robot]\nL = [0.5, 0.47, 0.53]\nrho = [0.234, 0.25, 0.22]\nweld_deg = [0, 121.5, 238]\n\
                 [base]\nsides = [0.63, 0.6, 0.64]";
    let cfg = variant(out.path(), "plan-centre", robot);
    let dir = plan(&cfg, out.path());
    let toml = std::fs::read_to_string(dir.join("plan.toml")).unwrap();
    assert!(
        toml.contains("weld_deg = [0, 121.5, 238]") && toml.contains("[base]"),
        "{toml}"
    );
    let (h, rows) = table(&dir.join("plan.csv"));
    let last = &rows[rows.len() - 1];
    for (c, to) in ["Gx", "Gy", "theta"].iter().zip([0.03, -0.02, 0.2]) {
        assert!((last[col(&h, c)] - to).abs() < 1e-12);
    }
    let t_rest = 0.42;
    let fem = |m: &str| residual_peak(&dir.join(format!("{m}/fem.csv")), t_rest);
    let (plain, planned) = (fem("plain"), fem("planned"));
    assert!(planned < plain, "planned {planned:.3e} m against plain {plain:.3e} m");
    let amm = json(&dir.join("planned/amm-enriched.json"))["residual_G_peak_m"]
        .as_f64()
        .unwrap();
    assert!(
        (amm / planned - 1.0).abs() < 0.1,
        "AMM {amm:.4e} m, FEM {planned:.4e} m"
    );
}

/// A binding `a_max` holds on the planned motion (the peak of `|s_i''|` from `flexstar
/// kinematics` of `plan.toml`, a second computation of the slider jets) while the residual still
/// falls tenfold on the FEM. The user's `a_max` alone (`peak_factor = "off"`): with the default
/// factor the jerk bound of 4.10 binds too and the residual falls 7-fold (measured 14.6 %).
#[test]
fn the_planned_motion_keeps_its_limits() {
    let out = tempfile::tempdir().unwrap();
    let cfg = out.path().join("limited.toml");
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions/plan-centre.toml"))
            .unwrap()
            .replace("name = \"plan-centre\"", "name = \"limited\"");
    std::fs::write(&cfg, format!("{base}\npeak_factor = \"off\"\n[limits]\na_max = 2.5\n")).unwrap();
    let dir = plan(&cfg, out.path());
    let o = flexstar(&[
        "kinematics",
        dir.join("plan.toml").to_str().unwrap(),
        "--out",
        out.path().join("kin").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = table(&out.path().join("kin/limited/kinematics.csv"));
    let acc = ["sdd1", "sdd2", "sdd3"].map(|c| col(&h, c));
    let peak = rows.iter().flat_map(|r| acc.map(|c| r[c].abs())).fold(0.0, f64::max);
    assert!(peak <= 2.5 * (1.0 + 1e-6), "peak |s''| = {peak}");
    let [(plain, _), _, (planned, _)] = fem_peaks(&dir);
    assert!(
        planned <= plain / 10.0,
        "planned {planned:.3e} m vs plain {plain:.3e} m"
    );
}

/// Item 6, third target: with `objective = "time"` the planned move is at least 30 % shorter than
/// the ZVD-shaped quintic at the same residual, and its FEM residual holds the bound; the ZVD
/// baseline (base duration found by the planner) holds it on the FEM too. `budget_s = 60`, as
/// the target moves' files have it: with the default 8 s the bisection's length depends on how
/// busy the machine is (docs/motions.md 4.5), and under the test harness's parallel plans the
/// smooth searches of 4.10 ran out of it before a first success.
#[test]
fn the_time_objective_beats_the_zvd_shaped_quintic_by_thirty_percent() {
    let out = tempfile::tempdir().unwrap();
    let cfg = out.path().join("fast.toml");
    std::fs::write(
        &cfg,
        "name = \"fast\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n[plan]\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\n\
         to = { Gx = 0.03, Gy = -0.02, theta = 0.2 }\nobjective = \"time\"\nresidual_max = 5e-5\nbudget_s = 60\n",
    )
    .unwrap();
    let dir = plan(&cfg, out.path());
    let [_, (zvd, zvd_rest), (planned, planned_rest)] = fem_peaks(&dir);
    assert!(
        planned <= 5e-5 && zvd <= 5e-5 * 1.05,
        "planned {planned:.3e}, ZVD {zvd:.3e}"
    );
    assert!(
        planned_rest <= 0.7 * zvd_rest,
        "planned {planned_rest} s vs ZVD {zvd_rest} s"
    );
    // the record of the search: the AMM runs of every duration tried, and the chosen one's trace
    let planner = &json(&dir.join("plan.json"))["planner"];
    let total = planner["evaluations"].as_u64().unwrap();
    let trace = planner["trace"].as_array().unwrap();
    let last = trace.last().expect("the chosen duration's search")["evaluations"]
        .as_u64()
        .unwrap();
    assert!(
        total > 0 && last > 0 && last <= total,
        "{total} evaluations, the chosen search {last}"
    );
    // the search over t_move: every duration tried made AMM runs, and they add up to the total
    let ts = &planner["time_search"];
    let steps = ts["steps"].as_array().unwrap();
    assert!(!steps.is_empty() && steps.iter().all(|s| s["evaluations"].as_u64().unwrap() > 0));
    let per_step: u64 = steps.iter().map(|s| s["evaluations"].as_u64().unwrap()).sum();
    let (zvd, search) = (
        ts["zvd_evaluations"].as_u64().unwrap(),
        ts["search_evaluations"].as_u64().unwrap(),
    );
    assert!(
        per_step == search && zvd + search == total && zvd > 0,
        "steps {per_step}, search {search}, ZVD {zvd}, total {total}"
    );
}

/// Bad input is refused before any work with the file and the key, and nothing is written.
/// `[robust] t_move = "zvd"` (docs/motions.md 4.11, "The robust plan's time"): the robust plan
/// takes the ZVD-shaped quintic's duration, read here from the ZVD run's own `t_rest`, while the
/// plain quintic and the nominal plan keep the file's 0.42 s; on the FEM (its CSVs read here) the
/// robust plan leaves far less than the plain quintic. A short search and two draws keep it cheap:
/// even the plain quintic of the longer duration leaves a tenth of the short one's (4.11). The
/// draws run on the FEM here (`check = "fem"`), each row the FEM's residual of that draw.
#[test]
fn a_robust_plan_in_the_zvd_time_keeps_the_plain_quintic_as_its_reference() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/motions");
    let text = std::fs::read_to_string(root.join("plan-robust-zvd.toml")).unwrap();
    assert!(text.contains("budget_s = 60"));
    let cfg = dir.path().join("plan-robust-zvd.toml");
    std::fs::write(
        &cfg,
        format!(
            "{}\ndraws = 2\ncheck = \"fem\"\n",
            text.replace("budget_s = 60", "budget_s = 4")
        ),
    )
    .unwrap();
    let case = plan(&cfg, dir.path());
    let v = json(&case.join("plan.json"));
    let rest_of = |label: &str| {
        v["comparison"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["motion"].as_str().unwrap().starts_with(label))
            .unwrap_or_else(|| panic!("no {label} in the comparison"))["t_rest"]
            .as_f64()
            .unwrap()
    };
    let (t_plain, t_zvd, t_planned) = (rest_of("plain quintic"), rest_of("ZVD"), rest_of("planned"));
    assert!((t_plain - 0.42).abs() < 1e-12 && (rest_of("nominal plan") - 0.42).abs() < 1e-12);
    assert!(
        t_zvd > 0.8 && (t_planned - t_zvd).abs() < 1e-9,
        "planned {t_planned} s, ZVD {t_zvd} s"
    );
    assert!((v["robust"]["t_move_s"]["robust_plan"].as_f64().unwrap() - t_zvd).abs() < 1e-9);
    assert_eq!(v["robust"]["check"]["draws"].as_array().unwrap().len(), 2);
    assert_eq!(v["robust"]["check"]["draws_model"], "FEM");
    let plain = residual_peak(&case.join("plain/fem.csv"), t_plain);
    let planned = residual_peak(&case.join("planned/fem.csv"), t_planned);
    assert!(
        planned < plain / 5.0,
        "robust plan {planned:.3e} m against the plain quintic's {plain:.3e} m"
    );
}

#[test]
fn bad_plans_are_refused_with_the_key_and_nothing_is_written() {
    let out = tempfile::tempdir().unwrap();
    let head = "name = \"bad\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n";
    let plan = "[plan]\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.03, Gy = -0.02, theta = 0.2 }\n";
    let cases = [
        (format!("{plan}t_move = 0.42\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n"), "trajectory"),
        (format!("{plan}t_move = 0.42\nspeed = 3\n"), "speed"),
        (format!("{plan}objective = \"time\"\nt_move = 0.4\nresidual_max = 1e-5\n"), "plan.t_move"),
        (format!("{plan}objective = \"time\"\n"), "plan.residual_max"),
        (format!("{plan}t_move = 0.1\n[limits]\na_max = 2.0\nv_max = 0.5\n"), "shorter than the limits allow"),
        (format!("{plan}t_move = 0.42\n[limits]\na_max = 2.0\n"), "the plain quintic in t_move = 0.42 s reaches |s''|"),
        (format!("{plan}t_move = 0.42\n[limits]\nv_max = -1.0\n"), "limits.v_max"),
        (format!("{plan}t_move = 0.42\n[limits]\nj_max = 0.0\n"), "limits.j_max"),
        (format!("{plan}t_move = 0.42\n[limits]\nj_max = nan\n"), "limits.j_max"),
        (format!("{plan}t_move = 0.42\n[limits]\nj_max = 40.0\n"), "the plain quintic in t_move = 0.42 s reaches |s'''|"),
        (format!("{plan}t_move = 0.42\npeak_factor = 0.5\n"), "plan.peak_factor"),
        (format!("{plan}t_move = 0.42\nsmoothness = -1.0\n"), "plan.smoothness"),
        (format!("{plan}t_move = 0.42\ntip_weight = -1.0\n"), "plan.tip_weight"),
        (format!("{plan}t_move = 0.42\npoints = 40\n"), "plan.points"),
        (
            "[plan]\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.5, Gy = 0.0, theta = 0.0 }\nt_move = 0.4\n".into(),
            "plan.to",
        ),
        (format!("{plan}t_move = 0.42\n[limits]\nFa_max = 0.5\n"), "limits.Fa_max"),
        (format!("{plan}t_move = 1.2\n"), "time.t_end"),
        (
            format!("{plan}t_move = 0.42\n[payload]\nmass = 0.25\n[robust]\n\"payload.mass\" = [0.0, 0.5]\nt_move = 0.3\n"),
            "robust.t_move",
        ),
        (
            format!("{plan}t_move = 0.42\n[payload]\nmass = 0.25\n[robust]\n\"payload.mass\" = [0.0, 0.5]\nt_move = \"zvd\"\n"),
            "ends before the robust plan's residual window does",
        ),
        (
            format!("{plan}t_move = 0.42\n[payload]\nmass = 0.25\n[robust]\n\"payload.mass\" = [0.0, 0.5]\ncheck = \"exudyn\"\n"),
            "robust.check",
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
