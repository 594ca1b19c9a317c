//! Index-3 generalized-alpha time integration of the constrained star (Arnold & Bruls 2007,
//! Multibody Syst. Dyn. 18:185), with the equations of motion scaled by `beta'` and the
//! multipliers carried as `nu = beta' lambda` (Bottasso, Bauchau & Cardona 2007, SIAM J. Sci.
//! Comput. 29:397), so that the iteration matrix
//!
//! ```text
//! [ M + beta' K    Phi_q^T ] [ dq  ]     [ beta' (M q_dd + f_conv + f_int) + Phi_q^T nu ]
//! [ Phi_q          0       ] [ dnu ] = - [ Phi(q, t)                                     ]
//! ```
//!
//! has entries of comparable size whatever the step. `q_{n+1} = q_hat + beta' q_dd`,
//! `v_{n+1} = v_hat + gamma' q_dd` with the coefficients of [`flexstar_numerics::GenAlpha`]; the
//! equations hold exactly at `t_{n+1}` (positions, multipliers), so the pin forces and hence Fa
//! come out at the output times with second-order accuracy.

use flexstar_model::geometry::slider_direction;
use flexstar_model::{RobotParams, Trajectory};
use flexstar_numerics::GenAlpha;

use crate::star::{InitialState, Pins, Star, ROWS};
use crate::FemError;

/// Newton iterations allowed per step.
const MAX_ITER: usize = 30;
/// Guard of the reused factorisation: the matrix is assembled and factorised at the first
/// iteration of every step and reused by the following ones (residual only) while each Newton
/// increment, measured against the convergence tolerances, is at most this fraction of the
/// previous one; otherwise the next iteration assembles and factorises afresh. (Reusing it across
/// steps too was measured to double the iterations, 4.2 per step, for a smaller gain.)
const RATE_REFACTOR: f64 = 0.1;

/// Numerical settings of one run.
#[derive(Debug, Clone)]
pub(crate) struct RunSettings {
    /// Elements per beam.
    pub ne: usize,
    /// Largest time step [s].
    pub dt: f64,
    pub rho_inf: f64,
}

/// What the solver records at one output time (fixed frame, SI).
#[derive(Debug, Clone)]
pub(crate) struct Sample {
    pub t: f64,
    /// Position of the weld node G [m].
    pub g: [f64; 2],
    /// Rotation increment of the weld node G since t = 0 [rad].
    pub phi_g: f64,
    /// Tip positions [m].
    pub tip: [[f64; 2]; 3],
    /// Absolute sleeve angles `gamma0_i + psi_i` [rad].
    pub sleeve_angle: [f64; 3],
    /// Contact coordinates (centre) xi_ic [m].
    pub xi_c: [f64; 3],
    /// Driving forces (Eq. 33) [N].
    pub fa: [f64; 3],
    /// Force the beam exerts on sleeve i, hence on its pin [N], fixed frame.
    pub pin_force: [[f64; 2]; 3],
    /// Kinetic energy of the beams, sleeves (rotation), sliders [J]; strain energy [J].
    pub ke_star: f64,
    pub ke_sleeves: f64,
    pub ke_sliders: f64,
    pub strain: f64,
    /// Work of the three drivers since t = 0 [J] (trapezoidal rule on the integration steps).
    pub work: f64,
}

/// Deformed star at one instant: node positions of each beam from G to the tip [m].
#[derive(Debug, Clone)]
pub(crate) struct Snapshot {
    pub t: f64,
    pub beams: [Vec<[f64; 2]>; 3],
}

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Time steps taken.
    pub steps: usize,
    /// Newton iterations (residual evaluations and solves) in all.
    pub newton_iterations: usize,
    /// Sparsity patterns built (one at the start, a new one when a sleeve's contact point leaves
    /// its window of elements); the sparse LU fallback redoes its symbolic factorisation on these.
    pub symbolic_factorisations: usize,
    /// Factorisations that fell back from the structured solver (banded beam blocks and a dense
    /// border, `docs/fem.md` section 3) to the general sparse LU (0 in the paper cases).
    pub sparse_fallbacks: usize,
    /// Numeric factorisations of the Newton matrix: one at the first iteration of each step,
    /// reused by the step's later iterations while the increments contract by a factor 10 or
    /// better, refactorised otherwise (docs/fem.md section 3).
    pub factorisations: usize,
}

/// Everything a run produces.
pub(crate) struct History {
    pub samples: Vec<Sample>,
    pub snapshots: Vec<Snapshot>,
    pub node_x: Vec<f64>,
    pub stats: Stats,
}

fn pins_at(params: &RobotParams, traj: &Trajectory, t: f64) -> Result<Pins, FemError> {
    let j = traj
        .jets(params, t)
        .map_err(|source| FemError::Trajectory { t, source })?;
    Ok(Pins::new(params, j.map(|x| [x.v, x.d1, x.d2])))
}

/// Driving force (Eq. 33): `Fa_i = (mpp + mpa) s_i'' - F_i . u_i`, F_i the force of the beam on
/// sleeve i (the sleeve is translationally massless: F_i passes through the pin to the slider).
fn driving_forces(params: &RobotParams, pins: &Pins, lam: &[f64]) -> ([f64; 3], [[f64; 2]; 3]) {
    let mut fa = [0.0; 3];
    let mut f = [[0.0; 2]; 3];
    for i in 0..3 {
        let l = &lam[ROWS * i..ROWS * i + ROWS];
        f[i] = [l[0] + l[2] + l[4], l[1] + l[3] + l[5]];
        let u = slider_direction(i);
        fa[i] = params.mpp_mpa * pins.s[i][2] - (f[i][0] * u[0] + f[i][1] * u[1]);
    }
    (fa, f)
}

fn power(fa: &[f64; 3], pins: &Pins) -> f64 {
    (0..3).map(|i| fa[i] * pins.s[i][1]).sum()
}

/// Integrate from the initial state to the last output time.
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate(
    params: &RobotParams,
    traj: &Trajectory,
    t_out: &[f64],
    snap_times: &[f64],
    init: &InitialState,
    run: &RunSettings,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<History, FemError> {
    if !(run.dt.is_finite() && run.dt > 0.0) {
        return Err(FemError::Input(format!(
            "the time step must be positive, got {}",
            run.dt
        )));
    }
    if t_out.is_empty() || t_out[0] != 0.0 {
        return Err(FemError::Input("output times must start at t = 0".into()));
    }
    let (mut star, mut q, mut v) = Star::new(params, run.ne, init)?;
    let (n_dof, n_sys) = (star.n_dof, star.n_sys);
    let l = params.l;
    let limit = params.half_side();

    // --- consistency of the initial pose with the pins
    let pins0 = pins_at(params, traj, 0.0)?;
    let phi0 = star.constraints(&q, &pins0);
    let worst = phi0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if worst > 1e-9 * l {
        return Err(FemError::Input(format!(
            "the initial pose does not pass through the pins (largest constraint residual {worst:.3e})"
        )));
    }
    // --- consistent initial accelerations and multipliers: [M Phi_q^T; Phi_q 0] [qdd; lam] = ...
    let mut res = vec![0.0; n_sys];
    let zeros = vec![0.0; n_dof];
    let lam0 = vec![0.0; 3 * ROWS];
    star.assemble(&q, &v, &zeros, &lam0, &pins0, 1.0, 0.0, &mut res, 0.0, true)?;
    let mut rhs: Vec<f64> = res.iter().map(|r| -r).collect();
    let vmax = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut conv = [0.0; 3 * ROWS];
    if vmax > 0.0 {
        // d^2/dtau^2 Phi(q + tau v) at tau = 0 by central differences (convective part)
        let tau = 1e-4 * l / vmax.max(1e-3);
        let qp: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a + tau * b).collect();
        let qm: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a - tau * b).collect();
        let (fp, fm) = (star.constraints(&qp, &pins0), star.constraints(&qm, &pins0));
        for k in 0..conv.len() {
            conv[k] = (fp[k] - 2.0 * phi0[k] + fm[k]) / (tau * tau);
        }
    }
    for i in 0..3 {
        let u = slider_direction(i);
        for r in 0..6 {
            // Phi contains -P(t): its second derivative contributes -s'' u
            conv[ROWS * i + r] -= pins0.s[i][2] * u[r % 2];
        }
    }
    for k in 0..conv.len() {
        rhs[n_dof + k] = -conv[k];
    }
    star.factor(0.0)?;
    star.solve(&mut rhs);
    let mut qdd = rhs[..n_dof].to_vec();
    let mut lam = rhs[n_dof..].to_vec();
    let mut a = qdd.clone();

    // --- time grid: every output and snapshot time is a step boundary
    let t_end = *t_out.last().unwrap();
    let mut events: Vec<f64> = t_out
        .iter()
        .chain(snap_times.iter())
        .copied()
        .filter(|t| *t >= 0.0 && *t <= t_end)
        .collect();
    events.sort_by(|a, b| a.total_cmp(b));
    events.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let ga = GenAlpha::new(run.rho_inf);
    let mut samples = Vec::with_capacity(t_out.len());
    let mut snapshots = Vec::new();
    let (mut out_k, mut snap_k) = (0usize, 0usize);
    let mut snaps_sorted: Vec<f64> = snap_times.to_vec();
    snaps_sorted.sort_by(|a, b| a.total_cmp(b));
    let mut stats = Stats::default();
    let (fa0, _) = driving_forces(params, &pins0, &lam);
    let mut pow_prev = power(&fa0, &pins0);
    let mut work = 0.0;

    let record = |star: &Star,
                  q: &[f64],
                  v: &[f64],
                  lam: &[f64],
                  pins: &Pins,
                  t: f64,
                  work: f64,
                  out_k: &mut usize,
                  snap_k: &mut usize,
                  samples: &mut Vec<Sample>,
                  snapshots: &mut Vec<Snapshot>| {
        if *out_k < t_out.len() && (t_out[*out_k] - t).abs() < 1e-12 {
            let (fa, pf) = driving_forces(params, pins, lam);
            let pos = |j: usize| [q[3 * j], q[3 * j + 1]];
            samples.push(Sample {
                t: t_out[*out_k],
                g: pos(0),
                phi_g: q[2],
                tip: [0, 1, 2].map(|i| pos(star.node(i, star.ne))),
                sleeve_angle: [0, 1, 2].map(|i| star.gamma0[i] + q[star.psi(i)]),
                xi_c: [0, 1, 2].map(|i| q[star.xi(i, 0)]),
                fa,
                pin_force: pf,
                ke_star: star.kinetic_energy_beams(q, v),
                ke_sleeves: 0.5 * params.jp * (0..3).map(|i| v[star.psi(i)].powi(2)).sum::<f64>(),
                ke_sliders: 0.5 * params.mpp_mpa * (0..3).map(|i| pins.s[i][1].powi(2)).sum::<f64>(),
                strain: star.strain_energy(q),
                work,
            });
            *out_k += 1;
        }
        while *snap_k < snaps_sorted.len() && (snaps_sorted[*snap_k] - t).abs() < 1e-12 {
            let beams = [0, 1, 2].map(|i| {
                (0..=star.ne)
                    .map(|k| {
                        let j = star.node(i, k);
                        [q[3 * j], q[3 * j + 1]]
                    })
                    .collect()
            });
            snapshots.push(Snapshot {
                t: snaps_sorted[*snap_k],
                beams,
            });
            *snap_k += 1;
        }
    };
    record(
        &star,
        &q,
        &v,
        &lam,
        &pins0,
        0.0,
        0.0,
        &mut out_k,
        &mut snap_k,
        &mut samples,
        &mut snapshots,
    );

    let mut t = 0.0;
    let mut a_part = vec![0.0; n_dof];
    let mut qh = vec![0.0; n_dof];
    let mut vh = vec![0.0; n_dof];
    let mut nu = vec![0.0; 3 * ROWS];
    let mut dx = vec![0.0; n_sys];
    let rot_scale = star.h;
    // whether the next iteration must assemble and factorise the matrix
    let mut stale;
    let is_rot = |j: usize, star: &Star| {
        j < 3 * star.n_nodes && j % 3 == 2 || (j >= 3 * star.n_nodes && j < 3 * star.n_nodes + 3)
    };
    for w in events.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        let n_sub = ((tb - ta) / run.dt - 1e-9).ceil().max(1.0) as usize;
        let h = (tb - ta) / n_sub as f64;
        let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
        for sub in 1..=n_sub {
            let t1 = if sub == n_sub { tb } else { ta + h * sub as f64 };
            let pins = pins_at(params, traj, t1)?;
            for i in 0..3 {
                if pins.s[i][0].abs() >= limit {
                    return Err(FemError::SliderOffBase {
                        t: t1,
                        slider: i + 1,
                        s: pins.s[i][0],
                        limit,
                    });
                }
            }
            for j in 0..n_dof {
                a_part[j] = (ga.alpha_f * qdd[j] - ga.alpha_m * a[j]) / (1.0 - ga.alpha_m);
                qh[j] = q[j] + h * v[j] + h * h * ((0.5 - ga.beta) * a[j] + ga.beta * a_part[j]);
                vh[j] = v[j] + h * ((1.0 - ga.gamma) * a[j] + ga.gamma * a_part[j]);
            }
            // predictor: constant acceleration, previous multipliers
            let mut qdd1 = qdd.clone();
            let mut q1: Vec<f64> = (0..n_dof).map(|j| qh[j] + bp * qdd1[j]).collect();
            let mut v1: Vec<f64> = (0..n_dof).map(|j| vh[j] + gp * qdd1[j]).collect();
            for k in 0..nu.len() {
                nu[k] = bp * lam[k];
            }
            let mut converged = false;
            let mut last = (0.0, 0.0);
            let mut last_err = f64::INFINITY;
            // a fresh matrix at the first iteration of every step (see RATE_REFACTOR)
            stale = true;
            for it in 0..MAX_ITER {
                let fresh = star.assemble(&q1, &v1, &qdd1, &nu, &pins, bp, bp, &mut res, t1, stale)?;
                if fresh {
                    star.factor(t1)?;
                    stats.factorisations += 1;
                    stale = false;
                }
                stats.newton_iterations += 1;
                for k in 0..n_sys {
                    dx[k] = -res[k];
                }
                star.solve(&mut dx);
                let mut dq_max = 0.0f64;
                for j in 0..n_dof {
                    let d = dx[j];
                    q1[j] += d;
                    qdd1[j] += d / bp;
                    v1[j] += gp / bp * d;
                    let s = if is_rot(j, &star) { rot_scale } else { 1.0 };
                    dq_max = dq_max.max((d * s).abs());
                }
                let mut dl_max = 0.0f64;
                let mut l_max = 0.0f64;
                for k in 0..nu.len() {
                    nu[k] += dx[n_dof + k];
                    dl_max = dl_max.max(dx[n_dof + k].abs() / bp);
                    l_max = l_max.max(nu[k].abs() / bp);
                }
                if !(dq_max.is_finite() && dl_max.is_finite()) {
                    return Err(FemError::Newton {
                        t: t1,
                        h,
                        reason: "non-finite Newton increment".into(),
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
                    reason: format!(
                        "no convergence in {MAX_ITER} iterations (last increments: {:.3e} m, {:.3e} N)",
                        last.0, last.1
                    ),
                });
            }
            for j in 0..n_dof {
                a[j] = a_part[j] + ga.a_per_qdd() * qdd1[j];
            }
            q = q1;
            v = v1;
            qdd = qdd1;
            for k in 0..nu.len() {
                lam[k] = nu[k] / bp;
            }
            t = t1;
            stats.steps += 1;
            // the sleeves must stay on their beams
            for i in 0..3 {
                for (p, name) in [(0, "centre"), (1, "left edge"), (2, "right edge")] {
                    let xi = q[star.xi(i, p)];
                    if !(xi > 0.0 && xi < l) {
                        return Err(FemError::SleeveOffBeam {
                            t,
                            sleeve: i + 1,
                            point: name,
                            xi,
                            l,
                        });
                    }
                }
            }
            let (fa, _) = driving_forces(params, &pins, &lam);
            let pw = power(&fa, &pins);
            work += 0.5 * h * (pow_prev + pw);
            pow_prev = pw;
            record(
                &star,
                &q,
                &v,
                &lam,
                &pins,
                t,
                work,
                &mut out_k,
                &mut snap_k,
                &mut samples,
                &mut snapshots,
            );
        }
        if let Some(cb) = progress {
            cb((t / t_end).min(1.0));
        }
    }
    stats.symbolic_factorisations = star.symbolic_count;
    stats.sparse_fallbacks = star.sparse_fallbacks;
    Ok(History {
        samples,
        snapshots,
        node_x: star.node_x(),
        stats,
    })
}
