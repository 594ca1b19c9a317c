//! The model of a recording in `flexstar fit` (`docs/measured.md` 4.2, 4.5): the accurate AMM
//! on the experiment patched at the fitted keys, its N and step frozen at those of the start's
//! run, its sensors without noise, its readings cut to the recording's times; their derivatives
//! from the tangent-linear AMM (4.5).

use std::ops::Range;
use std::path::Path;

use flexstar_fit::{Model, Slopes};
use flexstar_model::{Experiment, SensorTable};
use rayon::prelude::*;

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
    /// The last evaluation's prepared run and its parameters' bits: the Jacobian that follows an
    /// accepted step is taken at the same parameters ([`Model::slopes`]).
    pub last: std::sync::Mutex<Option<(Vec<u64>, std::sync::Arc<crate::run::Prepared>)>>,
    /// Set once the tangent has been refused (a key that moves the mode basis, friction,
    /// gravity: nothing that changes with the parameters' values): the Jacobians are then taken
    /// by differences without preparing the directions again.
    pub refused: std::sync::atomic::AtomicBool,
}

impl AmmEvaluation<'_> {
    /// The experiment at `theta`.
    pub fn experiment(&self, theta: &[f64]) -> std::result::Result<ExperimentDoc, String> {
        let values: Vec<toml::Value> = theta.iter().map(|&v| toml::Value::Float(v)).collect();
        let doc = flexstar_study::patch::case_document(self.base, &self.keys, &values)?;
        ExperimentDoc::from_table(doc, self.source).map_err(|e| e.to_string())
    }

    /// The run at `theta` prepared at the frozen N and step, its sensors without noise.
    fn prepared(&self, theta: &[f64]) -> std::result::Result<crate::run::Prepared, String> {
        let exp = noiseless(self.experiment(theta)?.exp);
        let settings = RunSettings {
            modes: Some(self.modes),
            dt: Some(self.dt),
            ..RunSettings::new(Solver::Amm)
        };
        let src = self.source.display().to_string();
        crate::run::prepare(exp, &src, &settings).map_err(|e| e.to_string())
    }

    /// One run at `base` carrying the directions `theta + steps[k] e_k` of `group`
    /// (`flexstar_solve::sensor_slopes`): its readings and their derivatives, cut to the window.
    fn group_slopes(
        &self,
        base: &crate::run::Prepared,
        theta: &[f64],
        (steps, group): (&[f64], std::ops::Range<usize>),
    ) -> std::result::Result<(SensorTable, Vec<SensorTable>), String> {
        let moved = group
            .clone()
            .map(|k| {
                let mut at = theta.to_vec();
                at[k] += steps[k];
                self.prepared(&at).map(|p| p.problem)
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let s = flexstar_solve::sensor_slopes(&base.problem, &base.exp.amm, &moved, &steps[group]).map_err(|e| {
            // a refused setting (a direction that moves the mode basis, the sensors, the output
            // times) holds at every parameter value; a run that fails here may not
            if let flexstar_solve::SolveError::Amm(flexstar_amm::AmmError::InvalidSetting { .. }) = e {
                self.refused.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            e.to_string()
        })?;
        let table = s
            .response
            .sensors
            .ok_or_else(|| "the run read no sensors".to_string())?;
        let slopes = s.slopes.iter().map(|d| cut(d, self.window.clone())).collect();
        Ok((cut(&table, self.window.clone()), slopes))
    }
}

/// The bits of parameter values, to recognise the same values again.
fn bits(theta: &[f64]) -> Vec<u64> {
    theta.iter().map(|v| v.to_bits()).collect()
}

impl Model for AmmEvaluation<'_> {
    fn evaluate(&self, theta: &[f64]) -> std::result::Result<SensorTable, String> {
        let prepared = std::sync::Arc::new(self.prepared(theta)?);
        if let Ok(mut last) = self.last.lock() {
            *last = Some((bits(theta), prepared.clone()));
        }
        let r = crate::run::solve(&prepared, None).map_err(|e| e.to_string())?;
        let table = r.sensors.ok_or_else(|| "the run read no sensors".to_string())?;
        Ok(cut(&table, self.window.clone()))
    }

    /// The tangent-linear AMM (`docs/measured.md` 4.5, Eq. LS9b) where it covers the experiment
    /// (a prescribed motion, no friction or gravity: `flexstar_amm::sensitivities_cover`): the
    /// directions split into one contiguous group per thread, each group one run.
    fn slopes(&self, theta: &[f64], steps: &[f64]) -> Option<std::result::Result<Slopes, String>> {
        use std::sync::atomic::Ordering;
        if self.refused.load(Ordering::Relaxed) {
            return None;
        }
        let kept = (self.last.lock().ok())
            .and_then(|last| last.as_ref().filter(|(b, _)| *b == bits(theta)).map(|(_, p)| p.clone()));
        let base = match kept {
            Some(p) => p,
            None => std::sync::Arc::new(self.prepared(theta).ok()?),
        };
        let covered =
            flexstar_amm::sensitivities_cover(&base.problem, &base.exp.amm).is_ok() && !base.exp.drive.is_direct();
        if !covered || steps.is_empty() {
            self.refused.store(true, Ordering::Relaxed);
            return None;
        }
        let groups = rayon::current_num_threads().clamp(1, steps.len());
        let size = steps.len().div_ceil(groups);
        let ranges: Vec<_> = (0..steps.len())
            .step_by(size)
            .map(|a| a..(a + size).min(steps.len()))
            .collect();
        let runs = ranges.len();
        let done: std::result::Result<Vec<_>, String> = ranges
            .into_par_iter()
            .map(|g| self.group_slopes(&base, theta, (steps, g)))
            .collect();
        Some(done.map(|groups| {
            let mut groups = groups.into_iter();
            let (readings, mut derivatives) = groups.next().expect("one group at least");
            derivatives.extend(groups.flat_map(|(_, d)| d));
            Slopes {
                readings,
                derivatives,
                runs,
            }
        }))
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

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_fit::jacobian::TANGENT_STEP;

    /// The bench's model (`configs/measured/nominal.toml`) at its start, as `flexstar fit`
    /// evaluates it: N and step frozen at the start's run, every sample.
    fn bench(doc: &ExperimentDoc) -> AmmEvaluation<'_> {
        let start = start_run(doc).unwrap();
        AmmEvaluation {
            base: &doc.doc,
            keys: ["payload.mass", "payload.J", "damping.zeta", "robot.E"]
                .map(String::from)
                .to_vec(),
            source: &doc.source,
            modes: start.modes,
            dt: start.dt,
            window: 0..start.sensors.t.len(),
            last: Default::default(),
            refused: Default::default(),
        }
    }

    /// Eq. LS9b against central differences of whole evaluations at +-1e-4 of each parameter:
    /// every channel of every column within 1.5e-3 of its largest derivative (the encoders'
    /// exactly zero), the readings the plain evaluation's bit for bit. *Measured*: 3e-5 to
    /// 9.3e-4 (E the largest: the one-sided step's second-order terms), as Eq. LS9's forward
    /// differences at the same step are, to a few per cent of that figure (printed beside):
    /// the tangent is the internal difference of the same step (`docs/measured.md` 4.5).
    #[test]
    fn the_tangent_columns_match_central_differences() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/measured/nominal.toml");
        let doc = ExperimentDoc::load(&path).unwrap();
        let model = bench(&doc);
        let theta = [0.3, 1.0e-3, 0.01, 200e9];
        let steps = theta.map(|t| TANGENT_STEP * t);
        let slopes = model
            .slopes(&theta, &steps)
            .expect("the tangent covers the bench")
            .unwrap();
        let plain = model.evaluate(&theta).unwrap();
        for (a, b) in slopes.readings.columns.iter().zip(&plain.columns) {
            assert_eq!(a.values, b.values, "{}", a.name);
        }
        for (k, d) in slopes.derivatives.iter().enumerate() {
            let at = |f: f64| {
                let mut x = theta;
                x[k] *= 1.0 + f;
                model.evaluate(&x).unwrap()
            };
            let (plus, minus, forward) = (at(1e-4), at(-1e-4), at(1e-4));
            for (c, col) in d.columns.iter().enumerate() {
                let (mut err, mut err_fd, mut big) = (0.0f64, 0.0f64, 0.0f64);
                for (j, v) in col.values.iter().enumerate() {
                    let central = (plus.columns[c].values[j] - minus.columns[c].values[j]) / (2e-4 * theta[k]);
                    let fd = (forward.columns[c].values[j] - plain.columns[c].values[j]) / (1e-4 * theta[k]);
                    err = err.max((v - central).abs());
                    err_fd = err_fd.max((fd - central).abs());
                    big = big.max(central.abs());
                }
                if big == 0.0 {
                    // an encoder reads the prescribed motion, which no parameter moves
                    assert_eq!(err, 0.0, "{} along {}", col.name, model.keys[k]);
                    continue;
                }
                println!(
                    "{} along {}: tangent {:.2e}, forward differences {:.2e}",
                    col.name,
                    model.keys[k],
                    err / big,
                    err_fd / big
                );
                assert!(
                    err < 1.5e-3 * big,
                    "{} along {}: {:.2e}",
                    col.name,
                    model.keys[k],
                    err / big
                );
            }
        }
    }
}
