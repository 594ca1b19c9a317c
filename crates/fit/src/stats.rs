//! The statistics of the estimates at the optimum (`docs/measured.md` 4.7, Eqs. LS11-LS14): the
//! residual variance, the covariance `s^2 (J^T J)^-1`, standard errors, correlations and 95 %
//! intervals from Student's t.

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
    /// Standard errors, the square roots of its diagonal.
    pub standard_errors: Vec<Option<f64>>,
    /// Eq. LS13: correlations `C_ij / (se_i se_j)`.
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Eq. LS14: `theta_j -+ t se_j`.
    pub intervals: Vec<Option<[f64; 2]>>,
    /// Student's t quantile of Eq. LS14 (0.975 at `dof`).
    pub t_quantile: f64,
}

/// Eqs. LS11-LS14 at the estimates `theta` with the Jacobian `j` (`dr/dtheta`, physical units) and
/// the residuals `r`; `free[j]` false leaves parameter j out (it sits at a bound: the quadratic
/// model of the cost does not hold there). The inverse goes through the SVD of `J` with unit
/// columns, so that parameters of very different units lose no digits.
pub fn statistics(j: &DMatrix<f64>, r: &[f64], theta: &[f64], free: &[bool]) -> Statistics {
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
        .map(|k| standard_errors[k].map(|se| [theta[k] - t_quantile * se, theta[k] + t_quantile * se]))
        .collect();
    Statistics {
        n,
        dof,
        s2,
        covariance,
        standard_errors,
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
