//! The start of a run under gravity (`docs/fem.md` 9.5, Eq. G8): the deflected static
//! equilibrium of a pose, the sliders held and the pins fixed, by Newton's method with the FEM's
//! own assembly (inertia off: zero velocities and accelerations, the mass out of the matrix).

use super::step::increment_weights;
use super::*;

/// Newton iterations allowed for the static equilibrium. The matrix leaves out the constraint
/// Hessians `lambda . Phi_qq` (the sleeves' reactions turning with the beams) and the weights'
/// dependence on q, so the iteration converges linearly where these matter. Measured on the
/// paper's robot: 11 iterations at the centre pose, 13 off-centre, 26 at the centre with a
/// 0.5 kg payload, 52 with it at `catalogue::GENERAL_TARGET` (a factor 0.6 per iteration); 2-3
/// on the stiff star (E x 1e4).
const MAX_STATIC_ITER: usize = 200;

/// The factors of the static equations (Eq. G8): imbalance `f_int - M t_g + Phi_q^T lambda`
/// (unscaled: the multipliers are the forces), matrix `[K Phi_q^T; Phi_q 0]` with Eq. S9's
/// compliance (as in the time steps, so that the first step starts in equilibrium).
const STATIC: Factors = Factors {
    cf: 1.0,
    ck: 1.0,
    cv: 0.0,
    cm: 0.0,
};

/// The static equilibrium under `attached`'s weights and its load at time `t` [s] of the star
/// of `robot` meshed with `ne` elements per beam around the rigid pose `init` (its rates ignored), the
/// sliders held at `s` [m] (Eq. G8). Returns that star (inverse layout: no slider unknowns) and
/// its coordinates (nodes, sleeve rotations, contact coordinates); a Newton iteration that does
/// not converge is [`FemError::StaticEquilibrium`] with the time and the slider positions.
pub(crate) fn static_equilibrium(
    robot: &Robot,
    ne: usize,
    init: &InitialState,
    attached: &Attached,
    s: [f64; 3],
    t: f64,
) -> Result<(Star, Vec<f64>), FemError> {
    let at_rest = InitialState {
        g_dot: [0.0; 2],
        theta_dot: 0.0,
        xp_dot: [0.0; 3],
        ..*init
    };
    let (mut star, mut q, zeros) = Star::new(robot, ne, &at_rest, None)?;
    star.attached = attached.clone();
    let pins = Pins::new(robot, s.map(|si| [si, 0.0, 0.0]));
    let l = star.length_scale();
    let load = star.attached.load_at(t);
    let weight = increment_weights(&star);
    let mut lam = vec![0.0; 3 * ROWS];
    let mut dx = vec![0.0; star.n_sys];
    let failed = |reason| FemError::StaticEquilibrium { t, s, reason };
    let mut last = (f64::INFINITY, f64::INFINITY);
    for _ in 0..MAX_STATIC_ITER {
        let it = Iterate {
            q: &q,
            v: &zeros,
            qdd: &zeros,
            lam: &lam,
            pins: &pins,
            sliders: None,
            load,
        };
        star.assemble(it, STATIC, &mut dx, t, true)?;
        star.factor(t)?;
        dx.iter_mut().for_each(|r| *r = -*r);
        star.solve(&mut dx);
        let (dq, dl, l_max) = apply_increment(&mut q, &mut lam, &dx, &weight);
        if !(dq.is_finite() && dl.is_finite()) {
            return Err(failed(NewtonFailure::NonFiniteIncrement));
        }
        // the same tolerances as a time step's Newton iteration (a stall of the multipliers at
        // round-off accepted once the positions are converged)
        let stalled = dl >= 0.5 * last.1 && dl <= 1e-4 * (1.0 + l_max);
        last = (dq, dl);
        if dq <= 1e-11 * l && (dl <= 1e-6 * (1.0 + l_max) || stalled) {
            star.check_on_beams(&q, t)?;
            return Ok((star, q));
        }
    }
    Err(failed(NewtonFailure::NoConvergence {
        iterations: MAX_STATIC_ITER,
        dq: last.0,
        dl: last.1,
    }))
}

/// `q += dx`, `lambda += dlambda` from the Newton increment `dx` (coordinates, then
/// multipliers); the largest coordinate increment weighted by `weight` [m], the largest
/// multiplier increment and multiplier [N].
fn apply_increment(q: &mut [f64], lam: &mut [f64], dx: &[f64], weight: &[f64]) -> (f64, f64, f64) {
    let n = q.len();
    let mut dq = 0.0f64;
    for ((x, d), w) in q.iter_mut().zip(&dx[..n]).zip(weight) {
        *x += d;
        dq = dq.max((d * w).abs());
    }
    let (mut dl, mut l_max) = (0.0f64, 0.0f64);
    for (l, d) in lam.iter_mut().zip(&dx[n..]) {
        *l += d;
        dl = dl.max(d.abs());
        l_max = l_max.max(l.abs());
    }
    (dq, dl, l_max)
}
