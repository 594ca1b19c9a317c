//! The planned motions (`docs/motions.md` 4.2): a clamped quintic spline (`kind = "via"`,
//! `rest = false`, section 1.3) from `from` at `t0` to `to` at `t0 + T` through `m` interior
//! poses at the fixed times `t0 + j T / (m + 1)`, j = 1..m. The decision variables place the
//! interior poses; the variables of the plain quintic are known in closed form, and the spline
//! through the quintic's own poses is that quintic exactly (a quintic is its own C4 spline).

use flexstar_model::motion::{ViaMotion, ViaPoint};
use flexstar_model::{Pose, Trajectory};

use crate::section::Shape;

/// Scale of a path offset in a task coordinate that does not move (m for Gx, Gy; rad for theta).
const STILL_SCALE: [f64; 3] = [0.01, 0.01, 0.05];

/// The family of planned motions between two poses.
#[derive(Debug, Clone, PartialEq)]
pub struct Family {
    pub shape: Shape,
    pub from: Pose,
    pub to: Pose,
    /// Start of the move [s].
    pub t0: f64,
    /// Interior via points m.
    pub m: usize,
}

/// The quintic blend `b(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5` of the rest-to-rest quintic.
pub fn blend(tau: f64) -> f64 {
    tau * tau * tau * (tau * (tau * 6.0 - 15.0) + 10.0)
}

fn coords(p: Pose) -> [f64; 3] {
    [p.gx, p.gy, p.theta]
}

impl Family {
    /// Number of decision variables: m (timing) or 3 m (path).
    pub fn dim(&self) -> usize {
        match self.shape {
            Shape::Timing => self.m,
            Shape::Path => 3 * self.m,
        }
    }

    /// The normalised knot times `tau_j = j / (m + 1)`, j = 1..m.
    pub fn taus(&self) -> Vec<f64> {
        (1..=self.m).map(|j| j as f64 / (self.m + 1) as f64).collect()
    }

    /// The variables of the plain quintic: the progress `b(tau_j)` (timing) or zero offsets (path).
    pub fn plain(&self) -> Vec<f64> {
        match self.shape {
            Shape::Timing => self.taus().into_iter().map(blend).collect(),
            Shape::Path => vec![0.0; self.dim()],
        }
    }

    /// The scale of a path offset per task coordinate: the move's extent in it, at least
    /// [`STILL_SCALE`].
    fn scales(&self) -> [f64; 3] {
        let (a, b) = (coords(self.from), coords(self.to));
        [0, 1, 2].map(|k| (b[k] - a[k]).abs().max(STILL_SCALE[k]))
    }

    /// The interior poses for the variables `x` (`docs/motions.md` 4.2): on the segment at the
    /// progress `x_j` (timing), or the quintic's pose at `tau_j` plus the scaled offset
    /// `x_3j..x_3j+2` (path).
    pub fn interior(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let (a, b) = (coords(self.from), coords(self.to));
        let on_segment = |lambda: f64| [0, 1, 2].map(|k| a[k] + lambda * (b[k] - a[k]));
        match self.shape {
            Shape::Timing => x.iter().map(|&l| on_segment(l)).collect(),
            Shape::Path => {
                let s = self.scales();
                self.taus()
                    .into_iter()
                    .zip(x.chunks(3))
                    .map(|(tau, c)| {
                        let p = on_segment(blend(tau));
                        [0, 1, 2].map(|k| p[k] + c[k] * s[k])
                    })
                    .collect()
            }
        }
    }

    /// The progress along the move of a pose (dimensionless; `docs/motions.md` 4.10): its
    /// projection on the chord from `from` to `to` in the scaled task coordinates,
    /// `p = <D (q - q_from), D (q_to - q_from)> / |D (q_to - q_from)|^2` with `D` the inverse
    /// scales of [`Family::interior`]. 0 at `from`, 1 at `to`; on the segment (timing) it is the
    /// progress `lambda` itself. Linear in the pose, so `p'(t)` is this map of the pose rate
    /// applied without the offset ([`Family::progress_rate`]).
    pub fn progress(&self, pose: [f64; 3]) -> f64 {
        let a = coords(self.from);
        self.progress_rate([0, 1, 2].map(|k| pose[k] - a[k]))
    }

    /// `p'(t)` [1/s] for the pose rate `q'(t)` (task coordinates per second): the linear part of
    /// [`Family::progress`].
    pub fn progress_rate(&self, rate: [f64; 3]) -> f64 {
        let (a, b, s) = (coords(self.from), coords(self.to), self.scales());
        let d = [0, 1, 2].map(|k| (b[k] - a[k]) / (s[k] * s[k]));
        let norm: f64 = (0..3).map(|k| d[k] * (b[k] - a[k])).sum();
        (0..3).map(|k| d[k] * rate[k]).sum::<f64>() / norm
    }

    /// The via points of the motion of duration `t_move` [s] for the variables `x`.
    pub fn points(&self, x: &[f64], t_move: f64) -> Vec<ViaPoint> {
        let point = |t: f64, p: [f64; 3]| ViaPoint {
            t,
            gx: p[0],
            gy: p[1],
            theta: p[2],
        };
        let mut pts = vec![point(self.t0, coords(self.from))];
        for (tau, p) in self.taus().into_iter().zip(self.interior(x)) {
            pts.push(point(self.t0 + tau * t_move, p));
        }
        pts.push(point(self.t0 + t_move, coords(self.to)));
        pts
    }

    /// The motion itself: `kind = "via"`, `rest = false`.
    pub fn trajectory(&self, x: &[f64], t_move: f64) -> Trajectory {
        Trajectory::Via(ViaMotion::new(self.points(x, t_move), false))
    }

    /// The plain quintic of duration `t_move` [s].
    pub fn quintic(&self, t_move: f64) -> Trajectory {
        Trajectory::Quintic {
            from: self.from,
            to: self.to,
            t0: self.t0,
            t1: self.t0 + t_move,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::Dual2;

    fn family(shape: Shape) -> Family {
        Family {
            shape,
            from: Pose {
                gx: 0.0,
                gy: 0.0,
                theta: 0.0,
            },
            to: Pose {
                gx: 0.03,
                gy: -0.02,
                theta: 0.2,
            },
            t0: 0.1,
            m: 6,
        }
    }

    /// The spline through the quintic's own poses is the quintic (`docs/motions.md` 4.2):
    /// pose, velocity and acceleration agree with the closed-form quintic at off-knot times.
    #[test]
    fn plain_variables_give_the_quintic_exactly() {
        for shape in [Shape::Timing, Shape::Path] {
            let f = family(shape);
            let spline = f.trajectory(&f.plain(), 0.4);
            let quintic = f.quintic(0.4);
            for k in 0..=97 {
                let t = 0.09 + k as f64 * 0.0043;
                let a = spline.pose(Dual2::from_re(t).derivative()).unwrap().unwrap();
                let b = quintic.pose(Dual2::from_re(t).derivative()).unwrap().unwrap();
                for c in 0..3 {
                    assert!((a[c].re - b[c].re).abs() < 1e-12, "{shape:?} t = {t}");
                    assert!((a[c].v1 - b[c].v1).abs() < 1e-10, "{shape:?} t = {t}");
                    assert!((a[c].v2 - b[c].v2).abs() < 1e-8, "{shape:?} t = {t}");
                }
            }
        }
    }

    /// The progress of 4.10: 0 at `from`, 1 at `to`, the timing variables themselves at the
    /// knots of a timing motion, and blind to a path offset orthogonal to the chord in the scaled
    /// coordinates; its rate is the derivative of the progress (central differences).
    #[test]
    fn progress_is_the_timing_variable_on_the_segment() {
        let f = family(Shape::Timing);
        assert!(f.progress([0.0, 0.0, 0.0]).abs() < 1e-15);
        assert!((f.progress([0.03, -0.02, 0.2]) - 1.0).abs() < 1e-14);
        let x = [0.05, 0.1, 0.4, 0.5, 0.9, 0.97];
        for (p, xj) in f.interior(&x).into_iter().zip(x) {
            assert!((f.progress(p) - xj).abs() < 1e-14);
        }
        // the scaled chord is (1, -1, 1) (extents 0.03, -0.02, 0.2 are the scales): the offset
        // (0.03, 0.02, 0), scaled (1, 1, 0), is orthogonal to it
        let off = [0.03, 0.02, 0.0];
        let on = [0.012, -0.008, 0.08];
        let p = f.progress([on[0] + 0.1 * off[0], on[1] + 0.1 * off[1], on[2] + 0.1 * off[2]]);
        assert!((p - 0.4).abs() < 1e-12, "{p}");
        let traj = f.trajectory(&x, 0.4);
        let (t, h) = (0.23, 1e-6);
        let q = |t: f64| traj.pose(t).unwrap().unwrap();
        let fd = (f.progress(q(t + h)) - f.progress(q(t - h))) / (2.0 * h);
        let rate = traj
            .pose(Dual2::from_re(t).derivative())
            .unwrap()
            .unwrap()
            .map(|c| c.v1);
        assert!((f.progress_rate(rate) - fd).abs() < 1e-6 * fd.abs().max(1.0), "{fd}");
    }

    /// Timing variables keep the path on the segment (the curve is linear in its knot values).
    #[test]
    fn timing_motions_stay_on_the_segment() {
        let f = family(Shape::Timing);
        let x = [0.05, 0.1, 0.4, 0.5, 0.9, 0.97];
        let traj = f.trajectory(&x, 0.4);
        for k in 0..50 {
            let p = traj.pose(0.1 + k as f64 * 0.008).unwrap().unwrap();
            let lambda = p[0] / 0.03;
            assert!((p[1] - lambda * -0.02).abs() < 1e-14 && (p[2] - lambda * 0.2).abs() < 1e-14);
        }
    }
}
