//! The search (`docs/measured.md` 4.4-4.6, Eqs. LS6-LS10): Levenberg-Marquardt on the scaled
//! parameters, kept inside their box by an active set and a projection.
//!
//! Each iteration: the gradient `g = J^T r` and the Gauss-Newton matrix `A = J^T J` (Eq. LS6);
//! the parameters at a bound whose gradient pushes them outwards are held (Eq. LS7); the damped
//! step of the others solves `(A_F + mu diag A_F) d = -g_F` (Eq. LS8) and is projected onto the
//! box; it is taken when the cost falls, the damping then lowered by the gain ratio (Nielsen's
//! rule), else the damping is raised and the step tried again. Where the model has
//! sensitivities, a trial after an accepted step carries the Jacobian's directions (4.5), so
//! that an accepted trial has its Jacobian without another run. The search stops on the relative
//! offset (Eq. LS10), a statistical criterion: the distance left to the optimum is below a
//! thousandth of the estimates' own uncertainty.

use std::time::Instant;

use nalgebra::{DMatrix, DVector};

use flexstar_model::SensorTable;

use crate::identifiability::Verdict;
use crate::jacobian::{evaluate_with_columns, jacobian, Columns};
use crate::outcome::{ChannelFit, Estimate, Fit, Iteration, StartOutcome, Stop};
use crate::problem::Problem;
use crate::step::{damped_step, free_set, normal_equations, predicted_decrease, project, relative_offset};
use crate::{FitError, Model};

/// The damping of the first step, relative to the diagonal of `A`.
pub const MU0: f64 = 1e-3;
/// The damping at which no step is left to try.
pub const MU_MAX: f64 = 1e10;

/// How long the search may go on and when it stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// The most iterations (accepted steps).
    pub max_iterations: usize,
    /// Eq. LS10: the relative offset below which the search has converged.
    pub offset_tol: f64,
    /// How many samples the model's error may stay correlated over: the bandwidth of Eq. LS18
    /// (`docs/measured.md` 4.7: one period of the slowest mode; 0 treats the residuals as white).
    pub correlation_samples: usize,
    /// How many starts (`docs/measured.md` 4.6): the given one, then `starts - 1` Halton points
    /// of the box ([`crate::starts::halton_starts`]); 0 and 1 are the given start alone.
    pub starts: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            max_iterations: 50,
            offset_tol: 1e-3,
            correlation_samples: 0,
            starts: 1,
        }
    }
}

/// An iterate: scaled parameters, residuals, the model's readings and the Jacobian there.
struct State {
    u: Vec<f64>,
    /// The parameters in their units: the starts as given at the start, `u` through Eq. LS5 after.
    theta: Vec<f64>,
    r: Vec<f64>,
    table: SensorTable,
    j: DMatrix<f64>,
    /// The model runs its Jacobian took beyond the evaluation's own, and whether it came from
    /// the model's sensitivities.
    j_runs: usize,
    j_tangent: bool,
}

impl State {
    fn cost(&self) -> f64 {
        cost(&self.r)
    }
}

/// Eq. LS4: `|r|^2 / 2`.
fn cost(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

/// Fit `problem` with `model`: the start evaluated with its Jacobian, refused when that Jacobian
/// is rank-deficient (Eq. LS15: the data cannot separate the parameters, named by their
/// combination), the search, then a search from each further start of `settings.starts`
/// (`docs/measured.md` 4.6), the best kept (converged before not, then the lowest cost), the
/// statistics and the identifiability at its end. `on_iteration` sees each search's start and
/// accepted iterates. A search that does not converge is still a [`Fit`] (its [`Fit::stop`] says
/// why); an error is a start that cannot be evaluated or separated.
pub fn fit<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    settings: &Settings,
    on_iteration: &dyn Fn(&Iteration),
) -> Result<Fit, FitError> {
    let started = Instant::now();
    let theta0: Vec<f64> = problem.params.iter().map(|p| p.start).collect();
    let start = evaluate_state(problem, model, problem.start_scaled(), theta0.clone())?;
    refuse_unidentifiable(problem, &start)?;
    let before = start.table.clone();
    let mut run = Run {
        problem,
        model,
        settings,
        started,
        evaluations: 0,
        jacobians: (0, 0),
        speculate: true,
        trace: Vec::new(),
    };
    run.count(&start);
    let mut best = run.search_from(start, on_iteration);
    let mut starts = vec![best.outcome(&theta0, settings.offset_tol)];
    let mut chosen = 0;
    for u in crate::starts::halton_starts(problem.params.len(), settings.starts.saturating_sub(1)) {
        let theta = problem.physical(&u);
        match evaluate_state(problem, model, u, theta.clone()) {
            Ok(state) => {
                run.count(&state);
                let other = run.search_from(state, on_iteration);
                starts.push(other.outcome(&theta, settings.offset_tol));
                if other.better_than(&best) {
                    best = other;
                    chosen = starts.len() - 1;
                }
            }
            Err(e) => {
                run.evaluations += 1;
                starts.push(StartOutcome {
                    start: theta.clone(),
                    end: theta,
                    cost: f64::NAN,
                    converged: false,
                    iterations: 0,
                    reason: e.to_string(),
                    chosen: false,
                });
            }
        }
    }
    starts[chosen].chosen = true;
    run.trace = best.trace;
    let mut fit = run.finish(best.end, best.stop, before);
    fit.starts = starts;
    Ok(fit)
}

/// One start's search: where it ended, why, and its iterations.
struct Searched {
    end: State,
    stop: Stop,
    trace: Vec<Iteration>,
}

impl Searched {
    /// Converged before not, then the lower cost.
    fn better_than(&self, other: &Searched) -> bool {
        match (self.stop.converged(), other.stop.converged()) {
            (true, false) => true,
            (false, true) => false,
            _ => self.end.cost() < other.end.cost(),
        }
    }

    /// Its summary, started at `start` (the parameters' units).
    fn outcome(&self, start: &[f64], tol: f64) -> StartOutcome {
        StartOutcome {
            start: start.to_vec(),
            end: self.end.theta.clone(),
            cost: self.end.cost(),
            converged: self.stop.converged(),
            iterations: self.trace.len().saturating_sub(1),
            reason: self.stop.text(tol),
            chosen: false,
        }
    }
}

/// The model and its Jacobian at the scaled `u`, whose physical values are `theta` (the given
/// start exactly as written, not through Eq. LS5).
fn evaluate_state<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    u: Vec<f64>,
    theta: Vec<f64>,
) -> Result<State, FitError> {
    let at = describe(problem, &theta);
    if let Some(done) = evaluate_with_columns(problem, model, &u) {
        let done = done.map_err(|reason| FitError::Evaluation { at, reason })?;
        return Ok(State {
            u,
            theta,
            r: done.r,
            table: done.readings,
            j: done.columns.j,
            j_runs: done.columns.runs - 1,
            j_tangent: true,
        });
    }
    let evaluated = model.evaluate(&theta).and_then(|t| Ok((problem.residuals(&t)?, t)));
    let (r, table) = evaluated.map_err(|reason| FitError::Evaluation { at: at.clone(), reason })?;
    let j = jacobian(problem, model, &u, &r).map_err(|(k, reason)| FitError::Evaluation {
        at: format!("{at} (the step of {})", problem.params[k].key),
        reason,
    })?;
    Ok(State {
        u,
        theta,
        r,
        table,
        j: j.j,
        j_runs: j.runs,
        j_tangent: j.by_tangent,
    })
}

/// `key = value` of every parameter.
fn describe(problem: &Problem, theta: &[f64]) -> String {
    problem
        .params
        .iter()
        .zip(theta)
        .map(|(p, v)| format!("{} = {}", p.key, number(*v)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A number in messages: plain between 1e-3 and 1e6, else with an exponent (`2.5e-12`).
fn number(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Eq. LS15 at the start: a rank-deficient Jacobian is refused before the search.
fn refuse_unidentifiable(problem: &Problem, s: &State) -> Result<(), FitError> {
    let check = crate::identifiability::check(&physical_jacobian(problem, &s.j), &problem.params, &s.theta);
    if check.verdict == Verdict::RankDeficient {
        return Err(FitError::Unidentifiable(format!(
            "at the start ({}): {}",
            describe(problem, &s.theta),
            check.message
        )));
    }
    Ok(())
}

/// `dr/dtheta` from `dr/du` (Eq. LS5: `du = dtheta / (hi - lo)`).
fn physical_jacobian(problem: &Problem, j: &DMatrix<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(j.nrows(), j.ncols(), |i, k| j[(i, k)] / problem.params[k].width())
}

/// The search's bookkeeping.
struct Run<'a, M: Model + ?Sized> {
    problem: &'a Problem,
    model: &'a M,
    settings: &'a Settings,
    started: Instant,
    evaluations: usize,
    /// The Jacobians taken, and how many of them came from the model's sensitivities.
    jacobians: (usize, usize),
    /// Whether the next trial carries the Jacobian's directions: after an accepted step (a
    /// rejected trial then costs the directions too), not after a rejected one.
    speculate: bool,
    trace: Vec<Iteration>,
}

/// A trial's residual vector and readings, and its Jacobian where the trial carried it.
type Evaluated = (Vec<f64>, SensorTable, Option<Columns>);

/// The outcome of one iteration.
enum Step {
    Accepted(State, f64),
    Stopped(Stop),
}

impl<M: Model + ?Sized> Run<'_, M> {
    /// Count an evaluated state: its run and its Jacobian's.
    fn count(&mut self, s: &State) {
        self.evaluations += 1 + s.j_runs;
        self.jacobians.0 += 1;
        self.jacobians.1 += usize::from(s.j_tangent);
    }

    /// A search from `s`, its iterations taken out of the bookkeeping.
    fn search_from(&mut self, s: State, on_iteration: &dyn Fn(&Iteration)) -> Searched {
        self.record(&s, 0, 0.0, on_iteration);
        let (end, stop) = self.search(s, on_iteration);
        Searched {
            end,
            stop,
            trace: std::mem::take(&mut self.trace),
        }
    }

    /// Iterate from `s` until Eq. LS10 holds or the search gives up.
    fn search(&mut self, mut s: State, on_iteration: &dyn Fn(&Iteration)) -> (State, Stop) {
        let mut mu = MU0;
        for iteration in 1..=self.settings.max_iterations {
            let (a, g) = normal_equations(&s.j, &s.r);
            let free = free_set(&s.u, &g);
            if !free.contains(&true) {
                return (s, Stop::AtBounds);
            }
            let offset = relative_offset(&a, &g, &free, &s.r);
            if offset <= self.settings.offset_tol {
                return (s, Stop::Converged { offset });
            }
            match self.iterate(&s, &a, &g, &free, &mut mu, offset) {
                Step::Accepted(next, damping) => {
                    s = next;
                    self.record(&s, iteration, damping, on_iteration);
                }
                Step::Stopped(stop) => return (s, stop),
            }
        }
        let (a, g) = normal_equations(&s.j, &s.r);
        let free = free_set(&s.u, &g);
        let offset = relative_offset(&a, &g, &free, &s.r);
        let stop = if offset <= self.settings.offset_tol {
            Stop::Converged { offset }
        } else {
            Stop::MaxIterations { offset }
        };
        (s, stop)
    }

    /// Try damped steps from `s` until one lowers the cost (then the Jacobian at the new
    /// iterate) or the damping passes [`MU_MAX`].
    fn iterate(
        &mut self,
        s: &State,
        a: &DMatrix<f64>,
        g: &DVector<f64>,
        free: &[bool],
        mu: &mut f64,
        offset: f64,
    ) -> Step {
        let mut nu = 2.0;
        let cost0 = s.cost();
        while *mu <= MU_MAX {
            let Some(d) = damped_step(a, g, free, *mu) else {
                *mu *= nu;
                nu *= 2.0;
                continue;
            };
            let u = project(&s.u, &d);
            let taken: Vec<f64> = u.iter().zip(&s.u).map(|(a, b)| a - b).collect();
            let predicted = predicted_decrease(a, g, &taken);
            // after an accepted step the trial carries the Jacobian's directions (the model's
            // sensitivities, `docs/measured.md` 4.5): an accepted trial then needs no more runs
            let speculated = (self.speculate)
                .then(|| evaluate_with_columns(self.problem, self.model, &u))
                .flatten();
            let (trial, columns) = match speculated {
                Some(Ok(done)) => (Ok((done.r, done.readings)), Some(done.columns)),
                Some(Err(e)) => (Err(e), None),
                None => (self.problem.evaluate(self.model, &u), None),
            };
            self.evaluations += columns.as_ref().map_or(1, |c| c.runs);
            if let Ok((r, table)) = trial {
                let actual = cost0 - cost(&r);
                if actual > 0.0 && predicted > 0.0 {
                    let rho = actual / predicted;
                    let damping = *mu;
                    *mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    self.speculate = true;
                    return self.accept(u, (r, table, columns), damping);
                }
            }
            self.speculate = false;
            *mu *= nu;
            nu *= 2.0;
        }
        Step::Stopped(Stop::NoDecrease { offset })
    }

    /// The Jacobian at an accepted iterate.
    fn accept(&mut self, u: Vec<f64>, (r, table, columns): Evaluated, damping: f64) -> Step {
        let taken = match columns {
            Some(c) => Ok(c),
            None => jacobian(self.problem, self.model, &u, &r).inspect(|j| self.evaluations += j.runs),
        };
        match taken {
            Ok(j) => {
                self.jacobians.0 += 1;
                self.jacobians.1 += usize::from(j.by_tangent);
                let theta = self.problem.physical(&u);
                let state = State {
                    u,
                    theta,
                    r,
                    table,
                    j: j.j,
                    j_runs: j.runs,
                    j_tangent: j.by_tangent,
                };
                Step::Accepted(state, damping)
            }
            Err((k, reason)) => Step::Stopped(Stop::EvaluationFailed {
                reason: format!(
                    "at {} (the step of {}): {reason}",
                    describe(self.problem, &self.problem.physical(&u)),
                    self.problem.params[k].key
                ),
            }),
        }
    }

    fn record(&mut self, s: &State, iteration: usize, damping: f64, on_iteration: &dyn Fn(&Iteration)) {
        let (a, g) = normal_equations(&s.j, &s.r);
        let row = Iteration {
            iteration,
            evaluations: self.evaluations,
            cost: s.cost(),
            theta: s.theta.clone(),
            offset: relative_offset(&a, &g, &free_set(&s.u, &g), &s.r),
            damping,
            wall_s: self.started.elapsed().as_secs_f64(),
        };
        on_iteration(&row);
        self.trace.push(row);
    }

    /// The estimates, the statistics (Eqs. LS11-LS14) and the identifiability (Eqs. LS15-LS16)
    /// at the last iterate.
    fn finish(self, s: State, stop: Stop, before: SensorTable) -> Fit {
        let p = self.problem;
        let theta = s.theta.clone();
        let at_bound: Vec<bool> = s.u.iter().map(|&u| u <= 0.0 || u >= 1.0).collect();
        let free: Vec<bool> = at_bound.iter().map(|b| !b).collect();
        let jp = physical_jacobian(p, &s.j);
        let layout = crate::stats::Layout {
            segment: p.t.len(),
            bandwidth: self.settings.correlation_samples,
        };
        let statistics = crate::stats::statistics(&jp, &s.r, &theta, &free, layout);
        let identifiability = crate::identifiability::check(&jp, &p.params, &theta);
        let estimates = p
            .params
            .iter()
            .enumerate()
            .map(|(k, q)| Estimate {
                key: q.key.clone(),
                lo: q.lo,
                hi: q.hi,
                start: q.start,
                estimate: theta[k],
                standard_error: statistics.standard_errors[k],
                standard_error_correlated: statistics.standard_errors_correlated[k],
                interval: statistics.intervals[k],
                at_bound: at_bound[k],
            })
            .collect();
        let channels = channel_fits(p, &before, &s.table);
        let reason = stop.text(self.settings.offset_tol);
        Fit {
            estimates,
            statistics,
            channels,
            identifiability,
            stop,
            reason,
            iterations: self.trace.len().saturating_sub(1),
            evaluations: self.evaluations,
            jacobians: self.jacobians.0,
            tangent_jacobians: self.jacobians.1,
            wall_s: self.started.elapsed().as_secs_f64(),
            trace: self.trace,
            starts: Vec::new(),
            before,
            after: s.table,
        }
    }
}

/// Every channel's RMS error before and after (the tables were evaluated on the recording's
/// times, so their errors exist).
fn channel_fits(p: &Problem, before: &SensorTable, after: &SensorTable) -> Vec<ChannelFit> {
    let rms_of = |t: &SensorTable| -> Vec<f64> {
        p.errors(t)
            .map(|e| e.iter().map(|x| crate::noise::rms(x)).collect())
            .unwrap_or_else(|_| vec![f64::NAN; p.channels.len()])
    };
    let (b, a) = (rms_of(before), rms_of(after));
    p.channels
        .iter()
        .enumerate()
        .map(|(k, c)| ChannelFit {
            column: c.column.clone(),
            unit: c.unit.clone(),
            weight: c.weight,
            noise: c.sigma,
            rms_before: b[k],
            rms_after: a[k],
        })
        .collect()
}
