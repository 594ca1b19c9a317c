//! The algebra of one iteration of the search (`docs/measured.md` 4.4 and 4.6): the normal
//! equations (Eq. LS6), the free set (Eq. LS7), the damped step and its projection (Eq. LS8),
//! the predicted decrease and the relative offset (Eq. LS10).

use nalgebra::{DMatrix, DVector};

/// Eq. LS6: `A = J^T J` and `g = J^T r`.
pub(crate) fn normal_equations(j: &DMatrix<f64>, r: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
    let rv = DVector::from_column_slice(r);
    (j.tr_mul(j), j.tr_mul(&rv))
}

/// Eq. LS7: the parameters free to move: not at a bound with the descent direction `-g` leaving
/// the box.
pub(crate) fn free_set(u: &[f64], g: &DVector<f64>) -> Vec<bool> {
    u.iter()
        .zip(g.iter())
        .map(|(&u, &g)| !((u <= 0.0 && g > 0.0) || (u >= 1.0 && g < 0.0)))
        .collect()
}

/// The rows and columns `idx` of `a`, the entries `idx` of `g`.
fn restrict(a: &DMatrix<f64>, g: &DVector<f64>, idx: &[usize]) -> (DMatrix<f64>, DVector<f64>) {
    let m = idx.len();
    (
        DMatrix::from_fn(m, m, |x, y| a[(idx[x], idx[y])]),
        DVector::from_fn(m, |x, _| g[idx[x]]),
    )
}

/// Eq. LS10: the relative offset `sqrt(g_F^T A_F^+ g_F / p_F) / sqrt(|r|^2 / (n - p_F))` over
/// the free parameters (Bates & Watts 1981): the Gauss-Newton step's length in the metric of
/// the estimates' uncertainty. 0 for an exact fit or no free parameter.
pub(crate) fn relative_offset(a: &DMatrix<f64>, g: &DVector<f64>, free: &[bool], r: &[f64]) -> f64 {
    let idx: Vec<usize> = (0..free.len()).filter(|&k| free[k]).collect();
    let rr: f64 = r.iter().map(|v| v * v).sum();
    if idx.is_empty() || rr == 0.0 {
        return 0.0;
    }
    let (af, gf) = restrict(a, g, &idx);
    let x = match af.svd(true, true).solve(&gf, 0.0) {
        Ok(x) => x,
        Err(_) => return f64::INFINITY,
    };
    let p = idx.len() as f64;
    let dof = (r.len() as f64 - p).max(1.0);
    ((gf.dot(&x) / p).max(0.0) / (rr / dof)).sqrt()
}

/// Eq. LS8: the damped step of the free parameters (0 for the held ones); `None` when the
/// damped matrix cannot be factored (then the damping is raised).
pub(crate) fn damped_step(a: &DMatrix<f64>, g: &DVector<f64>, free: &[bool], mu: f64) -> Option<Vec<f64>> {
    let idx: Vec<usize> = (0..free.len()).filter(|&k| free[k]).collect();
    let (mut af, gf) = restrict(a, g, &idx);
    let top = (0..idx.len()).fold(0.0f64, |m, k| m.max(af[(k, k)]));
    for k in 0..idx.len() {
        // Marquardt's scaling by the diagonal, kept positive for a parameter that changes nothing
        af[(k, k)] += mu * af[(k, k)].max(1e-12 * top).max(f64::MIN_POSITIVE);
    }
    let d = af.cholesky()?.solve(&(-gf));
    let mut step = vec![0.0; free.len()];
    for (x, &k) in idx.iter().enumerate() {
        step[k] = d[x];
    }
    Some(step)
}

/// `u + d` projected onto the box `[0, 1]^p`.
pub(crate) fn project(u: &[f64], d: &[f64]) -> Vec<f64> {
    u.iter().zip(d).map(|(u, d)| (u + d).clamp(0.0, 1.0)).collect()
}

/// The cost's decrease that the Gauss-Newton model predicts for the step `d`:
/// `-(g^T d + d^T A d / 2)`.
pub(crate) fn predicted_decrease(a: &DMatrix<f64>, g: &DVector<f64>, d: &[f64]) -> f64 {
    let dv = DVector::from_column_slice(d);
    -(g.dot(&dv) + 0.5 * dv.dot(&(a * &dv)))
}
