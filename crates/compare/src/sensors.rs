//! The sensors in `compare` (`docs/sensors.md` section 7): one overlay figure per sensor (the
//! FEM's and every AMM run's channels against time) and the EVP of each channel (Eq. S14, the
//! paper's Eq. 45 with the FEM's channel as the reference). Nothing without `[[sensors]]`.

use std::fmt::Write as _;

use flexstar_model::{Experiment, SensorTable};
use flexstar_numerics::measures::evp;
use flexstar_plot::{Figure, Panel, Series};
use serde::Serialize;

use crate::figures::Run;
use crate::runs::CaseResults;

/// The EVP of one sensor channel of one AMM run against the FEM's (Eq. S14).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelEvp {
    /// The AMM run's file stem (`amm-<label>`).
    pub run: String,
    /// The channel (a column of `<stem>-sensors.csv`).
    pub channel: String,
    /// Its unit (`m/s^2`, `m/m`, `m`, `N`).
    pub unit: String,
    /// `int |AMM - FEM| dt / int |FEM| dt * 100` [%] on the sensors' sample times; `None` where
    /// the FEM's channel is zero throughout or the two runs do not share one clock.
    pub evp: Option<f64>,
}

/// The EVP of every channel of every AMM run of `case` (Eq. S14), in the order of the runs and
/// of the FEM's channels; empty without sensors.
pub fn sensor_evps(case: &CaseResults) -> Vec<ChannelEvp> {
    let Some(fem) = &case.fem.sensors else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (run, r) in &case.amm {
        let amm = r.sensors.as_ref();
        for (col, unit) in fem.columns.iter().zip(&fem.units) {
            out.push(ChannelEvp {
                run: run.file_stem(),
                channel: col.name.clone(),
                unit: unit.clone(),
                evp: amm.and_then(|a| channel_evp(a, fem, &col.name)),
            });
        }
    }
    out
}

/// Eq. S14 of channel `name`: the AMM's table `amm` against the FEM's `fem`, on one clock.
fn channel_evp(amm: &SensorTable, fem: &SensorTable, name: &str) -> Option<f64> {
    if amm.t != fem.t {
        return None;
    }
    evp(&fem.t, amm.column(name)?, fem.column(name)?)
}

/// The section of `compare.md` listing [`sensor_evps`]: one line per AMM run and channel; empty
/// text without sensors.
pub fn sensors_markdown(evps: &[ChannelEvp]) -> String {
    if evps.is_empty() {
        return String::new();
    }
    let mut s = String::from("## Sensors: EVP (Eq. 45) per channel, % of the FEM's channel\n\n");
    s.push_str(
        "`EVP = int |y_AMM - y_FEM| dt / int |y_FEM| dt x 100` on the sensors' sample times \
         (docs/sensors.md Eq. S14); n/a: the FEM's channel is zero throughout.\n\n",
    );
    s.push_str("| run | channel | unit | EVP [%] |\n|---|---|---|---|\n");
    for e in evps {
        let v = e.evp.map_or_else(|| "n/a".to_string(), |v| format!("{v:.4}"));
        let _ = writeln!(s, "| {} | {} | {} | {v} |", e.run, e.channel, e.unit);
    }
    s
}

/// One figure per sensor of `exp` (`<case>-sensor-<name>`): a panel per channel, every run of
/// `runs` that has sensors overlaid against the sensors' time. Empty without sensors.
pub fn sensor_figures(exp: &Experiment, runs: &[Run]) -> Vec<Figure> {
    let Some(first) = runs.iter().find_map(|r| r.response.sensors.as_ref()) else {
        return Vec::new();
    };
    exp.sensors
        .iter()
        .map(|spec| sensor_figure(&exp.name, &spec.name, first, runs))
        .filter(|f| !f.panels.is_empty())
        .collect()
}

/// The channels of sensor `name` in `table`: `<name>` or `<name>_x`, `<name>_y`.
fn channels_of<'t>(table: &'t SensorTable, name: &str) -> Vec<(&'t str, &'t str)> {
    let own = |c: &str| c == name || c.strip_prefix(name).is_some_and(|r| r == "_x" || r == "_y");
    table
        .columns
        .iter()
        .zip(&table.units)
        .filter(|(c, _)| own(&c.name))
        .map(|(c, u)| (c.name.as_str(), u.as_str()))
        .collect()
}

/// The figure of sensor `name` (its channels as listed in `table`).
fn sensor_figure(case: &str, name: &str, table: &SensorTable, runs: &[Run]) -> Figure {
    let panels = channels_of(table, name)
        .into_iter()
        .map(|(channel, unit)| Panel {
            title: channel.to_string(),
            x_label: "t [s]".into(),
            y_label: format!("{channel} [{unit}]"),
            series: runs
                .iter()
                .filter_map(|r| {
                    let s = r.response.sensors.as_ref()?;
                    Some(Series {
                        label: r.label.clone(),
                        x: s.t.clone(),
                        y: s.column(channel)?.to_vec(),
                        style: r.style,
                    })
                })
                .collect(),
            equal_axes: false,
            min_y_span: 0.0,
        })
        .collect();
    Figure {
        zooms: Vec::new(),
        name: format!("{case}-sensor-{name}"),
        title: format!("{case}: sensor {name}, every run's reading"),
        caption: format!(
            "What sensor {name} reads (docs/sensors.md), after its acquisition (filter, sampling, noise), \
             in every AMM run against the FEM (black); compare.md lists the EVP of each channel (Eq. S14)."
        ),
        panels,
    }
}
