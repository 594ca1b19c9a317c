//! Figures of the modal analyses (plotters, SVG and PNG, through the drawing kit of
//! `flexstar-plot`): the first mode shapes at a pose (AMM over FEM over the rigid
//! star) and the heat map of a frequency map with the workspace boundary and the experiment's path.

use flexstar_model::RestPose;
use flexstar_plot::{
    axis_ticks, colormap, draw_legend, Drawing, Figure, GridFigure, Panel, Series, Style, FEM_STYLE, RIGID_STYLE,
};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::analysis::Modal;
use crate::freqmap::{Axis, MapPoint};

/// Style of the AMM's shapes (the enriched family's orange of the compare figures).
pub const AMM_STYLE: Style = Style {
    color: RGBColor(255, 127, 14),
    width: 2,
    dashed: false,
};

/// Largest drawn deflection of a mode shape, as a fraction of the beam length L.
pub const SHAPE_AMPLITUDE: f64 = 0.12;

/// Modes shown by [`mode_shapes_figure`].
pub const SHAPES_SHOWN: usize = 6;

/// Deflections of one mode along the three beams at `x[k]` [m]: AMM (evaluated at the FEM's
/// nodes, `k h_i` on beam i) and FEM, both along `e_wi` of the pose, per unit modal coordinate
/// (mass-normalised).
fn sampled(modal: &Modal, j: usize) -> ([Vec<f64>; 3], [Vec<f64>; 3]) {
    let (a, f) = (&modal.amm.system, &modal.fem.system);
    let fem = [0, 1, 2].map(|i| f.deflections(&modal.fem.shapes[j], i));
    let amm = [0, 1, 2].map(|i| {
        (0..=f.ne)
            .map(|k| a.deflection(&modal.amm.shapes[j], i, k as f64 * f.element_lengths[i]))
            .collect()
    });
    (amm, fem)
}

fn flat(v: &[Vec<f64>; 3]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solve the small symmetric system `g c = r` (the normal equations of the least-squares match) by
/// nalgebra's LU with partial pivoting; `None` when singular.
fn solve_small(g: Vec<Vec<f64>>, r: Vec<f64>) -> Option<Vec<f64>> {
    let n = r.len();
    let m = nalgebra::DMatrix::from_fn(n, n, |i, j| g[i][j]);
    let x = m.lu().solve(&nalgebra::DVector::from_vec(r))?;
    x.iter().all(|v| v.is_finite()).then(|| x.iter().copied().collect())
}

/// Relative frequency gap below which two modes count as one repeated frequency (the star's
/// three-fold symmetry gives exact pairs at the centre pose).
const REPEATED: f64 = 1e-3;

/// The FEM shape matched to AMM mode `j`: within a cluster of repeated frequencies the shapes are
/// any basis of the eigenspace, so the FEM combination nearest (least squares over the sampled
/// deflections) to the AMM shape is drawn; otherwise the FEM shape with the AMM's sign.
fn matched_fem(modal: &Modal, j: usize, samples: &[(Vec<f64>, Vec<f64>)]) -> Vec<f64> {
    let f = &modal.fem.freq_hz;
    let near = |a: usize, b: usize| (f[a] - f[b]).abs() <= REPEATED * f[a].abs().max(f[b].abs()).max(1e-12);
    let lo = (0..=j).rev().take_while(|&c| near(c, j)).last().unwrap_or(j);
    let hi = (j..samples.len()).take_while(|&c| near(c, j)).last().unwrap_or(j);
    let cluster: Vec<&Vec<f64>> = (lo..=hi).map(|c| &samples[c].1).collect();
    let target = &samples[j].0;
    let g: Vec<Vec<f64>> = cluster
        .iter()
        .map(|a| cluster.iter().map(|b| dot(a, b)).collect())
        .collect();
    let r: Vec<f64> = cluster.iter().map(|a| dot(a, target)).collect();
    match solve_small(g, r) {
        Some(c) => (0..target.len())
            .map(|k| cluster.iter().zip(&c).map(|(v, ck)| ck * v[k]).sum())
            .collect(),
        None => samples[j].1.clone(),
    }
}

/// Where the beams of a drawn star lie: each beam's element length `h_i` [m] and weld angle
/// `phi_i` [rad] (the FEM's pose system: the paper's 0, 120, 240 degrees and equal h on the
/// paper's robot).
struct BeamLines {
    h: [f64; 3],
    weld: [f64; 3],
}

impl BeamLines {
    fn of(fem: &flexstar_fem::pose_modes::SparsePoseSystem) -> Self {
        BeamLines {
            h: fem.element_lengths,
            weld: fem.weld,
        }
    }

    /// `e_xi` and `e_wi` of beam i at orientation `theta` (Eqs. 11-12, W1).
    fn frame(&self, i: usize, theta: f64) -> ([f64; 2], [f64; 2]) {
        let a = theta + self.weld[i];
        ([a.sin(), -a.cos()], [a.cos(), a.sin()])
    }
}

/// The star drawn at `pose` with deflections `w[i][k]` at `x_k = k h_i` magnified by `scale`.
fn star_series(
    pose: &RestPose,
    beams: &BeamLines,
    w: &[Vec<f64>],
    scale: f64,
    label: &str,
    style: Style,
) -> Vec<Series> {
    (0..3)
        .map(|i| {
            let (ex, ew) = beams.frame(i, pose.theta);
            let h = beams.h[i];
            let (x, y) = w[i]
                .iter()
                .enumerate()
                .map(|(k, wk)| {
                    let s = k as f64 * h;
                    (
                        pose.g[0] + s * ex[0] + scale * wk * ew[0],
                        pose.g[1] + s * ex[1] + scale * wk * ew[1],
                    )
                })
                .unzip();
            Series {
                label: if i == 0 { label.to_string() } else { String::new() },
                x,
                y,
                style,
            }
        })
        .collect()
}

/// The first [`SHAPES_SHOWN`] elastic mode shapes at `pose`: the AMM's (orange) and the FEM's
/// (black) star over the rigid one (grey dashed), drawn with the same magnification (the AMM
/// shape's largest deflection = [`SHAPE_AMPLITUDE`] L), so that both normalisations show.
/// Each beam is drawn along its own weld angle with its own length (the FEM's mesh of a robot
/// as built); `l` [m] sets the magnification (the longest beam).
pub fn mode_shapes_figure(name: &str, modal: &Modal, pose: &RestPose, l: f64) -> GridFigure {
    let first = modal.amm.rigid;
    let last = (first + SHAPES_SHOWN)
        .min(modal.amm.shapes.len())
        .min(modal.fem.shapes.len());
    let samples: Vec<(Vec<f64>, Vec<f64>)> = (0..last)
        .map(|j| {
            let (a, f) = sampled(modal, j);
            (flat(&a), flat(&f))
        })
        .collect();
    let beams = BeamLines::of(&modal.fem.system);
    let per_beam = |v: &[f64]| -> Vec<Vec<f64>> { v.chunks(v.len() / 3).map(|c| c.to_vec()).collect() };
    let rigid: Vec<Vec<f64>> = vec![vec![0.0; modal.fem.system.ne + 1]; 3];
    let panels = (first..last)
        .map(|j| {
            let amm = &samples[j].0;
            let fem = matched_fem(modal, j, &samples);
            let peak = amm.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let scale = if peak > 0.0 { SHAPE_AMPLITUDE * l / peak } else { 1.0 };
            let mut series = star_series(pose, &beams, &rigid, 0.0, "rigid star", RIGID_STYLE);
            series.extend(star_series(pose, &beams, &per_beam(&fem), scale, "FEM", FEM_STYLE));
            series.extend(star_series(pose, &beams, &per_beam(amm), scale, "AMM", AMM_STYLE));
            Panel {
                title: format!(
                    "mode {}: AMM {:.3} Hz, FEM {:.3} Hz",
                    j + 1,
                    modal.amm.freq_hz[j],
                    modal.fem.freq_hz[j]
                ),
                x_label: "X [m]".into(),
                y_label: "Y [m]".into(),
                series,
                equal_axes: true,
                min_y_span: 0.0,
            }
        })
        .collect();
    let figure = Figure {
        zooms: Vec::new(),
        name: name.to_string(),
        title: format!(
            "mode shapes at G = ({:.4}, {:.4}) m, theta = {:.4} rad, sliders {}",
            pose.g[0],
            pose.g[1],
            pose.theta,
            modal.amm.system.sliders.name()
        ),
        caption: "The first elastic mode shapes of the star held by its sleeves: AMM (orange) and FEM (black), \
                  same magnification, over the rigid star (grey dashed); within a repeated frequency the FEM \
                  shape drawn is the combination of the pair nearest the AMM's. Transverse deflections along e_wi \
                  are drawn; the beams' axial motion is left out, so G can look split."
            .into(),
        panels,
    };
    GridFigure { figure, columns: 3 }
}

/// A path drawn over a frequency map (G(t) of a motion) [m].
#[derive(Debug, Clone)]
pub struct MapPath {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
}

/// Colours of the paper's four cases' paths (the `f1_paths` example's figure).
pub const PATH_COLORS: [RGBColor; 4] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(227, 119, 194),
];

/// Colour of the experiment's path over a frequency map.
pub const PATH_COLOR: RGBColor = RGBColor(214, 39, 40);

/// G(t) of the experiment over `[0, t_end]` at its output times (rigid kinematics), the path
/// drawn over its frequency map; `None` when the experiment has no prescribed path (a forces
/// drive: the motion is what the solver finds) or its trajectory leaves the feasible range. A
/// servo's path is its reference. The map holds at one orientation `map_theta` [rad]; when the
/// path turns away from it (by more than 1e-3 rad), its label says how far, so that the figure
/// never suggests the frequencies along a turning move.
pub fn trajectory_path(exp: &flexstar_model::Experiment, map_theta: f64) -> Option<MapPath> {
    if exp.drive.kind == flexstar_model::DriveKind::Forces {
        return None;
    }
    let states = rigid_path(exp)?;
    let what = if exp.drive.kind == flexstar_model::DriveKind::Servo {
        "reference G(t)"
    } else {
        "G(t)"
    };
    // round-off (2e-16 rad at a start from theta = 0) reads 0
    let (lo, hi) = states
        .iter()
        .map(|s| if s.theta.v.abs() < 1e-9 { 0.0 } else { s.theta.v })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let turns = if (lo - map_theta).abs().max((hi - map_theta).abs()) > 1e-3 {
        format!(
            "; its theta runs {} .. {} rad, the map holds at theta = {} rad only",
            flexstar_io::output::fmt_sig(lo, 3),
            flexstar_io::output::fmt_sig(hi, 3),
            flexstar_io::output::fmt_sig(map_theta, 3)
        )
    } else {
        String::new()
    };
    Some(MapPath {
        label: format!(
            "{what} of {}, t = 0 .. {} s{turns}",
            exp.name,
            flexstar_io::output::fmt_display(exp.time.t_end)
        ),
        points: states.iter().map(|s| (s.g[0].v, s.g[1].v)).collect(),
        style: Style {
            color: PATH_COLOR,
            width: 3,
            dashed: false,
        },
    })
}

/// The rigid states of the experiment's robot (the paper's or one as built, [`crate::robot`]) at
/// its output times; `None` when its motion leaves the feasible range.
fn rigid_path(exp: &flexstar_model::Experiment) -> Option<Vec<flexstar_kinematics::RigidState>> {
    use flexstar_kinematics::{feasibility::check_trajectory, RigidState};
    let robot = crate::robot(exp).ok()?;
    check_trajectory(&robot, &exp.trajectory, exp.time.t_end, exp.time.dt_out).ok()?;
    let times = exp.time.output_times();
    times
        .into_iter()
        .map(|t| RigidState::at(&robot, &exp.trajectory, t).ok())
        .collect()
}

/// The heat map of the first `shown` frequencies of a map (one panel each, own colour scale),
/// infeasible poses grey, the workspace boundary (edges between feasible and infeasible grid
/// cells) black, and `paths` over it.
pub struct FreqMapFigure {
    pub name: String,
    pub title: String,
    pub gx: Axis,
    pub gy: Axis,
    pub points: Vec<MapPoint>,
    pub shown: usize,
    pub paths: Vec<MapPath>,
}

const MAP_W: u32 = 640;
const MAP_H: u32 = 560;
const TOP_H: u32 = 36;
const LEGEND_H: u32 = 28;
const BAR_W: u32 = 90;
const INFEASIBLE: RGBColor = RGBColor(205, 205, 205);
const BOUNDARY: Style = Style {
    color: RGBColor(0, 0, 0),
    width: 2,
    dashed: false,
};

impl FreqMapFigure {
    fn value(&self, ix: usize, iy: usize, mode: usize) -> Option<f64> {
        match &self.points[iy * self.gx.n + ix].result {
            Ok(f) => f.get(mode).copied().filter(|v| v.is_finite()),
            Err(_) => None,
        }
    }

    fn feasible(&self, ix: usize, iy: usize) -> bool {
        self.points[iy * self.gx.n + ix].result.is_ok()
    }

    /// Edges between feasible and infeasible cells (cell of point k spans k +- half a step).
    fn boundary(&self) -> Vec<[(f64, f64); 2]> {
        let (dx, dy) = (step(&self.gx), step(&self.gy));
        let mut edges = Vec::new();
        for iy in 0..self.gy.n {
            for ix in 0..self.gx.n {
                let (x, y) = (self.gx.at(ix), self.gy.at(iy));
                if ix + 1 < self.gx.n && self.feasible(ix, iy) != self.feasible(ix + 1, iy) {
                    let xe = x + 0.5 * dx;
                    edges.push([(xe, y - 0.5 * dy), (xe, y + 0.5 * dy)]);
                }
                if iy + 1 < self.gy.n && self.feasible(ix, iy) != self.feasible(ix, iy + 1) {
                    let ye = y + 0.5 * dy;
                    edges.push([(x - 0.5 * dx, ye), (x + 0.5 * dx, ye)]);
                }
            }
        }
        edges
    }

    fn draw_mode<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, mode: usize) -> Result<(), String> {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let values: Vec<f64> = (0..self.gy.n)
            .flat_map(|iy| (0..self.gx.n).map(move |ix| (ix, iy)))
            .filter_map(|(ix, iy)| self.value(ix, iy, mode))
            .collect();
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let span = if hi > lo { hi - lo } else { 1.0 };
        let (w, _) = area.dim_in_pixel();
        let (plot, bar) = area.split_horizontally(w.saturating_sub(BAR_W));
        let (dx, dy) = (step(&self.gx), step(&self.gy));
        let (xr, yr) = (
            (self.gx.min - 0.5 * dx, self.gx.max + 0.5 * dx),
            (self.gy.min - 0.5 * dy, self.gy.max + 0.5 * dy),
        );
        let mut chart = ChartBuilder::on(&plot)
            .caption(format!("f{} [Hz]", mode + 1), ("sans-serif", 15))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
            .map_err(|x| e(&x))?;
        let (x_ticks, y_ticks) = (axis_ticks(xr.0, xr.1), axis_ticks(yr.0, yr.1));
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("Gx [m]")
            .y_desc("Gy [m]")
            .label_style(("sans-serif", 12))
            .x_label_formatter(&x_ticks)
            .y_label_formatter(&y_ticks)
            .draw()
            .map_err(|x| e(&x))?;
        let cells = (0..self.gy.n).flat_map(|iy| (0..self.gx.n).map(move |ix| (ix, iy)));
        chart
            .draw_series(cells.map(|(ix, iy)| {
                let (x, y) = (self.gx.at(ix), self.gy.at(iy));
                let color = match self.value(ix, iy, mode) {
                    Some(v) => colormap((v - lo) / span),
                    None => INFEASIBLE,
                };
                Rectangle::new(
                    [(x - 0.5 * dx, y - 0.5 * dy), (x + 0.5 * dx, y + 0.5 * dy)],
                    color.filled(),
                )
            }))
            .map_err(|x| e(&x))?;
        let line = |s: Style| ShapeStyle {
            color: s.color.to_rgba(),
            filled: false,
            stroke_width: s.width,
        };
        chart
            .draw_series(
                self.boundary()
                    .into_iter()
                    .map(|seg| PathElement::new(seg.to_vec(), line(BOUNDARY))),
            )
            .map_err(|x| e(&x))?;
        for p in &self.paths {
            for piece in clipped(&p.points, xr, yr) {
                if piece.len() == 1 || span_of(&piece) < 1e-9 {
                    chart
                        .draw_series(std::iter::once(Circle::new(piece[0], 5, line(p.style).filled())))
                        .map_err(|x| e(&x))?;
                } else {
                    chart
                        .draw_series(LineSeries::new(piece, line(p.style)))
                        .map_err(|x| e(&x))?;
                }
            }
        }
        draw_colour_bar(&bar, lo, hi)
    }
}

fn step(a: &Axis) -> f64 {
    (a.max - a.min) / (a.n - 1) as f64
}

fn span_of(p: &[(f64, f64)]) -> f64 {
    p.iter()
        .map(|q| (q.0 - p[0].0).abs() + (q.1 - p[0].1).abs())
        .fold(0.0, f64::max)
}

/// The runs of consecutive points of `p` inside the ranges (a path leaving the map is cut).
fn clipped(p: &[(f64, f64)], xr: (f64, f64), yr: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let inside = |q: &(f64, f64)| (xr.0..=xr.1).contains(&q.0) && (yr.0..=yr.1).contains(&q.1);
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur = Vec::new();
    for q in p {
        if inside(q) {
            cur.push(*q);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// A vertical colour bar from `lo` to `hi` [Hz] with tick labels.
fn draw_colour_bar<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, lo: f64, hi: f64) -> Result<(), String> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Ok(());
    }
    let top = if hi > lo { hi } else { lo + 1.0 };
    let mut chart = ChartBuilder::on(area)
        .margin_top(34)
        .margin_bottom(44)
        .margin_right(8)
        .y_label_area_size(52)
        .build_cartesian_2d(0.0..1.0, lo..top)
        .map_err(|x| x.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .label_style(("sans-serif", 11))
        .y_label_formatter(&axis_ticks(lo, top))
        .draw()
        .map_err(|x| x.to_string())?;
    const STEPS: usize = 64;
    chart
        .draw_series((0..STEPS).map(|k| {
            let (a, b) = (k as f64 / STEPS as f64, (k + 1) as f64 / STEPS as f64);
            Rectangle::new(
                [(0.0, lo + a * (top - lo)), (1.0, lo + b * (top - lo))],
                colormap(0.5 * (a + b)).filled(),
            )
        }))
        .map_err(|x| x.to_string())?;
    Ok(())
}

impl Drawing for FreqMapFigure {
    fn name(&self) -> &str {
        &self.name
    }

    fn size(&self) -> (u32, u32) {
        (MAP_W * self.shown.max(1) as u32, MAP_H + TOP_H + LEGEND_H)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (top, rest) = root.split_vertically(TOP_H);
        top.titled(&self.title, ("sans-serif", 17)).map_err(|e| e.to_string())?;
        let (legend, body) = rest.split_vertically(LEGEND_H);
        let mut entries: Vec<(String, Style)> = self.paths.iter().map(|p| (p.label.clone(), p.style)).collect();
        entries.push(("workspace boundary (grey: infeasible)".into(), BOUNDARY));
        draw_legend(&legend, &entries)?;
        for (mode, area) in body.split_evenly((1, self.shown.max(1))).iter().enumerate() {
            self.draw_mode(area, mode)?;
        }
        root.present().map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_shows_the_experiments_own_path() {
        let mut exp = flexstar_model::catalogue::paper_case(3);
        // case 3 turns the star (general plane motion): the label says so, with its range of
        // theta from the rigid kinematics at the output times (independent of the map)
        let path = trajectory_path(&exp, 0.0).expect("a motion has a path");
        let thetas: Vec<f64> = (exp.time.output_times().iter())
            .map(|&t| {
                flexstar_kinematics::RigidState::at(&exp.robot, &exp.trajectory, t)
                    .unwrap()
                    .theta
                    .v
            })
            .collect();
        let (lo, hi) = thetas
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
        assert!(hi - lo > 1e-2, "case 3 turns: {lo} .. {hi}");
        assert_eq!(
            path.label,
            format!(
                "G(t) of case3, t = 0 .. 0.5 s; its theta runs {} .. {} rad, the map holds at theta = 0 rad only",
                flexstar_io::output::fmt_sig(lo, 3),
                flexstar_io::output::fmt_sig(hi, 3)
            )
        );
        // case 2 translates only: nothing to say
        let c2 = flexstar_model::catalogue::paper_case(2);
        assert_eq!(
            trajectory_path(&c2, 0.0).unwrap().label,
            "G(t) of case2, t = 0 .. 0.4 s"
        );
        // one point per output time, from G(0) (independent: the rigid kinematics at t = 0)
        assert_eq!(path.points.len(), exp.time.output_times().len());
        let g0 = flexstar_kinematics::RigidState::at(&exp.robot, &exp.trajectory, 0.0).unwrap();
        assert_eq!(path.points[0], (g0.g[0].v, g0.g[1].v));
        exp.drive.kind = flexstar_model::DriveKind::Forces;
        assert!(
            trajectory_path(&exp, 0.0).is_none(),
            "a forces drive has no prescribed path"
        );
    }

    #[test]
    fn paths_are_cut_where_they_leave_the_map() {
        let p = [(0.0, 0.0), (0.5, 0.0), (2.0, 0.0), (0.2, 0.1)];
        let c = clipped(&p, (-1.0, 1.0), (-1.0, 1.0));
        assert_eq!(c, vec![vec![(0.0, 0.0), (0.5, 0.0)], vec![(0.2, 0.1)]]);
    }
}
