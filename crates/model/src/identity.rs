//! Which experiment wrote a folder's files. Results go to `<out>/<name>/`, `name` taken from the
//! experiment file, so two files with the same `name` (a copied experiment) share a folder. Every
//! sidecar records the experiment file and its hash ([`fields`]), so that a command can say on
//! stderr when it replaces results of another experiment there ([`other_experiment_note`];
//! docs/outputs.md, "Whose folder").

use std::path::{Path, PathBuf};

use crate::hash::Fnv1a64;
use crate::Experiment;

/// Sidecar key: the experiment file a result came from (absolute when it can be resolved).
pub const FILE_KEY: &str = "experiment_file";
/// Sidecar key: the experiment's hash ([`experiment_hash`]).
pub const HASH_KEY: &str = "experiment_hash";

/// The experiment's hash: FNV-1a 64 (16 hex digits) of its TOML text followed by the bytes of every
/// file it reads (`inputs`, [`Experiment::input_files`]: a motion, forces or load table), each
/// preceded by a NUL byte; a file that cannot be read adds its path instead.
pub fn experiment_hash(text: &str, inputs: &[PathBuf]) -> String {
    let mut h = Fnv1a64::default();
    h.update(text.as_bytes());
    for f in inputs {
        h.update(b"\0");
        match std::fs::read(f) {
            Ok(bytes) => h.update(&bytes),
            Err(_) => h.update(f.to_string_lossy().as_bytes()),
        }
    }
    h.hex()
}

/// The experiment's file as recorded: its absolute path when it exists, else as given
/// (`<dict>`, `<toml>` for experiments built in memory).
pub fn source_text(exp: &Experiment) -> String {
    std::fs::canonicalize(&exp.source)
        .unwrap_or_else(|_| exp.source.clone())
        .display()
        .to_string()
}

/// The sidecar fields [`FILE_KEY`] and [`HASH_KEY`] of `exp`.
pub fn fields(exp: &Experiment) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    m.insert(FILE_KEY.into(), source_text(exp).into());
    m.insert(HASH_KEY.into(), exp.hash.clone().into());
    m
}

/// The experiment (file, hash) a sidecar document records, if it records one.
pub fn recorded(doc: &serde_json::Value) -> Option<(String, String)> {
    let file = doc.get(FILE_KEY)?.as_str()?;
    let hash = doc.get(HASH_KEY)?.as_str()?;
    Some((file.to_string(), hash.to_string()))
}

/// The experiments recorded by the sidecars (`*.json`) of `dir` and of its immediate subfolders
/// (a plan's `plain/`, `zvd/`, `planned/`), each once, in file-name order.
fn recorded_in(dir: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    let mut scan = |d: &Path, deeper: bool| -> Vec<PathBuf> {
        let mut subdirs = Vec::new();
        for entry in std::fs::read_dir(d).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                if deeper {
                    subdirs.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "json") {
                files.push(path);
            }
        }
        subdirs
    };
    for sub in scan(dir, true) {
        scan(&sub, false);
    }
    files.sort();
    let mut seen: Vec<(String, String)> = Vec::new();
    for f in files {
        let doc = std::fs::read_to_string(&f)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok());
        if let Some(id) = doc.as_ref().and_then(recorded) {
            if !seen.contains(&id) {
                seen.push(id);
            }
        }
    }
    seen
}

/// The note to print when `dir` holds results of another experiment than `exp`: one whose
/// sidecars record another file *and* another hash (a copied experiment with the same `name`).
/// `None` for an empty or new folder, for results of the same file (edited or not) and for an
/// identical copy (same hash: the same results).
pub fn other_experiment_note(dir: &Path, exp: &Experiment) -> Option<String> {
    let me = source_text(exp);
    let others: Vec<(String, String)> = recorded_in(dir)
        .into_iter()
        .filter(|(file, hash)| *file != me && *hash != exp.hash)
        .collect();
    let (file, hash) = others.first()?;
    let more = match others.len() {
        1 => String::new(),
        n => format!(" and {} more", n - 1),
    };
    Some(format!(
        "note: {} holds results of another experiment named `{}`: {file} (experiment hash {hash}){more}; \
         this one is {me} ({}). The files written now replace theirs; to keep both, pass --out DIR or \
         give one of the files another `name`",
        dir.display(),
        exp.name,
        exp.hash
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_covers_the_text_and_the_files_read() {
        let dir = tempfile::tempdir().unwrap();
        let table = dir.path().join("m.csv");
        std::fs::write(&table, "t,Gx\n").unwrap();
        let h0 = experiment_hash("name = \"a\"\n", std::slice::from_ref(&table));
        // FNV-1a 64 of the bytes, written out: text, NUL, the table
        assert_eq!(h0, crate::hash::hex64(b"name = \"a\"\n\0t,Gx\n"));
        std::fs::write(&table, "t,Gy\n").unwrap();
        assert_ne!(experiment_hash("name = \"a\"\n", std::slice::from_ref(&table)), h0);
        assert_ne!(
            experiment_hash("name = \"b\"\n", &[]),
            experiment_hash("name = \"a\"\n", &[])
        );
    }
}
