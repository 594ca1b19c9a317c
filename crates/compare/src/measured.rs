//! `compare CONFIG --measured FILE.csv`: a recording laid over the runs (`docs/measured.md`
//! sections 1, 2; `docs/outputs.md`): per sensor column the error of every run against the
//! recording (Eqs. M5, M6), the Welch spectra of recording and runs (Eq. W3) beside the accurate
//! AMM's natural frequencies at the final pose, and the model-free identification of the free decay
//! (section 3).
//! Nothing of it without `--measured`.

use std::fmt::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};

use flexstar_measured::identify::{identify_free_decay, IdentifyOptions};
use flexstar_measured::measure::{channel_error, ChannelError};
use flexstar_measured::welch::{welch, Psd, WelchOptions};
use flexstar_measured::{MeasuredError, Recording};
use flexstar_model::sensors::daq::sample_times;
use flexstar_model::sensors::Kind;
use flexstar_model::{Experiment, Offset, SensorTable, Sliders};
use serde::Serialize;

use crate::case_output::runs_of;
use crate::runs::CaseResults;
use crate::Error;

/// The natural frequencies marked on the spectra: this many of the accurate AMM at the final pose.
const MARKED_MODES: usize = 6;

/// The recording laid over one case, with what the report shows of it.
#[derive(Debug, Clone)]
pub struct MeasuredOverlay {
    /// The recording's file.
    pub file: PathBuf,
    /// The shift added to the recording's times [s] (Eq. M2) and whether Eq. M3 estimated it.
    pub offset_s: f64,
    pub estimated: bool,
    /// The recording on the runs' sensor times (Eq. M4).
    pub laid: SensorTable,
    /// Those times' rows in the runs' sensor tables.
    pub rows: Range<usize>,
    /// Every run's error per recorded channel, runs in the order of `runs_of`.
    pub errors: Vec<RunChannelError>,
    /// Per recorded channel, the Welch spectra of the recording and of every run.
    pub spectra: Vec<ChannelSpectra>,
    /// The natural frequencies marked on the spectra.
    pub modes: MarkedModes,
    /// Modes identified from the recorded free decay after `t_rest` ([`identify_measured_free_decay`]).
    pub identified: Vec<IdentifiedRow>,
    /// Why no mode was identified, if so (no rest before `t_end`, no channel that vibrates, or
    /// the identification's own reason).
    pub identified_note: Option<String>,
}

/// Eqs. M5, M6 of one run's channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunChannelError {
    /// The run's file stem (`fem`, `amm-<label>`).
    pub run: String,
    pub channel: String,
    pub unit: String,
    #[serde(flatten)]
    pub error: ChannelError,
}

/// The Welch spectra of one channel (Eq. W3): the recording's first, then every run's.
#[derive(Debug, Clone)]
pub struct ChannelSpectra {
    pub channel: String,
    pub unit: String,
    /// `(label, psd)`: `measured`, then the runs' stems; empty when the channel is too short
    /// (`note` says why).
    pub psd: Vec<(String, Psd)>,
    pub note: Option<String>,
}

/// The natural frequencies [Hz] marked on the spectra, and where they come from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarkedModes {
    pub hz: Vec<f64>,
    /// The pose's time [s]: `t_rest` of a rest-to-rest motion, else `t_end`.
    pub at_s: f64,
    /// Why there are none, if so.
    pub note: Option<String>,
}

/// One mode identified from the recorded free decay (`docs/measured.md` section 3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IdentifiedRow {
    /// Undamped natural frequency [Hz] (Eq. I2).
    pub f_hz: f64,
    /// Damping ratio [-] (Eq. I2).
    pub zeta: f64,
    /// Standard uncertainty (1 sigma) of `f_hz` [Hz] from the noise (Eqs. I10-I12).
    pub f_std_hz: f64,
    /// Standard uncertainty (1 sigma) of `zeta` [-] from the noise (Eqs. I10-I12).
    pub zeta_std: f64,
}

/// Read the recording `path` for the experiment (`[measured]`, its sensors) with every check
/// of `docs/measured.md` 1.1 before any run; a given offset is also checked for overlap with the
/// sensor times the runs will have.
pub fn read_recording(exp: &Experiment, path: &Path) -> Result<Recording, Error> {
    let problem = exp.problem()?;
    let section = exp.measured.clone().unwrap_or_default();
    let rec = Recording::read(path, &section, problem.sensors())?;
    if rec.shift().is_some() {
        let t = match problem.sensors().rate_hz() {
            Some(rate) => sample_times(rate, exp.time.t_end),
            None => exp.time.output_times(),
        };
        rec.on_times(&t)?;
    }
    Ok(rec)
}

/// Lay `rec` over `case` (`docs/measured.md` 1.3-1.5, 2): the offset resolved against the FEM's
/// sensors, the recording on their times, every run's error and spectra, the marked modes and
/// the identification of the free decay.
pub fn overlay(exp: &Experiment, case: &CaseResults, mut rec: Recording) -> Result<MeasuredOverlay, Error> {
    let fem = case.fem.sensors.as_ref().ok_or_else(|| Error::Input {
        file: rec.file().display().to_string(),
        reason: "the FEM run wrote no sensors: a recording needs [[sensors]]".into(),
    })?;
    let offset_s = rec.align(fem)?;
    let laid = rec.on_times(&fem.t)?;
    let (identified, identified_note) = match free_decay(exp, &laid) {
        Ok(rows) => (rows, None),
        Err(note) => (Vec::new(), Some(note)),
    };
    let rows = rec.span_in(&fem.t)?;
    let errors = run_errors(case, &laid, &rows);
    let spectra = laid
        .columns
        .iter()
        .zip(&laid.units)
        .map(|(c, u)| channel_spectra(case, &laid, &rows, &c.name, u))
        .collect();
    Ok(MeasuredOverlay {
        file: rec.file().to_path_buf(),
        offset_s,
        estimated: rec.offset() == Offset::Auto,
        identified,
        identified_note,
        modes: marked_modes(exp),
        laid,
        rows,
        errors,
        spectra,
    })
}

/// A run's channel `name` on the rows `rows` of its sensor table.
pub fn run_channel<'r>(r: &'r flexstar_model::Response, name: &str, rows: &Range<usize>) -> Option<&'r [f64]> {
    r.sensors.as_ref()?.column(name).and_then(|c| c.get(rows.clone()))
}

/// Eqs. M5, M6 of every run's channel against the recording, runs in the order of `runs_of`.
fn run_errors(case: &CaseResults, laid: &SensorTable, rows: &Range<usize>) -> Vec<RunChannelError> {
    let mut out = Vec::new();
    for (stem, r) in runs_of(case) {
        for (c, unit) in laid.columns.iter().zip(&laid.units) {
            if let Some(model) = run_channel(r, &c.name, rows) {
                out.push(RunChannelError {
                    run: stem.clone(),
                    channel: c.name.clone(),
                    unit: unit.clone(),
                    error: channel_error(&laid.t, model, &c.values),
                });
            }
        }
    }
    out
}

/// Eq. W3 of the recorded channel `name` and of every run's, on the same samples.
fn channel_spectra(
    case: &CaseResults,
    laid: &SensorTable,
    rows: &Range<usize>,
    name: &str,
    unit: &str,
) -> ChannelSpectra {
    let fs = match flexstar_measured::offset::median_step(&laid.t) {
        Some(h) => 1.0 / h,
        None => f64::NAN,
    };
    let opts = WelchOptions::default();
    let mut series: Vec<(String, &[f64])> = vec![("measured".into(), laid.column(name).unwrap_or_default())];
    for (stem, r) in runs_of(case) {
        if let Some(y) = run_channel(r, name, rows) {
            series.push((stem, y));
        }
    }
    let psd: Result<Vec<(String, Psd)>, MeasuredError> = series
        .into_iter()
        .map(|(label, y)| welch(y, fs, &opts, name).map(|p| (label, p)))
        .collect();
    let (psd, note) = match psd {
        Ok(p) => (p, None),
        Err(e) => (Vec::new(), Some(format!("no spectrum: {e}"))),
    };
    ChannelSpectra {
        channel: name.to_string(),
        unit: unit.to_string(),
        psd,
        note,
    }
}

/// The first [`MARKED_MODES`] elastic frequencies of the accurate AMM (`flexstar_modal`'s basis,
/// payload included), sliders locked, at the pose of `t_rest` (a rest-to-rest motion) or
/// `t_end`; none, with the reason, where the modal analysis cannot run.
fn marked_modes(exp: &Experiment) -> MarkedModes {
    let at_s = exp.trajectory.t_rest().unwrap_or(exp.time.t_end).min(exp.time.t_end);
    let found = flexstar_modal::pose::pose_at_time(exp, at_s).and_then(|pose| {
        Ok(flexstar_modal::analysis::amm_pose_model(exp)?.frequencies_at(&pose, Sliders::Locked, MARKED_MODES)?)
    });
    match found {
        Ok(hz) => MarkedModes { hz, at_s, note: None },
        Err(e) => MarkedModes {
            hz: Vec::new(),
            at_s,
            note: Some(format!("no natural frequencies: {e}")),
        },
    }
}

/// The recorded free decay after `t_rest` (a rest-to-rest motion that ends before `t_end`)
/// handed to [`identify_measured_free_decay`] (`docs/measured.md` 3.1, 3.6): the channels of the
/// sensors that see the elastic motion (accelerometers, strain gauges, force sensors; the
/// encoders read the held sliders), from `t_rest` plus one sample, or plus three time constants
/// `3 / lowpass_hz` of the slowest anti-aliasing filter among them. `Err` says why there is none.
fn free_decay(exp: &Experiment, laid: &SensorTable) -> Result<Vec<IdentifiedRow>, String> {
    let t_rest = flexstar_modal::settle::motion_end(exp)
        .ok_or("no identification: the motion does not come to rest before t_end")?;
    let problem = exp.problem().map_err(|e| e.to_string())?;
    let mut skip_s: f64 = 0.0;
    let mut names = Vec::new();
    for sensor in problem.sensors().list() {
        if matches!(sensor.kind, Kind::Encoder { .. }) {
            continue;
        }
        if let Some(fc) = sensor.daq.lowpass_hz {
            skip_s = skip_s.max(3.0 / fc);
        }
        names.extend(sensor.columns());
    }
    let from = laid.t.partition_point(|&t| t <= t_rest + skip_s);
    let channels: Vec<&[f64]> = laid
        .columns
        .iter()
        .filter(|c| names.contains(&c.name))
        .map(|c| &c.values[from..])
        .collect();
    if channels.is_empty() {
        return Err("no identification: no recorded accelerometer, strain or force channel".into());
    }
    identify_measured_free_decay(&laid.t[from..], &channels).map_err(|e| format!("no identification: {e}"))
}

/// The model-free identification of the recorded free decay (`docs/measured.md` section 3: ERA,
/// then the maximum likelihood fit, at the documented options), `t` [s] the times after
/// `t_rest`, `channels` the recorded channels there (the sensors' units); the modes ascending in
/// frequency with their standard uncertainties.
pub fn identify_measured_free_decay(t: &[f64], channels: &[&[f64]]) -> Result<Vec<IdentifiedRow>, MeasuredError> {
    let modes = identify_free_decay(t, channels, &IdentifyOptions::default())?;
    Ok(modes
        .into_iter()
        .map(|m| IdentifiedRow {
            f_hz: m.f_hz,
            zeta: m.zeta,
            f_std_hz: m.f_std_hz,
            zeta_std: m.zeta_std,
        })
        .collect())
}

impl MeasuredOverlay {
    /// The section of `compare.md` (and of the report).
    pub fn markdown(&self) -> String {
        let mut s = format!("## Measured: `{}`\n\n", self.file.display());
        let how = if self.estimated {
            "estimated by cross-correlation against the FEM's sensors (docs/measured.md Eq. M3)"
        } else {
            "as given (`[measured] offset`)"
        };
        let _ = writeln!(
            s,
            "Offset {} s added to the recording's times, {how}; compared on {} of the runs' sensor times, \
             t = {} .. {} s.\n",
            fmt(self.offset_s),
            self.laid.t.len(),
            fmt(self.laid.t[0]),
            fmt(self.laid.t[self.laid.t.len() - 1])
        );
        s.push_str(
            "`EVP = int |y_run - y_meas| dt / int |y_meas| dt x 100` (Eq. M5, the recording as the reference) \
             and `RMS = sqrt(int (y_run - y_meas)^2 dt / T)` in the channel's unit (Eq. M6); where the \
             recording is near zero or noise-dominated read the RMS against the sensor's noise \
             (docs/measured.md 1.5).\n\n",
        );
        s.push_str("| run | channel | unit | EVP [%] | RMS |\n|---|---|---|---|---|\n");
        for e in &self.errors {
            let evp = e.error.evp.map_or_else(|| "n/a".to_string(), |v| format!("{v:.3}"));
            let _ = writeln!(
                s,
                "| {} | {} | {} | {evp} | {:.4e} |",
                e.run, e.channel, e.unit, e.error.rms
            );
        }
        s.push('\n');
        s.push_str(&self.modes_markdown());
        s.push_str(&self.identified_markdown());
        s
    }

    /// The marked modes and each spectrum's peak.
    fn modes_markdown(&self) -> String {
        let mut s = String::new();
        match &self.modes.note {
            Some(note) => {
                let _ = writeln!(s, "Spectra (Welch, docs/measured.md section 2): {note}.\n");
            }
            None => {
                let hz: Vec<String> = self.modes.hz.iter().map(|f| format!("{f:.2}")).collect();
                let _ = writeln!(
                    s,
                    "Spectra (Welch, docs/measured.md section 2) are marked with the accurate AMM's natural \
                     frequencies at the pose of t = {} s, sliders locked: {} Hz.\n",
                    fmt(self.modes.at_s),
                    hz.join(", ")
                );
            }
        }
        let df = self.spectra.iter().find_map(|c| c.psd.first()).map(|(_, p)| p.df());
        if let Some(df) = df {
            let _ = writeln!(
                s,
                "Each spectrum's largest density above 0 Hz, at the resolution df = {df:.4} Hz (Welch segments of a \
                 quarter of the record):\n"
            );
        }
        s.push_str("| channel | PSD peak, measured [Hz] | PSD peak, runs [Hz] |\n|---|---|---|\n");
        for c in &self.spectra {
            let peak = |p: &Psd| p.peak_above(0.0).map_or("-".into(), |f| format!("{f:.2}"));
            let (measured, runs) = match c.psd.split_first() {
                Some((m, rest)) => (
                    peak(&m.1),
                    rest.iter()
                        .map(|(l, p)| format!("{l} {}", peak(p)))
                        .collect::<Vec<_>>()
                        .join(", "),
                ),
                None => ("-".into(), c.note.clone().unwrap_or_default()),
            };
            let _ = writeln!(s, "| {} | {measured} | {runs} |", c.channel);
        }
        s.push('\n');
        s
    }

    /// The identified modes of the free decay, if any.
    fn identified_markdown(&self) -> String {
        if let Some(note) = &self.identified_note {
            return format!("{note}.\n\n");
        }
        let mut s = String::from(
            "Modes identified from the recorded free decay after t_rest, model-free (ERA, then maximum \
             likelihood: docs/measured.md section 3), with their 95 % intervals (1.96 standard \
             uncertainties from the noise):\n\n\
             | mode | f [Hz] | zeta [%] | model f [Hz] (final pose) |\n|---|---|---|---|\n",
        );
        for (k, m) in self.identified.iter().enumerate() {
            let model = self
                .modes
                .hz
                .get(k)
                .map_or_else(|| "-".to_string(), |f| format!("{f:.4}"));
            let _ = writeln!(
                s,
                "| {} | {:.4} +- {:.4} | {:.3} +- {:.3} | {model} |",
                k + 1,
                m.f_hz,
                1.96 * m.f_std_hz,
                100.0 * m.zeta,
                196.0 * m.zeta_std
            );
        }
        s.push('\n');
        s
    }

    /// The key `measured` of `compare.json`.
    pub fn json(&self) -> serde_json::Value {
        let peaks: Vec<serde_json::Value> = self
            .spectra
            .iter()
            .flat_map(|c| {
                c.psd.iter().map(move |(label, p)| {
                    serde_json::json!({ "channel": c.channel, "run": label, "peak_hz": p.peak_above(0.0), "df_hz": p.df() })
                })
            })
            .collect();
        serde_json::json!({
            "file": self.file.display().to_string(),
            "offset_s": self.offset_s,
            "offset_estimated": self.estimated,
            "t_first": self.laid.t.first(),
            "t_last": self.laid.t.last(),
            "samples": self.laid.t.len(),
            "errors": self.errors,
            "modes_hz": self.modes.hz,
            "modes_at_s": self.modes.at_s,
            "spectrum_peaks": peaks,
            "identified": self.identified,
            "identified_note": self.identified_note,
        })
    }
}

/// A number for the text: six significant digits.
fn fmt(v: f64) -> String {
    flexstar_io::output::fmt_sig(v, 6)
}
