//! `export` (the CLI's `flexstar export DIR --rate HZ`, `docs/motions.md`, "Export for the
//! controller"): a run's or a plan's prescribed motion as the setpoint table of a motion
//! controller, `setpoints.csv` with its header `setpoints.json`, written into that folder.
//!
//! Every row is one sample `t = k / rate` [s] from 0 to the end of the motion: the sliders'
//! positions `s_i` [m] along their axes (`docs/conventions.md`), velocities [m/s], accelerations
//! [m/s^2] and jerks [m/s^3], exact derivatives of the motion's own definition
//! ([`Trajectory::jets4`]), and the feed-forward forces `F_i` [N] along `+u_i`: the accurate AMM's
//! `Fa_i` (Eq. 33; payload, damping, load and gravity included when the experiment has them)
//! from a solve at the output step `1 / rate`.

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde_json::{Map, Value};

use flexstar_io::output::fmt_number;
use flexstar_io::run_set::RunSet;
use flexstar_model::trajectory::Jet4;
use flexstar_model::{
    AmmSettings, DriveKind, Experiment, Impulse, Response, ShapedMotion, Sliders, Trajectory, ViaMotion, ViaPoint,
};
use flexstar_plan::Limits;

use crate::run::{RunSettings, Solver};
use crate::{ApiError, Result};

/// The highest rate the export accepts [Hz].
pub const MAX_RATE_HZ: f64 = 100_000.0;

/// The header of `setpoints.csv`, exactly (`docs/outputs.md`).
pub const SETPOINTS_HEADER: [&str; 16] = [
    "t", "s1", "s2", "s3", "v1", "v2", "v3", "a1", "a2", "a3", "j1", "j2", "j3", "F1", "F2", "F3",
];

/// The table and its header document.
pub const SETPOINTS_CSV: &str = "setpoints.csv";
pub const SETPOINTS_JSON: &str = "setpoints.json";

/// Points per sample interval at which the interpolation bounds take the sup of `|s''|`,
/// `|s'''|` and `|s''''|` (the peaks of the table are those of its samples).
pub const BOUND_REFINE: usize = 8;

/// What the export is asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSettings {
    /// The controller's sampling rate [Hz]: `2 f1 <= rate <= 100 kHz`.
    pub rate_hz: f64,
    /// The run to export (its file stem, `amm-enriched`) when the folder holds several.
    pub run: Option<String>,
}

/// Where the motion was read from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum MotionSource {
    /// A run's sidecar `<stem>.json` (`flexstar run`).
    Run { stem: String, sidecar: PathBuf },
    /// `plan.json`'s `via_points` (`flexstar plan`), the experiment of the runs in `planned/`.
    Plan { plan: PathBuf, sidecar: PathBuf },
}

impl MotionSource {
    /// The file the motion came from, first in messages.
    fn file(&self) -> String {
        match self {
            MotionSource::Run { sidecar, .. } => sidecar.display().to_string(),
            MotionSource::Plan { plan, .. } => plan.display().to_string(),
        }
    }
}

/// A motion to export: the experiment (with the exact motion as its trajectory), where it came
/// from, and the plan's `[limits]` (a plan only).
#[derive(Debug, Clone)]
pub struct Motion {
    pub exp: Experiment,
    pub source: MotionSource,
    pub limits: Option<Limits>,
}

/// Peaks over the samples, per slider: `|v|` [m/s], `|a|` [m/s^2], `|j|` [m/s^3], `|F|` [N].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Peaks {
    pub v_m_per_s: [f64; 3],
    pub a_m_per_s2: [f64; 3],
    pub j_m_per_s3: [f64; 3],
    #[serde(rename = "F_N")]
    pub f_n: [f64; 3],
}

/// What a controller's interpolation between two samples `h = 1 / rate` [s] apart can miss, per
/// slider, from the sups of the motion's derivatives (taken at [`BOUND_REFINE`] points per
/// interval): linear interpolation of positions `sup|s''| h^2 / 8` [m] and of velocities
/// `sup|s'''| h^2 / 8` [m/s]; cubic Hermite (PVT: position and velocity at both ends) positions
/// `sup|s''''| h^4 / 384` [m] and velocities `sqrt(3) / 216 sup|s''''| h^3` [m/s].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InterpolationBounds {
    pub linear_position_m: [f64; 3],
    pub linear_velocity_m_per_s: [f64; 3],
    pub cubic_position_m: [f64; 3],
    pub cubic_velocity_m_per_s: [f64; 3],
}

/// One of the plan's `[limits]` against the table's peak (largest over the sliders).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitCheck {
    /// `v_max`, `a_max` or `Fa_max`.
    pub limit: &'static str,
    pub unit: &'static str,
    pub value: f64,
    pub peak: f64,
    pub satisfied: bool,
}

/// One row of `setpoints.csv`: time [s], each slider's jets (m, m/s, m/s^2, m/s^3, m/s^4) and
/// feed-forward force [N].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub jets: [Jet4; 3],
    pub f: [f64; 3],
}

/// What `export` wrote.
#[derive(Debug, Clone)]
pub struct ExportOutcome {
    /// The folder written into (the one read).
    pub dir: PathBuf,
    /// `setpoints.csv` and `setpoints.json`.
    pub files: Vec<PathBuf>,
    pub source: MotionSource,
    pub experiment: String,
    pub rate_hz: f64,
    /// The samples, as written.
    pub samples: Vec<Sample>,
    /// The first elastic frequency at the final pose [Hz] (the rate rule's).
    pub f1_hz: f64,
    pub peaks: Peaks,
    pub bounds: InterpolationBounds,
    /// The plan's limits against the peaks (empty for a run).
    pub limits: Vec<LimitCheck>,
}

impl ExportOutcome {
    /// What the CLI prints: the table, the peaks, the interpolation bounds, the limits.
    pub fn summary(&self) -> Vec<String> {
        let max = |v: [f64; 3]| v.iter().fold(0.0f64, |a, b| a.max(*b));
        let b = &self.bounds;
        let mut lines = vec![
            format!(
                "export: {} rows at {} Hz ({} s) to {} (f1 = {:.3} Hz at the final pose)",
                self.samples.len(),
                self.rate_hz,
                flexstar_io::output::fmt_sig(self.samples.last().map_or(0.0, |s| s.t), 6),
                self.dir.join(SETPOINTS_CSV).display(),
                self.f1_hz
            ),
            format!(
                "export: peaks |v| {:.4} m/s, |a| {:.4} m/s^2, |j| {:.4e} m/s^3, |F| {:.4} N",
                max(self.peaks.v_m_per_s),
                max(self.peaks.a_m_per_s2),
                max(self.peaks.j_m_per_s3),
                max(self.peaks.f_n)
            ),
            format!(
                "export: interpolation between samples misses at most: linear {:.3e} m (a_max h^2/8), {:.3e} m/s; \
                 cubic PVT {:.3e} m, {:.3e} m/s",
                max(b.linear_position_m),
                max(b.linear_velocity_m_per_s),
                max(b.cubic_position_m),
                max(b.cubic_velocity_m_per_s)
            ),
        ];
        lines.extend(self.limits.iter().map(|l| {
            format!(
                "export: limit {} = {} {}: peak {:.4} {} ({})",
                l.limit,
                fmt_number(l.value),
                l.unit,
                l.peak,
                l.unit,
                if l.satisfied { "satisfied" } else { "EXCEEDED" }
            )
        }));
        lines
    }
}

/// The whole `flexstar export`: read the motion of `dir` (a run folder or a plan folder), check
/// the drive and the rate before any work, solve the accurate AMM at the output step `1 / rate`,
/// and write `setpoints.csv` and `setpoints.json` into `dir` together (whole or not at all).
pub fn export(dir: &Path, settings: &ExportSettings) -> Result<ExportOutcome> {
    check_rate_range(settings.rate_hz)?;
    let motion = read_motion(dir, settings.run.as_deref())?;
    check_prescribed(&motion)?;
    let f1_hz = first_frequency(&motion)?;
    check_rate(settings.rate_hz, f1_hz, &motion.exp)?;
    flexstar_io::output::ensure_writable_dir(dir)?;
    let response = feed_forward(&motion, settings.rate_hz)?;
    let h = 1.0 / settings.rate_hz;
    let samples = samples(&motion.exp, &response, h)?;
    let peaks = peaks(&samples);
    let bounds = bounds(&motion.exp, samples.last().map_or(0.0, |s| s.t), h)?;
    let limits = limit_checks(motion.limits.as_ref(), &peaks);
    let mut outcome = ExportOutcome {
        dir: dir.to_path_buf(),
        files: Vec::new(),
        source: motion.source.clone(),
        experiment: motion.exp.name.clone(),
        rate_hz: settings.rate_hz,
        samples,
        f1_hz,
        peaks,
        bounds,
        limits,
    };
    write(&mut outcome, &motion, &response)?;
    Ok(outcome)
}

/// `--rate` must be a positive number of Hz, at most [`MAX_RATE_HZ`].
fn check_rate_range(rate: f64) -> Result<()> {
    if !rate.is_finite() || rate <= 0.0 {
        return Err(ApiError::flag(
            "--rate",
            format!("need a positive rate in Hz, got {rate}"),
        ));
    }
    if rate > MAX_RATE_HZ {
        return Err(ApiError::flag(
            "--rate",
            format!("{rate} Hz is above 100 kHz ({MAX_RATE_HZ} Hz), the highest rate the export writes"),
        ));
    }
    Ok(())
}

/// The rate must resolve the robot's first elastic mode (`rate >= 2 f1`) and give at least two
/// samples within `time.t_end`.
fn check_rate(rate: f64, f1_hz: f64, exp: &Experiment) -> Result<()> {
    if rate < 2.0 * f1_hz {
        return Err(ApiError::flag(
            "--rate",
            format!(
                "{rate} Hz is below twice the robot's first elastic frequency at the final pose \
                 (f1 = {f1_hz:.3} Hz): give --rate >= {} Hz",
                flexstar_io::output::fmt_at_least(2.0 * f1_hz, 4)
            ),
        ));
    }
    if 1.0 / rate > exp.time.t_end {
        return Err(ApiError::flag(
            "--rate",
            format!(
                "{rate} Hz gives one sample over time.t_end = {} s: give --rate >= {} Hz",
                exp.time.t_end,
                fmt_number(1.0 / exp.time.t_end)
            ),
        ));
    }
    Ok(())
}

/// The export needs the prescribed motion: a direct run (forces or servo) has none to send.
fn check_prescribed(m: &Motion) -> Result<()> {
    let kind = m.exp.drive.kind;
    if kind == DriveKind::Motion {
        return Ok(());
    }
    let name = serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string));
    Err(ApiError::config(
        m.source.file(),
        Some("drive.kind"),
        format!(
            "the run is a direct run (drive.kind = \"{}\"): the export needs the prescribed motion \
             (drive.kind = \"motion\"); export a run of the trajectory itself",
            name.unwrap_or_default()
        ),
    ))
}

/// The first elastic frequency [Hz] of the accurate AMM, sliders locked, at the final pose of the
/// motion (its pose at `t_rest`, or at `time.t_end` for a motion that never rests).
pub fn first_frequency(m: &Motion) -> Result<f64> {
    let exp = &m.exp;
    let file = m.source.file();
    let err = |e| crate::modal::from_modal(Some(&file), exp.time.t_end, e);
    let f = match flexstar_modal::analysis::final_pose_frequencies(exp, 1).map_err(err)? {
        Some(f) => f,
        None => {
            let pose = flexstar_modal::pose::pose_at_time(exp, exp.time.t_end).map_err(err)?;
            let model = flexstar_modal::analysis::amm_pose_model(exp).map_err(err)?;
            model
                .frequencies_at(&pose, Sliders::Locked, 1)
                .map_err(|e| crate::solver_errors::from_amm(&file, e))?
        }
    };
    f.first()
        .copied()
        .ok_or_else(|| ApiError::solver(&file, "the modal analysis found no elastic mode"))
}

// ---- reading the motion ----------------------------------------------------------------------

/// The motion of `dir`: `plan.json` when present (a plan folder), else its run sidecar (`run`
/// names one when there are several).
pub fn read_motion(dir: &Path, run: Option<&str>) -> Result<Motion> {
    if !dir.is_dir() {
        return Err(ApiError::config(dir.display(), None, "not a folder"));
    }
    flexstar_io::run_set::recover(dir)?;
    let plan = dir.join("plan.json");
    if plan.is_file() {
        if let Some(stem) = run {
            let reason = format!(
                "{} is a plan folder (plan.json): it exports the planned motion, not a run `{stem}`",
                dir.display()
            );
            return Err(ApiError::flag("--run", reason));
        }
        return read_plan(&plan, dir);
    }
    let runs = run_sidecars(dir)?;
    let (stem, doc) = choose_run(dir, runs, run)?;
    let sidecar = dir.join(format!("{stem}.json"));
    let mut exp = recorded_experiment(&doc, &sidecar)?;
    read_inputs(&mut exp, &sidecar)?;
    Ok(Motion {
        exp,
        source: MotionSource::Run { stem, sidecar },
        limits: None,
    })
}

/// The run sidecars of `dir` (`<stem>.json` beside `<stem>.csv`, with a `label` and an
/// `experiment`), by stem in name order.
fn run_sidecars(dir: &Path) -> Result<Vec<(String, Value)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| ApiError::config(dir.display(), None, e.to_string()))?;
    let mut stems: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.strip_suffix(".json").map(str::to_string))
        .filter(|stem| dir.join(format!("{stem}.csv")).is_file())
        .collect();
    stems.sort();
    let mut runs = Vec::new();
    for stem in stems {
        let doc = read_json(&dir.join(format!("{stem}.json")))?;
        if doc.get("label").is_some_and(Value::is_string) && doc.get("experiment").is_some_and(Value::is_object) {
            runs.push((stem, doc));
        }
    }
    Ok(runs)
}

/// The run to export among `runs`: the one named by `--run`, or the only one.
fn choose_run(dir: &Path, runs: Vec<(String, Value)>, run: Option<&str>) -> Result<(String, Value)> {
    let stems: Vec<String> = runs.iter().map(|(s, _)| s.clone()).collect();
    match (run, runs.len()) {
        (_, 0) => Err(ApiError::config(
            dir.display(),
            None,
            "holds neither a run's sidecar (<stem>.json beside <stem>.csv, written by `flexstar run`) \
             nor plan.json (written by `flexstar plan`): nothing to export",
        )),
        (Some(want), _) => runs.into_iter().find(|(s, _)| s == want).ok_or_else(|| {
            ApiError::flag(
                "--run",
                format!("no run `{want}` in {} (its runs: {})", dir.display(), stems.join(", ")),
            )
        }),
        (None, 1) => Ok(runs.into_iter().next().expect("one run")),
        (None, _) => Err(ApiError::config(
            dir.display(),
            None,
            format!("holds several runs ({}): choose one with --run STEM", stems.join(", ")),
        )),
    }
}

/// A plan folder's motion: `plan.json`'s `via_points` as the exact `kind = "via"`,
/// `rest = false` motion, its `limits`, on the experiment of the runs in `planned/` (the first
/// sidecar by name).
fn read_plan(plan: &Path, dir: &Path) -> Result<Motion> {
    let doc = read_json(plan)?;
    let field = |key: &str| {
        doc.get(key)
            .cloned()
            .ok_or_else(|| ApiError::config(plan.display(), Some(key), "missing"))
    };
    let points: Vec<ViaPoint> = from_json(plan, "via_points", field("via_points")?)?;
    let limits: Option<Limits> = from_json(plan, "limits", field("limits")?)?;
    let planned = dir.join(crate::plan::MOTIONS[2].0);
    let (stem, run) = run_sidecars(&planned)?.into_iter().next().ok_or_else(|| {
        ApiError::config(
            planned.display(),
            None,
            "holds no run sidecar: the planned motion's experiment is unknown (rerun `flexstar plan`)",
        )
    })?;
    let sidecar = planned.join(format!("{stem}.json"));
    let mut exp = recorded_experiment(&run, &sidecar)?;
    exp.trajectory = Trajectory::Via(ViaMotion::new(points, false));
    exp.trajectory
        .validate(&exp.robot)
        .map_err(|e| ApiError::model_in(plan.display(), plan, e))?;
    read_inputs(&mut exp, &sidecar)?;
    Ok(Motion {
        exp,
        source: MotionSource::Plan {
            plan: plan.to_path_buf(),
            sidecar,
        },
        limits,
    })
}

/// The resolved experiment a sidecar document records (`experiment`), with its file and hash
/// (`experiment_file`, `experiment_hash`) and a shaped motion rebuilt from its base and impulses;
/// the tables it reads are not read yet ([`read_inputs`]).
fn recorded_experiment(doc: &Value, sidecar: &Path) -> Result<Experiment> {
    let mut value = doc.get("experiment").cloned().unwrap_or(Value::Null);
    let impulses = take_shaped(&mut value, sidecar)?;
    let mut exp: Experiment = from_json(sidecar, "experiment", value)?;
    if let Some(impulses) = impulses {
        let base = Box::new(exp.trajectory.clone());
        exp.trajectory = Trajectory::Shaped(ShapedMotion { base, impulses });
    }
    if let Some((file, hash)) = flexstar_model::identity::recorded(doc) {
        exp.source = PathBuf::from(file);
        exp.hash = hash;
    }
    Ok(exp)
}

/// Read the tables `exp` reads (a motion table, a load table) again, from beside the experiment
/// file it records.
fn read_inputs(exp: &mut Experiment, sidecar: &Path) -> Result<()> {
    let source = exp.source.clone();
    let in_sidecar = |e: flexstar_model::ModelError| ApiError::model_in(sidecar.display(), sidecar, e);
    exp.trajectory.read_file(&source, &exp.robot).map_err(in_sidecar)?;
    exp.load.read_file(&source).map_err(in_sidecar)
}

/// A shaped motion is written as `{kind = "shaped", base, impulses}`, which the experiment's
/// `[trajectory]` does not read: put its base in its place and return the impulses. The resolved
/// `[shaper]` (its frequencies, impulses, the `auto` choice) is dropped: the impulses carry it,
/// and the section as written back is not one a file may hold.
fn take_shaped(exp: &mut Value, sidecar: &Path) -> Result<Option<Vec<Impulse>>> {
    let Some(traj) = exp.get_mut("trajectory") else {
        return Ok(None);
    };
    if traj.get("kind").and_then(Value::as_str) != Some("shaped") {
        return Ok(None);
    }
    let impulses = from_json(sidecar, "experiment.trajectory.impulses", traj["impulses"].take())?;
    *traj = traj["base"].take();
    if let Some(map) = exp.as_object_mut() {
        map.remove("shaper");
    }
    Ok(Some(impulses))
}

fn read_json(path: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ApiError::config(path.display(), None, format!("cannot read: {e}")))?;
    serde_json::from_str(&text).map_err(|e| ApiError::config(path.display(), None, format!("not JSON: {e}")))
}

fn from_json<T: serde::de::DeserializeOwned>(path: &Path, key: &str, v: Value) -> Result<T> {
    serde_json::from_value(v).map_err(|e| ApiError::config(path.display(), Some(key), e.to_string()))
}

// ---- the samples -------------------------------------------------------------------------------

/// The experiment of the feed-forward: `exp` at the output step `1 / rate` [s] on the accurate
/// AMM (enriched family, full equations). A run of the accurate AMM keeps its choice of N (its
/// tolerance, else its fixed N) and its step when that is at most `1 / rate`; any other run gets
/// the accurate AMM's defaults. The FEM's step is dropped (not solved here; it may exceed the
/// new output step).
pub fn feed_forward_experiment(exp: &Experiment, rate: f64) -> Experiment {
    let mut e = exp.clone();
    let dt_out = 1.0 / rate;
    e.time.dt_out = dt_out;
    e.amm = accurate_settings(&exp.amm, dt_out);
    e.fem.dt = None;
    e
}

fn accurate_settings(amm: &AmmSettings, dt_out: f64) -> AmmSettings {
    let accurate = AmmSettings::accurate();
    if amm.family != accurate.family || amm.model != accurate.model {
        return accurate;
    }
    AmmSettings {
        modes: if amm.tol.is_some() { None } else { amm.modes },
        tol: amm.tol,
        dt: amm.dt.filter(|dt| *dt <= dt_out * (1.0 + 1e-12)),
        ..accurate
    }
}

/// The accurate AMM's response at the output step `1 / rate` (its `Fa` columns are the
/// feed-forward).
fn feed_forward(m: &Motion, rate: f64) -> Result<Response> {
    let exp = feed_forward_experiment(&m.exp, rate);
    let prepared = crate::run::prepare(exp, &m.source.file(), &RunSettings::new(Solver::Amm))?;
    crate::run::solve(&prepared, None)
}

/// The end of the motion [s]: `t_rest`, or `time.t_end` for a motion that never rests.
pub fn motion_end(exp: &Experiment) -> f64 {
    exp.trajectory.t_rest().unwrap_or(exp.time.t_end)
}

/// The samples: the response's output times (every `h` [s]) from 0 to the first at or after the
/// end of the motion, each with the motion's exact jets and the response's `Fa`.
fn samples(exp: &Experiment, r: &Response, h: f64) -> Result<Vec<Sample>> {
    let last = ((motion_end(exp) / h - 1e-9).ceil() as usize).min(r.t.len().saturating_sub(1));
    (0..=last)
        .map(|k| {
            let t = r.t[k];
            let jets = exp.trajectory.jets4(&exp.robot, t)?;
            Ok(Sample {
                t,
                jets,
                f: [r.fa[0][k], r.fa[1][k], r.fa[2][k]],
            })
        })
        .collect::<std::result::Result<_, flexstar_model::ModelError>>()
        .map_err(ApiError::from_model)
}

/// The largest `|x|` per slider over `items`.
fn peak_of<T>(items: &[T], x: impl Fn(&T, usize) -> f64) -> [f64; 3] {
    std::array::from_fn(|i| items.iter().fold(0.0f64, |a, s| a.max(x(s, i).abs())))
}

fn peaks(samples: &[Sample]) -> Peaks {
    Peaks {
        v_m_per_s: peak_of(samples, |s, i| s.jets[i].d1),
        a_m_per_s2: peak_of(samples, |s, i| s.jets[i].d2),
        j_m_per_s3: peak_of(samples, |s, i| s.jets[i].d3),
        f_n: peak_of(samples, |s, i| s.f[i]),
    }
}

/// The interpolation bounds over `[0, t_last]` [s] for samples `h` [s] apart (see
/// [`InterpolationBounds`]).
fn bounds(exp: &Experiment, t_last: f64, h: f64) -> Result<InterpolationBounds> {
    let n = ((t_last / h).round() as usize).max(1) * BOUND_REFINE;
    let jets = (0..=n)
        .map(|k| exp.trajectory.jets4(&exp.robot, t_last * k as f64 / n as f64))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let (a, j, snap) = (
        peak_of(&jets, |s, i| s[i].d2),
        peak_of(&jets, |s, i| s[i].d3),
        peak_of(&jets, |s, i| s[i].d4),
    );
    Ok(InterpolationBounds {
        linear_position_m: a.map(|x| x * h * h / 8.0),
        linear_velocity_m_per_s: j.map(|x| x * h * h / 8.0),
        cubic_position_m: snap.map(|x| x * h.powi(4) / 384.0),
        cubic_velocity_m_per_s: snap.map(|x| x * 3f64.sqrt() / 216.0 * h.powi(3)),
    })
}

/// The plan's limits against the peaks (largest over the sliders).
fn limit_checks(limits: Option<&Limits>, p: &Peaks) -> Vec<LimitCheck> {
    let Some(l) = limits else {
        return Vec::new();
    };
    let max = |v: [f64; 3]| v.iter().fold(0.0f64, |a, b| a.max(*b));
    [
        ("v_max", "m/s", l.v_max, max(p.v_m_per_s)),
        ("a_max", "m/s^2", l.a_max, max(p.a_m_per_s2)),
        ("j_max", "m/s^3", l.j_max, max(p.j_m_per_s3)),
        ("Fa_max", "N", l.fa_max, max(p.f_n)),
    ]
    .into_iter()
    .filter_map(|(limit, unit, value, peak)| {
        value.map(|value| LimitCheck {
            limit,
            unit,
            value,
            peak,
            satisfied: peak <= value,
        })
    })
    .collect()
}

// ---- the files -----------------------------------------------------------------------------------

/// `setpoints.csv`: the header and one row per sample, numbers in shortest round-trip form.
pub fn setpoints_csv(samples: &[Sample]) -> String {
    let mut s = SETPOINTS_HEADER.join(",") + "\n";
    for row in samples {
        let j = &row.jets;
        let cells = std::iter::once(row.t)
            .chain(j.iter().map(|x| x.v))
            .chain(j.iter().map(|x| x.d1))
            .chain(j.iter().map(|x| x.d2))
            .chain(j.iter().map(|x| x.d3))
            .chain(row.f);
        s += &cells.map(fmt_number).collect::<Vec<_>>().join(",");
        s.push('\n');
    }
    s
}

/// `setpoints.json`: provenance, the experiment (name, file, hash), the source, the rate and
/// the rows, the columns and their units, the peaks, the interpolation bounds, f1, the
/// feed-forward's solver settings, the plan's limits.
fn setpoints_json(o: &ExportOutcome, m: &Motion, r: &Response) -> Value {
    let mut doc: Map<String, Value> = crate::provenance().fields();
    doc.extend(flexstar_model::identity::fields(&m.exp));
    doc.insert("command".into(), "export".into());
    doc.insert("table".into(), SETPOINTS_CSV.into());
    doc.insert("experiment".into(), m.exp.name.clone().into());
    doc.insert("source_dir".into(), absolute(&o.dir).into());
    doc.insert("source".into(), json(&o.source));
    doc.insert("rate_hz".into(), o.rate_hz.into());
    doc.insert("step_s".into(), (1.0 / o.rate_hz).into());
    doc.insert("rows".into(), o.samples.len().into());
    doc.insert("t_last_s".into(), o.samples.last().map_or(0.0, |s| s.t).into());
    doc.insert("t_rest".into(), m.exp.trajectory.t_rest().into());
    doc.insert("columns".into(), SETPOINTS_HEADER.to_vec().into());
    doc.insert(
        "column_units".into(),
        flexstar_model::quantity::column_units(&SETPOINTS_HEADER),
    );
    doc.insert("peaks".into(), json(&o.peaks));
    doc.insert("interpolation_bounds".into(), json(&o.bounds));
    doc.insert("f1_hz".into(), o.f1_hz.into());
    doc.insert("feed_forward".into(), json(&r.info));
    let limits = if m.limits.is_some() {
        json(&o.limits)
    } else {
        Value::Null
    };
    doc.insert("limits".into(), limits);
    Value::Object(doc)
}

/// A part of the document (plain numbers, strings and lists: it always serialises).
fn json<T: Serialize>(v: &T) -> Value {
    serde_json::to_value(v).unwrap_or(Value::Null)
}

fn absolute(p: &Path) -> String {
    std::fs::canonicalize(p)
        .unwrap_or_else(|_| p.to_path_buf())
        .display()
        .to_string()
}

/// Write both files into the outcome's folder as one set.
fn write(o: &mut ExportOutcome, m: &Motion, r: &Response) -> Result<()> {
    let mut set = RunSet::begin(&o.dir)?;
    set.text(SETPOINTS_CSV, &setpoints_csv(&o.samples))?;
    let json_path = o.dir.join(SETPOINTS_JSON);
    let doc = setpoints_json(o, m, r);
    set.text(
        SETPOINTS_JSON,
        &flexstar_model::response::sidecar_text(&json_path, &doc)?,
    )?;
    set.commit()?;
    o.files = vec![o.dir.join(SETPOINTS_CSV), json_path];
    Ok(())
}
