//! The sidecar `<stem>.json` of a solver run, typed: every key of `docs/outputs.md` ("`<stem>.json`:
//! the sidecar of every solver run") is a field here, built in one place and read by field.
//!
//! The document is written through `serde_json::Value`, whose maps keep their keys in
//! alphabetical order: the files list the keys alphabetically, whatever the field order here.

use serde::{Deserialize, Serialize};

use crate::config::Experiment;
use crate::residual::Residual;
use crate::response::RunInfo;
use crate::validity::ValidityExceeded;

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

impl ResidualKeys {
    /// The keys of a residual (`None`: the motion does not rest before `t_end`) measured in the
    /// band `settle_tol` [m]. `g_pinned`: the run's modes pin G (the AMM's pinned-free family,
    /// `phi(0) = 0`), so it has no residual of G: those keys are null, with `residual_note`.
    pub fn new(res: Option<&Residual>, settle_tol: f64, g_pinned: bool) -> Self {
        let get = |f: fn(&Residual) -> f64| res.map(f);
        let opt = |f: fn(&Residual) -> Option<f64>| res.and_then(f);
        let tracking = res.filter(|r| r.tracking_peak_m.is_some());
        let mut keys = ResidualKeys {
            t_rest: get(|r| r.t_rest),
            g_peak_m: get(|r| r.g_peak_m),
            g_rms_m: get(|r| r.g_rms_m),
            tip_peak_m: get(|r| r.tip_peak_m),
            tip_rms_m: get(|r| r.tip_rms_m),
            settle_s: opt(|r| r.settle_s),
            settled: res.map(Residual::settled),
            settle_tol: Some(settle_tol),
            settle_hold_s: get(|r| r.hold_s),
            g_decay_per_s: opt(|r| r.decay_per_s),
            settle_predicted_s: opt(|r| r.settle_predicted_s),
            tracking_peak_m: tracking.map(|r| r.tracking_peak_m),
            tracking_end_m: tracking.map(|r| r.tracking_end_m),
            residual_note: None,
        };
        if g_pinned && res.is_some() {
            keys.g_peak_m = None;
            keys.g_rms_m = None;
            keys.settle_s = None;
            keys.settled = None;
            keys.g_decay_per_s = None;
            keys.settle_predicted_s = None;
            keys.residual_note = Some("G is pinned in this family".into());
        }
        keys
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
