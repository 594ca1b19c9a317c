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
