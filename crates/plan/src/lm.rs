//! Levenberg-Marquardt on the residual vector of an evaluation (`docs/motions.md` 4.5): the
//! Jacobian by forward differences, its columns evaluated in parallel, or given by the caller
//! (the tangent-linear AMM on a cheaper model than the one that judges the iterates: 4.9, "The
//! Jacobian's step" and "The Jacobian from the tangent"). With limits, each damped
//! step is a small quadratic program: the Gauss-Newton model of `|r|^2` minimised within the
//! limits linearised at the iterate ([`crate::qp`]). A trial step that breaks a limit, leaves the
//! workspace or does not lower `|r|` is rejected and the damping raised, so that every accepted
//! iterate is feasible and within the limits.
//!
//! Written here rather than taken from a crate: the steps must be rejected on feasibility and
//! limits (a constraint a least-squares crate does not know), the Jacobian's columns are whole
//! AMM runs that run in parallel, and the search stops on a wall-clock budget and a model floor.

use std::time::Instant;

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;
use serde::Serialize;

use crate::objective::{Eval, Rejected};

/// Relative step of the forward differences (4.5: derivatives to about 1e-7).
pub(crate) const FD_STEP: f64 = 1e-6;
/// Initial damping, relative to the largest diagonal entry of `J^T J`.
pub(crate) const MU0: f64 = 1e-4;
/// Damping at which the search gives up on a step.
pub(crate) const MU_MAX: f64 = 1e8;
/// Most iterations.
pub(crate) const MAX_ITERATIONS: usize = 40;
/// A step landing below this share of the model floor is shortened onto the floor.
const FLOOR_LANDING: f64 = 0.8;
/// Stop when `|r|^2` fell by less than this share in one iteration.
pub(crate) const STALL: f64 = 1e-2;

/// When the search stops.
#[derive(Debug, Clone, Copy)]
pub struct Stop {
    /// `|r|` at or below this is good enough [m] (the model floor).
    pub r_floor: f64,
    /// The wall-clock deadline.
    pub deadline: Instant,
}

/// One accepted iterate of the trace (plan.json).
#[derive(Debug, Clone, Serialize)]
pub struct TraceRow {
    pub iteration: usize,
    /// Evaluations so far.
    pub evaluations: usize,
    /// `|r|`: RMS of |dG| over the window [m].
    pub r_norm_m: f64,
    /// The square root of the objective, tips' and smoothness terms included (4.10) [m].
    pub objective_m: f64,
    /// Peak |dG| over the window [m].
    pub window_peak_m: f64,
    /// The damping of the accepted step (relative).
    pub damping: f64,
    /// Wall time since the start [s].
    pub wall_s: f64,
}

/// The outcome of a search.
#[derive(Debug, Clone)]
pub struct Solution {
    pub x: Vec<f64>,
    pub eval: Eval,
    pub trace: Vec<TraceRow>,
    pub evaluations: usize,
    /// Why it stopped.
    pub reason: String,
}

/// Minimise `|r(x)|^2` from `x0` (whose evaluation `e0` must be feasible); `accept` tells a
/// trial within the limits. `slope`: the Jacobian at a point and the runs it took
/// (`docs/motions.md` 4.9, "The Jacobian's step"); `None`, forward differences of `f` itself.
/// Every iterate and trial is judged by `f`.
pub fn minimise<F, G, A>(
    f: &F,
    slope: Option<&G>,
    accept: &A,
    x0: Vec<f64>,
    e0: Eval,
    stop: Stop,
) -> Result<Solution, Rejected>
where
    F: Fn(&[f64]) -> Result<Eval, Rejected> + Sync,
    G: Fn(&[f64]) -> Result<(Jacobian, usize), Rejected>,
    A: Fn(&Eval) -> bool,
{
    let start = Instant::now();
    let mut s = Search::new(x0, e0, start);
    let mut mu = MU0;
    let mut previous = s.cost();
    loop {
        if let Some(reason) = s.finished(stop) {
            s.reason = reason;
            break;
        }
        // a slope model that cannot run a column (a run that fails at its step) gives way to
        // the search's own model
        let (jac, runs) = match slope.map(|g| g(&s.x)) {
            Some(Ok(done)) => done,
            _ => jacobian(f, &s.x, Some(&s.eval))?,
        };
        s.evaluations += runs;
        match s.step(f, accept, &jac, &mut mu, stop) {
            Some(()) => {}
            None if Instant::now() >= stop.deadline => {
                s.reason = "the wall-clock budget is spent".into();
                break;
            }
            None => {
                s.reason =
                    "no step lowers |r| within the limits: a minimum of the family (damping at its largest)".into();
                break;
            }
        }
        let cost = s.cost();
        if previous - cost < STALL * previous {
            s.reason = "|r|^2 fell by less than 1 % in one iteration".into();
            break;
        }
        previous = cost;
    }
    Ok(s.into_solution())
}

/// The state of a search.
struct Search {
    x: Vec<f64>,
    eval: Eval,
    trace: Vec<TraceRow>,
    evaluations: usize,
    start: Instant,
    reason: String,
}

impl Search {
    fn new(x: Vec<f64>, eval: Eval, start: Instant) -> Self {
        let mut s = Search {
            x,
            eval,
            trace: Vec::new(),
            evaluations: 1,
            start,
            reason: String::new(),
        };
        s.record(0.0);
        s
    }

    fn cost(&self) -> f64 {
        self.eval.norm().powi(2)
    }

    fn record(&mut self, damping: f64) {
        self.trace.push(TraceRow {
            iteration: self.trace.len(),
            evaluations: self.evaluations,
            r_norm_m: self.eval.norm_g(),
            objective_m: self.eval.norm(),
            window_peak_m: self.eval.window_peak_m,
            damping,
            wall_s: self.start.elapsed().as_secs_f64(),
        });
    }

    fn finished(&self, stop: Stop) -> Option<String> {
        if self.eval.norm_g() <= stop.r_floor * 1.05 {
            Some(format!("|r| at or below the model floor {:.3e} m", stop.r_floor))
        } else if Instant::now() >= stop.deadline {
            Some("the wall-clock budget is spent".into())
        } else if self.trace.len() > MAX_ITERATIONS {
            Some(format!("{MAX_ITERATIONS} iterations"))
        } else {
            None
        }
    }

    /// Damped Gauss-Newton trials until one lowers the cost within the limits (`None`: the
    /// damping reached [`MU_MAX`] or the deadline passed first).
    fn step<F, A>(&mut self, f: &F, accept: &A, jac: &Jacobian, mu: &mut f64, stop: Stop) -> Option<()>
    where
        F: Fn(&[f64]) -> Result<Eval, Rejected> + Sync,
        A: Fn(&Eval) -> bool,
    {
        let (jtj, jtr) = normal_equations(&jac.r, &self.eval.r);
        let scale = (0..jtj.nrows()).map(|i| jtj[(i, i)]).fold(0.0, f64::max).max(1e-300);
        let limits = crate::qp::linearised_limits(&self.eval.usage, &jac.usage, &self.eval.progress, &jac.progress);
        while *mu <= MU_MAX && Instant::now() < stop.deadline {
            let dx = match &limits {
                None => damped_step(&jtj, &jtr, *mu * scale)?,
                Some(lim) => crate::qp::damped_step_within(&jtj, &jtr, *mu * scale, lim)?,
            };
            let trial: Vec<f64> = self.x.iter().zip(&dx).map(|(x, d)| x + d).collect();
            self.evaluations += 1;
            match f(&trial) {
                Ok(e) if accept(&e) && e.norm() < self.eval.norm() => {
                    let (x, e) = self.onto_floor(f, accept, &dx, (trial, e), stop.r_floor);
                    self.x = x;
                    self.eval = e;
                    self.record(*mu);
                    *mu = (*mu / 3.0).max(1e-12);
                    return Some(());
                }
                _ => *mu *= 10.0,
            }
        }
        None
    }

    /// A step that lands well below the model floor is shortened to land on it (4.5: below
    /// the floor the model cannot vouch for the residual, and a shorter step keeps the motion
    /// closer to the plain quintic): `alpha` from the affine model `r(alpha) = r0 + alpha (r1 -
    /// r0)` of G's rows along the step, `|r_G(alpha)| = r_floor`. The full step stays when the
    /// shortened one is rejected.
    fn onto_floor<F, A>(
        &mut self,
        f: &F,
        accept: &A,
        dx: &[f64],
        full: (Vec<f64>, Eval),
        r_floor: f64,
    ) -> (Vec<f64>, Eval)
    where
        F: Fn(&[f64]) -> Result<Eval, Rejected> + Sync,
        A: Fn(&Eval) -> bool,
    {
        if full.1.norm_g() >= FLOOR_LANDING * r_floor {
            return full;
        }
        let n_g = self.eval.n_g;
        let (r0, r1) = (&self.eval.r[..n_g], &full.1.r[..n_g]);
        let d: Vec<f64> = r1.iter().zip(r0).map(|(a, b)| a - b).collect();
        let a = d.iter().map(|v| v * v).sum::<f64>();
        let b = 2.0 * r0.iter().zip(&d).map(|(p, q)| p * q).sum::<f64>();
        let c = r0.iter().map(|v| v * v).sum::<f64>() - r_floor * r_floor;
        let disc = b * b - 4.0 * a * c;
        if a <= 0.0 || disc < 0.0 {
            return full;
        }
        let alpha = (-b - disc.sqrt()) / (2.0 * a);
        if !(alpha > 0.0 && alpha < 1.0) {
            return full;
        }
        let trial: Vec<f64> = self.x.iter().zip(dx).map(|(x, d)| x + alpha * d).collect();
        self.evaluations += 1;
        match f(&trial) {
            Ok(e) if accept(&e) && e.norm() < self.eval.norm() => (trial, e),
            _ => full,
        }
    }

    fn into_solution(self) -> Solution {
        Solution {
            x: self.x,
            eval: self.eval,
            trace: self.trace,
            evaluations: self.evaluations,
            reason: self.reason,
        }
    }
}

/// The Jacobians of the residual vector, of the limits' usage and of the progress rows at one
/// point.
pub struct Jacobian {
    pub r: Mat<f64>,
    pub usage: Mat<f64>,
    pub progress: Mat<f64>,
}

/// The forward-difference step of variable `x` (4.5).
pub(crate) fn difference_step(x: f64) -> f64 {
    FD_STEP * x.abs().max(1.0)
}

/// One column's point: the evaluation at `x + sign h e_j`, the sign and `h`.
pub(crate) type Point = (Eval, f64, f64);

/// The Jacobians of `r` and of the usage at `x` by forward differences of `f` (a backward
/// difference where the forward point is rejected), the columns in parallel. `base`: `f`'s
/// evaluation at `x` when known; `None` runs it beside the columns. Returns the Jacobian and the
/// runs it took.
pub(crate) fn jacobian<F>(f: &F, x: &[f64], base: Option<&Eval>) -> Result<(Jacobian, usize), Rejected>
where
    F: Fn(&[f64]) -> Result<Eval, Rejected> + Sync,
{
    let n = x.len();
    let extra = usize::from(base.is_none());
    // item j < n: the column's point and the difference's sign; item n: the base point
    let points: Vec<Result<Point, Rejected>> = (0..n + extra)
        .into_par_iter()
        .map(|j| {
            if j == n {
                return f(x).map(|e| (e, 0.0, 0.0));
            }
            let h = difference_step(x[j]);
            let at = |sign: f64| {
                let mut xp = x.to_vec();
                xp[j] += sign * h;
                f(&xp)
            };
            match at(1.0) {
                Ok(e) => Ok((e, 1.0, h)),
                Err(_) => Ok((at(-1.0)?, -1.0, h)),
            }
        })
        .collect();
    let mut points = points.into_iter().collect::<Result<Vec<_>, _>>()?;
    let own_base = (extra == 1).then(|| points.pop().map(|(e, _, _)| e)).flatten();
    let e0 = own_base.as_ref().or(base).expect("the base evaluation is given or run");
    Ok((assemble(e0, &points), n + extra))
}

/// The Jacobian whose column j is the difference of `points[j]` from the base evaluation `e0`
/// over its signed step.
pub(crate) fn assemble(e0: &Eval, points: &[Point]) -> Jacobian {
    let rows0: Vec<f64> = e0.r.iter().chain(&e0.usage).chain(&e0.progress).copied().collect();
    let columns: Vec<Vec<f64>> = points
        .iter()
        .map(|(e, sign, h)| {
            let rows = e.r.iter().chain(&e.usage).chain(&e.progress);
            rows.zip(&rows0).map(|(a, b)| sign * (a - b) / h).collect()
        })
        .collect();
    let (nr, nu) = (e0.r.len(), e0.usage.len());
    Jacobian {
        r: Mat::from_fn(nr, points.len(), |i, j| columns[j][i]),
        usage: Mat::from_fn(nu, points.len(), |i, j| columns[j][nr + i]),
        progress: Mat::from_fn(e0.progress.len(), points.len(), |i, j| columns[j][nr + nu + i]),
    }
}

/// `J^T J` and `J^T r`.
fn normal_equations(jac: &Mat<f64>, r: &[f64]) -> (Mat<f64>, Mat<f64>) {
    let jtj = jac.transpose() * jac;
    let rv = Mat::from_fn(r.len(), 1, |i, _| r[i]);
    let jtr = jac.transpose() * &rv;
    (jtj, jtr)
}

/// Solve `(J^T J + lambda I) dx = -J^T r` (Cholesky; `None` if not positive definite).
fn damped_step(jtj: &Mat<f64>, jtr: &Mat<f64>, lambda: f64) -> Option<Vec<f64>> {
    let n = jtj.nrows();
    let a = Mat::from_fn(n, n, |i, j| jtj[(i, j)] + if i == j { lambda } else { 0.0 });
    let llt = a.llt(Side::Lower).ok()?;
    let dx = llt.solve(jtr);
    Some((0..n).map(|i| -dx[(i, 0)]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objective::eval_of;

    /// A residual function of the tests.
    type Residual = dyn Fn(&[f64]) -> Result<Eval, Rejected> + Sync;

    /// Rosenbrock's function as least squares, `r = (10 (y - x^2), 1 - x)`, searched from the
    /// textbook start (-1.2, 1), the Jacobian's runs on `slope` (`None`: `r` itself): the
    /// minimum reached, to 1e-6.
    fn assert_rosenbrock_minimum(slope: Option<&Residual>) {
        let f = |x: &[f64]| Ok(eval_of(vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]));
        let x0 = vec![-1.2, 1.0];
        let e0 = f(&x0).unwrap();
        let stop = Stop {
            r_floor: 1e-10,
            deadline: Instant::now() + std::time::Duration::from_secs(10),
        };
        let slope = slope.map(|g| move |x: &[f64]| jacobian(&|y: &[f64]| g(y), x, None));
        let s = minimise(&f, slope.as_ref(), &|_: &Eval| true, x0, e0, stop).unwrap();
        assert!(
            (s.x[0] - 1.0).abs() < 1e-6 && (s.x[1] - 1.0).abs() < 1e-6,
            "{:?}: {}",
            s.x,
            s.reason
        );
    }

    /// The textbook minimum (1, 1) of Rosenbrock's function from the textbook start (-1.2, 1).
    #[test]
    fn finds_the_rosenbrock_minimum() {
        assert_rosenbrock_minimum(None);
    }

    /// The Jacobian from a different model than the one that judges the trials (4.9, "The
    /// Jacobian's step"): a slope model whose first residual is 5 % too large and whose own
    /// minimum is elsewhere, (1.02, 1.0404), still leads the search to Rosenbrock's textbook
    /// minimum (1, 1): every trial is judged by the true residual, and with an invertible
    /// Jacobian the search stops only where that residual is zero.
    #[test]
    fn a_slope_model_still_finds_the_minimum_of_the_true_residual() {
        let g = |x: &[f64]| Ok(eval_of(vec![10.5 * (x[1] - x[0] * x[0]), 1.02 - x[0]]));
        assert_rosenbrock_minimum(Some(&g));
    }

    /// A progress row (`docs/motions.md` 4.10) is a linear constraint the step honours exactly:
    /// the minimum of `(x - 2)^2 + (y - 1)^2` with the rows `x - 1.5 <= 0` and `x + y - 2 <= 0`
    /// is the textbook KKT point (1.5, 0.5), reached without ever crossing a row (from a start
    /// where both rows are active, above `qp::PROGRESS_ACTIVE`).
    #[test]
    fn progress_rows_bound_the_search_like_linear_constraints() {
        let f = |x: &[f64]| {
            let mut e = eval_of(vec![x[0] - 2.0, x[1] - 1.0]);
            e.progress = vec![x[0] - 1.5, x[0] + x[1] - 2.0];
            Ok(e)
        };
        let x0 = vec![1.3, 0.4];
        let e0 = f(&x0).unwrap();
        let stop = Stop {
            r_floor: 0.0,
            deadline: Instant::now() + std::time::Duration::from_secs(10),
        };
        let accept = |e: &Eval| e.within(&crate::section::Limits::default());
        let s = minimise(
            &f,
            None::<&fn(&[f64]) -> Result<(Jacobian, usize), Rejected>>,
            &accept,
            x0,
            e0,
            stop,
        )
        .unwrap();
        assert!(
            (s.x[0] - 1.5).abs() < 1e-4 && (s.x[1] - 0.5).abs() < 1e-4,
            "{:?}: {}",
            s.x,
            s.reason
        );
        assert!(
            s.eval.progress.iter().all(|p| *p <= crate::objective::PROGRESS_TOL),
            "{:?}",
            s.eval.progress
        );
    }

    /// A rejected region is never entered: the minimum of `(x - 2)^2` with every `x > 1.5`
    /// rejected stays at or below 1.5 and comes close to it.
    #[test]
    fn rejected_trials_are_never_accepted() {
        let f = |x: &[f64]| {
            if x[0] > 1.5 {
                Err(Rejected::Infeasible("x > 1.5".into()))
            } else {
                Ok(eval_of(vec![x[0] - 2.0]))
            }
        };
        let x0 = vec![0.0];
        let e0 = f(&x0).unwrap();
        let stop = Stop {
            r_floor: 0.0,
            deadline: Instant::now() + std::time::Duration::from_secs(10),
        };
        let s = minimise(
            &f,
            None::<&fn(&[f64]) -> Result<(Jacobian, usize), Rejected>>,
            &|_: &Eval| true,
            x0,
            e0,
            stop,
        )
        .unwrap();
        assert!(s.x[0] <= 1.5 && s.x[0] > 1.49, "{:?}", s.x);
    }
}
