//! Result files are written whole or not at all: into a temporary file beside the target, then
//! renamed over it.

use std::io::Write;
use std::path::Path;

use crate::error::ModelError;

/// Write `path` through `fill`; on any error nothing is left at `path` (an older file is kept).
pub fn write_atomically<F>(path: &Path, fill: F) -> Result<(), ModelError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
{
    let err = |reason: String| ModelError::Write {
        file: path.to_path_buf(),
        reason,
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| err(e.to_string()))?;
    let mut tmp = tempfile::NamedTempFile::new_in(&dir).map_err(|e| err(e.to_string()))?;
    {
        let mut buf = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buf).map_err(|e| err(e.to_string()))?;
        buf.flush().map_err(|e| err(e.to_string()))?;
    }
    tmp.persist(path).map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// Write a string to `path`, whole or not at all.
pub fn write_string_atomically(path: &Path, text: &str) -> Result<(), ModelError> {
    write_atomically(path, |w| {
        w.write_all(text.as_bytes())?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_fill_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.csv");
        let r = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err("boom".into())
        });
        assert!(r.is_err());
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
