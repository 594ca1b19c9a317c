//! How `[robot]` and `[base]` are read (`docs/usage.md`, "Your robot"; `docs/as-built.md`).
//!
//! Every beam and sleeve key takes one number (all three beams) or a list of three
//! (`L = [0.42, 0.42, 0.40]`); the axial stiffness is `EA`, or follows from the section area `A`
//! (`EA = E A`) or the material's `density` (`EA = E rho / density`); `weld_deg` gives the beams'
//! weld angles and `[base]` the actuator axes (`sides`, or `points` with `directions`). The robot
//! description holds all of it ([`crate::Robot`]); the solvers model the paper's form, so a value
//! that differs between beams, weld angles other than 0, 120, 240 degrees or an uneven base are
//! refused when the file is read, naming the key, until the solvers take them.

use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;

use crate::params::RobotParams;
use crate::robot::ActuatorAxis;

/// A `[robot]` value for the three beams: one number or a list of three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerBeam(pub [f64; 3]);

impl PerBeam {
    /// The common value of three equal ones; `None` when they differ.
    fn common(&self) -> Option<f64> {
        let [a, b, c] = self.0;
        (a == b && b == c).then_some(a)
    }
}

impl<'de> Deserialize<'de> for PerBeam {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = PerBeam;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number (all three beams) or a list of three numbers (beams 1, 2, 3)")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<PerBeam, E> {
                Ok(PerBeam([v; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<PerBeam, E> {
                Ok(PerBeam([v as f64; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<PerBeam, E> {
                Ok(PerBeam([v as f64; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<PerBeam, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                <[f64; 3]>::try_from(v.as_slice())
                    .map(PerBeam)
                    .map_err(|_| de::Error::invalid_length(v.len(), &"a list of three values, one per beam"))
            }
        }
        d.deserialize_any(V)
    }
}

/// `[robot]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RobotSection {
    #[serde(rename = "E")]
    e: Option<PerBeam>,
    #[serde(rename = "I")]
    i: Option<PerBeam>,
    rho: Option<PerBeam>,
    #[serde(rename = "L")]
    l: Option<PerBeam>,
    d: Option<f64>,
    #[serde(rename = "Lp")]
    lp: Option<PerBeam>,
    mpp_mpa: Option<PerBeam>,
    #[serde(rename = "Jp")]
    jp: Option<PerBeam>,
    #[serde(rename = "EA")]
    ea: Option<PerBeam>,
    /// Section area [m^2]: `EA = E A`.
    #[serde(rename = "A")]
    area: Option<PerBeam>,
    /// Material density [kg/m^3]: `EA = E rho / density`.
    density: Option<PerBeam>,
    /// The beams' weld angles [deg], beam 1 at 0.
    weld_deg: Option<[f64; 3]>,
}

/// One value of the three beams, refused when they differ (the solvers' paper form).
fn one(key: &str, v: Option<PerBeam>, paper: f64) -> Result<f64, String> {
    match v {
        None => Ok(paper),
        Some(p) => p.common().ok_or_else(|| {
            format!(
                "robot.{key} = {:?}: beams with different values are part of the robot description \
                 (docs/as-built.md) but neither solver models them yet; give one value for the three beams",
                p.0
            )
        }),
    }
}

impl TryFrom<RobotSection> for RobotParams {
    type Error = String;

    fn try_from(s: RobotSection) -> Result<Self, String> {
        let paper = RobotParams::paper();
        let e = one("E", s.e, paper.e)?;
        let rho = one("rho", s.rho, paper.rho)?;
        let ea = match (s.ea, s.area, s.density) {
            (None, None, None) => None,
            (Some(v), None, None) => Some(one("EA", Some(v), 0.0)?),
            (None, Some(a), None) => Some(e * one("A", Some(a), 0.0)?),
            (None, None, Some(dens)) => Some(e * rho / one("density", Some(dens), 0.0)?),
            _ => {
                return Err(
                    "robot.EA: give the axial stiffness one way: EA [N], or the section area A [m^2] \
                            (EA = E A), or the density [kg/m^3] (EA = E rho / density)"
                        .into(),
                )
            }
        };
        if let Some(w) = s.weld_deg {
            let paper_welds = [0.0, 120.0, 240.0];
            if w.iter().zip(paper_welds).any(|(a, b)| (a - b).abs() > 1e-9) {
                return Err(format!(
                    "robot.weld_deg = {w:?}: weld angles other than [0, 120, 240] are part of the robot \
                     description (docs/as-built.md) but neither solver models them yet"
                ));
            }
        }
        Ok(RobotParams {
            e,
            i: one("I", s.i, paper.i)?,
            rho,
            l: one("L", s.l, paper.l)?,
            d: s.d.unwrap_or(paper.d),
            lp: one("Lp", s.lp, paper.lp)?,
            mpp_mpa: one("mpp_mpa", s.mpp_mpa, paper.mpp_mpa)?,
            jp: one("Jp", s.jp, paper.jp)?,
            ea,
        })
    }
}

/// `[base]`: the three actuator axes, by the triangle's `sides` [m] or by `points` [m] and
/// `directions` (`docs/as-built.md` 2).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSection {
    pub sides: Option<[f64; 3]>,
    pub points: Option<[[f64; 2]; 3]>,
    pub directions: Option<[[f64; 2]; 3]>,
}

impl BaseSection {
    /// The in-radius `d` [m] of the paper's equilateral base that this section describes; an
    /// error (key, reason) for a base the solvers do not model yet or an invalid one.
    pub fn paper_in_radius(&self) -> Result<f64, (String, String)> {
        let axes = match (self.sides, self.points, self.directions) {
            (Some(sides), None, None) => {
                ActuatorAxis::from_sides(sides).map_err(|e| ("base.sides".into(), e.detail()))?
            }
            (None, Some(points), Some(directions)) => std::array::from_fn(|i| {
                let u = directions[i];
                let n = u[0].hypot(u[1]);
                ActuatorAxis {
                    origin: points[i],
                    direction: [u[0] / n, u[1] / n],
                }
            }),
            _ => {
                return Err((
                    "base".into(),
                    "give either sides = [l1, l2, l3] or points = [[x, y], ...] with directions = [[ux, uy], ...]"
                        .into(),
                ))
            }
        };
        if axes
            .iter()
            .any(|a| !(a.origin.iter().chain(&a.direction).all(|v| v.is_finite())))
        {
            return Err((
                "base".into(),
                "every point and direction must be finite and non-zero".into(),
            ));
        }
        let d = -axes[0].origin[1];
        let paper = d > 0.0
            && (0..3).all(|i| {
                let p = ActuatorAxis::paper(i, d);
                (0..2).all(|k| {
                    (axes[i].origin[k] - p.origin[k]).abs() <= 1e-12 * d
                        && (axes[i].direction[k] - p.direction[k]).abs() <= 1e-12
                })
            });
        if !paper {
            return Err((
                "base".into(),
                format!(
                    "an uneven base is part of the robot description (docs/as-built.md 2) but neither solver \
                     models it yet; its axes are {axes:?}"
                ),
            ));
        }
        Ok(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<RobotParams, String> {
        let s: RobotSection = toml::from_str(text).map_err(|e| e.to_string())?;
        RobotParams::try_from(s)
    }

    #[test]
    fn equal_lists_are_one_value_and_unequal_ones_are_refused_naming_the_key() {
        assert_eq!(read("L = [0.5, 0.5, 0.5]\nJp = 2e-4").unwrap(), RobotParams::paper());
        let e = read("L = [0.42, 0.42, 0.40]").unwrap_err();
        assert!(e.contains("robot.L") && e.contains("docs/as-built.md"), "{e}");
        let e = read("L = [0.42, 0.42]").unwrap_err();
        assert!(e.contains("three"), "{e}");
        let e = read("L = \"long\"").unwrap_err();
        assert!(e.contains("a list of three numbers"), "{e}");
    }

    #[test]
    fn the_axial_stiffness_follows_from_the_area_or_the_density() {
        // aluminium strip 20 mm x 2 mm, E = 70 GPa: EA = 2.8e6 N
        let p = read("E = 70e9\nrho = 0.108\nA = 4e-5").unwrap();
        assert!((p.ea() - 2.8e6).abs() < 1e-6);
        // the same from its density 2700 kg/m^3: A = rho / density = 4e-5 m^2
        let q = read("E = 70e9\nrho = 0.108\ndensity = 2700").unwrap();
        assert!((q.ea() / 2.8e6 - 1.0).abs() < 1e-12);
        // steel (the default when none is given): E rho / 7800
        assert_eq!(read("").unwrap().ea, None);
        let e = read("EA = 1e6\nA = 1e-5").unwrap_err();
        assert!(e.contains("one way"), "{e}");
    }

    #[test]
    fn the_paper_welds_and_base_are_accepted_and_others_refused() {
        assert!(read("weld_deg = [0, 120, 240]").is_ok());
        assert!(read("weld_deg = [0, 121, 240]").unwrap_err().contains("robot.weld_deg"));
        let equal = BaseSection {
            sides: Some([2.0 * 3f64.sqrt() * 0.2; 3]),
            points: None,
            directions: None,
        };
        assert!((equal.paper_in_radius().unwrap() - 0.2).abs() < 1e-15);
        let uneven = BaseSection {
            sides: Some([0.62, 0.64, 0.61]),
            ..equal.clone()
        };
        assert!(uneven.paper_in_radius().unwrap_err().1.contains("uneven base"));
        let paper = RobotParams::paper();
        let by_points = BaseSection {
            sides: None,
            points: Some(std::array::from_fn(|i| ActuatorAxis::paper(i, paper.d).origin)),
            directions: Some(std::array::from_fn(|i| ActuatorAxis::paper(i, paper.d).direction)),
        };
        assert_eq!(by_points.paper_in_radius().unwrap(), paper.d);
    }
}
