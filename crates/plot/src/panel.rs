//! One panel of curves: its axis ranges, tick labels and lines.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::figure::{Panel, PANEL_H, PANEL_W};

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

pub(crate) fn draw_panel<DB: DrawingBackend>(panel: &Panel, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
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
