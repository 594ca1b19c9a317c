//! The weights that keep a set of complex linear forms smallest: `min_w max_k |c_k . w|` over
//! non-negative weights summing to 1, a second-order cone program (Clarabel). Used to design
//! input shapers of specified insensitivity (`docs/motions.md` 3.1, Eq. H3): the weights are the
//! impulses' amplitudes and each form the residual vibration at one frequency of the band.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus, ZeroConeT,
};

/// The minimising weights and the least largest modulus.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimax {
    /// Non-negative weights summing to 1.
    pub weights: Vec<f64>,
    /// `max_k |c_k . w|` at the solution.
    pub largest: f64,
}

/// `min_w max_k |sum_j forms[k][j] w_j|` subject to `w >= 0`, `sum w = 1`; each form a list of
/// `(re, im)` coefficients, all of the same length. `None` when the solver does not converge.
///
/// As a cone program in `x = (w, t)`: minimise t with `(t, Re c_k.w, Im c_k.w)` in the
/// three-dimensional second-order cone for every k, `w` in the non-negative orthant and one
/// equality row.
pub fn minimax_weights(forms: &[Vec<(f64, f64)>]) -> Option<Minimax> {
    let n = forms.first()?.len();
    let cols = n + 1;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut b = Vec::new();
    // sum w = 1
    rows.push((0..cols).map(|j| if j < n { 1.0 } else { 0.0 }).collect());
    b.push(1.0);
    // w >= 0: s = w = b - A x with A = -I
    for i in 0..n {
        rows.push((0..cols).map(|j| if j == i { -1.0 } else { 0.0 }).collect());
        b.push(0.0);
    }
    // (t, Re, Im) in the cone: s = -A x
    for form in forms {
        rows.push((0..cols).map(|j| if j == n { -1.0 } else { 0.0 }).collect());
        rows.push(form.iter().map(|c| -c.0).chain([0.0]).collect());
        rows.push(form.iter().map(|c| -c.1).chain([0.0]).collect());
        b.extend([0.0; 3]);
    }
    let mut cones = vec![ZeroConeT(1), NonnegativeConeT(n)];
    cones.extend(forms.iter().map(|_| SecondOrderConeT(3)));
    let a = CscMatrix::from(&rows);
    let p = CscMatrix::zeros((cols, cols));
    let q: Vec<f64> = (0..cols).map(|j| if j == n { 1.0 } else { 0.0 }).collect();
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .tol_gap_abs(1e-10)
        .tol_gap_rel(1e-10)
        .tol_feas(1e-10)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    if !matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return None;
    }
    // clean round-off: clip to the orthant and renormalise, then measure
    let mut w: Vec<f64> = solver.solution.x[..n].iter().map(|v| v.max(0.0)).collect();
    let sum: f64 = w.iter().sum();
    w.iter_mut().for_each(|v| *v /= sum);
    let largest = forms
        .iter()
        .map(|f| {
            let (re, im) = f
                .iter()
                .zip(&w)
                .fold((0.0, 0.0), |(r, i), (c, x)| (r + c.0 * x, i + c.1 * x));
            re.hypot(im)
        })
        .fold(0.0, f64::max);
    Some(Minimax { weights: w, largest })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two forms `1` and `e^(i pi) = -1` on two weights: `|w1 + w2| = 1` always for the first,
    /// so the least largest modulus is 1. With one form `(1, -1)`: `|w1 - w2|` is 0 at the
    /// centroid (the ZV shaper's two equal impulses at zero damping).
    #[test]
    fn small_programs_have_their_known_optima() {
        let zv = minimax_weights(&[vec![(1.0, 0.0), (-1.0, 0.0)]]).unwrap();
        assert!((zv.weights[0] - 0.5).abs() < 1e-7 && zv.largest < 1e-7, "{zv:?}");
        let one = minimax_weights(&[vec![(1.0, 0.0), (1.0, 0.0)], vec![(1.0, 0.0), (-1.0, 0.0)]]).unwrap();
        assert!((one.largest - 1.0).abs() < 1e-7, "{one:?}");
    }
}
