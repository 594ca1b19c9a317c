//! A run's files published as one unit: a reader of the folder sees either the complete old set
//! or the complete new one, never a mixture, even when the writer is killed or the disk fills.
//!
//! The protocol, for one folder `DIR`:
//! 1. [`RunSet::begin`] takes an exclusive advisory lock (`flock`) on `DIR/.flexstar.lock`, so
//!    that writers of one folder run one after the other (a second one waits), then recovers the
//!    folder (below);
//! 2. [`RunSet::file`] writes each file whole into a temporary `DIR/.flexstar-<pid>-XXXXXX.tmp`
//!    (flushed to disk); an error removes every temporary and leaves the old set untouched;
//! 3. [`RunSet::commit`] writes the journal `DIR/.flexstar-journal` (the renames to do and the
//!    files to remove) atomically, renames each temporary over its file, then removes the journal.
//!
//! Recovery, at the start of every writer and before a reader inside flexstar reads the folder
//! ([`recover`]): a journal left by a writer killed during step 3 is rolled forward (the renames
//! not yet done are done), and temporaries `.flexstar-<pid>-*` whose process `pid` is gone are
//! removed. The lock file is removed when the lock is released.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::WriteError;

/// Name of the journal of a commit in progress.
pub const JOURNAL: &str = ".flexstar-journal";
/// Name of the lock file of a folder (present only while a writer holds it).
pub const LOCK: &str = ".flexstar.lock";

/// What fills one staged file.
pub type Fill<'a> = dyn FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error + Send + Sync>> + 'a;

/// The staged files of one run in one folder, published together by [`RunSet::commit`]; dropped
/// without a commit, it removes its temporaries and publishes nothing.
pub struct RunSet {
    dir: PathBuf,
    lock: Option<FolderLock>,
    staged: Vec<(tempfile::TempPath, String)>,
    removals: Vec<String>,
}

impl RunSet {
    /// Lock `dir` (created if needed) for writing and recover it (see the module docs).
    pub fn begin(dir: &Path) -> Result<RunSet, WriteError> {
        std::fs::create_dir_all(dir).map_err(|e| write_error(dir, format!("cannot create the folder: {e}")))?;
        let lock = FolderLock::acquire(dir)?;
        recover_locked(dir)?;
        Ok(RunSet {
            dir: dir.to_path_buf(),
            lock: Some(lock),
            staged: Vec::new(),
            removals: Vec::new(),
        })
    }

    /// The folder of the set.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The path file `name` will have once published.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Stage file `name` (a plain file name in the folder) written by `fill`.
    pub fn file<F>(&mut self, name: &str, fill: F) -> Result<&mut RunSet, WriteError>
    where
        F: FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
    {
        let target = self.checked(name)?;
        let err = |reason: String| write_error(&target, reason);
        let mut tmp = crate::output::temp_file_in(&self.dir, ".tmp").map_err(|e| err(e.to_string()))?;
        {
            let mut buf = std::io::BufWriter::new(tmp.as_file_mut());
            fill(&mut buf).map_err(|e| err(e.to_string()))?;
            buf.flush().map_err(|e| err(e.to_string()))?;
        }
        tmp.as_file().sync_all().map_err(|e| err(e.to_string()))?;
        self.staged.retain(|(_, n)| n != name);
        self.staged.push((tmp.into_temp_path(), name.to_string()));
        Ok(self)
    }

    /// Stage a text file.
    pub fn text(&mut self, name: &str, text: &str) -> Result<&mut RunSet, WriteError> {
        self.file(name, |w| {
            w.write_all(text.as_bytes())?;
            Ok(())
        })
    }

    /// Remove file `name` of an older set when this one is published (a file the new run does not
    /// write); a missing file is no error.
    pub fn remove(&mut self, name: &str) -> Result<&mut RunSet, WriteError> {
        self.checked(name)?;
        self.removals.push(name.to_string());
        Ok(self)
    }

    fn checked(&self, name: &str) -> Result<PathBuf, WriteError> {
        let plain = !name.is_empty()
            && !name.starts_with(".flexstar")
            && !name.contains(['/', '\\', '\t', '\n'])
            && name != "."
            && name != "..";
        if plain {
            Ok(self.dir.join(name))
        } else {
            Err(write_error(
                &self.dir.join(name),
                "not a plain file name of a run".into(),
            ))
        }
    }

    /// Publish every staged file together (see the module docs) and release the folder.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let mut journal = String::new();
        for (tmp, name) in &self.staged {
            let t = tmp.file_name().and_then(|s| s.to_str()).unwrap_or_default();
            journal.push_str(&format!("rename\t{t}\t{name}\n"));
        }
        for name in &self.removals {
            journal.push_str(&format!("remove\t{name}\n"));
        }
        journal.push_str("end\n");
        let jpath = self.dir.join(JOURNAL);
        let mut jtmp =
            crate::output::temp_file_in(&self.dir, ".tmp").map_err(|e| write_error(&jpath, e.to_string()))?;
        jtmp.write_all(journal.as_bytes())
            .and_then(|_| jtmp.as_file().sync_all())
            .map_err(|e| write_error(&jpath, e.to_string()))?;
        jtmp.persist(&jpath).map_err(|e| write_error(&jpath, e.to_string()))?;
        sync_dir(&self.dir);
        // from here the journal owns the temporaries: a kill is rolled forward by the next start
        for (tmp, _) in std::mem::take(&mut self.staged) {
            let _ = tmp.keep();
        }
        roll_forward(&self.dir, &journal)?;
        if let Some(lock) = self.lock.take() {
            lock.release();
        }
        Ok(())
    }
}

impl Drop for RunSet {
    fn drop(&mut self) {
        // an uncommitted set: the staged TempPaths remove themselves; then the lock goes
        self.staged.clear();
        if let Some(lock) = self.lock.take() {
            lock.release();
        }
    }
}

/// Bring `dir` to a consistent state before reading it: roll a leftover journal forward and remove
/// dead writers' temporaries. A folder that does not exist, or that this process cannot write and
/// that holds no journal, is left as it is.
pub fn recover(dir: &Path) -> Result<(), WriteError> {
    if !dir.is_dir() {
        return Ok(());
    }
    match FolderLock::acquire(dir) {
        Ok(lock) => {
            let r = recover_locked(dir);
            lock.release();
            r
        }
        Err(_) if !dir.join(JOURNAL).exists() => Ok(()),
        Err(e) => Err(e),
    }
}

fn recover_locked(dir: &Path) -> Result<(), WriteError> {
    let jpath = dir.join(JOURNAL);
    match std::fs::read_to_string(&jpath) {
        Ok(text) => roll_forward(dir, &text)?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => {
            return Err(write_error(
                &jpath,
                format!("cannot read the journal of an interrupted write: {e}"),
            ))
        }
    }
    remove_dead_temporaries(dir);
    Ok(())
}

/// Do the renames and removals of `journal` not yet done, then remove the journal.
fn roll_forward(dir: &Path, journal: &str) -> Result<(), WriteError> {
    let jpath = dir.join(JOURNAL);
    let bad = |line: &str| write_error(&jpath, format!("unreadable journal line {line:?}"));
    if journal.lines().last() != Some("end") {
        return Err(write_error(&jpath, "the journal is incomplete (no end line)".into()));
    }
    for line in journal.lines() {
        let fields: Vec<&str> = line.split('\t').collect();
        match fields.as_slice() {
            ["rename", tmp, name] => {
                let from = dir.join(tmp);
                if from.exists() {
                    std::fs::rename(&from, dir.join(name)).map_err(|e| write_error(&dir.join(name), e.to_string()))?;
                }
            }
            ["remove", name] => match std::fs::remove_file(dir.join(name)) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(write_error(&dir.join(name), e.to_string()))
                }
                _ => {}
            },
            ["end"] => {}
            _ => return Err(bad(line)),
        }
    }
    sync_dir(dir);
    std::fs::remove_file(&jpath).map_err(|e| write_error(&jpath, e.to_string()))?;
    sync_dir(dir);
    Ok(())
}

/// The process id in a temporary's name `.flexstar-<pid>-XXXXXX.<ext>`.
fn owner_of(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(".flexstar-")?;
    let (pid, _) = rest.split_once('-')?;
    pid.parse().ok()
}

/// Whether process `pid` exists (on other systems than Unix: assumed to).
fn alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        match rustix::process::Pid::from_raw(pid as i32) {
            Some(p) => !matches!(rustix::process::test_kill_process(p), Err(e) if e == rustix::io::Errno::SRCH),
            None => true,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

fn remove_dead_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if let Some(pid) = owner_of(&name) {
            if pid != std::process::id() && !alive(pid) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

fn write_error(file: &Path, reason: String) -> WriteError {
    WriteError {
        file: file.to_path_buf(),
        reason,
    }
}

/// An exclusive `flock` on `DIR/.flexstar.lock`, removed on release (re-checked after locking, so
/// that a writer never holds the lock of a file another one has removed).
struct FolderLock {
    path: PathBuf,
    file: File,
}

impl FolderLock {
    fn acquire(dir: &Path) -> Result<FolderLock, WriteError> {
        let path = dir.join(LOCK);
        let err = |e: std::io::Error| write_error(&path, format!("cannot lock the folder: {e}"));
        loop {
            let file = std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)
                .map_err(err)?;
            lock_exclusive(&file).map_err(err)?;
            if same_file(&file, &path) {
                return Ok(FolderLock { path, file });
            }
        }
    }

    fn release(self) {
        let _ = std::fs::remove_file(&self.path);
        drop(self.file);
    }
}

#[cfg(unix)]
fn lock_exclusive(file: &File) -> std::io::Result<()> {
    rustix::fs::flock(file, rustix::fs::FlockOperation::LockExclusive).map_err(std::io::Error::from)
}

#[cfg(not(unix))]
fn lock_exclusive(_file: &File) -> std::io::Result<()> {
    Ok(())
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_set_is_published_whole_and_leaves_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let mut set = RunSet::begin(dir.path()).unwrap();
        set.text("a.csv", "1\n").unwrap().text("a.json", "{}\n").unwrap();
        assert_eq!(names(dir.path()).iter().filter(|n| !n.starts_with('.')).count(), 0);
        set.commit().unwrap();
        assert_eq!(names(dir.path()), ["a.csv", "a.json"]);
    }

    #[test]
    fn a_failed_file_keeps_the_old_set() {
        let dir = tempfile::tempdir().unwrap();
        let mut old = RunSet::begin(dir.path()).unwrap();
        old.text("a.csv", "old").unwrap();
        old.commit().unwrap();
        let mut set = RunSet::begin(dir.path()).unwrap();
        set.text("a.csv", "new").unwrap();
        let r = set.file("a.json", |_| Err("disk full".into())).map(|_| ());
        assert!(r.unwrap_err().to_string().contains("disk full"));
        drop(set);
        assert_eq!(names(dir.path()), ["a.csv"]);
        assert_eq!(std::fs::read_to_string(dir.path().join("a.csv")).unwrap(), "old");
    }

    #[test]
    fn a_leftover_journal_is_rolled_forward_and_dead_temporaries_removed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.csv"), "new-done").unwrap();
        std::fs::write(d.join("b.csv"), "old").unwrap();
        std::fs::write(d.join("gone.csv"), "old").unwrap();
        // a writer killed after renaming a.csv: b.csv's rename is left to do
        let dead = u32::MAX / 2; // above any pid_max (2^22): never a live process
        let tmp_b = format!(".flexstar-{dead}-abcdef.tmp");
        std::fs::write(d.join(&tmp_b), "new").unwrap();
        std::fs::write(d.join(format!(".flexstar-{dead}-zzzzzz.tmp")), "stray").unwrap();
        let live = format!(".flexstar-{}-keep00.tmp", std::process::id());
        std::fs::write(d.join(&live), "mine").unwrap();
        std::fs::write(
            d.join(JOURNAL),
            format!("rename\t.flexstar-{dead}-aaaaaa.tmp\ta.csv\nrename\t{tmp_b}\tb.csv\nremove\tgone.csv\nend\n"),
        )
        .unwrap();
        recover(d).unwrap();
        assert_eq!(names(d), [live.as_str(), "a.csv", "b.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("b.csv")).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "new-done");
    }

    #[test]
    fn names_outside_the_folder_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut set = RunSet::begin(dir.path()).unwrap();
        for bad in ["../x", "", ".flexstar-journal", "a/b"] {
            assert!(set.text(bad, "x").map(|_| ()).is_err(), "{bad}");
        }
    }
}
