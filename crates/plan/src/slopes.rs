//! The search's Jacobian on its slope model (`docs/motions.md` 4.9, "The Jacobian from the
//! tangent"): from the tangent-linear AMM where it covers the evaluator
//! ([`Evaluator::tangent_covers`]), the directions split over the threads, each group one run
//! with the derivatives along its directions; else by forward differences of whole runs
//! ([`crate::lm::jacobian`]), as before.

use rayon::prelude::*;

use crate::family::Family;
use crate::lm::{assemble, difference_step, jacobian, Jacobian, Point};
use crate::objective::{Eval, Evaluator, Rejected};
use crate::planner::{evaluate, knot_times};

/// The Jacobian of a family's evaluations at a fixed duration, on one evaluator.
pub struct Slopes {
    ev: Evaluator,
    family: Family,
    /// The move's duration [s].
    t_move: f64,
    /// Whether the tangent covers `ev` (decided once).
    tangent: bool,
}

impl Slopes {
    /// The slopes of `family`'s motions of duration `t_move` [s] evaluated by `ev`.
    pub fn new(ev: Evaluator, family: &Family, t_move: f64) -> Self {
        let tangent = ev.tangent_covers();
        Slopes {
            ev,
            family: family.clone(),
            t_move,
            tangent,
        }
    }

    /// The slopes of a search whose iterates `ev` evaluates: on its coarse model
    /// ([`Evaluator::for_slopes`]) or on `ev` itself; `None` where they would be `ev`'s own
    /// forward differences (the search then reuses its iterate's evaluation as their base).
    pub fn for_search(ev: &Evaluator, family: &Family, t_move: f64) -> Option<Self> {
        let coarse = ev.for_slopes();
        let own = coarse.is_some();
        let slopes = Slopes::new(coarse.unwrap_or_else(|| ev.clone()), family, t_move);
        (own || slopes.tangent).then_some(slopes)
    }

    /// Whether the Jacobians come from the tangent-linear AMM.
    pub fn tangent_covers(&self) -> bool {
        self.tangent
    }

    /// The Jacobian at `x` and the AMM runs it took. By the tangent, column j is that of the
    /// forward difference at the same step `h_j` ([`difference_step`]) with the AMM's outputs
    /// taken to first order in `h_j` (the derivative itself for the rows of G and the tips and
    /// the force's usage, the difference of the moved trajectory's own samples for the
    /// kinematic rows).
    /// Where a moved motion cannot run (it leaves the workspace, or its run fails), the
    /// Jacobian is taken by forward differences on the same model, which step backwards where
    /// the forward point is rejected.
    pub fn jacobian(&self, x: &[f64]) -> Result<(Jacobian, usize), Rejected> {
        let tangent = (self.tangent && !x.is_empty()).then(|| self.by_tangent(x));
        match tangent {
            Some(Ok(done)) => Ok(done),
            _ => {
                let f = |y: &[f64]| evaluate(&self.ev, &self.family, y, self.t_move);
                jacobian(&f, x, None)
            }
        }
    }

    /// [`Slopes::jacobian`] by the tangent.
    fn by_tangent(&self, x: &[f64]) -> Result<(Jacobian, usize), Rejected> {
        let (family, t_move) = (&self.family, self.t_move);
        let traj = family.trajectory(x, t_move);
        let knots = knot_times(family, t_move);
        let t_rest = family.t0 + t_move;
        let moved: Vec<_> = (0..x.len())
            .map(|j| {
                let h = difference_step(x[j]);
                let mut xp = x.to_vec();
                xp[j] += h;
                (family.trajectory(&xp, t_move), h)
            })
            .collect();
        // one group per thread: each group's run carries its directions
        let groups = rayon::current_num_threads().clamp(1, moved.len());
        let parts: Vec<(Eval, Vec<Eval>)> = moved
            .par_chunks(moved.len().div_ceil(groups))
            .map(|chunk| self.ev.eval_with_tangents(&traj, chunk, t_rest, &knots))
            .collect::<Result<_, _>>()?;
        let runs = parts.len();
        let e0 = parts[0].0.clone();
        let evals = parts.into_iter().flat_map(|(_, evals)| evals);
        let points: Vec<Point> = evals.zip(&moved).map(|(e, (_, h))| (e, 1.0, *h)).collect();
        Ok((assemble(&e0, &points), runs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::section::{Limits, Shape};
    use flexstar_model::catalogue::paper_case;
    use flexstar_model::Pose;

    /// A plan's evaluations of the move from the centre towards the edge in 0.3 s through two
    /// interior poses (6 path variables), a window of 0.1 s, the accurate model at N = 16, with
    /// limits on every kinematic quantity and the force so that every kind of row is there.
    fn setting() -> (Evaluator, Family, f64) {
        let mut exp = paper_case(3);
        exp.time.dt_out = 1e-3;
        let family = Family {
            shape: Shape::Path,
            from: Pose {
                gx: 0.0,
                gy: 0.0,
                theta: 0.0,
            },
            to: Pose {
                gx: 0.1,
                gy: -0.05,
                theta: 0.05,
            },
            t0: 0.0,
            m: 2,
        };
        let limits = Limits {
            v_max: Some(1.0),
            a_max: Some(10.0),
            j_max: Some(500.0),
            fa_max: Some(10.0),
        };
        let ev = Evaluator::new(&exp, 16, 0.1).with_limits(limits);
        (ev, family, 0.3)
    }

    /// The tangent's Jacobian (`docs/motions.md` 4.9, "The Jacobian from the tangent") against
    /// central differences of whole evaluations at `+-1e-4` (the same figures at `+-1e-5` to
    /// four digits: their truncation and round-off are below those asserted), per block of
    /// rows, as the largest difference over the block's largest entry: G's rows (the derivative
    /// of the discrete run) within 1e-5 (measured 9.1e-7), the kinematic usage (forward
    /// differences of the exact kinematics at the search's step 1e-6) within 1e-5 (1.7e-8), and
    /// the force's usage within 1e-4 (4.5e-5: the multipliers' tangent carries the round-off of
    /// the probe's constraint rows over its step, `docs/amm.md` 2.2).
    #[test]
    fn the_tangent_jacobian_matches_central_differences() {
        let (ev, family, t_move) = setting();
        let slopes = Slopes::new(ev.clone(), &family, t_move);
        assert!(slopes.tangent_covers(), "the tangent covers the bare robot");
        let x: Vec<f64> = (0..family.dim()).map(|j| 0.02 * (j as f64 - 2.5)).collect();
        let (jac, runs) = slopes.jacobian(&x).unwrap();
        assert!(runs <= rayon::current_num_threads().max(1), "{runs} runs");
        let delta = 1e-4;
        let at = |j: usize, d: f64| {
            let mut y = x.clone();
            y[j] += d;
            evaluate(&ev, &family, &y, t_move).unwrap()
        };
        // the force's usage: the last rows, one per output time and slider
        let n_force = 3 * (((t_move + ev.window) / ev.experiment().time.dt_out).round() as usize + 1);
        let n_kin = jac.usage.nrows() - n_force;
        let block_of = |r_row: Option<usize>| match r_row {
            None => 0,
            Some(i) if i < n_kin => 1,
            Some(_) => 2,
        };
        let (mut worst, mut scale) = ([0.0f64; 3], [0.0f64; 3]);
        for j in 0..x.len() {
            let (p, m) = (at(j, delta), at(j, -delta));
            let diff = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .map(|(a, b)| (a - b) / (2.0 * delta))
                    .collect::<Vec<_>>()
            };
            let (g, u) = (diff(&p.r, &m.r), diff(&p.usage, &m.usage));
            let rows = g.iter().enumerate().map(|(i, c)| (None, jac.r[(i, j)], *c));
            let rows = rows.chain(u.iter().enumerate().map(|(i, c)| (Some(i), jac.usage[(i, j)], *c)));
            for (row, t, c) in rows {
                let b = block_of(row);
                worst[b] = worst[b].max((t - c).abs());
                scale[b] = scale[b].max(c.abs());
            }
        }
        for (b, (name, tol)) in [("G", 1e-5), ("kinematic usage", 1e-5), ("force usage", 1e-4)]
            .iter()
            .enumerate()
        {
            let e = worst[b] / scale[b];
            println!(
                "{name}: largest difference {e:.2e} of the largest entry {:.3e}",
                scale[b]
            );
            assert!(scale[b] > 0.0 && e < *tol, "{name}: {e:.2e}");
        }
    }
}
