//! Joining the shards of a study (`results.shard-K-of-N.csv`) into one `results.csv` in the
//! study's case order, refusing shards of different studies or splits and reporting cases that
//! are missing or written twice.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use crate::error::StudyError;
use crate::shard::{meta_file, results_file, write_pair, Meta};
use crate::table::Table;

/// What a merge found and wrote.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MergeReport {
    /// The merged table.
    pub results: PathBuf,
    /// N of the shards.
    pub shards: usize,
    /// Shard numbers K with no table.
    pub missing_shards: Vec<usize>,
    /// Cases of the shards that are present but lack a row: `(run_id, solver)`; the cases of
    /// missing shards are not listed (their ids are unknown without the study).
    pub missing: Vec<(String, String)>,
    /// Cases missing with the missing shards.
    pub missing_in_missing_shards: usize,
    /// `(run_id, solver)` pairs found more than once (the first row is kept).
    pub duplicates: Vec<(String, String)>,
    /// Rows of cases that the shard's sidecar does not list (dropped).
    pub unexpected: Vec<(String, String)>,
    /// Rows written.
    pub rows: usize,
}

impl MergeReport {
    /// Whether every case of the study has all its rows.
    pub fn complete(&self) -> bool {
        self.missing_shards.is_empty() && self.missing.is_empty()
    }
}

/// `(K, N)` of a file named `results.shard-K-of-N.csv`.
fn shard_of(name: &str) -> Option<(usize, usize)> {
    let rest = name.strip_prefix("results.shard-")?.strip_suffix(".csv")?;
    let (k, n) = rest.split_once("-of-")?;
    Some((k.parse().ok()?, n.parse().ok()?))
}

/// Merge the shards found in `dir` (a study's results folder, `<out>/<name>`) into
/// `dir/results.csv` and its sidecar. Nothing is written when the shards belong to different
/// studies (hash of the study and base files) or splits, or when a `results.csv` already there is
/// of another study; the rows of such a `results.csv` of the same study that no shard holds are
/// kept (a whole-study rerun that filled gaps). Missing and duplicated cases are reported, and
/// the rows present are still written.
pub fn merge(dir: &Path) -> Result<MergeReport, StudyError> {
    let refuse = |reason: String| StudyError::Merge {
        dir: dir.to_path_buf(),
        reason,
    };
    flexstar_io::run_set::recover(dir)?;
    let entries = std::fs::read_dir(dir).map_err(|source| StudyError::Read {
        file: dir.to_path_buf(),
        source,
    })?;
    let mut found: Vec<(usize, usize, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            shard_of(&name).map(|(k, n)| (k, n, e.path()))
        })
        .collect();
    found.sort();
    let Some(&(_, n, ref first)) = found.first() else {
        return Err(refuse("no results.shard-K-of-N.csv here".into()));
    };
    let mut shards: Vec<(usize, Meta, Table, PathBuf)> = Vec::new();
    for (k, nk, path) in &found {
        if *nk != n {
            return Err(refuse(format!(
                "shards of different splits: {} and {} (N = {n} and {nk}); merge one split at a time",
                first.display(),
                path.display()
            )));
        }
        let meta = Meta::read(&meta_file(path))?;
        let table = Table::read(path)?;
        shards.push((*k, meta, table, path.clone()));
    }
    let (_, m0, t0, p0) = &shards[0];
    for (k, meta, table, path) in &shards {
        if meta.hash != m0.hash || meta.study != m0.study {
            return Err(refuse(format!(
                "refusing to merge {} (study {}, hash {}) with {} (study {}, hash {}): different study or base files",
                path.display(),
                meta.study,
                meta.hash,
                p0.display(),
                m0.study,
                m0.hash
            )));
        }
        if meta.shard != Some([*k, n]) {
            let says = match meta.shard {
                Some([a, b]) => format!("shard {a}/{b}"),
                None => "the whole study (no shard)".to_string(),
            };
            return Err(refuse(format!("{}: its sidecar says {says}", path.display())));
        }
        if table.header != t0.header {
            return Err(refuse(format!(
                "{}: header differs from {}",
                path.display(),
                p0.display()
            )));
        }
    }
    let existing = existing_results(dir, m0, t0)?;
    join(dir, n, &shards, existing)
}

/// The `results.csv` already in `dir`, if any: it must be of the same study (hash and name) and
/// header as the shards, else the merge is refused (nothing is written).
fn existing_results(dir: &Path, m0: &Meta, t0: &Table) -> Result<Option<(Meta, Table)>, StudyError> {
    let path = results_file(dir, None);
    if !path.exists() {
        return Ok(None);
    }
    let refuse = |reason: String| StudyError::Results {
        file: path.clone(),
        reason,
    };
    let meta_path = meta_file(&path);
    if !meta_path.exists() {
        return Err(refuse(format!(
            "exists without its sidecar {}: cannot tell which study wrote it (move it away to merge here)",
            meta_path.display()
        )));
    }
    let meta = Meta::read(&meta_path)?;
    if meta.hash != m0.hash || meta.study != m0.study || meta.shard.is_some() {
        return Err(refuse(format!(
            "was written by another study (study {}, hash {}{}; the shards: study {}, hash {}): \
             move it away or merge the shards in another folder",
            meta.study,
            meta.hash,
            meta.shard_text(),
            m0.study,
            m0.hash
        )));
    }
    let table = Table::read(&path)?;
    if table.header != t0.header {
        return Err(refuse("its header is not the shards' one".into()));
    }
    Ok(Some((meta, table)))
}

type Shards = [(usize, Meta, Table, PathBuf)];

/// Global index of each expected case: the j-th case of shard K is case j N + K - 1; a whole
/// study's earlier results.csv lists every case in order.
fn case_index(n: usize, shards: &Shards, existing: Option<&(Meta, Table)>) -> HashMap<String, usize> {
    let mut index: HashMap<String, usize> = HashMap::new();
    if let Some((meta, _)) = existing.filter(|(m, _)| m.cases.len() == m.total_cases) {
        index.extend(meta.cases.iter().enumerate().map(|(i, id)| (id.clone(), i)));
    }
    for (k, meta, _, _) in shards {
        for (j, id) in meta.cases.iter().enumerate() {
            index.insert(id.clone(), j * n + k - 1);
        }
    }
    index
}

/// The shards' rows, each (case, solver) once; rows of cases a shard does not own and repeated
/// rows go to the report. Returns the rows and the (case, solver) pairs seen.
fn shard_rows(
    shards: &Shards,
    solver_col: usize,
    report: &mut MergeReport,
) -> (Vec<Vec<String>>, HashSet<(String, String)>) {
    let mut seen: HashSet<(String, String)> = HashSet::new();
    let mut rows: Vec<Vec<String>> = Vec::new();
    for (_, meta, table, _) in shards {
        let mine: HashSet<&String> = meta.cases.iter().collect();
        for r in &table.rows {
            let key = (r[0].clone(), r[solver_col].clone());
            if !mine.contains(&r[0]) {
                report.unexpected.push(key);
            } else if !seen.insert(key.clone()) {
                report.duplicates.push(key);
            } else {
                rows.push(r.clone());
            }
        }
    }
    (rows, seen)
}

fn join(dir: &Path, n: usize, shards: &Shards, existing: Option<(Meta, Table)>) -> Result<MergeReport, StudyError> {
    let (_, m0, t0, _) = &shards[0];
    let solver_col = t0.column("solver").unwrap_or(0);
    let mut report = MergeReport {
        results: results_file(dir, None),
        shards: n,
        ..MergeReport::default()
    };
    let mut index = case_index(n, shards, existing.as_ref());
    let (mut rows, mut seen) = shard_rows(shards, solver_col, &mut report);
    // rows of the earlier results.csv that no shard holds are kept (a shard's row wins)
    let mut earlier_ids: Vec<String> = Vec::new();
    if let Some((meta, table)) = &existing {
        earlier_ids.clone_from(&meta.cases);
        for r in &table.rows {
            if seen.insert((r[0].clone(), r[solver_col].clone())) {
                rows.push(r.clone());
            }
        }
    }
    let present: HashSet<usize> = shards.iter().map(|s| s.0).collect();
    let whole_earlier = existing.as_ref().is_some_and(|(m, _)| m.cases.len() == m.total_cases);
    let mut expected: Vec<&String> = shards.iter().flat_map(|s| &s.1.cases).collect();
    for k in (1..=n).filter(|k| !present.contains(k)) {
        if whole_earlier {
            // the cases of a missing shard are known from the whole study's table
            expected.extend(earlier_ids.iter().skip(k - 1).step_by(n));
        } else {
            report.missing_shards.push(k);
            report.missing_in_missing_shards += (m0.total_cases + n - k) / n;
        }
    }
    for id in expected {
        for s in &m0.solvers {
            if !seen.contains(&(id.clone(), s.clone())) {
                report.missing.push((id.clone(), s.clone()));
            }
        }
    }
    let rank = |s: &str| m0.solvers.iter().position(|x| x == s).unwrap_or(usize::MAX);
    rows.sort_by_key(|r| (index.get(&r[0]).copied().unwrap_or(usize::MAX), rank(&r[solver_col])));
    for id in earlier_ids {
        let next = index.len();
        index.entry(id).or_insert(usize::MAX / 2 + next);
    }
    let mut ids: Vec<(usize, String)> = index.into_iter().map(|(id, i)| (i, id)).collect();
    ids.sort();
    report.rows = rows.len();
    let table = Table {
        header: t0.header.clone(),
        rows,
    };
    let meta = Meta {
        shard: None,
        cases: ids.into_iter().map(|(_, id)| id).collect(),
        ..m0.clone()
    };
    write_pair(&report.results, &table, &meta)?;
    Ok(report)
}
