//! How `[robot]` and `[base]` are read (`docs/usage.md`, "Your robot"; `docs/as-built.md`).
//!
//! Every beam and sleeve key takes one number (all three beams) or a list of three
//! (`L = [0.42, 0.42, 0.40]`); the axial stiffness is `EA`, or follows from the section area `A`
//! (`EA = E A`) or the material's `density` (`EA = E rho / density`); `weld_deg` gives the beams'
//! weld angles and `[base]` the actuator axes (`sides`, or `points` with `directions`). The robot
//! description holds all of it ([`crate::Robot`]): a robot other than the paper's (a value that
//! differs between beams, weld angles other than 0, 120, 240 degrees, an uneven base) is carried
//! whole in [`RobotParams::as_built`]; a command or solver that does not model it yet refuses it
//! by name (`docs/as-built.md` 6).

use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::params::RobotParams;
use crate::robot::{ActuatorAxis, AsBuilt};

/// A `[robot]` value for the three beams: one number or a list of three (also the per-sleeve
/// and per-slider values of `[friction]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerBeam(pub [f64; 3]);

impl PerBeam {
    /// The same value for all three.
    pub fn all(v: f64) -> Self {
        PerBeam([v; 3])
    }
}

impl Default for PerBeam {
    /// Zero for all three (the `[friction]` coefficients left out).
    fn default() -> Self {
        PerBeam::all(0.0)
    }
}

impl Serialize for PerBeam {
    /// Written back as it reads: one number when the three are equal (by bits), else the list.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = self.0;
        if v[1].to_bits() == v[0].to_bits() && v[2].to_bits() == v[0].to_bits() {
            s.serialize_f64(v[0])
        } else {
            v.serialize(s)
        }
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

/// The three beams' values of a key: the given ones, or the paper's for the three.
fn list(v: Option<PerBeam>, paper: f64) -> [f64; 3] {
    v.map_or([paper; 3], |p| p.0)
}

/// Weld angles within this of the paper's (degrees) are the paper's: `120.0` written in a file is
/// the paper's `2 pi / 3`.
const PAPER_WELD_TOL_DEG: f64 = 1e-9;

impl TryFrom<RobotSection> for RobotParams {
    type Error = String;

    fn try_from(s: RobotSection) -> Result<Self, String> {
        let paper = RobotParams::paper();
        let e = list(s.e, paper.e);
        let rho = list(s.rho, paper.rho);
        let ea: Option<[f64; 3]> = match (s.ea, s.area, s.density) {
            (None, None, None) => None,
            (Some(v), None, None) => Some(v.0),
            (None, Some(a), None) => Some(std::array::from_fn(|k| e[k] * a.0[k])),
            (None, None, Some(dens)) => Some(std::array::from_fn(|k| e[k] * rho[k] / dens.0[k])),
            _ => {
                return Err(
                    "robot.EA: give the axial stiffness one way: EA [N], or the section area A [m^2] \
                            (EA = E A), or the density [kg/m^3] (EA = E rho / density)"
                        .into(),
                )
            }
        };
        let values = [
            e,
            list(s.i, paper.i),
            rho,
            list(s.l, paper.l),
            list(s.lp, paper.lp),
            list(s.mpp_mpa, paper.mpp_mpa),
            list(s.jp, paper.jp),
        ];
        let [e, i, rho, l, lp, mpp_mpa, jp] = values;
        let paper_welds = [0.0, 120.0, 240.0];
        let welds = s.weld_deg.filter(|w| {
            w.iter()
                .zip(paper_welds)
                .any(|(a, b)| (a - b).abs() > PAPER_WELD_TOL_DEG)
        });
        let compact = RobotParams {
            e: e[0],
            i: i[0],
            rho: rho[0],
            l: l[0],
            d: s.d.unwrap_or(paper.d),
            lp: lp[0],
            mpp_mpa: mpp_mpa[0],
            jp: jp[0],
            ea: ea.map(|v| v[0]),
            as_built: None,
        };
        // by bits: three NaN are one (invalid) value, refused by the compact form's checks
        let equal = |v: &[f64; 3]| v[0].to_bits() == v[1].to_bits() && v[1].to_bits() == v[2].to_bits();
        if welds.is_none() && values.iter().all(equal) && ea.as_ref().is_none_or(equal) {
            return Ok(compact);
        }
        // a robot as built: beam 1's values above, every beam's here
        let mut a = AsBuilt::of_paper(&compact);
        for (k, b) in a.beams.iter_mut().enumerate() {
            b.youngs_modulus = e[k];
            b.second_moment = i[k];
            b.mass_per_length = rho[k];
            b.length = l[k];
            b.sleeve_length = lp[k];
            b.sleeve_mass = mpp_mpa[k];
            b.sleeve_inertia = jp[k];
            b.axial_stiffness = ea.map_or(e[k] * rho[k] / 7800.0, |v| v[k]);
            if let Some(w) = welds {
                b.weld_angle = w[k].to_radians();
            }
        }
        Ok(RobotParams {
            as_built: Some(a),
            ..compact
        })
    }
}

/// `[base]`: the three actuator axes, by the triangle's `sides` [m] or by `points` [m] and
/// `directions` (`docs/as-built.md` 2).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSection {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sides: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<[[f64; 2]; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub directions: Option<[[f64; 2]; 3]>,
}

impl BaseSection {
    /// The three actuator axes this section gives (`docs/as-built.md` 2: from the sides, Eq. B1,
    /// or the points and directions, normalised); an error (key, reason) for an invalid base.
    pub fn axes(&self) -> Result<[ActuatorAxis; 3], (String, String)> {
        let axes = match (self.sides, self.points, self.directions) {
            (Some(sides), None, None) => {
                ActuatorAxis::from_sides(sides).map_err(|e| ("base.sides".into(), e.detail()))?
            }
            (None, Some(points), Some(directions)) => {
                let mut axes = [ActuatorAxis::paper(0, 1.0); 3];
                for (k, axis) in axes.iter_mut().enumerate() {
                    let u = directions[k];
                    let n = u[0].hypot(u[1]);
                    if !(n.is_finite() && n > 0.0 && points[k].iter().all(|v| v.is_finite())) {
                        return Err((
                            format!("base.directions[{}]", k + 1),
                            format!("every point and direction must be finite and the direction non-zero, got point {:?}, direction {u:?}", points[k]),
                        ));
                    }
                    *axis = ActuatorAxis {
                        origin: points[k],
                        direction: [u[0] / n, u[1] / n],
                    };
                }
                axes
            }
            _ => {
                return Err((
                    "base".into(),
                    "give either sides = [l1, l2, l3] or points = [[x, y], ...] with directions = [[ux, uy], ...]"
                        .into(),
                ))
            }
        };
        Ok(axes)
    }

    /// The in-radius `d` [m] when the axes are the paper's equilateral base centred at O (to
    /// rounding), else `None`: the base is uneven.
    pub fn paper_in_radius(axes: &[ActuatorAxis; 3]) -> Option<f64> {
        let d = -axes[0].origin[1];
        let paper = d > 0.0
            && (0..3).all(|i| {
                let p = ActuatorAxis::paper(i, d);
                (0..2).all(|k| {
                    (axes[i].origin[k] - p.origin[k]).abs() <= 1e-12 * d
                        && (axes[i].direction[k] - p.direction[k]).abs() <= 1e-12
                })
            });
        paper.then_some(d)
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
    fn equal_lists_are_one_value_and_unequal_ones_a_robot_as_built() {
        assert_eq!(read("L = [0.5, 0.5, 0.5]\nJp = 2e-4").unwrap(), RobotParams::paper());
        let p = read("L = [0.42, 0.42, 0.40]\nE = 70e9\nrho = 0.108\nA = 4e-5").unwrap();
        let a = p.as_built.expect("beams differ");
        assert_eq!(a.beams.map(|b| b.length), [0.42, 0.42, 0.40]);
        // the material's EA follows per beam: E A = 2.8e6 N for each
        assert!(a.beams.iter().all(|b| (b.axial_stiffness - 2.8e6).abs() < 1e-6));
        // beam 1's values in the compact form; the paper's base and welds
        assert_eq!((p.l, p.e), (0.42, 70e9));
        assert_eq!(a.axes, std::array::from_fn(|i| ActuatorAxis::paper(i, p.d)));
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
    fn the_paper_welds_and_base_are_the_paper_form_and_others_a_robot_as_built() {
        assert_eq!(read("weld_deg = [0, 120, 240]").unwrap(), RobotParams::paper());
        let w = read("weld_deg = [0, 121, 240]").unwrap().as_built.unwrap();
        assert_eq!(w.beams[1].weld_angle, 121f64.to_radians());
        let equal = BaseSection {
            sides: Some([2.0 * 3f64.sqrt() * 0.2; 3]),
            points: None,
            directions: None,
        };
        let d = BaseSection::paper_in_radius(&equal.axes().unwrap()).unwrap();
        assert!((d - 0.2).abs() < 1e-15);
        let uneven = BaseSection {
            sides: Some([0.62, 0.64, 0.61]),
            ..equal.clone()
        };
        assert_eq!(BaseSection::paper_in_radius(&uneven.axes().unwrap()), None);
        let paper = RobotParams::paper();
        let by_points = BaseSection {
            sides: None,
            points: Some(std::array::from_fn(|i| ActuatorAxis::paper(i, paper.d).origin)),
            directions: Some(std::array::from_fn(|i| ActuatorAxis::paper(i, paper.d).direction)),
        };
        assert_eq!(BaseSection::paper_in_radius(&by_points.axes().unwrap()), Some(paper.d));
        let zero = BaseSection {
            directions: Some([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]),
            ..by_points
        };
        assert_eq!(zero.axes().unwrap_err().0, "base.directions[2]");
    }
}
