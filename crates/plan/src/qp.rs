//! The damped Gauss-Newton step within linearised limits (`docs/motions.md` 4.4): minimise
//! `1/2 dx^T (J^T J + lambda I) dx + (J^T r)^T dx` subject to `u_k + G_k dx <= 1 - margin` for
//! every usage sample `u_k` (a sample of `|s_i'| / v_max`, `|s_i''| / a_max` or
//! `|Fa_i| / Fa_max`) above [`ACTIVE`], `G_k` its gradient. A convex quadratic program, solved by
//! Clarabel's interior-point method.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus, SupportedConeT,
};
use faer::Mat;

/// Samples below this usage are left out of the step's constraints (a step of the damped search
/// is small; a sample far below its limit cannot reach it).
pub const ACTIVE: f64 = 0.5;
/// The linearised limit is `1 - MARGIN`: the step aims a little inside, so that the nonlinear
/// usage of the trial stays below 1.
pub const MARGIN: f64 = 2e-3;

/// Progress rows (`docs/motions.md` 4.10, each `<= 0` for a monotone motion) above this value
/// join the step's constraints: a rate below half the mean rate, or knots closer than half the
/// progress.
pub const PROGRESS_ACTIVE: f64 = -0.5;
/// The linearised progress row is `<= -PROGRESS_MARGIN` where it already is, else `<=` its value:
/// the step aims a little inside (the rows are linear in the variables; the margin absorbs the
/// QP's tolerance).
pub const PROGRESS_MARGIN: f64 = 1e-7;

/// The constraint rows `G_k dx <= h_k` of the active samples: `h_k = 1 - MARGIN - u_k` for a
/// limit's usage, `h_k = min(-p_k, max(-p_k - PROGRESS_MARGIN, 0))` for a progress row `p_k`.
#[derive(Debug, Clone)]
pub struct LinearLimits {
    pub g: Vec<Vec<f64>>,
    pub h: Vec<f64>,
}

/// The active samples' rows (usage above [`ACTIVE`], progress above [`PROGRESS_ACTIVE`]); `None`
/// when no sample is active (the step is unconstrained).
pub fn linearised_limits(
    usage: &[f64],
    grad: &Mat<f64>,
    progress: &[f64],
    progress_grad: &Mat<f64>,
) -> Option<LinearLimits> {
    let mut g = Vec::new();
    let mut h = Vec::new();
    for (k, &u) in usage.iter().enumerate().filter(|(_, u)| **u > ACTIVE) {
        g.push((0..grad.ncols()).map(|j| grad[(k, j)]).collect());
        h.push(1.0 - MARGIN - u);
    }
    for (k, &p) in progress.iter().enumerate().filter(|(_, p)| **p > PROGRESS_ACTIVE) {
        g.push((0..progress_grad.ncols()).map(|j| progress_grad[(k, j)]).collect());
        h.push((-p).min((-p - PROGRESS_MARGIN).max(0.0)));
    }
    (!g.is_empty()).then_some(LinearLimits { g, h })
}

/// The step of the module docs; `None` when the program has no solution (the limits cannot be
/// met to first order from this iterate).
pub fn damped_step_within(jtj: &Mat<f64>, jtr: &Mat<f64>, lambda: f64, lim: &LinearLimits) -> Option<Vec<f64>> {
    let n = jtj.nrows();
    // scale the objective to order 1: Clarabel's tolerances are absolute
    let s = (0..n).map(|i| jtj[(i, i)]).fold(0.0, f64::max).max(1e-300) + lambda;
    let upper: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| match j.cmp(&i) {
                    std::cmp::Ordering::Less => 0.0,
                    std::cmp::Ordering::Equal => (jtj[(i, i)] + lambda) / s,
                    std::cmp::Ordering::Greater => jtj[(i, j)] / s,
                })
                .collect()
        })
        .collect();
    let p = CscMatrix::from(&upper);
    let q: Vec<f64> = (0..n).map(|i| jtr[(i, 0)] / s).collect();
    let a = CscMatrix::from(&lim.g);
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(100)
        .build()
        .ok()?;
    let cones = [NonnegativeConeT(lim.h.len())];
    let mut solver = DefaultSolver::new(&p, &q, &a, &lim.h, &cones, settings).ok()?;
    solver.solve();
    matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    )
    .then(|| solver.solution.x.clone())
}

/// One model's linearised residual in compressed form (`docs/motions.md` 4.11, Eq. U3):
/// `|r_k + J_k dx| = |a dx + b|` with `[a | b]` the triangular factor `R` of the thin QR of
/// `[J_k | r_k]` (`n + 1` rows instead of the window's thousands; exact, `Q` is orthonormal).
#[derive(Debug, Clone)]
pub struct Block {
    /// `(n + 1) x n`.
    pub a: Vec<Vec<f64>>,
    /// `n + 1`.
    pub b: Vec<f64>,
}

impl Block {
    /// The compressed block of `r + J dx` (`j`: rows x n, `r`: rows).
    pub fn of(j: &Mat<f64>, r: &[f64]) -> Block {
        let n = j.ncols();
        let m = Mat::from_fn(r.len(), n + 1, |i, c| if c < n { j[(i, c)] } else { r[i] });
        let qr = m.qr();
        let rr = qr.thin_R();
        let rows = rr.nrows();
        let at = |i: usize, c: usize| if i <= c { rr[(i, c)] } else { 0.0 };
        Block {
            a: (0..rows).map(|i| (0..n).map(|c| at(i, c)).collect()).collect(),
            b: (0..rows).map(|i| at(i, n)).collect(),
        }
    }

    /// `|a dx + b|`.
    pub fn norm_at(&self, dx: &[f64]) -> f64 {
        self.a
            .iter()
            .zip(&self.b)
            .map(|(row, b)| row.iter().zip(dx).map(|(a, d)| a * d).sum::<f64>() + b)
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
    }
}

/// The epigraph step of Eq. U3 (`docs/motions.md` 4.11): minimise `t + lambda/2 |dx|^2` subject
/// to `|a_k dx + b_k| <= t` for every block and the linearised limits `lim`; a second-order cone
/// program in `(dx, t)`. The blocks should be scaled to order 1 (Clarabel's tolerances are
/// absolute). `None` when the program has no solution.
pub fn epigraph_step(blocks: &[Block], lambda: f64, lim: Option<&LinearLimits>) -> Option<Vec<f64>> {
    let n = blocks.first()?.a.first().map_or(0, |r| r.len());
    let p = CscMatrix::from(
        &(0..=n)
            .map(|i| (0..=n).map(|j| if i == j && i < n { lambda } else { 0.0 }).collect())
            .collect::<Vec<Vec<f64>>>(),
    );
    let mut q = vec![0.0; n + 1];
    q[n] = 1.0;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut rhs = Vec::new();
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    if let Some(lim) = lim {
        for (g, h) in lim.g.iter().zip(&lim.h) {
            rows.push(g.iter().copied().chain([0.0]).collect());
            rhs.push(*h);
        }
        cones.push(NonnegativeConeT(lim.h.len()));
    }
    for blk in blocks {
        let mut t_row = vec![0.0; n + 1];
        t_row[n] = -1.0;
        rows.push(t_row);
        rhs.push(0.0);
        for (a, b) in blk.a.iter().zip(&blk.b) {
            rows.push(a.iter().map(|v| -v).chain([0.0]).collect());
            rhs.push(*b);
        }
        cones.push(SecondOrderConeT(blk.b.len() + 1));
    }
    let a = CscMatrix::from(&rows);
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(100)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &rhs, &cones, settings).ok()?;
    solver.solve();
    matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    )
    .then(|| solver.solution.x[..n].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textbook QP with a known solution: minimise `1/2 |dx|^2 - (1, 1) . dx` (the
    /// unconstrained minimum (1, 1)) with `dx_1 + dx_2 <= 1`: the projection (0.5, 0.5).
    #[test]
    fn the_step_is_the_projection_onto_the_limit() {
        let jtj = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 0.0 });
        let jtr = Mat::from_fn(2, 1, |_, _| -1.0);
        let lim = LinearLimits {
            g: vec![vec![1.0, 1.0]],
            h: vec![1.0],
        };
        let dx = damped_step_within(&jtj, &jtr, 0.0, &lim).unwrap();
        assert!((dx[0] - 0.5).abs() < 1e-6 && (dx[1] - 0.5).abs() < 1e-6, "{dx:?}");
    }

    /// The compressed block keeps the norm: `|a dx + b| = |r + J dx|` at random `dx` (direct
    /// products against the factor).
    #[test]
    fn the_compressed_block_keeps_the_norm() {
        let j = Mat::from_fn(40, 3, |i, c| ((i * 7 + c * 3) % 11) as f64 - 5.0 + 0.1 * c as f64);
        let r: Vec<f64> = (0..40).map(|i| (i as f64 * 0.37).sin()).collect();
        let blk = Block::of(&j, &r);
        for dx in [[0.0, 0.0, 0.0], [0.3, -1.2, 0.5], [2.0, 0.1, -0.7]] {
            let direct = (0..40)
                .map(|i| r[i] + (0..3).map(|c| j[(i, c)] * dx[c]).sum::<f64>())
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt();
            assert!(
                (blk.norm_at(&dx) - direct).abs() < 1e-10 * direct,
                "{} against {direct}",
                blk.norm_at(&dx)
            );
        }
    }

    /// The epigraph step of the minimax of two affine residuals in one variable, `|x - 1|` and
    /// `|x + 1|` from `x = 3` (blocks `r = x0 - 1 + dx`, `x0 + 1 + dx`): without damping the
    /// minimax point x = 0 (the two balance), i.e. `dx = -3`.
    #[test]
    fn the_epigraph_step_balances_two_models() {
        let blocks = [
            Block {
                a: vec![vec![1.0]],
                b: vec![2.0],
            },
            Block {
                a: vec![vec![1.0]],
                b: vec![4.0],
            },
        ];
        let dx = epigraph_step(&blocks, 0.0, None).unwrap();
        assert!((dx[0] + 3.0).abs() < 1e-6, "{dx:?}");
        // with a limit dx >= -2 (-dx <= 2) it stops there
        let lim = LinearLimits {
            g: vec![vec![-1.0]],
            h: vec![2.0],
        };
        let dx = epigraph_step(&blocks, 0.0, Some(&lim)).unwrap();
        assert!((dx[0] + 2.0).abs() < 1e-6, "{dx:?}");
    }
}
