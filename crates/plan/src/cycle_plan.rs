//! Planning a whole cycle (`docs/motions.md` 4.12): every move planned alone from rest to rest
//! with the single-move planner (4.2-4.10), then the moves shifted to their start times and
//! joined by the dwells (Eq. C3).

use std::time::Instant;

use rayon::prelude::*;

use serde::Serialize;

use flexstar_model::{ModelError, Pose, Trajectory};

use crate::cycle::{Cycle, CycleMove};
use crate::planner::{check_plan_input, Planned};
use crate::section::PlanConfig;
use crate::PlanError;

/// One move of a planned cycle: its times in the cycle and its single-move plan (from `t0 = 0`).
#[derive(Debug, Clone, Serialize)]
pub struct PlannedMove {
    pub span: CycleMove,
    pub planned: Planned,
}

/// A planned cycle: the moves in order, and the wall time of the planning [s].
#[derive(Debug, Clone, Serialize)]
pub struct PlannedCycle {
    pub cycle: Cycle,
    pub moves: Vec<PlannedMove>,
    pub wall_s: f64,
}

impl PlannedCycle {
    /// The planned cycle's pose at `t` [s] (Eq. C3): move k's plan at `t - t_k^start` on move
    /// k, the point held on each dwell, the first point before the cycle.
    pub fn pose(&self, t: f64) -> Result<[f64; 3], ModelError> {
        let arr = |p: Pose| [p.gx, p.gy, p.theta];
        let Some(first) = self.moves.first() else {
            return Err(ModelError::invalid("plan.points", "a cycle without moves"));
        };
        if t <= first.span.t_start {
            return Ok(arr(first.span.from));
        }
        for m in &self.moves {
            if t <= m.span.t_end() {
                let local = (t - m.span.t_start).max(0.0);
                return Ok(m.planned.trajectory.pose(local)?.unwrap_or(arr(m.span.from)));
            }
            if t < m.span.t_end() + m.span.dwell {
                return Ok(arr(m.span.to));
            }
        }
        Ok(self.moves.last().map_or(arr(first.span.from), |m| arr(m.span.to)))
    }
}

/// The configuration of move `m` alone (`docs/motions.md` 4.12): the file's experiment, keys
/// and limits with `from`, `to`, `t0 = 0` and `t_move` of the move; its run time is what the
/// cycle has left after the move's start (so the single plan's ZVD check is the cycle's).
pub fn move_config(cfg: &PlanConfig, m: &CycleMove) -> PlanConfig {
    let mut sub = cfg.clone();
    sub.cycle = None;
    sub.plan.from = m.from;
    sub.plan.to = m.to;
    sub.plan.t0 = 0.0;
    sub.plan.t_move = Some(m.t_move);
    sub.exp.trajectory = Trajectory::Quintic {
        from: m.from,
        to: m.to,
        t0: 0.0,
        t1: m.t_move,
    };
    sub.exp.time.t_end = cfg.exp.time.t_end - m.t_start;
    sub
}

/// Plan the cycle of `cfg` (`docs/motions.md` 4.12; its points were checked reachable when the
/// file was read): every move's checks of 4.8 first (nothing planned before all pass), then the moves' single plans, side by side.
pub fn plan_cycle(cfg: &PlanConfig) -> Result<PlannedCycle, PlanError> {
    let started = Instant::now();
    let Some(cycle) = cfg.cycle.clone() else {
        return Err(PlanError::Solver("plan_cycle: the configuration holds no cycle".into()));
    };
    let subs: Vec<PlanConfig> = cycle.moves.iter().map(|m| move_config(cfg, m)).collect();
    for (k, sub) in subs.iter().enumerate() {
        check_plan_input(sub).map_err(|e| in_move(e, k))?;
    }
    // the moves are independent (each from rest to rest): planned side by side, the first
    // failing move (in the cycle's order) reported
    let plans: Vec<Result<Planned, PlanError>> = subs.par_iter().map(crate::planner::plan).collect();
    let mut moves = Vec::with_capacity(subs.len());
    for (k, (planned, span)) in plans.into_iter().zip(&cycle.moves).enumerate() {
        let planned = planned.map_err(|e| in_move(e, k))?;
        moves.push(PlannedMove { span: *span, planned });
    }
    Ok(PlannedCycle {
        cycle,
        moves,
        wall_s: started.elapsed().as_secs_f64(),
    })
}

/// A move's error, said of that move (`move k of the cycle`, 1-based).
fn in_move(e: PlanError, k: usize) -> PlanError {
    match e {
        PlanError::Input(ModelError::Invalid { file, key, reason }) => PlanError::Input(ModelError::Invalid {
            file,
            key,
            reason: format!("{reason} (move {} of the cycle)", k + 1),
        }),
        PlanError::Infeasible { what, reason } => PlanError::Infeasible {
            what: format!("move {} of the cycle: {what}", k + 1),
            reason,
        },
        PlanError::Solver(s) => PlanError::Solver(format!("move {} of the cycle: {s}", k + 1)),
        other => other,
    }
}
