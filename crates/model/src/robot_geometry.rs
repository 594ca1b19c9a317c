//! The rigid geometry every kinematic function reads, of the paper's compact form
//! ([`RobotParams`]) or of a robot as built ([`Robot`]) (`docs/as-built.md` 1-3).
//!
//! The rigid kinematics (trajectories' inverse kinematics, the direct pose, the rigid state and
//! its feasibility) is written once, generic over [`RobotGeometry`]. For the paper's form each
//! method returns the paper's own numbers (Eqs. 1-3, the 120-degree offsets of Eqs. 11-12), so a
//! generic function computes exactly what the paper's formulas compute, bit for bit.

use crate::geometry::{beam_offset, Scalar};
use crate::params::RobotParams;
use crate::robot::{ActuatorAxis, Robot};

/// What the rigid kinematics needs of a robot (see the module doc). Frames and signs:
/// `docs/conventions.md`; indices are 0-based (beam, sleeve, slider i + 1).
pub trait RobotGeometry {
    /// Weld angle phi_i of beam i [rad], from beam 1's (Eq. W1; the paper: `(i - 1) 2 pi / 3`).
    fn weld_angle(&self, i: usize) -> f64;
    /// The gaps `[g_23, g_31, g_12]` [rad] (Eq. W2), gap k opposite beam k: the angle under which
    /// G sees the two revolute points other than k's.
    fn gaps(&self) -> [f64; 3];
    /// Actuator axis i: revolute point `origin + s direction` [m], fixed frame (Eqs. 1-3).
    fn axis(&self, i: usize) -> ActuatorAxis;
    /// Travel `[lo, hi]` of slider i [m]: its side of the base, between the points where its
    /// axis meets the other two (the paper: `|s_i| < sqrt(3) d`).
    fn slider_travel(&self, i: usize) -> [f64; 2];
    /// Length L_i of beam i [m].
    fn beam_length(&self, i: usize) -> f64;
    /// Length Lp_i of sleeve i [m].
    fn sleeve_length(&self, i: usize) -> f64;
    /// The paper's compact form when the robot is the paper's robot (equal beams, 120-degree
    /// welds, equilateral base), whose formulas the generic functions then use.
    fn paper_form(&self) -> Option<&RobotParams>;

    /// Revolute point i at actuator coordinate `s` [m], fixed frame: `o_i + s u_i`.
    fn revolute_point<D: Scalar>(&self, i: usize, s: D) -> [D; 2] {
        let a = self.axis(i);
        [s * a.direction[0] + a.origin[0], s * a.direction[1] + a.origin[1]]
    }

    /// Unit vector `e_xi` along rigid beam i at orientation `theta` [rad] (Eqs. 11, W1).
    fn e_x<D: Scalar>(&self, i: usize, theta: D) -> [D; 2] {
        let a = theta + self.weld_angle(i);
        [a.sin(), -a.cos()]
    }

    /// Unit vector `e_wi` normal to rigid beam i at orientation `theta` [rad] (Eqs. 12, W1).
    fn e_w<D: Scalar>(&self, i: usize, theta: D) -> [D; 2] {
        let a = theta + self.weld_angle(i);
        [a.cos(), a.sin()]
    }

    /// The data the feasibility of a motion depends on (axes, travel, welds, lengths): two robots
    /// with equal keys have the same feasible motions.
    fn feasibility_key(&self) -> FeasibilityKey {
        FeasibilityKey {
            welds: std::array::from_fn(|i| self.weld_angle(i)),
            axes: std::array::from_fn(|i| self.axis(i)),
            travel: std::array::from_fn(|i| self.slider_travel(i)),
            lengths: std::array::from_fn(|i| [self.beam_length(i), self.sleeve_length(i)]),
        }
    }
}

/// The part of a robot its motions' feasibility depends on ([`RobotGeometry::feasibility_key`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeasibilityKey {
    welds: [f64; 3],
    axes: [ActuatorAxis; 3],
    travel: [[f64; 2]; 3],
    lengths: [[f64; 2]; 3],
}

/// A reference reads as what it refers to (`&&RobotParams` where a solver holds a reference).
impl<T: RobotGeometry + ?Sized> RobotGeometry for &T {
    fn weld_angle(&self, i: usize) -> f64 {
        (**self).weld_angle(i)
    }
    fn gaps(&self) -> [f64; 3] {
        (**self).gaps()
    }
    fn axis(&self, i: usize) -> ActuatorAxis {
        (**self).axis(i)
    }
    fn slider_travel(&self, i: usize) -> [f64; 2] {
        (**self).slider_travel(i)
    }
    fn beam_length(&self, i: usize) -> f64 {
        (**self).beam_length(i)
    }
    fn sleeve_length(&self, i: usize) -> f64 {
        (**self).sleeve_length(i)
    }
    fn paper_form(&self) -> Option<&RobotParams> {
        (**self).paper_form()
    }
}

/// The compact form answers with its robot as built when it carries one
/// ([`RobotParams::as_built`], the file's per-beam lists, welds and base): a generic function
/// given `&exp.robot` then reads the robot the file describes, never the paper's geometry by
/// mistake. Without it, the paper's own numbers.
impl RobotGeometry for RobotParams {
    fn weld_angle(&self, i: usize) -> f64 {
        match &self.as_built {
            Some(a) => a.beams[i].weld_angle,
            None => beam_offset(i),
        }
    }
    fn gaps(&self) -> [f64; 3] {
        match &self.as_built {
            Some(a) => gaps_of(a.beams.map(|b| b.weld_angle)),
            None => [2.0 * std::f64::consts::FRAC_PI_3; 3],
        }
    }
    fn axis(&self, i: usize) -> ActuatorAxis {
        match &self.as_built {
            Some(a) => a.axes[i],
            None => ActuatorAxis::paper(i, self.d),
        }
    }
    fn slider_travel(&self, i: usize) -> [f64; 2] {
        match &self.as_built {
            Some(a) => side_of(&a.axes, i),
            None => [-self.half_side(), self.half_side()],
        }
    }
    fn beam_length(&self, i: usize) -> f64 {
        match &self.as_built {
            Some(a) => a.beams[i].length,
            None => self.l,
        }
    }
    fn sleeve_length(&self, i: usize) -> f64 {
        match &self.as_built {
            Some(a) => a.beams[i].sleeve_length,
            None => self.lp,
        }
    }
    fn paper_form(&self) -> Option<&RobotParams> {
        self.as_built.is_none().then_some(self)
    }
}

impl RobotGeometry for Robot {
    fn weld_angle(&self, i: usize) -> f64 {
        self.beams()[i].weld_angle
    }
    fn gaps(&self) -> [f64; 3] {
        Robot::gaps(self)
    }
    fn axis(&self, i: usize) -> ActuatorAxis {
        self.axes()[i]
    }
    fn slider_travel(&self, i: usize) -> [f64; 2] {
        match self.paper_form() {
            Some(p) => p.slider_travel(i),
            None => side_of(self.axes(), i),
        }
    }
    fn beam_length(&self, i: usize) -> f64 {
        self.beams()[i].length
    }
    fn sleeve_length(&self, i: usize) -> f64 {
        self.beams()[i].sleeve_length
    }
    fn paper_form(&self) -> Option<&RobotParams> {
        self.paper_params()
    }
}

/// The gaps `[g_23, g_31, g_12]` [rad] of beams welded at `phi` (Eq. W2).
pub(crate) fn gaps_of(phi: [f64; 3]) -> [f64; 3] {
    [phi[2] - phi[1], std::f64::consts::TAU - phi[2], phi[1] - phi[0]]
}

/// The side of the base that axis i runs along: `[lo, hi]` in its coordinate s between the points
/// where it meets the axes before and after it (`docs/as-built.md` 2); unbounded on a side where
/// the two axes are parallel.
fn side_of(axes: &[ActuatorAxis; 3], i: usize) -> [f64; 2] {
    let a = axes[i];
    let meet = |j: usize| {
        // a.origin + s a.direction = b.origin + r b.direction, solved for s by Cramer's rule
        let b = axes[j];
        let det = -a.direction[0] * b.direction[1] + a.direction[1] * b.direction[0];
        let (dx, dy) = (b.origin[0] - a.origin[0], b.origin[1] - a.origin[1]);
        (det.abs() > 1e-12).then(|| (-dx * b.direction[1] + dy * b.direction[0]) / det)
    };
    let ends = [meet((i + 2) % 3), meet((i + 1) % 3)];
    match ends {
        [Some(p), Some(q)] => [p.min(q), p.max(q)],
        [Some(p), None] | [None, Some(p)] => {
            if p < 0.0 {
                [p, f64::INFINITY]
            } else {
                [f64::NEG_INFINITY, p]
            }
        }
        [None, None] => [f64::NEG_INFINITY, f64::INFINITY],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_robot_as_data_has_the_paper_travel_and_axes() {
        let p = RobotParams::paper();
        let robot = Robot::from_params(&p).unwrap();
        // the base from sides of 2 sqrt(3) d is the paper's; its travel, computed as the side
        // between the neighbouring axes, is |s| < sqrt(3) d
        let sides = ActuatorAxis::from_sides([2.0 * 3f64.sqrt() * p.d; 3]).unwrap();
        for i in 0..3 {
            let t = side_of(&sides, i);
            assert!(
                (t[0] + p.half_side()).abs() < 1e-12 && (t[1] - p.half_side()).abs() < 1e-12,
                "{t:?}"
            );
            assert_eq!(robot.axis(i), p.axis(i));
            assert_eq!(robot.weld_angle(i), p.weld_angle(i));
        }
    }

    #[test]
    fn an_uneven_base_travels_between_its_vertices() {
        // side i runs from A_i to A_(i+1): s from -t_i to l_i - t_i (docs/as-built.md Eq. B1)
        let l = [0.626, 0.618, 0.631];
        let axes = ActuatorAxis::from_sides(l).unwrap();
        let p = 0.5 * (l[0] + l[1] + l[2]);
        let t = [p - l[1], p - l[2], p - l[0]];
        for i in 0..3 {
            let s = side_of(&axes, i);
            assert!(
                (s[0] + t[i]).abs() < 1e-12 && (s[1] - (l[i] - t[i])).abs() < 1e-12,
                "{i}: {s:?}"
            );
        }
    }

    #[test]
    fn parameters_carrying_a_robot_as_built_answer_with_it() {
        // the file's robot as built: beam 3 shorter and welded 2 degrees off, an uneven base
        let p = RobotParams::paper();
        let mut a = crate::robot::AsBuilt::of_paper(&p);
        a.beams[2].length = 0.47;
        a.beams[2].weld_angle += 2f64.to_radians();
        a.axes = ActuatorAxis::from_sides([0.63, 0.6, 0.64]).unwrap();
        let params = RobotParams { as_built: Some(a), ..p };
        let robot = Robot::from_params(&params).unwrap();
        assert!(params.paper_form().is_none() && robot.paper_form().is_none());
        assert_eq!(params.feasibility_key(), robot.feasibility_key());
        assert_eq!(params.gaps(), robot.gaps());
        // and the paper's own parameters keep the paper's numbers
        assert_eq!(p.feasibility_key(), Robot::from_params(&p).unwrap().feasibility_key());
    }
}
