//! One panel of curves: its axis ranges, tick labels and lines.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::figure::{Panel, PANEL_H, PANEL_W};

/// A series of two points at the same x is a vertical marker (`t_rest`): it spans the panel's y
/// range as drawn and takes no part in setting it.
pub(crate) fn is_marker(s: &crate::figure::Series) -> bool {
    s.x.len() == 2 && s.x[0] == s.x[1]
}

fn bounds(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let mut x = (f64::INFINITY, f64::NEG_INFINITY);
    let mut y = (f64::INFINITY, f64::NEG_INFINITY);
    for s in panel.series.iter().filter(|s| !is_marker(s)) {
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

/// The tick labels of an axis from `lo` to `hi`, all in one format (a mixture such as `-1.0e-2`
/// beside `-0.02` on one axis reads badly): plain decimals when the largest magnitude lies in
/// [1e-3, 1e4), exponents otherwise, with as many digits as a tenth of the span needs plus one
/// (ticks a twentieth of the span apart stay apart: 3.955 and 3.96 on a colour bar of
/// 3.93-3.965 Hz); `0` for values below a millionth of the magnitude (round-off).
pub fn axis_ticks(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let m = lo.abs().max(hi.abs());
    let plain = (1e-3..1e4).contains(&m);
    let span = (hi - lo).abs();
    let step = if span > 0.0 && span.is_finite() {
        span / 10.0
    } else {
        m.max(1e-300)
    };
    let decimals = ((1.0 - step.log10().floor()) as i32).clamp(0, 10) as usize;
    let mantissa = if m > 0.0 && m.is_finite() {
        ((m / step).log10().floor() as i32 + 1).clamp(1, 6) as usize
    } else {
        1
    };
    move |v: &f64| {
        if v.abs() <= 1e-6 * m || *v == 0.0 {
            return "0".into();
        }
        if plain {
            plain_decimal(*v, decimals)
        } else {
            format!("{v:.mantissa$e}")
        }
    }
}

/// Largest number of points a curve is drawn with per pixel column of its plot area: a longer
/// curve is thinned to its smallest and largest value in each column ([`min_max_thin`]).
const POINTS_PER_COLUMN: usize = 2;

/// `pts` (increasing x) thinned to at most two points per pixel column of a plot `columns` wide
/// over `x0..x1`: the smallest and the largest y of the column, in the order they occur, so that
/// every extreme of the curve is kept and a dense oscillation draws as its envelope instead of
/// the stair steps of thousands of one-pixel segments.
pub fn min_max_thin(pts: &[(f64, f64)], (x0, x1): (f64, f64), columns: usize) -> Vec<(f64, f64)> {
    if pts.len() <= POINTS_PER_COLUMN * columns.max(1) || x1.partial_cmp(&x0) != Some(std::cmp::Ordering::Greater) {
        return pts.to_vec();
    }
    let col = |x: f64| (((x - x0) / (x1 - x0)) * columns as f64).floor() as i64;
    let mut out = Vec::with_capacity(2 * columns + 2);
    let mut k = 0;
    while k < pts.len() {
        let c = col(pts[k].0);
        let (mut lo, mut hi) = (k, k);
        let mut j = k;
        while j < pts.len() && col(pts[j].0) == c {
            if pts[j].1 < pts[lo].1 {
                lo = j;
            }
            if pts[j].1 > pts[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let (a, b) = (lo.min(hi), lo.max(hi));
        out.push(pts[a]);
        if b != a {
            out.push(pts[b]);
        }
        k = j;
    }
    out
}

/// Tick labels: plain decimals for moderate magnitudes, exponents otherwise (one value alone;
/// an axis uses [`axis_ticks`], one format for all its labels).
pub fn tick(v: &f64) -> String {
    let a = v.abs();
    if a < 1e-10 {
        return "0".into();
    }
    if (1e-2..1e4).contains(&a) {
        plain_decimal(*v, 3)
    } else {
        format!("{v:.1e}")
    }
}

/// `v` with `decimals` decimals, trailing zeros (and a bare point) dropped, `-0` read as `0`.
fn plain_decimal(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
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
    let (x_ticks, y_ticks) = (axis_ticks(xr.0, xr.1), axis_ticks(yr.0, yr.1));
    let columns = chart.plotting_area().dim_in_pixel().0 as usize;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style(("sans-serif", 12))
        .y_label_formatter(&y_ticks)
        .x_label_formatter(&x_ticks)
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
        let pts: Vec<(f64, f64)> = if is_marker(s) {
            vec![(s.x[0], yr.0), (s.x[0], yr.1)]
        } else {
            let inside: Vec<(f64, f64)> =
                s.x.iter()
                    .zip(&s.y)
                    .map(|(a, b)| (*a, *b))
                    .filter(|(a, b)| a.is_finite() && b.is_finite() && *a >= xr.0 && *a <= xr.1)
                    .collect();
            min_max_thin(&inside, xr, columns)
        };
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_axis_has_one_tick_format() {
        // the frequency map's axis of G: -0.012 .. 0.012 m, ticks every 0.005
        let f = axis_ticks(-0.012, 0.012);
        let labels: Vec<String> = [-0.01, -0.005, 0.0, 0.005, 0.01].iter().map(&f).collect();
        assert_eq!(labels, ["-0.01", "-0.005", "0", "0.005", "0.01"]);
        // the single-value rule mixed them: -1.0e-2 beside -0.02
        assert_eq!(tick(&-0.01), "-0.01");
        assert_eq!(tick(&-0.005), "-5.0e-3");
        let f = axis_ticks(0.0, 2.4e-5);
        assert!([0.5e-5, 1e-5, 2e-5].iter().all(|v| f(v).contains("e-")), "{}", f(&1e-5));
        assert_eq!(axis_ticks(0.0, 1500.0)(&1200.0), "1200");
        assert_eq!(axis_ticks(-3.0, 3.0)(&1e-17), "0");
        // a narrow range far from zero (a colour bar of 3.93-3.965 Hz): every tick its own label
        let f = axis_ticks(3.93, 3.965);
        let labels: Vec<String> = (0..8).map(|k| f(&(3.93 + 0.005 * k as f64))).collect();
        assert_eq!(
            labels,
            ["3.93", "3.935", "3.94", "3.945", "3.95", "3.955", "3.96", "3.965"]
        );
        // steps of a quarter: 0.25 is not rounded to 0.3
        assert_eq!(axis_ticks(0.0, 1.2)(&0.25), "0.25");
        let f = axis_ticks(3.951e-5, 3.965e-5);
        assert_ne!(f(&3.955e-5), f(&3.96e-5));
    }

    #[test]
    fn thinning_keeps_every_columns_extremes() {
        // a 50 Hz sine sampled every 0.1 ms over 1 s (10001 points) into 400 columns
        let pts: Vec<(f64, f64)> = (0..=10_000)
            .map(|k| {
                let t = k as f64 * 1e-4;
                (t, (2.0 * std::f64::consts::PI * 50.0 * t).sin())
            })
            .collect();
        let thin = min_max_thin(&pts, (0.0, 1.0), 400);
        assert!(thin.len() <= 2 * 400 + 2, "{}", thin.len());
        for c in 0..400 {
            let (a, b) = (c as f64 / 400.0, (c + 1) as f64 / 400.0);
            let inside = |p: &&(f64, f64)| p.0 >= a && p.0 < b;
            let hi = pts.iter().filter(inside).map(|p| p.1).fold(f64::MIN, f64::max);
            let lo = pts.iter().filter(inside).map(|p| p.1).fold(f64::MAX, f64::min);
            let thi = thin.iter().filter(inside).map(|p| p.1).fold(f64::MIN, f64::max);
            let tlo = thin.iter().filter(inside).map(|p| p.1).fold(f64::MAX, f64::min);
            assert_eq!((thi, tlo), (hi, lo), "column {c}");
        }
        assert!(thin.windows(2).all(|w| w[0].0 <= w[1].0), "in order");
        // short curves are left alone
        assert_eq!(min_max_thin(&pts[..500], (0.0, 1.0), 400).len(), 500);
    }
}
