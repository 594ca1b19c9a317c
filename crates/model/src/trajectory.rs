//! Actuator trajectories `s_i(t)` (paper, section 8): polynomials in t, or a rest-to-rest quintic
//! between two task-space poses mapped through the inverse kinematics.

use num_dual::Dual2;

use crate::geometry::Scalar;
use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::geometry::inverse_kinematics;
use crate::params::RobotParams;

/// A task-space pose of the rigid star: centre G [m] in the fixed frame and orientation theta [rad].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pose {
    #[serde(rename = "Gx")]
    pub gx: f64,
    #[serde(rename = "Gy")]
    pub gy: f64,
    pub theta: f64,
}

/// The prescribed motion of the three actuated prismatic joints.
///
/// Read through [`TrajectoryTable`] (a plain table, so that a wrong type is reported at its key
/// rather than at the `[trajectory]` header); written tagged by `kind`, the same shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", try_from = "TrajectoryTable")]
pub enum Trajectory {
    /// `s_i(t) = sum_k c_ik t^k` [m], coefficients in increasing powers of t (section 8).
    Polynomial { s1: Vec<f64>, s2: Vec<f64>, s3: Vec<f64> },
    /// Rest-to-rest quintic from pose `from` at `t0` to pose `to` at `t1` (zero velocity and
    /// acceleration at both ends), holding still outside `[t0, t1]`.
    Quintic { from: Pose, to: Pose, t0: f64, t1: f64 },
}

/// The kinds of [`Trajectory`], as the `kind` key names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrajectoryKind {
    Polynomial,
    Quintic,
}

/// The `[trajectory]` table as written: every key of every kind, checked against `kind` when
/// converted into a [`Trajectory`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryTable {
    kind: TrajectoryKind,
    s1: Option<Vec<f64>>,
    s2: Option<Vec<f64>>,
    s3: Option<Vec<f64>>,
    from: Option<Pose>,
    to: Option<Pose>,
    t0: Option<f64>,
    t1: Option<f64>,
}

impl TryFrom<TrajectoryTable> for Trajectory {
    type Error = String;
    fn try_from(t: TrajectoryTable) -> Result<Self, String> {
        let (name, own, foreign): (_, &[&str], _) = match t.kind {
            TrajectoryKind::Polynomial => ("polynomial", &["s1", "s2", "s3"], t.quintic_keys()),
            TrajectoryKind::Quintic => ("quintic", &["from", "to", "t0", "t1"], t.polynomial_keys()),
        };
        if let Some(key) = foreign.first() {
            return Err(format!(
                "key `trajectory.{key}` does not belong to kind = \"{name}\" (its keys: {})",
                own.join(", ")
            ));
        }
        let missing = |key: &str| format!("kind = \"{name}\" needs key `trajectory.{key}`");
        Ok(match t.kind {
            TrajectoryKind::Polynomial => Trajectory::Polynomial {
                s1: t.s1.ok_or_else(|| missing("s1"))?,
                s2: t.s2.ok_or_else(|| missing("s2"))?,
                s3: t.s3.ok_or_else(|| missing("s3"))?,
            },
            TrajectoryKind::Quintic => Trajectory::Quintic {
                from: t.from.ok_or_else(|| missing("from"))?,
                to: t.to.ok_or_else(|| missing("to"))?,
                t0: t.t0.ok_or_else(|| missing("t0"))?,
                t1: t.t1.ok_or_else(|| missing("t1"))?,
            },
        })
    }
}

impl TrajectoryTable {
    fn polynomial_keys(&self) -> Vec<&'static str> {
        [
            ("s1", self.s1.is_some()),
            ("s2", self.s2.is_some()),
            ("s3", self.s3.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, present)| present.then_some(k))
        .collect()
    }

    fn quintic_keys(&self) -> Vec<&'static str> {
        [
            ("from", self.from.is_some()),
            ("to", self.to.is_some()),
            ("t0", self.t0.is_some()),
            ("t1", self.t1.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, present)| present.then_some(k))
        .collect()
    }
}

/// Value, first and second time derivative of one scalar.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jet {
    pub v: f64,
    pub d1: f64,
    pub d2: f64,
}

impl Jet {
    pub fn from_dual2(x: Dual2<f64>) -> Self {
        Jet {
            v: x.re,
            d1: x.v1,
            d2: x.v2,
        }
    }
}

impl Trajectory {
    /// The paper's polynomial trajectories: `s_i = k_i t^2`.
    pub fn quadratic(k: [f64; 3]) -> Self {
        Trajectory::Polynomial {
            s1: vec![0.0, 0.0, k[0]],
            s2: vec![0.0, 0.0, k[1]],
            s3: vec![0.0, 0.0, k[2]],
        }
    }

    /// Actuator coordinates `s_i(t)` [m], generic over dual numbers for exact derivatives.
    pub fn s<D: Scalar>(&self, params: &RobotParams, t: D) -> Result<[D; 3], ModelError> {
        match self {
            Trajectory::Polynomial { s1, s2, s3 } => Ok([horner(s1, t), horner(s2, t), horner(s3, t)]),
            Trajectory::Quintic { from, to, t0, t1 } => {
                let tau = if t.re() <= *t0 {
                    D::zero()
                } else if t.re() >= *t1 {
                    D::one()
                } else {
                    (t - *t0) / (t1 - t0)
                };
                // 10 tau^3 - 15 tau^4 + 6 tau^5
                let blend = tau * tau * tau * (tau * (tau * 6.0 - 15.0) + 10.0);
                let g = [blend * (to.gx - from.gx) + from.gx, blend * (to.gy - from.gy) + from.gy];
                let th = blend * (to.theta - from.theta) + from.theta;
                inverse_kinematics(params, g, th)
            }
        }
    }

    /// `s_i`, `s_i'` and `s_i''` at time t [s].
    pub fn jets(&self, params: &RobotParams, t: f64) -> Result<[Jet; 3], ModelError> {
        let s = self.s(params, Dual2::from_re(t).derivative())?;
        Ok(s.map(Jet::from_dual2))
    }

    /// Check coefficients and times; the key is relative to the `[trajectory]` table.
    pub fn validate(&self, params: &RobotParams) -> Result<(), ModelError> {
        match self {
            Trajectory::Polynomial { s1, s2, s3 } => {
                for (key, c) in [("trajectory.s1", s1), ("trajectory.s2", s2), ("trajectory.s3", s3)] {
                    if let Some(bad) = c.iter().find(|v| !v.is_finite()) {
                        return Err(ModelError::invalid(
                            key,
                            format!("coefficients must be finite, got {bad}"),
                        ));
                    }
                    if c.len() > 12 {
                        return Err(ModelError::invalid(
                            key,
                            format!("at most 12 coefficients, got {}", c.len()),
                        ));
                    }
                }
            }
            Trajectory::Quintic { from, to, t0, t1 } => {
                for (key, v) in [
                    ("trajectory.from.Gx", from.gx),
                    ("trajectory.from.Gy", from.gy),
                    ("trajectory.from.theta", from.theta),
                    ("trajectory.to.Gx", to.gx),
                    ("trajectory.to.Gy", to.gy),
                    ("trajectory.to.theta", to.theta),
                    ("trajectory.t0", *t0),
                    ("trajectory.t1", *t1),
                ] {
                    if !v.is_finite() {
                        return Err(ModelError::invalid(key, format!("must be finite, got {v}")));
                    }
                }
                if *t0 < 0.0 || t1 <= t0 {
                    return Err(ModelError::invalid(
                        "trajectory.t1",
                        format!("need 0 <= t0 < t1, got t0 = {t0}, t1 = {t1}"),
                    ));
                }
                for (key, pose) in [("trajectory.from", from), ("trajectory.to", to)] {
                    inverse_kinematics(params, [pose.gx, pose.gy], pose.theta)
                        .map_err(|e| ModelError::invalid(key, e.to_string()))?;
                }
            }
        }
        Ok(())
    }
}

fn horner<D: Scalar>(c: &[f64], t: D) -> D {
    c.iter().rev().fold(D::zero(), |acc, &ck| acc * t + ck)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_derivatives_are_exact() {
        let p = RobotParams::paper();
        let j = Trajectory::quadratic([1.0, -0.5, 0.0]).jets(&p, 0.3).unwrap();
        assert!((j[0].v - 0.09).abs() < 1e-15 && (j[0].d1 - 0.6).abs() < 1e-15 && (j[0].d2 - 2.0).abs() < 1e-15);
        assert!((j[1].d2 + 1.0).abs() < 1e-15);
        assert_eq!(j[2], Jet::default());
    }

    #[test]
    fn quintic_is_rest_to_rest() {
        let p = RobotParams::paper();
        let tr = Trajectory::Quintic {
            from: Pose {
                gx: 0.0,
                gy: 0.0,
                theta: 0.0,
            },
            to: Pose {
                gx: 0.02,
                gy: -0.01,
                theta: 0.1,
            },
            t0: 0.0,
            t1: 0.4,
        };
        for t in [0.0, 0.4, 0.6] {
            for j in tr.jets(&p, t).unwrap() {
                assert!(j.d1.abs() < 1e-12 && j.d2.abs() < 1e-9, "t = {t}: {j:?}");
            }
        }
        let mid = tr.jets(&p, 0.2).unwrap();
        assert!(mid.iter().any(|j| j.d1.abs() > 1e-3));
    }
}
