//! The outputs of one experiment, as `flexstar compare` writes them into `DIR/<name>/` (and
//! `flexstar verify` for each paper case): every run's CSV, shapes and sidecar JSON, the EVPs
//! (`compare.md`, `compare.csv`, `compare.json`), the figure set and a report for the
//! experiment. Columns and fields are listed in `docs/outputs.md`.

use std::fmt::Write as _;
use std::path::Path;

use flexstar_io::run_set::RunSet;
use flexstar_kinematics::{rigid_inverse_dynamics_of, RigidState};
use flexstar_metrics::small_deflection_check;
use flexstar_model::{DriveKind, Experiment, Feedforward, ModeFamily, Provenance, Response, ValidityExceeded};
use serde::Serialize;

use flexstar_plot::{Figure, RenderedFigure, Style, EXTRA_COLORS, FAMILY_COLORS, FEM_STYLE};

use crate::dwells::{case_dwells, dwells_markdown, RunDwells};
use crate::figures::{figure_forces, figure_sliders, figure_star, figure_tips, figure_w_g, Run};
use crate::residual::{case_residuals, mark_t_rest, residual_csv, residual_markdown, RunResidual};
use crate::runs::CaseResults;
use crate::servo::servo_summary;
use crate::table::{csv_text, opt_number, TableRow};
use crate::Error;

/// Header of `compare.csv` (a file contract, `docs/outputs.md`).
pub const COMPARE_CSV_HEADER: &str = "model,evp_A,evp_B,evp_C,evp_G,evp_mean";

/// A run that leaves the small-deflection range the AMM assumes.
#[derive(Debug, Clone, Serialize)]
pub struct ValidityWarning {
    /// Experiment file.
    pub file: String,
    /// Run file stem (`fem`, `amm-<label>`).
    pub run: String,
    pub exceeded: ValidityExceeded,
}

impl std::fmt::Display for ValidityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {} {}", self.file, self.run, self.exceeded)
    }
}

/// Every run of a case with its file stem: the FEM first, then the AMM runs.
pub fn runs_of(case: &CaseResults) -> Vec<(String, &Response)> {
    std::iter::once(("fem".to_string(), &case.fem))
        .chain(case.amm.iter().map(|(run, r)| (run.file_stem(), r)))
        .collect()
}

/// The small-deflection check of every run of a case (`flexstar_metrics::small_deflection_check`),
/// in the order of [`runs_of`]: computed once per case by [`write_case`] and shown from there in
/// the tables, `compare.json`, the warnings and the report.
pub type RunChecks = Vec<(String, Option<ValidityExceeded>)>;

/// [`RunChecks`] of `case`.
pub fn run_checks(exp: &Experiment, case: &CaseResults) -> RunChecks {
    runs_of(case)
        .into_iter()
        .map(|(run, r)| (run, small_deflection_check(r, &exp.robot)))
        .collect()
}

/// The runs of `checks` that leave the small-deflection range, as warnings.
pub fn validity_warnings(exp: &Experiment, checks: &RunChecks) -> Vec<ValidityWarning> {
    checks
        .iter()
        .filter_map(|(run, check)| {
            check.clone().map(|exceeded| ValidityWarning {
                file: exp.source.display().to_string(),
                run: run.clone(),
                exceeded,
            })
        })
        .collect()
}

/// The colour of a family (the same in every figure); a second run of a family already drawn
/// takes the next of [`EXTRA_COLORS`].
fn run_style(family: ModeFamily, used: &mut Vec<ModeFamily>) -> Style {
    let k = ModeFamily::ALL.iter().position(|f| *f == family).unwrap_or(0);
    let repeats = used.iter().filter(|f| **f == family).count();
    used.push(family);
    let color = match repeats {
        0 => FAMILY_COLORS[k % FAMILY_COLORS.len()],
        n => EXTRA_COLORS[(n - 1) % EXTRA_COLORS.len()],
    };
    Style {
        color,
        width: 2,
        dashed: false,
    }
}

/// The figure set of one case: w_G, tips, the deformed star at its last snapshot, and the driving
/// forces over the rigid-body inverse dynamics. `hold` [s]: one period of the first mode at the
/// final pose when the motion rests before `t_end` (the settling hold): the time figures then get
/// zoom rows on the motion and on the residual window after it ([`crate::residual::time_zooms`]).
/// `dwells`: every run's dwells (`docs/motions.md` 2.5): with any, the figure `-dG` (|dG|, the
/// band, the settling instants); with several, the time figures' zoom rows are one per move and
/// its dwell instead ([`crate::dwells::dwell_zooms`]).
pub fn case_figures(
    exp: &Experiment,
    case: &CaseResults,
    hold: Option<f64>,
    dwells: &[RunDwells],
) -> Result<Vec<Figure>, Error> {
    let runs = styled_runs(case);
    let kin = |t: f64| {
        RigidState::at(&exp.robot, &exp.trajectory, t).map_err(|source| Error::Kinematics {
            file: exp.source.display().to_string(),
            source: Box::new(source),
        })
    };
    let t = &case.fem.t;
    let attached = flexstar_model::Attachments::of(exp);
    let robot = flexstar_model::Robot::from_params(&exp.robot)?;
    let rigid: Vec<[f64; 3]> = t
        .iter()
        .map(|&ti| kin(ti).map(|s| rigid_inverse_dynamics_of(&robot, &attached, &s).fa))
        .collect::<Result<_, _>>()?;
    let mut figs = vec![figure_w_g(&exp.name, &runs), figure_tips(&exp.name, &runs)];
    let last = kin(exp.time.t_end)?;
    let peak = case
        .fem
        .w_tip
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-9);
    // magnify the elastic part to about a fifth of the beam length
    let magnify = (0.2 * exp.robot.l / peak).clamp(1.0, 1e4).round();
    if let Some(f) = figure_star(&exp.name, &runs, &last, magnify) {
        figs.push(f);
    }
    let mut forces = figure_forces(&exp.name, &runs, Some((t, &rigid)));
    if let Some(caption) = direct_forces_caption(exp) {
        forces.caption = caption;
    }
    figs.push(forces);
    if exp.drive.kind == DriveKind::Servo {
        let reference: Vec<[f64; 3]> = t
            .iter()
            .map(|&ti| kin(ti).map(|s| s.s.map(|si| si.v)))
            .collect::<Result<_, _>>()?;
        figs.push(figure_sliders(&exp.name, &runs, t, &reference));
    }
    figs.extend(crate::sensors::sensor_figures(exp, &runs));
    if let Some(t_rest) = flexstar_modal::settle::motion_end(exp) {
        let zooms = hold.map_or_else(Vec::new, |h| crate::residual::time_zooms(t_rest, h, exp.time.t_end));
        for f in figs.iter_mut().filter(|f| !f.name.ends_with("-star")) {
            mark_t_rest(f, t_rest);
            f.zooms = zooms.clone();
        }
    }
    // per dwell (docs/motions.md 2.5): every run has the same dwells (one trajectory)
    let per_run: Vec<&[flexstar_model::DwellKeys]> = runs_of(case)
        .iter()
        .map(|(stem, _)| {
            dwells
                .iter()
                .find(|d| d.run == *stem)
                .map_or(&[][..], |d| d.dwells.as_slice())
        })
        .collect();
    if let Some(first) = per_run.iter().find(|d| !d.is_empty()) {
        if first.len() > 1 {
            let zooms = crate::dwells::dwell_zooms(first, exp.time.t_end);
            for f in figs.iter_mut().filter(|f| !f.name.ends_with("-star")) {
                f.zooms = zooms.clone();
            }
        }
        figs.push(crate::dwells::figure_dg(
            &format!("{}-dG", exp.name),
            &format!("{}: |dG| per move and dwell", exp.name),
            &runs,
            &per_run,
            exp.report.settle_tol,
            exp.time.t_end,
        ));
    }
    figs.extend(crate::sensitivity::figure_sensitivity(exp)?);
    Ok(figs)
}

/// The runs of a case as every figure draws them: the FEM (black) first, then the AMM runs in
/// their family's colour ([`run_style`]).
pub(crate) fn styled_runs(case: &CaseResults) -> Vec<Run<'_>> {
    let mut runs = vec![Run {
        label: "FEM".into(),
        response: &case.fem,
        style: FEM_STYLE,
    }];
    let mut used = Vec::new();
    for (run, r) in &case.amm {
        runs.push(Run {
            label: format!("AMM {}", run.label),
            response: r,
            style: run_style(run.settings.family, &mut used),
        });
    }
    runs
}

/// The caption of the forces figure of a direct experiment (`None`: the motion is prescribed and
/// the dashed curve is the rigid-body inverse dynamics of that motion, as `figure_forces` says).
fn direct_forces_caption(exp: &Experiment) -> Option<String> {
    let servo = match exp.drive.kind {
        DriveKind::Motion => return None,
        DriveKind::Servo => true,
        DriveKind::Forces => false,
    };
    let what = if servo {
        let ff = match exp.drive.feedforward.unwrap_or_default() {
            Feedforward::Rigid => "the servo's rigid feedforward: the rest is what its PD loop added",
            Feedforward::None => "the servo has no feedforward: every newton here comes from its PD loop",
        };
        format!(
            "What the servo pushed in every run, against the rigid-body inverse dynamics of its reference \
                motion, the [trajectory] (grey dashed; {ff})."
        )
    } else {
        "The forces the [drive] prescribes, the same in every run (the sliders move as they make them), \
            against the rigid-body inverse dynamics of the [trajectory] (grey dashed), the motion those forces \
            were meant to produce."
            .to_string()
    };
    Some(what)
}

/// `compare.csv`: one row per AMM run, `model` = its file stem, EVPs in %, `n/a` where the FEM
/// reference is negligible.
pub fn compare_csv(row: &TableRow) -> String {
    let records = row.families.iter().map(|e| {
        let p = e.evp.points;
        vec![
            format!("amm-{}", e.label),
            opt_number(p[0]),
            opt_number(p[1]),
            opt_number(p[2]),
            opt_number(p[3]),
            opt_number(e.evp.mean),
        ]
    });
    let header: Vec<&str> = COMPARE_CSV_HEADER.split(',').collect();
    csv_text(&header, records)
}

fn pct(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into())
}

/// What the robot carries beyond the paper's (payload, damping, load), in one sentence: `None` when it carries
/// nothing (no payload, no damping, no load).
pub(crate) fn attachments_line(exp: &Experiment) -> Option<String> {
    let mut parts = Vec::new();
    let p = &exp.payload;
    if !p.is_none() {
        parts.push(format!(
            "a payload at G (m = {} kg, J = {} kg m^2, offset [{}, {}] m)",
            p.mass, p.j, p.offset[0], p.offset[1]
        ));
    }
    if exp.damping != flexstar_model::Damping::default() {
        let (alpha, beta) = exp.damping.coefficients();
        parts.push(if alpha == 0.0 {
            format!("Kelvin-Voigt damping (beta = {beta:.4e} s)")
        } else {
            format!("Rayleigh damping (alpha = {alpha:.4e} 1/s, beta = {beta:.4e} s)")
        });
    }
    if !exp.load.is_none() {
        let l = &exp.load;
        let how = if l.file.is_some() {
            "a table of Fx, Fy, Mz".to_string()
        } else {
            let given = [("Fx", &l.fx), ("Fy", &l.fy), ("Mz", &l.mz)];
            let names: Vec<&str> = given.iter().filter(|(_, p)| p.is_some()).map(|(n, _)| *n).collect();
            format!("polynomial {}", names.join(", "))
        };
        parts.push(format!("a load at G ({how})"));
    }
    (!parts.is_empty()).then(|| format!("The robot carries {}.", parts.join(", ")))
}

/// `compare.md`: what was run, the EVPs, the behaviour of G, the figures.
pub fn compare_markdown(
    exp: &Experiment,
    case: &CaseResults,
    row: &TableRow,
    (checks, warnings): (&RunChecks, &[ValidityWarning]),
    figures: &[RenderedFigure],
    (residuals, dwells, measured): (Option<&[RunResidual]>, &[RunDwells], Option<&str>),
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}: AMM against FEM\n", exp.name);
    if !exp.description.is_empty() {
        let _ = writeln!(s, "{}\n", exp.description);
    }
    let _ = writeln!(
        s,
        "Experiment file `{}`; t = 0 .. {} s, output every {} s.\n",
        exp.source.display(),
        exp.time.t_end,
        exp.time.dt_out
    );
    if let Some(line) = attachments_line(exp) {
        let _ = writeln!(s, "{line}\n");
    }
    let _ = writeln!(s, "## Runs\n");
    let _ = writeln!(s, "{}", runs_markdown(case, checks));
    if let Some(servo) = servo_summary(exp, case) {
        s.push_str(&servo.markdown());
    }
    let _ = writeln!(s, "## EVP (Eq. 45), % of the FEM response\n");
    let _ = writeln!(
        s,
        "`EVP = int |w_AMM - w_FEM| dt / int |w_FEM| dt * 100` at the tips A, B, C and at G (length of G's \
         elastic displacement vector); *n/a*: the FEM response there is below 1 % of its largest tip peak, \
         left out of the mean.\n"
    );
    let _ = writeln!(s, "| run | A | B | C | G | mean | correct at G |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for e in &row.families {
        let p = e.evp.points;
        let _ = writeln!(
            s,
            "| {}{} | {} | {} | {} | {} | {} | {} |",
            e.label,
            if e.most_accurate { " (**best**)" } else { "" },
            pct(p[0]),
            pct(p[1]),
            pct(p[2]),
            pct(p[3]),
            pct(e.evp.mean),
            if e.correct { "yes" } else { "no" }
        );
    }
    let sensors = crate::sensors::sensors_markdown(&crate::sensors::sensor_evps(case));
    if !sensors.is_empty() {
        let _ = write!(s, "\n{sensors}");
    }
    if let Some(md) = measured {
        let _ = write!(s, "\n{md}");
    }
    if let Some(res) = residuals {
        let _ = write!(s, "\n{}", residual_markdown(res));
    }
    let per_dwell = dwells_markdown(dwells);
    if !per_dwell.is_empty() {
        let _ = write!(s, "\n{per_dwell}");
    }
    let m = row.measures;
    let _ = writeln!(
        s,
        "\n## Behaviour of G (from the FEM): {}\n\npeak |w_G| / peak tip = {:.3e} (moves when >= 1e-2); \
         peak |slope_G| L / peak tip = {} (turns when >= 5e-2). A run is *correct at G* when its modes' boundary \
         conditions at G can represent that: pinned-free forces w_G = 0, slide-free a zero slope, free-free \
         neither.\n",
        row.behaviour.name(),
        m.w_g_rel,
        m.slope_rel.map(|v| format!("{v:.3e}")).unwrap_or_else(|| "n/a".into())
    );
    if !warnings.is_empty() {
        let _ = writeln!(s, "## Model validity\n");
        for w in warnings {
            let _ = writeln!(s, "- {} {}", w.run, w.exceeded);
        }
        let _ = writeln!(s);
    }
    if !figures.is_empty() {
        let _ = writeln!(s, "## Figures\n");
        for f in figures {
            let _ = writeln!(s, "![{}](figures/{}.png)\n\n{}\n", f.title, f.name, f.caption);
        }
    }
    s
}

/// The run metadata table (Markdown): solver, settings, wall time, small-deflection check.
pub fn runs_markdown(case: &CaseResults, checks: &RunChecks) -> String {
    let mut s =
        String::from("| run | solver | family | model | N | elements | dt [s] | wall time [s] | small deflection |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for ((stem, r), (_, check)) in runs_of(case).into_iter().zip(checks) {
        let i = &r.info;
        let opt = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
        let check = match check {
            None => "in range".to_string(),
            Some(v) => format!("**left at t = {:.4} s** ({})", v.t, v.quantity),
        };
        let _ = writeln!(
            s,
            "| {stem} | {} | {} | {} | {} | {} | {} | {:.2} | {check} |",
            i.solver,
            opt(&i.family),
            opt(&i.model),
            i.modes.map(|n| n.to_string()).unwrap_or_else(|| "-".into()),
            i.elements.map(|n| n.to_string()).unwrap_or_else(|| "-".into()),
            short(i.dt),
            i.wall_s
        );
    }
    s
}

#[derive(Serialize)]
struct RunJson<'a> {
    run: String,
    info: &'a flexstar_model::RunInfo,
    small_deflection: Option<ValidityExceeded>,
}

/// `compare.json`: provenance, the experiment file, the row (EVPs, verdicts, behaviour, junction
/// measures) and every run's settings, cost and small-deflection check.
pub fn compare_json(
    exp: &Experiment,
    case: &CaseResults,
    row: &TableRow,
    prov: &Provenance,
    (checks, residuals, measured): (&RunChecks, Option<&[RunResidual]>, Option<serde_json::Value>),
) -> String {
    let runs: Vec<RunJson> = runs_of(case)
        .into_iter()
        .zip(checks)
        .map(|((run, r), (_, check))| RunJson {
            run,
            info: &r.info,
            small_deflection: check.clone(),
        })
        .collect();
    let doc = serde_json::json!({
        "flexstar_version": prov.version,
        "commit": prov.commit,
        "date": prov.date,
        "experiment": exp.name,
        "file": exp.source.display().to_string(),
        "comparison": row,
        "runs": runs,
    });
    let mut doc = doc;
    for (k, v) in flexstar_model::identity::fields(exp) {
        doc[k] = v;
    }
    let sensors = crate::sensors::sensor_evps(case);
    if !sensors.is_empty() {
        doc["sensors"] = serde_json::to_value(&sensors).expect("plain data serialises");
    }
    if let Some(m) = measured {
        doc["measured"] = m;
    }
    if let Some(res) = residuals {
        let list: Vec<_> = res
            .iter()
            .map(|r| {
                let fields = crate::residual::sidecar_keys_of(r);
                serde_json::json!({ "run": r.run, "g_pinned": r.g_pinned, "residual": fields })
            })
            .collect();
        doc["residual"] = serde_json::Value::Array(list);
    }
    serde_json::to_string_pretty(&doc).expect("plain data serialises") + "\n"
}

/// What [`write_case`] wrote that its callers show again, each computed once: the figures as
/// drawn (the reports embed the SVG written to disk), the small-deflection warnings and the text
/// of `compare.csv` (printed by the CLI).
#[derive(Debug, Clone)]
pub struct WrittenCase {
    /// Empty when the figures were not asked for.
    pub figures: Vec<RenderedFigure>,
    pub warnings: Vec<ValidityWarning>,
    /// Every run's small-deflection check, in the order of [`runs_of`].
    pub checks: RunChecks,
    pub compare_csv: String,
    /// Every run's residual vibration after the motion (`None`: it does not rest before
    /// `t_end`), written as `residual.csv`.
    pub residuals: Option<Vec<RunResidual>>,
    /// Every run's residual per dwell (`docs/motions.md` 2.5; empty without a dwell), written as
    /// `<stem>-dwells.csv` and the sidecars' `dwells`.
    pub dwells: Vec<RunDwells>,
    /// The section of a recording laid over the runs (`compare --measured`), as in `compare.md`.
    pub measured_markdown: Option<String>,
}

/// Write every output of one case into `dir` (see the module docs).
pub fn write_case(
    dir: &Path,
    exp: &Experiment,
    case: &CaseResults,
    row: &TableRow,
    prov: &Provenance,
    figures: bool,
) -> Result<WrittenCase, Error> {
    write_case_measured(dir, exp, case, row, (prov, figures), None)
}

/// [`write_case`] with a recording laid over the runs (`compare --measured`,
/// [`crate::measured`]): its figures after the others, its section in `compare.md` and the key
/// `measured` of `compare.json`.
pub fn write_case_measured(
    dir: &Path,
    exp: &Experiment,
    case: &CaseResults,
    row: &TableRow,
    (prov, figures): (&Provenance, bool),
    measured: Option<&crate::measured::MeasuredOverlay>,
) -> Result<WrittenCase, Error> {
    let residuals = case_residuals(exp, case)?;
    let dwells = case_dwells(exp, case)?;
    let hold = residuals.iter().flatten().next().map(|r| r.residual.hold_s);
    let mut drawn = if figures {
        case_figures(exp, case, hold, &dwells)?
    } else {
        Vec::new()
    };
    if let (Some(m), true) = (measured, figures) {
        let t_rest = flexstar_modal::settle::motion_end(exp);
        drawn.extend(crate::measured_figures::measured_figures(
            &exp.name,
            m,
            &styled_runs(case),
            t_rest,
        ));
    }
    let measured_markdown = measured.map(|m| m.markdown());
    let figdir = dir.join("figures");
    let figs = drawn.iter().map(|f| f.write(&figdir)).collect::<Result<Vec<_>, _>>()?;
    let csv = compare_csv(row);
    let checks = run_checks(exp, case);
    let warnings = validity_warnings(exp, &checks);
    // every run's files and the EVP files are published together (a run set, `docs/outputs.md`)
    let mut set = RunSet::begin(dir)?;
    for (stem, r) in runs_of(case) {
        let res = residuals.iter().flatten().find(|x| x.run == stem);
        let mut keys = match res {
            Some(x) => crate::residual::sidecar_keys_of(x),
            None => flexstar_metrics::residual::sidecar_keys(None, exp.report.settle_tol, false),
        };
        keys.dwells = dwells.iter().find(|d| d.run == stem).map(|d| d.dwells.clone());
        if let Some(d) = &keys.dwells {
            set.text(&format!("{stem}-dwells.csv"), &flexstar_model::sidecar::dwells_csv(d))?;
        }
        let check = small_deflection_check(r, &exp.robot);
        r.stage_run(&mut set, &stem, None, (exp, prov), (check, Some(keys)))?;
    }
    set.text("compare.csv", &csv)?;
    set.text(
        "compare.md",
        &compare_markdown(
            exp,
            case,
            row,
            (&checks, &warnings),
            &figs,
            (residuals.as_deref(), &dwells, measured_markdown.as_deref()),
        ),
    )?;
    set.text(
        "compare.json",
        &compare_json(
            exp,
            case,
            row,
            prov,
            (&checks, residuals.as_deref(), measured.map(|m| m.json())),
        ),
    )?;
    if let Some(res) = &residuals {
        set.text("residual.csv", &residual_csv(res))?;
    }
    set.commit()?;
    Ok(WrittenCase {
        figures: figs,
        warnings,
        checks,
        compare_csv: csv,
        residuals,
        dwells,
        measured_markdown,
    })
}

/// A step for display: four significant digits (`1.667e-4`); files keep the exact value.
fn short(v: f64) -> String {
    format!("{v:.3e}")
}
