//! Result files: written whole or not at all (into a temporary file beside the target, then
//! renamed over it), with the permissions of any new file (`0666` less the umask, not the
//! temporary file's `0600`), and numbers in the shortest form that reads back exactly.

use std::io::Write;
use std::path::Path;

use crate::run_set::RunSet;
use crate::WriteError;

/// A temporary file `dir/.flexstar-<pid>-XXXXXX<suffix>`, created with mode `0666` less the
/// process umask (as `File::create` would), so that the result it becomes has normal permissions.
/// The process id in the name lets a later writer remove the temporaries of a killed one
/// ([`crate::run_set::recover`]).
pub fn temp_file_in(dir: &Path, suffix: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    let prefix = format!(".flexstar-{}-", std::process::id());
    b.prefix(&prefix).suffix(suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
}

/// Write `path` through `fill`; on any error nothing is left at `path` (an older file is kept).
pub fn write_atomically<F>(path: &Path, fill: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
{
    let err = |reason: String| WriteError {
        file: path.to_path_buf(),
        reason,
    };
    let dir = parent_dir(path);
    std::fs::create_dir_all(&dir).map_err(|e| err(e.to_string()))?;
    let mut tmp = temp_file_in(&dir, ".tmp").map_err(|e| err(e.to_string()))?;
    {
        let mut buf = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buf).map_err(|e| err(e.to_string()))?;
        buf.flush().map_err(|e| err(e.to_string()))?;
    }
    tmp.persist(path).map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// Where one result file goes: alone (written atomically) or staged into a [`RunSet`] under a
/// file name of its folder.
pub enum Dest<'a> {
    /// A file of its own, written by [`write_atomically`].
    File(&'a Path),
    /// File `name` of a set, published with the others by [`RunSet::commit`].
    Set(&'a mut RunSet, &'a str),
}

impl Dest<'_> {
    /// The path the file has once written.
    pub fn path(&self) -> std::path::PathBuf {
        match self {
            Dest::File(p) => p.to_path_buf(),
            Dest::Set(set, name) => set.path(name),
        }
    }

    /// Write (or stage) the file through `fill`.
    pub fn write<F>(self, fill: F) -> Result<(), WriteError>
    where
        F: FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
    {
        match self {
            Dest::File(p) => write_atomically(p, fill),
            Dest::Set(set, name) => set.file(name, fill).map(|_| ()),
        }
    }
}

fn parent_dir(path: &Path) -> std::path::PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    }
}

/// Write a string to `path`, whole or not at all.
pub fn write_string_atomically(path: &Path, text: &str) -> Result<(), WriteError> {
    write_atomically(path, |w| {
        w.write_all(text.as_bytes())?;
        Ok(())
    })
}

/// Create the directory `dir` (and its parents) and check that a file can be written in it, so
/// that a run fails before any work instead of after it (e.g. `--out` names an existing file, or
/// a read-only place). The probe file is removed again, and the folder is recovered from an
/// interrupted writer ([`crate::run_set::recover`]).
pub fn ensure_writable_dir(dir: &Path) -> Result<(), WriteError> {
    let err = |reason: String| WriteError {
        file: dir.to_path_buf(),
        reason,
    };
    if dir.exists() && !dir.is_dir() {
        return Err(err("exists and is not a directory".into()));
    }
    std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create the output directory: {e}")))?;
    temp_file_in(dir, ".probe").map_err(|e| err(format!("the output directory is not writable: {e}")))?;
    crate::run_set::recover(dir)
}

/// A number as written into result files: the shortest decimal that parses back to exactly the
/// same `f64` (plain or with an exponent, whichever is shorter; plain on a tie), and `0` for
/// both zeros (no `-0`). Non-finite values are written `NaN`, `inf`, `-inf`.
pub fn fmt_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    // Rust's `{}` and `{:e}` both print the shortest digits that round-trip
    let plain = format!("{v}");
    let sci = format!("{v:e}");
    if sci.len() < plain.len() {
        sci
    } else {
        plain
    }
}

/// A number as shown to a person (stderr, titles, reports): rounded to 12 significant digits,
/// then as [`fmt_number`] (so `0.49999999999999994` reads `0.5`, `-0.0` reads `0`). Files keep
/// [`fmt_number`], which reads back exactly.
pub fn fmt_display(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return fmt_number(v);
    }
    let rounded: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    fmt_number(rounded)
}

/// A measured or derived number as shown to a person (stderr, reports): rounded to `sig`
/// significant digits, then as [`fmt_number`] (`1.2908680383436644` with 5 reads `1.2909`,
/// `5.2620000000000005` reads `5.262`). Files keep [`fmt_number`].
pub fn fmt_sig(v: f64, sig: usize) -> String {
    if v == 0.0 || !v.is_finite() || sig == 0 {
        return fmt_number(v);
    }
    let rounded: f64 = format!("{v:.*e}", sig - 1).parse().unwrap_or(v);
    // plain for magnitudes a person reads as plain numbers (5000, not 5e3)
    if (1e-4..1e7).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        fmt_number(rounded)
    }
}

/// A bound the user must reach ("raise t_end to at least ..."), shown with `sig` significant
/// digits and rounded *up*, so that the value shown still satisfies the bound (up to a relative
/// 1e-15 of rounding noise: `0.30000000000000004` reads `0.3`).
pub fn fmt_at_least(v: f64, sig: usize) -> String {
    if v <= 0.0 || !v.is_finite() || sig == 0 {
        return fmt_sig(v, sig.max(1));
    }
    let scale = 10f64.powi(sig as i32 - 1 - v.log10().floor() as i32);
    let up = (v * scale * (1.0 - 1e-15)).ceil() / scale;
    fmt_sig(up.max(v), sig + 1)
}

/// `v` with `digits` decimals as shown to a person, without the sign of a value that rounds to
/// zero (`-0.000001` with 5 decimals reads `0.00000`, not `-0.00000`).
pub fn fmt_fixed(v: f64, digits: usize) -> String {
    let text = format!("{v:.digits$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_for_people_keep_the_digits_that_mean_something() {
        assert_eq!(fmt_sig(5.2620000000000005, 5), "5.262");
        assert_eq!(fmt_sig(1.2908680383436644, 5), "1.2909");
        assert_eq!(fmt_sig(0.3, 5), "0.3");
        assert_eq!(fmt_sig(1e308, 4), "1e308");
        assert_eq!(fmt_sig(4999.99, 4), "5000");
        assert_eq!(fmt_sig(-2.65050407285505e-9, 3), "-2.65e-9");
        // a bound rounds up, never below the value
        assert_eq!(fmt_at_least(1.2908680383436644, 5), "1.2909");
        assert_eq!(fmt_at_least(1.29081, 5), "1.2909");
        assert_eq!(fmt_at_least(0.5, 5), "0.5");
        for v in [1.2908680383436644, 0.30000000000000004, 12.07351, 9.99999999] {
            let shown: f64 = fmt_at_least(v, 5).parse().unwrap();
            // up to rounding noise (1e-12 relative), which the bounds checked allow
            assert!(shown >= v * (1.0 - 1e-12), "{v} shown as {shown}");
        }
    }

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

    #[cfg(unix)]
    #[test]
    fn new_files_get_the_permissions_of_file_create() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        // reference: what File::create gives under this process's umask
        let reference = dir.path().join("reference");
        std::fs::File::create(&reference).unwrap();
        let want = std::fs::metadata(&reference).unwrap().permissions().mode() & 0o777;
        let path = dir.path().join("x.csv");
        write_string_atomically(&path, "a\n").unwrap();
        let got = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(got, want, "got {got:o}, File::create gives {want:o}");
        assert_ne!(got & 0o044, 0, "readable by others under the usual umask 022 ({got:o})");
    }

    #[test]
    fn numbers_are_shortest_and_read_back_exactly() {
        assert_eq!(fmt_number(0.0), "0");
        assert_eq!(fmt_number(-0.0), "0");
        assert_eq!(fmt_number(0.5), "0.5");
        assert_eq!(fmt_number(0.001), "1e-3");
        assert_eq!(fmt_number(0.01), "0.01");
        assert_eq!(fmt_number(1.5e-7), "1.5e-7");
        assert_eq!(fmt_number(-2.0), "-2");
        assert_eq!(fmt_number(123456789.0), "123456789");
        assert_eq!(fmt_number(1e21), "1e21");
        // exact read-back over a spread of magnitudes and awkward values
        let mut x = 0.1f64;
        for k in 0..2000 {
            let v = if k % 2 == 0 { x } else { -x / 3.0 };
            let s = fmt_number(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{v:e} -> {s}");
            assert!(s.len() <= format!("{v:e}").len() && s.len() <= format!("{v}").len());
            x *= 1.0373;
            if x > 1e150 {
                x = 1e-150;
            }
        }
    }

    #[test]
    fn numbers_for_people_are_rounded_and_have_no_negative_zero() {
        // the paper robot's EI: E I computed in floating point
        assert_eq!(fmt_display(0.49999999999999994), "0.5");
        assert_eq!(fmt_display(0.1 + 0.2), "0.3");
        assert_eq!(fmt_display(-0.0), "0");
        assert_eq!(fmt_display(2.1e11), "2.1e11");
        assert_eq!(fmt_display(1.5e-7), "1.5e-7");
        assert_eq!(fmt_display(0.234), "0.234");
        assert_eq!(fmt_display(123.456789012345), "123.456789012");
        assert_eq!(fmt_display(f64::NAN), "NaN");
        assert_eq!(fmt_fixed(-0.0, 5), "0.00000");
        assert_eq!(fmt_fixed(-0.000004, 5), "0.00000");
        assert_eq!(fmt_fixed(-0.000006, 5), "-0.00001");
        assert_eq!(fmt_fixed(-1.5, 2), "-1.50");
        assert_eq!(fmt_fixed(-0.4, 0), "0");
        assert_eq!(fmt_fixed(0.123456, 3), "0.123");
    }

    #[test]
    fn unwritable_output_is_found_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("plain-file");
        std::fs::write(&file, "x").unwrap();
        let e = ensure_writable_dir(&file).unwrap_err().to_string();
        assert!(e.contains("plain-file") && e.contains("not a directory"), "{e}");
        let e = ensure_writable_dir(&file.join("sub")).unwrap_err().to_string();
        assert!(e.contains("plain-file"), "{e}");
        let ok = dir.path().join("a/b");
        ensure_writable_dir(&ok).unwrap();
        assert_eq!(std::fs::read_dir(&ok).unwrap().count(), 0, "the probe is removed");
    }
}
