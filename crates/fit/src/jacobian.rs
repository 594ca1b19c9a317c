//! The Jacobian of the residual vector by forward differences (`docs/measured.md` 4.5, Eq. LS9):
//! one model evaluation per parameter, all in parallel.

use nalgebra::DMatrix;
use rayon::prelude::*;

use crate::problem::{Param, Problem};
use crate::Model;

/// The relative step of Eq. LS9: `h_j = FD_STEP max(|theta_j|, FD_FLOOR (hi_j - lo_j))`.
pub const FD_STEP: f64 = 1e-4;
/// The share of the box below which a parameter's own value no longer sets the step (a value
/// at or near zero).
pub const FD_FLOOR: f64 = 1e-3;

/// Eq. LS9: the step of parameter `p` at the scaled value `u`, in scaled units; backwards when a
/// forward step would leave the box.
pub fn step(p: &Param, u: f64) -> f64 {
    let theta = p.physical(u);
    let h = FD_STEP * theta.abs().max(FD_FLOOR * p.width()) / p.width();
    if u + h > 1.0 {
        -h
    } else {
        h
    }
}

/// The Jacobian `dr/du` (rows: residuals, columns: scaled parameters) at `u`, where the residual
/// vector is `r`; the columns' evaluations run in parallel. An error names the parameter whose
/// step could not be evaluated, and why.
pub fn jacobian<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    u: &[f64],
    r: &[f64],
) -> Result<DMatrix<f64>, (usize, String)> {
    let columns: Vec<Vec<f64>> = (0..u.len())
        .into_par_iter()
        .map(|j| {
            let h = step(&problem.params[j], u[j]);
            let mut up = u.to_vec();
            up[j] += h;
            let (rj, _) = problem.evaluate(model, &up).map_err(|e| (j, e))?;
            Ok(rj.iter().zip(r).map(|(a, b)| (a - b) / h).collect())
        })
        .collect::<Result<_, _>>()?;
    Ok(DMatrix::from_fn(r.len(), u.len(), |i, j| columns[j][i]))
}
