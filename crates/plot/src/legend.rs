//! The legend strip of a figure.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::style::Style;

const SAMPLE: i32 = 28;
const GAP: i32 = 8;
/// Space between two legend entries [px].
pub(crate) const SPACING: i32 = 26;
const FONT_SIZE: f64 = 14.0;

/// Width of one legend entry [px]: the line sample, the gap and the label in the bundled font.
pub(crate) fn entry_width(label: &str) -> i32 {
    crate::drawing::register_font();
    let text = ("sans-serif", FONT_SIZE)
        .into_font()
        .box_size(label)
        .map(|(w, _)| w as i32)
        // without the font: a generous 0.62 em per character
        .unwrap_or((0.62 * FONT_SIZE * label.chars().count() as f64) as i32);
    SAMPLE + GAP + text
}

/// One row of legend entries, centred: a line sample in the run's style, then its label.
pub fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Style)],
) -> Result<(), String> {
    let font: TextStyle = ("sans-serif", FONT_SIZE).into_font().into();
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
