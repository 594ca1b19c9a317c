//! A run's files are one unit (`docs/outputs.md`): runs killed with SIGKILL at spread-out points,
//! runs that hit a file-size limit (a full disk) and concurrent runs into one folder each leave,
//! after the next start, either the complete old set or the complete new one, and no temporary.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;

/// 30 ms (old) or 40 ms (new) of case 3 with 5 free-free modes: same file names, other contents.
fn config(t_end: f64) -> String {
    let text = common::TINY.replace("name = \"tiny\"", "name = \"unit\"");
    assert!(text.contains("t_end = 0.03"));
    text.replace("t_end = 0.03", &format!("t_end = {t_end}"))
}

const STEMS: [&str; 3] = ["amm-free-free.csv", "amm-free-free-shapes.csv", "amm-free-free.json"];

/// What identifies a set: the two CSVs byte for byte and the sidecar's resolved experiment (its
/// date and wall time differ from run to run).
type Set = Vec<String>;

fn read_set(dir: &Path) -> Option<Set> {
    let mut v = Vec::new();
    for name in STEMS {
        let text = std::fs::read_to_string(dir.join(name)).ok()?;
        if name.ends_with(".json") {
            let doc: serde_json::Value = serde_json::from_str(&text).expect("a complete sidecar");
            v.push(doc["experiment"].to_string());
        } else {
            v.push(text);
        }
    }
    Some(v)
}

fn run_cmd(cfg: &Path, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_flexstar"));
    c.args(["run", "--solver", "amm", "--out"])
        .arg(out)
        .arg(cfg)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// Temporaries, journals and locks left in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".flexstar"))
        .collect()
}

struct Fixture {
    _tmp: tempfile::TempDir,
    old_cfg: std::path::PathBuf,
    new_cfg: std::path::PathBuf,
    old: Set,
    new: Set,
    /// How long one run takes here.
    took: Duration,
}

fn fixture() -> Fixture {
    let tmp = tempfile::tempdir().unwrap();
    let old_cfg = tmp.path().join("old.toml");
    let new_cfg = tmp.path().join("new.toml");
    std::fs::write(&old_cfg, config(0.03)).unwrap();
    std::fs::write(&new_cfg, config(0.04)).unwrap();
    let reference = |cfg: &Path, name: &str| {
        let out = tmp.path().join(name);
        let started = Instant::now();
        assert!(run_cmd(cfg, &out).status().unwrap().success());
        (read_set(&out.join("unit")).unwrap(), started.elapsed())
    };
    let (old, _) = reference(&old_cfg, "ref-old");
    let (new, took) = reference(&new_cfg, "ref-new");
    assert_ne!(old, new);
    Fixture {
        _tmp: tmp,
        old_cfg,
        new_cfg,
        old,
        new,
        took,
    }
}

impl Fixture {
    /// A fresh folder holding the complete old set.
    fn folder(&self, name: &str) -> std::path::PathBuf {
        let out = self.old_cfg.parent().unwrap().join(name);
        assert!(run_cmd(&self.old_cfg, &out).status().unwrap().success());
        out
    }

    /// After the next start (the recovery every writer and reader of flexstar runs first): the
    /// old or the new set whole, and nothing of flexstar's own left.
    fn assert_whole(&self, run_dir: &Path, what: &str) -> bool {
        flexstar_io::run_set::recover(run_dir).unwrap();
        let set = read_set(run_dir);
        let is_new = set.as_ref() == Some(&self.new);
        assert!(
            is_new || set.as_ref() == Some(&self.old),
            "{what}: a mixed or missing set"
        );
        assert!(leftovers(run_dir).is_empty(), "{what}: left {:?}", leftovers(run_dir));
        is_new
    }
}

#[cfg(unix)]
#[test]
fn killed_runs_leave_the_old_or_the_new_set() {
    let f = fixture();
    let out = f.folder("killed");
    let run_dir = out.join("unit");
    // kill times spread over the whole run (start-up, solve, writing) by a fixed LCG
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let (mut new, mut old) = (0, 0);
    for k in 0..24 {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let frac = (seed >> 11) as f64 / (1u64 << 53) as f64;
        let cfg = if k % 2 == 0 { &f.new_cfg } else { &f.old_cfg };
        let mut child = run_cmd(cfg, &out).spawn().unwrap();
        std::thread::sleep(f.took.mul_f64(1.2 * frac));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        if f.assert_whole(&run_dir, &format!("kill {k} at {:.0} % of a run", 120.0 * frac)) {
            new += 1;
        } else {
            old += 1;
        }
    }
    eprintln!("after 24 kills: {new} new sets, {old} old ones");
    // a stray temporary of a dead writer is removed by the next run itself
    let stray = run_dir.join(format!(".flexstar-{}-dead00.tmp", i32::MAX));
    std::fs::write(&stray, "x").unwrap();
    assert!(run_cmd(&f.new_cfg, &out).status().unwrap().success());
    assert!(leftovers(&run_dir).is_empty(), "{:?}", leftovers(&run_dir));
}

/// A disk that fills during a rerun: a file-size limit (`ulimit -f`, SIGXFSZ ignored so that the
/// write fails with EFBIG as on a full disk) at several levels below and above the run's files.
#[cfg(unix)]
#[test]
fn a_full_disk_keeps_the_old_set() {
    let f = fixture();
    let out = f.folder("full");
    let run_dir = out.join("unit");
    let largest = f.new.iter().map(|s| s.len()).max().unwrap();
    let mut failed = 0;
    for kib in [1, 2, 4, 8, 16, 32, 64, (largest / 1024 + 8).max(128)] {
        let script =
            format!("trap '' XFSZ; ulimit -f {kib}; exec \"$0\" run --solver amm --out \"$1\" \"$2\" 2>/dev/null");
        let status = Command::new("bash")
            .args(["-c", &script, env!("CARGO_BIN_EXE_flexstar")])
            .arg(&out)
            .arg(&f.new_cfg)
            .status()
            .unwrap();
        let is_new = f.assert_whole(&run_dir, &format!("limit {kib} KiB"));
        assert_eq!(
            is_new,
            status.success(),
            "limit {kib} KiB: exit {status} but new set {is_new}"
        );
        if !is_new {
            failed += 1;
            // back to the old set for the next level
            assert!(run_cmd(&f.old_cfg, &out).status().unwrap().success());
        }
    }
    assert!(failed >= 1, "no level was small enough to fail");
    assert_eq!(
        read_set(&run_dir).as_ref(),
        Some(&f.new),
        "the largest limit lets the run through"
    );
}

#[cfg(unix)]
#[test]
fn concurrent_runs_into_one_folder_leave_one_whole_set() {
    let f = fixture();
    let out = f.folder("concurrent");
    let run_dir = out.join("unit");
    for k in 0..6 {
        let mut a = run_cmd(&f.new_cfg, &out).spawn().unwrap();
        let mut b = run_cmd(&f.old_cfg, &out).spawn().unwrap();
        assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
        f.assert_whole(&run_dir, &format!("trial {k}"));
    }
}
