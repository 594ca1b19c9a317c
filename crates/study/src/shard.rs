//! Slices of a study for clusters (`--shard K/N`) and the sidecar that says which study and which
//! cases a results table holds.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::StudyError;

/// The K-th of N disjoint slices (1 <= K <= N): the cases whose index i has `i % N == K - 1`
/// (round robin, so that slices of a sorted grid cost about the same).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl std::str::FromStr for Shard {
    type Err = StudyError;
    fn from_str(s: &str) -> Result<Self, StudyError> {
        let err = |reason: &str| StudyError::Shard {
            given: s.to_string(),
            reason: reason.to_string(),
        };
        let (k, n) = s.split_once('/').ok_or_else(|| err("expected K/N, e.g. 3/16"))?;
        let k: usize = k.trim().parse().map_err(|_| err("K is not a whole number"))?;
        let n: usize = n.trim().parse().map_err(|_| err("N is not a whole number"))?;
        if n == 0 || k == 0 || k > n {
            return Err(err("need 1 <= K <= N (shards are numbered from 1)"));
        }
        Ok(Shard { k, n })
    }
}

impl Shard {
    /// Whether case `index` belongs to this shard.
    pub fn holds(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }

    /// Index in the study of the j-th case of this shard.
    pub fn study_index(&self, j: usize) -> usize {
        j * self.n + self.k - 1
    }
}

/// `results.csv`, or `results.shard-K-of-N.csv` for a shard.
pub fn results_file(dir: &Path, shard: Option<Shard>) -> PathBuf {
    match shard {
        None => dir.join("results.csv"),
        Some(s) => dir.join(format!("results.shard-{}-of-{}.csv", s.k, s.n)),
    }
}

/// The sidecar of a results table: `results.csv` -> `results.meta.json`.
pub fn meta_file(results: &Path) -> PathBuf {
    results.with_extension("meta.json")
}

/// Publish a results table and its sidecar together (a kill or a full disk between the two
/// leaves the old pair): both in the table's folder.
pub fn write_pair(results: &Path, table: &crate::table::Table, meta: &Meta) -> Result<(), StudyError> {
    let dir = results.parent().unwrap_or(Path::new("."));
    let name = |p: &Path| p.file_name().and_then(|s| s.to_str()).unwrap_or_default().to_string();
    let mut set = flexstar_io::run_set::RunSet::begin(dir)?;
    table.stage(&mut set, &name(results))?;
    meta.stage(&mut set, &name(&meta_file(results)))?;
    set.commit()?;
    Ok(())
}

/// The sidecar JSON beside every results table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// Study name.
    pub study: String,
    /// Hash of the study and base files ([`crate::Study::hash`]).
    pub hash: String,
    /// The study file, as given.
    pub study_file: String,
    /// The varied keys in order.
    pub keys: Vec<String>,
    /// The solvers in order.
    pub solvers: Vec<String>,
    /// Number of levels of each key when the study is a grid; empty for a Latin hypercube.
    pub grid_levels: Vec<usize>,
    /// Which slice this table holds, `[K, N]`; `None` for the whole study.
    pub shard: Option<[usize; 2]>,
    /// Cases in the whole study.
    pub total_cases: usize,
    /// Run ids of the cases this table is to hold, in the study's order.
    pub cases: Vec<String>,
}

impl Meta {
    /// Read a sidecar.
    pub fn read(path: &Path) -> Result<Meta, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|source| StudyError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| StudyError::Results {
            file: path.to_path_buf(),
            reason: e.to_string(),
        })
    }

    /// Write a sidecar, whole or not at all.
    pub fn write(&self, path: &Path) -> Result<(), StudyError> {
        flexstar_io::output::write_string_atomically(path, &self.text())?;
        Ok(())
    }

    /// Stage the sidecar as file `name` of a run set (published with its table).
    pub fn stage(&self, set: &mut flexstar_io::run_set::RunSet, name: &str) -> Result<(), StudyError> {
        set.text(name, &self.text())?;
        Ok(())
    }

    fn text(&self) -> String {
        serde_json::to_string_pretty(self).expect("a sidecar of plain data serialises") + "\n"
    }

    /// `, shard K/N` for a slice, nothing for the whole study (for messages).
    pub fn shard_text(&self) -> String {
        shard_text(self.shard)
    }
}

/// `, shard K/N` for a slice `[K, N]`, nothing for the whole study (`None`): what messages show.
pub fn shard_text(shard: Option<[usize; 2]>) -> String {
    shard.map(|[k, n]| format!(", shard {k}/{n}")).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_shown_as_k_of_n_and_a_whole_study_as_nothing() {
        assert_eq!(shard_text(Some([2, 4])), ", shard 2/4");
        assert_eq!(shard_text(None), "");
    }

    #[test]
    fn shards_partition_the_cases() {
        let n = 4;
        let shards: Vec<Shard> = (1..=n).map(|k| format!("{k}/{n}").parse().unwrap()).collect();
        for i in 0..23 {
            assert_eq!(shards.iter().filter(|s| s.holds(i)).count(), 1, "case {i}");
        }
        let s = shards[2];
        let held: Vec<usize> = (0..23).filter(|&i| s.holds(i)).collect();
        assert!(held.iter().enumerate().all(|(j, &i)| s.study_index(j) == i));
        for bad in ["0/4", "5/4", "1/0", "x/2", "3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
