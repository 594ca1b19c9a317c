//! The trajectory kinds users run (`docs/motions.md` sections 1.2-1.6): `kind = "via"`
//! (task-space poses with times) and `kind = "table"` (a CSV of task-space poses or slider
//! positions), both through a [`PiecewiseQuintic`], at rest before the first and after the last
//! time.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::drive_section::ForceSamples;
use crate::error::ModelError;
use crate::geometry::{inverse_kinematics, Scalar};
use crate::robot_geometry::RobotGeometry;
use crate::spline::PiecewiseQuintic;

/// A via point: time `t` [s] and the task-space pose of the rigid star at it (centre G [m] in
/// the fixed frame, orientation theta [rad]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViaPoint {
    pub t: f64,
    #[serde(rename = "Gx")]
    pub gx: f64,
    #[serde(rename = "Gy")]
    pub gy: f64,
    pub theta: f64,
}

/// `kind = "via"`: the pose passes through `points` at their times (`docs/motions.md` 1.2, 1.3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViaMotion {
    /// The via points, times strictly increasing from >= 0.
    pub points: Vec<ViaPoint>,
    /// `true`: a rest-to-rest quintic per pair of points (a dwell where a pose repeats);
    /// `false`: the clamped quintic spline through all of them, at rest at the first and last.
    pub rest: bool,
    /// The curve of (Gx, Gy, theta); `None` while the points are invalid.
    #[serde(skip)]
    curve: Option<PiecewiseQuintic>,
}

impl ViaMotion {
    /// The motion through `points`; its curve is built when the points pass
    /// [`ViaMotion::check`] (otherwise [`ViaMotion::validate`] reports why).
    pub fn new(points: Vec<ViaPoint>, rest: bool) -> Self {
        let curve = check_points(&points).ok().map(|()| {
            let t: Vec<f64> = points.iter().map(|p| p.t).collect();
            let v: Vec<[f64; 3]> = points.iter().map(|p| [p.gx, p.gy, p.theta]).collect();
            if rest {
                PiecewiseQuintic::rest_segments(&t, &v)
            } else {
                PiecewiseQuintic::clamped_spline(&t, &v)
            }
        });
        ViaMotion { points, rest, curve }
    }

    /// Check the points (count, finite values, times, every pose reachable by the inverse
    /// kinematics); errors name `trajectory.points` and the 1-based point.
    pub fn validate<K: RobotGeometry + ?Sized>(&self, params: &K) -> Result<(), ModelError> {
        check_points(&self.points).map_err(|r| ModelError::invalid("trajectory.points", r))?;
        for (k, p) in self.points.iter().enumerate() {
            inverse_kinematics(params, [p.gx, p.gy], p.theta).map_err(|e| {
                ModelError::invalid(
                    "trajectory.points",
                    format!(
                        "point {} (Gx = {}, Gy = {}, theta = {}) is outside the workspace: {e}",
                        k + 1,
                        p.gx,
                        p.gy,
                        p.theta
                    ),
                )
            })?;
        }
        Ok(())
    }
}

/// The checks of a via list that need no robot: at least two points, finite values, first time
/// >= 0, strictly increasing times.
fn check_points(points: &[ViaPoint]) -> Result<(), String> {
    if points.len() < 2 {
        return Err(format!(
            "kind = \"via\" needs at least two points, got {}",
            points.len()
        ));
    }
    for (k, p) in points.iter().enumerate() {
        for (name, v) in [("t", p.t), ("Gx", p.gx), ("Gy", p.gy), ("theta", p.theta)] {
            if !v.is_finite() {
                return Err(format!("point {}: {name} must be finite, got {v}", k + 1));
            }
        }
        if k == 0 && p.t < 0.0 {
            return Err(format!(
                "point 1 at t = {} s: times must be >= 0 (the run starts at rest at t = 0)",
                p.t
            ));
        }
        if k > 0 && p.t <= points[k - 1].t {
            return Err(format!(
                "point {} at t = {} s does not come after point {k} at t = {} s",
                k + 1,
                p.t,
                points[k - 1].t
            ));
        }
    }
    Ok(())
}

/// Which coordinates a table holds (`trajectory.columns`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TableSpace {
    /// `t,Gx,Gy,theta` [s, m, m, rad]: task space, mapped through the inverse kinematics.
    Task,
    /// `t,s1,s2,s3` [s, m]: the slider coordinates themselves.
    Slider,
}

impl TableSpace {
    /// The three column names after `t`.
    pub fn columns(self) -> [&'static str; 3] {
        match self {
            TableSpace::Task => ["Gx", "Gy", "theta"],
            TableSpace::Slider => ["s1", "s2", "s3"],
        }
    }
}

/// A step between table rows larger than this many times the median step is a gap
/// (`docs/motions.md` section 1.4).
pub const GAP_FACTOR: f64 = 10.0;

/// The rows of a table as read, and their clamped quintic spline.
#[derive(Debug, Clone, PartialEq)]
pub struct TableData {
    /// Task or slider space.
    pub space: TableSpace,
    /// Row times [s].
    pub t: Vec<f64>,
    /// Row values: (Gx, Gy, theta) [m, m, rad] or (s1, s2, s3) [m].
    pub rows: Vec<[f64; 3]>,
    curve: PiecewiseQuintic,
}

/// `kind = "table"`: a CSV file of rows interpolated by the clamped quintic spline
/// (`docs/motions.md` section 1.4), read when the experiment is loaded.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableMotion {
    /// The CSV file, relative to the experiment file.
    pub file: PathBuf,
    /// Which columns to use when the file holds both sets.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<TableSpace>,
    /// The rows as read (`None` until [`TableMotion::read_file`] or [`TableMotion::from_rows`]).
    #[serde(skip)]
    pub data: Option<TableData>,
}

impl TableMotion {
    /// A table given in memory (`file` only names it in messages): rows checked as
    /// [`TableMotion::read_file`] checks a file's. Errors are the reason, with the 1-based row.
    pub fn from_rows<K: RobotGeometry + ?Sized>(
        file: PathBuf,
        space: TableSpace,
        t: Vec<f64>,
        rows: Vec<[f64; 3]>,
        params: &K,
    ) -> Result<Self, String> {
        ForceSamples::check(&t, &rows).map_err(|e| e.to_string())?;
        check_table_rows(space, &t, &rows, params)?;
        let curve = PiecewiseQuintic::clamped_spline(&t, &rows);
        Ok(TableMotion {
            file,
            columns: Some(space),
            data: Some(TableData { space, t, rows, curve }),
        })
    }

    /// The table file resolved against the experiment file `config`.
    pub fn file_path(&self, config: &Path) -> PathBuf {
        let dir = config.parent().unwrap_or_else(|| Path::new(""));
        if self.file.is_absolute() {
            self.file.clone()
        } else {
            dir.join(&self.file)
        }
    }

    /// Read and check the table file (relative to the experiment file `config`) for the robot
    /// `params`. Errors name the experiment file, `trajectory.file`, the table file and the row.
    pub fn read_file<K: RobotGeometry + ?Sized>(&mut self, config: &Path, params: &K) -> Result<(), ModelError> {
        let path = self.file_path(config);
        let bad = |reason: String| ModelError::Invalid {
            file: config.to_path_buf(),
            key: "trajectory.file".into(),
            reason: format!("{}: {reason}", path.display()),
        };
        let space = table_space(&path, self.columns).map_err(bad)?;
        let samples =
            ForceSamples::read_columns(&path, "trajectory.file", space.columns(), "table").map_err(|e| match e {
                ModelError::Invalid { reason, .. } => bad(reason),
                other => other,
            })?;
        let read = TableMotion::from_rows(self.file.clone(), space, samples.t, samples.fa, params).map_err(bad)?;
        self.data = read.data;
        Ok(())
    }

    /// The rows as read, or an error if the file was not read.
    pub fn data(&self) -> Result<&TableData, ModelError> {
        self.data
            .as_ref()
            .ok_or_else(|| ModelError::invalid("trajectory.file", "the table file was not read"))
    }
}

impl TableData {
    /// The three channels at `t` [s].
    pub fn eval<D: Scalar>(&self, t: D) -> [D; 3] {
        self.curve.eval(t)
    }
}

impl ViaMotion {
    /// The curve of (Gx, Gy, theta), or the reason it is missing.
    pub fn curve(&self) -> Result<&PiecewiseQuintic, ModelError> {
        self.curve
            .as_ref()
            .ok_or_else(|| ModelError::invalid("trajectory.points", "the via points are invalid"))
    }
}

/// Which columns of the file at `path` to read: the header's, or `columns` when it holds both.
fn table_space(path: &Path, columns: Option<TableSpace>) -> Result<TableSpace, String> {
    let mut rd = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| format!("cannot read the table file: {e}"))?;
    let header = rd.headers().map_err(|e| format!("cannot read the header: {e}"))?;
    let has = |s: TableSpace| s.columns().iter().all(|c| header.iter().any(|h| h == *c));
    let (task, slider) = (has(TableSpace::Task), has(TableSpace::Slider));
    let got = header.iter().collect::<Vec<_>>().join(",");
    if header.get(0) != Some("t") || !(task || slider) {
        return Err(format!(
            "the header must start with t and hold Gx, Gy, theta or s1, s2, s3, got `{got}`"
        ));
    }
    match (columns, task, slider) {
        (Some(c), _, _) => Ok(c),
        (None, true, true) => Err(format!(
            "the header `{got}` holds both Gx, Gy, theta and s1, s2, s3; say columns = \"task\" or \"slider\""
        )),
        (None, true, false) => Ok(TableSpace::Task),
        (None, false, _) => Ok(TableSpace::Slider),
    }
}

/// The table checks beyond a forces file's: first time >= 0, no gap, every task-space row
/// reachable by the inverse kinematics (the full feasible range of every row is checked with the
/// motion, by `flexstar_kinematics::check_trajectory`).
fn check_table_rows<K: RobotGeometry + ?Sized>(
    space: TableSpace,
    t: &[f64],
    rows: &[[f64; 3]],
    params: &K,
) -> Result<(), String> {
    if t[0] < 0.0 {
        return Err(format!(
            "row 1: time {} s: times must be >= 0 (the run starts at rest at t = 0)",
            t[0]
        ));
    }
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    if let Some(k) = t.windows(2).position(|w| w[1] - w[0] > GAP_FACTOR * median) {
        return Err(format!(
            "rows {}-{}: a gap of {} s (median step {median} s, more than {GAP_FACTOR} times it); \
             a table is interpolated, not planned: give the dwell as rows at the table's step, or use kind = \"via\"",
            k + 1,
            k + 2,
            t[k + 1] - t[k]
        ));
    }
    if space == TableSpace::Task {
        for (k, r) in rows.iter().enumerate() {
            inverse_kinematics(params, [r[0], r[1]], r[2]).map_err(|e| {
                format!(
                    "row {} (Gx = {}, Gy = {}, theta = {}) is outside the workspace: {e}",
                    k + 1,
                    r[0],
                    r[1],
                    r[2]
                )
            })?;
        }
    }
    Ok(())
}
