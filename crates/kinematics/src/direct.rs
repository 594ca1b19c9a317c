//! Direct kinematics of the rigid robot (Eqs. 4-10): from the actuator coordinates to G, theta and
//! the sleeve positions xp_i.
//!
//! G sees I, J and K at 120 degrees to each other: it is the Fermat-Torricelli point of triangle
//! IJK. The paper intersects two circular arcs (Eqs. 5-7); here the same point is built as the
//! intersection of two Simpson lines (a vertex joined to the apex of the equilateral triangle
//! erected outwards on the opposite side), which is rational in the coordinates and therefore
//! differentiable by dual numbers without branch switching.

use flexstar_model::geometry::{revolute_point, Scalar};

/// Rigid pose of the star for given actuator coordinates, in the fixed frame.
#[derive(Debug, Clone, Copy)]
pub struct RigidPose<D> {
    /// Revolute points I, J, K [m] (Eqs. 1-3).
    pub p: [[D; 2]; 3],
    /// Centre G of the star [m] (Eq. 7).
    pub g: [D; 2],
    /// Orientation theta [rad] (Eq. 9): `e_x1 = (I - G)/|I - G| = [sin th, -cos th]`.
    pub theta: D,
    /// Sleeve positions `xp_i = |G P_i|` [m] along the rigid beams (Eq. 10).
    pub xp: [D; 3],
}

/// Largest interior angle of triangle IJK [rad] and the vertex (0, 1, 2) where it sits.
pub fn largest_angle(p: &[[f64; 2]; 3]) -> (f64, usize) {
    let mut best = (0.0, 0);
    for k in 0..3 {
        let a = p[k];
        let b = p[(k + 1) % 3];
        let c = p[(k + 2) % 3];
        let u = [b[0] - a[0], b[1] - a[1]];
        let v = [c[0] - a[0], c[1] - a[1]];
        let ang = (u[0] * v[1] - u[1] * v[0]).abs().atan2(u[0] * v[0] + u[1] * v[1]);
        if ang > best.0 {
            best = (ang, k);
        }
    }
    best
}

pub(crate) fn sub<D: Scalar>(a: [D; 2], b: [D; 2]) -> [D; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

pub(crate) fn cross<D: Scalar>(a: [D; 2], b: [D; 2]) -> D {
    a[0] * b[1] - a[1] * b[0]
}

/// Apex of the equilateral triangle erected on segment a -> b, on the side opposite to the
/// triangle's interior (`ccw`: the triangle a, b, c is counter-clockwise).
fn outward_apex<D: Scalar>(a: [D; 2], b: [D; 2], ccw: bool) -> [D; 2] {
    let (c60, s60) = (0.5, 0.75f64.sqrt());
    let s = if ccw { -s60 } else { s60 };
    let e = sub(b, a);
    [a[0] + e[0] * c60 - e[1] * s, a[1] + e[0] * s + e[1] * c60]
}

/// Eqs. 1-10: the rigid pose for actuator coordinates `s` [m].
///
/// Returns `None` when IJK is degenerate or has an angle of 120 degrees or more (no point sees
/// the vertices at 120 degrees).
pub fn direct_kinematics<D: Scalar>(d: f64, s: [D; 3]) -> Option<RigidPose<D>> {
    let p = [
        revolute_point(0, d, s[0]),
        revolute_point(1, d, s[1]),
        revolute_point(2, d, s[2]),
    ];
    let re = p.map(|q| [q[0].re(), q[1].re()]);
    let area2 = cross(sub(re[1], re[0]), sub(re[2], re[0]));
    if area2.abs() < 1e-14 || largest_angle(&re).0 >= 2.0 * std::f64::consts::FRAC_PI_3 {
        return None;
    }
    let ccw = area2 > 0.0;
    // Simpson lines: I -> apex on JK, J -> apex on KI; they meet at the Fermat point.
    let a_jk = outward_apex(p[1], p[2], ccw);
    let a_ki = outward_apex(p[2], p[0], ccw);
    Some(pose_on_lines(p, sub(a_jk, p[0]), sub(a_ki, p[1])))
}

/// The pose whose centre G is where the line from revolute point I along `d0` meets the line from
/// J along `d1` (two Simpson lines, or the apex lines of `crate::as_built`): G, theta from
/// `e_x1 = (I - G)/|I - G| = [sin th, -cos th]` (Eq. 9) and `xp_i = |P_i - G|` (Eq. 10).
pub(crate) fn pose_on_lines<D: Scalar>(p: [[D; 2]; 3], d0: [D; 2], d1: [D; 2]) -> RigidPose<D> {
    let tpar = cross(sub(p[1], p[0]), d1) / cross(d0, d1);
    let g = [p[0][0] + d0[0] * tpar, p[0][1] + d0[1] * tpar];
    let gi = sub(p[0], g);
    let theta = gi[0].atan2(-gi[1]);
    let xp = p.map(|q| {
        let r = sub(q, g);
        (r[0] * r[0] + r[1] * r[1]).sqrt()
    });
    RigidPose { p, g, theta, xp }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_configuration() {
        // docs/conventions.md, Frames: at s = 0, G = O, theta = 0, xp_i = d.
        let pose = direct_kinematics(0.18, [0.0f64; 3]).unwrap();
        assert!(pose.g[0].abs() < 1e-15 && pose.g[1].abs() < 1e-15);
        assert!(pose.theta.abs() < 1e-15);
        for xp in pose.xp {
            assert!((xp - 0.18).abs() < 1e-15);
        }
    }

    #[test]
    fn obtuse_triangle_has_no_solution() {
        // Push J and K down their sliders: the angle at I becomes about 138 degrees.
        assert!(direct_kinematics(0.18, [0.0f64, -0.2, 0.2]).is_none());
    }
}
