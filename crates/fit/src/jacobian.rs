//! The Jacobian of the residual vector (`docs/measured.md` 4.5): from the model's forward
//! sensitivities where it has them (Eq. LS9b: the tangent-linear model), else by forward
//! differences (Eq. LS9: one model evaluation per parameter), the evaluations in parallel.

use nalgebra::DMatrix;
use rayon::prelude::*;

use flexstar_model::SensorTable;

use crate::problem::{Param, Problem};
use crate::Model;

/// The relative step of Eq. LS9: `h_j = FD_STEP max(|theta_j|, FD_FLOOR (hi_j - lo_j))`.
pub const FD_STEP: f64 = 1e-4;
/// The share of the box below which a parameter's own value no longer sets the step (a value
/// at or near zero).
pub const FD_FLOOR: f64 = 1e-3;
/// The relative step of the tangent's directions (Eq. LS9b): their second-order terms grow
/// with it, the round-off of their residuals' difference falls with it, the more so the less
/// the parameter moves the readings (a damping ratio); 1e-4 balances the two on the bench's
/// parameters (`docs/measured.md` 4.5).
pub const TANGENT_STEP: f64 = 1e-4;

/// A Jacobian and how it was taken.
#[derive(Debug, Clone)]
pub struct Columns {
    /// `dr/du` (rows: residuals, columns: scaled parameters).
    pub j: DMatrix<f64>,
    /// The model runs it took.
    pub runs: usize,
    /// Whether it came from the model's sensitivities (else forward differences).
    pub by_tangent: bool,
}

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

/// The Jacobian `dr/du` at `u`, where the residual vector is `r`: from the model's sensitivities
/// ([`Model::slopes`]) where it has them and they can be taken here, else by forward
/// differences. An error names the parameter whose step could not be evaluated, and why.
pub fn jacobian<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    u: &[f64],
    r: &[f64],
) -> Result<Columns, (usize, String)> {
    if let Some(Ok((done, _))) = by_tangent(problem, model, u) {
        return Ok(done);
    }
    let j = differences(problem, model, u, r)?;
    Ok(Columns {
        j,
        runs: u.len(),
        by_tangent: false,
    })
}

/// An evaluation of the model with its Jacobian ([`evaluate_with_columns`]).
#[derive(Debug, Clone)]
pub struct WithColumns {
    /// The residual vector (Eq. LS1).
    pub r: Vec<f64>,
    pub readings: SensorTable,
    pub columns: Columns,
}

/// The model at `u` and its Jacobian in one go, from its sensitivities (the run that gives the
/// readings carries the directions): the residual vector, the readings and the Jacobian. `None`
/// where the model has none, or they cannot be taken here (the caller then evaluates the model
/// alone). An evaluation that fails is an error, with the model's reason.
pub fn evaluate_with_columns<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    u: &[f64],
) -> Option<Result<WithColumns, String>> {
    let (columns, readings) = match by_tangent(problem, model, u)? {
        Ok(done) => done,
        Err(_) => return None,
    };
    Some(
        problem
            .residuals(&readings)
            .map(|r| WithColumns { r, readings, columns }),
    )
}

/// Eq. LS9b: column j is `dr/dtheta_j (hi_j - lo_j)`, `dr/dtheta_j` from the model's
/// derivative along `h_j = TANGENT_STEP max(|theta_j|, FD_FLOOR (hi_j - lo_j))`. `None` where
/// the model has no sensitivities; an error where they cannot be taken here (the caller then
/// takes differences).
fn by_tangent<M: Model + ?Sized>(
    problem: &Problem,
    model: &M,
    u: &[f64],
) -> Option<Result<(Columns, SensorTable), String>> {
    let theta = problem.physical(u);
    let steps: Vec<f64> = (problem.params.iter().zip(&theta))
        .map(|(p, t)| TANGENT_STEP * t.abs().max(FD_FLOOR * p.width()))
        .collect();
    let slopes = model.slopes(&theta, &steps)?;
    Some(slopes.and_then(|s| {
        if s.derivatives.len() != steps.len() {
            return Err(format!(
                "the model gave {} derivatives for {} directions",
                s.derivatives.len(),
                steps.len()
            ));
        }
        let rows = (s.derivatives.iter())
            .map(|d| problem.residual_slopes(d))
            .collect::<Result<Vec<_>, _>>()?;
        let j = DMatrix::from_fn(problem.rows(), u.len(), |i, k| rows[k][i] * problem.params[k].width());
        let columns = Columns {
            j,
            runs: s.runs,
            by_tangent: true,
        };
        Ok((columns, s.readings))
    }))
}

/// Eq. LS9: the Jacobian by forward differences, the columns' evaluations in parallel.
fn differences<M: Model + ?Sized>(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Slopes;

    /// `y(t) = a sin(b t)` on one channel, with its exact derivatives as the model's slopes
    /// (or an error, or none).
    struct Sine {
        slopes: Option<bool>,
    }

    const T: [f64; 5] = [0.0, 0.1, 0.2, 0.3, 0.4];

    fn table(y: impl Fn(f64) -> f64) -> SensorTable {
        let mut s = SensorTable::new(T.to_vec());
        s.push_column("y".into(), "m", T.iter().map(|&t| y(t)).collect());
        s
    }

    impl Model for Sine {
        fn evaluate(&self, th: &[f64]) -> Result<SensorTable, String> {
            Ok(table(|t| th[0] * (th[1] * t).sin()))
        }

        fn slopes(&self, th: &[f64], steps: &[f64]) -> Option<Result<Slopes, String>> {
            let ok = self.slopes?;
            assert_eq!(steps.len(), 2);
            Some(if ok {
                Ok(Slopes {
                    readings: self.evaluate(th).unwrap(),
                    derivatives: vec![table(|t| (th[1] * t).sin()), table(|t| th[0] * t * (th[1] * t).cos())],
                    runs: 1,
                })
            } else {
                Err("not here".into())
            })
        }
    }

    fn problem() -> Problem {
        let p = |key: &str, lo: f64, hi: f64| Param {
            key: key.into(),
            lo,
            hi,
            start: 0.5 * (lo + hi),
        };
        let rec = table(|t| 2.0 * (3.0 * t).sin());
        Problem::with_sigmas(vec![p("a", 1.0, 3.0), p("b", 2.0, 6.0)], &rec, &[2.0], &[0.5]).unwrap()
    }

    /// The search with the model's sensitivities (each trial after an accepted step carrying
    /// the Jacobian's directions) lands where the search by differences does, every Jacobian
    /// from the sensitivities, in fewer model runs; the recording `2 sin(3 t)` is fitted
    /// exactly.
    #[test]
    fn a_search_on_the_models_slopes_finds_the_same_minimum() {
        let p = problem();
        let settings = crate::Settings::default();
        let by_slopes = crate::fit(&p, &Sine { slopes: Some(true) }, &settings, &|_| {}).unwrap();
        let by_differences = crate::fit(&p, &Sine { slopes: None }, &settings, &|_| {}).unwrap();
        assert!(by_slopes.converged() && by_differences.converged());
        assert_eq!(by_slopes.tangent_jacobians, by_slopes.jacobians);
        assert_eq!(by_differences.tangent_jacobians, 0);
        for (a, b) in by_slopes.theta().iter().zip(by_differences.theta()) {
            assert!((a - b).abs() < 1e-6 * b.abs(), "{a} vs {b}");
        }
        assert!((by_slopes.theta()[0] - 2.0).abs() < 1e-6 && (by_slopes.theta()[1] - 3.0).abs() < 1e-6);
        assert!(by_slopes.evaluations < by_differences.evaluations);
    }

    /// Eq. LS9b: the columns are the model's derivatives weighted (`w / sigma` = 4) and scaled
    /// to the boxes (widths 2 and 4), exactly; a model that cannot give them here, or has none,
    /// gets forward differences (Eq. LS9), which agree to their step's truncation.
    #[test]
    fn columns_come_from_the_models_slopes_else_from_differences() {
        let p = problem();
        let u = [0.5, 0.25];
        let th = p.physical(&u);
        let r = p.residuals(&Sine { slopes: None }.evaluate(&th).unwrap()).unwrap();
        let exact = jacobian(&p, &Sine { slopes: Some(true) }, &u, &r).unwrap();
        assert!(exact.by_tangent && exact.runs == 1);
        for (i, &t) in T.iter().enumerate() {
            assert_eq!(exact.j[(i, 0)], 4.0 * (th[1] * t).sin() * 2.0);
            assert_eq!(exact.j[(i, 1)], 4.0 * th[0] * t * (th[1] * t).cos() * 4.0);
        }
        for model in [Sine { slopes: Some(false) }, Sine { slopes: None }] {
            let fd = jacobian(&p, &model, &u, &r).unwrap();
            assert!(!fd.by_tangent && fd.runs == 2);
            let worst = (fd.j.clone() - &exact.j).abs().max() / exact.j.abs().max();
            assert!(worst < 1e-3, "{worst}");
        }
    }
}
