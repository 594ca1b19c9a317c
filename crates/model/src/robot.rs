//! The robot as data: three beams, each with its own section, sleeve and weld angle, and three
//! actuator axes (`docs/architecture.md`, "The robot description").
//!
//! Frames and signs follow `docs/conventions.md`: the fixed XY frame with origin O at the centre
//! of the base triangle; beam i's rigid axis `e_xi` at the angle `theta + weld_i` of Eq. 11.
//! The paper's robot (section 8: three equal beams welded 120 degrees apart on an equilateral base)
//! is one value of this data; whether a robot is that one is an explicit check on the data
//! ([`Robot::equal_beams`]), which the solvers' equal-beam fast paths (one mode set for the three
//! beams, the FEM's three SIMD lanes) rely on.

use crate::error::ModelError;
use crate::geometry::{beam_offset, revolute_origin, slider_direction};
use crate::params::RobotParams;

/// One flexible beam of the star with its sleeve (the passive prismatic joint it slides through).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Young's modulus E [Pa].
    pub youngs_modulus: f64,
    /// Second moment of area I of the section [m^4].
    pub second_moment: f64,
    /// Axial stiffness EA [N].
    pub axial_stiffness: f64,
    /// Mass per unit length rho [kg/m].
    pub mass_per_length: f64,
    /// Length L, junction G to free tip [m].
    pub length: f64,
    /// Sleeve length Lp [m].
    pub sleeve_length: f64,
    /// Mass of the sleeve and its slider, mpp + mpa [kg] (Eq. 33).
    pub sleeve_mass: f64,
    /// Rotational inertia Jp of the sleeve about its pin [kg m^2] (Eq. 31).
    pub sleeve_inertia: f64,
    /// Angle of the beam's rigid axis at the weld, from beam 1's [rad]: the offset
    /// `(i - 1) 2 pi / 3` of Eqs. 11-12 on the paper's robot.
    pub weld_angle: f64,
}

impl Beam {
    /// This beam in the paper's compact form, as if the three were equal, on the base of
    /// in-radius `d` [m]: what a one-beam computation (a mode set, a sleeve, a check) reads.
    pub fn params(&self, d: f64) -> RobotParams {
        RobotParams {
            e: self.youngs_modulus,
            i: self.second_moment,
            rho: self.mass_per_length,
            l: self.length,
            d,
            lp: self.sleeve_length,
            mpp_mpa: self.sleeve_mass,
            jp: self.sleeve_inertia,
            ea: Some(self.axial_stiffness),
            as_built: None,
        }
    }

    /// Bending stiffness EI [N m^2].
    pub fn bending_stiffness(&self) -> f64 {
        self.youngs_modulus * self.second_moment
    }
}

/// The line an actuated slider moves along: its revolute point is `origin + s direction`
/// (Eqs. 1-3 on the paper's base) [m], fixed frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorAxis {
    /// The revolute point at `s = 0` [m].
    pub origin: [f64; 2],
    /// Unit direction of increasing `s`.
    pub direction: [f64; 2],
}

impl ActuatorAxis {
    /// Axis i of the paper's equilateral base of in-radius `d` [m] (Eqs. 1-3).
    pub fn paper(i: usize, d: f64) -> Self {
        ActuatorAxis {
            origin: revolute_origin(i, d),
            direction: slider_direction(i),
        }
    }

    /// The three axes on the sides of the triangle of side lengths `sides` [m]
    /// (`docs/as-built.md` 2, Eq. B1): origin at the in-centre, side 1 below it parallel to X,
    /// slider i along side i from A_i towards A_(i+1), `s_i = 0` where the in-circle touches it.
    /// Errors name `base.sides` when the sides make no triangle.
    pub fn from_sides(sides: [f64; 3]) -> Result<[ActuatorAxis; 3], ModelError> {
        let [l1, l2, l3] = sides;
        let p = 0.5 * (l1 + l2 + l3);
        let (e1, e2, e3) = (p - l1, p - l2, p - l3);
        if !sides.iter().all(|l| l.is_finite() && *l > 0.0) || e1 <= 0.0 || e2 <= 0.0 || e3 <= 0.0 {
            return Err(ModelError::invalid(
                "base.sides",
                format!("need three positive lengths, each shorter than the sum of the other two, got {sides:?}"),
            ));
        }
        // Heron's area, the in-radius and the tangent lengths from A_1, A_2, A_3
        let r = (p * e1 * e2 * e3).sqrt() / p;
        let t = [e2, e3, e1];
        let cos_a1 = (l1 * l1 + l3 * l3 - l2 * l2) / (2.0 * l1 * l3);
        let sin_a1 = (1.0 - cos_a1 * cos_a1).max(0.0).sqrt();
        let a = [[-t[0], -r], [l1 - t[0], -r], [-t[0] + l3 * cos_a1, -r + l3 * sin_a1]];
        Ok(std::array::from_fn(|i| {
            let (from, to) = (a[i], a[(i + 1) % 3]);
            let u = [(to[0] - from[0]) / sides[i], (to[1] - from[1]) / sides[i]];
            ActuatorAxis {
                origin: [from[0] + t[i] * u[0], from[1] + t[i] * u[1]],
                direction: u,
            }
        }))
    }
}

/// The data of a robot other than the paper's, as the file gives it (`[robot]` lists,
/// `weld_deg`, `[base]`): carried by [`RobotParams::as_built`] and checked by [`Robot::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsBuilt {
    pub beams: [Beam; 3],
    pub axes: [ActuatorAxis; 3],
}

impl AsBuilt {
    /// The paper's robot of `params` as data: its beams welded 120 degrees apart on the
    /// equilateral base of in-radius `params.d`, to be changed key by key.
    pub fn of_paper(params: &RobotParams) -> Self {
        let beam = |i: usize| Beam {
            youngs_modulus: params.e,
            second_moment: params.i,
            axial_stiffness: params.ea(),
            mass_per_length: params.rho,
            length: params.l,
            sleeve_length: params.lp,
            sleeve_mass: params.mpp_mpa,
            sleeve_inertia: params.jp,
            weld_angle: beam_offset(i),
        };
        AsBuilt {
            beams: [beam(0), beam(1), beam(2)],
            axes: std::array::from_fn(|i| ActuatorAxis::paper(i, params.d)),
        }
    }
}

/// The robot: its three beams and three actuator axes, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    beams: [Beam; 3],
    axes: [ActuatorAxis; 3],
    /// The paper-form parameters when the data is the paper's robot (equal beams, 120-degree
    /// welds, equilateral base), else the first datum that differs ([`paper_form`]).
    equal: Result<RobotParams, String>,
}

impl Robot {
    /// A robot from its beams and axes, each value checked (`robot.<key>` names the beam:
    /// `robot.L[2]`).
    pub fn new(beams: [Beam; 3], axes: [ActuatorAxis; 3]) -> Result<Self, ModelError> {
        for (i, b) in beams.iter().enumerate() {
            check_beam(i, b)?;
        }
        for (i, a) in axes.iter().enumerate() {
            let norm = a.direction[0].hypot(a.direction[1]);
            if !(a.origin.iter().all(|v| v.is_finite()) && (norm - 1.0).abs() < 1e-9) {
                return Err(ModelError::invalid(
                    format!("base.axes[{}]", i + 1),
                    format!("need a finite origin and a unit direction, got {a:?}"),
                ));
            }
        }
        check_welds(&beams)?;
        let equal = paper_form(&beams, &axes);
        Ok(Robot { beams, axes, equal })
    }

    /// The robot `params` describe (every value checked by [`RobotParams::validate`]): its
    /// [`RobotParams::as_built`] data when it has some, else the paper's form, three equal beams
    /// of `params` welded 120 degrees apart on the equilateral base of in-radius `params.d`.
    pub fn from_params(params: &RobotParams) -> Result<Self, ModelError> {
        params.validate()?;
        if let Some(a) = params.as_built {
            return Self::new(a.beams, a.axes);
        }
        let a = AsBuilt::of_paper(params);
        let mut robot = Self::new(a.beams, a.axes)?;
        // the check found the paper's robot; keep the caller's own form of it (`EA` given or
        // defaulted), so that it compares equal with the parameters it came from
        if robot.equal.is_ok() {
            robot.equal = Ok(*params);
        }
        Ok(robot)
    }

    /// The compact form that carries this robot, for a holder of [`RobotParams`]: the paper's
    /// form when it is the paper's robot ([`Robot::equal_beams`]), else beam 1's values with the
    /// whole robot in [`RobotParams::as_built`] and `d` the distance of O from axis 1 (the
    /// in-radius of a base from sides) [m]. [`Robot::from_params`] of it is this robot again.
    pub fn to_params(&self) -> RobotParams {
        if let Ok(p) = &self.equal {
            return *p;
        }
        let a = self.axes[0];
        let d = (a.origin[0] * a.direction[1] - a.origin[1] * a.direction[0]).abs();
        RobotParams {
            as_built: Some(AsBuilt {
                beams: self.beams,
                axes: self.axes,
            }),
            ..self.beams[0].params(d)
        }
    }

    /// The three beams, beam 1 first.
    pub fn beams(&self) -> &[Beam; 3] {
        &self.beams
    }

    /// The three actuator axes, slider 1 first.
    pub fn axes(&self) -> &[ActuatorAxis; 3] {
        &self.axes
    }

    /// The weld angles phi_i [rad] (`docs/as-built.md` Eq. W1; phi_1 = 0).
    pub fn weld_angles(&self) -> [f64; 3] {
        self.beams.map(|b| b.weld_angle)
    }

    /// The gaps `[g_23, g_31, g_12]` [rad] between the beams (Eq. W2), each opposite the beam of
    /// its index: `gaps()[k]` is the angle under which G sees the two revolute points other
    /// than k's.
    pub fn gaps(&self) -> [f64; 3] {
        crate::robot_geometry::gaps_of(self.weld_angles())
    }

    /// The robot in the paper's form, when it is the paper's robot: three equal beams welded at
    /// 0, 120 and 240 degrees on an equilateral base centred at O. Otherwise the error says which
    /// datum differs: the solvers' equal-beam models refuse such a robot with it.
    pub fn equal_beams(&self) -> Result<&RobotParams, ModelError> {
        self.paper_form_for("this solver")
    }

    /// The robot in the paper's form, when it is the paper's robot ([`Robot::equal_beams`]
    /// without the error's text: nothing is allocated, for the solvers' time loops).
    pub(crate) fn paper_params(&self) -> Option<&RobotParams> {
        self.equal.as_ref().ok()
    }

    /// [`Robot::equal_beams`] for a command or model `by` that takes only the paper's robot so
    /// far: the error names it and the datum that differs.
    pub fn paper_form_for(&self, by: &str) -> Result<&RobotParams, ModelError> {
        self.equal.as_ref().map_err(|what| ModelError::Unsupported {
            what: what.clone(),
            by: by.to_string(),
        })
    }
}

/// Is the data the paper's robot? Its parameters when it is (with `EA` as given), else which
/// datum differs: a beam other than beam 1, a weld angle, or the base.
fn paper_form(beams: &[Beam; 3], axes: &[ActuatorAxis; 3]) -> Result<RobotParams, String> {
    let b = beams[0];
    let other = |x: &Beam| {
        Beam {
            weld_angle: b.weld_angle,
            ..*x
        } != b
    };
    if let Some(i) = (1..3).find(|&i| other(&beams[i])) {
        return Err(format!("beam {} differs from beam 1", i + 1));
    }
    if let Some(i) = (0..3).find(|&i| !close(beams[i].weld_angle, beam_offset(i))) {
        return Err(format!(
            "beam {} is welded at {} degrees, not {}",
            i + 1,
            beams[i].weld_angle.to_degrees(),
            beam_offset(i).to_degrees()
        ));
    }
    let d = -axes[0].origin[1];
    if !(d > 0.0 && (0..3).all(|i| close_axis(&axes[i], &ActuatorAxis::paper(i, d)))) {
        return Err("the base is not the equilateral triangle centred at O".to_string());
    }
    Ok(b.params(d))
}

/// Equal to rounding: angles and lengths built by different sums of the same numbers.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + b.abs())
}

fn close_axis(a: &ActuatorAxis, b: &ActuatorAxis) -> bool {
    (0..2).all(|k| close(a.origin[k], b.origin[k]) && close(a.direction[k], b.direction[k]))
}

/// The weld angles: beam 1 at 0, then counter-clockwise `0 < phi_2 < phi_3 < 2 pi`, every gap
/// below pi (`docs/as-built.md` 1: otherwise the beams do not surround G).
fn check_welds(beams: &[Beam; 3]) -> Result<(), ModelError> {
    let phi = beams.map(|b| b.weld_angle);
    let gaps = [phi[1] - phi[0], phi[2] - phi[1], std::f64::consts::TAU - phi[2]];
    let ordered = phi[0] == 0.0 && phi[1] < phi[2] && phi[2] < std::f64::consts::TAU;
    if !ordered || gaps.iter().any(|g| !(*g > 0.0 && *g < std::f64::consts::PI)) {
        let deg = phi.map(f64::to_degrees);
        return Err(ModelError::invalid(
            "robot.weld_deg",
            format!(
                "need beam 1 at 0 degrees and the beams counter-clockwise 1, 2, 3 with every gap between \
                 neighbours below 180 degrees (otherwise they do not surround G), got {deg:?}"
            ),
        ));
    }
    Ok(())
}

/// Every value of one beam finite and positive (the sleeve's mass and inertia may be 0), the
/// sleeve shorter than the beam.
fn check_beam(i: usize, b: &Beam) -> Result<(), ModelError> {
    let key = |name: &str| format!("robot.{name}[{}]", i + 1);
    let positive = [
        ("E", b.youngs_modulus),
        ("I", b.second_moment),
        ("EA", b.axial_stiffness),
        ("rho", b.mass_per_length),
        ("L", b.length),
        ("Lp", b.sleeve_length),
    ];
    for (name, v) in positive {
        if !v.is_finite() || v <= 0.0 {
            return Err(ModelError::invalid(
                key(name),
                format!("must be a positive finite number, got {v}"),
            ));
        }
    }
    for (name, v) in [
        ("mpp_mpa", b.sleeve_mass),
        ("Jp", b.sleeve_inertia),
        ("weld_deg", b.weld_angle),
    ] {
        if !v.is_finite() || v < 0.0 {
            return Err(ModelError::invalid(
                key(name),
                format!("must be a finite number >= 0, got {v}"),
            ));
        }
    }
    if b.sleeve_length >= b.length {
        return Err(ModelError::invalid(
            key("Lp"),
            format!(
                "the sleeve must be shorter than the beam: 0 < Lp < L = {}, got {}",
                b.length, b.sleeve_length
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_robot_is_found_equal_and_keeps_its_parameters() {
        let p = RobotParams::paper();
        let r = Robot::from_params(&p).unwrap();
        assert_eq!(*r.equal_beams().unwrap(), p);
        // the same data built beam by beam is recognised by the check alone, EA made explicit
        let again = Robot::new(*r.beams(), *r.axes()).unwrap();
        assert_eq!(again.equal_beams().unwrap().ea(), p.ea());
        assert_eq!(again.equal_beams().unwrap().d, p.d);
    }

    /// The compact form that carries a robot reads back as that robot: the paper's form for the
    /// paper's robot, the data as built for another, with `d` the in-radius of a base from sides.
    #[test]
    fn the_compact_form_of_a_robot_reads_back_as_it() {
        let p = RobotParams::paper();
        assert_eq!(Robot::from_params(&p).unwrap().to_params(), p);
        let mut beams = *Robot::from_params(&p).unwrap().beams();
        beams[1].sleeve_mass = 0.25;
        beams[2].weld_angle = 243f64.to_radians();
        let sides = [0.626, 0.618, 0.631];
        let robot = Robot::new(beams, ActuatorAxis::from_sides(sides).unwrap()).unwrap();
        let compact = robot.to_params();
        assert!(compact.as_built.is_some());
        assert_eq!(Robot::from_params(&compact).unwrap(), robot);
        let s = 0.5 * sides.iter().sum::<f64>();
        let in_radius = (s * (s - sides[0]) * (s - sides[1]) * (s - sides[2])).sqrt() / s;
        assert!((compact.d - in_radius).abs() < 1e-15, "{} vs {in_radius}", compact.d);
    }

    #[test]
    fn any_difference_in_the_data_is_named() {
        let r = Robot::from_params(&RobotParams::paper()).unwrap();
        let mut beams = *r.beams();
        beams[2].length = 0.48;
        let e = Robot::new(beams, *r.axes()).unwrap().equal_beams().unwrap_err();
        assert!(e.to_string().contains("beam 3 differs from beam 1"), "{e}");

        let mut beams = *r.beams();
        beams[1].weld_angle += 1f64.to_radians();
        let e = Robot::new(beams, *r.axes()).unwrap().equal_beams().unwrap_err();
        assert!(e.to_string().contains("beam 2 is welded at 121"), "{e}");

        let mut axes = *r.axes();
        axes[1].origin[0] += 1e-3;
        let e = Robot::new(*r.beams(), axes).unwrap().equal_beams().unwrap_err();
        assert!(e.to_string().contains("equilateral"), "{e}");
    }

    /// Equal sides `2 sqrt(3) d` give the paper's base (Eqs. 1-3), to rounding.
    #[test]
    fn equal_sides_are_the_paper_base() {
        let d = 0.18;
        let axes = ActuatorAxis::from_sides([2.0 * 3f64.sqrt() * d; 3]).unwrap();
        for (i, a) in axes.iter().enumerate() {
            let p = ActuatorAxis::paper(i, d);
            for k in 0..2 {
                assert!((a.origin[k] - p.origin[k]).abs() < 1e-15, "{i}: {a:?} {p:?}");
                assert!((a.direction[k] - p.direction[k]).abs() < 1e-15, "{i}: {a:?} {p:?}");
            }
        }
        let e = ActuatorAxis::from_sides([1.0, 0.3, 0.6]).unwrap_err();
        assert!(e.to_string().contains("base.sides"), "{e}");
    }

    /// An uneven base: each origin is the in-circle's touch point (at distance r from O, on its
    /// side), consecutive sides meet at the triangle's corners, and the sides have their lengths.
    #[test]
    fn uneven_sides_make_the_triangle_with_its_in_circle() {
        let sides = [0.62, 0.64, 0.61];
        let axes = ActuatorAxis::from_sides(sides).unwrap();
        let r = axes[0].origin[1].abs();
        // each origin is the foot of the perpendicular from O; consecutive lines meet at the
        // corners A_(i+1), with equal tangent lengths from each corner, and the corners are the
        // side lengths apart
        let mut corner = [[0.0; 2]; 3];
        for i in 0..3 {
            let (a, b) = (axes[i], axes[(i + 1) % 3]);
            assert!((a.origin[0].hypot(a.origin[1]) - r).abs() < 1e-14);
            assert!((a.origin[0] * a.direction[0] + a.origin[1] * a.direction[1]).abs() < 1e-14);
            let cross = a.direction[0] * b.direction[1] - a.direction[1] * b.direction[0];
            let w = [b.origin[0] - a.origin[0], b.origin[1] - a.origin[1]];
            let along_a = (w[0] * b.direction[1] - w[1] * b.direction[0]) / cross;
            let back_b = (w[0] * a.direction[1] - w[1] * a.direction[0]) / cross;
            assert!((along_a + back_b).abs() < 1e-14, "equal tangents from corner {}", i + 2);
            corner[(i + 1) % 3] = [
                a.origin[0] + along_a * a.direction[0],
                a.origin[1] + along_a * a.direction[1],
            ];
        }
        for i in 0..3 {
            let (c0, c1) = (corner[i], corner[(i + 1) % 3]);
            assert!(
                ((c1[0] - c0[0]).hypot(c1[1] - c0[1]) - sides[i]).abs() < 1e-14,
                "side {}",
                i + 1
            );
        }
        let p = 0.5 * sides.iter().sum::<f64>();
        let area = (p * (p - sides[0]) * (p - sides[1]) * (p - sides[2])).sqrt();
        assert!((r - area / p).abs() < 1e-15);
    }

    #[test]
    fn weld_angles_must_surround_g() {
        let r = Robot::from_params(&RobotParams::paper()).unwrap();
        let mut beams = *r.beams();
        beams[2].weld_angle = 190f64.to_radians();
        beams[1].weld_angle = 5f64.to_radians();
        let e = Robot::new(beams, *r.axes()).unwrap_err();
        assert!(e.to_string().contains("robot.weld_deg"), "{e}");
    }

    #[test]
    fn bad_beam_values_name_the_beam() {
        let r = Robot::from_params(&RobotParams::paper()).unwrap();
        let mut beams = *r.beams();
        beams[1].sleeve_length = 0.6;
        let e = Robot::new(beams, *r.axes()).unwrap_err();
        assert!(e.to_string().contains("robot.Lp[2]"), "{e}");
    }
}
