//! `[gravity]`: a uniform gravity field in the plane of the robot, for a robot working in a
//! vertical plane (`docs/as-built.md` 5, Eqs. G1-G5).
//!
//! ```toml
//! [gravity]
//! g = [0.0, -9.81]     # m/s^2, base frame (X, Y of docs/conventions.md)
//! ```
//! It acts on the beams, the sleeves, the sliders and the payload. Default: none (`[0, 0]`),
//! which leaves every equation as it was.

use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

use crate::error::ModelError;

/// `[gravity]` (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gravity {
    /// The acceleration of gravity `[gx, gy]` [m/s^2] in the base frame.
    #[serde(deserialize_with = "planar")]
    pub g: [f64; 2],
}

impl Gravity {
    /// Gravity `g` [m/s^2], base frame.
    pub fn new(g: [f64; 2]) -> Self {
        Gravity { g }
    }

    /// No gravity (the default).
    pub fn is_none(&self) -> bool {
        self.g == [0.0, 0.0]
    }

    /// Check the vector (key `gravity.g`).
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.g.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::invalid(
                "gravity.g",
                format!("must be two finite numbers [gx, gy] in m/s^2, got {:?}", self.g),
            ));
        }
        Ok(())
    }
}

/// `g` as written: exactly two numbers, the field in the robot's plane.
fn planar<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    struct V;
    impl<'de> Visitor<'de> for V {
        type Value = [f64; 2];
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("gravity.g as the field in the robot's plane, [gx, gy] in m/s^2 (base frame)")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; 2], A::Error> {
            let mut v = Vec::new();
            while let Some(x) = seq.next_element::<f64>()? {
                v.push(x);
            }
            <[f64; 2]>::try_from(v.as_slice()).map_err(|_| {
                de::Error::custom(format!(
                    "gravity acts in the robot's plane: give [gx, gy] in m/s^2 (base frame), got {} components{}",
                    v.len(),
                    if v.len() == 3 {
                        " (a component normal to the plane is carried by the base, not modelled)"
                    } else {
                        ""
                    }
                ))
            })
        }
    }
    d.deserialize_seq(V)
}

#[cfg(test)]
mod tests {
    use crate::Experiment;
    use std::path::Path;

    fn load(extra: &str) -> Result<Experiment, String> {
        crate::attachments::tests::load(extra, Path::new("g.toml"))
    }

    #[test]
    fn gravity_reads_and_defaults_to_none() {
        assert!(load("").unwrap().gravity.is_none());
        assert_eq!(load("[gravity]\ng = [0.0, -9.81]").unwrap().gravity.g, [0.0, -9.81]);
    }

    #[test]
    fn bad_gravity_names_file_and_key() {
        for (extra, key, why) in [
            ("[gravity]\ng = [0.0, 0.0, -9.81]", "gravity", "normal to the plane"),
            ("[gravity]\ng = [1.0]", "gravity", "plane"),
            ("[gravity]\ng = [0.0, nan]", "gravity.g", "finite"),
            ("[gravity]\ng = -9.81", "gravity.g", "plane"),
            ("[gravity]\ngz = 1.0", "gz", "unknown"),
        ] {
            let e = load(extra).unwrap_err();
            assert!(
                e.contains("g.toml") && e.contains(key) && e.contains(why),
                "{extra}: {e}"
            );
        }
    }
}
