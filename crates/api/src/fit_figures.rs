//! The figures of `flexstar fit` (`docs/measured.md` 4.9): per sensor column the recording with
//! the model before and after the fit, the model's errors before and after, and their spectra.

use flexstar_model::SensorTable;
use flexstar_plot::{Figure, Panel, Series, Style, FAMILY_COLORS, RIGID_STYLE};

use crate::fit::Fitted;

/// The recording: thin grey.
const MEASURED: Style = Style {
    color: RIGID_STYLE.color,
    width: 1,
    dashed: false,
};
/// The model at the start: thin blue (solid: a dashed curve of a thousand samples is drawn as
/// thousands of dashes, megabytes of SVG).
const BEFORE: Style = Style {
    color: FAMILY_COLORS[1],
    width: 1,
    dashed: false,
};
/// The model at the estimates: orange.
const AFTER: Style = Style {
    color: FAMILY_COLORS[4],
    width: 2,
    dashed: false,
};

/// The figures, in report order.
pub(crate) fn figures(f: &Fitted) -> Vec<Figure> {
    let n = &f.input.exp.name;
    vec![
        Figure {
            name: format!("{n}-fit-overlay"),
            title: format!("{n}: recording {} and the model before and after the fit", f.recording),
            caption: "Each sensor column: the recording (grey, with its noise), the model at the start (blue) and at \
                      the estimates (orange). After a good fit the orange curve runs through the middle of the grey band."
                .into(),
            panels: panels(f, &[("recording", MEASURED, None), ("before", BEFORE, Some(&f.fit.before)), ("after", AFTER, Some(&f.fit.after))]),
            zooms: Vec::new(),
        },
        Figure {
            name: format!("{n}-fit-errors"),
            title: format!("{n}: the model's error, model - recording"),
            caption: "Each sensor column: model - recording before (blue) and after (orange) the fit. After a good fit \
                      the error is the recording's noise, with no oscillation left in it (docs/measured.md 4.9)."
                .into(),
            panels: error_panels(f),
            zooms: Vec::new(),
        },
        Figure {
            name: format!("{n}-fit-spectra"),
            title: format!("{n}: spectra of the model's error (Welch), in dB re 1 unit^2/Hz"),
            caption: "Each sensor column: the power spectral density of model - recording before (blue) and after (orange) \
                      the fit (docs/measured.md section 2), and the level of white noise of the channel's noise level \
                      (grey, Eq. LS17). After a good fit the orange spectrum lies on the grey line, with no peak left at \
                      the robot's modes; the lower row is 0-50 Hz."
                .into(),
            panels: spectrum_panels(f),
            zooms: vec![flexstar_plot::Zoom {
                label: "0-50 Hz".into(),
                windows: vec![(0.0, 50.0)],
            }],
        },
    ]
}

/// One panel per channel: the Welch PSD of `model - recording` before and after [dB], and the
/// white-noise level of Eq. LS17 for the channel's noise level.
fn spectrum_panels(f: &Fitted) -> Vec<Panel> {
    let m = &f.measured;
    let Some(fs) = m.t.get(1).zip(m.t.first()).map(|(b, a)| 1.0 / (b - a)) else {
        return Vec::new();
    };
    let db = |p: f64| 10.0 * p.max(f64::MIN_POSITIVE).log10();
    let opts = flexstar_measured::welch::WelchOptions::default();
    m.columns
        .iter()
        .enumerate()
        .filter_map(|(k, c)| {
            let psd = |model: &SensorTable| {
                flexstar_measured::welch::welch(&error_of(model, &c.name, &c.values), fs, &opts, &c.name).ok()
            };
            let (before, after) = (psd(&f.fit.before)?, psd(&f.fit.after)?);
            let noise = f.fit.channels.iter().find(|ch| ch.column == c.name)?.noise;
            let level = db(flexstar_fit::noise::white_psd(noise, fs));
            let curve = |label: &str, style: Style, psd: &flexstar_measured::welch::Psd| Series {
                label: label.into(),
                x: psd.f.clone(),
                y: psd.p.iter().map(|p| db(*p)).collect(),
                style,
            };
            let unit = m.units.get(k).map_or("", String::as_str);
            let mut p = panel(
                &c.name,
                unit,
                vec![
                    curve("before", BEFORE, &before),
                    curve("after", AFTER, &after),
                    Series {
                        label: "noise level (Eq. LS17)".into(),
                        x: after.f.clone(),
                        y: vec![level; after.f.len()],
                        style: MEASURED,
                    },
                ],
            );
            p.x_label = "f [Hz]".into();
            p.y_label = format!("PSD [dB re 1 ({unit})^2/Hz]");
            Some(p)
        })
        .collect()
}

/// One panel per channel with the curves `(label, style, model)`: a model's channel, or the
/// recording for `None`.
fn panels(f: &Fitted, curves: &[(&str, Style, Option<&SensorTable>)]) -> Vec<Panel> {
    let m = &f.measured;
    m.columns
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let series = curves
                .iter()
                .map(|(label, style, table)| Series {
                    label: label.to_string(),
                    x: m.t.clone(),
                    y: match table {
                        Some(t) => t.column(&c.name).map(<[f64]>::to_vec).unwrap_or_default(),
                        None => c.values.clone(),
                    },
                    style: *style,
                })
                .collect();
            panel(&c.name, m.units.get(k).map_or("", String::as_str), series)
        })
        .collect()
}

/// One panel per channel: `model - recording` before and after.
fn error_panels(f: &Fitted) -> Vec<Panel> {
    let m = &f.measured;
    m.columns
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let curve = |label: &str, style: Style, model: &SensorTable| Series {
                label: label.into(),
                x: m.t.clone(),
                y: error_of(model, &c.name, &c.values),
                style,
            };
            panel(
                &c.name,
                m.units.get(k).map_or("", String::as_str),
                vec![
                    curve("before", BEFORE, &f.fit.before),
                    curve("after", AFTER, &f.fit.after),
                ],
            )
        })
        .collect()
}

/// `y - m` of channel `name` of the model's table.
fn error_of(model: &SensorTable, name: &str, measured: &[f64]) -> Vec<f64> {
    model
        .column(name)
        .map(|y| y.iter().zip(measured).map(|(y, m)| y - m).collect())
        .unwrap_or_default()
}

fn panel(title: &str, unit: &str, series: Vec<Series>) -> Panel {
    Panel {
        title: title.to_string(),
        x_label: "t [s]".into(),
        y_label: format!("{title} [{unit}]"),
        series,
        equal_axes: false,
        min_y_span: 1e-12,
    }
}
