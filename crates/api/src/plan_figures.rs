//! The figures of `flexstar plan` that show the motions themselves (`docs/motions.md` 4.7):
//! slider speeds and accelerations against the limits, the driving forces against `Fa_max`, the
//! path of G.

use flexstar_model::{Experiment, Trajectory};
use flexstar_plot::{Figure, Panel, Series, RIGID_STYLE};

use crate::plan::PlanOutcome;
use crate::plan_report::style;

/// `max_i |d^k s_i / dt^k|` (k = 1, 2) of `traj` at the times `t` [s].
fn slider_peak(exp: &Experiment, traj: &Trajectory, t: &[f64], order: usize) -> Vec<f64> {
    t.iter()
        .map(|&t| {
            traj.jets(&exp.robot, t).map_or(f64::NAN, |j| {
                j.iter()
                    .map(|j| if order == 1 { j.d1.abs() } else { j.d2.abs() })
                    .fold(0.0, f64::max)
            })
        })
        .collect()
}

/// A horizontal line at `y` over `[t0, t1]`, labelled.
fn limit_line(label: &str, y: f64, t0: f64, t1: f64) -> Series {
    Series {
        label: label.into(),
        x: vec![t0, t1],
        y: vec![y, y],
        style: RIGID_STYLE,
    }
}

fn panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    Panel {
        title: title.into(),
        x_label: "t [s]".into(),
        y_label: y_label.into(),
        series,
        equal_axes: false,
        min_y_span: 1e-9,
    }
}

/// The largest slider speed and acceleration of each motion, with `v_max` and `a_max`.
pub fn sliders_figure(exp: &Experiment, o: &PlanOutcome) -> Figure {
    let limits = o.planned.limits;
    let mut panels = Vec::new();
    for (order, (title, unit, max)) in [
        (1, ("largest slider speed", "max |s_i'| [m/s]", limits.v_max)),
        (2, ("largest slider acceleration", "max |s_i''| [m/s^2]", limits.a_max)),
    ] {
        let mut series: Vec<Series> = o
            .motions
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let t = &m.amm.response.t;
                Series {
                    label: if order == 1 { m.key.to_string() } else { String::new() },
                    x: t.clone(),
                    y: slider_peak(exp, &m.exp.trajectory, t, order),
                    style: style(k, false),
                }
            })
            .collect();
        if let Some(max) = max {
            series.push(limit_line(
                if order == 1 { "v_max" } else { "a_max" },
                max,
                0.0,
                exp.time.t_end,
            ));
        }
        panels.push(panel(title, unit, series));
    }
    Figure {
        zooms: Vec::new(),
        name: format!("{}-plan-sliders", exp.name),
        title: format!("{}: slider speeds and accelerations", exp.name),
        caption:
            "The largest of the three sliders at each time, rigid inverse kinematics; grey: the limits of [limits]."
                .into(),
        panels,
    }
}

/// The largest driving force `max_i |Fa_i|` of each motion on the AMM and the FEM, with `Fa_max`.
pub fn forces_figure(exp: &Experiment, o: &PlanOutcome) -> Figure {
    let largest = |r: &flexstar_model::Response| -> Vec<f64> {
        (0..r.t.len())
            .map(|k| r.fa.iter().map(|f| f[k].abs()).fold(0.0, f64::max))
            .collect()
    };
    let mut series = Vec::new();
    for (k, m) in o.motions.iter().enumerate() {
        for (run, dashed, solver) in [(&m.amm, false, "AMM"), (&m.fem, true, "FEM")] {
            series.push(Series {
                label: format!("{}, {solver}", m.key),
                x: run.response.t.clone(),
                y: largest(&run.response),
                style: style(k, dashed),
            });
        }
    }
    if let Some(max) = o.planned.limits.fa_max {
        series.push(limit_line("Fa_max", max, 0.0, exp.time.t_end));
    }
    Figure {
        zooms: Vec::new(),
        name: format!("{}-plan-forces", exp.name),
        title: format!("{}: driving forces", exp.name),
        caption: "max_i |Fa_i| (Eq. 33) of the three motions, AMM solid and FEM dashed; grey: Fa_max.".into(),
        panels: vec![panel("largest driving force", "max |Fa_i| [N]", series)],
    }
}

/// The path of G of each motion in the fixed frame.
pub fn path_figure(exp: &Experiment, o: &PlanOutcome) -> Figure {
    let series = o
        .motions
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let poses: Vec<[f64; 3]> = m
                .amm
                .response
                .t
                .iter()
                .filter_map(|&t| m.exp.trajectory.pose(t).ok().flatten())
                .collect();
            Series {
                label: m.key.to_string(),
                x: poses.iter().map(|p| 1e3 * p[0]).collect(),
                y: poses.iter().map(|p| 1e3 * p[1]).collect(),
                style: style(k, k == 1),
            }
        })
        .collect();
    Figure {
        zooms: Vec::new(),
        name: format!("{}-plan-path", exp.name),
        title: format!("{}: path of G", exp.name),
        caption: "G in the fixed frame (rigid); a timing plan keeps the straight segment, a path plan may leave it."
            .into(),
        panels: vec![Panel {
            title: "path of G".into(),
            x_label: "Gx [mm]".into(),
            y_label: "Gy [mm]".into(),
            series,
            equal_axes: true,
            min_y_span: 1.0,
        }],
    }
}
