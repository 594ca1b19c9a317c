//! The paper's figures for one case, AMM families against the FEM (plotters, SVG and PNG):
//! elastic displacement of G in the three rigid frames (Figs. 8, 12, 16, 20), tip displacements
//! (Figs. 9, 13, 17, 21), the deformed star at t_end (Figs. 10, 14, 18, 22) and the driving
//! forces with the rigid-body limit (Figs. 11, 15, 19, 23).

use std::path::Path;
use std::sync::Once;

use flexstar_kinematics::RigidState;
use flexstar_model::Response;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("figure {name}: {reason}")]
pub struct FigureError {
    pub name: String,
    pub reason: String,
}

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: Style,
}

/// Line style of a curve: colour index and dash.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    pub color: RGBColor,
    pub width: u32,
    pub dashed: bool,
}

/// One panel: title, axis labels, curves; `equal_axes` keeps the aspect ratio (star shapes).
#[derive(Debug, Clone)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub equal_axes: bool,
    /// Smallest y span shown, so that a response that is zero up to round-off (w_G in case 1)
    /// draws as a flat line instead of magnified noise.
    pub min_y_span: f64,
}

/// A figure: a title and one legend strip on top (outside every plot area, so that it never
/// covers data), panels side by side below; `caption` is the one or two sentences saying what to
/// look at, shown under the figure in the report and in `compare.md`.
#[derive(Debug, Clone)]
pub struct Figure {
    pub name: String,
    pub title: String,
    pub caption: String,
    pub panels: Vec<Panel>,
}

/// A [`Figure`] laid out with `columns` panels per row (further panels wrap onto new rows)
/// instead of all in one row.
#[derive(Debug, Clone)]
pub struct GridFigure {
    pub figure: Figure,
    pub columns: usize,
}

/// Something drawn on any plotters backend, written as SVG and PNG by [`svg_string`] and
/// [`write_svg_png`] (shared by every crate that draws: compare, study, modal).
pub trait Drawing {
    /// File stem of the drawing (`<name>.svg`, `<name>.png`).
    fn name(&self) -> &str;
    /// Size in pixels (width, height).
    fn size(&self) -> (u32, u32);
    /// Draw on `root` (already sized); errors as text.
    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// The drawing as an SVG document.
pub fn svg_string<D: Drawing>(d: &D) -> Result<String, FigureError> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, d.size()).into_drawing_area();
        d.draw_on(root).map_err(|reason| FigureError {
            name: d.name().to_string(),
            reason,
        })?;
    }
    Ok(svg)
}

/// Write `<dir>/<name>.svg` and `<dir>/<name>.png`, each whole or not at all.
pub fn write_svg_png<D: Drawing>(d: &D, dir: &Path) -> Result<(), FigureError> {
    register_font();
    let err = |reason: String| FigureError {
        name: d.name().to_string(),
        reason,
    };
    let svg = svg_string(d)?;
    flexstar_model::output::write_string_atomically(&dir.join(format!("{}.svg", d.name())), &svg)
        .map_err(|e| err(e.to_string()))?;
    // PNG: drawn into a temporary file beside the target, renamed when complete
    let png = dir.join(format!("{}.png", d.name()));
    let tmp = flexstar_model::output::temp_file_in(dir, ".png").map_err(|e| err(e.to_string()))?;
    {
        let root = BitMapBackend::new(tmp.path(), d.size()).into_drawing_area();
        d.draw_on(root).map_err(err)?;
    }
    tmp.persist(&png).map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// Viridis-like colour of `u` in [0, 1] (five anchors of matplotlib's viridis, linearly blended);
/// NaN maps to the dark end.
pub fn colormap(u: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let u = if u.is_finite() { u.clamp(0.0, 1.0) } else { 0.0 };
    let s = u * 4.0;
    let i = (s.floor() as usize).min(3);
    let f = s - i as f64;
    let (a, b) = (ANCHORS[i], ANCHORS[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Colours: FEM black, then one per AMM family, rigid grey.
pub const FEM_STYLE: Style = Style {
    color: RGBColor(0, 0, 0),
    width: 3,
    dashed: false,
};
pub const RIGID_STYLE: Style = Style {
    color: RGBColor(140, 140, 140),
    width: 1,
    dashed: true,
};
/// One colour per mode family, in the order of `ModeFamily::ALL` (pinned-free red, slide-free
/// blue, free-free green, clamped-free purple, enriched orange), so that a family has the same
/// colour in every figure and report.
pub const FAMILY_COLORS: [RGBColor; 5] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];
/// Colours for further runs of a family already drawn (e.g. the same family at another N).
pub const EXTRA_COLORS: [RGBColor; 3] = [RGBColor(140, 86, 75), RGBColor(227, 119, 194), RGBColor(23, 190, 207)];

static FONT: Once = Once::new();

/// Register the bundled DejaVu Sans (see assets/DejaVuSans-LICENSE.txt) as `sans-serif` so that
/// text renders without system fonts; idempotent. Other crates drawing with plotters call it first.
pub fn register_font() {
    FONT.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../assets/DejaVuSans.ttf"),
        );
    });
}

const PANEL_W: u32 = 520;
const PANEL_H: u32 = 400;
const CAPTION_H: u32 = 36;
const LEGEND_H: u32 = 28;

impl Figure {
    pub fn size(&self) -> (u32, u32) {
        grid_size(self.panels.len(), self.panels.len())
    }

    /// Legend entries: every labelled series once, in order of appearance.
    pub fn legend(&self) -> Vec<(String, Style)> {
        let mut v: Vec<(String, Style)> = Vec::new();
        for s in self.panels.iter().flat_map(|p| &p.series) {
            if !s.label.is_empty() && !v.iter().any(|(l, _)| *l == s.label) {
                v.push((s.label.clone(), s.style));
            }
        }
        v
    }

    /// The figure as an SVG document.
    pub fn to_svg_string(&self) -> Result<String, FigureError> {
        svg_string(self)
    }

    /// Write `<dir>/<name>.svg` and `<dir>/<name>.png`, each whole or not at all.
    pub fn write(&self, dir: &Path) -> Result<(), FigureError> {
        write_svg_png(self, dir)
    }

    /// Draw with `columns` panels per row.
    fn draw_grid<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>, columns: usize) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (top, rest) = root.split_vertically(CAPTION_H);
        top.titled(&self.title, ("sans-serif", 18)).map_err(|e| e.to_string())?;
        let (legend, body) = rest.split_vertically(LEGEND_H);
        draw_legend(&legend, &self.legend())?;
        let (cols, rows) = grid_shape(self.panels.len(), columns);
        let areas = body.split_evenly((rows, cols));
        for (panel, area) in self.panels.iter().zip(areas) {
            draw_panel(panel, &area)?;
        }
        root.present().map_err(|e| e.to_string())
    }
}

/// Columns and rows of `panels` panels at `columns` per row.
fn grid_shape(panels: usize, columns: usize) -> (usize, usize) {
    let n = panels.max(1);
    let cols = columns.clamp(1, n);
    (cols, n.div_ceil(cols))
}

/// Pixel size of a figure of `panels` panels at `columns` per row.
fn grid_size(panels: usize, columns: usize) -> (u32, u32) {
    let (cols, rows) = grid_shape(panels, columns);
    (PANEL_W * cols as u32, PANEL_H * rows as u32 + CAPTION_H + LEGEND_H)
}

impl Drawing for Figure {
    fn name(&self) -> &str {
        &self.name
    }

    fn size(&self) -> (u32, u32) {
        Figure::size(self)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        self.draw_grid(root, self.panels.len())
    }
}

impl Drawing for GridFigure {
    fn name(&self) -> &str {
        &self.figure.name
    }

    fn size(&self) -> (u32, u32) {
        grid_size(self.figure.panels.len(), self.columns)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        self.figure.draw_grid(root, self.columns)
    }
}

/// One row of legend entries, centred: a line sample in the run's style, then its label.
pub fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Style)],
) -> Result<(), String> {
    const SAMPLE: i32 = 28;
    const GAP: i32 = 8;
    const SPACING: i32 = 26;
    let font: TextStyle = ("sans-serif", 14).into_font().into();
    let widths: Vec<i32> = entries
        .iter()
        .map(|(l, _)| {
            area.estimate_text_size(l, &font)
                .map(|(w, _)| w as i32)
                .map_err(|e| e.to_string())
        })
        .collect::<Result<_, _>>()?;
    let total: i32 = widths.iter().map(|w| SAMPLE + GAP + w).sum::<i32>() + SPACING * (entries.len() as i32 - 1).max(0);
    let (w, h) = area.dim_in_pixel();
    let mut x = ((w as i32 - total) / 2).max(4);
    let y = h as i32 / 2;
    for ((label, style), tw) in entries.iter().zip(widths) {
        let shape = ShapeStyle {
            color: style.color.to_rgba(),
            filled: false,
            stroke_width: style.width.max(2),
        };
        if style.dashed {
            for k in 0..3 {
                let x0 = x + k * 10;
                area.draw(&PathElement::new(vec![(x0, y), (x0 + 6, y)], shape))
                    .map_err(|e| e.to_string())?;
            }
        } else {
            area.draw(&PathElement::new(vec![(x, y), (x + SAMPLE, y)], shape))
                .map_err(|e| e.to_string())?;
        }
        area.draw(&Text::new(
            label.clone(),
            (x + SAMPLE + GAP, y),
            font.pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(|e| e.to_string())?;
        x += SAMPLE + GAP + tw + SPACING;
    }
    Ok(())
}

fn bounds(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let mut x = (f64::INFINITY, f64::NEG_INFINITY);
    let mut y = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &panel.series {
        for (&a, &b) in s.x.iter().zip(&s.y) {
            if a.is_finite() && b.is_finite() {
                x = (x.0.min(a), x.1.max(a));
                y = (y.0.min(b), y.1.max(b));
            }
        }
    }
    if !x.0.is_finite() {
        return ((0.0, 1.0), (-1.0, 1.0));
    }
    let pad = |r: (f64, f64)| {
        let span = (r.1 - r.0).abs().max(1e-12 * (1.0 + r.0.abs()));
        (r.0 - 0.05 * span, r.1 + 0.05 * span)
    };
    if y.1 - y.0 < panel.min_y_span {
        let mid = 0.5 * (y.0 + y.1);
        y = (mid - 0.5 * panel.min_y_span, mid + 0.5 * panel.min_y_span);
    }
    let (mut x, mut y) = (pad(x), pad(y));
    if panel.equal_axes {
        let (w, h) = (x.1 - x.0, y.1 - y.0);
        let aspect = (PANEL_W as f64 - 80.0) / (PANEL_H as f64 - 80.0);
        if w / h < aspect {
            let extra = (h * aspect - w) / 2.0;
            x = (x.0 - extra, x.1 + extra);
        } else {
            let extra = (w / aspect - h) / 2.0;
            y = (y.0 - extra, y.1 + extra);
        }
    }
    (x, y)
}

/// Tick labels: plain decimals for moderate magnitudes, exponents otherwise.
pub fn tick(v: &f64) -> String {
    let a = v.abs();
    if a < 1e-10 {
        return "0".into();
    }
    if (1e-2..1e4).contains(&a) {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        format!("{v:.1e}")
    }
}

fn draw_panel<DB: DrawingBackend>(panel: &Panel, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
    let (xr, yr) = bounds(panel);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style(("sans-serif", 12))
        .y_label_formatter(&tick)
        .x_label_formatter(&tick)
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| e.to_string())?;
    for s in &panel.series {
        let color = s.style.color;
        let style = ShapeStyle {
            color: color.to_rgba(),
            filled: false,
            stroke_width: s.style.width,
        };
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .zip(&s.y)
                .map(|(a, b)| (*a, *b))
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .collect();
        // no legend inside the plot area: the figure's legend strip names every curve
        if s.style.dashed {
            chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, style))
                .map_err(|e| e.to_string())?;
        } else {
            chart
                .draw_series(LineSeries::new(pts, style))
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormap_ends_are_viridis_ends() {
        assert_eq!(colormap(0.0), RGBColor(68, 1, 84));
        assert_eq!(colormap(1.0), RGBColor(253, 231, 37));
        assert_eq!(colormap(f64::NAN), RGBColor(68, 1, 84));
    }
}
