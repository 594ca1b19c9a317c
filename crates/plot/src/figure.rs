//! Figures of curves: [`Series`] in [`Panel`]s, laid out side by side ([`Figure`]) or in a grid
//! ([`GridFigure`]) below a title and one legend strip.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::drawing::{svg_string, write_svg_png, Drawing, FigureError};
use crate::legend::draw_legend;
use crate::panel::draw_panel;
use crate::style::Style;

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: Style,
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

/// A figure: a title and a legend strip on top (outside every plot area, so that it never covers
/// data; wrapped onto more rows when it is wider than the figure), panels side by side below, and
/// under them one row per zoom; `caption` is the one or two sentences saying what to look at,
/// shown under the figure in the report and in `compare.md`.
#[derive(Debug, Clone)]
pub struct Figure {
    pub name: String,
    pub title: String,
    pub caption: String,
    pub panels: Vec<Panel>,
    /// Windows of x (time) drawn again below the whole run, one row of panels each
    /// ([`Figure::drawn_panels`]): a short motion and the residual after it in a long run.
    pub zooms: Vec<Zoom>,
}

/// A window of a figure's x axis (time) drawn as a row of its own: every panel once more with
/// its curves cut to the window (and its y range from what lies inside), titled
/// `<panel title>: <label>, <t0>-<t1> s`. `windows` holds one `(t0, t1)` for every panel, or one
/// for all.
#[derive(Debug, Clone, PartialEq)]
pub struct Zoom {
    pub label: String,
    pub windows: Vec<(f64, f64)>,
}

impl Zoom {
    /// The window of panel `k`.
    pub fn window(&self, k: usize) -> (f64, f64) {
        match self.windows.get(k).or_else(|| self.windows.first()) {
            Some(w) => *w,
            None => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
}

impl Panel {
    /// This panel with its curves cut to `t0 <= x <= t1` and `label, t0-t1 s` after its title; a
    /// vertical marker ([`crate::panel::is_marker`]) inside the window is kept, one outside it
    /// dropped.
    pub fn zoomed(&self, label: &str, (t0, t1): (f64, f64)) -> Panel {
        let inside = |x: f64| x >= t0 && x <= t1;
        let series = self
            .series
            .iter()
            .filter(|s| !crate::panel::is_marker(s) || inside(s.x[0]))
            .map(|s| {
                let keep: Vec<usize> = (0..s.x.len().min(s.y.len())).filter(|&k| inside(s.x[k])).collect();
                Series {
                    x: keep.iter().map(|&k| s.x[k]).collect(),
                    y: keep.iter().map(|&k| s.y[k]).collect(),
                    ..s.clone()
                }
            })
            .collect();
        let secs = |t: f64| flexstar_io::output::fmt_sig(t, 4);
        Panel {
            title: format!("{}: {label}, {}-{} s", self.title, secs(t0), secs(t1)),
            series,
            ..self.clone()
        }
    }
}

/// A [`Figure`] laid out with `columns` panels per row (further panels wrap onto new rows)
/// instead of all in one row.
#[derive(Debug, Clone)]
pub struct GridFigure {
    pub figure: Figure,
    pub columns: usize,
}

/// A figure drawn once: its name, title and caption with the SVG document, written to disk and
/// embedded in reports from the same string.
#[derive(Debug, Clone)]
pub struct RenderedFigure {
    pub name: String,
    pub title: String,
    pub caption: String,
    /// The whole SVG document (with its XML declaration).
    pub svg: String,
}

impl RenderedFigure {
    /// The SVG element alone (the XML declaration dropped), for inlining into HTML.
    pub fn svg_element(&self) -> &str {
        match self.svg.find("<svg") {
            Some(i) => &self.svg[i..],
            None => &self.svg,
        }
    }
}

pub(crate) const PANEL_W: u32 = 520;
pub(crate) const PANEL_H: u32 = 400;
const CAPTION_H: u32 = 36;
const LEGEND_H: u32 = 28;

impl Figure {
    pub fn size(&self) -> (u32, u32) {
        self.grid_size(self.panels.len())
    }

    /// Every panel as drawn, row by row: the panels, then each zoom's row of the same panels cut
    /// to its window.
    pub fn drawn_panels(&self) -> Vec<Panel> {
        let mut all = self.panels.clone();
        for z in &self.zooms {
            all.extend(
                self.panels
                    .iter()
                    .enumerate()
                    .map(|(k, p)| p.zoomed(&z.label, z.window(k))),
            );
        }
        all
    }

    /// Columns per row: with zooms, each zoom is a row of the panels, so `panels.len()`.
    fn columns_for(&self, columns: usize) -> usize {
        if self.zooms.is_empty() {
            columns
        } else {
            self.panels.len()
        }
    }

    /// Pixel size with `columns` panels per row and the legend wrapped to the width.
    fn grid_size(&self, columns: usize) -> (u32, u32) {
        let columns = self.columns_for(columns);
        let (cols, rows) = grid_shape(self.drawn_panels().len(), columns);
        let width = PANEL_W * cols as u32;
        let legend_rows = legend_rows(&self.legend(), width).len().max(1) as u32;
        (width, PANEL_H * rows as u32 + CAPTION_H + LEGEND_H * legend_rows)
    }

    /// The legend entries laid out in rows that fit a figure `width` pixels wide.
    pub fn legend_layout(&self) -> Vec<Vec<(String, Style)>> {
        legend_rows(&self.legend(), self.size().0)
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

    /// Write `<dir>/<name>.svg` and `<dir>/<name>.png`, each whole or not at all; returns the
    /// figure with the SVG document written, for a report to embed without drawing it again.
    pub fn write(&self, dir: &Path) -> Result<RenderedFigure, FigureError> {
        let svg = write_svg_png(self, dir)?;
        Ok(self.rendered(svg))
    }

    /// The figure drawn as SVG only (no files).
    pub fn render(&self) -> Result<RenderedFigure, FigureError> {
        let svg = svg_string(self)?;
        Ok(self.rendered(svg))
    }

    fn rendered(&self, svg: String) -> RenderedFigure {
        RenderedFigure {
            name: self.name.clone(),
            title: self.title.clone(),
            caption: self.caption.clone(),
            svg,
        }
    }

    /// Draw with `columns` panels per row.
    fn draw_grid<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>, columns: usize) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (top, mut rest) = root.split_vertically(CAPTION_H);
        top.titled(&self.title, ("sans-serif", 18)).map_err(|e| e.to_string())?;
        let width = root.dim_in_pixel().0;
        for row in legend_rows(&self.legend(), width) {
            let (legend, body) = rest.split_vertically(LEGEND_H);
            draw_legend(&legend, &row)?;
            rest = body;
        }
        let panels = self.drawn_panels();
        let (cols, rows) = grid_shape(panels.len(), self.columns_for(columns));
        let areas = rest.split_evenly((rows, cols));
        for (panel, area) in panels.iter().zip(areas) {
            draw_panel(panel, &area)?;
        }
        root.present().map_err(|e| e.to_string())
    }
}

/// The legend entries packed greedily into rows no wider than `width` pixels (an entry wider
/// than the figure gets a row of its own); at least one row, empty for no entries.
pub fn legend_rows(entries: &[(String, Style)], width: u32) -> Vec<Vec<(String, Style)>> {
    let mut rows: Vec<Vec<(String, Style)>> = vec![Vec::new()];
    let mut used = 0i32;
    for e in entries {
        let w = crate::legend::entry_width(&e.0);
        let last = rows.last_mut().expect("one row at least");
        let need = if last.is_empty() {
            w
        } else {
            used + crate::legend::SPACING + w
        };
        if last.is_empty() || need <= width as i32 - 8 {
            last.push(e.clone());
            used = need;
        } else {
            rows.push(vec![e.clone()]);
            used = w;
        }
    }
    rows
}

/// Columns and rows of `panels` panels at `columns` per row.
fn grid_shape(panels: usize, columns: usize) -> (usize, usize) {
    let n = panels.max(1);
    let cols = columns.clamp(1, n);
    (cols, n.div_ceil(cols))
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
        self.figure.grid_size(self.columns)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        self.figure.draw_grid(root, self.columns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::style::{FEM_STYLE, MARK_STYLE};

    fn series(label: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series {
            label: label.into(),
            x,
            y,
            style: FEM_STYLE,
        }
    }

    fn panel(series: Vec<Series>) -> Panel {
        Panel {
            title: "tip A".into(),
            x_label: "t [s]".into(),
            y_label: "w [mm]".into(),
            series,
            equal_axes: false,
            min_y_span: 0.0,
        }
    }

    #[test]
    fn a_wide_legend_wraps_and_keeps_every_entry() {
        // the plan's forces figure: one panel, six runs and a limit
        let labels = [
            "plain, AMM",
            "plain, FEM",
            "zvd, AMM",
            "zvd, FEM",
            "planned, AMM",
            "planned, FEM",
            "Fa_max",
        ];
        let fig = Figure {
            name: "f".into(),
            title: "forces".into(),
            caption: String::new(),
            panels: vec![panel(
                labels
                    .iter()
                    .map(|l| series(l, vec![0.0, 1.0], vec![0.0, 1.0]))
                    .collect(),
            )],
            zooms: Vec::new(),
        };
        let rows = fig.legend_layout();
        assert!(rows.len() >= 2, "one row of {} px cannot hold them", fig.size().0);
        let flat: Vec<&str> = rows.iter().flatten().map(|(l, _)| l.as_str()).collect();
        assert_eq!(flat, labels);
        for row in &rows {
            let w: i32 = row.iter().map(|(l, _)| crate::legend::entry_width(l)).sum::<i32>()
                + crate::legend::SPACING * (row.len() as i32 - 1);
            assert!(w <= fig.size().0 as i32, "{w} px in a {} px figure", fig.size().0);
        }
        // the figure grows by a legend strip per row
        assert_eq!(fig.size().1, PANEL_H + CAPTION_H + LEGEND_H * rows.len() as u32);
    }

    #[test]
    fn a_zoom_row_cuts_every_curve_to_its_window() {
        let t: Vec<f64> = (0..=600).map(|k| k as f64 * 1e-2).collect();
        let mark = Series {
            label: "t_rest".into(),
            x: vec![0.3, 0.3],
            y: vec![-1.0, 1.0],
            style: MARK_STYLE,
        };
        let fig = Figure {
            name: "w".into(),
            title: "w".into(),
            caption: String::new(),
            panels: vec![panel(vec![
                series("FEM", t.clone(), t.iter().map(|x| x.sin()).collect()),
                mark,
            ])],
            zooms: vec![
                Zoom {
                    label: "the motion".into(),
                    windows: vec![(0.0, 0.3)],
                },
                Zoom {
                    label: "after it".into(),
                    windows: vec![(0.3, 0.75)],
                },
            ],
        };
        let drawn = fig.drawn_panels();
        assert_eq!(drawn.len(), 3);
        let range = |p: &Panel| {
            let x = &p.series[0].x;
            (x[0], *x.last().unwrap())
        };
        assert_eq!(range(&drawn[0]), (0.0, 6.0));
        assert_eq!(range(&drawn[1]), (0.0, 0.3));
        assert_eq!(range(&drawn[2]), (0.3, 0.75));
        assert_eq!(drawn[2].title, "tip A: after it, 0.3-0.75 s");
        // the t_rest marker stays in both windows that hold it
        assert!(drawn[1..].iter().all(|p| p.series.len() == 2));
        // rows of one panel each: 1 column, 3 rows
        assert_eq!(fig.size(), (PANEL_W, 3 * PANEL_H + CAPTION_H + LEGEND_H));
    }
}
