//! Direct kinematics of a robot as built: any base (three actuator axes as data) and any weld
//! angles (`docs/as-built.md` section 3, Eqs. K1, D1-D3).
//!
//! G sees each pair of revolute points under the gap between their beams. The apex A_k of the
//! triangle erected on P_i P_j (away from P_k) with base angles `pi - g_jk`, `pi - g_ki` lies on the
//! line P_k G (Eq. D1); G is the intersection of two such lines (Eq. D2). The construction is
//! rational in the revolute points, so dual numbers give exact time derivatives; for 120-degree
//! gaps it is the Fermat construction of [`crate::direct`].

use flexstar_model::geometry::Scalar;
use flexstar_model::RobotGeometry;

use crate::direct::{cross, direct_kinematics, pose_on_lines, sub, RigidPose};

/// Interior angle of the triangle `p` at vertex k [rad].
pub(crate) fn angle_at(p: &[[f64; 2]; 3], k: usize) -> f64 {
    let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
    let (u, v) = (sub(b, a), sub(c, a));
    cross(u, v).abs().atan2(u[0] * v[0] + u[1] * v[1])
}

/// Eq. D1: the apex A_k on the chord `P_i P_j` (i, j, k in cyclic order), on the side away from
/// `P_k`; `gaps` as [`Robot::gaps`] (gap k opposite beam k); `sigma`: +1 when the revolute points
/// run counter-clockwise.
fn apex<D: Scalar>(p: &[[D; 2]; 3], k: usize, gaps: [f64; 3], sigma: f64) -> [D; 2] {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    // base angle at P_i: pi - g_jk, where g_jk is the gap opposite beam i
    let alpha_i = std::f64::consts::PI - gaps[i];
    // |P_i A_k| / |P_i P_j| = sin(g_ki) / sin(g_ij), g_ki opposite beam j, g_ij opposite beam k
    let ratio = gaps[j].sin() / gaps[k].sin();
    let (c, s) = ((-sigma * alpha_i).cos() * ratio, (-sigma * alpha_i).sin() * ratio);
    let e = sub(p[j], p[i]);
    [p[i][0] + e[0] * c - e[1] * s, p[i][1] + e[0] * s + e[1] * c]
}

/// The rigid pose of `robot` for actuator coordinates `s` [m]: the paper's Fermat construction
/// (Eqs. 4-10, [`direct_kinematics`]) for the paper's robot, the apex construction of
/// [`direct_pose`] (Eqs. K1, D1-D3) for any other.
pub fn rigid_pose<K: RobotGeometry + ?Sized, D: Scalar>(robot: &K, s: [D; 3]) -> Option<RigidPose<D>> {
    match robot.paper_form() {
        Some(p) => direct_kinematics(p.d, s),
        None => direct_pose(robot, s),
    }
}

/// Eqs. K1, D1-D3: the rigid pose of `robot` for actuator coordinates `s` [m].
///
/// Returns `None` when the revolute points are degenerate or an angle of their triangle at P_k
/// reaches the gap g_ij that G must see P_i P_j under (no pose assembles the star there,
/// `docs/as-built.md` 3).
pub fn direct_pose<K: RobotGeometry + ?Sized, D: Scalar>(robot: &K, s: [D; 3]) -> Option<RigidPose<D>> {
    let p: [[D; 2]; 3] = std::array::from_fn(|i| robot.revolute_point(i, s[i]));
    let re = p.map(|q| [q[0].re(), q[1].re()]);
    let area2 = cross(sub(re[1], re[0]), sub(re[2], re[0]));
    let gaps = robot.gaps();
    if area2.abs() < 1e-14 || (0..3).any(|k| angle_at(&re, k) >= gaps[k]) {
        return None;
    }
    let sigma = area2.signum();
    // Eq. D2: G on the lines P_0 A_0 and P_1 A_1; Eq. D3: theta (phi_1 = 0) and xp
    let d0 = sub(apex(&p, 0, gaps, sigma), p[0]);
    let d1 = sub(apex(&p, 1, gaps, sigma), p[1]);
    Some(pose_on_lines(p, d0, d1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::geometry::inverse_kinematics;
    use flexstar_model::{ActuatorAxis, Robot, RobotParams};
    use num_dual::Dual64;

    /// A robot as built: uneven base, unequal weld angles (the beams' other data do not enter).
    fn as_built() -> Robot {
        let paper = Robot::from_params(&RobotParams::paper()).unwrap();
        let mut beams = *paper.beams();
        beams[1].weld_angle = 117f64.to_radians();
        beams[2].weld_angle = 243.5f64.to_radians();
        let axes = ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap();
        Robot::new(beams, axes).unwrap()
    }

    /// The second characterisation (`docs/as-built.md` 4): Newton's method on the loop equations
    /// K1, `P_i - G - r_i e_xi(theta) = 0` in (G, theta, r_1..r_3), from the centroid.
    fn newton_pose(robot: &Robot, s: [f64; 3]) -> ([f64; 2], f64, [f64; 3]) {
        let p: [[f64; 2]; 3] = std::array::from_fn(|i| robot.revolute_point(i, s[i]));
        let mut x = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            0.0,
            0.2,
            0.2,
            0.2,
        ];
        let residual = |x: &[f64; 6]| -> [f64; 6] {
            let mut f = [0.0; 6];
            for i in 0..3 {
                let e = robot.e_x(i, x[2]);
                f[2 * i] = p[i][0] - x[0] - x[3 + i] * e[0];
                f[2 * i + 1] = p[i][1] - x[1] - x[3 + i] * e[1];
            }
            f
        };
        for _ in 0..50 {
            let f = residual(&x);
            // Jacobian by its exact columns: d/dG = -I, d/dtheta = -r_i e_wi, d/dr_i = -e_xi
            let mut jac = nalgebra::SMatrix::<f64, 6, 6>::zeros();
            for i in 0..3 {
                let (e, th) = (robot.e_x(i, x[2]), x[2] + robot.weld_angle(i));
                let ew = [th.cos(), th.sin()];
                jac[(2 * i, 0)] = -1.0;
                jac[(2 * i + 1, 1)] = -1.0;
                jac[(2 * i, 2)] = -x[3 + i] * ew[0];
                jac[(2 * i + 1, 2)] = -x[3 + i] * ew[1];
                jac[(2 * i, 3 + i)] = -e[0];
                jac[(2 * i + 1, 3 + i)] = -e[1];
            }
            let dx = jac.lu().solve(&nalgebra::SVector::<f64, 6>::from(f)).unwrap();
            for k in 0..6 {
                x[k] -= dx[k];
            }
        }
        ([x[0], x[1]], x[2], [x[3], x[4], x[5]])
    }

    #[test]
    fn the_apex_construction_solves_the_loop_equations() {
        let robot = as_built();
        for s in [[0.0, 0.0, 0.0], [0.03, -0.02, 0.05], [-0.06, 0.04, 0.01]] {
            let pose = direct_pose(&robot, s).expect("assembles");
            let (g, theta, r) = newton_pose(&robot, s);
            assert!(
                (pose.g[0] - g[0]).abs() < 1e-12 && (pose.g[1] - g[1]).abs() < 1e-12,
                "{s:?}"
            );
            assert!((pose.theta - theta).abs() < 1e-12, "{s:?}: {} {theta}", pose.theta);
            for (i, ri) in r.iter().enumerate() {
                assert!((pose.xp[i] - ri).abs() < 1e-12, "{s:?} beam {}", i + 1);
            }
            // and the inverse kinematics of the pose returns s
            let back = inverse_kinematics(&robot, pose.g, pose.theta).unwrap();
            for i in 0..3 {
                assert!((back[i] - s[i]).abs() < 1e-12, "{s:?}: {back:?}");
            }
        }
    }

    #[test]
    fn the_paper_robot_gives_the_fermat_pose() {
        let params = RobotParams::paper();
        let robot = Robot::from_params(&params).unwrap();
        for s in [[0.0f64, 0.0, 0.0], [0.04, -0.03, 0.02], [0.1, 0.05, -0.08]] {
            let a = direct_pose(&robot, s).unwrap();
            let b = crate::direct_kinematics(params.d, s).unwrap();
            assert!(
                (a.g[0] - b.g[0]).abs() < 1e-15 && (a.g[1] - b.g[1]).abs() < 1e-15,
                "{s:?}"
            );
            assert!((a.theta - b.theta).abs() < 1e-15, "{s:?}");
        }
    }

    #[test]
    fn dual_derivatives_are_those_of_central_differences() {
        let robot = as_built();
        let (s, v) = ([0.02, -0.01, 0.03], [0.7, -0.4, 0.2]);
        let t = Dual64::from_re(0.0).derivative();
        let sd: [Dual64; 3] = std::array::from_fn(|i| t * v[i] + s[i]);
        let pose = direct_pose(&robot, sd).unwrap();
        let h = 1e-6;
        let at = |k: f64| direct_pose(&robot, std::array::from_fn(|i| s[i] + k * h * v[i])).unwrap();
        let (plus, minus) = (at(1.0), at(-1.0));
        let fd = |a: f64, b: f64| (a - b) / (2.0 * h);
        assert!((pose.g[0].eps - fd(plus.g[0], minus.g[0])).abs() < 1e-8);
        assert!((pose.g[1].eps - fd(plus.g[1], minus.g[1])).abs() < 1e-8);
        assert!((pose.theta.eps - fd(plus.theta, minus.theta)).abs() < 1e-8);
        assert!((pose.xp[2].eps - fd(plus.xp[2], minus.xp[2])).abs() < 1e-8);
    }

    #[test]
    fn a_triangle_with_too_wide_an_angle_does_not_assemble() {
        let robot = as_built();
        // J and K pushed down their sliders: the angle at I grows past the gap opposite it
        assert!(direct_pose(&robot, [0.0f64, -0.2, 0.2]).is_none());
    }
}
