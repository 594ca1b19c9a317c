//! The worst-case (or quantile) search of a robust plan (`docs/motions.md` 4.11): minimise
//! `max_{k in S_q} |r_k(x)|` over the sample models (Eq. U1) by Gauss-Newton steps on the
//! epigraph (Eq. U3, [`crate::qp::epigraph_step`]), each model's Jacobian on its slope model
//! ([`crate::slopes`]: the tangent-linear AMM where it covers the model, else forward
//! differences; 4.9, "The Jacobian's step"), the damping and the acceptance of 4.9: a trial is accepted when
//! every model's evaluation is within its limits and the objective falls.

use std::time::Instant;

use faer::Mat;
use rayon::prelude::*;

use crate::lm::{jacobian, Jacobian, TraceRow, MAX_ITERATIONS, MU0, MU_MAX, STALL};
use crate::objective::{Eval, Rejected};
use crate::qp::{epigraph_step, linearised_limits, Block};

/// What the search needs of the models: their count, an evaluation of model `k` at `x`, and
/// whether an evaluation of model `k` is within its limits.
pub trait Models: Sync {
    fn count(&self) -> usize;
    fn eval(&self, k: usize, x: &[f64]) -> Result<Eval, Rejected>;
    fn accept(&self, k: usize, e: &Eval) -> bool;
    /// Model `k`'s Jacobian at `x` and the runs it took, on its slope model (`docs/motions.md`
    /// 4.9, "The Jacobian's step", "The Jacobian from the tangent"); `None` when it is forward
    /// differences of [`Models::eval`] itself.
    fn slope_jacobian(&self, k: usize, x: &[f64]) -> Option<Result<(Jacobian, usize), Rejected>> {
        let _ = (k, x);
        None
    }
}

/// When the search stops.
#[derive(Debug, Clone)]
pub struct Stop {
    /// Each model's floor [m] (`FLOOR_SHARE` of its plain quintic's `|r|`): the search stops
    /// when every model of the objective is at or below its own.
    pub floors: Vec<f64>,
    pub deadline: Instant,
}

/// The outcome.
#[derive(Debug, Clone)]
pub struct Solution {
    pub x: Vec<f64>,
    /// Every model's evaluation at `x`.
    pub evals: Vec<Eval>,
    /// The objective of Eq. U1 at `x` [m].
    pub objective: f64,
    pub trace: Vec<TraceRow>,
    pub evaluations: usize,
    pub reason: String,
}

/// The models of the objective (Eq. U1): the `ceil(q K)` of smallest `|r_k|`, in model order.
pub fn active(norms: &[f64], quantile: f64) -> Vec<usize> {
    let count = ((quantile * norms.len() as f64).ceil() as usize).clamp(1, norms.len());
    let mut order: Vec<usize> = (0..norms.len()).collect();
    order.sort_by(|&a, &b| norms[a].total_cmp(&norms[b]));
    let mut keep = order[..count].to_vec();
    keep.sort_unstable();
    keep
}

/// The objective of Eq. U1: the largest `|r_k|` over [`active`] models (the q-quantile of the
/// sample; the worst for q = 1).
pub fn objective(norms: &[f64], quantile: f64) -> f64 {
    active(norms, quantile).iter().map(|&k| norms[k]).fold(0.0, f64::max)
}

/// Minimise Eq. U1 from `x0` (`e0`: every model's evaluation there, each within its limits).
pub fn minimise<M: Models>(
    models: &M,
    quantile: f64,
    x0: Vec<f64>,
    e0: Vec<Eval>,
    stop: &Stop,
) -> Result<Solution, Rejected> {
    let start = Instant::now();
    let mut s = State {
        x: x0,
        evals: e0,
        trace: Vec::new(),
        evaluations: models.count(),
        quantile,
        start,
    };
    s.record(0.0);
    let mut mu = MU0;
    let reason = loop {
        if let Some(reason) = s.finished(stop) {
            break reason;
        }
        let (jacs, runs) = jacobians(models, &s.x, &s.evals)?;
        s.evaluations += runs;
        let before = s.objective();
        if s.step(models, &jacs, &mut mu, stop).is_none() {
            break if Instant::now() >= stop.deadline {
                "the wall-clock budget is spent".to_string()
            } else {
                "no step lowers the worst residual within the limits (damping at its largest)".to_string()
            };
        }
        if before - s.objective() < STALL * before {
            break "the objective fell by less than 1 % in one iteration".to_string();
        }
    };
    Ok(Solution {
        objective: s.objective(),
        x: s.x,
        evals: s.evals,
        trace: s.trace,
        evaluations: s.evaluations,
        reason,
    })
}

/// Every model's Jacobian at `x`, and the runs they took.
fn jacobians<M: Models>(models: &M, x: &[f64], evals: &[Eval]) -> Result<(Vec<Jacobian>, usize), Rejected> {
    let mut runs = 0;
    let mut jacs = Vec::with_capacity(models.count());
    for (k, own) in evals.iter().enumerate().take(models.count()) {
        // a slope model that cannot run a column gives way to the model itself
        let (jac, n) = match models.slope_jacobian(k, x) {
            Some(Ok(done)) => done,
            _ => jacobian(&|y: &[f64]| models.eval(k, y), x, Some(own))?,
        };
        runs += n;
        jacs.push(jac);
    }
    Ok((jacs, runs))
}

struct State {
    x: Vec<f64>,
    evals: Vec<Eval>,
    trace: Vec<TraceRow>,
    evaluations: usize,
    quantile: f64,
    start: Instant,
}

impl State {
    fn norms(&self) -> Vec<f64> {
        self.evals.iter().map(Eval::norm).collect()
    }

    fn objective(&self) -> f64 {
        objective(&self.norms(), self.quantile)
    }

    fn record(&mut self, damping: f64) {
        let active = active(&self.norms(), self.quantile);
        let worst_g = active.iter().map(|&k| self.evals[k].norm_g()).fold(0.0, f64::max);
        let peak = active.iter().map(|&k| self.evals[k].window_peak_m).fold(0.0, f64::max);
        self.trace.push(TraceRow {
            iteration: self.trace.len(),
            evaluations: self.evaluations,
            r_norm_m: worst_g,
            objective_m: self.objective(),
            window_peak_m: peak,
            damping,
            wall_s: self.start.elapsed().as_secs_f64(),
        });
    }

    fn finished(&self, stop: &Stop) -> Option<String> {
        let active = active(&self.norms(), self.quantile);
        if active.iter().all(|&k| self.evals[k].norm_g() <= stop.floors[k] * 1.05) {
            Some("every sample model at or below its model floor".into())
        } else if Instant::now() >= stop.deadline {
            Some("the wall-clock budget is spent".into())
        } else if self.trace.len() > MAX_ITERATIONS {
            Some(format!("{MAX_ITERATIONS} iterations"))
        } else {
            None
        }
    }

    /// Epigraph trials (Eq. U3) with growing damping until one lowers the objective within
    /// every model's limits.
    fn step<M: Models>(&mut self, models: &M, jacs: &[Jacobian], mu: &mut f64, stop: &Stop) -> Option<()> {
        let phi = self.objective().max(1e-300);
        let active = active(&self.norms(), self.quantile);
        let blocks: Vec<Block> = active
            .iter()
            .map(|&k| {
                let j = Mat::from_fn(jacs[k].r.nrows(), jacs[k].r.ncols(), |i, c| jacs[k].r[(i, c)] / phi);
                let r: Vec<f64> = self.evals[k].r.iter().map(|v| v / phi).collect();
                Block::of(&j, &r)
            })
            .collect();
        let scale = blocks
            .iter()
            .flat_map(|b| (0..self.x.len()).map(move |c| b.a.iter().map(|row| row[c] * row[c]).sum::<f64>()))
            .fold(0.0, f64::max)
            .max(1e-300);
        let limits = self.stacked_limits(jacs);
        while *mu <= MU_MAX && Instant::now() < stop.deadline {
            let dx = epigraph_step(&blocks, *mu * scale, limits.as_ref())?;
            let trial: Vec<f64> = self.x.iter().zip(&dx).map(|(x, d)| x + d).collect();
            self.evaluations += models.count();
            let evals: Vec<Result<Eval, Rejected>> = (0..models.count())
                .into_par_iter()
                .map(|k| models.eval(k, &trial))
                .collect();
            let ok: Option<Vec<Eval>> = evals
                .into_iter()
                .enumerate()
                .map(|(k, e)| e.ok().filter(|e| models.accept(k, e)))
                .collect();
            match ok {
                Some(e) if objective(&e.iter().map(Eval::norm).collect::<Vec<_>>(), self.quantile) < phi => {
                    self.x = trial;
                    self.evals = e;
                    self.record(*mu);
                    *mu = (*mu / 3.0).max(1e-12);
                    return Some(());
                }
                _ => *mu *= 10.0,
            }
        }
        None
    }

    /// The limits' and progress rows of every model, stacked, linearised (4.9, 4.10).
    fn stacked_limits(&self, jacs: &[Jacobian]) -> Option<crate::qp::LinearLimits> {
        let n = self.x.len();
        let usage: Vec<f64> = self.evals.iter().flat_map(|e| e.usage.iter().copied()).collect();
        let progress: Vec<f64> = self.evals.iter().flat_map(|e| e.progress.iter().copied()).collect();
        let stack = |m: &dyn Fn(&Jacobian) -> &Mat<f64>| {
            let rows: Vec<Vec<f64>> = jacs
                .iter()
                .flat_map(|j| {
                    let mat = m(j);
                    (0..mat.nrows()).map(move |i| (0..n).map(|c| mat[(i, c)]).collect::<Vec<f64>>())
                })
                .collect();
            Mat::from_fn(rows.len(), n, |i, c| rows[i][c])
        };
        linearised_limits(&usage, &stack(&|j| &j.usage), &progress, &stack(&|j| &j.progress))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objective::eval_of;

    /// Three "models" `r_k(x) = (x_0 - c_k, 0.5 (x_1 - d_k))`: the minimax point is the centre
    /// of the smallest circle (in the scaled metric) through the three targets, here known in
    /// closed form: targets (0, 0), (2, 0), (1, 4) in (x_0, x_1 / 2) coordinates ... (1, 2) with
    /// the x_1 axis halved gives the points (0,0), (2,0), (1,2): circumcentre (1, 0.75),
    /// radius 1.25.
    struct Three;
    impl Models for Three {
        fn count(&self) -> usize {
            3
        }
        fn eval(&self, k: usize, x: &[f64]) -> Result<Eval, Rejected> {
            let (c, d) = [(0.0, 0.0), (2.0, 0.0), (1.0, 4.0)][k];
            Ok(eval_of(vec![x[0] - c, 0.5 * (x[1] - d)]))
        }
        fn accept(&self, _: usize, _: &Eval) -> bool {
            true
        }
    }

    #[test]
    fn finds_the_minimax_point_of_three_models() {
        let stop = Stop {
            floors: vec![0.0; 3],
            deadline: Instant::now() + std::time::Duration::from_secs(10),
        };
        let x0 = vec![5.0, -3.0];
        let e0 = (0..3).map(|k| Three.eval(k, &x0).unwrap()).collect();
        let s = minimise(&Three, 1.0, x0, e0, &stop).unwrap();
        // in (x_0, x_1 / 2): (1, 0.75) -> x = (1, 1.5), worst residual 1.25
        assert!(
            (s.x[0] - 1.0).abs() < 1e-3 && (s.x[1] - 1.5).abs() < 2e-3 && (s.objective - 1.25).abs() < 1e-3,
            "{:?} {} {}",
            s.x,
            s.objective,
            s.reason
        );
    }

    /// The quantile drops the worst models: with q = 2/3 of three models the objective is the
    /// second smallest norm.
    #[test]
    fn the_quantile_keeps_the_smallest_share() {
        assert_eq!(active(&[3.0, 1.0, 2.0], 2.0 / 3.0), vec![1, 2]);
        assert_eq!(objective(&[3.0, 1.0, 2.0], 2.0 / 3.0), 2.0);
        assert_eq!(objective(&[3.0, 1.0, 2.0], 1.0), 3.0);
        assert_eq!(objective(&[3.0, 1.0, 2.0], 0.01), 1.0);
    }
}
