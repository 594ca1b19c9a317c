//! The sidecar `<stem>.json` of a solver run, typed: every key of `docs/outputs.md` ("`<stem>.json`:
//! the sidecar of every solver run") is a field here, built in one place and read by field.
//!
//! The document is written through `serde_json::Value`, whose maps keep their keys in
//! alphabetical order: the files list the keys alphabetically, whatever the field order here.

use serde::{Deserialize, Serialize};

use crate::config::Experiment;
use crate::response::RunInfo;

/// The residual vibration keys of a run's sidecar (`docs/motions.md` 2.4, `docs/outputs.md`):
/// peaks and RMS of |dG| and of the tips after `t_rest` [m], the settling time [s] and the band
/// [m]. Without a residual (no rest before `t_end`) every value is null but `settle_tol`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualKeys {
    /// The motion's end [s].
    pub t_rest: Option<f64>,
    #[serde(rename = "residual_G_peak_m")]
    pub g_peak_m: Option<f64>,
    #[serde(rename = "residual_G_rms_m")]
    pub g_rms_m: Option<f64>,
    #[serde(rename = "residual_tip_peak_m")]
    pub tip_peak_m: Option<f64>,
    #[serde(rename = "residual_tip_rms_m")]
    pub tip_rms_m: Option<f64>,
    /// When |dG| enters the band for good [s]; null when it does not by `t_end`.
    pub settle_s: Option<f64>,
    pub settled: Option<bool>,
    /// The settling band [m] (`[report] settle_tol`).
    pub settle_tol: Option<f64>,
    /// How long |dG| must stay in the band [s].
    pub settle_hold_s: Option<f64>,
    /// The decay rate of |dG|'s envelope [1/s], when measured.
    #[serde(rename = "residual_G_decay_per_s")]
    pub g_decay_per_s: Option<f64>,
    /// The settling time predicted from that decay [s].
    pub settle_predicted_s: Option<f64>,
    /// A servo run's sliders: largest tracking error after `t_rest` [m] (the key only for a run
    /// with tracking errors; its value may be null).
    #[serde(
        rename = "residual_tracking_peak_m",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub tracking_peak_m: Option<Option<f64>>,
    /// The same at `t_end` [m].
    #[serde(rename = "residual_tracking_end_m", default, skip_serializing_if = "Option::is_none")]
    pub tracking_end_m: Option<Option<f64>>,
    /// Why the keys of G are null (`G is pinned in this family`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_note: Option<String>,
    /// The residual and settling per dwell (`docs/motions.md` 2.5), one entry per dwell in time
    /// order; the key only for a run whose motion has at least one dwell (a move ending before
    /// `t_end`). The last entry is the window of the keys above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwells: Option<Vec<DwellKeys>>,
    /// A run with friction (`docs/friction.md` 5): the rest state the keys above are measured
    /// about, or the sleeve still slipping at the end; the key only for such a run.
    #[serde(rename = "residual_friction", default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionRestKeys>,
}

/// How a run with friction ends (`docs/friction.md` 5): every sleeve stuck over the last hold
/// window, with the rest state's elastic displacement of G, or a sleeve still slipping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrictionRestKeys {
    /// |dG| of the rest state [m] (Eq. R1 of `docs/motions.md` 2.1): the offset friction holds.
    /// Null while a sleeve slips.
    #[serde(rename = "rest_G_m")]
    pub rest_g_m: Option<f64>,
    /// `w_iG` of the rest state [m], each in its beam's rigid frame. Null while a sleeve slips.
    #[serde(rename = "rest_w_G_m")]
    pub rest_w_g_m: Option<[f64; 3]>,
    /// The sleeve (1-3) still slipping in the last hold window, the last such time [s]; null
    /// when all are stuck. The keys above are then measured about the rest state without
    /// friction (the static sag under gravity, else zero), to which the star still relaxes.
    pub slipping_sleeve: Option<usize>,
    pub slipping_t: Option<f64>,
}

/// The residual vibration and settling of one dwell (`docs/motions.md` 2.5): the interval from
/// the end of a move (the sliders at rest) to the start of the next move, or to the run's last
/// output time after the last move. Times are absolute [s] on the run's clock; lengths [m] are
/// of |dG| (the elastic displacement of G, fixed frame, motions.md 2.1) and of the tips `w_i(L)`
/// (each beam's rigid frame), about the static sag under gravity. One entry of the sidecar's
/// `dwells` and one row of `<stem>-dwells.csv` ([`DWELLS_CSV_HEADER`], the same names).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DwellKeys {
    /// 1-based number of the dwell (and of the move it follows).
    pub dwell: usize,
    /// Start of the move before the dwell [s].
    pub move_start: f64,
    /// End of that move [s]: the sliders come to rest.
    pub move_end: f64,
    /// Start of the dwell [s] (= `move_end`).
    pub t_start: f64,
    /// End of the dwell [s]: the next move's start, or the run's last output time.
    pub t_end: f64,
    /// Largest |dG| at the output times in `[t_start, t_end]` [m]; null when not measured.
    #[serde(rename = "G_peak_m")]
    pub g_peak_m: Option<f64>,
    /// RMS of |dG| over the dwell (trapezoidal over its output times) [m].
    #[serde(rename = "G_rms_m")]
    pub g_rms_m: Option<f64>,
    /// Largest |w_i(L)| of the three tips in the dwell [m].
    pub tip_peak_m: Option<f64>,
    /// RMS over the dwell of `sqrt(1/3 sum_i w_i(L)^2)` [m].
    pub tip_rms_m: Option<f64>,
    /// The last output time in the dwell with |dG| above the band (`t_start` when none) when
    /// |dG| then stays in the band for at least `settle_hold_s` before the dwell ends [s,
    /// absolute]; null when not settled within the dwell or not measured.
    pub settle_s: Option<f64>,
    /// Settled within the dwell (motions.md 2.3 judged in the dwell); null when not measured.
    pub settled: Option<bool>,
    /// One period of the first elastic mode at the dwell's pose, sliders locked [s]: the quiet
    /// time the dwell must end with to count as settled.
    pub settle_hold_s: Option<f64>,
    /// Why a value is null or the dwell cannot settle (too short, shorter than the output step,
    /// G pinned, the sag under gravity unknown at this pose); null when there is nothing to say.
    pub note: Option<String>,
}

/// Header of `<stem>-dwells.csv` (a file contract, `docs/outputs.md`; every column declared in
/// [`crate::quantity::QUANTITIES`]): one row per dwell, the fields of [`DwellKeys`].
pub const DWELLS_CSV_HEADER: [&str; 13] = [
    "dwell",
    "move_start",
    "move_end",
    "t_start",
    "t_end",
    "G_peak_m",
    "G_rms_m",
    "tip_peak_m",
    "tip_rms_m",
    "settle_s",
    "settled",
    "settle_hold_s",
    "note",
];

/// The text of `<stem>-dwells.csv`: [`DWELLS_CSV_HEADER`], then one row per dwell; numbers in
/// the shortest form that reads back exactly, an empty field for a null, `true`/`false` for
/// `settled`, the note quoted when it holds a comma.
pub fn dwells_csv(dwells: &[DwellKeys]) -> String {
    use flexstar_io::output::fmt_number;
    let num = |v: Option<f64>| v.map(fmt_number).unwrap_or_default();
    let mut out = csv::Writer::from_writer(Vec::new());
    let mut rows = vec![DWELLS_CSV_HEADER.map(String::from).to_vec()];
    for d in dwells {
        rows.push(vec![
            d.dwell.to_string(),
            fmt_number(d.move_start),
            fmt_number(d.move_end),
            fmt_number(d.t_start),
            fmt_number(d.t_end),
            num(d.g_peak_m),
            num(d.g_rms_m),
            num(d.tip_peak_m),
            num(d.tip_rms_m),
            num(d.settle_s),
            d.settled.map(|b| b.to_string()).unwrap_or_default(),
            num(d.settle_hold_s),
            d.note.clone().unwrap_or_default(),
        ]);
    }
    for r in rows {
        out.write_record(&r).expect("a CSV record in memory");
    }
    String::from_utf8(out.into_inner().expect("a CSV in memory")).expect("UTF-8 fields")
}

/// The first time a run leaves the small-deflection range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ValidityExceeded {
    /// First output time at which a bound is exceeded [s].
    pub t: f64,
    /// The quantity, e.g. `|w2tip| / L` or `|thp1|`.
    pub quantity: String,
    /// Its value at `t` (dimensionless or rad).
    pub value: f64,
    /// The bound it exceeds (same unit).
    pub bound: f64,
    /// Its peak over the run (same unit).
    pub peak: f64,
}

impl std::fmt::Display for ValidityExceeded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "leaves the small-deflection range the AMM assumes at t = {:.4} s: {} = {:.4} > {} (peak {:.4}); \
             the AMM's results past that time are outside its model, the FEM (geometrically nonlinear) stays valid",
            self.t, self.quantity, self.value, self.bound, self.peak
        )
    }
}

/// The sidecar of a solver run (`docs/outputs.md`): provenance, the experiment's identity, the
/// run's settings and cost ([`RunInfo`], flattened), the small-deflection check, the columns'
/// units, the resolved experiment; the residual keys of a run judged after its motion, the
/// frames' hash of a run with frames, and the validated-envelope verdict of an AMM run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSidecar {
    pub flexstar_version: String,
    /// The git commit the binary was built from (`null` when unknown).
    pub commit: Option<String>,
    /// Date and time of the run, UTC, ISO 8601.
    pub date: String,
    /// The experiment file (absolute path), `crate::identity::FILE_KEY`.
    pub experiment_file: String,
    /// Its hash, `crate::identity::HASH_KEY`.
    pub experiment_hash: String,
    /// Solver label (`fem`, `amm-<family>`).
    pub label: String,
    #[serde(flatten)]
    pub info: RunInfo,
    /// `null` while the run stays in the small-deflection range, else the first excursion.
    pub small_deflection: Option<ValidityExceeded>,
    /// `{column: unit}` for every column of the run's CSV (`crate::quantity`).
    pub column_units: serde_json::Value,
    /// The experiment with the values the run used (`Response::resolved_experiment`).
    pub experiment: Experiment,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub residual: Option<ResidualKeys>,
    /// Under gravity: the static deflection where the motion rests, about which the residual is
    /// measured (`docs/as-built.md` 5.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rest_offset: Option<crate::RestOffset>,
    /// With friction: the time each sleeve (and slider) stayed stuck and the energy the friction
    /// dissipated (`docs/friction.md` 7).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<crate::friction::FrictionSummary>,
    /// The hash of the run's frames files (`crate::animation::FRAMES_HASH_KEY`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frames_hash: Option<String>,
    /// An AMM run: inside the validated envelope of the accurate model (`docs/validation.md` 8)?
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validated_envelope: Option<bool>,
    /// An AMM run: why not (empty inside).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validated_envelope_reasons: Option<Vec<String>>,
}

impl RunSidecar {
    /// The document as written (keys in alphabetical order; non-finite numbers become `null`).
    pub fn to_value(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_of_the_dwells_file_is_declared_and_a_note_with_a_comma_is_quoted() {
        for name in DWELLS_CSV_HEADER {
            assert!(crate::quantity::quantity_of(name).is_some(), "{name} is not declared");
        }
        let d = DwellKeys {
            dwell: 2,
            move_start: 0.7,
            move_end: 1.1,
            t_start: 1.1,
            t_end: 1.5,
            g_peak_m: Some(1e-4),
            g_rms_m: None,
            tip_peak_m: Some(0.5),
            tip_rms_m: Some(0.25),
            settle_s: None,
            settled: Some(false),
            settle_hold_s: Some(0.25),
            note: Some("too short, by far".into()),
        };
        let text = dwells_csv(std::slice::from_ref(&d));
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), DWELLS_CSV_HEADER.join(","));
        assert_eq!(
            lines.next().unwrap(),
            "2,0.7,1.1,1.1,1.5,1e-4,,0.5,0.25,,false,0.25,\"too short, by far\""
        );
        // the sidecar's entry has the same names as the columns
        let v = serde_json::to_value(&d).unwrap();
        let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        let mut cols = DWELLS_CSV_HEADER.to_vec();
        keys.sort();
        cols.sort();
        assert_eq!(keys, cols);
    }
}
