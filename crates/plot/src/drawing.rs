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
    // PNG: drawn into a pixel buffer, encoded into a temporary file beside the target, renamed
    // when complete
    let (w, h) = d.size();
    let mut pixels = vec![0u8; 3 * w as usize * h as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        d.draw_on(root).map_err(err)?;
    }
    let png = dir.join(format!("{}.png", d.name()));
    let mut tmp = flexstar_io::output::temp_file_in(dir, ".png").map_err(|e| err(e.to_string()))?;
    encode_png(tmp.as_file_mut(), (w, h), &pixels).map_err(|e| err(format!("PNG encoding: {e}")))?;
    tmp.persist(&png).map_err(|e| err(e.to_string()))?;
    Ok(svg)
}

/// 8-bit RGB pixels, row by row from the top left, as a PNG stream; the buffer is flushed here
/// so that a failed write is an error, not a truncated file.
fn encode_png<W: std::io::Write>(out: W, (w, h): (u32, u32), rgb: &[u8]) -> Result<(), png::EncodingError> {
    let mut buf = std::io::BufWriter::new(out);
    let mut enc = png::Encoder::new(&mut buf, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    std::io::Write::flush(&mut buf)?;
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A background of one colour with a rectangle of another in its top-left quarter.
    struct Blocks;

    impl Drawing for Blocks {
        fn name(&self) -> &str {
            "blocks"
        }
        fn size(&self) -> (u32, u32) {
            (40, 30)
        }
        fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
            root.fill(&RGBColor(10, 200, 30)).map_err(|e| e.to_string())?;
            root.draw(&Rectangle::new([(0, 0), (19, 14)], RGBColor(250, 5, 120).filled()))
                .map_err(|e| e.to_string())?;
            root.present().map_err(|e| e.to_string())
        }
    }

    #[test]
    fn the_png_file_holds_the_pixels_drawn() {
        let dir = tempfile::tempdir().unwrap();
        write_svg_png(&Blocks, dir.path()).unwrap();
        let file = std::fs::File::open(dir.path().join("blocks.png")).unwrap();
        let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (40, 30));
        assert_eq!(
            (info.color_type, info.bit_depth),
            (png::ColorType::Rgb, png::BitDepth::Eight)
        );
        let pixel = |x: usize, y: usize| &buf[3 * (y * 40 + x)..3 * (y * 40 + x) + 3];
        assert_eq!(pixel(3, 3), [250, 5, 120]);
        assert_eq!(pixel(17, 12), [250, 5, 120]);
        assert_eq!(pixel(21, 16), [10, 200, 30]);
        assert_eq!(pixel(39, 29), [10, 200, 30]);
        // nothing else beside the two files, no temporary left
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["blocks.png", "blocks.svg"]);
    }
}
