//! Whole cycles (`docs/motions.md` 4.12): `[plan] points = [{ Gx, Gy, theta, dwell }, ...]` or a
//! `[trajectory] kind = "via"`, `rest = true` next to `[plan]`, read into the moves and dwells of
//! Eq. C1 and checked before any work.

use std::path::Path;

use serde::{Deserialize, Serialize};

use flexstar_model::{ModelError, Pose};

/// One move of a cycle and the dwell after it (Eq. C1); times [s] on the run's clock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CycleMove {
    /// Start and end poses (G [m] in the fixed frame, theta [rad]).
    pub from: Pose,
    pub to: Pose,
    /// `t_k^start` [s].
    pub t_start: f64,
    /// `T_k` [s].
    pub t_move: f64,
    /// `d_k` [s], the dwell at `to` after the move.
    pub dwell: f64,
}

impl CycleMove {
    /// `t_k^end = t_k^start + T_k` [s].
    pub fn t_end(&self) -> f64 {
        self.t_start + self.t_move
    }
}

/// A cycle: its start time and its moves, in order (`docs/motions.md` 4.12).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cycle {
    pub t0: f64,
    pub moves: Vec<CycleMove>,
}

/// One entry of `[plan] points` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointEntry {
    #[serde(rename = "Gx")]
    gx: f64,
    #[serde(rename = "Gy")]
    gy: f64,
    theta: f64,
    dwell: Option<f64>,
    t_move: Option<f64>,
}

impl Cycle {
    /// The end of the last dwell [s].
    pub fn end(&self) -> f64 {
        self.moves.last().map_or(self.t0, |m| m.t_end() + m.dwell)
    }

    /// The end of the last move [s] (the planned table's last row).
    pub fn last_move_end(&self) -> f64 {
        self.moves.last().map_or(self.t0, CycleMove::t_end)
    }

    /// `[plan] points` (an array of tables) read with Eq. C1 from `t0` [s]; `t_move` is the
    /// `[plan]` default duration. Errors name `plan.points[k]` (0-based, as written).
    pub fn from_points(value: toml::Value, t_move: Option<f64>, t0: f64) -> Result<Cycle, ModelError> {
        let toml::Value::Array(items) = value else {
            return Err(ModelError::invalid(
                "plan.points",
                "must be an interior point count or an array of cycle points",
            ));
        };
        if items.len() < 2 {
            return Err(ModelError::invalid(
                "plan.points",
                format!(
                    "a cycle needs at least two points (a start and one move's end), got {}",
                    items.len()
                ),
            ));
        }
        let mut entries = Vec::with_capacity(items.len());
        for (k, item) in items.into_iter().enumerate() {
            let key = format!("plan.points[{k}]");
            let e: PointEntry = item
                .try_into()
                .map_err(|e: toml::de::Error| ModelError::invalid(&key, e.message().trim_end()))?;
            entries.push(check_entry(e, k, t_move)?);
        }
        let mut moves = Vec::with_capacity(entries.len() - 1);
        let mut t = t0;
        for k in 1..entries.len() {
            let (from, to, (dwell, t_move)) = (entries[k - 1].0, entries[k].0, entries[k].1);
            moves.push(CycleMove {
                from,
                to,
                t_start: t,
                t_move,
                dwell,
            });
            t += t_move + dwell;
        }
        let cycle = Cycle { t0, moves };
        cycle.check_extents()?;
        Ok(cycle)
    }

    /// A `[trajectory] kind = "via"`, `rest = true` read as a cycle (`docs/motions.md` 4.12):
    /// distinct consecutive poses are moves, a repeated pose the dwell before the next move, the
    /// last dwell runs to `t_end` [s]. Errors name `trajectory.points[k]`.
    pub fn from_via(traj: &toml::Table, t_end: f64) -> Result<Cycle, ModelError> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct ViaPoint {
            t: f64,
            #[serde(rename = "Gx")]
            gx: f64,
            #[serde(rename = "Gy")]
            gy: f64,
            theta: f64,
        }
        let Some(toml::Value::Array(items)) = traj.get("points") else {
            return Err(ModelError::invalid(
                "trajectory.points",
                "missing: a via cycle lists its points",
            ));
        };
        let mut pts = Vec::with_capacity(items.len());
        for (k, item) in items.iter().enumerate() {
            let p: ViaPoint = item.clone().try_into().map_err(|e: toml::de::Error| {
                ModelError::invalid(format!("trajectory.points[{k}]"), e.message().trim_end())
            })?;
            pts.push(p);
        }
        let Some(first) = pts.first() else {
            return Err(ModelError::invalid(
                "trajectory.points",
                "a cycle needs at least two points",
            ));
        };
        let t0 = first.t;
        let pose = |p: &ViaPoint| Pose {
            gx: p.gx,
            gy: p.gy,
            theta: p.theta,
        };
        let mut moves: Vec<CycleMove> = Vec::new();
        for w in pts.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if pose(a) == pose(b) {
                continue; // a dwell: measured from the move's end to the next move's start
            }
            if let Some(last) = moves.last_mut() {
                last.dwell = a.t - last.t_end();
            }
            moves.push(CycleMove {
                from: pose(a),
                to: pose(b),
                t_start: a.t,
                t_move: b.t - a.t,
                dwell: 0.0,
            });
        }
        let Some(last) = moves.last_mut() else {
            return Err(ModelError::invalid(
                "trajectory.points",
                "a cycle needs at least one move (two distinct poses)",
            ));
        };
        last.dwell = t_end - last.t_end();
        for (k, m) in moves.iter().enumerate() {
            if !(m.t_move > 0.0 && m.dwell > 0.0) {
                return Err(ModelError::invalid(
                    "trajectory.points",
                    format!(
                        "move {} (to Gx = {}, Gy = {}, theta = {}) needs a positive duration and a dwell after it \
                         (a cycle's moves are judged in their dwells; the last dwell runs to time.t_end), got t_move = {} s, dwell = {} s",
                        k + 1, m.to.gx, m.to.gy, m.to.theta, m.t_move, m.dwell
                    ),
                ));
            }
        }
        Ok(Cycle { t0, moves })
    }

    /// No move of zero extent (two equal consecutive points of `[plan] points`).
    fn check_extents(&self) -> Result<(), ModelError> {
        match self.moves.iter().position(|m| m.from == m.to) {
            Some(k) => Err(ModelError::invalid(
                format!("plan.points[{}]", k + 1),
                "equals the point before it: a move of no extent (lengthen the dwell instead)",
            )),
            None => Ok(()),
        }
    }

    /// `time.t_end` must hold the last dwell.
    pub fn check_t_end(&self, t_end: f64) -> Result<(), ModelError> {
        let end = self.end();
        if end > t_end + 1e-12 {
            return Err(ModelError::invalid(
                "time.t_end",
                format!("{t_end} s ends before the cycle's last dwell does ({end:.6} s): make t_end at least that"),
            ));
        }
        Ok(())
    }

    /// The plain quintic cycle (Eq. C1): the `[trajectory]` table of the `via`, `rest = true`
    /// motion through the cycle's points at the times of C1 (`docs/motions.md` 1.2).
    pub fn plain_trajectory(&self) -> toml::Value {
        let point = |t: f64, p: Pose| {
            toml::Value::Table(toml::Table::from_iter([
                ("t".to_string(), toml::Value::Float(t)),
                ("Gx".to_string(), toml::Value::Float(p.gx)),
                ("Gy".to_string(), toml::Value::Float(p.gy)),
                ("theta".to_string(), toml::Value::Float(p.theta)),
            ]))
        };
        let mut points = Vec::new();
        // each move's start (after the first, the end of the previous dwell: the same pose) and end
        for m in &self.moves {
            points.push(point(m.t_start, m.from));
            points.push(point(m.t_end(), m.to));
        }
        toml::Value::Table(toml::Table::from_iter([
            ("kind".to_string(), toml::Value::String("via".into())),
            ("rest".to_string(), toml::Value::Boolean(true)),
            ("points".to_string(), toml::Value::Array(points)),
        ]))
    }
}

/// One point's pose and, after the first, its `(dwell, t_move)`: finite pose, the first point
/// without either, later points with `dwell > 0` and a positive duration.
fn check_entry(e: PointEntry, k: usize, t_move: Option<f64>) -> Result<(Pose, (f64, f64)), ModelError> {
    let key = format!("plan.points[{k}]");
    if ![e.gx, e.gy, e.theta].iter().all(|v| v.is_finite()) {
        return Err(ModelError::invalid(&key, "Gx, Gy and theta must be finite"));
    }
    let pose = Pose {
        gx: e.gx,
        gy: e.gy,
        theta: e.theta,
    };
    if k == 0 {
        if e.dwell.is_some() || e.t_move.is_some() {
            return Err(ModelError::invalid(
                &key,
                "the first point is the cycle's start (at rest at plan.t0): it takes no dwell and no t_move",
            ));
        }
        return Ok((pose, (0.0, 0.0)));
    }
    let dwell = match e.dwell {
        Some(d) if d.is_finite() && d > 0.0 => d,
        Some(d) => {
            return Err(ModelError::invalid(
                format!("{key}.dwell"),
                format!("must be > 0 s, got {d}"),
            ))
        }
        None => {
            return Err(ModelError::invalid(
                format!("{key}.dwell"),
                "missing: every point after the first is a move's end and the dwell after it [s]",
            ))
        }
    };
    let t = match e.t_move.or(t_move) {
        Some(t) if t.is_finite() && t > 0.0 => t,
        Some(t) => {
            return Err(ModelError::invalid(
                format!("{key}.t_move"),
                format!("must be > 0 s, got {t}"),
            ))
        }
        None => {
            return Err(ModelError::invalid(
                format!("{key}.t_move"),
                "missing: give plan.t_move or the point's t_move [s]",
            ))
        }
    };
    Ok((pose, (dwell, t)))
}

/// Take a cycle out of a plan file's table (`docs/motions.md` 4.12), before `[plan]` is read:
/// `[plan] points` as an array (refused with `from`/`to`), or a `via`, `rest = true`
/// `[trajectory]` next to a `[plan]` without `from`, `to` and `points` (then removed). The
/// `[plan]` table gets `from`, `to`, `t_move` and `t0` of the first move, so that it reads and
/// checks as that move's plan. `None`: not a cycle (the table untouched).
pub fn take_cycle(table: &mut toml::Table, path: &Path) -> Result<Option<Cycle>, ModelError> {
    let in_file = |e: ModelError| e.in_file(path);
    let Some(toml::Value::Table(plan)) = table.get("plan") else {
        return Ok(None);
    };
    let has = |k: &str| plan.contains_key(k);
    let array_points = matches!(plan.get("points"), Some(toml::Value::Array(_)));
    let via = via_cycle_table(table);
    if (array_points || via.is_some()) && plan.get("objective").and_then(toml::Value::as_str) == Some("time") {
        return Err(in_file(ModelError::invalid(
            "plan.objective",
            "a cycle is planned for the residual of each dwell at given durations: objective = \"time\" is not designed for cycles",
        )));
    }
    let cycle = if array_points {
        if has("from") || has("to") {
            return Err(in_file(ModelError::invalid(
                "plan.points",
                "a cycle's points replace from and to: give one or the other",
            )));
        }
        let t_move = plan.get("t_move").and_then(toml::Value::as_float);
        let t0 = plan.get("t0").and_then(toml::Value::as_float).unwrap_or(0.0);
        let points = plan.get("points").cloned().unwrap_or(toml::Value::Array(Vec::new()));
        Cycle::from_points(points, t_move, t0).map_err(in_file)?
    } else if let (Some(traj), false) = (via, has("from") || has("to") || has("points")) {
        let t_end = table
            .get("time")
            .and_then(|t| t.get("t_end"))
            .and_then(toml::Value::as_float)
            .ok_or_else(|| {
                in_file(ModelError::invalid(
                    "time.t_end",
                    "missing: a via cycle's last dwell runs to it",
                ))
            })?;
        for key in ["t0", "t_move"] {
            if has(key) {
                return Err(in_file(ModelError::invalid(
                    format!("plan.{key}"),
                    "a via cycle takes its times from [trajectory] points: remove it",
                )));
            }
        }
        let c = Cycle::from_via(&traj, t_end).map_err(in_file)?;
        table.remove("trajectory");
        c
    } else {
        return Ok(None);
    };
    first_move_keys(table, &cycle);
    Ok(Some(cycle))
}

/// The `[trajectory]` of a plan file when it is a `via` with `rest = true` (default).
fn via_cycle_table(table: &toml::Table) -> Option<toml::Table> {
    let traj = table.get("trajectory")?.as_table()?;
    let is_via = traj.get("kind").and_then(toml::Value::as_str) == Some("via");
    let rest = traj.get("rest").and_then(toml::Value::as_bool).unwrap_or(true);
    (is_via && rest).then(|| traj.clone())
}

/// Write the first move's `from`, `to`, `t0` and `t_move` into `[plan]` (replacing `points`).
fn first_move_keys(table: &mut toml::Table, cycle: &Cycle) {
    let Some(toml::Value::Table(plan)) = table.get_mut("plan") else {
        return;
    };
    let pose = |p: Pose| {
        toml::Value::Table(toml::Table::from_iter([
            ("Gx".to_string(), toml::Value::Float(p.gx)),
            ("Gy".to_string(), toml::Value::Float(p.gy)),
            ("theta".to_string(), toml::Value::Float(p.theta)),
        ]))
    };
    plan.remove("points");
    if let Some(m) = cycle.moves.first() {
        plan.insert("from".into(), pose(m.from));
        plan.insert("to".into(), pose(m.to));
        plan.insert("t0".into(), toml::Value::Float(m.t_start));
        plan.insert("t_move".into(), toml::Value::Float(m.t_move));
    }
}

/// The key and reason of an error of the plain cycle's `via` list (`trajectory.points`, "point
/// n ...", 1-based over the list of [`Cycle::plain_trajectory`], two entries per move) said of
/// the cycle's point: `plan.points[k]`, k = n / 2 (the start, then each move's end, 0-based).
pub fn via_error_key(reason: &str) -> (String, String) {
    let parsed = reason
        .strip_prefix("point ")
        .and_then(|r| r.split_once(' '))
        .and_then(|(n, rest)| n.parse::<usize>().ok().map(|n| (n, rest)));
    match parsed {
        Some((n, rest)) if n >= 1 => (format!("plan.points[{}]", n / 2), format!("the point {rest}")),
        _ => ("plan.points".to_string(), reason.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "name = \"t\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n";

    fn cycle_of(text: &str) -> Cycle {
        let cfg = crate::section::plan_config_from_str(text, Path::new("c.toml")).unwrap();
        cfg.cycle.expect("a cycle")
    }

    /// The pick-and-place cycle written as `[plan] points` and as the via cycle of
    /// `configs/motions/pick-place.toml` read to the same moves and dwells (Eq. C1 by hand).
    #[test]
    fn points_and_via_cycles_read_alike() {
        let points = cycle_of(&format!(
            "{HEAD}[plan]\nt_move = 0.4\npoints = [{{ Gx = 0.0, Gy = 0.0, theta = 0.0 }}, \
             {{ Gx = 0.03, Gy = -0.02, theta = 0.2, dwell = 0.3 }}, {{ Gx = 0.0, Gy = 0.0, theta = 0.0, dwell = 0.4 }}]\n"
        ));
        let via = cycle_of(&format!(
            "{HEAD}[plan]\n[trajectory]\nkind = \"via\"\npoints = [{{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }}, \
             {{ t = 0.4, Gx = 0.03, Gy = -0.02, theta = 0.2 }}, {{ t = 0.7, Gx = 0.03, Gy = -0.02, theta = 0.2 }}, \
             {{ t = 1.1, Gx = 0.0, Gy = 0.0, theta = 0.0 }}]\n"
        ));
        let starts: Vec<f64> = points.moves.iter().map(|m| m.t_start).collect();
        let dwells: Vec<f64> = points.moves.iter().map(|m| m.dwell).collect();
        assert_eq!(starts, [0.0, 0.7]);
        assert_eq!(dwells, [0.3, 0.4]);
        assert_eq!(points.moves.len(), via.moves.len());
        for (a, b) in points.moves.iter().zip(&via.moves) {
            assert_eq!((a.from, a.to), (b.from, b.to));
            for (x, y) in [(a.t_start, b.t_start), (a.t_move, b.t_move), (a.dwell, b.dwell)] {
                assert!((x - y).abs() < 1e-12, "{a:?} vs {b:?}");
            }
        }
        assert!((points.end() - 1.5).abs() < 1e-12);
    }

    /// A via list's point n (1-based, two per move) is the cycle's point n / 2.
    #[test]
    fn via_errors_name_the_cycle_point() {
        let poses = ["P0", "P1", "P1", "P2", "P2", "P3"];
        for (j, want) in poses.iter().enumerate() {
            let (key, _) = via_error_key(&format!("point {} (Gx = 1) is outside", j + 1));
            assert_eq!(key, format!("plan.points[{}]", &want[1..]));
        }
        assert_eq!(via_error_key("other").0, "plan.points");
    }
}
