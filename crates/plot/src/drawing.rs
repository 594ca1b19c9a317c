//! Drawing onto files: the [`Drawing`] trait every figure implements, its SVG document, the SVG
//! and PNG files, and the bundled font.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

/// A figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("figure {name}: {reason}")]
pub struct FigureError {
    pub name: String,
    pub reason: String,
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

/// Write `<dir>/<name>.svg` and `<dir>/<name>.png`, each whole or not at all; returns the SVG
/// document written (drawn once, so that a report can embed the same string).
pub fn write_svg_png<D: Drawing>(d: &D, dir: &Path) -> Result<String, FigureError> {
    register_font();
    let err = |reason: String| FigureError {
        name: d.name().to_string(),
        reason,
    };
    let svg = svg_string(d)?;
    flexstar_io::output::write_string_atomically(&dir.join(format!("{}.svg", d.name())), &svg)
        .map_err(|e| err(e.to_string()))?;
    // PNG: drawn into a temporary file beside the target, renamed when complete
    let png = dir.join(format!("{}.png", d.name()));
    let tmp = flexstar_io::output::temp_file_in(dir, ".png").map_err(|e| err(e.to_string()))?;
    {
        let root = BitMapBackend::new(tmp.path(), d.size()).into_drawing_area();
        d.draw_on(root).map_err(err)?;
    }
    tmp.persist(&png).map_err(|e| err(e.to_string()))?;
    Ok(svg)
}

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
