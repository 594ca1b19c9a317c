//! `run`: one solver on one experiment (the CLI's `flexstar run`, Python's `flexstar.run`):
//! the settings applied over the experiment, the feasibility preflight, the drive dispatch
//! (prescribed motion or direct problem), the solve, the sidecar and the run's files.

use std::path::{Path, PathBuf};

use flexstar_kinematics::CheckedMotion;

use flexstar_io::run_set::RunSet;
use flexstar_model::config::check_step;
use flexstar_model::response::sidecar_text;
use flexstar_model::{
    AmmModel, DriveKind, DriveSettings, Experiment, ForceSamples, ModeFamily, Response, RobotGeometry,
};

use crate::solver_errors::{from_amm, from_fem};
use crate::{ApiError, Result};

pub use flexstar_solve::Solver;

/// Actuator forces that replace the experiment's `[drive]` (the direct problem).
#[derive(Debug, Clone, PartialEq)]
pub enum Forces {
    /// A CSV whose header starts with `t` and names `Fa1, Fa2, Fa3` (`--forces FILE`).
    File(PathBuf),
    /// Samples `Fa_i(t)` [N] at increasing times [s] (Python's `forces=` array).
    Samples(ForceSamples),
}

/// What a run may change over its experiment (every field optional, as the CLI's flags).
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    pub solver: Solver,
    /// AMM mode family (overrides `[amm] family`).
    pub family: Option<ModeFamily>,
    /// AMM modes per beam N, rigid ones included (overrides `[amm] modes` and `tol`).
    pub modes: Option<usize>,
    /// AMM equations (overrides `[amm] model`).
    pub model: Option<AmmModel>,
    /// AMM error tolerance [%] (overrides `[amm] tol` and `modes`).
    pub tol: Option<f64>,
    /// FEM elements in the whole star (overrides `[fem] elements`).
    pub elements: Option<usize>,
    /// Integration step [s] (overrides `[amm] dt` or `[fem] dt`).
    pub dt: Option<f64>,
    /// Actuator forces replacing the `[drive]`.
    pub forces: Option<Forces>,
    /// Also draw the figures in `DIR/<name>/figures/`.
    pub figures: bool,
}

impl RunSettings {
    /// The experiment as it is: no override.
    pub fn new(solver: Solver) -> Self {
        RunSettings {
            solver,
            family: None,
            modes: None,
            model: None,
            tol: None,
            elements: None,
            dt: None,
            forces: None,
            figures: false,
        }
    }
}

/// An experiment with a run's settings applied and checked: ready to solve.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The resolved experiment (what the sidecar records).
    pub exp: Experiment,
    /// Its physics, as the solver takes it (built once, here).
    pub problem: flexstar_model::Problem,
    pub solver: Solver,
    /// The file stem of the run: `amm-<family>`, `fem`, `amm-<family>-direct`, `fem-direct`.
    pub stem: String,
    /// The direct problem (forces or servo)?
    pub direct: bool,
    /// Notes for the user (e.g. forces replacing the `[drive]`).
    pub notes: Vec<String>,
    /// Where the experiment came from, first in every message (a file name, `<dict>`).
    pub source: String,
    figures: bool,
    /// The preflight's proof that the motion (a servo's reference) is feasible over the span,
    /// handed to the solver so that it does not scan it again; `None` for a forces-driven run.
    checked: Option<CheckedMotion>,
    /// The experiment keys a flag set, with the flag (`amm.modes`, `--modes`): a solver's refusal
    /// of such a value is the flag's error.
    flags: Vec<(&'static str, &'static str)>,
}

impl Prepared {
    /// An AMM error of this run: a refused setting that a flag gave is the flag's error
    /// (`--modes: the enriched family needs N >= 4 ...`), else as [`from_amm`].
    fn amm_error(&self, e: flexstar_amm::AmmError) -> ApiError {
        if let flexstar_amm::AmmError::InvalidSetting { key, reason } = &e {
            if let Some((k, flag)) = self.flags.iter().find(|(k, _)| k == key) {
                return ApiError::flag_at(flag, k, reason.clone());
            }
        }
        from_amm(&self.source, e)
    }

    /// One line that says what will be solved (`case3: AMM, tol = 0.2 %, enriched`).
    pub fn describe(&self) -> String {
        match self.solver {
            Solver::Amm => format!(
                "{}: AMM, {}, {}",
                self.exp.name,
                self.exp.amm.mode_count(),
                self.exp.amm.family
            ),
            Solver::Fem => format!("{}: FEM, {} elements", self.exp.name, self.exp.fem.elements),
        }
    }
}

/// The outcome of a run: the response, its sidecar document and the files written (if any).
#[derive(Debug, Clone)]
pub struct RunOutcome {
    pub response: Response,
    /// The sidecar JSON as written next to the CSV (provenance, run info, validity, experiment).
    pub sidecar: flexstar_model::RunSidecar,
    /// The file stem (`amm-enriched`, `fem-direct`, ...).
    pub stem: String,
    /// The resolved experiment.
    pub exp: Experiment,
    /// The small-deflection warning (`None` when the run stays in range).
    pub warning: Option<String>,
    /// Files written, in order (empty until [`write_run`]).
    pub files: Vec<PathBuf>,
    /// The main CSV (set by [`write_run`]).
    pub csv: Option<PathBuf>,
}

impl RunOutcome {
    /// The residual peak of |dG| after the motion [m] (the sidecar's `residual_G_peak_m`);
    /// `None` when there is none (no rest before `t_end`, G pinned by the family).
    pub fn residual_g_peak_m(&self) -> Option<f64> {
        self.sidecar.residual.as_ref()?.g_peak_m.filter(|v| v.is_finite())
    }

    /// The sidecar document as written (keys in alphabetical order).
    pub fn sidecar_json(&self) -> Result<serde_json::Value> {
        Ok(flexstar_model::response::sidecar_value(
            std::path::Path::new(&format!("{}.json", self.stem)),
            &self.sidecar,
        )?)
    }
}

/// Apply `settings` to `exp` (from `source`) and check everything before any work: the step,
/// the feasibility scan of the motion (a forces-driven run: its start), the flags that do not
/// apply to the solver, the resolved experiment.
pub fn prepare(mut exp: Experiment, source: &str, settings: &RunSettings) -> Result<Prepared> {
    let mut notes = Vec::new();
    if let Some(f) = &settings.forces {
        let (drive, what) = forces_drive(f)?;
        if exp.drive.is_direct() {
            notes.push(format!("note: {what} replaces the [drive] of {source}"));
        }
        exp.drive = drive;
    }
    if let Some(dt) = settings.dt {
        check_step("--dt", dt, exp.time.dt_out).map_err(|e| ApiError::from_flag("--dt", e))?;
    }
    let checked = preflight(&exp, source)?;
    let direct = exp.drive.is_direct();
    let stem = match settings.solver {
        Solver::Amm => apply_amm(&mut exp, source, settings)?,
        Solver::Fem => apply_fem(&mut exp, source, settings)?,
    };
    exp.validate().map_err(|e| {
        let flag = match &e {
            flexstar_model::ModelError::Invalid { key, .. } => flag_of(key, settings),
            _ => None,
        };
        match flag {
            Some(flag) => ApiError::from_flag(flag, e),
            None => ApiError::model_in(format!("{source} with the command-line flags"), Path::new(source), e),
        }
    })?;
    let stem = if direct { format!("{stem}-direct") } else { stem };
    let problem = exp
        .problem()
        .map_err(|e| ApiError::model_in(source, Path::new(source), e))?;
    // a sensor where a sleeve passes (docs/sensors.md Eq. S10), before any work
    flexstar_kinematics::check_sensor_mounts(&exp, problem.sensors())
        .map_err(|e| ApiError::model_in(source, Path::new(source), e))?;
    if settings.solver == Solver::Amm {
        if let Some(lost) = flexstar_amm::attachments_lost(exp.amm.family, &problem) {
            notes.push(format!("note: {source}: {lost}"));
        }
    }
    Ok(Prepared {
        exp,
        problem,
        solver: settings.solver,
        stem,
        direct,
        notes,
        source: source.to_string(),
        figures: settings.figures,
        checked,
        flags: FLAG_KEYS
            .iter()
            .filter_map(|k| flag_of(k, settings).map(|f| (*k, f)))
            .collect(),
    })
}

/// The experiment keys the flags of [`RunSettings`] set (see [`flag_of`]).
const FLAG_KEYS: [&str; 5] = ["amm.modes", "amm.tol", "amm.dt", "fem.dt", "fem.elements"];

/// The flag of `settings` that set the experiment key `key` (`amm.tol` from `--tol`), if one did:
/// an invalid value is then the flag's error, not the file's.
fn flag_of(key: &str, settings: &RunSettings) -> Option<&'static str> {
    match key {
        "amm.modes" if settings.modes.is_some() => Some("--modes"),
        "amm.tol" if settings.tol.is_some() => Some("--tol"),
        "amm.dt" | "fem.dt" if settings.dt.is_some() => Some("--dt"),
        "fem.elements" if settings.elements.is_some() => Some("--elements"),
        _ => None,
    }
}

/// The `[drive]` of a forces override and how to name it in a note.
fn forces_drive(f: &Forces) -> Result<(DriveSettings, String)> {
    match f {
        Forces::File(path) => Ok((
            DriveSettings::forces_file(path)?,
            format!("--forces {}", path.display()),
        )),
        Forces::Samples(s) => {
            ForceSamples::check(&s.t, &s.fa).map_err(|reason| ApiError::config("forces", None, reason.to_string()))?;
            let drive = DriveSettings {
                kind: DriveKind::Forces,
                // no file: the samples were given in memory (the sidecar records this name)
                file: Some(PathBuf::from("<forces array>")),
                samples: Some(s.clone()),
                ..DriveSettings::default()
            };
            Ok((drive, "forces".to_string()))
        }
    }
}

/// The feasibility scan of both solvers, here too so that nothing is created for a motion that
/// is refused (a forces-driven run: its start only; its motion is checked as it goes), on the
/// robot the experiment describes (the paper's form, or its robot as built).
fn preflight(exp: &Experiment, source: &str) -> Result<Option<CheckedMotion>> {
    let robot = flexstar_model::Robot::from_params(&exp.robot).map_err(ApiError::from_model)?;
    match robot.paper_form() {
        Some(p) => preflight_on(p, exp, source),
        None => preflight_on(&robot, exp, source),
    }
}

/// [`preflight`] on the geometry `robot`.
fn preflight_on<K: RobotGeometry + ?Sized>(robot: &K, exp: &Experiment, source: &str) -> Result<Option<CheckedMotion>> {
    let servo = exp.drive.kind == DriveKind::Servo;
    if exp.drive.is_direct() && !servo {
        let s0 = exp
            .trajectory
            .s(robot, 0.0)
            .map_err(|e| ApiError::infeasible(source, 0.0, e))?;
        flexstar_kinematics::check_configuration(robot, s0).map_err(|violation| {
            ApiError::infeasible(source, 0.0, flexstar_kinematics::Infeasible { t: 0.0, violation })
        })?;
        Ok(None)
    } else {
        let step = flexstar_kinematics::preflight_step(exp.time.dt_out);
        flexstar_kinematics::check_motion(robot, &exp.trajectory, exp.time.t_end, step)
            .map(Some)
            .map_err(|e| ApiError::infeasible(source, e.t, e))
    }
}

/// The AMM's settings over `[amm]`; the stem `amm-<family>`.
fn apply_amm(exp: &mut Experiment, source: &str, s: &RunSettings) -> Result<String> {
    if s.elements.is_some() {
        return Err(ApiError::config(
            source,
            None,
            "--elements applies to --solver fem only",
        ));
    }
    if s.modes.is_some() && s.tol.is_some() {
        // the file's refusal of `modes` with `tol`, in the flags' words
        let reason = flexstar_model::config::modes_with_tol_reason("--modes", "--tol");
        return Err(ApiError::flag("--modes, --tol", reason));
    }
    if let Some(f) = s.family {
        exp.amm.family = f;
    }
    if let Some(n) = s.modes {
        exp.amm.modes = Some(n);
        exp.amm.tol = None;
    }
    if let Some(p) = s.tol {
        exp.amm.tol = Some(p);
        exp.amm.modes = None;
    }
    if let Some(m) = s.model {
        exp.amm.model = m;
    }
    if s.dt.is_some() {
        exp.amm.dt = s.dt;
    }
    Ok(format!("amm-{}", exp.amm.family))
}

/// The FEM's settings over `[fem]`; the stem `fem`.
fn apply_fem(exp: &mut Experiment, source: &str, s: &RunSettings) -> Result<String> {
    if s.family.is_some() || s.modes.is_some() || s.model.is_some() || s.tol.is_some() {
        return Err(ApiError::config(
            source,
            None,
            "--family, --modes, --model and --tol apply to --solver amm only",
        ));
    }
    if let Some(n) = s.elements {
        exp.fem.elements = n;
    }
    if s.dt.is_some() {
        exp.fem.dt = s.dt;
    }
    Ok("fem".to_string())
}

/// Solve a prepared run; `progress` gets the fraction done (an FEM run at every output time, an
/// AMM run at its end), 0..1. A servo run's response gets its tracking errors `e1..e3`.
pub fn solve(p: &Prepared, progress: Option<&(dyn Fn(f64) + Sync)>) -> Result<Response> {
    let exp = &p.exp;
    let settings = flexstar_solve::Settings::of(exp, p.solver);
    let r = flexstar_solve::response(&p.problem, settings, p.checked.as_ref(), progress).map_err(|e| match e {
        flexstar_solve::SolveError::Amm(e) => p.amm_error(e),
        flexstar_solve::SolveError::Fem(e) => from_fem(&p.source, e),
        flexstar_solve::SolveError::Drive(e) => ApiError::config(&p.source, Some("drive"), e.to_string()),
        flexstar_solve::SolveError::Tracking(e) => ApiError::solver(&p.source, e),
        flexstar_solve::SolveError::Robot(e) => ApiError::from_model(e),
    })?;
    if let Some(reason) = r.not_finite_reason() {
        return Err(ApiError::config(&p.source, Some("robot"), reason));
    }
    Ok(r)
}

/// Solve a prepared run and build its outcome (sidecar document, validity warning); nothing is
/// written.
pub fn run(p: &Prepared, progress: Option<&(dyn Fn(f64) + Sync)>) -> Result<RunOutcome> {
    let response = solve(p, progress)?;
    // each beam judged against its own length (docs/as-built.md 6)
    let check = flexstar_metrics::small_deflection_check(&response, &p.exp.robot);
    let warning = check.as_ref().map(|v| format!("{}: {} {v}", p.source, p.stem));
    let mut sidecar = response.sidecar(&p.exp, &crate::provenance(), check);
    sidecar.residual = residual_keys(p, &response)?;
    if p.solver == Solver::Amm {
        let mut why = outside_envelope(&p.exp, warning.is_none());
        if p.exp.robot.as_built.is_some() {
            why.push("the robot is one as built; the envelope was validated on three equal beams".to_string());
        }
        sidecar.validated_envelope = Some(why.is_empty());
        sidecar.validated_envelope_reasons = Some(why);
    }
    Ok(RunOutcome {
        response,
        sidecar,
        stem: p.stem.clone(),
        exp: p.exp.clone(),
        warning,
        files: Vec::new(),
        csv: None,
    })
}

/// The residual vibration after the motion's end (`docs/motions.md` section 2) as the sidecar's
/// keys ([`flexstar_model::ResidualKeys`]), of the paper's robot or one as built (the hold is the
/// first period at the robot's own final pose). An AMM run of the pinned-free family has G
/// pinned by its modes (`phi(0) = 0`): its residual of G is null, with a note.
fn residual_keys(p: &Prepared, r: &Response) -> Result<Option<flexstar_model::ResidualKeys>> {
    use flexstar_modal::settle::{dwells_with_hold, residual_with_hold, settle_hold_s};
    let solver_error = |e| ApiError::solver(&p.source, e);
    // the final pose's modes once, for the residual and the last dwell
    let hold = settle_hold_s(&p.exp).map_err(solver_error)?;
    let res = residual_with_hold(&p.exp, r, hold);
    let pinned = p.solver == Solver::Amm && p.exp.amm.family == ModeFamily::PinnedFree;
    let mut keys = flexstar_metrics::residual::sidecar_keys(res.as_ref(), p.exp.report.settle_tol, pinned);
    // per dwell (docs/motions.md 2.5): an addition, the keys above stay as they are
    keys.dwells = dwells_with_hold(&p.exp, r, pinned, hold).map_err(solver_error)?;
    Ok(Some(keys))
}

/// Why an AMM run is outside the validated envelope of the accurate model (`docs/validation.md`
/// section 8, [`flexstar_metrics::envelope`]); empty inside it.
fn outside_envelope(exp: &Experiment, small_deflection: bool) -> Vec<String> {
    let attachments = !(exp.payload.is_none() && exp.damping.is_none() && exp.load.is_none() && exp.gravity.is_none());
    flexstar_metrics::envelope::outside_envelope(
        &exp.robot,
        exp.amm.model,
        exp.amm.family,
        attachments,
        small_deflection,
    )
}

/// The line `flexstar run` prints for an AMM run outside the validated envelope (`None` inside
/// it or for an FEM run).
pub fn envelope_line(sidecar: &flexstar_model::RunSidecar) -> Option<String> {
    if sidecar.validated_envelope != Some(false) {
        return None;
    }
    let why = sidecar.validated_envelope_reasons.as_deref().unwrap_or_default();
    Some(format!(
        "outside the validated envelope of the accurate AMM (docs/validation.md): {}; the error estimate is not vouched for here",
        why.join("; ")
    ))
}

/// The sidecar's residual after the motion in one line (`None` when the motion does not rest
/// before `t_end`): peak |dG| and tip after `t_rest`, and the settling time.
pub fn residual_line(sidecar: &flexstar_model::RunSidecar) -> Option<String> {
    // a value the document would write as null (absent or not finite) reads as absent
    let finite = |v: Option<f64>| v.filter(|x| x.is_finite());
    let keys = sidecar.residual.as_ref()?;
    let t_rest = finite(keys.t_rest)?;
    let g = finite(keys.g_peak_m).map_or("n/a (G pinned)".to_string(), |v| format!("{v:.3e} m"));
    let tip = finite(keys.tip_peak_m).unwrap_or(f64::NAN);
    let settle = match finite(keys.settle_s) {
        Some(t) => format!("settled at {t:.3} s"),
        None if keys.settled == Some(false) => flexstar_metrics::residual::not_settled_text(
            t_rest,
            sidecar.experiment.time.t_end,
            finite(keys.g_decay_per_s),
            finite(keys.settle_predicted_s),
            finite(keys.settle_hold_s).unwrap_or(f64::NAN),
        ),
        None => "settling n/a".to_string(),
    };
    let tracking = (
        finite(keys.tracking_peak_m.flatten()),
        finite(keys.tracking_end_m.flatten()),
    );
    let sliders = match tracking {
        (Some(peak), Some(end)) => format!("; {}", flexstar_metrics::residual::tracking_text(peak, end)),
        _ => String::new(),
    };
    let tol = finite(keys.settle_tol).unwrap_or(f64::NAN);
    let friction = keys.friction.as_ref().map_or(String::new(), |f| {
        format!("; {}", flexstar_metrics::residual::friction_rest_text(f))
    });
    Some(format!(
        "after t_rest = {} s: peak |dG| = {g}, peak |tip| = {tip:.3e} m, {settle} (band {} m){sliders}{friction}",
        flexstar_io::output::fmt_sig(t_rest, 5),
        flexstar_io::output::fmt_display(tol)
    ))
}

/// The sidecar's residual per dwell (`docs/motions.md` 2.5), one line each
/// ([`flexstar_metrics::dwell::dwell_text`]), when the motion has more than one dwell (a single
/// dwell is [`residual_line`]'s window); empty otherwise.
pub fn dwell_lines(sidecar: &flexstar_model::RunSidecar) -> Vec<String> {
    match sidecar.residual.as_ref().and_then(|k| k.dwells.as_ref()) {
        Some(d) if d.len() > 1 => d.iter().map(flexstar_metrics::dwell::dwell_text).collect(),
        _ => Vec::new(),
    }
}

/// Columns a direct run's file puts right after the fixed ones (a file contract, `docs/outputs.md`).
fn direct_columns(servo: bool) -> Vec<&'static str> {
    let mut v = vec!["Gx", "Gy", "theta"];
    if servo {
        v.extend(["e1", "e2", "e3"]);
    }
    v
}

/// Write a run's files in `dir` (already `DIR/<name>/`): `<stem>.csv` (a direct run: the
/// sliders first, then the fixed columns, the pose, a servo's errors), `<stem>-shapes.csv`,
/// `<stem>-sensors.csv` with `[[sensors]]` (`docs/sensors.md`),
/// `<stem>-dwells.csv` when the motion has a dwell (`docs/motions.md` 2.5), `<stem>.json` (the
/// outcome's sidecar) and with `figures` the figures in `dir/figures/`.
/// The CSV files and the sidecar are one run set ([`RunSet`]): published together.
pub fn write_run(out: &mut RunOutcome, dir: &Path, figures: bool) -> Result<()> {
    let (r, exp, stem) = (&out.response, &out.exp, &out.stem);
    let direct = exp.drive.is_direct();
    let csv = dir.join(format!("{stem}.csv"));
    // the run's three files are published together: a kill or a full disk keeps the old set
    let mut set = RunSet::begin(dir)?;
    let csv_name = format!("{stem}.csv");
    if direct {
        let servo = exp.drive.kind == DriveKind::Servo;
        r.stage_csv_ordered(&mut set, &csv_name, &["s1", "s2", "s3"], &direct_columns(servo))?;
    } else {
        r.stage_csv(&mut set, &csv_name)?;
    }
    let shapes = dir.join(format!("{stem}-shapes.csv"));
    r.stage_shapes_csv(&mut set, &format!("{stem}-shapes.csv"))?;
    r.stage_sensors_csv(&mut set, stem)?;
    let frames_hash = flexstar_model::animation::stage_run_frames(&r.frames, &mut set, stem)?;
    out.sidecar.frames_hash.clone_from(&frames_hash);
    let dwells = out.sidecar.residual.as_ref().and_then(|k| k.dwells.clone());
    if let Some(d) = &dwells {
        set.text(&format!("{stem}-dwells.csv"), &flexstar_model::sidecar::dwells_csv(d))?;
    }
    let json = dir.join(format!("{stem}.json"));
    let doc = flexstar_model::response::sidecar_value(&json, &out.sidecar)?;
    set.text(&format!("{stem}.json"), &sidecar_text(&json, &doc)?)?;
    set.commit()?;
    out.files.extend([csv.clone(), shapes, json]);
    if r.sensors.is_some() {
        out.files.push(dir.join(format!("{stem}-sensors.csv")));
    }
    if dwells.is_some() {
        out.files.push(dir.join(format!("{stem}-dwells.csv")));
    }
    if frames_hash.is_some() {
        out.files
            .extend(flexstar_model::animation::frames_file_names(stem).map(|n| dir.join(n)));
    }
    if figures {
        let figs = crate::figures::run_figures(exp, stem, r, direct, dir, dwells.as_deref())?;
        out.files.extend(figs);
    }
    out.csv = Some(csv);
    Ok(())
}

/// The whole `flexstar run`: prepare, create `out/<name>/` (checked writable before any work),
/// solve, write. `on_prepared` sees the prepared run before the solve (the CLI prints notes).
pub fn run_to_dir(
    exp: Experiment,
    source: &str,
    settings: &RunSettings,
    out: &Path,
    on_prepared: impl FnOnce(&Prepared),
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<RunOutcome> {
    let p = prepare(exp, source, settings)?;
    let dir = crate::case_dir(out, &p.exp)?;
    on_prepared(&p);
    let mut outcome = run(&p, progress)?;
    write_run(&mut outcome, &dir, p.figures)?;
    Ok(outcome)
}

/// Every column of a response by name, in the order of its CSV (`t` first, the fixed columns,
/// then the extra ones): what fronts hand out as arrays.
pub fn columns(r: &Response) -> Vec<(String, &[f64])> {
    let fixed: Vec<&[f64]> = std::iter::once(r.t.as_slice())
        .chain(r.w_g.iter().map(Vec::as_slice))
        .chain(r.w_tip.iter().map(Vec::as_slice))
        .chain(r.fa.iter().map(Vec::as_slice))
        .collect();
    let mut out: Vec<(String, &[f64])> = flexstar_model::response::RESPONSE_HEADER
        .iter()
        .map(|s| s.to_string())
        .zip(fixed)
        .collect();
    out.extend(r.extra.iter().map(|c| (c.name.clone(), c.values.as_slice())));
    out
}
