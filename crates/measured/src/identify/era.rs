//! The eigensystem realization algorithm on a multi-channel free decay (`docs/measured.md` 3.2,
//! Eqs. I3-I5): the Hankel matrices with a stride, one SVD, and the poles, shapes and amplitudes
//! of the realisation of each order.

use faer::linalg::solvers::Solve;
use faer::{c64, Mat};

use crate::error::MeasuredError;

use super::pole;

/// Most rows of the block Hankel matrix (3.2): m channels times the block rows.
pub(crate) const MAX_HANKEL_ROWS: usize = 240;
/// The block rows span this share of the window (3.2).
pub(crate) const ROW_SPAN: f64 = 1.0 / 3.0;
/// The stride's Nyquist frequency is at least this multiple of the band's top (3.2).
pub(crate) const NYQUIST_MARGIN: f64 = 1.25;
/// Poles above this share of the stride's Nyquist frequency are left out (aliasing, Eq. I5).
pub(crate) const ALIAS_GUARD: f64 = 0.8;
/// Singular values below this share of the largest end the orders (a rank-deficient Hankel).
const RANK_FLOOR: f64 = 1e-13;

/// The shape of the Hankel matrices and the orders realised.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    /// Block rows r.
    pub rows: usize,
    /// Stride d [samples] between block rows.
    pub stride: usize,
    /// Columns s (`N - r d`).
    pub cols: usize,
    /// The even orders n realised, ascending.
    pub orders: Vec<usize>,
}

impl Plan {
    /// The Hankel matrices for `n` samples of `m` channels at step `dt` [s], a band up to
    /// `f_max` [Hz] and the orders `[lo, hi]` (3.2): at most [`MAX_HANKEL_ROWS`] rows, enough for
    /// the largest order, block rows spanning [`ROW_SPAN`] of the window with the stride that
    /// keeps the band below the stride's Nyquist frequency.
    pub fn new(n: usize, m: usize, dt: f64, f_max: f64, range: [usize; 2]) -> Result<Self, MeasuredError> {
        let rows = (MAX_HANKEL_ROWS / m).max((range[1] + 2).div_ceil(m)).max(2);
        let span = ((n as f64) * ROW_SPAN) as usize;
        let band_stride = ((1.0 / dt) / (2.0 * NYQUIST_MARGIN * f_max)).floor().max(1.0) as usize;
        let stride = (span / rows).clamp(1, band_stride);
        let rows = rows.min((span / stride).max(2));
        let cols = n.saturating_sub(rows * stride);
        let rank = (rows * m).min(cols);
        let orders: Vec<usize> = (range[0].next_multiple_of(2)..=range[1])
            .step_by(2)
            .filter(|&o| o < rank)
            .collect();
        if orders.len() < 2 {
            return Err(MeasuredError::input(
                "window",
                format!(
                    "{n} samples of {m} channel(s) give Hankel matrices of rank at most {rank}: \
                     too few for two even orders of [{}, {}]",
                    range[0], range[1]
                ),
            ));
        }
        Ok(Plan {
            rows,
            stride,
            cols,
            orders,
        })
    }

    /// The stride's Nyquist frequency [Hz].
    pub fn nyquist_hz(&self, dt: f64) -> f64 {
        1.0 / (2.0 * self.stride as f64 * dt)
    }
}

/// A pole of one order's realisation.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    /// Continuous-time pole [1/s], `Im s > 0` (Eq. I5).
    pub s: c64,
    /// The shape `C_n psi` over the channels (Eq. I5).
    pub shape: Vec<c64>,
    /// RMS over the channels of the mode's amplitude at `t_0` (Eq. I5), in weighted units.
    pub amplitude: f64,
}

/// The stabilisation diagram's raw material: the candidates of each order.
#[derive(Debug, Clone)]
pub(crate) struct Diagram {
    /// The orders realised, ascending (fewer than the plan's when the Hankel matrix has a
    /// smaller numerical rank).
    pub orders: Vec<usize>,
    /// `candidates[i]`: the poles of order `orders[i]` with `Im s > 0` below the alias guard.
    pub candidates: Vec<Vec<Candidate>>,
}

/// The Hankel matrices `H0`, `H1` of Eq. I3 of the channels `y` (already weighted).
fn hankel(y: &[Vec<f64>], plan: &Plan) -> (Mat<f64>, Mat<f64>) {
    let m = y.len();
    let (r, d, s) = (plan.rows, plan.stride, plan.cols);
    let h0 = Mat::from_fn(m * r, s, |i, j| y[i % m][(i / m) * d + j]);
    let h1 = Mat::from_fn(m * r, s, |i, j| y[i % m][(i / m) * d + d + j]);
    (h0, h1)
}

/// Realise every order of `plan` from the weighted channels `y` sampled at `dt` [s]
/// (Eqs. I3-I5).
pub(crate) fn realise(y: &[Vec<f64>], dt: f64, plan: &Plan) -> Result<Diagram, MeasuredError> {
    let (h0, h1) = hankel(y, plan);
    let svd = h0.thin_svd().map_err(|e| MeasuredError::Numerical {
        step: "SVD of the Hankel matrix",
        reason: format!("{e:?}"),
    })?;
    let sv = svd.S().column_vector();
    let rank = (0..sv.nrows()).take_while(|&k| sv[k] > RANK_FLOOR * sv[0]).count();
    let orders: Vec<usize> = plan.orders.iter().copied().filter(|&n| n <= rank).collect();
    let n_max = orders.last().copied().unwrap_or(0);
    let u = svd.U().subcols(0, n_max);
    let v = svd.V().subcols(0, n_max);
    // U^T H1 V once: the realisation of order n is its leading n x n block (Eq. I4)
    let core = u.transpose() * (&h1 * v);
    let root: Vec<f64> = (0..n_max).map(|k| sv[k].sqrt()).collect();
    let step = plan.stride as f64 * dt;
    let nyquist = plan.nyquist_hz(dt);
    let mut candidates = Vec::with_capacity(orders.len());
    for &n in &orders {
        let a = Mat::from_fn(n, n, |i, j| core[(i, j)] / (root[i] * root[j]));
        let c = Mat::from_fn(y.len(), n, |i, j| u[(i, j)] * root[j]);
        let x0: Vec<f64> = (0..n).map(|j| v[(0, j)] * root[j]).collect();
        candidates.push(order_candidates(&a, &c, &x0, step, nyquist)?);
    }
    Ok(Diagram { orders, candidates })
}

/// The candidates of one realisation `(A, C, x_0)` with a step of `step` [s] (Eq. I5): upper
/// poles below [`ALIAS_GUARD`] of `nyquist` [Hz], with their shapes and amplitudes.
fn order_candidates(
    a: &Mat<f64>,
    c: &Mat<f64>,
    x0: &[f64],
    step: f64,
    nyquist: f64,
) -> Result<Vec<Candidate>, MeasuredError> {
    let n = a.nrows();
    let evd = a.eigen().map_err(|e| MeasuredError::Numerical {
        step: "eigenvalues of the realisation",
        reason: format!("{e:?}"),
    })?;
    let psi = evd.U();
    let lambda = evd.S().column_vector();
    // the modal state at t_0: Psi^{-1} x_0
    let x0c = Mat::from_fn(n, 1, |i, _| c64::new(x0[i], 0.0));
    let q = psi.partial_piv_lu().solve(&x0c);
    let cc = Mat::from_fn(c.nrows(), n, |i, j| c64::new(c[(i, j)], 0.0));
    let shapes = &cc * psi;
    let mut out = Vec::new();
    for k in 0..n {
        let l = lambda[k];
        if l.im <= 0.0 || l.norm() == 0.0 {
            continue;
        }
        let s = l.ln() / step;
        if !s.re.is_finite() || pole::frequency_hz(s) > ALIAS_GUARD * nyquist {
            continue;
        }
        let shape: Vec<c64> = (0..c.nrows()).map(|i| shapes[(i, k)]).collect();
        let amplitude = (shape.iter().map(|p| (p * q[(k, 0)]).norm_sqr()).sum::<f64>() / shape.len() as f64).sqrt();
        out.push(Candidate { s, shape, amplitude });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two damped sinusoids, noiseless, on two channels: every order from 4 on holds both poles
    /// to round-off (a sum of exponentials is exactly a realisation of order 4).
    #[test]
    fn exact_poles_of_a_noiseless_decay() {
        let dt = 1e-3;
        let poles = [pole::from_frequency(3.0, 0.02), pole::from_frequency(7.5, 0.04)];
        let y: Vec<Vec<f64>> = [[1.0, 0.3], [-0.5, 0.8]]
            .iter()
            .map(|amp| {
                (0..1000)
                    .map(|j| {
                        let t = j as f64 * dt;
                        poles.iter().zip(amp).map(|(s, a)| a * (s * t).exp().re).sum()
                    })
                    .collect()
            })
            .collect();
        let plan = Plan::new(1000, 2, dt, 20.0, [2, 8]).unwrap();
        let diagram = realise(&y, dt, &plan).unwrap();
        // order 4 and up: the numerical rank is 4, so the diagram stops there
        assert_eq!(diagram.orders, vec![2, 4]);
        let found = &diagram.candidates[1];
        assert_eq!(found.len(), 2);
        for s in poles {
            let best = found
                .iter()
                .map(|c| (c.s - s).norm() / s.norm())
                .fold(f64::INFINITY, f64::min);
            assert!(best < 1e-9, "pole {s}: nearest at {best}");
        }
    }
}
