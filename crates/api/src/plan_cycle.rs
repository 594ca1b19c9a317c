//! `flexstar plan` for a whole cycle (`docs/motions.md` 4.12): every move planned alone
//! (`flexstar_plan::plan_cycle`), the planned cycle (Eq. C3) and the plain quintic cycle run on
//! the accurate AMM and the FEM, both measured per dwell with the plain cycle's windows (2.5),
//! and the files: `plan.toml`, `plan.csv`, `plan.json`, `plan.md`, `plain/`, `planned/` (with
//! each run's `-dwells.csv` and figures).

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_io::run_set::RunSet;
use flexstar_model::{Experiment, ModeFamily};
use flexstar_plan::{PlanConfig, PlannedCycle};

use crate::plan::{from_plan, load_plan, run_motions, table_trajectory, MotionRuns};
use crate::run::RunOutcome;
use crate::{ApiError, Result};

/// The two motions of a cycle's comparison, in report order: folder name and label.
pub const CYCLE_MOTIONS: [(&str, &str); 2] = [("plain", "plain quintic cycle"), ("planned", "planned cycle")];

/// One dwell of the cycle: the residual peak of |dG| [m] in it for each motion and solver, and
/// the planned move's own residual from rest (the single plan's AMM window peak).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CycleDwell {
    /// 1-based, the dwell after move `dwell`.
    pub dwell: usize,
    pub t_start: f64,
    pub t_end: f64,
    pub plain_amm_m: Option<f64>,
    pub plain_fem_m: Option<f64>,
    pub planned_amm_m: Option<f64>,
    pub planned_fem_m: Option<f64>,
    /// `planned_fem_m / plain_fem_m` (the target's measure).
    pub ratio_fem: Option<f64>,
    /// The move planned from rest: its AMM peak of |dG| over the planner's window [m] (Eq. C2's
    /// first term), against which the cycle's value shows the coupling.
    pub from_rest_amm_m: f64,
}

/// What `flexstar plan` made of a cycle.
#[derive(Debug, Clone)]
pub struct CycleOutcome {
    pub planned: PlannedCycle,
    pub motions: Vec<MotionRuns>,
    pub dwells: Vec<CycleDwell>,
    pub dir: PathBuf,
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
    /// Wall time of the whole command [s].
    pub wall_s: f64,
}

/// Is the plan file a cycle (`[plan] points` or a `via` cycle)? Reads and checks it (4.8, 4.12).
pub fn is_cycle(config: &Path) -> Result<bool> {
    Ok(load_plan(config)?.cycle.is_some())
}

/// The whole command for a cycle: plan every move, run both cycles on both solvers, measure
/// each dwell, write everything into `out/<name>/`. `on_planned` sees the plan before the runs.
pub fn plan_cycle_to_dir(config: &Path, out: &Path, on_planned: impl FnOnce(&PlannedCycle)) -> Result<CycleOutcome> {
    let started = Instant::now();
    let cfg = load_plan(config)?;
    let source = config.display().to_string();
    if cfg.cycle.is_none() {
        return Err(ApiError::solver(
            &source,
            "not a cycle: [plan] has from and to (use plan_to_dir)",
        ));
    }
    let dir = crate::case_dir(out, &cfg.exp)?;
    let notes = flexstar_model::identity::other_experiment_note(&dir, &cfg.exp)
        .into_iter()
        .collect();
    let planned = flexstar_plan::plan_cycle(&cfg).map_err(|e| from_plan(&source, e))?;
    on_planned(&planned);
    let rows = cycle_rows(&cfg.exp, &planned)?;
    let mut planned_exp = cfg.exp.clone();
    planned_exp.trajectory = table_trajectory(&cfg.exp, &rows)?;
    let mut motions = run_motions(vec![cfg.exp.clone(), planned_exp], &CYCLE_MOTIONS, &source)?;
    for m in &mut motions {
        for run in [&mut m.amm, &mut m.fem] {
            measure_dwells(&cfg.exp, run, &source)?;
        }
    }
    let dwells = cycle_dwells(&planned, &motions);
    let mut files = write_cycle_runs(&motions, &dir)?;
    let outcome = CycleOutcome {
        planned,
        motions,
        dwells,
        dir,
        files: Vec::new(),
        notes,
        wall_s: started.elapsed().as_secs_f64(),
    };
    files.extend(write_cycle_files(&cfg, &outcome, &rows)?);
    Ok(CycleOutcome { files, ..outcome })
}

/// The rows of `plan.csv` (Eq. C3): `t,Gx,Gy,theta,s1,s2,s3` from the cycle's start to the end
/// of its last move at `dt_out` (the last dwell holds the last row, as a table does).
pub fn cycle_rows(exp: &Experiment, p: &PlannedCycle) -> Result<Vec<[f64; 7]>> {
    let (t0, t1, dt) = (p.cycle.t0, p.cycle.last_move_end(), exp.time.dt_out);
    let n = ((t1 - t0) / dt).round() as usize;
    (0..=n)
        .map(|k| {
            let t = if k == n { t1 } else { t0 + k as f64 * dt };
            let pose = p.pose(t)?;
            let s = flexstar_model::geometry::inverse_kinematics(&exp.robot, [pose[0], pose[1]], pose[2])?;
            Ok([t, pose[0], pose[1], pose[2], s[0], s[1], s[2]])
        })
        .collect::<std::result::Result<Vec<_>, flexstar_model::ModelError>>()
        .map_err(ApiError::from_model)
}

/// Measure `run` per dwell with the windows of the plain cycle `plain` (`docs/motions.md` 4.12:
/// the planned table has the plain cycle's moves, times and dwell poses).
fn measure_dwells(plain: &Experiment, run: &mut RunOutcome, source: &str) -> Result<()> {
    let pinned = run.stem.starts_with("amm") && run.exp.amm.family == ModeFamily::PinnedFree;
    let dwells =
        flexstar_modal::settle::run_dwells(plain, &run.response, pinned).map_err(|e| ApiError::solver(source, e))?;
    if let Some(keys) = run.sidecar.residual.as_mut() {
        keys.dwells = dwells;
    }
    Ok(())
}

/// The per-dwell comparison of the two motions.
fn cycle_dwells(p: &PlannedCycle, motions: &[MotionRuns]) -> Vec<CycleDwell> {
    let peak = |key: &str, fem: bool, k: usize| -> Option<f64> {
        let m = motions.iter().find(|m| m.key == key)?;
        let run = if fem { &m.fem } else { &m.amm };
        run.sidecar.residual.as_ref()?.dwells.as_ref()?.get(k)?.g_peak_m
    };
    p.moves
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let (plain_fem_m, planned_fem_m) = (peak("plain", true, k), peak("planned", true, k));
            CycleDwell {
                dwell: k + 1,
                t_start: m.span.t_end(),
                t_end: m.span.t_end() + m.span.dwell,
                plain_amm_m: peak("plain", false, k),
                plain_fem_m,
                planned_amm_m: peak("planned", false, k),
                planned_fem_m,
                ratio_fem: planned_fem_m.zip(plain_fem_m).map(|(a, b)| a / b),
                from_rest_amm_m: m.planned.eval.window_peak_m,
            }
        })
        .collect()
}

/// Each motion's runs into `dir/<key>/`, with their figures (the `-dG` figure per dwell).
fn write_cycle_runs(motions: &[MotionRuns], dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for m in motions {
        let sub = dir.join(m.key);
        flexstar_io::output::ensure_writable_dir(&sub)?;
        for run in [&m.amm, &m.fem] {
            let mut out = run.clone();
            crate::run::write_run(&mut out, &sub, true)?;
            files.extend(out.files);
        }
    }
    Ok(files)
}

/// `plan.toml`, `plan.csv`, `plan.json` and `plan.md`, published together.
fn write_cycle_files(cfg: &PlanConfig, o: &CycleOutcome, rows: &[[f64; 7]]) -> Result<Vec<PathBuf>> {
    let mut set = RunSet::begin(&o.dir)?;
    set.text("plan.toml", &crate::plan::plan_toml(cfg)?)?;
    set.text("plan.csv", &crate::plan::plan_csv(rows))?;
    let json = crate::plan_cycle_report::cycle_json(cfg, o);
    set.text(
        "plan.json",
        &flexstar_model::response::sidecar_text(&o.dir.join("plan.json"), &json)?,
    )?;
    set.text("plan.md", &crate::plan_cycle_report::cycle_markdown(cfg, o))?;
    set.commit()?;
    Ok(["plan.toml", "plan.csv", "plan.json", "plan.md"]
        .iter()
        .map(|n| o.dir.join(n))
        .collect())
}
