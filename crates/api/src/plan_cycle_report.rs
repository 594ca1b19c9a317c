//! `plan.json` and `plan.md` of a cycle (`docs/motions.md` 4.12): per move the single plan's
//! record and times, per dwell both motions' residual peaks of G and their ratio.

use serde_json::{json, Value};

use flexstar_plan::PlanConfig;

use crate::plan_cycle::CycleOutcome;

/// `plan.json`: the cycle, per move its times, via points and planner record (4.7), per dwell
/// the comparison, the wall times.
pub fn cycle_json(cfg: &PlanConfig, o: &CycleOutcome) -> Value {
    let moves: Vec<Value> = o
        .planned
        .moves
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let p = &m.planned;
            json!({
                "move": k + 1,
                "span": m.span,
                "via_points_from_move_start": p.family.points(&p.x, p.t_move),
                "plain_r_norm_m": p.plain.norm_g(),
                "planned_r_norm_m": p.eval.norm_g(),
                "planner": p,
            })
        })
        .collect();
    json!({
        "provenance": crate::provenance(),
        "experiment": cfg.exp.name,
        "limits": cfg.limits,
        "cycle": o.planned.cycle,
        "moves": moves,
        "dwells": o.dwells,
        "planning_wall_s": o.planned.wall_s,
        "wall_s": o.wall_s,
        "via_equivalent": "each move: kind = \"via\", rest = false through its via points shifted by span.t_start; the dwells hold the points",
    })
}

fn mm(v: Option<f64>) -> String {
    v.map_or("n/a".into(), |v| format!("{:.4}", 1e3 * v))
}

/// `plan.md`: the cycle, the moves, the dwells, how to read them.
pub fn cycle_markdown(cfg: &PlanConfig, o: &CycleOutcome) -> String {
    let mut s = format!(
        "# {}: planned cycle\n\n{} moves, each planned alone from rest to rest (docs/motions.md 4.12) and judged by \
         the residual of G during the dwell after it; planning {:.2} s, command {:.2} s.\n\n",
        cfg.exp.name,
        o.planned.moves.len(),
        o.planned.wall_s,
        o.wall_s
    );
    s.push_str("## Moves\n\n| move | from (Gx, Gy, theta) | to | start [s] | T [s] | dwell [s] | AMM runs | planning [s] | stop |\n|---|---|---|---|---|---|---|---|---|\n");
    for (k, m) in o.planned.moves.iter().enumerate() {
        let (a, b) = (m.span.from, m.span.to);
        s.push_str(&format!(
            "| {} | ({}, {}, {}) | ({}, {}, {}) | {:.4} | {:.4} | {:.4} | {} | {:.2} | {} |\n",
            k + 1,
            a.gx,
            a.gy,
            a.theta,
            b.gx,
            b.gy,
            b.theta,
            m.span.t_start,
            m.span.t_move,
            m.span.dwell,
            m.planned.evaluations,
            m.planned.wall_s,
            m.planned.reason
        ));
    }
    s.push_str(
        "\n## Residual peak of |dG| per dwell [mm]\n\n| dwell | window [s] | plain AMM | plain FEM | planned AMM | planned FEM | planned / plain (FEM) | move from rest (AMM, planner) |\n|---|---|---|---|---|---|---|---|\n",
    );
    for d in &o.dwells {
        s.push_str(&format!(
            "| {} | {:.3}-{:.3} | {} | {} | {} | {} | {} | {} |\n",
            d.dwell,
            d.t_start,
            d.t_end,
            mm(d.plain_amm_m),
            mm(d.plain_fem_m),
            mm(d.planned_amm_m),
            mm(d.planned_fem_m),
            d.ratio_fem.map_or("n/a".into(), |r| format!("{r:.4}")),
            mm(Some(d.from_rest_amm_m))
        ));
    }
    s.push_str(
        "\nHow to read: each dwell's window runs from the end of its move to the start of the next \
         (the last to t_end); both cycles are measured with the plain cycle's windows (docs/motions.md 2.5). \
         The last column is the move planned alone from rest (the planner's AMM window after the move); a \
         cycle value well above it means the previous dwell's leftover vibration carried into the move \
         (Eq. C2). The runs and their per-dwell tables are in plain/ and planned/ (`<stem>-dwells.csv`, \
         figures/<stem>-dG).\n",
    );
    s
}
