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
