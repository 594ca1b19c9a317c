//! The start of a run under gravity: the deflected static equilibrium of the start pose
//! (`docs/as-built.md` 5, Eq. G4), solved with the step's own factorisation.
//!
//! At rest at the rigid state `st` (theta' = theta'' = 0, `a_G` = 0 for a motion that starts at
//! rest) the equilibrium is `K q = f + C^T lambda`, `C q = 0` (with the constraints' compliances),
//! f the weights of Eq. G1. The generalized-alpha step with `qhat = q_k`, `vhat = 0` and `gp = 0`
//! solves `(M + bp K) qdd = f - K q_k + C^T lambda`, `C (q_k + bp qdd) = 0`, so
//! `q_(k+1) = q_k + bp qdd` is iterative refinement of the static system regularised by `M / bp`
//! (which keeps S invertible where a mode set has modes of no stiffness, fixed by the constraints
//! alone). The regularisation alone would contract the error by `1 / (1 + bp omega_1^2)` per
//! pass; the sleeves' rows of the accurate model depend on q (the material point in the sleeve
//! moves with the axial displacement, `crate::sleeve`), which each pass updates at the last q, so
//! the passes are a fixed-point iteration on that dependence: about a factor 0.1 per pass on the
//! paper's robot, down to a round-off floor that a larger bp raises (the step matrix holds
//! `bp lambda_N`), hence the moderate `bp`.

use flexstar_kinematics::RigidState;
use flexstar_model::RestOffset;

use crate::error::AmmError;
use crate::modes::dot;
use crate::star::Star;
use crate::system::System;

/// Most refinement passes: about 0.1 per pass on the paper's robot (module doc).
const PASSES: usize = 40;

/// Relative change of q [-] below which the equilibrium is converged: above the round-off floor
/// of the passes (about 5e-8 on the paper's robot), far below what a run resolves (a sag of 6 mm
/// to 6 nm).
const TOLERANCE: f64 = 1e-6;

/// The coordinates `q` of the static equilibrium at the rigid state `st` (at rest), into `q`;
/// `time_scale` [s] is a bending time of the beams (`crate::solver::beam_time_scale`), which sets
/// the regularisation `bp = 1e3 time_scale^2` (29 s^2 on the paper's robot). Errors when the passes do not converge.
pub(crate) fn static_equilibrium(
    sys: &mut System,
    st: &RigidState,
    time_scale: f64,
    q: &mut [f64],
) -> Result<(), AmmError> {
    let n = q.len();
    let bp = 1e3 * time_scale * time_scale;
    let (zero, mut dq) = (vec![0.0; n], vec![0.0; n]);
    q.iter_mut().for_each(|x| *x = 0.0);
    let mut change = f64::INFINITY;
    for _ in 0..PASSES {
        sys.solve(st, bp, 0.0, q, &zero, &mut dq)?;
        let (mut size, mut step) = (0.0f64, 0.0f64);
        for (x, d) in q.iter_mut().zip(&dq) {
            *x += bp * d;
            size = size.max(x.abs());
            step = step.max((bp * d).abs());
        }
        if !size.is_finite() {
            return Err(AmmError::NonFinite { t: st.t, dt: 0.0 });
        }
        change = step / size.max(f64::MIN_POSITIVE);
        if change < TOLERANCE {
            return Ok(());
        }
    }
    Err(AmmError::StaticStart { t: st.t, change })
}

/// Under gravity, the static equilibrium's `w_iG` and tips at the pose where the problem's
/// motion comes to rest (`docs/as-built.md` 5.5: the residual vibration is measured about it);
/// `None` without gravity or without a rest within the run. `sys` is left at that equilibrium.
pub(crate) fn rest_offset(sys: &mut System, problem: &Star, time_scale: f64) -> Result<Option<RestOffset>, AmmError> {
    let Some(t_rest) = problem.trajectory.t_rest().filter(|t| *t <= problem.time.t_end) else {
        return Ok(None);
    };
    if problem.gravity == [0.0; 2] {
        return Ok(None);
    }
    let st = problem.state(t_rest)?;
    let mut q = vec![0.0; sys.dim()];
    static_equilibrium(sys, &st, time_scale, &mut q)?;
    let (nm, nb) = (sys.nm, sys.nb);
    let along =
        |v: fn(&crate::system::BeamModel) -> &[f64]| [0, 1, 2].map(|i| dot(v(sys.beam(i)), &q[i * nb..i * nb + nm]));
    Ok(Some(RestOffset {
        t_rest,
        w_g: along(|b| &b.phi0),
        w_tip: along(|b| &b.phil),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{beam_time_scale, build_system};
    use flexstar_model::{AmmModel, AmmSettings, Experiment, ModeFamily};

    /// `docs/as-built.md` 5.4: the overhang of each beam beyond its sleeve is a cantilever clamped
    /// at the sleeve's outer edge under its weight's normal component `q = rho g . e_w`; in linear
    /// theory (the paper's model: no geometric stiffness of the axial weight) its tip leaves the
    /// beam's tangent at that edge by the textbook `q a^4 / (8 EI)`, `a = L - xp - Lp / 2`,
    /// whatever the rest of the star does. Gravity along -Y at an off-centre pose loads beams 2
    /// and 3 and leaves beam 1 (along -Y) unloaded. The modal series converges to it with N.
    #[test]
    fn the_overhangs_sag_as_cantilevers() {
        let text = "name = \"sag\"\n[time]\nt_end = 0.1\n[trajectory]\nkind = \"polynomial\"\n\
                    s1 = [0.02]\ns2 = [-0.03]\ns3 = [0.01]\n[gravity]\ng = [0.0, -9.81]\n";
        let exp = Experiment::from_toml_str(text, std::path::Path::new("sag.toml")).unwrap();
        let problem = exp.problem().unwrap();
        let eq = Star::new(&problem);
        let p = eq.beam(0);
        let st = eq.state(0.0).unwrap();
        // the largest departure from the textbook over the three beams, relative to the largest sag
        let error = |family: ModeFamily, nm: usize| {
            let settings = AmmSettings {
                family,
                model: AmmModel::Paper,
                ..AmmSettings::accurate()
            };
            let mut sys = build_system(&settings, nm, &eq).unwrap();
            let mut q = vec![0.0; sys.dim()];
            static_equilibrium(&mut sys, &st, beam_time_scale(p), &mut q).unwrap();
            let (mut worst, mut largest) = (0.0f64, 0.0f64);
            for i in 0..3 {
                let w = |x: f64, d: usize| {
                    (0..nm)
                        .map(|j| sys.beam(i).modes.eval(j, x)[d] * q[i * (nm + 2) + j])
                        .sum::<f64>()
                };
                let xr = st.xp[i].v + p.lp / 2.0;
                let sag = w(p.l, 0) - (w(xr, 0) + w(xr, 1) * (p.l - xr));
                let e_w = st.e_w(i);
                let load = p.rho * (exp.gravity.g[0] * e_w[0] + exp.gravity.g[1] * e_w[1]);
                let textbook = load * (p.l - xr).powi(4) / (8.0 * p.ei());
                eprintln!(
                    "{family:?} N = {nm}, beam {}: tip off the edge's tangent {sag:.6e} m, cantilever {textbook:.6e} m",
                    i + 1
                );
                worst = worst.max((sag - textbook).abs());
                largest = largest.max(textbook.abs());
            }
            worst / largest
        };
        for family in [ModeFamily::Enriched, ModeFamily::FreeFree] {
            let (coarse, fine) = (error(family, 40), error(family, 80));
            assert!(
                fine < 1e-3 && fine < coarse,
                "{family:?}: {coarse:.2e} at N = 40, {fine:.2e} at N = 80"
            );
        }
    }
}
