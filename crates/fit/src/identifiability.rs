//! Can the data tell the parameters apart? (`docs/measured.md` 4.8, Eqs. LS15-LS16): the
//! condition number of the Jacobian in relative units with unit columns, and the combination of
//! parameters along its smallest singular vector, which the data do not fix.

use nalgebra::DMatrix;
use serde::Serialize;

use crate::problem::Param;

/// Above this condition number (Eq. LS15) the parameters are flagged as hard to separate: for two
/// parameters it is a correlation of their estimates beyond 0.9998 (`kappa = sqrt((1 + rho) / (1 -
/// rho))`), their standard errors inflated a hundredfold over separable ones.
pub const ILL_CONDITIONED: f64 = 1e2;
/// Above this condition number the Jacobian is rank-deficient within its accuracy: a singular
/// value below 1e-4 of the largest is of the size of the forward differences' own error (Eq. LS9:
/// 5e-5 to 4e-4 of a column measured on the AMM, `docs/measured.md` 4.5), so the data say nothing
/// along its direction.
pub const RANK_DEFICIENT: f64 = 1e4;
/// Entries of the combination smaller than this share of its largest are left out of its name.
const NAMED_SHARE: f64 = 0.05;

/// The verdict of Eq. LS15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// `kappa <= ILL_CONDITIONED`.
    Identifiable,
    /// `ILL_CONDITIONED < kappa <= RANK_DEFICIENT`: estimated, with large correlated errors.
    IllConditioned,
    /// `kappa > RANK_DEFICIENT` (or a parameter the residuals do not depend on).
    RankDeficient,
}

/// Eq. LS16: the direction in parameter space along which the residuals change least, in relative
/// units (`d ln theta_j`) for a parameter away from zero and in units of its box
/// (`d theta_j / (hi_j - lo_j)`) otherwise, of unit length.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Combination {
    /// `(key, entry, relative)`: the parameters with an entry of at least 5 % of the largest, in
    /// the order of the parameters, the first positive; `relative` false: the entry is in units
    /// of the box.
    pub entries: Vec<(String, f64, bool)>,
    /// For two relative entries `(a, b)`: the product `theta_1^e1 theta_2^e2` that the data do fix
    /// (exponents `(b, -a)` scaled to a largest of 1), as text.
    pub determined: Option<String>,
}

impl Combination {
    /// `d ln robot.E = +0.707, d ln robot.I = -0.707`.
    pub fn direction_text(&self) -> String {
        self.entries
            .iter()
            .map(|(k, c, rel)| {
                if *rel {
                    format!("d ln {k} = {c:+.3}")
                } else {
                    format!("d {k} / (hi - lo) = {c:+.3}")
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The result of the check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identifiability {
    pub verdict: Verdict,
    /// Eq. LS15: `sigma_max / sigma_min` of the Jacobian in relative units with unit columns
    /// (infinite when a parameter changes nothing).
    pub condition_number: f64,
    /// The singular values of that matrix, largest first.
    pub singular_values: Vec<f64>,
    /// The weakest combination (for a verdict other than identifiable).
    pub combination: Option<Combination>,
    /// One sentence for the user.
    pub message: String,
}

/// Eqs. LS15-LS16 on the Jacobian `j` (`dr/dtheta`, physical units) at `theta`.
pub fn check(j: &DMatrix<f64>, params: &[Param], theta: &[f64]) -> Identifiability {
    let p = theta.len();
    let rel: Vec<bool> = (0..p).map(|k| theta[k] != 0.0).collect();
    let scale: Vec<f64> = (0..p)
        .map(|k| if rel[k] { theta[k].abs() } else { params[k].width() })
        .collect();
    let norms: Vec<f64> = (0..p).map(|k| j.column(k).norm() * scale[k]).collect();
    if let Some(k) = (0..p).find(|&k| norms[k] == 0.0 || !norms[k].is_finite()) {
        let combination = Combination {
            entries: vec![(params[k].key.clone(), 1.0, rel[k])],
            determined: None,
        };
        return Identifiability {
            verdict: Verdict::RankDeficient,
            condition_number: f64::INFINITY,
            singular_values: Vec::new(),
            message: format!(
                "{} does not change the model's readings of the fitted channels: the data cannot determine it \
                 (remove it from [fit] params, or fit to a sensor that sees it)",
                params[k].key
            ),
            combination: Some(combination),
        };
    }
    let jn = DMatrix::from_fn(j.nrows(), p, |i, k| j[(i, k)] * scale[k] / norms[k]);
    let svd = jn.svd(false, true);
    let mut order: Vec<usize> = (0..p).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let singular_values: Vec<f64> = order.iter().map(|&k| svd.singular_values[k]).collect();
    let (max, min) = (singular_values[0], singular_values[p - 1]);
    let condition_number = if min > 0.0 { max / min } else { f64::INFINITY };
    let verdict = if condition_number > RANK_DEFICIENT {
        Verdict::RankDeficient
    } else if condition_number > ILL_CONDITIONED {
        Verdict::IllConditioned
    } else {
        Verdict::Identifiable
    };
    let combination = (verdict != Verdict::Identifiable && p > 1).then(|| {
        let weakest = order[p - 1];
        // J_n v = 0 means J_rel (N^-1 v) = 0: the relative changes are v_k / |column k|
        let dir: Vec<f64> = match &svd.v_t {
            Some(vt) => (0..p).map(|k| vt[(weakest, k)] / norms[k]).collect(),
            None => vec![0.0; p],
        };
        combination(params, &rel, &dir)
    });
    let message = message(verdict, condition_number, combination.as_ref());
    Identifiability {
        verdict,
        condition_number,
        singular_values,
        combination,
        message,
    }
}

/// The direction `dir` (relative or box units per `rel`) normalised, its small entries dropped,
/// in the order of the parameters, the first one named positive.
fn combination(params: &[Param], rel: &[bool], dir: &[f64]) -> Combination {
    let len = dir.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::MIN_POSITIVE);
    let big = dir.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let named: Vec<usize> = (0..dir.len()).filter(|&k| dir[k].abs() >= NAMED_SHARE * big).collect();
    let sign = match named.first() {
        Some(&k) if dir[k] < 0.0 => -1.0,
        _ => 1.0,
    };
    let entries: Vec<(String, f64, bool)> = named
        .iter()
        .map(|&k| (params[k].key.clone(), sign * dir[k] / len, rel[k]))
        .collect();
    let determined = match entries.as_slice() {
        [(ka, a, true), (kb, b, true)] => {
            // the data fix e . ln(theta) with e orthogonal to (a, b): e = (b, -a), largest 1
            let m = b.abs().max(a.abs());
            let (mut ea, mut eb) = (b / m, -a / m);
            if ea < 0.0 {
                (ea, eb) = (-ea, -eb);
            }
            Some(format!("{ka}^{ea:.2} x {kb}^{eb:.2}"))
        }
        _ => None,
    };
    Combination { entries, determined }
}

fn message(verdict: Verdict, kappa: f64, c: Option<&Combination>) -> String {
    let along = c
        .map(|c| {
            let fixed = c
                .determined
                .as_ref()
                .map(|d| format!("; only {d} is determined"))
                .unwrap_or_default();
            format!(" along {}{fixed}", c.direction_text())
        })
        .unwrap_or_default();
    match verdict {
        Verdict::Identifiable => format!("identifiable: condition number {kappa:.3e} (at most {ILL_CONDITIONED:.0e})"),
        Verdict::IllConditioned => format!(
            "ill-conditioned: condition number {kappa:.3e} (above {ILL_CONDITIONED:.0e}): the data hardly separate the \
             parameters{along}; their estimates are strongly correlated"
        ),
        Verdict::RankDeficient => format!(
            "rank-deficient: condition number {kappa:.3e} (above {RANK_DEFICIENT:.0e}): the data cannot separate the \
             parameters{along}; fit fewer parameters (fix one of them)"
        ),
    }
}
