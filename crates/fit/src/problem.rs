//! The least-squares problem (`docs/measured.md` 4.1-4.3, Eqs. LS1-LS5): the parameters in their
//! boxes, the recorded channels with their weights and noise levels, and the residual vector of a
//! model's readings.

use flexstar_model::SensorTable;

use crate::FitError;

/// Two sample times closer than this (relative to max(1 s, t)) are the same time.
const SAME_TIME: f64 = 1e-9;

/// One parameter: its name (a dotted key of the experiment), its box `[lo, hi]` and where the
/// search starts, all in the parameter's own unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    pub key: String,
    pub lo: f64,
    pub hi: f64,
    pub start: f64,
}

impl Param {
    /// `hi - lo`.
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// Eq. LS5: the scaled value `u = (theta - lo) / (hi - lo)`, in [0, 1] inside the box.
    pub fn scaled(&self, theta: f64) -> f64 {
        (theta - self.lo) / self.width()
    }

    /// Eq. LS5 inverted: `theta = lo + u (hi - lo)`.
    pub fn physical(&self, u: f64) -> f64 {
        self.lo + u * self.width()
    }
}

/// One recorded channel (a sensor column): its samples on the recording's times, its weight
/// `w_c` and its noise level `sigma_c` (Eq. LS1).
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The column (`accG_x`, `enc1`).
    pub column: String,
    /// Its unit (`m/s^2`, `m`).
    pub unit: String,
    /// `w_c >= 0`; 0 leaves the channel out of the residual (it is still reported).
    pub weight: f64,
    /// `sigma_c > 0` in the channel's unit (Eq. LS2 unless given).
    pub sigma: f64,
    /// The recorded samples.
    pub measured: Vec<f64>,
}

impl Channel {
    /// Does the channel enter the residual?
    pub fn fitted(&self) -> bool {
        self.weight > 0.0
    }
}

/// The problem: parameters, the recording's times and its channels.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub params: Vec<Param>,
    /// The recording's times [s] (those the model's readings must have).
    pub t: Vec<f64>,
    pub channels: Vec<Channel>,
}

impl Problem {
    /// Every column of `recording` a channel, `weights[c]` its weight (one per column, in order),
    /// its noise level estimated from the recording (Eq. LS2).
    pub fn new(params: Vec<Param>, recording: &SensorTable, weights: &[f64]) -> Result<Self, FitError> {
        let sigmas = recording
            .columns
            .iter()
            .map(|c| {
                crate::noise::level(&c.values).ok_or_else(|| {
                    FitError::Input(format!(
                        "the recording has {} samples: too few to estimate the noise of {} (need {})",
                        c.values.len(),
                        c.name,
                        crate::noise::ORDER + 1
                    ))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::with_sigmas(params, recording, weights, &sigmas)
    }

    /// As [`Problem::new`] with the noise levels `sigmas` given (one per column, > 0).
    pub fn with_sigmas(
        params: Vec<Param>,
        recording: &SensorTable,
        weights: &[f64],
        sigmas: &[f64],
    ) -> Result<Self, FitError> {
        let n = recording.columns.len();
        if weights.len() != n || sigmas.len() != n {
            return Err(FitError::Input(format!(
                "{} weights and {} noise levels for {n} recorded channels",
                weights.len(),
                sigmas.len()
            )));
        }
        let channels = recording
            .columns
            .iter()
            .zip(weights.iter().zip(sigmas))
            .enumerate()
            .map(|(k, (c, (&weight, &sigma)))| Channel {
                column: c.name.clone(),
                unit: recording.units.get(k).cloned().unwrap_or_default(),
                weight,
                sigma,
                measured: c.values.clone(),
            })
            .collect();
        let problem = Problem {
            params,
            t: recording.t.clone(),
            channels,
        };
        problem.check()?;
        Ok(problem)
    }

    /// Parameters with starts inside their boxes, channels with positive noise and weights
    /// >= 0, one of them fitted, more residuals than parameters.
    fn check(&self) -> Result<(), FitError> {
        if self.params.is_empty() {
            return Err(FitError::Input("no parameter to fit".into()));
        }
        for p in &self.params {
            let ok = p.lo.is_finite() && p.hi.is_finite() && p.lo < p.hi && (p.lo..=p.hi).contains(&p.start);
            if !ok {
                return Err(FitError::Input(format!(
                    "{}: need lo < hi and lo <= start <= hi, got lo = {}, hi = {}, start = {}",
                    p.key, p.lo, p.hi, p.start
                )));
            }
        }
        for c in &self.channels {
            if c.measured.len() != self.t.len() {
                return Err(FitError::Input(format!(
                    "recorded channel {} has {} samples for {} times",
                    c.column,
                    c.measured.len(),
                    self.t.len()
                )));
            }
            if !(c.weight.is_finite() && c.weight >= 0.0 && c.sigma.is_finite() && c.sigma > 0.0) {
                return Err(FitError::Input(format!(
                    "channel {}: need a weight >= 0 and a noise level > 0, got {} and {}",
                    c.column, c.weight, c.sigma
                )));
            }
            if let Some(k) = c.measured.iter().position(|v| !v.is_finite()) {
                return Err(FitError::Input(format!(
                    "recorded channel {} is not a number at t = {} s",
                    c.column, self.t[k]
                )));
            }
        }
        if self.rows() <= self.params.len() {
            return Err(FitError::Input(format!(
                "{} residuals (fitted channels times samples) for {} parameters: need more residuals than parameters",
                self.rows(),
                self.params.len()
            )));
        }
        Ok(())
    }

    /// The number of residuals n: samples times fitted channels.
    pub fn rows(&self) -> usize {
        self.t.len() * self.channels.iter().filter(|c| c.fitted()).count()
    }

    /// The starts, scaled (Eq. LS5).
    pub fn start_scaled(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.scaled(p.start)).collect()
    }

    /// Physical values of the scaled `u`.
    pub fn physical(&self, u: &[f64]) -> Vec<f64> {
        self.params.iter().zip(u).map(|(p, &u)| p.physical(u)).collect()
    }

    /// The model at the scaled `u`: its readings and their residual vector (Eq. LS1).
    pub fn evaluate<M: crate::Model + ?Sized>(&self, model: &M, u: &[f64]) -> Result<(Vec<f64>, SensorTable), String> {
        let table = model.evaluate(&self.physical(u))?;
        let r = self.residuals(&table)?;
        Ok((r, table))
    }

    /// Eq. LS1: the residual vector of the model's readings, channel after channel (fitted
    /// channels only), `w_c (y_c(t_k) - m_ck) / sigma_c`. An error names a channel the model
    /// lacks, other times, or a reading that is not a number.
    pub fn residuals(&self, model: &SensorTable) -> Result<Vec<f64>, String> {
        let r = self.weighted(model, |y, m| y - m)?;
        if let Some(k) = r.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "the model's reading {} is not a number",
                k % self.t.len().max(1)
            ));
        }
        Ok(r)
    }

    /// The derivative of Eq. LS1's residual vector along a parameter from the derivatives
    /// `slopes` of the model's readings along it (a table of [`crate::Model::slopes`]):
    /// `w_c dy_c / sigma_c`, channel after channel (fitted channels only).
    pub fn residual_slopes(&self, slopes: &SensorTable) -> Result<Vec<f64>, String> {
        let r = self.weighted(slopes, |dy, _| dy)?;
        if r.iter().any(|v| !v.is_finite()) {
            return Err("a derivative of the model's readings is not a number".into());
        }
        Ok(r)
    }

    /// `w_c f(y_ck, m_ck) / sigma_c` of every fitted channel of `table` (its readings `y`
    /// against the recorded `m`), channel after channel.
    fn weighted(&self, table: &SensorTable, f: impl Fn(f64, f64) -> f64) -> Result<Vec<f64>, String> {
        let mut r = Vec::with_capacity(self.rows());
        for c in self.channels.iter().filter(|c| c.fitted()) {
            let y = self.model_channel(table, &c.column)?;
            let scale = c.weight / c.sigma;
            r.extend(y.iter().zip(&c.measured).map(|(&y, &m)| scale * f(y, m)));
        }
        Ok(r)
    }

    /// The model's error `y_c - m_c` of every channel (fitted or not), in its unit.
    pub fn errors(&self, model: &SensorTable) -> Result<Vec<Vec<f64>>, String> {
        self.channels
            .iter()
            .map(|c| {
                let y = self.model_channel(model, &c.column)?;
                Ok(y.iter().zip(&c.measured).map(|(y, m)| y - m).collect())
            })
            .collect()
    }

    /// Channel `column` of the model's table, checked to be on the recording's times.
    fn model_channel<'a>(&self, model: &'a SensorTable, column: &str) -> Result<&'a [f64], String> {
        self.check_times(&model.t)?;
        let y = model.column(column).ok_or_else(|| {
            format!(
                "the model has no channel {column} (it reads {})",
                model.header()[1..].join(", ")
            )
        })?;
        if y.len() != self.t.len() {
            return Err(format!(
                "the model's channel {column} has {} samples, the recording {}",
                y.len(),
                self.t.len()
            ));
        }
        Ok(y)
    }

    fn check_times(&self, t: &[f64]) -> Result<(), String> {
        if t.len() != self.t.len() {
            return Err(format!(
                "the model reads {} sample times, the recording has {}: resample the recording onto the run's sensor times",
                t.len(),
                self.t.len()
            ));
        }
        match t
            .iter()
            .zip(&self.t)
            .position(|(a, b)| (a - b).abs() > SAME_TIME * b.abs().max(1.0))
        {
            Some(k) => Err(format!(
                "sample {} is at t = {} s in the model and {} s in the recording",
                k + 1,
                t[k],
                self.t[k]
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(t: &[f64], cols: &[(&str, Vec<f64>)]) -> SensorTable {
        let mut s = SensorTable::new(t.to_vec());
        for (n, v) in cols {
            s.push_column(n.to_string(), "m", v.clone());
        }
        s
    }

    fn param() -> Param {
        Param {
            key: "a".into(),
            lo: -1.0,
            hi: 3.0,
            start: 0.0,
        }
    }

    /// Eq. LS1 by hand on two channels, one of weight 0; Eq. LS5 both ways.
    #[test]
    fn residuals_are_weighted_scaled_differences() {
        let t = [0.0, 0.5, 1.0];
        let rec = table(&t, &[("a", vec![1.0, 2.0, 3.0]), ("b", vec![0.0, 0.0, 0.0])]);
        let p = Problem::with_sigmas(vec![param()], &rec, &[2.0, 0.0], &[0.5, 1.0]).unwrap();
        let model = table(&t, &[("b", vec![9.0; 3]), ("a", vec![1.5, 2.0, 2.0])]);
        assert_eq!(p.residuals(&model).unwrap(), vec![2.0, 0.0, -4.0]);
        assert_eq!(p.errors(&model).unwrap()[1], vec![9.0; 3]);
        assert_eq!(p.rows(), 3);
        let q = &p.params[0];
        assert_eq!((q.scaled(0.0), q.physical(0.25)), (0.25, 0.0));
        // the model on other times, or without a channel
        let late = table(&[0.0, 0.5, 1.1], &[("a", vec![0.0; 3])]);
        assert!(p.residuals(&late).unwrap_err().contains("t = 1.1"));
        let none = table(&t, &[("b", vec![0.0; 3])]);
        assert!(p.residuals(&none).unwrap_err().contains("no channel a"));
    }

    #[test]
    fn bad_problems_are_refused() {
        let t = [0.0, 0.5];
        let rec = table(&t, &[("a", vec![1.0, 2.0])]);
        let bad_start = Param { start: 4.0, ..param() };
        let e = Problem::with_sigmas(vec![bad_start], &rec, &[1.0], &[1.0]).unwrap_err();
        assert!(e.to_string().contains("start = 4"), "{e}");
        let e = Problem::with_sigmas(vec![param(), param()], &rec, &[1.0], &[1.0]).unwrap_err();
        assert!(e.to_string().contains("more residuals than parameters"), "{e}");
        let e = Problem::with_sigmas(vec![param()], &rec, &[1.0], &[0.0]).unwrap_err();
        assert!(e.to_string().contains("noise level > 0"), "{e}");
        let e = Problem::new(vec![param()], &rec, &[1.0]).unwrap_err();
        assert!(e.to_string().contains("too few"), "{e}");
    }
}
