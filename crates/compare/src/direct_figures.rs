//! Figures of a direct-dynamics run (`docs/drives.md`): what the drive did to the sliders and to the star.
//!
//! - `<stem>-sliders`: the simulated slider positions s_i [mm] over the `[trajectory]` (the servo's
//!   reference, or the motion the forces were meant to produce) drawn dashed;
//! - `<stem>-tracking`: for a servo, the tracking errors e_i = s_ref,i - s_i [mm];
//! - `<stem>-tips` and `<stem>-forces`: the elastic tip deflections and the actuator forces, as
//!   for the inverse runs (`figures`).

use flexstar_model::{Experiment, Response};

use flexstar_plot::{Figure, Panel, Series, Style, FAMILY_COLORS, FEM_STYLE, RIGID_STYLE};

use crate::figures::{figure_forces, figure_tips, Run};

/// The response's column `name`, or an empty vector (a figure then shows nothing for it).
fn column(r: &Response, name: &str) -> Vec<f64> {
    r.column(name).map(<[f64]>::to_vec).unwrap_or_default()
}

fn mm(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| x * 1e3).collect()
}

/// Colour of a run: the FEM black, the AMM in its family's colour (orange for the accurate one).
pub fn run_style(r: &Response) -> Style {
    if r.info.solver.starts_with("fem") {
        return FEM_STYLE;
    }
    let family = r.info.family.as_deref().unwrap_or("");
    let k = flexstar_model::ModeFamily::ALL
        .iter()
        .position(|f| f.name() == family)
        .unwrap_or(4);
    Style {
        color: FAMILY_COLORS[k],
        width: 2,
        dashed: false,
    }
}

/// The figures of one direct run `r` of `exp`, named `<stem>-...`.
pub fn direct_figures(exp: &Experiment, stem: &str, r: &Response) -> Vec<Figure> {
    let label = stem.to_string();
    let style = run_style(r);
    let reference: Vec<[f64; 3]> =
        r.t.iter()
            .map(|&t| exp.trajectory.s(&exp.robot, t).unwrap_or([f64::NAN; 3]))
            .collect();
    let sliders = (0..3)
        .map(|i| Panel {
            title: format!("slider {}", i + 1),
            x_label: "t [s]".into(),
            y_label: format!("s{} [mm]", i + 1),
            series: vec![
                Series {
                    label: label.clone(),
                    x: r.t.clone(),
                    y: mm(&column(r, &format!("s{}", i + 1))),
                    style,
                },
                Series {
                    label: "[trajectory]".into(),
                    x: r.t.clone(),
                    y: reference.iter().map(|s| s[i] * 1e3).collect(),
                    style: RIGID_STYLE,
                },
            ],
            equal_axes: false,
            min_y_span: 1e-3,
        })
        .collect();
    let mut figs = vec![Figure {
        zooms: Vec::new(),
        name: format!("{stem}-sliders"),
        title: format!("{}: slider positions of the direct run", exp.name),
        caption: "Where the drive took the sliders (colour) against the [trajectory] of the config (grey dashed): \
                  the servo's reference, or the motion whose forces were fed in."
            .into(),
        panels: sliders,
    }];
    if r.column("e1").is_some() {
        figs.push(Figure {
            zooms: Vec::new(),
            name: format!("{stem}-tracking"),
            title: format!("{}: servo tracking errors", exp.name),
            caption: "Tracking error e_i = s_ref,i - s_i of each servo axis. With rigid feedforward it is the part of \
                      the force the flexible star asks for beyond the rigid one, filtered by the loop."
                .into(),
            panels: (0..3)
                .map(|i| Panel {
                    title: format!("axis {}", i + 1),
                    x_label: "t [s]".into(),
                    y_label: format!("e{} [mm]", i + 1),
                    series: vec![Series {
                        label: label.clone(),
                        x: r.t.clone(),
                        y: mm(&column(r, &format!("e{}", i + 1))),
                        style,
                    }],
                    equal_axes: false,
                    min_y_span: 1e-6,
                })
                .collect(),
        });
    }
    let runs = [Run {
        label,
        response: r,
        style,
    }];
    let mut tips = figure_tips(&exp.name, &runs);
    tips.name = format!("{stem}-tips");
    let mut forces = figure_forces(&exp.name, &runs, None);
    forces.name = format!("{stem}-forces");
    forces.caption = "The actuator forces of the direct run: the given profile, or what the servo pushed.".into();
    figs.push(tips);
    figs.push(forces);
    figs
}
