//! The maximum likelihood fit of Eq. I1 (`docs/measured.md` 3.2-3.4, Eqs. I6, I8-I11): variable
//! projection (amplitudes and constants linear, the poles by Levenberg-Marquardt), two passes of
//! channel weights, the covariance of the poles, and the modes a fit cannot hold dropped.

use faer::linalg::solvers::{DenseSolveCore, Solve, SolveLstsq};
use faer::{c64, Mat, Side};

use crate::error::MeasuredError;

use super::pole;
use super::stabilise::Start;
use super::window::Window;

/// Most Levenberg-Marquardt iterations of one fit.
const MAX_ITERATIONS: usize = 200;
/// Initial damping: this share of the diagonal of `J^T J` is added to it (Marquardt's scaling).
const MU0: f64 = 1e-3;
/// Damping at which a fit stops (no step lowers the residual any more).
const MU_MAX: f64 = 1e12;
/// A fit has converged when no pole moves by more than this share of its modulus ...
const STEP_TOLERANCE: f64 = 1e-10;
/// ... or the sum of squares falls by less than this share in one iteration (a change of the
/// poles of 1e-4 of their standard deviation at most, for records of 10^4 samples).
const STALL: f64 = 1e-12;
/// Largest lag-1 correlation of a residual taken into Eq. I11.
const RHO_MAX: f64 = 0.99;
/// Smallest noise level of a channel, relative to its RMS (Eq. I9): a record that the fit holds
/// to round-off keeps finite weights.
const NOISE_FLOOR: f64 = 1e-15;
/// False-alarm probability of the significance test of a mode (Eq. I8), over the whole record.
pub(crate) const FALSE_ALARM: f64 = 1e-3;

/// A mode as the fit leaves it.
#[derive(Debug, Clone)]
pub(crate) struct Fitted {
    /// The pole [1/s] (Eq. I2).
    pub s: c64,
    /// Covariance of `(Re s, Im s)` [1/s^2] (Eq. I10).
    pub cov: [[f64; 2]; 2],
    /// Complex amplitude per channel at `t_0`, in the channel's unit (Eq. I1).
    pub amplitude: Vec<c64>,
    /// Orders at which the stabilisation diagram found it.
    pub stable_orders: usize,
}

/// What the modes a fit must keep satisfy (3.3).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    /// Largest damping ratio.
    pub zeta_max: f64,
    /// Largest frequency [Hz] (the alias guard of the stride).
    pub f_max_hz: f64,
}

/// Fit Eq. I1 to the window from the stabilised poles `starts` (3.4): weights `1 / rms` for the
/// first pass, the residual's noise levels (Eq. I9) for the second; a mode that leaves the
/// limits, is not identifiable (`zeta_std >= zeta`), is not significant (Eq. I8) or makes the
/// problem singular is dropped (the weakest first) and the rest fitted again.
pub(crate) fn fit(window: &Window, starts: &[Start], limits: Limits) -> Result<Vec<Fitted>, MeasuredError> {
    let first = Problem::new(window, window.rms().iter().map(|r| 1.0 / r).collect());
    let theta = first.levenberg_marquardt(parameters(starts.iter().map(|s| s.s)));
    let weights: Vec<f64> = first
        .noise_levels(&theta)
        .iter()
        .zip(&first.weights)
        .map(|(sigma, w)| w / sigma.max(NOISE_FLOOR))
        .collect();
    let problem = Problem::new(window, weights);
    let mut kept: Vec<Start> = starts.to_vec();
    let mut theta = theta;
    loop {
        theta = problem.levenberg_marquardt(theta);
        match problem.assess(&theta, &kept, limits) {
            Ok(modes) => return Ok(modes),
            Err(drop) => {
                kept.remove(drop);
                theta.drain(2 * drop..2 * drop + 2);
                if kept.is_empty() {
                    return Err(MeasuredError::NotFound(
                        "no mode of the stabilisation diagram survives the fit (each left the damping \
                         bound or the band, or could not be told from the noise)"
                            .into(),
                    ));
                }
            }
        }
    }
}

/// `theta = (Re s_1, Im s_1, Re s_2, ...)`.
fn parameters(poles: impl Iterator<Item = c64>) -> Vec<f64> {
    poles.flat_map(|s| [s.re, s.im]).collect()
}

/// The poles of `theta`.
fn poles(theta: &[f64]) -> Vec<c64> {
    theta.chunks_exact(2).map(|p| c64::new(p[0], p[1])).collect()
}

/// An accepted Levenberg-Marquardt step.
struct Accepted {
    theta: Vec<f64>,
    proj: Projection,
    /// The step was below [`STEP_TOLERANCE`] or the sum of squares stalled.
    converged: bool,
}

/// The weighted data of one fit.
struct Problem<'a> {
    window: &'a Window,
    /// Weight of each channel [1 / channel unit].
    weights: Vec<f64>,
    /// The weighted samples, `N x m`.
    y: Mat<f64>,
}

/// The projected residual and the linear coefficients at some poles.
struct Projection {
    /// Residual, channel after channel (`m N`), weighted.
    r: Vec<f64>,
    /// Coefficients of the basis (Eq. I6), `(1 + 2K) x m`, weighted.
    coef: Mat<f64>,
    /// The basis (Eq. I6), `N x (1 + 2K)`.
    phi: Mat<f64>,
    /// An orthonormal basis of its columns (thin QR), `N x (1 + 2K)`.
    q: Mat<f64>,
}

impl<'a> Problem<'a> {
    fn new(window: &'a Window, weights: Vec<f64>) -> Self {
        let y = Mat::from_fn(window.len(), window.y.len(), |j, c| weights[c] * window.y[c][j]);
        Problem { window, weights, y }
    }

    /// The basis of Eq. I6 at the samples, `N x (1 + 2K)`: `exp(s t_j)` by its recurrence.
    fn basis(&self, theta: &[f64]) -> Mat<f64> {
        let n = self.window.len();
        let poles = poles(theta);
        let mut phi = Mat::zeros(n, 1 + 2 * poles.len());
        for j in 0..n {
            phi[(j, 0)] = 1.0;
        }
        for (k, s) in poles.iter().enumerate() {
            let z = (s * self.window.dt).exp();
            let mut w = c64::new(1.0, 0.0);
            for j in 0..n {
                phi[(j, 1 + 2 * k)] = w.re;
                phi[(j, 2 + 2 * k)] = w.im;
                w *= z;
            }
        }
        phi
    }

    /// The least squares amplitudes at `theta` and the residual they leave.
    fn project(&self, theta: &[f64]) -> Projection {
        let phi = self.basis(theta);
        let qr = phi.qr();
        let coef = qr.solve_lstsq(&self.y);
        let q = qr.compute_thin_Q();
        let fit = &phi * &coef;
        let (n, m) = (self.y.nrows(), self.y.ncols());
        let r = (0..m)
            .flat_map(|c| (0..n).map(move |j| (c, j)))
            .map(|(c, j)| self.y[(j, c)] - fit[(j, c)])
            .collect();
        Projection { r, coef, phi, q }
    }

    /// Jacobian of the projected residual in `theta` (`m N x 2K`), Kaufman's form of the
    /// variable projection: column i is `-(I - Q Q^T) (d Phi / d theta_i) coef` channel by
    /// channel, `d/d sigma_k` and `d/d omega_k` of `exp(s_k t)` being `t exp(s_k t)` and
    /// `i t exp(s_k t)`. At the optimum `J^T J` is the Gauss-Newton matrix of the poles with the
    /// amplitudes eliminated (the Schur complement of the full problem's).
    fn jacobian(&self, theta: &[f64], proj: &Projection) -> Mat<f64> {
        let (n, m) = (self.y.nrows(), self.y.ncols());
        let dt = self.window.dt;
        let mut jac = Mat::zeros(m * n, theta.len());
        let mut v = Mat::<f64>::zeros(n, 1);
        for i in 0..theta.len() {
            let k = i / 2;
            let (cc, cs) = (1 + 2 * k, 2 + 2 * k);
            for c in 0..m {
                let (bc, bs) = (proj.coef[(cc, c)], proj.coef[(cs, c)]);
                for j in 0..n {
                    let t = j as f64 * dt;
                    let (pc, ps) = (proj.phi[(j, cc)], proj.phi[(j, cs)]);
                    v[(j, 0)] = if i % 2 == 0 {
                        t * (bc * pc + bs * ps)
                    } else {
                        t * (bs * pc - bc * ps)
                    };
                }
                let back = &proj.q * (proj.q.transpose() * &v);
                for j in 0..n {
                    jac[(c * n + j, i)] = back[(j, 0)] - v[(j, 0)];
                }
            }
        }
        jac
    }

    /// Levenberg-Marquardt on the projected residual from `theta` (Marquardt's scaling by the
    /// diagonal of `J^T J`); stops when no pole moves by [`STEP_TOLERANCE`] of its modulus, the
    /// sum of squares stalls ([`STALL`]) or no step lowers it. Every iterate keeps `Im s > 0`.
    fn levenberg_marquardt(&self, mut theta: Vec<f64>) -> Vec<f64> {
        let mut proj = self.project(&theta);
        let mut mu = MU0;
        for _ in 0..MAX_ITERATIONS {
            let Some(step) = self.damped_step(&theta, &proj, &mut mu) else {
                break;
            };
            theta = step.theta;
            proj = step.proj;
            if step.converged {
                break;
            }
        }
        theta
    }

    /// The first step from `theta` that lowers the sum of squares, raising the damping `mu` (x4)
    /// until one does and lowering it (/3) after; `None` when none does below [`MU_MAX`].
    fn damped_step(&self, theta: &[f64], proj: &Projection, mu: &mut f64) -> Option<Accepted> {
        let jac = self.jacobian(theta, proj);
        let jtj = jac.transpose() * &jac;
        let g = jac.transpose() * Mat::from_fn(proj.r.len(), 1, |k, _| proj.r[k]);
        let top = (0..jtj.nrows()).map(|i| jtj[(i, i)]).fold(0.0, f64::max);
        if top == 0.0 {
            return None;
        }
        let cost = dot(&proj.r, &proj.r);
        while *mu < MU_MAX {
            let a = Mat::from_fn(jtj.nrows(), jtj.ncols(), |i, j| {
                jtj[(i, j)] + if i == j { *mu * (jtj[(i, i)] + 1e-12 * top) } else { 0.0 }
            });
            let Ok(llt) = a.llt(Side::Lower) else {
                *mu *= 4.0;
                continue;
            };
            let step: Vec<f64> = llt.solve(-&g).col(0).iter().copied().collect();
            let trial: Vec<f64> = theta.iter().zip(&step).map(|(t, d)| t + d).collect();
            let valid = trial.chunks_exact(2).all(|p| p[0].is_finite() && p[1] > 0.0);
            let next = valid.then(|| self.project(&trial));
            match next {
                Some(next) if dot(&next.r, &next.r) < cost => {
                    let moved = trial
                        .chunks_exact(2)
                        .zip(step.chunks_exact(2))
                        .map(|(p, d)| d[0].hypot(d[1]) / p[0].hypot(p[1]))
                        .fold(0.0, f64::max);
                    let stalled = cost - dot(&next.r, &next.r) < STALL * cost;
                    *mu = (*mu / 3.0).max(1e-12);
                    return Some(Accepted {
                        theta: trial,
                        proj: next,
                        converged: moved <= STEP_TOLERANCE || stalled,
                    });
                }
                _ => *mu *= 4.0,
            }
        }
        None
    }

    /// Each channel's noise level in weighted units (Eq. I9).
    fn noise_levels(&self, theta: &[f64]) -> Vec<f64> {
        let r = self.project(theta).r;
        let n = self.y.nrows();
        let dof = (n - 1 - theta.len()).max(1) as f64;
        r.chunks_exact(n).map(|rc| (dot(rc, rc) / dof).sqrt()).collect()
    }

    /// The modes at the optimum `theta`, or the index of the one to drop: the weakest of those
    /// outside `limits`, not identifiable or not significant (Eq. I8), or the weakest of all
    /// when `J^T J` is singular.
    fn assess(&self, theta: &[f64], starts: &[Start], limits: Limits) -> Result<Vec<Fitted>, usize> {
        let proj = self.project(theta);
        let amplitudes = self.amplitudes(&proj.coef, theta.len() / 2);
        let strength = energies(&proj);
        let chance = chance_energy(self.y.ncols(), self.y.nrows());
        let weakest = |of: &[usize]| of.iter().copied().min_by(|&a, &b| strength[a].total_cmp(&strength[b]));
        let all: Vec<usize> = (0..starts.len()).collect();
        let Some(cov) = self.covariance(theta, &proj) else {
            return Err(weakest(&all).unwrap_or(0));
        };
        let poles = poles(theta);
        let mut modes = Vec::with_capacity(poles.len());
        let mut bad = Vec::new();
        for (k, s) in poles.iter().enumerate() {
            let c = [
                [cov[(2 * k, 2 * k)], cov[(2 * k, 2 * k + 1)]],
                [cov[(2 * k + 1, 2 * k)], cov[(2 * k + 1, 2 * k + 1)]],
            ];
            let zeta = pole::damping_ratio(*s);
            let (_, zeta_std) = pole::standard_deviations(*s, c);
            let within = zeta > 0.0 && zeta < limits.zeta_max && pole::frequency_hz(*s) <= limits.f_max_hz;
            if !(within && zeta_std < zeta && strength[k] >= chance) {
                bad.push(k);
            }
            modes.push(Fitted {
                s: *s,
                cov: c,
                amplitude: amplitudes[k].clone(),
                stable_orders: starts[k].stable_orders,
            });
        }
        match weakest(&bad) {
            Some(k) => Err(k),
            None => Ok(modes),
        }
    }

    /// The complex amplitudes `a_ck` (Eq. I1) in the channels' units from the coefficients of
    /// the basis (Eq. I6): `a = coef_cos - i coef_sin`, unweighted.
    fn amplitudes(&self, coef: &Mat<f64>, modes: usize) -> Vec<Vec<c64>> {
        (0..modes)
            .map(|k| {
                (0..self.weights.len())
                    .map(|c| c64::new(coef[(1 + 2 * k, c)], -coef[(2 + 2 * k, c)]) / self.weights[c])
                    .collect()
            })
            .collect()
    }

    /// `kappa s^2 (J^T J)^{-1}` at the optimum (Eqs. I10, I11); `None` when `J^T J` is singular.
    fn covariance(&self, theta: &[f64], proj: &Projection) -> Option<Mat<f64>> {
        let r = &proj.r;
        let jac = self.jacobian(theta, proj);
        let jtj = jac.transpose() * &jac;
        let llt = jtj.llt(Side::Lower).ok()?;
        let (n, m, p) = (self.y.nrows(), self.y.ncols(), theta.len());
        let dof = (m * n).saturating_sub(m * (1 + p) + p).max(1) as f64;
        let s2 = dot(r, r) / dof;
        let kappa = r.chunks_exact(n).map(ar1_factor).fold(1.0, f64::max);
        let inv = llt.inverse();
        let finite = (0..p).all(|i| (0..p).all(|j| inv[(i, j)].is_finite()));
        finite.then(|| inv * faer::Scale(kappa * s2))
    }
}

/// Each mode's energy in the weighted record at a projection, `sum_c sum_j (coef_cos phi_cos +
/// coef_sin phi_sin)^2` (Eq. I8; in units of the noise variance once the weights are the noise
/// levels).
fn energies(proj: &Projection) -> Vec<f64> {
    let (phi, coef) = (&proj.phi, &proj.coef);
    (0..(phi.ncols() - 1) / 2)
        .map(|k| {
            let (cc, cs) = (1 + 2 * k, 2 + 2 * k);
            (0..coef.ncols())
                .map(|c| {
                    (0..phi.nrows())
                        .map(|j| (coef[(cc, c)] * phi[(j, cc)] + coef[(cs, c)] * phi[(j, cs)]).powi(2))
                        .sum::<f64>()
                })
                .sum()
        })
        .collect()
}

/// The energy that white noise of unit variance in `m` channels of `n` samples puts into the
/// best-fitting mode with probability [`FALSE_ALARM`] (Eq. I8): `x` with
/// `P(chi2_{2m} > x) = FALSE_ALARM / (n / 2)`, the `n / 2` independent frequencies searched.
pub(crate) fn chance_energy(m: usize, n: usize) -> f64 {
    let p = FALSE_ALARM / (0.5 * n as f64).max(1.0);
    // P(chi2_{2m} > x) = exp(-x/2) sum_{i<m} (x/2)^i / i!, decreasing in x: bisection
    let survival = |x: f64| {
        let h = 0.5 * x;
        let (mut term, mut sum) = (1.0, 1.0);
        for i in 1..m {
            term *= h / i as f64;
            sum += term;
        }
        (-h + sum.ln()).exp()
    };
    let (mut lo, mut hi) = (0.0, 2.0 * m as f64 + 200.0);
    while survival(hi) > p {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if survival(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The AR(1) variance factor `(1 + rho) / (1 - rho)` of one channel's residual (Eq. I11), at
/// least 1.
fn ar1_factor(r: &[f64]) -> f64 {
    let num: f64 = r.windows(2).map(|w| w[0] * w[1]).sum();
    let den = dot(r, r);
    if den == 0.0 {
        return 1.0;
    }
    let rho = (num / den).clamp(0.0, RHO_MAX);
    (1.0 + rho) / (1.0 - rho)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. I8's level against the chi-square tail in closed form for one channel
    /// (`P(chi2_2 > x) = exp(-x / 2)`) and a tabulated quantile for two (chi2_4 at 1e-6: 33.38).
    #[test]
    fn chance_energy_against_chi_square_tails() {
        let n = 2000;
        let p = FALSE_ALARM / 1000.0;
        assert!((chance_energy(1, n) - (-2.0 * p.ln())).abs() < 1e-9);
        assert!((chance_energy(2, n) - 33.38).abs() < 0.01, "{}", chance_energy(2, n));
    }

    /// White noise has an AR(1) factor near 1, a smooth residual a large one.
    #[test]
    fn ar1_factor_of_white_and_smooth_residuals() {
        let mut n = flexstar_model::sensors::daq::Normal::new(1, 0);
        let white: Vec<f64> = (0..20000).map(|_| n.draw()).collect();
        assert!((ar1_factor(&white) - 1.0).abs() < 0.03);
        let smooth: Vec<f64> = (0..2000).map(|j| (j as f64 * 0.01).sin()).collect();
        assert!(ar1_factor(&smooth) > 100.0);
    }
}
