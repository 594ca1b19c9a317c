//! An experiment together with its TOML document, for fronts that build experiments in memory
//! (Python's `Experiment.from_toml`, `from_dict`, `with_values`): the document is patched at the
//! dotted keys of sweeps (`robot.Lp`, `amm.tol`) and loaded again, so the experiment loader
//! checks every value exactly as for a file.

use std::path::{Path, PathBuf};

use flexstar_model::Experiment;

use crate::{ApiError, Result};

/// A checked experiment and the document it was read from.
#[derive(Debug, Clone)]
pub struct ExperimentDoc {
    pub exp: Experiment,
    /// The TOML document as written (what `with_values` patches).
    pub doc: toml::Table,
    /// Where it came from (a file, `<toml>`, `<dict>`): first in every message; relative paths in
    /// it (a forces file) are relative to this path's folder.
    pub source: PathBuf,
}

impl ExperimentDoc {
    /// Read and check an experiment file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ApiError::config(path.display(), None, format!("cannot read: {e}")))?;
        Self::from_toml(&text, path)
    }

    /// Parse and check TOML text (`source` names it in messages).
    pub fn from_toml(text: &str, source: &Path) -> Result<Self> {
        let exp = flexstar_shaping::shape_loaded(Experiment::from_toml_str(text, source)?)?;
        let doc: toml::Table =
            toml::from_str(text).map_err(|e| ApiError::config(source.display(), None, e.to_string()))?;
        Ok(ExperimentDoc {
            exp,
            doc,
            source: source.to_path_buf(),
        })
    }

    /// Build from a JSON object of the same shape as the TOML document.
    pub fn from_json(json: &str, source: &Path) -> Result<Self> {
        let value: serde_json::Value =
            serde_json::from_str(json).map_err(|e| ApiError::config(source.display(), None, e.to_string()))?;
        let doc = to_toml_table(&value).map_err(|reason| ApiError::config(source.display(), None, reason))?;
        Self::from_table(doc, source)
    }

    /// Load a document (checked by the experiment loader).
    pub(crate) fn from_table(doc: toml::Table, source: &Path) -> Result<Self> {
        let text = toml::to_string(&doc).map_err(|e| ApiError::config(source.display(), None, e.to_string()))?;
        Self::from_toml(&text, source)
    }

    /// The document as JSON (TOML tables as objects).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(&self.doc).map_err(|e| ApiError::Output(e.to_string()))
    }

    /// A copy with values set at dotted keys (`robot.Lp`, `amm.tol`, `scale.duration`), checked
    /// as the cases of a sweep: an error names the key and the reason.
    pub fn with_values(&self, values: &[(String, serde_json::Value)]) -> Result<Self> {
        let src = self.source.display();
        let mut keys = Vec::new();
        let mut tvals = Vec::new();
        for (k, v) in values {
            let tv = toml::Value::try_from(v)
                .map_err(|e| ApiError::config(&src, Some(k), format!("not a TOML value: {e}")))?;
            keys.push(k.clone());
            tvals.push(tv);
        }
        // each key alone first, so that an error names it (as a sweep's `[[vary]] key`)
        for (k, v) in keys.iter().zip(&tvals) {
            let one = flexstar_study::patch::case_document(&self.doc, std::slice::from_ref(k), std::slice::from_ref(v))
                .map_err(|reason| ApiError::config(&src, Some(k), reason))?;
            Self::from_table(one, &self.source).map_err(|e| match e {
                ApiError::Config { key: None, reason, .. } => ApiError::config(&src, Some(k), reason),
                other => other,
            })?;
        }
        let doc = flexstar_study::patch::case_document(&self.doc, &keys, &tvals)
            .map_err(|reason| ApiError::config(&src, None, reason))?;
        Self::from_table(doc, &self.source)
    }
}

/// A JSON object as a TOML table (no nulls: TOML has none).
fn to_toml_table(v: &serde_json::Value) -> std::result::Result<toml::Table, String> {
    match toml::Value::try_from(v) {
        Ok(toml::Value::Table(t)) => Ok(t),
        Ok(other) => Err(format!("expected a table of sections, got a {}", other.type_str())),
        Err(e) => Err(format!("not a TOML document: {e}")),
    }
}
