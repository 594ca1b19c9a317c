//! Actuator trajectories `s_i(t)` (paper, section 8): polynomials in t, a rest-to-rest quintic
//! between two task-space poses mapped through the inverse kinematics, and the kinds of
//! `docs/motions.md` section 1: via points and tables.

use num_dual::Dual2;

use crate::geometry::Scalar;
use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::geometry::inverse_kinematics;
use crate::motion::{TableMotion, TableSpace, ViaMotion, ViaPoint};
use crate::robot_geometry::RobotGeometry;
use crate::shaper::Impulse;

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
    /// Task-space via points with times (`docs/motions.md` 1.2, 1.3), mapped through the inverse
    /// kinematics.
    Via(ViaMotion),
    /// Rows of a CSV file in task or slider space (`docs/motions.md` 1.4).
    Table(TableMotion),
    /// A rest-to-rest motion whose task-space pose is convolved with a shaper's impulses
    /// (`docs/motions.md` 3.4); built from `[shaper]`, never read from `[trajectory]`.
    Shaped(ShapedMotion),
}

/// A shaped motion (`docs/motions.md` 3.4): pose `p_S(t) = sum_j A_j p(t - t_j)` of the base's
/// task-space pose `p = (Gx [m], Gy [m], theta [rad])`, then the inverse kinematics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShapedMotion {
    /// The unshaped rest-to-rest motion (quintic, via, or task-space table).
    pub base: Box<Trajectory>,
    /// The shaper's impulses (amplitudes summing to 1, first at t = 0).
    pub impulses: Vec<Impulse>,
}

/// The kinds of [`Trajectory`], as the `kind` key names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrajectoryKind {
    Polynomial,
    Quintic,
    Via,
    Table,
}

impl TrajectoryKind {
    /// The name and the keys of the kind.
    fn keys(self) -> (&'static str, &'static [&'static str]) {
        match self {
            TrajectoryKind::Polynomial => ("polynomial", &["s1", "s2", "s3"]),
            TrajectoryKind::Quintic => ("quintic", &["from", "to", "t0", "t1"]),
            TrajectoryKind::Via => ("via", &["points", "rest"]),
            TrajectoryKind::Table => ("table", &["file", "columns"]),
        }
    }
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
    points: Option<Vec<ViaPoint>>,
    rest: Option<bool>,
    file: Option<std::path::PathBuf>,
    columns: Option<TableSpace>,
}

impl TryFrom<TrajectoryTable> for Trajectory {
    type Error = String;
    fn try_from(t: TrajectoryTable) -> Result<Self, String> {
        let (name, own) = t.kind.keys();
        if let Some(key) = t.present().into_iter().find(|k| !own.contains(k)) {
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
            TrajectoryKind::Via => Trajectory::Via(ViaMotion::new(
                t.points.ok_or_else(|| missing("points"))?,
                t.rest.unwrap_or(true),
            )),
            TrajectoryKind::Table => Trajectory::Table(TableMotion {
                file: t.file.ok_or_else(|| missing("file"))?,
                columns: t.columns,
                data: None,
            }),
        })
    }
}

impl TrajectoryTable {
    /// The keys present besides `kind`, by TOML name.
    fn present(&self) -> Vec<&'static str> {
        [
            ("s1", self.s1.is_some()),
            ("s2", self.s2.is_some()),
            ("s3", self.s3.is_some()),
            ("from", self.from.is_some()),
            ("to", self.to.is_some()),
            ("t0", self.t0.is_some()),
            ("t1", self.t1.is_some()),
            ("points", self.points.is_some()),
            ("rest", self.rest.is_some()),
            ("file", self.file.is_some()),
            ("columns", self.columns.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, present)| present.then_some(k))
        .collect()
    }
}

/// A time at which a trajectory is given (a via point, a table row), named for messages.
#[derive(Debug, Clone, PartialEq)]
pub struct Knot {
    /// Time [s].
    pub t: f64,
    /// Where it is given: `trajectory.points: point 2 (Gx = .., Gy = .., theta = ..)` or
    /// `trajectory.file: path: row 42 (s1 = .., s2 = .., s3 = ..)`.
    pub label: String,
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

/// Value and first four time derivatives of one scalar: for a slider, position [m], velocity
/// [m/s], acceleration [m/s^2], jerk [m/s^3] and snap [m/s^4].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jet4 {
    pub v: f64,
    pub d1: f64,
    pub d2: f64,
    pub d3: f64,
    pub d4: f64,
}

impl Jet4 {
    /// The derivatives held by `f(x)` for the nested dual `x` of [`nested_dual`]: the outer
    /// parts are `f`, `f'`, `f''` evaluated at the inner dual `t + e`, whose parts are in turn
    /// the value and its first two derivatives.
    fn from_nested(x: Dual2<Dual2<f64>>) -> Self {
        Jet4 {
            v: x.re.re,
            d1: x.re.v1,
            d2: x.re.v2,
            d3: x.v1.v2,
            d4: x.v2.v2,
        }
    }
}

/// The time t [s] as a second-order dual number over a second-order dual number, both parts
/// seeded with dt/dt = 1: a function of it carries its derivatives up to the fourth, exactly.
fn nested_dual(t: f64) -> Dual2<Dual2<f64>> {
    Dual2::new(Dual2::from_re(t).derivative(), Dual2::from_re(1.0), Dual2::from_re(0.0))
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
    pub fn s<K: RobotGeometry + ?Sized, D: Scalar>(&self, params: &K, t: D) -> Result<[D; 3], ModelError> {
        match self {
            Trajectory::Polynomial { s1, s2, s3 } => Ok([horner(s1, t), horner(s2, t), horner(s3, t)]),
            Trajectory::Table(tab) if tab.data()?.space == TableSpace::Slider => Ok(tab.data()?.eval(t)),
            _ => {
                let p = self
                    .pose(t)?
                    .ok_or_else(|| ModelError::invalid("trajectory", "no task-space pose"))?;
                inverse_kinematics(params, [p[0], p[1]], p[2])
            }
        }
    }

    /// The task-space pose `(Gx [m], Gy [m], theta [rad])` at time t [s], generic over dual
    /// numbers; `None` for the kinds given in slider space (polynomial, slider table, or a shaped
    /// motion of one). A shaped motion sums its base's poses (`docs/motions.md` 3.4).
    pub fn pose<D: Scalar>(&self, t: D) -> Result<Option<[D; 3]>, ModelError> {
        Ok(match self {
            Trajectory::Polynomial { .. } => None,
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
                Some([
                    blend * (to.gx - from.gx) + from.gx,
                    blend * (to.gy - from.gy) + from.gy,
                    blend * (to.theta - from.theta) + from.theta,
                ])
            }
            Trajectory::Via(v) => Some(v.curve()?.eval(t)),
            Trajectory::Table(tab) => {
                let data = tab.data()?;
                (data.space == TableSpace::Task).then(|| data.eval(t))
            }
            Trajectory::Shaped(sh) => {
                let mut sum = [D::zero(), D::zero(), D::zero()];
                for imp in &sh.impulses {
                    let Some(p) = sh.base.pose(t - imp.t)? else {
                        return Ok(None);
                    };
                    for (acc, x) in sum.iter_mut().zip(p) {
                        *acc += x * imp.a;
                    }
                }
                Some(sum)
            }
        })
    }

    /// Start of a rest-to-rest motion [s]: a quintic's `t0`, the first via point's or table
    /// row's `t`, a shaped motion's base's; 0 for a polynomial (it moves from t = 0).
    pub fn t_start(&self) -> f64 {
        match self {
            Trajectory::Polynomial { .. } => 0.0,
            Trajectory::Quintic { t0, .. } => *t0,
            Trajectory::Via(v) => v.points.first().map_or(0.0, |p| p.t),
            Trajectory::Table(tab) => tab.data.as_ref().and_then(|d| d.t.first().copied()).unwrap_or(0.0),
            Trajectory::Shaped(sh) => sh.base.t_start(),
        }
    }

    /// End of the motion `t_rest` [s] (`docs/motions.md` section 1.5): the time after which a
    /// rest-to-rest kind holds still: `t1` of a quintic, the last via point's `t`, the last table
    /// row's `t`; `None` for a polynomial (it never comes to rest) and for a table not yet read.
    pub fn t_rest(&self) -> Option<f64> {
        match self {
            Trajectory::Polynomial { .. } => None,
            Trajectory::Quintic { t1, .. } => Some(*t1),
            Trajectory::Via(v) => v.points.last().map(|p| p.t),
            Trajectory::Table(tab) => tab.data.as_ref().and_then(|d| d.t.last().copied()),
            Trajectory::Shaped(sh) => sh.base.t_rest().map(|t| t + crate::shaper::duration(&sh.impulses)),
        }
    }

    /// The via points or table rows, with their times and labels (empty for the polynomial and
    /// quintic kinds): what a feasibility check names when a given pose is out of range.
    pub fn knots(&self) -> Vec<Knot> {
        match self {
            Trajectory::Via(v) => v
                .points
                .iter()
                .enumerate()
                .map(|(k, p)| Knot {
                    t: p.t,
                    label: format!(
                        "trajectory.points: point {} (Gx = {}, Gy = {}, theta = {})",
                        k + 1,
                        p.gx,
                        p.gy,
                        p.theta
                    ),
                })
                .collect(),
            Trajectory::Table(TableMotion {
                file, data: Some(d), ..
            }) => {
                let names = d.space.columns();
                let row = |k: usize, r: &[f64; 3]| {
                    let vals: Vec<String> = (0..3).map(|c| format!("{} = {}", names[c], r[c])).collect();
                    format!(
                        "trajectory.file: {}: row {} ({})",
                        file.display(),
                        k + 1,
                        vals.join(", ")
                    )
                };
                d.t.iter()
                    .zip(&d.rows)
                    .enumerate()
                    .map(|(k, (&t, r))| Knot { t, label: row(k, r) })
                    .collect()
            }
            Trajectory::Shaped(sh) => sh.base.knots(),
            _ => Vec::new(),
        }
    }

    /// Where `t` [s] lies among the via points or table rows, for messages:
    /// `between points 2 and 3`, `between rows 41 and 42`; `None` outside them or for the
    /// polynomial and quintic kinds.
    pub fn between(&self, t: f64) -> Option<String> {
        let (what, times): (&str, Vec<f64>) = match self {
            Trajectory::Via(v) => ("points", v.points.iter().map(|p| p.t).collect()),
            Trajectory::Table(TableMotion { data: Some(d), .. }) => ("rows", d.t.clone()),
            Trajectory::Shaped(sh) => return sh.base.between(t),
            _ => return None,
        };
        let k = times.partition_point(|&tk| tk <= t);
        (k > 0 && k < times.len()).then(|| format!("between {what} {k} and {}", k + 1))
    }

    /// Read the file of a `table` (relative to the experiment file `config`) for the robot
    /// `params`; a no-op for the other kinds. Errors name `config`, `trajectory.file`, the table
    /// file and the row.
    pub fn read_file<K: RobotGeometry + ?Sized>(
        &mut self,
        config: &std::path::Path,
        params: &K,
    ) -> Result<(), ModelError> {
        match self {
            Trajectory::Table(tab) => tab.read_file(config, params),
            Trajectory::Shaped(sh) => sh.base.read_file(config, params),
            _ => Ok(()),
        }
    }

    /// The table file of a `table`, resolved against the experiment file `config`.
    pub fn file_path(&self, config: &std::path::Path) -> Option<std::path::PathBuf> {
        match self {
            Trajectory::Table(tab) => Some(tab.file_path(config)),
            Trajectory::Shaped(sh) => sh.base.file_path(config),
            _ => None,
        }
    }

    /// `s_i`, `s_i'` and `s_i''` at time t [s].
    pub fn jets<K: RobotGeometry + ?Sized>(&self, params: &K, t: f64) -> Result<[Jet; 3], ModelError> {
        let s = self.s(params, Dual2::from_re(t).derivative())?;
        Ok(s.map(Jet::from_dual2))
    }

    /// `s_i` [m] and its first four time derivatives (velocity [m/s], acceleration [m/s^2], jerk
    /// [m/s^3], snap [m/s^4]) at time t [s], exact: [`Trajectory::s`] evaluated on nested
    /// second-order dual numbers (`Dual2<Dual2<f64>>`, `docs/motions.md`, "Export for the
    /// controller"). At a knot where a derivative jumps (a quintic's ends, a rest segment's
    /// joints) it is the value of the piece the evaluation falls in.
    pub fn jets4<K: RobotGeometry + ?Sized>(&self, params: &K, t: f64) -> Result<[Jet4; 3], ModelError> {
        Ok(self.s(params, nested_dual(t))?.map(Jet4::from_nested))
    }

    /// Check coefficients and times; the key is relative to the `[trajectory]` table.
    pub fn validate<K: RobotGeometry + ?Sized>(&self, params: &K) -> Result<(), ModelError> {
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
            Trajectory::Via(v) => v.validate(params)?,
            Trajectory::Table(tab) => {
                tab.data()?;
            }
            Trajectory::Shaped(sh) => sh.base.validate(params)?,
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
    use crate::params::RobotParams;

    #[test]
    fn quadratic_derivatives_are_exact() {
        let p = RobotParams::paper();
        let j = Trajectory::quadratic([1.0, -0.5, 0.0]).jets(&p, 0.3).unwrap();
        assert!((j[0].v - 0.09).abs() < 1e-15 && (j[0].d1 - 0.6).abs() < 1e-15 && (j[0].d2 - 2.0).abs() < 1e-15);
        assert!((j[1].d2 + 1.0).abs() < 1e-15);
        assert_eq!(j[2], Jet::default());
    }

    /// The four derivatives of a polynomial against its coefficients, differentiated by hand:
    /// s = 1 + 2 t - 3 t^2 + 4 t^3 - 5 t^4 + 6 t^5.
    #[test]
    fn jets4_of_a_polynomial_are_its_derivatives() {
        let c = vec![1.0, 2.0, -3.0, 4.0, -5.0, 6.0];
        let tr = Trajectory::Polynomial {
            s1: c.clone(),
            s2: vec![0.0],
            s3: c,
        };
        let t = 0.7f64;
        let want = [
            1.0 + 2.0 * t - 3.0 * t.powi(2) + 4.0 * t.powi(3) - 5.0 * t.powi(4) + 6.0 * t.powi(5),
            2.0 - 6.0 * t + 12.0 * t.powi(2) - 20.0 * t.powi(3) + 30.0 * t.powi(4),
            -6.0 + 24.0 * t - 60.0 * t.powi(2) + 120.0 * t.powi(3),
            24.0 - 120.0 * t + 360.0 * t.powi(2),
            -120.0 + 720.0 * t,
        ];
        let j = tr.jets4(&RobotParams::paper(), t).unwrap();
        let got = [j[0].v, j[0].d1, j[0].d2, j[0].d3, j[0].d4];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12 * (1.0 + w.abs()), "{got:?} vs {want:?}");
        }
        assert_eq!(j[0], j[2]);
        assert_eq!(j[1], Jet4::default());
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
