//! `fit` (the CLI's `flexstar fit CONFIG --measured FILE.csv [--out DIR]`, Python's
//! `flexstar.fit`; `docs/measured.md` section 4): the physical parameters of `[fit]` calibrated
//! on a recording by `flexstar_fit`, each evaluation one run of the accurate AMM with its N and
//! step frozen at the start's, and the files: `fit.toml` (the calibrated experiment, only when the
//! fit converged to identifiable estimates), `fit.json`, `fit.md`, `report.html` and the figures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_fit::{Fit, Iteration, Model, Param};
use flexstar_model::{Experiment, FitSection, SensorTable};
use flexstar_study::key::Key;

use crate::run::{RunSettings, Solver};
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
    /// The AMM's modes per beam N and step [s], frozen at the start's (4.5).
    pub modes: usize,
    pub dt: f64,
    /// The calibrated experiment (the document with the estimates patched in) when the fit is
    /// a calibration ([`Fit::calibrated`]).
    pub calibrated: Option<ExperimentDoc>,
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
    let recording = read_recording(measured)?;
    let dir = crate::case_dir(out, &input.exp)?;
    let notes = flexstar_model::identity::other_experiment_note(&dir, &input.exp)
        .into_iter()
        .collect();
    let fitted = fit_experiment(&input, &recording, &measured.display().to_string(), on_iteration)?;
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

/// Fit the experiment `input` (with its `[fit]`) to `recording` (named `name` in messages): the
/// checks of 4.1 before any run, the start run that fixes N and the step, the search; nothing is
/// written.
pub fn fit_experiment(
    input: &ExperimentDoc,
    recording: &SensorTable,
    name: &str,
    on_iteration: &dyn Fn(&Iteration),
) -> Result<Fitted> {
    let src = input.source.display().to_string();
    let section = fit_section(input)?;
    let (params, keys) = crate::fit_params::resolve(input, section)?;
    let (measured, weights) = channels(&input.exp, section, recording, name)?;
    let problem = flexstar_fit::Problem::new(params.clone(), &measured, &weights)
        .map_err(|e| ApiError::config(name, None, e.to_string()))?;
    let (modes, dt) = frozen_settings(input, &src)?;
    let model = AmmEvaluation {
        base: &input.doc,
        keys: keys.iter().map(Key::text).collect(),
        source: &input.source,
        modes,
        dt,
    };
    let settings = flexstar_fit::Settings {
        max_iterations: section.iterations(),
        ..flexstar_fit::Settings::default()
    };
    let fit = flexstar_fit::fit(&problem, &model, &settings, on_iteration).map_err(|e| match e {
        flexstar_fit::FitError::Unidentifiable(m) => ApiError::config(&src, Some("fit.params"), m),
        other => ApiError::solver(&src, other),
    })?;
    let calibrated = if fit.calibrated() {
        let cal = model.experiment(&fit.theta()).map_err(|e| ApiError::solver(&src, e))?;
        Some(with_damping_frequencies(cal, &input.doc)?)
    } else {
        None
    };
    Ok(Fitted {
        fit,
        input: input.clone(),
        params,
        recording: name.to_string(),
        measured,
        modes,
        dt,
        calibrated,
    })
}

/// The calibrated experiment with the frequencies its damping ratios hold at written out
/// (`damping.f_hz`) when the input left them to the start pose (4.9): the fitted ratio and that
/// frequency are the material's damping (Eq. D5's beta), which other moves and other start poses
/// keep, and a plan takes it.
fn with_damping_frequencies(cal: ExperimentDoc, input: &toml::Table) -> Result<ExperimentDoc> {
    let given = flexstar_study::patch::get_dotted(input, "damping.f_hz").is_some();
    let Some(f) = cal
        .exp
        .damping
        .f_hz
        .filter(|_| !given && cal.exp.damping.zeta.is_some())
    else {
        return Ok(cal);
    };
    let mut doc = cal.doc.clone();
    let value = toml::Value::try_from(f).map_err(|e| ApiError::Output(format!("damping.f_hz: {e}")))?;
    flexstar_study::patch::set_dotted(&mut doc, "damping.f_hz", value).map_err(ApiError::Output)?;
    ExperimentDoc::from_table(doc, &cal.source)
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

/// The recording's channels in the order of the experiment's sensor columns, with their units
/// and weights; a column the recording lacks is an error unless its sensor's weight is 0 (then
/// it is left out). The recording must be on the run's sensor times.
fn channels(exp: &Experiment, section: &FitSection, rec: &SensorTable, name: &str) -> Result<(SensorTable, Vec<f64>)> {
    let problem = exp.problem().map_err(ApiError::from_model)?;
    let sensors = problem.sensors();
    check_times(exp, sensors.rate_hz(), &rec.t, name)?;
    let mut table = SensorTable::new(rec.t.clone());
    let mut weights = Vec::new();
    for s in sensors.list() {
        for column in s.columns() {
            let w = section.weight(&s.name, &column);
            match rec.column(&column) {
                Some(v) => {
                    table.push_column(column, s.unit(), v.to_vec());
                    weights.push(w);
                }
                None if w == 0.0 => {}
                None => {
                    return Err(ApiError::config(
                        name,
                        None,
                        format!(
                            "the recording has no column {column} (sensor {}); its columns are {}; \
                             give it weight 0 in [fit] weights to fit without it",
                            s.name,
                            rec.header()[1..].join(", ")
                        ),
                    ))
                }
            }
        }
    }
    Ok((table, weights))
}

/// The recording's times are the run's sensor times (`k / rate_hz`, or the output times).
fn check_times(exp: &Experiment, rate_hz: Option<f64>, t: &[f64], name: &str) -> Result<()> {
    let expected = match rate_hz {
        Some(rate) => flexstar_model::sensors::daq::sample_times(rate, exp.time.t_end),
        None => exp.time.output_times(),
    };
    let what = match rate_hz {
        Some(rate) => format!("k / {rate} Hz up to time.t_end = {} s", exp.time.t_end),
        None => format!(
            "the output times, every {} s up to {} s",
            exp.time.dt_out, exp.time.t_end
        ),
    };
    let bad = if t.len() != expected.len() {
        Some(format!(
            "{} samples, the run's sensors read {}",
            t.len(),
            expected.len()
        ))
    } else {
        t.iter()
            .zip(&expected)
            .position(|(a, b)| (a - b).abs() > 1e-9 * b.abs().max(1.0))
            .map(|k| format!("sample {} is at t = {} s, the run's at {} s", k + 1, t[k], expected[k]))
    };
    match bad {
        Some(why) => Err(ApiError::config(
            name,
            Some("t"),
            format!("the recording is not on the run's sensor times ({what}): {why}"),
        )),
        None => Ok(()),
    }
}

/// The accurate AMM's N and step at the start (the experiment's own `[amm]`, N chosen by its
/// tolerance): one run, whose settings every evaluation then keeps (4.5).
fn frozen_settings(input: &ExperimentDoc, src: &str) -> Result<(usize, f64)> {
    let prepared = crate::run::prepare(model_experiment(input.exp.clone()), src, &RunSettings::new(Solver::Amm))?;
    let r = crate::run::solve(&prepared, None)?;
    let modes = r
        .info
        .modes
        .ok_or_else(|| ApiError::solver(src, "the AMM run reports no N"))?;
    Ok((modes, r.info.dt))
}

/// The experiment as the model of the recording reads it: the sensors without their noise (the
/// model's readings are the expected values, 4.1).
fn model_experiment(mut exp: Experiment) -> Experiment {
    for s in &mut exp.sensors {
        s.noise = None;
        s.seed = None;
    }
    exp
}

/// One evaluation: the document patched at the keys, loaded and checked as a file, run on the
/// AMM at the frozen N and step.
struct AmmEvaluation<'a> {
    base: &'a toml::Table,
    keys: Vec<String>,
    source: &'a Path,
    modes: usize,
    dt: f64,
}

impl AmmEvaluation<'_> {
    /// The experiment at `theta`.
    fn experiment(&self, theta: &[f64]) -> std::result::Result<ExperimentDoc, String> {
        let values: Vec<toml::Value> = theta.iter().map(|&v| toml::Value::Float(v)).collect();
        let doc = flexstar_study::patch::case_document(self.base, &self.keys, &values)?;
        ExperimentDoc::from_table(doc, self.source).map_err(|e| e.to_string())
    }
}

impl Model for AmmEvaluation<'_> {
    fn evaluate(&self, theta: &[f64]) -> std::result::Result<SensorTable, String> {
        let exp = model_experiment(self.experiment(theta)?.exp);
        let settings = RunSettings {
            modes: Some(self.modes),
            dt: Some(self.dt),
            ..RunSettings::new(Solver::Amm)
        };
        let src = self.source.display().to_string();
        let prepared = crate::run::prepare(exp, &src, &settings).map_err(|e| e.to_string())?;
        let r = crate::run::solve(&prepared, None).map_err(|e| e.to_string())?;
        r.sensors.ok_or_else(|| "the run read no sensors".to_string())
    }
}

/// A recording already on the run's sensor times: a CSV whose header is `t` and sensor columns
/// (what `<stem>-sensors.csv` holds), every cell a number.
pub fn read_recording(path: &Path) -> Result<SensorTable> {
    let src = path.display();
    let bad = |reason: String| ApiError::config(&src, None, reason);
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| bad(format!("cannot read the recording: {e}")))?;
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| bad(format!("cannot read the header: {e}")))?
        .iter()
        .map(str::to_string)
        .collect();
    if header.first().map(String::as_str) != Some("t") || header.len() < 2 {
        return Err(bad(format!(
            "the header must be t and the sensor columns, got {}",
            header.join(",")
        )));
    }
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
    for (k, row) in reader.records().enumerate() {
        let row = row.map_err(|e| bad(format!("row {}: {e}", k + 2)))?;
        if row.len() != header.len() {
            return Err(bad(format!(
                "row {} has {} cells, the header {}",
                k + 2,
                row.len(),
                header.len()
            )));
        }
        for (c, cell) in row.iter().enumerate() {
            let v: f64 = cell
                .parse()
                .map_err(|_| bad(format!("row {}, column {}: {cell:?} is not a number", k + 2, header[c])))?;
            cols[c].push(v);
        }
    }
    let mut cols = cols.into_iter();
    let mut table = SensorTable::new(cols.next().unwrap_or_default());
    for (name, values) in header.into_iter().skip(1).zip(cols) {
        table.push_column(name, "", values);
    }
    Ok(table)
}
