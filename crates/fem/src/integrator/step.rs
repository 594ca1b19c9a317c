//! One generalized-alpha step: prediction, Newton iterations with a reused factorisation,
//! update.

use super::*;

/// Newton iterations allowed per step.
const MAX_ITER: usize = 30;
/// Guard of the reused factorisation: the matrix is assembled and factorised at the first
/// iteration of every step and reused by the following ones (imbalance only) while each Newton
/// increment, measured against the convergence tolerances, is at most this fraction of the
/// previous one; otherwise the next iteration assembles and factorises afresh. (Reusing it across
/// steps too was measured to double the iterations, 4.2 per step, for a smaller gain.)
const RATE_REFACTOR: f64 = 0.1;

/// Work vectors of the Newton iteration, allocated once.
pub(super) struct Workspace {
    /// Weight of each coordinate's increment in the convergence test: the element length for
    /// rotations (node rotations and sleeve rotations), 1 for lengths.
    pub(super) weight: Vec<f64>,
    pub(super) a_part: Vec<f64>,
    pub(super) qh: Vec<f64>,
    pub(super) vh: Vec<f64>,
    /// The Newton iterate: coordinates, velocities, accelerations, scaled multipliers.
    pub(super) q1: Vec<f64>,
    pub(super) v1: Vec<f64>,
    pub(super) qdd1: Vec<f64>,
    pub(super) nu: Vec<f64>,
    pub(super) dx: Vec<f64>,
    pub(super) res: Vec<f64>,
}

impl Workspace {
    /// The work vectors of `star`'s system, zeroed; the weights: the element length h [m] for
    /// rotations (node rotations and the three sleeve rotations), 1 for lengths.
    pub(super) fn new(star: &Star) -> Self {
        let (n_dof, n_sys) = (star.n_dof, star.n_sys);
        Workspace {
            weight: increment_weights(star),
            a_part: vec![0.0; n_dof],
            qh: vec![0.0; n_dof],
            vh: vec![0.0; n_dof],
            q1: vec![0.0; n_dof],
            v1: vec![0.0; n_dof],
            qdd1: vec![0.0; n_dof],
            nu: vec![0.0; 3 * ROWS],
            dx: vec![0.0; n_sys],
            res: vec![0.0; n_sys],
        }
    }
}

/// Weight of each coordinate's increment in Newton's convergence tests: the element length
/// `h_i` [m] of its beam for rotations (node rotations of beam i, sleeve i's rotation; G's, the
/// longest element's), 1 for lengths.
pub(super) fn increment_weights(star: &Star) -> Vec<f64> {
    let n = 3 * star.n_nodes;
    let h_g = star.h[0].max(star.h[1]).max(star.h[2]);
    let weight = |j: usize| {
        if j == 2 {
            h_g
        } else if j < n && j % 3 == 2 {
            star.h[(j / 3 - 1) / star.ne]
        } else if (n..n + 3).contains(&j) {
            star.h[j - n]
        } else {
            1.0
        }
    };
    (0..star.n_dof).map(weight).collect()
}

/// Generalized-alpha predictor of every coordinate ([`GenAlpha::predict`]) and the first Newton
/// iterate: constant acceleration, `q = q_hat + beta' q_dd`, `v = v_hat + gamma' q_dd`.
#[inline(always)]
fn predict(ga: &GenAlpha, h: f64, bp: f64, gp: f64, st: &State, ws: &mut Workspace) {
    let n = st.q.len();
    let (q, v, a, qdd) = (&st.q[..n], &st.v[..n], &st.a[..n], &st.qdd[..n]);
    let (ap, qh, vh) = (&mut ws.a_part[..n], &mut ws.qh[..n], &mut ws.vh[..n]);
    let (q1, v1, qdd1) = (&mut ws.q1[..n], &mut ws.v1[..n], &mut ws.qdd1[..n]);
    for j in 0..n {
        (ap[j], qh[j], vh[j]) = ga.predict(h, q[j], v[j], a[j], qdd[j]);
        qdd1[j] = qdd[j];
        q1[j] = qh[j] + bp * qdd[j];
        v1[j] = vh[j] + gp * qdd[j];
    }
}

/// Newton update of the coordinates with the increment `dx` (first `n` entries):
/// `q += dx`, `q_dd += dx / beta'`, `v += gamma' / beta' dx`; returns the largest increment
/// weighted by `weight` (the maximum in four interleaved partial maxima, the same number).
#[inline(always)]
fn update_coordinates(ws: &mut Workspace, inv_bp: f64, gp: f64) -> f64 {
    let n = ws.q1.len();
    let (q1, v1, qdd1) = (&mut ws.q1[..n], &mut ws.v1[..n], &mut ws.qdd1[..n]);
    let dx = &ws.dx[..n];
    for j in 0..n {
        let d = dx[j];
        q1[j] += d;
        qdd1[j] += d * inv_bp;
        v1[j] += gp * inv_bp * d;
    }
    let mut m = [0.0f64; 4];
    let (chunks, rest) = (dx.chunks_exact(4), dx.len() / 4 * 4);
    for (c, w) in chunks.zip(ws.weight.chunks_exact(4)) {
        for k in 0..4 {
            m[k] = m[k].max((c[k] * w[k]).abs());
        }
    }
    let mut dq_max = m[0].max(m[1]).max(m[2].max(m[3]));
    for j in rest..n {
        dq_max = dq_max.max((dx[j] * ws.weight[j]).abs());
    }
    dq_max
}

flexstar_numerics::dispatch_avx2! {
    /// One generalized-alpha step from `st` (at `t1 - h`) to `t1`; `st` holds the new state on
    /// return. Compiled for AVX2 and for the baseline, chosen at run time (the vector loops of the
    /// predictor and the Newton updates; the solver's parts dispatch on their own).
    pub(super) fn step(
        motion: &Motion,
        star: &mut Star,
        ga: &GenAlpha,
        st: &mut State,
        ws: &mut Workspace,
        stats: &mut Stats,
        t1: f64,
        h: f64,
    ) -> Result<(), FemError> {
        let (n_dof, l) = (star.n_dof, star.length_scale());
        let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
        let fixed = motion.prescribed_pins(star, t1)?;
        let load = star.attached.load_at(t1);
        // predictor: constant acceleration, previous multipliers
        predict(ga, h, bp, gp, st, ws);
        if star.friction.is_some() {
            super::friction::freeze(star, &mut ws.q1, &mut ws.v1, &mut ws.qdd1);
        }
        for k in 0..ws.nu.len() {
            ws.nu[k] = bp * st.lam[k];
        }
        let inv_bp = 1.0 / bp;
        let mut converged = false;
        let mut last = (0.0, 0.0);
        let mut last_err = f64::INFINITY;
        // a fresh matrix at the first iteration of every step (see RATE_REFACTOR)
        let mut stale = true;
        for it in 0..MAX_ITER {
            // the pins: prescribed, or following the iterate's sliders (direct problem)
            let (pins, sliders) = match fixed {
                Some(p) => (p, None),
                None => {
                    let p = star.pins_of(&ws.q1, &ws.v1, &ws.qdd1);
                    (p, motion.slider_rows(star, &p, t1, bp, gp)?)
                }
            };
            let fresh = newton_increment(star, ws, (&pins, sliders.as_ref(), load), (bp, gp), t1, stale, stats)?;
            if fresh {
                stale = false;
            }
            let dq_max = update_coordinates(ws, inv_bp, gp);
            if star.friction.is_some() {
                super::friction::freeze(star, &mut ws.q1, &mut ws.v1, &mut ws.qdd1);
            }
            let (dl_max, l_max) = update_multipliers(ws, n_dof, bp);
            if !(dq_max.is_finite() && dl_max.is_finite()) {
                return Err(FemError::Newton {
                    t: t1,
                    h,
                    reason: NewtonFailure::NonFiniteIncrement,
                });
            }
            // converged: positions to 1e-11 L, multipliers to 1e-6 (1 + |lambda|) N, or, once
            // the positions are converged, multipliers that stopped decreasing at a small
            // level (round-off floor of very stiff runs)
            // (a stall counts only with a fresh matrix: a reused one contracts more slowly)
            let stalled = fresh && it > 0 && dl_max >= 0.5 * last.1 && dl_max <= 1e-4 * (1.0 + l_max);
            last = (dq_max, dl_max);
            // guard of the reused factorisation: increments against the tolerances
            let err = (dq_max / (1e-11 * l)).max(dl_max / (1e-6 * (1.0 + l_max)));
            if err > RATE_REFACTOR * last_err {
                stale = true;
            }
            last_err = err;
            if dq_max <= 1e-11 * l && (dl_max <= 1e-6 * (1.0 + l_max) || stalled) {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(FemError::Newton {
                t: t1,
                h,
                reason: NewtonFailure::NoConvergence {
                    iterations: MAX_ITER,
                    dq: last.0,
                    dl: last.1,
                },
            });
        }
        accept(ga, star, st, ws, fixed, bp);
        stats.steps += 1;
        Ok(())
    }
}

/// What acts on the star at a Newton iterate besides its coordinates: the pins, the sliders'
/// rows (direct problem) and the load at G.
type Drive<'a> = (&'a Pins, Option<&'a SliderRows>, Option<[f64; 3]>);

/// Assemble the imbalance (and, when `stale`, the matrix, then factorise it) at the Newton
/// iterate and solve for the increment `dx = -A^{-1} res`; whether the matrix was fresh.
/// `(bp, gp)` = `(beta', gamma')` of the step.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn newton_increment(
    star: &mut Star,
    ws: &mut Workspace,
    (pins, sliders, load): Drive,
    (bp, gp): (f64, f64),
    t1: f64,
    stale: bool,
    stats: &mut Stats,
) -> Result<bool, FemError> {
    let n_sys = star.n_sys;
    let fresh = star.assemble(
        Iterate {
            q: &ws.q1,
            v: &ws.v1,
            qdd: &ws.qdd1,
            lam: &ws.nu,
            pins,
            sliders,
            load,
        },
        Factors {
            cf: bp,
            ck: bp,
            cv: gp,
            cm: 1.0,
        },
        &mut ws.res,
        t1,
        stale,
    )?;
    if fresh {
        star.factor(t1)?;
        stats.factorisations += 1;
    }
    stats.newton_iterations += 1;
    for (d, r) in ws.dx[..n_sys].iter_mut().zip(&ws.res[..n_sys]) {
        *d = -r;
    }
    star.solve(&mut ws.dx);
    Ok(fresh)
}

/// `nu += dnu` from the increment; the largest multiplier increment and multiplier, both
/// divided by `beta'` (hence in N).
#[inline(always)]
fn update_multipliers(ws: &mut Workspace, n_dof: usize, bp: f64) -> (f64, f64) {
    let mut dl_max = 0.0f64;
    let mut l_max = 0.0f64;
    for k in 0..ws.nu.len() {
        ws.nu[k] += ws.dx[n_dof + k];
        dl_max = dl_max.max(ws.dx[n_dof + k].abs() / bp);
        l_max = l_max.max(ws.nu[k].abs() / bp);
    }
    (dl_max, l_max)
}

/// The converged iterate becomes the state: accelerations `a = a_part + (a/q_dd) q_dd`, the
/// pins, coordinates, velocities, and the multipliers `lambda = nu / beta'`.
#[inline(always)]
fn accept(ga: &GenAlpha, star: &Star, st: &mut State, ws: &mut Workspace, fixed: Option<Pins>, bp: f64) {
    let n_dof = star.n_dof;
    let apq = ga.a_per_qdd();
    for ((a, ap), qdd) in st.a[..n_dof].iter_mut().zip(&ws.a_part[..n_dof]).zip(&ws.qdd1[..n_dof]) {
        *a = ap + apq * qdd;
    }
    if star.friction.is_some() {
        for (k, _) in star.stuck_coordinates() {
            st.a[k] = 0.0;
        }
    }
    st.pins = fixed.unwrap_or_else(|| star.pins_of(&ws.q1, &ws.v1, &ws.qdd1));
    std::mem::swap(&mut st.q, &mut ws.q1);
    std::mem::swap(&mut st.v, &mut ws.v1);
    std::mem::swap(&mut st.qdd, &mut ws.qdd1);
    for k in 0..ws.nu.len() {
        st.lam[k] = ws.nu[k] / bp;
    }
}
