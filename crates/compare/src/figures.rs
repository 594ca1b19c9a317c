//! The paper's figures for one case, AMM families against the FEM, drawn with `flexstar-plot`:
//! elastic displacement of G in the three rigid frames (Figs. 8, 12, 16, 20), tip displacements
//! (Figs. 9, 13, 17, 21), the deformed star at t_end (Figs. 10, 14, 18, 22) and the driving
//! forces with the rigid-body limit (Figs. 11, 15, 19, 23).

use flexstar_kinematics::RigidState;
use flexstar_model::Response;
use flexstar_plot::{Figure, Panel, Series, Style, RIGID_STYLE};

/// A labelled response with its drawing style.
pub struct Run<'a> {
    pub label: String,
    pub response: &'a Response,
    pub style: Style,
}

fn scaled(v: &[f64], k: f64) -> Vec<f64> {
    v.iter().map(|x| x * k).collect()
}

/// Three panels of one quantity (per beam), every run overlaid; values in mm.
fn per_beam(runs: &[Run], title: &str, y_label: &str, pick: impl Fn(&Response, usize) -> Vec<f64>) -> Vec<Panel> {
    (0..3)
        .map(|i| Panel {
            title: format!("{title} {}", i + 1),
            x_label: "t [s]".into(),
            y_label: y_label.into(),
            series: runs
                .iter()
                .map(|r| Series {
                    label: r.label.clone(),
                    x: r.response.t.clone(),
                    y: pick(r.response, i),
                    style: r.style,
                })
                .collect(),
            equal_axes: false,
            min_y_span: 1e-3,
        })
        .collect()
}

/// Elastic displacement of G in the three rigid frames, w_iG [mm].
pub fn figure_w_g(case: &str, runs: &[Run]) -> Figure {
    Figure {
        zooms: Vec::new(),
        name: format!("{case}-wG"),
        title: format!("{case}: elastic displacement of G in the rigid frames x_i w_i"),
        caption: "The junction G's elastic displacement seen from each beam's rigid frame, every AMM run against \
                  the FEM (black). Pinned-free modes hold G still (a flat zero line), so where the FEM's G moves \
                  that family cannot follow; the EVP at G compares the length of this displacement vector."
            .into(),
        panels: per_beam(runs, "w_G in frame", "w_iG [mm]", |r, i| scaled(&r.w_g[i], 1e3)),
    }
}

/// Elastic tip displacements w_i(L) [mm] (points A, B, C).
pub fn figure_tips(case: &str, runs: &[Run]) -> Figure {
    let mut f = Figure {
        zooms: Vec::new(),
        name: format!("{case}-tips"),
        title: format!("{case}: elastic tip displacements w_i(L) (A, B, C)"),
        caption: "Tip deflections of the three beams, the responses behind the EVPs at A, B and C. Compare each \
                  run's phase and amplitude with the FEM (black): a curve that drifts away from it has a large EVP."
            .into(),
        panels: per_beam(runs, "tip of beam", "w_i(L) [mm]", |r, i| scaled(&r.w_tip[i], 1e3)),
    };
    for (p, name) in f.panels.iter_mut().zip(["A", "B", "C"]) {
        p.title = format!("tip {name} (beam {})", &p.title[p.title.len() - 1..]);
    }
    f
}

/// Driving forces Fa_i [N] (Eq. 33), with the rigid-body inverse dynamics as a dashed line.
pub fn figure_forces(case: &str, runs: &[Run], rigid: Option<(&[f64], &[[f64; 3]])>) -> Figure {
    let mut panels = per_beam(runs, "driving force Fa", "Fa_i [N]", |r, i| r.fa[i].clone());
    if let Some((t, fa)) = rigid {
        for (i, p) in panels.iter_mut().enumerate() {
            p.series.push(Series {
                label: "rigid".into(),
                x: t.to_vec(),
                y: fa.iter().map(|f| f[i]).collect(),
                style: RIGID_STYLE,
            });
        }
    }
    Figure {
        zooms: Vec::new(),
        name: format!("{case}-forces"),
        title: format!("{case}: driving forces Fa_i (Eq. 33)"),
        caption: "Actuator forces against the rigid-body inverse dynamics (grey dashed): the elastic star adds an \
                  oscillation around the rigid curve. The FEM's forces also carry a small fast ripple (a few per \
                  cent, 100-400 Hz): they come from the sleeve pin reactions, which feel the local bending of the \
                  beam inside the moving sleeve, modes that the AMM's truncated basis does not hold."
            .into(),
        panels,
    }
}

/// The slider positions s_i [mm] of direct runs (their columns `s1..s3`) over the reference
/// motion `reference` (the servo's `[trajectory]` at the times `t`), dashed.
pub fn figure_sliders(case: &str, runs: &[Run], t: &[f64], reference: &[[f64; 3]]) -> Figure {
    let mut panels = per_beam(runs, "slider", "s_i [mm]", |r, i| {
        scaled(r.column(&format!("s{}", i + 1)).unwrap_or(&[]), 1e3)
    });
    for (i, p) in panels.iter_mut().enumerate() {
        p.series.push(Series {
            label: "reference".into(),
            x: t.to_vec(),
            y: reference.iter().map(|s| s[i] * 1e3).collect(),
            style: RIGID_STYLE,
        });
    }
    Figure {
        zooms: Vec::new(),
        name: format!("{case}-sliders"),
        title: format!("{case}: slider positions s_i against the servo's reference"),
        caption: "Where the servo took each slider in every run, against the ideal motion it was asked to follow \
            (the [trajectory], grey dashed). The gap is the tracking error of compare.md's servo table."
            .into(),
        panels,
    }
}

/// The deformed star at its last snapshot: (a) elastic deflection w_i(x) of each beam [mm];
/// (b) absolute shape with the elastic part magnified by `magnify`, over the rigid star
/// (`rigid`: the rigid kinematics at the snapshot time, post-processing only).
pub fn figure_star(case: &str, runs: &[Run], rigid: &RigidState, magnify: f64) -> Option<Figure> {
    let mut deflection: Vec<Panel> = (0..3)
        .map(|i| Panel {
            title: format!("(a) beam {}: elastic deflection", i + 1),
            x_label: "x [m]".into(),
            y_label: "w_i(x) [mm]".into(),
            series: vec![],
            equal_axes: false,
            min_y_span: 1e-3,
        })
        .collect();
    let mut absolute = Panel {
        title: format!("(b) star, elastic part x{magnify:.0}"),
        x_label: "X [m]".into(),
        y_label: "Y [m]".into(),
        series: vec![],
        equal_axes: true,
        min_y_span: 0.0,
    };
    let mut t_snap = None;
    for r in runs {
        let Some(shape) = r.response.shapes.last() else {
            continue;
        };
        t_snap = Some(shape.t);
        for (i, b) in shape.beams.iter().enumerate() {
            deflection[i].series.push(Series {
                label: r.label.clone(),
                x: b.x.clone(),
                y: scaled(&b.w, 1e3),
                style: r.style,
            });
            let (xs, ys): (Vec<f64>, Vec<f64>) =
                b.x.iter()
                    .zip(&b.pos)
                    .map(|(x, p)| {
                        let q = rigid.point(i, *x);
                        (q[0] + magnify * (p[0] - q[0]), q[1] + magnify * (p[1] - q[1]))
                    })
                    .unzip();
            let label = if i == 0 { r.label.clone() } else { String::new() };
            absolute.series.push(Series {
                label,
                x: xs,
                y: ys,
                style: r.style,
            });
        }
    }
    let t = t_snap?;
    for i in 0..3 {
        let (a, b) = (rigid.point(i, 0.0), rigid.point(i, rigid_length(runs, i)));
        absolute.series.push(Series {
            label: if i == 0 { "rigid".into() } else { String::new() },
            x: vec![a[0], b[0]],
            y: vec![a[1], b[1]],
            style: RIGID_STYLE,
        });
    }
    deflection.push(absolute);
    Some(Figure {
        zooms: Vec::new(),
        name: format!("{case}-star"),
        title: format!("{case}: beam shapes at t = {t:.3} s (deflection in the rigid frames; star magnified)"),
        caption: format!(
            "(a) Deflection along each beam at the end of the motion, in its rigid frame; look at G (x = 0): \
             its value and slope show what the junction does, and at the sleeve, where the beam is held. \
             (b) The whole star with the elastic part magnified {magnify:.0} times over the rigid star (grey dashed)."
        ),
        panels: deflection,
    })
}

/// Length of beam i as sampled by the runs' last snapshots.
fn rigid_length(runs: &[Run], i: usize) -> f64 {
    runs.iter()
        .filter_map(|r| r.response.shapes.last().and_then(|s| s.beams[i].x.last().copied()))
        .fold(0.0, f64::max)
}
