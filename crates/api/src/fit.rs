//! `fit` (the CLI's `flexstar fit CONFIG --measured FILE.csv [--out DIR]`, Python's
//! `flexstar.fit`; `docs/measured.md` section 4): the physical parameters of `[fit]` calibrated
//! on a recording by `flexstar_fit`, each evaluation one run of the accurate AMM with its N and
//! step frozen at the start's ([`crate::fit_model`]), the recording read and laid onto the run's
//! sensor times by `flexstar_measured` ([`crate::fit_data`]), and the files: `fit.toml` (the
//! calibrated experiment, only when the fit converged to identifiable estimates), `fit.json`,
//! `fit.md`, `report.html` and the figures ([`crate::fit_report`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_fit::{Fit, Iteration, Param};
use flexstar_model::{FitSection, SensorTable, Sensors};
use flexstar_study::key::Key;

use crate::fit_model::{AmmEvaluation, StartRun};
use crate::{ApiError, ExperimentDoc, Result};

/// A fit and what it was made of.
#[derive(Debug, Clone)]
pub struct Fitted {
    pub fit: Fit,
    /// The input experiment and its document.
    pub input: ExperimentDoc,
    /// The parameters as fitted (keys, boxes, starts).
    pub params: Vec<Param>,
    /// The recording's name (its file) in messages and reports.
    pub recording: String,
    /// The recording on the run's sensor times, its channels in the experiment's order.
    pub measured: SensorTable,
    /// The sensor columns the recording does not hold (not fitted).
    pub not_recorded: Vec<String>,
    /// The AMM's modes per beam N and step [s], frozen at the start's (4.5).
    pub modes: usize,
    pub dt: f64,
    /// The calibrated experiment (the document with the estimates patched in) when the fit is
    /// a calibration ([`Fit::calibrated`]).
    pub calibrated: Option<ExperimentDoc>,
    /// The FEM of the calibrated experiment against the recording and the AMM (4.9): per fitted
    /// channel, or why it could not run; `None` without a calibration.
    pub fem_check: Option<std::result::Result<Vec<FemCheck>, String>>,
}

/// One channel of the FEM's check of a calibration (`docs/measured.md` 4.9): RMS values in the
/// channel's unit over the recording's times.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FemCheck {
    pub column: String,
    pub unit: String,
    /// The noise level of Eq. LS2.
    pub noise: f64,
    /// The calibrated AMM's error against the recording (the fit's `rms_after`).
    pub rms_amm: f64,
    /// The calibrated FEM's error against the recording.
    pub rms_fem: f64,
    /// The two models' difference at the estimates.
    pub rms_fem_amm: f64,
}

/// What `flexstar fit` made.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    pub fitted: Fitted,
    /// `DIR/<name>/`.
    pub dir: PathBuf,
    pub files: Vec<PathBuf>,
    /// Notes for the user (another experiment's results in the folder).
    pub notes: Vec<String>,
    /// Wall time of the whole command [s].
    pub wall_s: f64,
}

/// The whole command: read and check the experiment, its `[fit]` and the recording (before any
/// run), fit, write everything into `out/<name>/` (checked writable before any work).
pub fn fit_to_dir(config: &Path, measured: &Path, out: &Path, on_iteration: &dyn Fn(&Iteration)) -> Result<FitOutcome> {
    let started = Instant::now();
    let input = ExperimentDoc::load(config)?;
    let dir = crate::case_dir(out, &input.exp)?;
    let notes = flexstar_model::identity::other_experiment_note(&dir, &input.exp)
        .into_iter()
        .collect();
    let fitted = fit_file(&input, measured, on_iteration)?;
    let mut outcome = FitOutcome {
        fitted,
        dir,
        files: Vec::new(),
        notes,
        wall_s: 0.0,
    };
    outcome.wall_s = started.elapsed().as_secs_f64();
    outcome.files = crate::fit_report::write(&outcome)?;
    Ok(outcome)
}

/// Fit the experiment `input` (with its `[fit]`) to the recording file `measured`, read as its
/// `[measured]` maps it and laid onto the run's sensor times (`docs/measured.md` section 1); the
/// checks of 4.1 and the reader's before any run; nothing is written.
pub fn fit_file(input: &ExperimentDoc, measured: &Path, on_iteration: &dyn Fn(&Iteration)) -> Result<Fitted> {
    let setup = Setup::new(input)?;
    let mut rec = crate::fit_data::read(measured, &input.exp, &setup.sensors)?;
    let start = crate::fit_model::start_run(input)?;
    let table = crate::fit_data::on_run_times(&mut rec, &start.sensors)?;
    setup.fit(input, &table, &measured.display().to_string(), start, on_iteration)
}

/// Fit the experiment `input` (with its `[fit]`) to `recording`, already on the run's sensor
/// times (what [`flexstar_measured::Recording::on_times`] returns), named `name` in messages:
/// the checks of 4.1 before any run, the start run that fixes N and the step, the search;
/// nothing is written.
pub fn fit_experiment(
    input: &ExperimentDoc,
    recording: &SensorTable,
    name: &str,
    on_iteration: &dyn Fn(&Iteration),
) -> Result<Fitted> {
    let setup = Setup::new(input)?;
    let run_t = crate::fit_data::sensor_times(&input.exp, &setup.sensors);
    crate::fit_data::window(&run_t, &recording.t, name)?;
    crate::fit_data::channels(&setup.sensors, setup.section, recording, name)?;
    let start = crate::fit_model::start_run(input)?;
    setup.fit(input, recording, name, start, on_iteration)
}

/// The bandwidth of Eq. LS18 (`docs/measured.md` 4.7): one period of the first elastic mode at the
/// motion's final pose (the accurate AMM, sliders locked, payload included: the slowest component
/// of the model's error) in samples of the recording; without a rest pose or a mode, the whole
/// record.
fn correlation_samples(exp: &flexstar_model::Experiment, t: &[f64]) -> usize {
    let n = t.len();
    let dt = match n {
        0 | 1 => return 0,
        _ => (t[n - 1] - t[0]) / (n - 1) as f64,
    };
    match flexstar_modal::analysis::final_pose_frequencies(exp, 1) {
        Ok(Some(f)) if f.first().is_some_and(|&f1| f1 > 0.0) => ((1.0 / (f[0] * dt)).round() as usize).min(n - 1),
        _ => n - 1,
    }
}

/// What the experiment says before any run: its `[fit]`, the parameters resolved against its
/// document, its sensors.
struct Setup<'a> {
    section: &'a FitSection,
    params: Vec<Param>,
    keys: Vec<Key>,
    sensors: Sensors,
}

impl<'a> Setup<'a> {
    fn new(input: &'a ExperimentDoc) -> Result<Self> {
        let section = fit_section(input)?;
        let (params, keys) = crate::fit_params::resolve(input, section)?;
        let problem = input.exp.problem().map_err(ApiError::from_model)?;
        Ok(Setup {
            section,
            params,
            keys,
            sensors: problem.sensors().clone(),
        })
    }

    /// The search on `recording` (on the run's sensor times) from the start's run `start`.
    fn fit(
        self,
        input: &ExperimentDoc,
        recording: &SensorTable,
        name: &str,
        start: StartRun,
        on_iteration: &dyn Fn(&Iteration),
    ) -> Result<Fitted> {
        let src = input.source.display().to_string();
        let data = crate::fit_data::channels(&self.sensors, self.section, recording, name)?;
        let window = crate::fit_data::window(&start.sensors.t, &recording.t, name)?;
        let problem = flexstar_fit::Problem::new(self.params.clone(), &data.table, &data.weights)
            .map_err(|e| ApiError::config(name, None, e.to_string()))?;
        let model = AmmEvaluation {
            base: &input.doc,
            keys: self.keys.iter().map(Key::text).collect(),
            source: &input.source,
            modes: start.modes,
            dt: start.dt,
            window,
            last: Default::default(),
            refused: Default::default(),
        };
        let settings = flexstar_fit::Settings {
            max_iterations: self.section.iterations(),
            starts: self.section.start_count(),
            correlation_samples: correlation_samples(&input.exp, &recording.t),
            ..flexstar_fit::Settings::default()
        };
        let fit = flexstar_fit::fit(&problem, &model, &settings, on_iteration).map_err(|e| match e {
            flexstar_fit::FitError::Unidentifiable(m) => ApiError::config(&src, Some("fit.params"), m),
            other => ApiError::solver(&src, other),
        })?;
        let calibrated = match fit.calibrated() {
            true => {
                let cal = model.experiment(&fit.theta()).map_err(|e| ApiError::solver(&src, e))?;
                Some(crate::fit_model::with_damping_frequencies(cal, &input.doc)?)
            }
            false => None,
        };
        let fem_check = calibrated.as_ref().map(|_| fem_check(&model, &fit, &data.table));
        Ok(Fitted {
            fit,
            input: input.clone(),
            params: self.params,
            recording: name.to_string(),
            measured: data.table,
            not_recorded: data.missing,
            modes: start.modes,
            dt: start.dt,
            calibrated,
            fem_check,
        })
    }
}

/// The FEM's check of a calibration (4.9): the FEM of the calibrated experiment, each fitted
/// channel's RMS error against the recording beside the AMM's, and the two models' difference.
fn fem_check(model: &AmmEvaluation, fit: &Fit, recording: &SensorTable) -> std::result::Result<Vec<FemCheck>, String> {
    let fem = crate::fit_model::fem_readings(model, &fit.theta())?;
    let rms = |a: &[f64], b: &[f64]| flexstar_fit::noise::rms(&a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<_>>());
    fit.channels
        .iter()
        .filter(|c| c.weight > 0.0)
        .map(|c| {
            let (Some(y), Some(f), Some(a)) = (
                recording.column(&c.column),
                fem.column(&c.column),
                fit.after.column(&c.column),
            ) else {
                return Err(format!("channel {} missing from the FEM's readings", c.column));
            };
            Ok(FemCheck {
                column: c.column.clone(),
                unit: c.unit.clone(),
                noise: c.noise,
                rms_amm: rms(a, y),
                rms_fem: rms(f, y),
                rms_fem_amm: rms(f, a),
            })
        })
        .collect()
}

/// The `[fit]` section, and sensors to fit to.
fn fit_section(input: &ExperimentDoc) -> Result<&FitSection> {
    let src = input.source.display().to_string();
    let section = input.exp.fit.as_ref().ok_or_else(|| {
        ApiError::config(
            &src,
            Some("fit"),
            "the experiment has no [fit] section: name the parameters to fit, \
             [fit] params = [{ key = \"payload.mass\", lo = 0.0, hi = 1.0 }]",
        )
    })?;
    if input.exp.sensors.is_empty() {
        return Err(ApiError::config(
            src,
            Some("sensors"),
            "the experiment has no [[sensors]]: a fit compares the model's sensor readings with the recording's",
        ));
    }
    Ok(section)
}
