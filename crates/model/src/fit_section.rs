//! `[fit]`: the physical parameters that `flexstar fit` calibrates on a recording
//! (`docs/measured.md` section 4.1).
//!
//! ```toml
//! [fit]
//! params = [
//!   { key = "payload.mass", lo = 0.0, hi = 1.0 },            # start: the experiment's own value
//!   { key = "robot.E", lo = 150e9, hi = 250e9, start = 2e11 },
//!   { key = "robot.L[2]", lo = 0.45, hi = 0.55 },            # one beam's entry
//! ]
//! weights = { accG = 2.0, enc1 = 0.0, accB_x = 0.0 }           # per sensor or column; default 1
//! max_iterations = 50                                          # of the search (default 50)
//! starts = 4                                                   # the given start and 3 more (default 1)
//! ```
//! What needs no document is checked here, when the file is read: bounds, starts, weights. That
//! each key is a number the experiment accepts, at its bounds too, is checked by the command
//! before any run (it patches the document, `flexstar_api::fit`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::error::ModelError;

/// One fitted parameter: a dotted numeric key of the experiment and its box.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitParam {
    /// A dotted key as sweeps take it (`payload.mass`, `damping.zeta`, `robot.L[2]`).
    pub key: String,
    /// Lower bound, in the key's unit.
    pub lo: f64,
    /// Upper bound, in the key's unit; `lo < hi`.
    pub hi: f64,
    /// Where the search starts; default: the experiment's own value at `key`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<f64>,
}

/// `[fit]` (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// The parameters, in the order of every output.
    pub params: Vec<FitParam>,
    /// A weight >= 0 per sensor name (`[[sensors]] name`) or per column (`accB_x`), multiplying
    /// the residuals of its channels (`docs/measured.md` Eq. LS1); a column's own weight comes
    /// before its sensor's, one named by neither has weight 1, weight 0 leaves it out.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub weights: BTreeMap<String, f64>,
    /// The most iterations of the search (default [`DEFAULT_MAX_ITERATIONS`]; 1..=1000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_iterations: Option<usize>,
    /// How many starts the search takes (`docs/measured.md` 4.6): the given one, then Halton
    /// points of the boxes; default 1, at most [`MAX_STARTS`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub starts: Option<usize>,
}

/// The most starts `[fit] starts` may ask for.
pub const MAX_STARTS: usize = 64;

/// The most iterations of the search when `[fit] max_iterations` is not given
/// (`docs/measured.md` 4.6).
pub const DEFAULT_MAX_ITERATIONS: usize = 50;

impl FitSection {
    /// Check what needs no document (keys named `fit.params[k].lo`, `fit.weights.<name>`):
    /// at least one parameter, each key non-empty, finite bounds with `lo < hi`, a start inside
    /// them; weights finite and >= 0, each naming one of `sensors` (`(name, columns)` of the
    /// `[[sensors]]`) or one of their columns, not all of them 0.
    pub fn validate(&self, sensors: &[(String, Vec<String>)]) -> Result<(), ModelError> {
        if self.params.is_empty() {
            return Err(ModelError::invalid(
                "fit.params",
                "name at least one parameter: params = [{ key = \"payload.mass\", lo = 0.0, hi = 1.0 }]",
            ));
        }
        for (k, p) in self.params.iter().enumerate() {
            p.validate(&format!("fit.params[{}]", k + 1))?;
        }
        if let Some(n) = self.max_iterations {
            if !(1..=1000).contains(&n) {
                return Err(ModelError::invalid(
                    "fit.max_iterations",
                    format!("need 1 <= max_iterations <= 1000, got {n}"),
                ));
            }
        }
        if let Some(n) = self.starts {
            if !(1..=MAX_STARTS).contains(&n) {
                return Err(ModelError::invalid(
                    "fit.starts",
                    format!("need 1 <= starts <= {MAX_STARTS}, got {n}"),
                ));
            }
        }
        self.validate_weights(sensors)
    }

    fn validate_weights(&self, sensors: &[(String, Vec<String>)]) -> Result<(), ModelError> {
        for (name, w) in &self.weights {
            let key = format!("fit.weights.{name}");
            let known = sensors.iter().any(|(s, cols)| s == name || cols.contains(name));
            if !known {
                let known = if sensors.is_empty() {
                    "the experiment has no [[sensors]]".to_string()
                } else {
                    let names: Vec<String> = sensors
                        .iter()
                        .map(|(s, cols)| format!("{s} ({})", cols.join(", ")))
                        .collect();
                    format!("the sensors (columns) are {}", names.join(", "))
                };
                return Err(ModelError::invalid(
                    key,
                    format!("names no sensor and no sensor column ({known})"),
                ));
            }
            if !(w.is_finite() && *w >= 0.0) {
                return Err(ModelError::invalid(
                    key,
                    format!("must be a finite number >= 0, got {w}"),
                ));
            }
        }
        let all_zero = !sensors.is_empty()
            && sensors
                .iter()
                .all(|(s, cols)| cols.iter().all(|c| self.weight(s, c) == 0.0));
        if all_zero {
            return Err(ModelError::invalid(
                "fit.weights",
                "every sensor has weight 0: nothing is left to fit to",
            ));
        }
        Ok(())
    }

    /// The most iterations of the search.
    pub fn iterations(&self) -> usize {
        self.max_iterations.unwrap_or(DEFAULT_MAX_ITERATIONS)
    }

    /// How many starts the search takes (default 1: the given one).
    pub fn start_count(&self) -> usize {
        self.starts.unwrap_or(1)
    }

    /// The weight of column `column` of sensor `sensor`: the column's own, else the sensor's,
    /// else 1.
    pub fn weight(&self, sensor: &str, column: &str) -> f64 {
        self.weights
            .get(column)
            .or_else(|| self.weights.get(sensor))
            .copied()
            .unwrap_or(1.0)
    }
}

/// The columns a `[[sensors]]` table will have (`Sensor::columns` of the checked sensor: an
/// accelerometer's `<name>_x`, `<name>_y`, any other's `<name>`), for the weights' names, which
/// are checked with the file before the sensors are.
pub fn spec_columns(spec: &crate::sensors::SensorSpec) -> Vec<String> {
    if spec.kind == "accelerometer" {
        vec![format!("{}_x", spec.name), format!("{}_y", spec.name)]
    } else {
        vec![spec.name.clone()]
    }
}

impl FitParam {
    /// Check bounds and start; `at` names the entry (`fit.params[2]`).
    fn validate(&self, at: &str) -> Result<(), ModelError> {
        if self.key.trim().is_empty() {
            return Err(ModelError::invalid(
                format!("{at}.key"),
                "is empty: give a dotted key of the experiment (payload.mass, robot.L[2])",
            ));
        }
        for (name, v) in [("lo", self.lo), ("hi", self.hi)] {
            if !v.is_finite() {
                return Err(ModelError::invalid(
                    format!("{at}.{name}"),
                    format!("{}: the bound must be a finite number, got {v}", self.key),
                ));
            }
        }
        if self.lo >= self.hi {
            return Err(ModelError::invalid(
                format!("{at}.hi"),
                format!("{}: need lo < hi, got lo = {} and hi = {}", self.key, self.lo, self.hi),
            ));
        }
        if let Some(s) = self.start {
            if !(s.is_finite() && (self.lo..=self.hi).contains(&s)) {
                return Err(ModelError::invalid(
                    format!("{at}.start"),
                    format!(
                        "{}: start = {s} lies outside [lo, hi] = [{}, {}]",
                        self.key, self.lo, self.hi
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn section(params: &str, weights: &str) -> FitSection {
        toml::from_str(&format!("params = [{params}]\n{weights}")).unwrap()
    }

    /// Each refusal names its key and says why.
    #[test]
    fn bad_bounds_starts_and_weights_are_named() {
        let sensors = [
            ("accG".to_string(), vec!["accG_x".to_string(), "accG_y".to_string()]),
            ("enc1".to_string(), vec!["enc1".to_string()]),
        ];
        let cases = [
            (
                "{ key = \"payload.mass\", lo = 1.0, hi = 1.0 }",
                "",
                "fit.params[1].hi",
                "lo < hi",
            ),
            (
                "{ key = \"payload.mass\", lo = 2.0, hi = 1.0 }",
                "",
                "fit.params[1].hi",
                "lo < hi",
            ),
            (
                "{ key = \"payload.mass\", lo = 0.0, hi = inf }",
                "",
                "fit.params[1].hi",
                "finite",
            ),
            (
                "{ key = \"a.b\", lo = 0.0, hi = 1.0 }, { key = \"payload.J\", lo = 0.0, hi = 1.0, start = 2.0 }",
                "",
                "fit.params[2].start",
                "outside [lo, hi]",
            ),
            ("{ key = \" \", lo = 0.0, hi = 1.0 }", "", "fit.params[1].key", "empty"),
            (
                "{ key = \"a\", lo = 0.0, hi = 1.0 }",
                "weights = { accB = 1.0 }",
                "fit.weights.accB",
                "accG (accG_x, accG_y), enc1 (enc1)",
            ),
            (
                "{ key = \"a\", lo = 0.0, hi = 1.0 }",
                "weights = { accG = -1.0 }",
                "fit.weights.accG",
                ">= 0",
            ),
            (
                "{ key = \"a\", lo = 0.0, hi = 1.0 }",
                "weights = { accG = 0.0, enc1 = 0 }",
                "fit.weights",
                "nothing is left",
            ),
        ];
        for (params, weights, key, why) in cases {
            let e = section(params, weights).validate(&sensors).unwrap_err().to_string();
            assert!(e.contains(key) && e.contains(why), "{params} {weights}: {e}");
        }
        let e = section("{ key = \"a\", lo = 0.0, hi = 1.0 }", "starts = 0")
            .validate(&sensors)
            .unwrap_err()
            .to_string();
        assert!(e.contains("fit.starts") && e.contains("1 <= starts <= 64"), "{e}");
        let e = section("{ key = \"a\", lo = 0.0, hi = 1.0 }", "max_iterations = 0")
            .validate(&sensors)
            .unwrap_err()
            .to_string();
        assert!(e.contains("fit.max_iterations"), "{e}");
        let e = FitSection {
            params: Vec::new(),
            weights: BTreeMap::new(),
            max_iterations: None,
            starts: None,
        }
        .validate(&sensors)
        .unwrap_err()
        .to_string();
        assert!(e.contains("fit.params") && e.contains("at least one"), "{e}");
        let ok = section(
            "{ key = \"a\", lo = 0.0, hi = 1.0, start = 1.0 }",
            "weights = { accG = 2, accG_y = 0.5 }",
        );
        ok.validate(&sensors).unwrap();
        let w = |s, c| ok.weight(s, c);
        assert_eq!(
            (w("accG", "accG_x"), w("accG", "accG_y"), w("enc1", "enc1")),
            (2.0, 0.5, 1.0)
        );
        // one column weighted 0 and the other columns weighted is a fit
        section(
            "{ key = \"a\", lo = 0.0, hi = 1.0 }",
            "weights = { accG_x = 0.0, enc1 = 0.0 }",
        )
        .validate(&sensors)
        .unwrap();
        let e = section("{ key = \"a\", lo = 0.0, hi = 1.0 }", "weights = { accG = 1.0 }")
            .validate(&[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no [[sensors]]"), "{e}");
    }

    /// The columns the weights may name are those the checked sensors have, for every kind.
    #[test]
    fn spec_columns_are_the_sensors_columns() {
        let text = "name = \"s\"\n[time]\nt_end = 0.1\n[trajectory]\nkind = \"polynomial\"\n\
                    s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n[payload]\nmass = 0.1\n\
                    [[sensors]]\nname = \"a\"\nkind = \"accelerometer\"\nat = \"G\"\n\
                    [[sensors]]\nname = \"g\"\nkind = \"strain\"\nbeam = 1\nx = 0.45\nc = 1e-3\n\
                    [[sensors]]\nname = \"e\"\nkind = \"encoder\"\nslider = 1\n\
                    [[sensors]]\nname = \"f\"\nkind = \"force\"\nslider = 2\n";
        let exp = crate::Experiment::from_toml_str(text, std::path::Path::new("s.toml")).unwrap();
        let problem = exp.problem().unwrap();
        let checked: Vec<Vec<String>> = problem.sensors().list().iter().map(|s| s.columns()).collect();
        let from_specs: Vec<Vec<String>> = exp.sensors.iter().map(spec_columns).collect();
        assert_eq!(from_specs, checked);
        assert_eq!(checked.len(), 4);
    }

    #[test]
    fn unknown_keys_in_the_section_are_refused() {
        let e = toml::from_str::<FitSection>("params = [{ key = \"a\", lo = 0.0, hi = 1.0, step = 2 }]")
            .unwrap_err()
            .to_string();
        assert!(e.contains("step"), "{e}");
        let e = toml::from_str::<FitSection>("params = []\nmethod = \"lm\"")
            .unwrap_err()
            .to_string();
        assert!(e.contains("method"), "{e}");
    }
}
