//! Robot parameters (paper, section 8; docs/paper-defects.md, Parameters).

use serde::{Deserialize, Serialize, Serializer};

use crate::error::ModelError;

/// The `[robot]` section: the paper's compact form of the robot, one set of beam values for the
/// three beams and the in-radius `d` of the equilateral base. The solvers read the per-beam
/// [`crate::Robot`] built from it ([`crate::Robot::from_params`]; `docs/architecture.md`, "The
/// robot description").
///
/// TOML keys keep the paper's symbols (`E`, `I`, `rho`, `L`, `d`, `Lp`, `mpp_mpa`, `Jp`); every
/// key is optional and defaults to the paper's value (section 8).
/// Read through [`crate::robot_section`]: a key may be a list of three values, `EA` may come
/// from `A` or `density`, and `weld_deg` and `[base]` may be given. A robot other than the
/// paper's (values that differ between beams, other weld angles, an uneven base) is carried
/// whole in [`RobotParams::as_built`]; the fields then hold beam 1's values and the in-radius
/// of the base, and every reader of beam data reads the per-beam [`crate::Robot`] instead
/// ([`crate::Problem::robot`], [`crate::RobotGeometry`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(try_from = "crate::robot_section::RobotSection")]
pub struct RobotParams {
    /// Young's modulus E [Pa].
    #[serde(rename = "E")]
    pub e: f64,
    /// Second moment of area I of the beam section [m^4].
    #[serde(rename = "I")]
    pub i: f64,
    /// Mass per unit length rho of each beam [kg/m].
    pub rho: f64,
    /// Beam length L, junction G to free tip [m].
    #[serde(rename = "L")]
    pub l: f64,
    /// In-radius d of the base triangle [m] (Eqs. 1-3).
    pub d: f64,
    /// Sleeve (passive prismatic joint) length Lp [m].
    #[serde(rename = "Lp")]
    pub lp: f64,
    /// Mass of passive + active prismatic joint, mpp + mpa [kg] (Eq. 33).
    pub mpp_mpa: f64,
    /// Rotational inertia Jp of a sleeve about its pin [kg m^2] (Eq. 31).
    #[serde(rename = "Jp")]
    pub jp: f64,
    /// Axial stiffness EA [N] used by models with axially flexible beams (FEM).
    /// Default `E * rho / 7800` (steel density), docs/paper-defects.md: 6e6 N.
    #[serde(rename = "EA")]
    pub ea: Option<f64>,
    /// The robot as built when it is not the paper's (`docs/as-built.md`): every beam's data,
    /// its weld angle and the actuator axes; `None` for the paper's form.
    #[serde(skip)]
    pub as_built: Option<crate::robot::AsBuilt>,
}

impl Default for RobotParams {
    fn default() -> Self {
        Self::paper()
    }
}

impl RobotParams {
    /// The paper's parameters (section 8).
    pub fn paper() -> Self {
        RobotParams {
            e: 200e9,
            i: 2.5e-12,
            rho: 0.234,
            l: 0.5,
            d: 0.18,
            lp: 0.03,
            mpp_mpa: 0.2,
            jp: 2e-4,
            ea: None,
            as_built: None,
        }
    }

    /// Bending stiffness EI [N m^2].
    pub fn ei(&self) -> f64 {
        self.e * self.i
    }

    /// Axial stiffness EA [N]: the given value or `E * rho / 7800`.
    pub fn ea(&self) -> f64 {
        self.ea.unwrap_or(self.e * self.rho / 7800.0)
    }

    /// Half a side of the base triangle, `sqrt(3) d` [m]: a slider stays within `|s_i| < sqrt(3) d`.
    pub fn half_side(&self) -> f64 {
        3f64.sqrt() * self.d
    }

    /// Mass of the rigid star, `3 rho L` [kg].
    pub fn star_mass(&self) -> f64 {
        3.0 * self.rho * self.l
    }

    /// Rotational inertia of the rigid star about G, `3 rho L^3 / 3 = rho L^3` [kg m^2].
    pub fn star_inertia(&self) -> f64 {
        self.rho * self.l.powi(3)
    }

    /// Check every parameter; the error names the key and the reason. A robot as built is
    /// checked beam by beam (`robot.L[3]`), with its weld angles and axes ([`crate::Robot::new`]).
    pub fn validate(&self) -> Result<(), ModelError> {
        if let Some(a) = &self.as_built {
            crate::Robot::new(a.beams, a.axes)?;
            for b in &a.beams {
                // the base is checked by Robot::new; d does not describe an uneven one
                let one = b.params(RobotParams::paper().d);
                one.check_derived()?;
            }
            return Ok(());
        }
        let positive = [
            ("robot.E", self.e),
            ("robot.I", self.i),
            ("robot.rho", self.rho),
            ("robot.L", self.l),
            ("robot.d", self.d),
            ("robot.Lp", self.lp),
        ];
        for (key, v) in positive {
            if !v.is_finite() || v <= 0.0 {
                return Err(ModelError::invalid(
                    key,
                    format!("must be a positive finite number, got {v}"),
                ));
            }
        }
        for (key, v) in [("robot.mpp_mpa", self.mpp_mpa), ("robot.Jp", self.jp)] {
            if !v.is_finite() || v < 0.0 {
                return Err(ModelError::invalid(
                    key,
                    format!("must be a finite number >= 0, got {v}"),
                ));
            }
        }
        if let Some(ea) = self.ea {
            if !ea.is_finite() || ea <= 0.0 {
                return Err(ModelError::invalid(
                    "robot.EA",
                    format!("must be a positive finite number, got {ea}"),
                ));
            }
        }
        if self.lp >= self.l {
            return Err(ModelError::invalid(
                "robot.Lp",
                format!(
                    "the sleeve must be shorter than the beam: 0 < Lp < L = {}, got {}",
                    self.l, self.lp
                ),
            ));
        }
        self.check_derived()?;
        if self.d + self.lp / 2.0 >= self.l {
            return Err(ModelError::invalid(
                "robot.L",
                format!(
                    "the beams must pass through the sleeves at the start: need d + Lp/2 < L, got d = {}, Lp = {}, L = {}",
                    self.d, self.lp, self.l
                ),
            ));
        }
        Ok(())
    }

    /// Every quantity the solvers derive from the parameters must be a finite positive number:
    /// a value that makes one overflow to infinity or underflow to zero (`L = 1e300`: `rho L^3`
    /// is infinite) is refused, naming the key among those involved that lies farthest from the
    /// paper's value (in decades) and the quantity.
    fn check_derived(&self) -> Result<(), ModelError> {
        let paper = RobotParams::paper();
        let t_scale = self.l * self.l * (self.rho / self.ei()).sqrt();
        let ea_keys: &[&str] = if self.ea.is_some() { &["EA"] } else { &["E", "rho"] };
        let derived: [(&str, f64, &[&str]); 8] = [
            ("E I (the bending stiffness)", self.ei(), &["E", "I"]),
            ("EA (the axial stiffness)", self.ea(), ea_keys),
            ("3 rho L (the star's mass)", self.star_mass(), &["rho", "L"]),
            (
                "rho L^3 (the star's inertia about G)",
                self.star_inertia(),
                &["rho", "L"],
            ),
            (
                "L^2 sqrt(rho / EI) (a beam's time scale)",
                t_scale,
                &["L", "rho", "E", "I"],
            ),
            (
                "EI / L^3 (a beam's stiffness)",
                self.ei() / self.l.powi(3),
                &["E", "I", "L"],
            ),
            (
                "EA / L (the axial stiffness per length)",
                self.ea() / self.l,
                &["E", "rho", "L"],
            ),
            ("2 sqrt(3) d (the base triangle's side)", 2.0 * self.half_side(), &["d"]),
        ];
        for (what, v, keys) in derived {
            if v.is_finite() && v > 0.0 {
                continue;
            }
            let value = |k: &str| match k {
                "E" => (self.e, paper.e),
                "I" => (self.i, paper.i),
                "rho" => (self.rho, paper.rho),
                "L" => (self.l, paper.l),
                "d" => (self.d, paper.d),
                _ => (self.ea(), paper.ea()),
            };
            let decades = |k: &&str| {
                let (v, p) = value(k);
                (v / p).log10().abs()
            };
            let key = keys
                .iter()
                .copied()
                .max_by(|a, b| decades(a).total_cmp(&decades(b)))
                .unwrap_or("L");
            let given: Vec<String> = keys
                .iter()
                .map(|k| format!("{k} = {}", flexstar_io::output::fmt_display(value(k).0)))
                .collect();
            let how = if v.is_finite() { "underflow to 0" } else { "overflow" };
            return Err(ModelError::invalid(
                format!("robot.{key}"),
                format!(
                    "{} makes {what} {how} (with {}); every quantity derived from the robot must be a finite, \
                     positive number: give a physical value (SI units: m, kg/m, Pa, m^4)",
                    flexstar_io::output::fmt_display(value(key).0),
                    given.join(", ")
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_values_give_ei_half() {
        // paper, section 8 (docs/paper-defects.md): EI = 0.5 N m^2, EA = 6e6 N.
        let p = RobotParams::paper();
        assert!((p.ei() - 0.5).abs() < 1e-12);
        assert!((p.ea() - 6e6).abs() < 1e-6);
        p.validate().unwrap();
    }

    #[test]
    fn rejects_nan_and_negative() {
        let mut p = RobotParams::paper();
        p.rho = f64::NAN;
        assert!(p.validate().unwrap_err().to_string().contains("robot.rho"));
        let mut p = RobotParams::paper();
        p.l = -1.0;
        assert!(p.validate().unwrap_err().to_string().contains("robot.L"));
    }

    #[test]
    fn values_whose_derived_quantities_overflow_are_refused_naming_the_key() {
        // L = 1e300: rho L^3 = 0.234e900 is beyond the largest double (1.8e308)
        let mut p = RobotParams::paper();
        p.l = 1e300;
        let e = p.validate().unwrap_err().to_string();
        assert!(
            e.contains("robot.L") && e.contains("1e300") && e.contains("overflow"),
            "{e}"
        );
        // E I = 1e-320 Pa m^4 underflows (below the smallest normal double), naming I (further
        // from the paper's 2.5e-12 than E from 200e9)
        let mut p = RobotParams::paper();
        p.e = 1e-150;
        p.i = 1e-200;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("robot.I") && e.contains("underflow"), "{e}");
        // large but representable values pass: L = 1e100 m with d and Lp of its size
        let mut p = RobotParams::paper();
        p.l = 1e100;
        p.d = 1e99;
        assert!(p.validate().is_ok());
    }
}

/// One value for the three beams, or a list of three where they differ (how `[robot]` is written
/// back, e.g. in a run's sidecar: the per-beam values used).
#[derive(Serialize)]
#[serde(untagged)]
enum Written {
    One(f64),
    Three([f64; 3]),
}

impl Written {
    fn of(v: [f64; 3]) -> Self {
        if v[0] == v[1] && v[1] == v[2] {
            Written::One(v[0])
        } else {
            Written::Three(v)
        }
    }
}

/// `[robot]` as it is written back: the keys of the file, per beam where the beams differ,
/// `weld_deg` when the welds are not the paper's, and `d` unless the base is uneven (then the
/// experiment writes `[base]`).
#[derive(Serialize)]
struct RobotWritten {
    #[serde(rename = "E")]
    e: Written,
    #[serde(rename = "I")]
    i: Written,
    rho: Written,
    #[serde(rename = "L")]
    l: Written,
    #[serde(skip_serializing_if = "Option::is_none")]
    d: Option<f64>,
    #[serde(rename = "Lp")]
    lp: Written,
    mpp_mpa: Written,
    #[serde(rename = "Jp")]
    jp: Written,
    #[serde(rename = "EA")]
    ea: Option<Written>,
    #[serde(skip_serializing_if = "Option::is_none")]
    weld_deg: Option<[f64; 3]>,
}

impl Serialize for RobotParams {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        let written = match &self.as_built {
            None => RobotWritten {
                e: Written::One(self.e),
                i: Written::One(self.i),
                rho: Written::One(self.rho),
                l: Written::One(self.l),
                d: Some(self.d),
                lp: Written::One(self.lp),
                mpp_mpa: Written::One(self.mpp_mpa),
                jp: Written::One(self.jp),
                ea: self.ea.map(Written::One),
                weld_deg: None,
            },
            Some(a) => {
                let per = |f: fn(&crate::Beam) -> f64| Written::of(a.beams.map(|b| f(&b)));
                let paper_axes = (0..3).all(|i| a.axes[i] == crate::ActuatorAxis::paper(i, self.d));
                let welds = a.beams.map(|b| b.weld_angle);
                let paper_welds = (0..3).all(|i| welds[i] == crate::geometry::beam_offset(i));
                RobotWritten {
                    e: per(|b| b.youngs_modulus),
                    i: per(|b| b.second_moment),
                    rho: per(|b| b.mass_per_length),
                    l: per(|b| b.length),
                    d: paper_axes.then_some(self.d),
                    lp: per(|b| b.sleeve_length),
                    mpp_mpa: per(|b| b.sleeve_mass),
                    jp: per(|b| b.sleeve_inertia),
                    ea: Some(per(|b| b.axial_stiffness)),
                    weld_deg: (!paper_welds).then(|| welds.map(f64::to_degrees)),
                }
            }
        };
        written.serialize(ser)
    }
}
