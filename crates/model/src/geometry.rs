//! Base geometry (Eqs. 1-3) and the closed-form inverse kinematics of the rigid robot.
//!
//! Frame: the fixed XY frame with origin O at the centre of the base triangle
//! (`docs/conventions.md`, Frames). Functions are generic over [`num_dual::DualNum`] so that time
//! derivatives of any geometric quantity come out exact by automatic differentiation.

use num_dual::DualNum;

use crate::error::ModelError;
use crate::robot_geometry::RobotGeometry;

/// A real number or a dual number over f64: the scalar type of every differentiable geometric
/// function, so that `Dual2` arguments give exact first and second derivatives.
pub trait Scalar: DualNum<Primitive = f64> + Copy {}
impl<T: DualNum<Primitive = f64> + Copy> Scalar for T {}

/// sin(pi/6) and cos(pi/6).
const S30: f64 = 0.5;
const C30: f64 = 0.866_025_403_784_438_6;

/// Unit direction `dO(I|J|K)/ds_i` along which slider i moves (Eqs. 1-3).
pub fn slider_direction(i: usize) -> [f64; 2] {
    match i {
        0 => [1.0, 0.0],
        1 => [-S30, C30],
        2 => [-S30, -C30],
        _ => panic!("slider index {i} out of 0..3"),
    }
}

/// Position of revolute point i (I, J, K for i = 0, 1, 2) at `s = 0` [m], fixed frame.
pub fn revolute_origin(i: usize, d: f64) -> [f64; 2] {
    match i {
        0 => [0.0, -d],
        1 => [d * C30, d * S30],
        2 => [-d * C30, d * S30],
        _ => panic!("revolute index {i} out of 0..3"),
    }
}

/// Eqs. 1-3: position of revolute point i (I, J, K) for actuator coordinate `s` [m], fixed frame.
pub fn revolute_point<D: Scalar>(i: usize, d: f64, s: D) -> [D; 2] {
    let o = revolute_origin(i, d);
    let u = slider_direction(i);
    [s * u[0] + o[0], s * u[1] + o[1]]
}

/// Angle offset `(i - 1) 2 pi / 3` of beam i (0-based index here) in the beam frames of Eqs. 11-12.
pub fn beam_offset(i: usize) -> f64 {
    i as f64 * 2.0 * std::f64::consts::FRAC_PI_3
}

/// Eq. 11: unit vector `e_xi = [sin(th + offset_i), -cos(th + offset_i)]` along rigid beam i.
pub fn e_x<D: Scalar>(i: usize, theta: D) -> [D; 2] {
    let a = theta + beam_offset(i);
    [a.sin(), -a.cos()]
}

/// Eq. 12: unit vector `e_wi = [cos(th + offset_i), sin(th + offset_i)]` normal to rigid beam i.
pub fn e_w<D: Scalar>(i: usize, theta: D) -> [D; 2] {
    let a = theta + beam_offset(i);
    [a.cos(), a.sin()]
}

/// Closed-form inverse kinematics of the rigid robot: the actuator coordinates `s_i` that put
/// the star's centre at `G = (gx, gy)` with orientation `theta` [rad], for the paper's robot or
/// one as built (`docs/as-built.md` 3, inverse kinematics).
///
/// Revolute point i is where the line `G + r e_xi` (r > 0) meets slider line i. Fails when a beam
/// is parallel to its slider or points away from it.
pub fn inverse_kinematics<K: RobotGeometry + ?Sized, D: Scalar>(
    robot: &K,
    g: [D; 2],
    theta: D,
) -> Result<[D; 3], ModelError> {
    let mut s = [D::zero(); 3];
    for (i, si) in s.iter_mut().enumerate() {
        let axis = robot.axis(i);
        *si = axis_coordinate(i, robot.e_x(i, theta), (axis.origin, axis.direction), g, theta)?;
    }
    Ok(s)
}

/// The coordinate s where beam i's rigid axis `g + r ex` (r > 0) meets slider line i, `o + s u`
/// (`axis = (o, u)`): `r ex - s u = o - g`, solved by Cramer's rule. Fails when the beam is parallel
/// to its slider or points away from it (`theta` [rad] only names the pose in the message).
pub(crate) fn axis_coordinate<D: Scalar>(
    i: usize,
    ex: [D; 2],
    (o, u): ([f64; 2], [f64; 2]),
    g: [D; 2],
    theta: D,
) -> Result<D, ModelError> {
    let bx = -g[0] + o[0];
    let by = -g[1] + o[1];
    let det = ex[1] * u[0] - ex[0] * u[1];
    if det.re().abs() < 1e-12 {
        return Err(ModelError::InverseKinematics(format!(
            "beam {} is parallel to slider {} at theta = {} rad",
            i + 1,
            i + 1,
            theta.re()
        )));
    }
    let r = (by * u[0] - bx * u[1]) / det;
    if r.re() <= 0.0 {
        return Err(ModelError::InverseKinematics(format!(
            "beam {} points away from slider {} (G = ({}, {}), theta = {})",
            i + 1,
            i + 1,
            g[0].re(),
            g[1].re(),
            theta.re()
        )));
    }
    Ok((ex[0] * by - ex[1] * bx) / det)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::RobotParams;

    #[test]
    fn start_pose_gives_zero_strokes() {
        // Fig. 2(a): G = O, theta = 0 is the configuration s = 0.
        let p = RobotParams::paper();
        let s = inverse_kinematics(&p, [0.0f64, 0.0], 0.0).unwrap();
        for si in s {
            assert!(si.abs() < 1e-15);
        }
    }

    #[test]
    fn revolute_point_lies_on_beam_line() {
        let p = RobotParams::paper();
        let (g, th) = ([0.013f64, -0.021], 0.17f64);
        let s = inverse_kinematics(&p, g, th).unwrap();
        for (i, si) in s.iter().enumerate() {
            let q = revolute_point(i, p.d, *si);
            let ex = e_x(i, th);
            let rel = [q[0] - g[0], q[1] - g[1]];
            // cross product with the beam direction vanishes, dot product positive
            assert!((rel[0] * ex[1] - rel[1] * ex[0]).abs() < 1e-14);
            assert!(rel[0] * ex[0] + rel[1] * ex[1] > 0.0);
        }
    }

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        for i in 0..3 {
            let (x, w) = (e_x(i, 0.3f64), e_w(i, 0.3f64));
            assert!((x[0] * w[0] + x[1] * w[1]).abs() < 1e-15);
            assert!((x[0] * w[1] - x[1] * w[0] - 1.0).abs() < 1e-15);
        }
    }
}
