//! Expansion of a study's `[[vary]]` entries into cases: full-factorial grids and Latin
//! hypercubes, with run ids derived from the parameter values.

use crate::hash::hex64;
use crate::patch::value_text;
use crate::shard::Shard;
use crate::spec::{Levels, Sampling, Study, Vary};

/// One point of the study: a value for each varied key, in the study's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Position in the study's case order (0-based); shard K of N holds the indices i with
    /// `i % N == K - 1`.
    pub index: usize,
    /// Stable id: [`run_id`] of the values.
    pub run_id: String,
    pub values: Vec<toml::Value>,
}

/// The run id of a case: 16 hex digits of the FNV-1a hash of `key=value` lines (values as written
/// in the results table). The same values give the same id in every run, shard and machine.
pub fn run_id(keys: &[String], values: &[toml::Value]) -> String {
    let text: String = keys
        .iter()
        .zip(values)
        .map(|(k, v)| format!("{k}={}\n", value_text(v)))
        .collect();
    hex64(text.as_bytes())
}

/// `x` rounded to 12 significant digits, so that generated points read 0.0002 rather than
/// 0.00019999999999999998.
pub fn tidy(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.11e}").parse().unwrap_or(x)
}

impl Vary {
    /// The grid levels, duplicates removed (first kept).
    pub fn grid_values(&self) -> Vec<toml::Value> {
        let raw: Vec<toml::Value> = match &self.levels {
            Levels::Values(v) => v.clone(),
            Levels::Linspace { a, b, n, integer } => {
                let pts: Vec<f64> = (0..*n)
                    .map(|k| {
                        if *n == 1 {
                            *a
                        } else {
                            a + (b - a) * k as f64 / (*n - 1) as f64
                        }
                    })
                    .map(tidy)
                    .collect();
                if *integer && pts.iter().all(|p| p.fract() == 0.0) {
                    pts.into_iter().map(|p| toml::Value::Integer(p as i64)).collect()
                } else {
                    pts.into_iter().map(toml::Value::Float).collect()
                }
            }
            Levels::Normal { mean, .. } => vec![toml::Value::Float(*mean)],
            Levels::Uniform { lo, hi } => vec![toml::Value::Float(*lo), toml::Value::Float(*hi)],
            Levels::Logspace { a, b, n } => (0..*n)
                .map(|k| {
                    if *n == 1 {
                        *a
                    } else {
                        a * (b / a).powf(k as f64 / (*n - 1) as f64)
                    }
                })
                .map(|p| toml::Value::Float(tidy(p)))
                .collect(),
        };
        // duplicates by their text in the table (1 and 1.0 are one level: one run id)
        let mut seen = std::collections::HashSet::with_capacity(raw.len());
        raw.into_iter().filter(|v| seen.insert(value_text(v))).collect()
    }

    /// The values the key check patches in: every listed value; the two bounds of a range.
    pub fn probe_values(&self) -> Vec<toml::Value> {
        match &self.levels {
            Levels::Values(v) => v.clone(),
            _ => {
                let g = self.grid_values();
                let mut out = vec![g[0].clone()];
                if let Some(last) = g.last().filter(|l| **l != g[0]) {
                    out.push(last.clone());
                }
                out
            }
        }
    }

    /// The value at `u` in [0, 1) of the key's range: uniform for linspace and uniform,
    /// log-uniform for logspace, the `floor(u * len)`-th entry of a values list, the quantile `u`
    /// of a normal distribution (statrs' inverse CDF; `u = 0` is moved to the smallest positive
    /// double, so every draw is finite).
    fn at(&self, u: f64) -> toml::Value {
        match &self.levels {
            Levels::Normal { mean, sd } => {
                use statrs::distribution::{ContinuousCDF, Normal};
                let q = Normal::new(*mean, *sd).map_or(*mean, |n| n.inverse_cdf(u.max(f64::MIN_POSITIVE)));
                toml::Value::Float(tidy(q))
            }
            Levels::Uniform { lo, hi } => toml::Value::Float(tidy(lo + (hi - lo) * u)),
            Levels::Values(v) => v[((u * v.len() as f64) as usize).min(v.len() - 1)].clone(),
            Levels::Linspace { a, b, .. } => toml::Value::Float(tidy(a + (b - a) * u)),
            Levels::Logspace { a, b, .. } => toml::Value::Float(tidy(a * (b / a).powf(u))),
        }
    }
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny, seedable generator, identical everywhere.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniformly random permutation of 0..n (Fisher-Yates).
    fn permutation(&mut self, n: usize) -> Vec<usize> {
        let mut p: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = (self.next_u64() % (i as u64 + 1)) as usize;
            p.swap(i, j);
        }
        p
    }
}

/// The Latin hypercube's values, `samples` rows of one value per key: in every key's column, the
/// stratum `[s/n, (s+1)/n)` of the unit range holds exactly one point.
pub fn latin_hypercube(vary: &[Vary], samples: usize, seed: u64) -> Vec<Vec<toml::Value>> {
    let mut rng = SplitMix64(seed);
    let columns: Vec<Vec<toml::Value>> = vary
        .iter()
        .map(|v| {
            let strata = rng.permutation(samples);
            strata
                .into_iter()
                .map(|s| v.at((s as f64 + rng.unit()) / samples as f64))
                .collect()
        })
        .collect();
    (0..samples)
        .map(|i| columns.iter().map(|c| c[i].clone()).collect())
        .collect()
}

/// Monte Carlo draws: `samples` rows, each key's value drawn independently at a uniform `u`.
pub fn random_draws(vary: &[Vary], samples: usize, seed: u64) -> Vec<Vec<toml::Value>> {
    let mut rng = SplitMix64(seed);
    (0..samples)
        .map(|_| vary.iter().map(|v| v.at(rng.unit())).collect())
        .collect()
}

/// Every combination of the grid levels, the first key varying slowest.
pub fn full_factorial(vary: &[Vary]) -> Vec<Vec<toml::Value>> {
    vary.iter().fold(vec![Vec::new()], |acc, v| {
        let levels = v.grid_values();
        acc.into_iter()
            .flat_map(|prefix| {
                levels.iter().map(move |l| {
                    let mut p = prefix.clone();
                    p.push(l.clone());
                    p
                })
            })
            .collect()
    })
}

/// The `index`-th point of the full factorial of `levels` (the first key varying slowest).
fn grid_point(levels: &[Vec<toml::Value>], mut index: usize) -> Vec<toml::Value> {
    let mut values = vec![toml::Value::Boolean(false); levels.len()];
    for (v, l) in values.iter_mut().zip(levels).rev() {
        *v = l[index % l.len()].clone();
        index /= l.len();
    }
    values
}

impl Study {
    /// Number of cases of the study.
    pub fn case_count(&self) -> usize {
        match self.sampling {
            Sampling::Grid => self.vary.iter().map(|v| v.grid_values().len()).product(),
            Sampling::Lhs { .. } | Sampling::Random { .. } => self.cases().len(),
        }
    }

    /// The cases of one shard (`None`: of the whole study) in the study's order. For a grid they
    /// are made one at a time from their index, so that a shard of a study of [`MAX_CASES`]
    /// cases costs the memory of its own cases only; a Latin hypercube is drawn whole first
    /// (its strata are permutations of all samples).
    ///
    /// [`MAX_CASES`]: crate::spec::MAX_CASES
    pub fn shard_cases(&self, shard: Option<Shard>) -> Box<dyn Iterator<Item = Case> + '_> {
        let Sampling::Grid = self.sampling else {
            return Box::new(
                self.cases()
                    .into_iter()
                    .filter(move |c| shard.is_none_or(|s| s.holds(c.index))),
            );
        };
        let levels: Vec<Vec<toml::Value>> = self.vary.iter().map(Vary::grid_values).collect();
        let total: usize = levels.iter().map(Vec::len).product();
        let (first, step) = shard.map_or((0, 1), |s| (s.k - 1, s.n));
        let keys = self.keys();
        Box::new((first..total).step_by(step).map(move |index| {
            let values = grid_point(&levels, index);
            Case {
                index,
                run_id: run_id(&keys, &values),
                values,
            }
        }))
    }

    /// The study's cases in order, each once (a repeated point keeps its first position).
    pub fn cases(&self) -> Vec<Case> {
        let points = match self.sampling {
            Sampling::Grid => return self.shard_cases(None).collect(),
            Sampling::Lhs { samples, seed } => latin_hypercube(&self.vary, samples, seed),
            Sampling::Random { samples, seed } => random_draws(&self.vary, samples, seed),
        };
        let keys = self.keys();
        let mut seen = std::collections::HashSet::new();
        let mut cases = Vec::with_capacity(points.len());
        for values in points {
            let id = run_id(&keys, &values);
            if seen.insert(id.clone()) {
                cases.push(Case {
                    index: cases.len(),
                    run_id: id,
                    values,
                });
            }
        }
        cases
    }
}
