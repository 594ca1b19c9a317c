//! The study's plots (plotters, SVG): a metric against a varied key, a heat map of a metric
//! over two gridded keys, and the histogram of a metric over a sampled study's runs.

use flexstar_plot::axis_ticks;
use plotters::prelude::*;

use crate::error::StudyError;

/// Colours of the solvers' points: AMM red, FEM black (as in the paper's figures).
pub fn solver_color(solver: &str) -> RGBColor {
    match solver {
        "fem" => RGBColor(0, 0, 0),
        _ => RGBColor(214, 39, 40),
    }
}

/// Points of one solver.
#[derive(Debug, Clone)]
pub struct PointSet {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
}

/// A metric against a key; `connect` draws lines through the points sorted by x (a one-key grid).
#[derive(Debug, Clone)]
pub struct Scatter {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub sets: Vec<PointSet>,
    pub connect: bool,
}

/// A metric over a grid of two keys: `values[iy][ix]` at `x_levels[ix]`, `y_levels[iy]`.
#[derive(Debug, Clone)]
pub struct Heat {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_levels: Vec<String>,
    pub y_levels: Vec<String>,
    pub values: Vec<Vec<Option<f64>>>,
}

/// The distribution of one metric over a sampled study's runs: `bins` equal bins from the
/// smallest to the largest value, one bar series per solver (bars side by side in each bin).
#[derive(Debug, Clone)]
pub struct Histogram {
    pub title: String,
    pub x_label: String,
    /// Per solver: its name, colour and values.
    pub sets: Vec<(String, RGBColor, Vec<f64>)>,
    pub bins: usize,
}

impl Histogram {
    /// The counts of `values` in the bins of `[lo, hi]` (the largest value in the last bin).
    pub fn counts(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<usize> {
        let mut c = vec![0; bins];
        let width = (hi - lo) / bins as f64;
        for v in values {
            let k = if width > 0.0 { ((v - lo) / width) as usize } else { 0 };
            c[k.min(bins - 1)] += 1;
        }
        c
    }

    /// The histogram as an SVG document.
    pub fn to_svg(&self) -> Result<String, StudyError> {
        flexstar_plot::register_font();
        let e = err(&self.title);
        let all = self.sets.iter().flat_map(|s| s.2.iter().copied());
        let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        let (lo, hi) = if lo.is_finite() {
            (lo, hi.max(lo + 1e-12 * (1.0 + lo.abs())))
        } else {
            (0.0, 1.0)
        };
        let counts: Vec<Vec<usize>> = self
            .sets
            .iter()
            .map(|s| Self::counts(&s.2, lo, hi, self.bins))
            .collect();
        let top = counts.iter().flatten().copied().max().unwrap_or(1).max(1);
        let width = (hi - lo) / self.bins as f64;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
            root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
            let mut chart = cartesian(&root, &self.title, 50, lo..hi, 0.0..top as f64 * 1.1).map_err(&e)?;
            chart
                .configure_mesh()
                .x_desc(self.x_label.as_str())
                .y_desc("runs")
                .label_style(("sans-serif", 12))
                .x_label_formatter(&axis_ticks(lo, hi))
                .y_label_formatter(&|v: &f64| format!("{v:.0}"))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(|x| e(x.to_string()))?;
            let n = self.sets.len().max(1) as f64;
            for (j, ((label, color, _), c)) in self.sets.iter().zip(&counts).enumerate() {
                let color = *color;
                let bars = c.iter().enumerate().map(|(k, &count)| {
                    let x0 = lo + width * (k as f64 + j as f64 / n);
                    Rectangle::new([(x0, 0.0), (x0 + width / n, count as f64)], color.mix(0.7).filled())
                });
                chart
                    .draw_series(bars)
                    .map_err(|x| e(x.to_string()))?
                    .label(label.as_str())
                    .legend(move |(x, y)| Rectangle::new([(x + 2, y - 4), (x + 12, y + 4)], color.filled()));
            }
            legend(&mut chart).map_err(&e)?;
            root.present().map_err(|x| e(x.to_string()))?;
        }
        Ok(svg)
    }
}

/// A titled chart of the ranges `x` by `y` on `root`, with `y_area` pixels for the y labels.
fn cartesian<'a, DB: DrawingBackend + 'a>(
    root: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    y_area: u32,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<
    ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>>,
    String,
> {
    ChartBuilder::on(root)
        .caption(title, ("sans-serif", 15))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x, y)
        .map_err(|x| x.to_string())
}

/// The legend of a chart's labelled series, upper right, on a white box.
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(180, 180, 180))
        .label_font(("sans-serif", 12))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|x| x.to_string())
}

const W: u32 = 560;
const H: u32 = 420;

fn err(name: &str) -> impl Fn(String) -> StudyError + '_ {
    move |reason| StudyError::Plot {
        name: name.to_string(),
        reason,
    }
}

/// Tick labels: plain decimals for moderate magnitudes, exponents otherwise.
pub fn tick(v: &f64) -> String {
    let a = v.abs();
    if a < 1e-14 {
        "0".into()
    } else if (1e-2..1e4).contains(&a) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let span = (hi - lo).abs().max(1e-12 * (1.0 + lo.abs().max(hi.abs())));
    (lo - 0.06 * span, hi + 0.06 * span)
}

impl Scatter {
    /// The plot as an SVG document.
    pub fn to_svg(&self) -> Result<String, StudyError> {
        flexstar_plot::register_font();
        let e = err(&self.title);
        let all = self.sets.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for &(x, y) in all {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !x0.is_finite() {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        let (xr, yr) = (padded(x0, x1), padded(y0, y1));
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
            root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
            let mut chart = cartesian(&root, &self.title, 70, xr.0..xr.1, yr.0..yr.1).map_err(&e)?;
            chart
                .configure_mesh()
                .x_desc(self.x_label.as_str())
                .y_desc(self.y_label.as_str())
                .label_style(("sans-serif", 12))
                .x_label_formatter(&axis_ticks(xr.0, xr.1))
                .y_label_formatter(&axis_ticks(yr.0, yr.1))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(|x| e(x.to_string()))?;
            for set in &self.sets {
                let color = set.color;
                if self.connect {
                    let mut pts = set.points.clone();
                    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(1)))
                        .map_err(|x| e(x.to_string()))?;
                }
                chart
                    .draw_series(set.points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                    .map_err(|x| e(x.to_string()))?
                    .label(set.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
            }
            legend(&mut chart).map_err(&e)?;
            root.present().map_err(|x| e(x.to_string()))?;
        }
        Ok(svg)
    }
}

pub use flexstar_plot::colormap;

impl Heat {
    /// Each cell's value as text at its centre, white on the dark end of the colour map.
    fn cell_labels(&self, lo: f64, span: f64) -> Vec<Text<'static, (f64, f64), String>> {
        let mut out = Vec::new();
        for (iy, row) in self.values.iter().enumerate() {
            for (ix, v) in row.iter().enumerate() {
                if let Some(v) = *v {
                    let dark = (v - lo) / span < 0.6;
                    let style = TextStyle::from(("sans-serif", 10).into_font())
                        .color(if dark { &WHITE } else { &BLACK })
                        .pos(plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Center,
                            plotters::style::text_anchor::VPos::Center,
                        ));
                    out.push(Text::new(tick(&v), (ix as f64 + 0.5, iy as f64 + 0.5), style));
                }
            }
        }
        out
    }

    /// The heat map as an SVG document; cells without a value are grey, and each cell is labelled
    /// with its value when the grid has at most 12 x 12 cells.
    pub fn to_svg(&self) -> Result<String, StudyError> {
        flexstar_plot::register_font();
        let e = err(&self.title);
        let (nx, ny) = (self.x_levels.len(), self.y_levels.len());
        let finite = self
            .values
            .iter()
            .flatten()
            .flatten()
            .copied()
            .filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        let span = if hi > lo { hi - lo } else { 1.0 };
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
            root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
            let title = if lo.is_finite() {
                format!("{} (dark {} .. light {})", self.title, tick(&lo), tick(&hi))
            } else {
                self.title.clone()
            };
            let xl = self.x_levels.clone();
            let yl = self.y_levels.clone();
            let label = |levels: &Vec<String>, v: &f64| {
                let i = v.floor();
                if (v - i - 0.5).abs() < 1e-6 && i >= 0.0 {
                    levels.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            };
            let x_fmt = |v: &f64| label(&xl, v);
            let y_fmt = |v: &f64| label(&yl, v);
            let mut chart = ChartBuilder::on(&root)
                .caption(title, ("sans-serif", 14))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..nx as f64, 0.0..ny as f64)
                .map_err(|x| e(x.to_string()))?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(self.x_label.as_str())
                .y_desc(self.y_label.as_str())
                .x_labels(2 * nx + 1)
                .y_labels(2 * ny + 1)
                .label_style(("sans-serif", 11))
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt)
                .draw()
                .map_err(|x| e(x.to_string()))?;
            let cells = (0..ny).flat_map(|iy| (0..nx).map(move |ix| (ix, iy)));
            chart
                .draw_series(cells.map(|(ix, iy)| {
                    let color = match self.values[iy][ix] {
                        Some(v) if v.is_finite() => colormap((v - lo) / span),
                        _ => RGBColor(200, 200, 200),
                    };
                    Rectangle::new(
                        [(ix as f64, iy as f64), (ix as f64 + 1.0, iy as f64 + 1.0)],
                        color.filled(),
                    )
                }))
                .map_err(|x| e(x.to_string()))?;
            if nx <= 12 && ny <= 12 {
                for label in self.cell_labels(lo, span) {
                    chart
                        .draw_series(std::iter::once(label))
                        .map_err(|x| e(x.to_string()))?;
                }
            }
            root.present().map_err(|x| e(x.to_string()))?;
        }
        Ok(svg)
    }
}
