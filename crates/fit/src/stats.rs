//! The statistics of the estimates at the optimum (`docs/measured.md` 4.7, Eqs. LS11-LS14,
//! LS18-LS19): the residual variance, the covariance `s^2 (J^T J)^-1`, standard errors and
//! correlations; the sandwich covariance that lets the residuals be correlated in time (the
//! model's own error); 95 % intervals from Student's t on the wider of the two.

use nalgebra::DMatrix;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// The two-sided level of the intervals.
pub const LEVEL: f64 = 0.95;

/// What the residuals and the Jacobian at the optimum say about the estimates. Entries of a
/// parameter left out (at a bound) or of a singular problem are `None`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Statistics {
    /// Residuals n (fitted channels times samples).
    pub n: usize,
    /// Degrees of freedom `n - p` (p: the parameters inside their boxes).
    pub dof: usize,
    /// Eq. LS11: the residual variance `|r|^2 / (n - p)` (of the weighted residuals of Eq. LS1;
    /// about 1 when the model is right and the noise levels are).
    pub s2: f64,
    /// Eq. LS12: the covariance of the estimates, in their units.
    pub covariance: Vec<Vec<Option<f64>>>,
    /// Standard errors, the square roots of its diagonal (the noise's alone: white residuals).
    pub standard_errors: Vec<Option<f64>>,
    /// Eq. LS18: standard errors from the sandwich covariance with residuals correlated over
    /// `bandwidth` samples (the model's error as well as the noise).
    pub standard_errors_correlated: Vec<Option<f64>>,
    /// The Bartlett kernel's bandwidth of Eq. LS18 [samples].
    pub bandwidth: usize,
    /// Eq. LS13: correlations `C_ij / (se_i se_j)`.
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Eqs. LS14, LS19: `theta_j -+ t max(se_j, se_corr_j)`.
    pub intervals: Vec<Option<[f64; 2]>>,
    /// Student's t quantile of Eq. LS14 (0.975 at `dof`).
    pub t_quantile: f64,
}

/// How the residual vector is laid out and how long its errors may stay correlated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Residuals per channel: the vector is channel after channel, each this long.
    pub segment: usize,
    /// The Bartlett kernel's bandwidth of Eq. LS18 [samples] (0: white residuals).
    pub bandwidth: usize,
}

/// Eqs. LS11-LS14, LS18-LS19 at the estimates `theta` with the Jacobian `j` (`dr/dtheta`, physical
/// units) and the residuals `r` laid out as `layout` says; `free[j]` false leaves parameter j out
/// (it sits at a bound: the quadratic model of the cost does not hold there). The inverse goes
/// through the SVD of `J` with unit columns, so that parameters of very different units lose no
/// digits.
pub fn statistics(j: &DMatrix<f64>, r: &[f64], theta: &[f64], free: &[bool], layout: Layout) -> Statistics {
    let p = theta.len();
    let idx: Vec<usize> = (0..p).filter(|&k| free[k]).collect();
    let n = r.len();
    let dof = n.saturating_sub(idx.len()).max(1);
    let s2 = r.iter().map(|v| v * v).sum::<f64>() / dof as f64;
    let t_quantile = StudentsT::new(0.0, 1.0, dof as f64)
        .map(|d| d.inverse_cdf(0.5 + LEVEL / 2.0))
        .unwrap_or(f64::NAN);
    let inv = scaled_inverse(j, &idx);
    let mut covariance = vec![vec![None; p]; p];
    if let Some(inv) = &inv {
        for (a, &ja) in idx.iter().enumerate() {
            for (b, &jb) in idx.iter().enumerate() {
                covariance[ja][jb] = Some(s2 * inv[(a, b)]);
            }
        }
    }
    let standard_errors: Vec<Option<f64>> = (0..p).map(|k| covariance[k][k].map(f64::sqrt)).collect();
    let mut standard_errors_correlated = vec![None; p];
    if let Some(inv) = &inv {
        let sandwich = sandwich(inv, &meat(j, r, &idx, layout), n, idx.len());
        for (a, &ja) in idx.iter().enumerate() {
            standard_errors_correlated[ja] = Some(sandwich[(a, a)].max(0.0).sqrt());
        }
    }
    let correlation = (0..p)
        .map(|a| {
            (0..p)
                .map(|b| match (covariance[a][b], standard_errors[a], standard_errors[b]) {
                    (Some(c), Some(sa), Some(sb)) if sa > 0.0 && sb > 0.0 => Some(c / (sa * sb)),
                    _ => None,
                })
                .collect()
        })
        .collect();
    let intervals = (0..p)
        .map(|k| {
            let se = match (standard_errors[k], standard_errors_correlated[k]) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            };
            se.map(|se| [theta[k] - t_quantile * se, theta[k] + t_quantile * se])
        })
        .collect();
    Statistics {
        n,
        dof,
        s2,
        covariance,
        standard_errors,
        standard_errors_correlated,
        bandwidth: layout.bandwidth,
        correlation,
        intervals,
        t_quantile,
    }
}

/// `(J_F^T J_F)^-1` over the columns `idx` of `j`, through the SVD of `J_F D^-1` (D: the column
/// norms): `D^-1 V S^-2 V^T D^-1`. `None` when a column is zero or a singular value is (the
/// problem is singular; the identifiability check says which combination).
fn scaled_inverse(j: &DMatrix<f64>, idx: &[usize]) -> Option<DMatrix<f64>> {
    if idx.is_empty() {
        return None;
    }
    let norms: Vec<f64> = idx.iter().map(|&k| j.column(k).norm()).collect();
    if norms.iter().any(|&v| v == 0.0 || !v.is_finite()) {
        return None;
    }
    let jf = DMatrix::from_fn(j.nrows(), idx.len(), |i, c| j[(i, idx[c])] / norms[c]);
    let svd = jf.svd(false, true);
    let vt = svd.v_t?;
    if svd.singular_values.iter().any(|&s| s == 0.0) {
        return None;
    }
    let m = idx.len();
    Some(DMatrix::from_fn(m, m, |a, b| {
        (0..m)
            .map(|k| vt[(k, a)] * vt[(k, b)] / svd.singular_values[k].powi(2))
            .sum::<f64>()
            / (norms[a] * norms[b])
    }))
}

/// Eq. LS18's middle factor over the columns `idx`: the long-run covariance of the scores
/// `g_k = J_k^T r_k`, summed within each channel over lags up to the bandwidth with Bartlett's
/// weights `1 - l / (L + 1)` (Newey & West 1987: positive semi-definite at any bandwidth);
/// channels are taken as uncorrelated with each other.
fn meat(j: &DMatrix<f64>, r: &[f64], idx: &[usize], layout: Layout) -> DMatrix<f64> {
    let m = idx.len();
    let scores = DMatrix::from_fn(r.len(), m, |i, a| j[(i, idx[a])] * r[i]);
    let mut b = DMatrix::<f64>::zeros(m, m);
    let segment = layout.segment.max(1);
    for start in (0..r.len()).step_by(segment) {
        let g = scores.rows(start, segment.min(r.len() - start));
        let rows = g.nrows();
        for lag in 0..=layout.bandwidth.min(rows.saturating_sub(1)) {
            let lagged = g.rows(0, rows - lag).transpose() * g.rows(lag, rows - lag);
            if lag == 0 {
                b += lagged;
            } else {
                let w = 1.0 - lag as f64 / (layout.bandwidth as f64 + 1.0);
                b += (&lagged + lagged.transpose()) * w;
            }
        }
    }
    b
}

/// Eq. LS18: `n / (n - p) (J^T J)^-1 B (J^T J)^-1` with `inv = (J^T J)^-1`.
fn sandwich(inv: &DMatrix<f64>, meat: &DMatrix<f64>, n: usize, p: usize) -> DMatrix<f64> {
    let dof = n.saturating_sub(p).max(1) as f64;
    inv * meat * inv * (n as f64 / dof)
}
