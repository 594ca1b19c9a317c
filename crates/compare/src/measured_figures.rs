//! The figures of `compare --measured` (`docs/measured.md` sections 1, 2): per recorded sensor
//! column `<case>-measured-<channel>`, the time histories of the recording and of every run, and
//! their Welch spectra on a log scale with the natural frequencies at the final pose marked.

use flexstar_measured::welch::Psd;
use flexstar_plot::{Figure, Panel, Series, Style, MARK_STYLE, RIGID_STYLE};

use crate::figures::Run;
use crate::measured::{run_channel, ChannelSpectra, MeasuredOverlay};

/// The recording's curve: the rigid curves' grey, solid and wider, under the runs' curves.
pub const MEASURED_STYLE: Style = Style {
    color: RIGID_STYLE.color,
    width: 2,
    dashed: false,
};

/// One figure per recorded channel: its time histories and its spectra (`runs`: the FEM first,
/// then the AMM runs, as the other figures draw them); `t_rest` [s] marked on the time panel.
pub fn measured_figures(case: &str, overlay: &MeasuredOverlay, runs: &[Run], t_rest: Option<f64>) -> Vec<Figure> {
    overlay
        .laid
        .columns
        .iter()
        .zip(&overlay.laid.units)
        .zip(&overlay.spectra)
        .map(|((c, unit), spectra)| {
            let mut time = time_panel(overlay, runs, &c.name, unit);
            if let Some(t) = t_rest {
                push_marker(&mut time, t, "t_rest");
            }
            let mut panels = vec![time];
            panels.extend(spectrum_panel(overlay, runs, spectra));
            Figure {
                name: format!("{case}-measured-{}", c.name),
                title: format!("{case}: {} measured against the runs", c.name),
                caption: caption(overlay, &c.name),
                panels,
                zooms: Vec::new(),
            }
        })
        .collect()
}

/// What the figure of `channel` shows.
fn caption(overlay: &MeasuredOverlay, channel: &str) -> String {
    let modes = if overlay.modes.hz.is_empty() {
        String::new()
    } else {
        format!(
            "; dashed: the accurate AMM's natural frequencies at the pose of t = {} s, sliders locked",
            flexstar_io::output::fmt_sig(overlay.modes.at_s, 6)
        )
    };
    format!(
        "Left: {channel} as recorded (grey; mapped, scaled and shifted onto the runs' clock, docs/measured.md \
         section 1) and as every run reads it; compare.md lists each run's EVP and RMS against the recording \
         (Eqs. M5, M6). Right: the Welch power spectral densities (Hann window, half overlap, one-sided, Eq. W3) \
         as log10 of the density{modes}."
    )
}

/// The recording and every run's channel against time.
fn time_panel(overlay: &MeasuredOverlay, runs: &[Run], channel: &str, unit: &str) -> Panel {
    let mut series = vec![Series {
        label: "measured".into(),
        x: overlay.laid.t.clone(),
        y: overlay.laid.column(channel).unwrap_or_default().to_vec(),
        style: MEASURED_STYLE,
    }];
    for r in runs {
        if let Some(y) = run_channel(r.response, channel, &overlay.rows) {
            series.push(Series {
                label: r.label.clone(),
                x: overlay.laid.t.clone(),
                y: y.to_vec(),
                style: r.style,
            });
        }
    }
    Panel {
        title: channel.to_string(),
        x_label: "t [s]".into(),
        y_label: format!("{channel} [{unit}]"),
        series,
        equal_axes: false,
        min_y_span: 0.0,
    }
}

/// The spectra of the recording and of every run as `log10` of the density, the modes marked;
/// none when the channel has no spectrum.
fn spectrum_panel(overlay: &MeasuredOverlay, runs: &[Run], spectra: &ChannelSpectra) -> Option<Panel> {
    let (first, rest) = spectra.psd.split_first()?;
    let nyquist = first.1.f.last().copied().unwrap_or(0.0);
    let f_top = shown_band(&overlay.modes.hz, nyquist);
    // the band shown, densities in log10
    let shown = |psd: &Psd, style| {
        let n = psd.f.partition_point(|f| *f <= f_top);
        Series {
            label: String::new(),
            x: psd.f[..n].to_vec(),
            y: psd.p[..n]
                .iter()
                .map(|v| if *v > 0.0 { v.log10() } else { f64::NAN })
                .collect(),
            style,
        }
    };
    let mut series = vec![shown(&first.1, MEASURED_STYLE)];
    // the runs' spectra follow runs_of's order, the runs' styles that of the figures
    for ((_, psd), run) in rest.iter().zip(runs) {
        series.push(shown(psd, run.style));
    }
    let mut panel = Panel {
        title: format!("{}: PSD", spectra.channel),
        x_label: "f [Hz]".into(),
        y_label: format!("log10 PSD [({})^2/Hz]", spectra.unit),
        series,
        equal_axes: false,
        min_y_span: 0.0,
    };
    for (k, f) in overlay.modes.hz.iter().filter(|f| **f <= f_top).enumerate() {
        let label = if k == 0 {
            "natural frequencies (AMM, final pose)"
        } else {
            ""
        };
        push_marker(&mut panel, *f, label);
    }
    Some(panel)
}

/// The top of the spectra's band [Hz]: three times the highest marked natural frequency, where
/// the modes' content is (above it the densities are the noise floor), at most the Nyquist
/// frequency; all of it without marked frequencies.
fn shown_band(marked_hz: &[f64], nyquist: f64) -> f64 {
    match marked_hz
        .iter()
        .copied()
        .fold(None, |m: Option<f64>, f| Some(m.map_or(f, |m| m.max(f))))
    {
        Some(f) if f > 0.0 => (3.0 * f).min(nyquist),
        _ => nyquist,
    }
}

/// A vertical dashed marker at `x` over the panel's y range.
fn push_marker(panel: &mut Panel, x: f64, label: &str) {
    let (lo, hi) = panel
        .series
        .iter()
        .flat_map(|s| s.y.iter().copied())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if lo.is_finite() {
        panel.series.push(Series {
            label: label.to_string(),
            x: vec![x, x],
            y: vec![lo, hi],
            style: MARK_STYLE,
        });
    }
}
