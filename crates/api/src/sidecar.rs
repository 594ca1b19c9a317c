//! The sidecar JSON of a table that is not a run (`modal.json` beside `modal.csv`, `freqmap.json`
//! beside `freqmap.csv`): provenance, the settings that made the table, the resolved experiment;
//! and the guard that keeps a rerun with other settings from replacing the table silently.

use std::path::{Path, PathBuf};

use flexstar_io::run_set::RunSet;
use flexstar_model::{Experiment, ModelError};
use serde_json::{Map, Value};

use crate::{ApiError, Result};

/// What a table's sidecar says: `command`, the `settings` (compared on a rerun, key by key) and
/// the experiment they were applied to.
pub struct TableSidecar<'a> {
    /// The command that wrote the table (`modal`, `freqmap`).
    pub command: &'static str,
    /// The table's file name (`modal.csv`); the sidecar is the same name with `.json`.
    pub csv: &'static str,
    /// The settings: solver(s), pose or grid, sliders, K (the document lists its keys sorted).
    pub settings: Map<String, Value>,
    pub experiment: &'a Experiment,
}

impl TableSidecar<'_> {
    /// The sidecar's file name (`modal.json`).
    pub fn json_name(&self) -> String {
        self.csv.trim_end_matches(".csv").to_string() + ".json"
    }

    /// The document: `flexstar_version`, `commit`, `date` (as a run's sidecar), `command`,
    /// `table`, every setting, the resolved `experiment`.
    pub fn document(&self, path: &Path) -> Result<Value> {
        let mut doc = crate::provenance().fields();
        doc.extend(flexstar_model::identity::fields(self.experiment));
        doc.insert("command".into(), self.command.into());
        doc.insert("table".into(), self.csv.into());
        doc.extend(self.settings.clone());
        let exp = serde_json::to_value(self.experiment).map_err(|e| write_error(path, e))?;
        doc.insert("experiment".into(), exp);
        Ok(Value::Object(doc))
    }

    /// Stage the sidecar into `set` (published with the table).
    pub fn stage(&self, set: &mut RunSet) -> Result<()> {
        let name = self.json_name();
        let path = set.path(&name);
        let text = serde_json::to_string_pretty(&self.document(&path)?).map_err(|e| write_error(&path, e))?;
        set.text(&name, &(text + "\n"))?;
        Ok(())
    }

    /// Refuse to replace the table in `dir` when it was written with other settings (or its
    /// sidecar is missing or unreadable, so that they cannot be told), naming the file and what
    /// differs; `force` replaces it anyway. An identical rerun (or an empty folder) passes.
    pub fn check_rerun(&self, dir: &Path, force: bool) -> Result<()> {
        let (csv, json) = (dir.join(self.csv), dir.join(self.json_name()));
        if force || !(csv.exists() || json.exists()) {
            return Ok(());
        }
        let old = match std::fs::read_to_string(&json) {
            Ok(text) => serde_json::from_str::<Value>(&text).map_err(|e| e.to_string()),
            Err(e) => Err(format!("cannot read {}: {e}", json.display())),
        };
        let differs = match old {
            Ok(old) => differences(&old, &self.settings),
            Err(why) => return Err(refusal(&csv, &format!("{why}, so its settings cannot be told"))),
        };
        if differs.is_empty() {
            return Ok(());
        }
        let what = format!("was written with other settings ({})", differs.join("; "));
        Err(refusal(&csv, &what))
    }
}

/// `key: old -> new` for each setting whose value in the old document `old` is not the new one
/// (both as JSON text, the new one read back first, so that equal numbers compare equal).
fn differences(old: &Value, new: &Map<String, Value>) -> Vec<String> {
    let new = Value::Object(new.clone());
    let new: Value = serde_json::from_str(&new.to_string()).unwrap_or(new);
    let text = |v: Option<&Value>| v.map_or("none".to_string(), Value::to_string);
    new.as_object()
        .into_iter()
        .flatten()
        .filter(|(key, value)| old.get(key.as_str()) != Some(value))
        .map(|(key, value)| format!("{key}: {} -> {}", text(old.get(key.as_str())), text(Some(value))))
        .collect()
}

/// The refusal to replace `csv`: `why`, and how to go on.
fn refusal(csv: &Path, why: &str) -> ApiError {
    let reason = format!("{why}: give --force to replace it, or another --out");
    ApiError::config(csv.display(), None, reason)
}

fn write_error(path: &Path, e: serde_json::Error) -> ApiError {
    ApiError::from_model(ModelError::Write {
        file: PathBuf::from(path),
        reason: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(k: usize, sliders: &str, at: f64) -> Map<String, Value> {
        let v = serde_json::json!({ "pose": { "at": at, "s": [0.1, 1.0 / 3.0, 0.0] }, "sliders": sliders, "K": k });
        v.as_object().unwrap().clone()
    }

    fn table(settings: Map<String, Value>, exp: &Experiment) -> TableSidecar<'_> {
        TableSidecar {
            command: "modal",
            csv: "modal.csv",
            settings,
            experiment: exp,
        }
    }

    #[test]
    fn a_rerun_with_other_settings_is_refused_naming_what_differs() {
        let dir = tempfile::tempdir().unwrap();
        let exp = flexstar_model::catalogue::paper_case(3);
        let first = table(settings(6, "locked", 0.25), &exp);
        first.check_rerun(dir.path(), false).unwrap(); // empty folder
        let mut set = RunSet::begin(dir.path()).unwrap();
        set.text("modal.csv", "mode\n").unwrap();
        first.stage(&mut set).unwrap();
        set.commit().unwrap();
        // the same settings (1/3 read back from the file): replaced
        first.check_rerun(dir.path(), false).unwrap();
        let other = table(settings(2, "free", 0.25), &exp);
        let e = other.check_rerun(dir.path(), false).unwrap_err().to_string();
        assert!(e.contains("modal.csv") && e.contains("other settings"), "{e}");
        assert!(
            e.contains("sliders: \"locked\" -> \"free\"") && e.contains("K: 6 -> 2"),
            "{e}"
        );
        assert!(!e.contains("pose"), "the pose is the same: {e}");
        assert!(e.contains("--force"), "{e}");
        other.check_rerun(dir.path(), true).unwrap();
        // a table without its sidecar cannot be told: refused too
        std::fs::remove_file(dir.path().join("modal.json")).unwrap();
        let e = first.check_rerun(dir.path(), false).unwrap_err().to_string();
        assert!(e.contains("modal.json") && e.contains("cannot be told"), "{e}");
    }

    #[test]
    fn the_document_has_provenance_settings_and_experiment() {
        let exp = flexstar_model::catalogue::paper_case(3);
        let doc = table(settings(6, "locked", 0.25), &exp)
            .document(Path::new("modal.json"))
            .unwrap();
        for key in [
            "flexstar_version",
            "commit",
            "date",
            "command",
            "table",
            "pose",
            "sliders",
            "K",
            "experiment",
        ] {
            assert!(doc.get(key).is_some(), "{key} missing: {doc}");
        }
        assert_eq!(doc["experiment"]["name"], "case3");
    }
}
