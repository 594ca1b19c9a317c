//! `[measured]`: how a recording of the real robot maps onto the experiment's sensor columns
//! (`docs/measured.md` section 1). The recording itself is read by `flexstar_measured`.
//!
//! ```toml
//! [measured]
//! columns = { t = "time_s", acc1_x = "accel_x" }   # sensor column (or t) = recording column
//! scale = { acc1_x = 9.81 }                          # per sensor column: multiplies the recorded value
//! offset = 0.012                                     # s, added to the recording's times; or "auto"
//! max_lag = 0.05                                     # s, the lag window of offset = "auto" (M3)
//! ```
//! A recording column named as a sensor column needs no mapping. Every key is optional; the
//! names are checked against the experiment's `[[sensors]]` when the file is read.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::error::ModelError;

/// The name of the time column, in a recording and as a key of `columns`.
pub const TIME_COLUMN: &str = "t";

/// `offset`: the shift [s] added to the recording's times (Eq. M2), or estimated by
/// cross-correlation against the run (Eq. M3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Offset {
    /// A given shift [s].
    Seconds(f64),
    /// `offset = "auto"`: estimated within `[-max_lag, max_lag]`.
    Auto,
}

impl Default for Offset {
    fn default() -> Self {
        Offset::Seconds(0.0)
    }
}

/// `[measured]` (see the module doc).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeasuredSection {
    /// Sensor column (or `t`) = the recording's column that holds it.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub columns: BTreeMap<String, String>,
    /// Sensor column = the factor that turns the recorded value into the sensor's unit (Eq. M1).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub scale: BTreeMap<String, f64>,
    /// The recording's clock against the run's (Eq. M2); default 0.
    pub offset: Offset,
    /// Half-width [s] of the lag window searched by `offset = "auto"` (Eq. M3); default
    /// [`MeasuredSection::default_max_lag`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_lag: Option<f64>,
}

impl MeasuredSection {
    /// The default lag window of `offset = "auto"` for a run of `t_end` [s]: a quarter of the
    /// run, so that every lag tried keeps at least three quarters of it in the overlap.
    pub fn default_max_lag(t_end: f64) -> f64 {
        0.25 * t_end
    }

    /// The lag window [s] of `offset = "auto"` for a run of `t_end` [s].
    pub fn max_lag(&self, t_end: f64) -> f64 {
        self.max_lag.unwrap_or_else(|| Self::default_max_lag(t_end))
    }

    /// The recording's column that holds the sensor column `column` (or `t`): its mapping, else
    /// the same name.
    pub fn recording_column<'a>(&'a self, column: &'a str) -> &'a str {
        self.columns.get(column).map(String::as_str).unwrap_or(column)
    }

    /// The factor of Eq. M1 for the sensor column `column` (1 without `scale`).
    pub fn scale_of(&self, column: &str) -> f64 {
        self.scale.get(column).copied().unwrap_or(1.0)
    }

    /// Check the section against the experiment's sensor columns `sensor_columns` (after `t`)
    /// and its span `t_end` [s]; keys named `measured.<key>`.
    pub fn validate(&self, sensor_columns: &[String], t_end: f64) -> Result<(), ModelError> {
        if sensor_columns.is_empty() {
            return Err(ModelError::invalid(
                "measured",
                "the experiment has no [[sensors]]: a recording is laid over the sensors' columns, define them first",
            ));
        }
        self.check_names(sensor_columns)?;
        self.check_values(t_end)
    }

    /// Every key of `columns` and `scale` a sensor column (`t` too for `columns`), no recording
    /// column mapped twice.
    fn check_names(&self, sensor_columns: &[String]) -> Result<(), ModelError> {
        let known = |c: &str| sensor_columns.iter().any(|s| s == c);
        let listing = sensor_columns.join(", ");
        let columns = self.columns.keys().map(|n| ("columns", n));
        let scales = self.scale.keys().map(|n| ("scale", n));
        for (key, name) in columns.chain(scales) {
            if !(known(name) || (key == "columns" && name == TIME_COLUMN)) {
                return Err(ModelError::invalid(
                    format!("measured.{key}.{name}"),
                    format!("{name:?} is not a sensor column of the experiment (they are t, {listing})"),
                ));
            }
        }
        let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
        for (column, source) in &self.columns {
            if source.trim().is_empty() {
                return Err(ModelError::invalid(
                    format!("measured.columns.{column}"),
                    "names no recording column (empty)",
                ));
            }
            if let Some(other) = seen.insert(source, column) {
                return Err(ModelError::invalid(
                    format!("measured.columns.{column}"),
                    format!("the recording column {source:?} is also mapped to {other}: one column, one channel"),
                ));
            }
        }
        Ok(())
    }

    /// Finite non-zero scales, a finite offset, a positive lag window below the run's span and
    /// only with `offset = "auto"`.
    fn check_values(&self, t_end: f64) -> Result<(), ModelError> {
        if let Some((c, s)) = self.scale.iter().find(|(_, s)| !s.is_finite() || **s == 0.0) {
            return Err(ModelError::invalid(
                format!("measured.scale.{c}"),
                format!("need a finite, non-zero factor, got {s}"),
            ));
        }
        if let Offset::Seconds(o) = self.offset {
            if !o.is_finite() {
                return Err(ModelError::invalid(
                    "measured.offset",
                    format!("need a finite shift in s or \"auto\", got {o}"),
                ));
            }
        }
        if let Some(l) = self.max_lag {
            if self.offset != Offset::Auto {
                return Err(ModelError::invalid(
                    "measured.max_lag",
                    "is the lag window of offset = \"auto\": give it only with that offset",
                ));
            }
            if !(l.is_finite() && l > 0.0 && l < t_end) {
                return Err(ModelError::invalid(
                    "measured.max_lag",
                    format!("need 0 < max_lag < time.t_end = {t_end} s, got {l}"),
                ));
            }
        }
        Ok(())
    }
}

impl Serialize for Offset {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Offset::Seconds(v) => s.serialize_f64(*v),
            Offset::Auto => s.serialize_str("auto"),
        }
    }
}

impl<'de> Deserialize<'de> for Offset {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Offset;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("measured.offset as a shift in s (a number) or \"auto\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Offset, E> {
                Ok(Offset::Seconds(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Offset, E> {
                Ok(Offset::Seconds(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Offset, E> {
                Ok(Offset::Seconds(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Offset, E> {
                match v {
                    "auto" => Ok(Offset::Auto),
                    other => Err(E::custom(format!(
                        "measured.offset: {other:?} is neither a shift in s nor \"auto\""
                    ))),
                }
            }
        }
        d.deserialize_any(V)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cols() -> Vec<String> {
        ["acc_x", "acc_y", "enc"].map(String::from).to_vec()
    }

    fn read(text: &str) -> Result<MeasuredSection, String> {
        toml::from_str::<MeasuredSection>(text).map_err(|e| e.to_string())
    }

    #[test]
    fn offset_reads_a_number_or_auto_and_writes_it_back() {
        assert_eq!(read("offset = 0.012").unwrap().offset, Offset::Seconds(0.012));
        assert_eq!(read("offset = -1").unwrap().offset, Offset::Seconds(-1.0));
        assert_eq!(read("offset = \"auto\"").unwrap().offset, Offset::Auto);
        assert_eq!(read("").unwrap().offset, Offset::Seconds(0.0));
        let e = read("offset = \"later\"").unwrap_err();
        assert!(e.contains("later") && e.contains("auto"), "{e}");
        let e = read("lag = 1.0").unwrap_err();
        assert!(e.contains("lag"), "{e}");
        let m =
            read("offset = \"auto\"\nmax_lag = 0.1\ncolumns = { acc_x = \"ax\" }\nscale = { enc = 0.001 }").unwrap();
        let again = read(&toml::to_string(&m).unwrap()).unwrap();
        assert_eq!(again, m);
    }

    #[test]
    fn names_and_values_are_checked_with_the_key() {
        let check = |text: &str| read(text).unwrap().validate(&cols(), 1.0).map_err(|e| e.to_string());
        check("columns = { t = \"time\", acc_x = \"ax\" }\nscale = { enc = 1e-3 }").unwrap();
        for (text, key, why) in [
            (
                "columns = { acc_z = \"az\" }",
                "measured.columns.acc_z",
                "not a sensor column",
            ),
            ("scale = { t = 2.0 }", "measured.scale.t", "not a sensor column"),
            (
                "columns = { acc_x = \"a\", acc_y = \"a\" }",
                "measured.columns.acc_y",
                "also mapped",
            ),
            ("columns = { acc_x = \"\" }", "measured.columns.acc_x", "empty"),
            ("scale = { enc = 0.0 }", "measured.scale.enc", "non-zero"),
            ("offset = nan", "measured.offset", "finite"),
            ("max_lag = 0.1", "measured.max_lag", "auto"),
            ("offset = \"auto\"\nmax_lag = 2.0", "measured.max_lag", "t_end"),
        ] {
            let e = check(text).unwrap_err();
            assert!(e.contains(key) && e.contains(why), "{text}: {e}");
        }
        let e = MeasuredSection::default().validate(&[], 1.0).unwrap_err().to_string();
        assert!(e.contains("measured") && e.contains("no [[sensors]]"), "{e}");
    }
}
