//! The model of a recording in `flexstar fit` (`docs/measured.md` 4.2, 4.5): the accurate AMM
//! on the experiment patched at the fitted keys, its N and step frozen at those of the start's
//! run, its sensors without noise, its readings cut to the recording's times.

use std::ops::Range;
use std::path::Path;

use flexstar_fit::Model;
use flexstar_model::{Experiment, SensorTable};

use crate::run::{RunSettings, Solver};
use crate::{ApiError, ExperimentDoc, Result};

/// The start's run: the N and step it chose, its sensor readings.
#[derive(Debug, Clone)]
pub(crate) struct StartRun {
    pub modes: usize,
    pub dt: f64,
    pub sensors: SensorTable,
}

/// The accurate AMM at the start (the experiment's own `[amm]`, N chosen by its tolerance):
/// one run, whose N and step every evaluation then keeps (4.5).
pub(crate) fn start_run(input: &ExperimentDoc) -> Result<StartRun> {
    let src = input.source.display().to_string();
    let prepared = crate::run::prepare(noiseless(input.exp.clone()), &src, &RunSettings::new(Solver::Amm))?;
    let r = crate::run::solve(&prepared, None)?;
    let modes = r
        .info
        .modes
        .ok_or_else(|| ApiError::solver(&src, "the AMM run reports no N"))?;
    let sensors = r
        .sensors
        .ok_or_else(|| ApiError::solver(&src, "the AMM run read no sensors"))?;
    Ok(StartRun {
        modes,
        dt: r.info.dt,
        sensors,
    })
}

/// The experiment as the model of a recording reads it: its sensors without their noise (the
/// model's readings are the expected values, 4.2).
fn noiseless(mut exp: Experiment) -> Experiment {
    for s in &mut exp.sensors {
        s.noise = None;
        s.seed = None;
    }
    exp
}

/// One evaluation: the document patched at the keys, loaded and checked as a file, run on the
/// AMM at the frozen N and step, its readings at the sensor times `window` (the recording's).
pub(crate) struct AmmEvaluation<'a> {
    pub base: &'a toml::Table,
    pub keys: Vec<String>,
    pub source: &'a Path,
    pub modes: usize,
    pub dt: f64,
    pub window: Range<usize>,
}

impl AmmEvaluation<'_> {
    /// The experiment at `theta`.
    pub fn experiment(&self, theta: &[f64]) -> std::result::Result<ExperimentDoc, String> {
        let values: Vec<toml::Value> = theta.iter().map(|&v| toml::Value::Float(v)).collect();
        let doc = flexstar_study::patch::case_document(self.base, &self.keys, &values)?;
        ExperimentDoc::from_table(doc, self.source).map_err(|e| e.to_string())
    }
}

impl Model for AmmEvaluation<'_> {
    fn evaluate(&self, theta: &[f64]) -> std::result::Result<SensorTable, String> {
        let exp = noiseless(self.experiment(theta)?.exp);
        let settings = RunSettings {
            modes: Some(self.modes),
            dt: Some(self.dt),
            ..RunSettings::new(Solver::Amm)
        };
        let src = self.source.display().to_string();
        let prepared = crate::run::prepare(exp, &src, &settings).map_err(|e| e.to_string())?;
        let r = crate::run::solve(&prepared, None).map_err(|e| e.to_string())?;
        let table = r.sensors.ok_or_else(|| "the run read no sensors".to_string())?;
        Ok(cut(&table, self.window.clone()))
    }
}

/// The FEM's readings of the experiment at `theta` (its own `[fem]` mesh and step, sensors
/// without noise), cut to the recording's times: the second model that checks a calibration
/// (4.9).
pub(crate) fn fem_readings(eval: &AmmEvaluation, theta: &[f64]) -> std::result::Result<SensorTable, String> {
    let exp = noiseless(eval.experiment(theta)?.exp);
    let src = eval.source.display().to_string();
    let prepared = crate::run::prepare(exp, &src, &RunSettings::new(Solver::Fem)).map_err(|e| e.to_string())?;
    let r = crate::run::solve(&prepared, None).map_err(|e| e.to_string())?;
    let table = r.sensors.ok_or_else(|| "the FEM run read no sensors".to_string())?;
    Ok(cut(&table, eval.window.clone()))
}

/// The rows `window` of a table.
fn cut(table: &SensorTable, window: Range<usize>) -> SensorTable {
    if window == (0..table.t.len()) {
        return table.clone();
    }
    let mut out = SensorTable::new(table.t[window.clone()].to_vec());
    for (k, c) in table.columns.iter().enumerate() {
        let unit = table.units.get(k).map_or("", String::as_str);
        out.push_column(c.name.clone(), unit, c.values[window.clone()].to_vec());
    }
    out
}

/// The calibrated experiment with the frequencies its damping ratios hold at written out
/// (`damping.f_hz`) when the input left them to the start pose (4.9): the fitted ratio and that
/// frequency are the material's damping (Eq. D5's beta), which other moves and other start poses
/// keep, and a plan takes it.
pub(crate) fn with_damping_frequencies(cal: ExperimentDoc, input: &toml::Table) -> Result<ExperimentDoc> {
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
