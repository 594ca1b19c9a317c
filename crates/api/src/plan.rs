//! `plan` (the CLI's `flexstar plan CONFIG [--out DIR]`, `docs/motions.md`
//! 4.7): the plan made by `flexstar_plan`, then the three motions it is compared with (the plain
//! quintic of the same duration, the ZVD-shaped quintic with `f_hz = "auto"`, the planned motion)
//! each run on the accurate AMM and on the FEM, and the files: `plan.toml`, `plan.csv`,
//! `plan.json`, `plan.md`, the runs in `plain/`, `zvd/`, `planned/` and the figures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;

use flexstar_io::run_set::RunSet;
use flexstar_model::{Experiment, TableMotion, TableSpace, Trajectory};
use flexstar_plan::{PlanConfig, PlanError, Planned};

use crate::run::{RunOutcome, RunSettings, Solver};
use crate::{ApiError, Result};

/// The three motions of the comparison, in report order: folder name and label.
pub const MOTIONS: [(&str, &str); 3] = [
    ("plain", "plain quintic"),
    ("zvd", "ZVD-shaped quintic (f_hz = \"auto\")"),
    ("planned", "planned"),
];

/// With `[robust]` (`docs/motions.md` 4.11) the comparison has two motions more, after these:
/// the nominal plan and the quintic shaped over the uncertainty; `planned` is the robust plan.
pub const ROBUST_MOTIONS: [(&str, &str); 2] = [
    ("nominal", "nominal plan (the file's model)"),
    ("shaped", "quintic shaped over the uncertainty (si)"),
];

/// One motion of the comparison with its AMM and FEM runs.
#[derive(Debug, Clone)]
pub struct MotionRuns {
    /// `plain`, `zvd` or `planned`.
    pub key: &'static str,
    pub label: &'static str,
    pub exp: Experiment,
    pub amm: RunOutcome,
    pub fem: RunOutcome,
}

/// What `flexstar plan` made.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    pub planned: Planned,
    pub motions: Vec<MotionRuns>,
    /// `DIR/<name>/`.
    pub dir: PathBuf,
    pub files: Vec<PathBuf>,
    /// Notes for the user: the output folder held results of another experiment with the same
    /// name ([`flexstar_model::identity::other_experiment_note`]).
    pub notes: Vec<String>,
    /// Wall time of the whole command [s] and of the planning alone.
    pub wall_s: f64,
    /// With `[robust]`: the motions on the sample (AMM) and on fresh draws (`[robust] check`), the curves.
    pub robust: Option<crate::plan_robust::RobustCheck>,
}

/// A planner error as the command reports it (bad input names the file and key).
pub(crate) fn from_plan(source: &str, e: PlanError) -> ApiError {
    match e {
        PlanError::Input(m) => ApiError::from_model(m),
        PlanError::Infeasible { what, reason } => ApiError::solver(source, format!("{what}: infeasible at {reason}")),
        PlanError::Solver(s) => ApiError::solver(source, s),
    }
}

/// Read and check a plan file (every check of 4.8 that needs no solver).
pub fn load_plan(config: &Path) -> Result<PlanConfig> {
    let cfg = flexstar_plan::read_plan_config(config).map_err(|e| from_plan(&config.display().to_string(), e))?;
    crate::ApiError::frictionless(&cfg.exp, config.display(), "flexstar plan")?;
    Ok(cfg)
}

/// The whole command: plan, run the three motions on both solvers, write everything into
/// `out/<name>/` (checked writable before any work). `on_planned` sees the plan before the runs.
pub fn plan_to_dir(config: &Path, out: &Path, on_planned: impl FnOnce(&Planned)) -> Result<PlanOutcome> {
    let started = Instant::now();
    let cfg = load_plan(config)?;
    let source = config.display().to_string();
    if cfg.cycle.is_some() {
        return Err(ApiError::solver(
            &source,
            "the file is a cycle ([plan] points or a via cycle): plan it with flexstar_api::plan_cycle::plan_cycle_to_dir",
        ));
    }
    let dir = crate::case_dir(out, &cfg.exp)?;
    let notes = flexstar_model::identity::other_experiment_note(&dir, &cfg.exp)
        .into_iter()
        .collect();
    let labels: Vec<(&'static str, &'static str)> = MOTIONS.into_iter().chain(ROBUST_MOTIONS).collect();
    // the plain and ZVD baselines run beside the search when they are known before it
    let (planned, baselines) =
        flexstar_plan::planner::plan_beside(&cfg, |exps| run_motions(exps, &labels[..2], &source));
    let planned = planned.map_err(|e| from_plan(&source, e))?;
    on_planned(&planned);
    let rows = plan_rows(&cfg.exp, &planned)?;
    let exps = motion_experiments(&cfg, &planned, &rows)?;
    let motions = match baselines {
        Some(done) => {
            let mut motions = done?;
            let rest = exps.into_iter().skip(motions.len()).collect();
            motions.extend(run_motions(rest, &labels[motions.len()..], &source)?);
            motions
        }
        None => run_motions(exps, &labels, &source)?,
    };
    let robust = planned.robust.as_ref().map(|info| {
        let trajectories: Vec<(String, Trajectory)> = motions
            .iter()
            .map(|m| (m.key.to_string(), m.exp.trajectory.clone()))
            .collect();
        let amm = crate::plan_robust::CheckAmm {
            modes: planned.modes,
            dt: planned.dt,
        };
        crate::plan_robust::check(info, &trajectories, amm)
    });
    let mut files = write_runs(&motions, &dir)?;
    let wall_s = started.elapsed().as_secs_f64();
    let outcome = PlanOutcome {
        planned,
        motions,
        dir: dir.clone(),
        files: Vec::new(),
        notes,
        wall_s,
        robust,
    };
    files.extend(write_plan_files(&cfg, &outcome, &rows)?);
    files.extend(crate::plan_report::write_figures(&cfg.exp, &outcome)?);
    Ok(PlanOutcome { files, ..outcome })
}

/// The rows of `plan.csv`: `t,Gx,Gy,theta,s1,s2,s3` from `t0` to `t_rest` at `dt_out`.
pub fn plan_rows(exp: &Experiment, p: &Planned) -> Result<Vec<[f64; 7]>> {
    let (t0, t1, dt) = (p.family.t0, p.t_rest, exp.time.dt_out);
    let n = ((t1 - t0) / dt).round() as usize;
    (0..=n)
        .map(|k| {
            let t = if k == n { t1 } else { t0 + k as f64 * dt };
            let pose = p.trajectory.pose(t)?.unwrap_or([0.0; 3]);
            let s = p.trajectory.s(&exp.robot, t)?;
            Ok([t, pose[0], pose[1], pose[2], s[0], s[1], s[2]])
        })
        .collect::<std::result::Result<Vec<_>, flexstar_model::ModelError>>()
        .map_err(ApiError::from_model)
}

/// The table trajectory of the rows (what `plan.toml` runs).
pub(crate) fn table_trajectory(exp: &Experiment, rows: &[[f64; 7]]) -> Result<Trajectory> {
    let t = rows.iter().map(|r| r[0]).collect();
    let v = rows.iter().map(|r| [r[1], r[2], r[3]]).collect();
    TableMotion::from_rows(PathBuf::from("plan.csv"), TableSpace::Task, t, v, &exp.robot)
        .map(Trajectory::Table)
        .map_err(|e| ApiError::solver("plan.csv", e))
}

/// The experiments of the three motions: the plain quintic and the ZVD-shaped quintic of the
/// planned duration (for `objective = "time"` the ZVD baseline at the same residual), the
/// planned motion as its table.
fn motion_experiments(cfg: &PlanConfig, p: &Planned, rows: &[[f64; 7]]) -> Result<Vec<Experiment>> {
    let with = |traj: Trajectory| {
        let mut e = cfg.exp.clone();
        e.trajectory = traj;
        e
    };
    // the plain quintic at the plan's t_move (a robust plan may take longer, [robust] t_move)
    let t_plain = p.robust.as_ref().map_or(p.t_move, |info| info.nominal.t_move);
    let mut exps = vec![
        with(p.family.quintic(t_plain)),
        p.zvd.clone(),
        with(table_trajectory(&cfg.exp, rows)?),
    ];
    if let Some(info) = &p.robust {
        exps.push(with(info.nominal.trajectory.clone()));
        let mut shaped = with(info.shaped.exp.trajectory.clone());
        shaped.shaper = info.shaped.exp.shaper.clone();
        exps.push(shaped);
    }
    Ok(exps)
}

/// Run every motion on the accurate AMM and the FEM (the runs in parallel); `labels` the
/// motions' folder names and labels, in the order of `exps`.
pub(crate) fn run_motions(
    exps: Vec<Experiment>,
    labels: &[(&'static str, &'static str)],
    source: &str,
) -> Result<Vec<MotionRuns>> {
    let jobs: Vec<(usize, Solver)> = (0..exps.len())
        .flat_map(|k| [(k, Solver::Fem), (k, Solver::Amm)])
        .collect();
    let outcomes: Vec<Result<RunOutcome>> = jobs
        .par_iter()
        .map(|&(k, solver)| {
            let prepared = crate::run::prepare(exps[k].clone(), source, &RunSettings::new(solver))?;
            crate::run::run(&prepared, None)
        })
        .collect();
    let mut outcomes = outcomes.into_iter().collect::<Result<Vec<_>>>()?.into_iter();
    let mut motions = Vec::new();
    for (exp, &(key, label)) in exps.into_iter().zip(labels) {
        let (fem, amm) = (outcomes.next(), outcomes.next());
        let (Some(fem), Some(amm)) = (fem, amm) else {
            return Err(ApiError::solver(source, "a run of the comparison is missing"));
        };
        motions.push(MotionRuns {
            key,
            label,
            exp,
            amm,
            fem,
        });
    }
    Ok(motions)
}

/// Write each motion's runs into `dir/<key>/`.
pub(crate) fn write_runs(motions: &[MotionRuns], dir: &Path) -> Result<Vec<PathBuf>> {
    for m in motions {
        flexstar_io::output::ensure_writable_dir(&dir.join(m.key))?;
    }
    let jobs: Vec<(&MotionRuns, &RunOutcome)> = motions.iter().flat_map(|m| [(m, &m.amm), (m, &m.fem)]).collect();
    let written: Vec<Result<Vec<PathBuf>>> = jobs
        .par_iter()
        .map(|(m, run)| {
            let mut out = (*run).clone();
            crate::run::write_run(&mut out, &dir.join(m.key), false)?;
            Ok(out.files)
        })
        .collect();
    let mut files = Vec::new();
    for w in written {
        files.extend(w?);
    }
    Ok(files)
}

/// `plan.toml`, `plan.csv`, `plan.json` and `plan.md`, published together.
fn write_plan_files(cfg: &PlanConfig, o: &PlanOutcome, rows: &[[f64; 7]]) -> Result<Vec<PathBuf>> {
    let mut set = RunSet::begin(&o.dir)?;
    set.text("plan.toml", &plan_toml(cfg)?)?;
    set.text("plan.csv", &plan_csv(rows))?;
    let json = crate::plan_report::plan_json(cfg, o);
    set.text(
        "plan.json",
        &flexstar_model::response::sidecar_text(&o.dir.join("plan.json"), &json)?,
    )?;
    set.text("plan.md", &crate::plan_report::plan_markdown(cfg, o))?;
    set.commit()?;
    Ok(["plan.toml", "plan.csv", "plan.json", "plan.md"]
        .iter()
        .map(|n| o.dir.join(n))
        .collect())
}

/// `plan.csv`: the header and the rows, every number in its shortest exact form (the table read
/// back is the same spline).
pub(crate) fn plan_csv(rows: &[[f64; 7]]) -> String {
    let mut s = String::from("t,Gx,Gy,theta,s1,s2,s3\n");
    for r in rows {
        let cells: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

/// `plan.toml`: the file's experiment with `[plan]` and `[limits]` replaced by the table
/// trajectory of `plan.csv` (task columns). A relative `[load] file` is made absolute, as
/// `plan.toml` lives in another folder.
pub(crate) fn plan_toml(cfg: &PlanConfig) -> Result<String> {
    let mut table = cfg.table.clone();
    if let Some(toml::Value::Table(load)) = table.get_mut("load") {
        if let Some(toml::Value::String(f)) = load.get("file").cloned() {
            let dir = cfg.exp.source.parent().unwrap_or_else(|| Path::new("."));
            let joined = dir.join(&f);
            let abs = std::fs::canonicalize(&joined).unwrap_or(joined);
            load.insert("file".into(), toml::Value::String(abs.display().to_string()));
        }
    }
    let traj = toml::Table::from_iter([
        ("kind".to_string(), toml::Value::String("table".into())),
        ("file".to_string(), toml::Value::String("plan.csv".into())),
        ("columns".to_string(), toml::Value::String("task".into())),
    ]);
    table.insert("trajectory".into(), toml::Value::Table(traj));
    let body = toml::to_string(&table).map_err(|e| ApiError::Output(format!("plan.toml: {e}")))?;
    Ok(format!(
        "# Written by `flexstar plan {}`: the experiment with [plan] replaced by the planned motion\n\
         # (plan.csv, task-space columns); runnable by every command.\n{body}",
        cfg.exp.source.display()
    ))
}
