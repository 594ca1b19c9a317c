//! `configs/thresholds.toml`: what `flexstar verify` (and the CI regression test) demands of the
//! regenerated Table I: the verdicts and most accurate family per case (MODEL-NOTES section 5),
//! and every mean EVP inside a recorded band (provenance written beside the band in the file).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use flexstar_model::ModeFamily;
use serde::Deserialize;

use crate::behaviour::Behaviour;
use crate::table::TableI;

/// Expectations for one case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseThresholds {
    /// Actual behaviour of G expected from the FEM.
    pub behaviour: Behaviour,
    /// Families whose boundary conditions at G can represent the behaviour.
    pub correct: Vec<ModeFamily>,
    /// Families that cannot.
    pub incorrect: Vec<ModeFamily>,
    /// The most accurate family (smallest mean EVP).
    pub most_accurate: ModeFamily,
    /// A family allowed to take the first place instead when its mean EVP is within
    /// `tie_points` of the expected one (case 1: pinned-free and free-free).
    #[serde(default)]
    pub tie_with: Option<ModeFamily>,
    #[serde(default)]
    pub tie_points: f64,
    /// Band `[low, high]` of the mean EVP [%] per family.
    #[serde(default)]
    pub evp: HashMap<ModeFamily, [f64; 2]>,
}

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Modes per beam of the verified runs.
    pub modes: usize,
    /// Further N for the convergence columns of the table (not checked).
    #[serde(default)]
    pub n_study: Vec<usize>,
    /// Per case name.
    pub case: BTreeMap<String, CaseThresholds>,
}

/// Errors reading the thresholds file.
#[derive(Debug, thiserror::Error)]
pub enum ThresholdsError {
    #[error("{file}: {reason}")]
    Read { file: String, reason: String },
}

impl Thresholds {
    pub fn load(path: &Path) -> Result<Self, ThresholdsError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ThresholdsError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        let t: Thresholds = toml::from_str(&text).map_err(|e| ThresholdsError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        for (name, c) in &t.case {
            for (f, band) in &c.evp {
                if !band[0].is_finite() || !band[1].is_finite() || band[0] > band[1] {
                    return Err(ThresholdsError::Read {
                        file: file.clone(),
                        reason: format!("case.{name}.evp.{f}: need low <= high, got {band:?}"),
                    });
                }
            }
        }
        Ok(t)
    }

    /// Every failed check, as a sentence; empty when all hold.
    pub fn check(&self, table: &TableI) -> Vec<String> {
        let mut fails = Vec::new();
        for (name, exp) in &self.case {
            let Some(row) = table.rows.iter().find(|r| &r.case == name) else {
                fails.push(format!("{name}: not in the table"));
                continue;
            };
            if row.behaviour != exp.behaviour {
                fails.push(format!(
                    "{name}: behaviour of G is {}, expected {}",
                    row.behaviour.name(),
                    exp.behaviour.name()
                ));
            }
            for (families, want) in [(&exp.correct, true), (&exp.incorrect, false)] {
                for f in families {
                    match row.family(*f) {
                        Some(e) if e.correct != want => fails.push(format!(
                            "{name}: {f} is {}, expected {}",
                            if e.correct { "correct" } else { "incorrect" },
                            if want { "correct" } else { "incorrect" }
                        )),
                        None => fails.push(format!("{name}: {f} was not run")),
                        _ => {}
                    }
                }
            }
            let mean = |f: ModeFamily| row.family(f).and_then(|e| e.evp.mean);
            match row.most_accurate {
                Some(best) if best == exp.most_accurate => {}
                Some(best) if Some(best) == exp.tie_with => {
                    let (a, b) = (mean(best), mean(exp.most_accurate));
                    let within = matches!((a, b), (Some(a), Some(b)) if (a - b).abs() <= exp.tie_points);
                    if !within {
                        fails.push(format!(
                            "{name}: most accurate is {best} ({}), expected {} ({}) or a tie within {} EVP points",
                            fmt(a),
                            exp.most_accurate,
                            fmt(b),
                            exp.tie_points
                        ));
                    }
                }
                Some(best) => fails.push(format!(
                    "{name}: most accurate is {best} ({}), expected {} ({})",
                    fmt(mean(best)),
                    exp.most_accurate,
                    fmt(mean(exp.most_accurate))
                )),
                None => fails.push(format!("{name}: no family has an EVP")),
            }
            let mut bands: Vec<_> = exp.evp.iter().collect();
            bands.sort_by_key(|(f, _)| f.name());
            for (f, band) in bands {
                match mean(*f) {
                    Some(v) if v >= band[0] && v <= band[1] => {}
                    v => fails.push(format!(
                        "{name}: mean EVP of {f} is {}, outside the band [{}, {}]",
                        fmt(v),
                        band[0],
                        band[1]
                    )),
                }
            }
        }
        fails
    }
}

fn fmt(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2} %")).unwrap_or_else(|| "n/a".into())
}
