//! Sensors: what an accelerometer, a strain gauge, an encoder or a force cell reads
//! (`docs/sensors.md`). The definitions (`[[sensors]]`, [`spec`]), the readings of a material
//! point whose kinematics a solver supplies ([`read`], Eqs. S4-S7), the data acquisition
//! ([`daq`]: the anti-aliasing filter, the sampling and the noise, Eqs. S11-S13) and the table the
//! solvers return and write as `<stem>-sensors.csv` ([`table`]). No solver code lives here: each
//! solver implements [`read::Instant`] for the points it owns.

pub mod daq;
pub mod read;
pub mod spec;
pub mod table;

pub use read::{Instant, JunctionMotion, PointMotion};
pub use spec::{Acquisition, Axes, Kind, Place, Sensor, SensorSpec};
pub use table::SensorTable;

use crate::error::ModelError;
use crate::robot::Robot;

/// The checked sensors of an experiment, in the order of its `[[sensors]]` tables (empty
/// without).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sensors {
    list: Vec<Sensor>,
}

impl Sensors {
    /// Check the `[[sensors]]` tables of an experiment (`docs/sensors.md` section 5): each on its
    /// own ([`SensorSpec`]), then the names unique and not a result column's, one sampling rate.
    /// `dt_out` [s]: the output step.
    pub fn from_specs(specs: &[SensorSpec], robot: &Robot, has_payload: bool, dt_out: f64) -> Result<Self, ModelError> {
        let cx = spec::Context {
            robot,
            has_payload,
            dt_out,
        };
        let mut list: Vec<Sensor> = Vec::with_capacity(specs.len());
        for (k, s) in specs.iter().enumerate() {
            let sensor = s.validate(k + 1, &cx)?;
            let key = |name: &str| format!("sensors[{}].{name}", k + 1);
            if let Some(j) = list.iter().position(|o| o.name == sensor.name) {
                return Err(ModelError::invalid(
                    key("name"),
                    format!(
                        "{:?} is also the name of sensors[{}]: names must be unique",
                        sensor.name,
                        j + 1
                    ),
                ));
            }
            if let Some(c) = sensor
                .columns()
                .iter()
                .find(|c| crate::quantity::column_unit(c).is_some() || *c == "t")
            {
                return Err(ModelError::invalid(
                    key("name"),
                    format!("its column {c} is the name of a result column: choose another name"),
                ));
            }
            if let (Some(first), Some(r)) = (list.iter().find_map(|o| o.daq.rate_hz), sensor.daq.rate_hz) {
                if r != first {
                    return Err(ModelError::invalid(
                        key("rate_hz"),
                        format!(
                            "{r} Hz differs from the {first} Hz of an earlier sensor: one acquisition, one clock \
                             (one t column)"
                        ),
                    ));
                }
            }
            list.push(sensor);
        }
        Ok(Sensors { list })
    }

    /// No sensor.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The sensors.
    pub fn list(&self) -> &[Sensor] {
        &self.list
    }

    /// The columns of the sensors' file after `t`, in order.
    pub fn columns(&self) -> Vec<String> {
        self.list.iter().flat_map(Sensor::columns).collect()
    }

    /// `(column, unit)` of every column after `t`.
    pub fn units(&self) -> Vec<(String, &'static str)> {
        self.list
            .iter()
            .flat_map(|s| s.columns().into_iter().map(move |c| (c, s.unit())))
            .collect()
    }

    /// The sampling rate [Hz] of every channel (`None`: the output times).
    pub fn rate_hz(&self) -> Option<f64> {
        self.list.iter().find_map(|s| s.daq.rate_hz)
    }

    /// Section 5 on another robot (`Problem::with_robot`): every point on a beam still lies on
    /// that beam of `robot`, `0 <= x <= L_i`; the error names the `k`-th sensor's `x`.
    pub fn check_on(&self, robot: &Robot) -> Result<(), ModelError> {
        for (k, s) in self.list.iter().enumerate() {
            if let Some((beam, x)) = s.beam_point() {
                spec::check_on_beam(beam, x, robot, &format!("sensors[{}].x", k + 1))?;
            }
        }
        Ok(())
    }

    /// Eq. S10: refuse a sensor mounted where its sleeve passes. `bands[i] = [lo, hi]` [m]: the
    /// material coordinates of beam i that sleeve i covers over the motion (the rigid `xp_i`
    /// range widened by `Lp_i / 2` each side). The error names the `k`-th sensor's `x`.
    pub fn check_mounts(&self, bands: &[[f64; 2]; 3]) -> Result<(), ModelError> {
        for (k, s) in self.list.iter().enumerate() {
            if let Some((beam, x)) = s.beam_point() {
                let [lo, hi] = bands[beam];
                if x >= lo && x <= hi {
                    return Err(ModelError::invalid(
                        format!("sensors[{}].x", k + 1),
                        format!(
                            "x = {x} m lies inside the sleeve's travel on beam {} ({lo:.6} .. {hi:.6} m from G over \
                             the motion): sleeve {} slides over that point, nothing can be mounted there",
                            beam + 1,
                            beam + 1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}
