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

use flexstar_drive::ActuatorLaw;
use flexstar_kinematics::feasibility::check_configuration;
use flexstar_model::geometry::slider_direction;
use flexstar_model::{RobotParams, Trajectory};
use flexstar_numerics::GenAlpha;

use crate::error::PivotError;
use crate::star::{InitialState, Pins, SliderRows, Star, ROWS};
use crate::{FemError, NewtonFailure};

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
    /// Slider positions s_i [m] and speeds s_i' [m/s] (prescribed, or simulated).
    pub s: [f64; 3],
    pub sd: [f64; 3],
}

/// Deformed star at one instant: node positions of each beam from G to the tip [m].
#[derive(Debug, Clone)]
pub(crate) struct Snapshot {
    pub t: f64,
    /// Slider positions s_i [m].
    pub s: [f64; 3],
    pub beams: [Vec<[f64; 2]>; 3],
}

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
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
    /// Why the structured solver last failed, and when (`None` without a fallback).
    pub last_fallback: Option<Fallback>,
}

/// A fallback from the structured solver to the sparse LU: the Newton time `t` [s] and the
/// failing pivot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fallback {
    /// Time of the step whose factorisation fell back [s].
    pub t: f64,
    /// The pivot that failed.
    pub reason: PivotError,
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

/// Force `F_i = lambda_c + lambda_l + lambda_r` the beam exerts on sleeve i, hence on its pin
/// and slider [N], fixed frame.
fn pin_forces(lam: &[f64]) -> [[f64; 2]; 3] {
    [0, 1, 2].map(|i| {
        let l = &lam[ROWS * i..ROWS * i + ROWS];
        [l[0] + l[2] + l[4], l[1] + l[3] + l[5]]
    })
}

/// Driving force (Eq. 33): `Fa_i = (mpp + mpa) s_i'' - F_i . u_i`, F_i the force of the beam on
/// sleeve i (the sleeve is translationally massless: F_i passes through the pin to the slider).
fn driving_forces(params: &RobotParams, pins: &Pins, lam: &[f64]) -> ([f64; 3], [[f64; 2]; 3]) {
    let f = pin_forces(lam);
    let fa = [0, 1, 2].map(|i| {
        let u = slider_direction(i);
        params.mpp_mpa * pins.s[i][2] - (f[i][0] * u[0] + f[i][1] * u[1])
    });
    (fa, f)
}

fn power(fa: &[f64; 3], pins: &Pins) -> f64 {
    (0..3).map(|i| fa[i] * pins.s[i][1]).sum()
}

/// What moves the sliders.
pub(crate) enum Motion<'a> {
    /// Inverse problem: `s_i(t)` prescribed by the trajectory, `Fa_i` from Eq. 33.
    Prescribed(&'a Trajectory),
    /// Direct problem: each slider a body of mass `mpp + mpa` on its rail pushed along `+u_i` by
    /// the law's `Fa_i(t, s_i, s_i')`, starting at `s0` [m] with speeds `v0` [m/s].
    Driven {
        law: &'a dyn ActuatorLaw,
        s0: [f64; 3],
        v0: [f64; 3],
    },
}

impl Motion<'_> {
    /// `[s_i, s_i']` at t = 0 of the slider unknowns (direct problem only).
    fn slider_unknowns(&self) -> Option<[[f64; 2]; 3]> {
        match self {
            Motion::Prescribed(_) => None,
            Motion::Driven { s0, v0, .. } => Some([0, 1, 2].map(|i| [s0[i], v0[i]])),
        }
    }

    /// Prescribed pins at time `t` (inverse problem), `None` in the direct problem, where the
    /// pins follow the Newton iterate. Checks that the prescribed sliders stay on their sides.
    fn prescribed_pins(&self, params: &RobotParams, t: f64) -> Result<Option<Pins>, FemError> {
        let Motion::Prescribed(traj) = self else {
            return Ok(None);
        };
        let pins = pins_at(params, traj, t)?;
        let limit = params.half_side();
        for i in 0..3 {
            if pins.s[i][0].abs() >= limit {
                return Err(FemError::SliderOffBase {
                    t,
                    slider: i + 1,
                    s: pins.s[i][0],
                    limit,
                });
            }
        }
        Ok(Some(pins))
    }

    /// The actuator law at the sliders' state of `pins`.
    fn law_forces(law: &dyn ActuatorLaw, pins: &Pins, t: f64) -> Result<[f64; 3], FemError> {
        law.force(t, pins.s.map(|s| s[0]), pins.s.map(|s| s[1]))
            .map_err(|source| FemError::Drive { t, source })
    }

    /// The sliders' rows at one iterate of the direct problem (`bp = beta'`, `gp = gamma'`, both
    /// zero for the initial accelerations); `None` in the inverse problem.
    fn slider_rows(
        &self,
        params: &RobotParams,
        pins: &Pins,
        t: f64,
        bp: f64,
        gp: f64,
    ) -> Result<Option<SliderRows>, FemError> {
        let Motion::Driven { law, .. } = self else {
            return Ok(None);
        };
        let (kp, kd) = (law.stiffness(), law.damping());
        Ok(Some(SliderRows {
            fa: Self::law_forces(*law, pins, t)?,
            diag: [0, 1, 2].map(|i| params.mpp_mpa + bp * kp[i] + gp * kd[i]),
        }))
    }

    /// `Fa` [N] and the pin forces at a converged state: Eq. 33 (inverse), the law (direct).
    fn forces(
        &self,
        params: &RobotParams,
        pins: &Pins,
        lam: &[f64],
        t: f64,
    ) -> Result<([f64; 3], [[f64; 2]; 3]), FemError> {
        match self {
            Motion::Prescribed(_) => Ok(driving_forces(params, pins, lam)),
            Motion::Driven { law, .. } => Ok((Self::law_forces(*law, pins, t)?, pin_forces(lam))),
        }
    }

    /// Direct problem: the simulated configuration must stay feasible (the limits of
    /// `flexstar_kinematics::feasibility`, applied to the simulated s: a check, not an equation).
    fn check_feasible(&self, params: &RobotParams, pins: &Pins, t: f64) -> Result<(), FemError> {
        if let Motion::Prescribed(_) = self {
            return Ok(());
        }
        check_configuration(params, pins.s.map(|s| s[0])).map_err(|violation| FemError::Infeasible { t, violation })
    }
}

/// The integration state at one time: coordinates, velocities, algorithmic accelerations
/// `q_dd`, the generalized-alpha acceleration variable `a`, multipliers, and the pins.
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    qdd: Vec<f64>,
    a: Vec<f64>,
    lam: Vec<f64>,
    pins: Pins,
}

/// Consistent accelerations and multipliers at t = 0:
/// `[M Phi_q^T; Phi_q 0] [q_dd; lambda] = [-f_conv - f_int; -Phi_dd_conv]` (with the sliders'
/// rows `m s'' - u . F = Fa` in the direct problem).
fn initial_state(
    params: &RobotParams,
    motion: &Motion,
    star: &mut Star,
    q: Vec<f64>,
    v: Vec<f64>,
) -> Result<State, FemError> {
    let (n_dof, n_sys) = (star.n_dof, star.n_sys);
    let l = params.l;
    let zeros = vec![0.0; n_dof];
    let pins_of = |star: &Star, q: &[f64]| match motion {
        Motion::Prescribed(traj) => pins_at(params, traj, 0.0),
        Motion::Driven { .. } => Ok(star.pins_of(q, &v, &zeros)),
    };
    let pins0 = pins_of(star, &q)?;
    let phi0 = star.constraints(&q, &pins0);
    let worst = phi0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if worst > 1e-9 * l {
        return Err(FemError::Input(format!(
            "the initial pose does not pass through the pins (largest constraint residual {worst:.3e})"
        )));
    }
    let mut res = vec![0.0; n_sys];
    let lam0 = vec![0.0; 3 * ROWS];
    let sl0 = motion.slider_rows(params, &pins0, 0.0, 0.0, 0.0)?;
    star.assemble(
        &q,
        &v,
        &zeros,
        &lam0,
        &pins0,
        sl0.as_ref(),
        1.0,
        0.0,
        &mut res,
        0.0,
        true,
    )?;
    let mut rhs: Vec<f64> = res.iter().map(|r| -r).collect();
    let vmax = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut conv = [0.0; 3 * ROWS];
    if vmax > 0.0 {
        // d^2/dtau^2 Phi(q + tau v) at tau = 0 by central differences (convective part; in the
        // direct problem the pins move with q, linearly, and add nothing)
        let tau = 1e-4 * l / vmax.max(1e-3);
        let qp: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a + tau * b).collect();
        let qm: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a - tau * b).collect();
        let fp = star.constraints(&qp, &pins_of(star, &qp)?);
        let fm = star.constraints(&qm, &pins_of(star, &qm)?);
        for k in 0..conv.len() {
            conv[k] = (fp[k] - 2.0 * phi0[k] + fm[k]) / (tau * tau);
        }
    }
    for i in 0..3 {
        let u = slider_direction(i);
        for r in 0..6 {
            // Phi contains -P(t): its second derivative contributes -s'' u (prescribed s only;
            // the direct problem's s'' is an unknown, zero in pins0)
            conv[ROWS * i + r] -= pins0.s[i][2] * u[r % 2];
        }
    }
    for k in 0..conv.len() {
        rhs[n_dof + k] = -conv[k];
    }
    star.factor(0.0)?;
    star.solve(&mut rhs);
    let qdd = rhs[..n_dof].to_vec();
    let lam = rhs[n_dof..].to_vec();
    let pins = match motion {
        Motion::Prescribed(_) => pins0,
        Motion::Driven { .. } => star.pins_of(&q, &v, &qdd),
    };
    Ok(State {
        a: qdd.clone(),
        q,
        v,
        qdd,
        lam,
        pins,
    })
}

/// Every output and snapshot time in `[0, t_end]`, sorted, duplicates removed: the step
/// boundaries.
fn event_times(t_out: &[f64], snap_times: &[f64]) -> Vec<f64> {
    let t_end = *t_out.last().unwrap_or(&0.0);
    let mut events: Vec<f64> = t_out
        .iter()
        .chain(snap_times.iter())
        .copied()
        .filter(|t| *t >= 0.0 && *t <= t_end)
        .collect();
    events.sort_by(|a, b| a.total_cmp(b));
    events.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    events
}

/// The recorded history being built: output samples and snapshots at their times.
struct Recorder<'a> {
    t_out: &'a [f64],
    snaps: Vec<f64>,
    out_k: usize,
    snap_k: usize,
    samples: Vec<Sample>,
    snapshots: Vec<Snapshot>,
}

impl<'a> Recorder<'a> {
    fn new(t_out: &'a [f64], snap_times: &[f64]) -> Self {
        let mut snaps = snap_times.to_vec();
        snaps.sort_by(|a, b| a.total_cmp(b));
        Recorder {
            t_out,
            snaps,
            out_k: 0,
            snap_k: 0,
            samples: Vec::with_capacity(t_out.len()),
            snapshots: Vec::new(),
        }
    }

    /// Record the state at time `t` if it is an output or a snapshot time.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        params: &RobotParams,
        star: &Star,
        st: &State,
        fa: [f64; 3],
        pin_force: [[f64; 2]; 3],
        t: f64,
        work: f64,
    ) {
        let (q, v, pins) = (&st.q, &st.v, &st.pins);
        if self.out_k < self.t_out.len() && (self.t_out[self.out_k] - t).abs() < 1e-12 {
            let pos = |j: usize| [q[3 * j], q[3 * j + 1]];
            let (ke_star, strain) = star.beam_energies(q, v);
            self.samples.push(Sample {
                t: self.t_out[self.out_k],
                g: pos(0),
                phi_g: q[2],
                tip: [0, 1, 2].map(|i| pos(star.node(i, star.ne))),
                sleeve_angle: [0, 1, 2].map(|i| star.gamma0[i] + q[star.psi(i)]),
                xi_c: [0, 1, 2].map(|i| q[star.xi(i, 0)]),
                fa,
                pin_force,
                ke_star,
                ke_sleeves: 0.5 * params.jp * (0..3).map(|i| v[star.psi(i)].powi(2)).sum::<f64>(),
                ke_sliders: 0.5 * params.mpp_mpa * (0..3).map(|i| pins.s[i][1].powi(2)).sum::<f64>(),
                strain,
                work,
                s: pins.s.map(|s| s[0]),
                sd: pins.s.map(|s| s[1]),
            });
            self.out_k += 1;
        }
        while self.snap_k < self.snaps.len() && (self.snaps[self.snap_k] - t).abs() < 1e-12 {
            let beams = [0, 1, 2].map(|i| {
                (0..=star.ne)
                    .map(|k| {
                        let j = star.node(i, k);
                        [q[3 * j], q[3 * j + 1]]
                    })
                    .collect()
            });
            self.snapshots.push(Snapshot {
                t: self.snaps[self.snap_k],
                s: pins.s.map(|s| s[0]),
                beams,
            });
            self.snap_k += 1;
        }
    }
}

/// The sleeves must stay on their beams: every contact point inside (0, L).
fn check_sleeves(star: &Star, q: &[f64], l: f64, t: f64) -> Result<(), FemError> {
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
    Ok(())
}

/// Work vectors of the Newton iteration, allocated once.
struct Workspace {
    /// Weight of each coordinate's increment in the convergence test: the element length for
    /// rotations (node rotations and sleeve rotations), 1 for lengths.
    weight: Vec<f64>,
    a_part: Vec<f64>,
    qh: Vec<f64>,
    vh: Vec<f64>,
    /// The Newton iterate: coordinates, velocities, accelerations, scaled multipliers.
    q1: Vec<f64>,
    v1: Vec<f64>,
    qdd1: Vec<f64>,
    nu: Vec<f64>,
    dx: Vec<f64>,
    res: Vec<f64>,
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
    fn step(
        params: &RobotParams,
        motion: &Motion,
        star: &mut Star,
        ga: &GenAlpha,
        st: &mut State,
        ws: &mut Workspace,
        stats: &mut Stats,
        t1: f64,
        h: f64,
    ) -> Result<(), FemError> {
        let (n_dof, n_sys) = (star.n_dof, star.n_sys);
        let l = params.l;
        let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
        let fixed = motion.prescribed_pins(params, t1)?;
        // predictor: constant acceleration, previous multipliers
        predict(ga, h, bp, gp, st, ws);
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
                    (p, motion.slider_rows(params, &p, t1, bp, gp)?)
                }
            };
            let fresh = star.assemble(
                &ws.q1,
                &ws.v1,
                &ws.qdd1,
                &ws.nu,
                &pins,
                sliders.as_ref(),
                bp,
                bp,
                &mut ws.res,
                t1,
                stale,
            )?;
            if fresh {
                star.factor(t1)?;
                stats.factorisations += 1;
                stale = false;
            }
            stats.newton_iterations += 1;
            for (d, r) in ws.dx[..n_sys].iter_mut().zip(&ws.res[..n_sys]) {
                *d = -r;
            }
            star.solve(&mut ws.dx);
            let dq_max = update_coordinates(ws, inv_bp, gp);
            let mut dl_max = 0.0f64;
            let mut l_max = 0.0f64;
            for k in 0..ws.nu.len() {
                ws.nu[k] += ws.dx[n_dof + k];
                dl_max = dl_max.max(ws.dx[n_dof + k].abs() / bp);
                l_max = l_max.max(ws.nu[k].abs() / bp);
            }
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
        let apq = ga.a_per_qdd();
        for ((a, ap), qdd) in st.a[..n_dof].iter_mut().zip(&ws.a_part[..n_dof]).zip(&ws.qdd1[..n_dof]) {
            *a = ap + apq * qdd;
        }
        st.pins = fixed.unwrap_or_else(|| star.pins_of(&ws.q1, &ws.v1, &ws.qdd1));
        std::mem::swap(&mut st.q, &mut ws.q1);
        std::mem::swap(&mut st.v, &mut ws.v1);
        std::mem::swap(&mut st.qdd, &mut ws.qdd1);
        for k in 0..ws.nu.len() {
            st.lam[k] = ws.nu[k] / bp;
        }
        stats.steps += 1;
        Ok(())
    }
}

/// Integrate from the initial state to the last output time.
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate(
    params: &RobotParams,
    motion: &Motion,
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
    let (mut star, q, v) = Star::new(params, run.ne, init, motion.slider_unknowns())?;
    let (n_dof, n_sys) = (star.n_dof, star.n_sys);
    let l = params.l;
    let mut st = initial_state(params, motion, &mut star, q, v)?;
    motion.check_feasible(params, &st.pins, 0.0)?;

    let t_end = *t_out.last().unwrap_or(&0.0);
    let events = event_times(t_out, snap_times);
    let ga = GenAlpha::new(run.rho_inf);
    let mut rec = Recorder::new(t_out, snap_times);
    let mut stats = Stats::default();
    let (fa0, pf0) = motion.forces(params, &st.pins, &st.lam, 0.0)?;
    let mut pow_prev = power(&fa0, &st.pins);
    let mut work = 0.0;
    rec.record(params, &star, &st, fa0, pf0, 0.0, 0.0);

    let rot = |j: usize| j < 3 * star.n_nodes && j % 3 == 2 || (j >= 3 * star.n_nodes && j < 3 * star.n_nodes + 3);
    let mut ws = Workspace {
        weight: (0..n_dof).map(|j| if rot(j) { star.h } else { 1.0 }).collect(),
        a_part: vec![0.0; n_dof],
        qh: vec![0.0; n_dof],
        vh: vec![0.0; n_dof],
        q1: vec![0.0; n_dof],
        v1: vec![0.0; n_dof],
        qdd1: vec![0.0; n_dof],
        nu: vec![0.0; 3 * ROWS],
        dx: vec![0.0; n_sys],
        res: vec![0.0; n_sys],
    };
    let mut t = 0.0;
    for w in events.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        let n_sub = ((tb - ta) / run.dt - 1e-9).ceil().max(1.0) as usize;
        let h = (tb - ta) / n_sub as f64;
        for sub in 1..=n_sub {
            let t1 = if sub == n_sub { tb } else { ta + h * sub as f64 };
            step(params, motion, &mut star, &ga, &mut st, &mut ws, &mut stats, t1, h)?;
            t = t1;
            check_sleeves(&star, &st.q, l, t)?;
            motion.check_feasible(params, &st.pins, t)?;
            let (fa, pf) = motion.forces(params, &st.pins, &st.lam, t)?;
            let pw = power(&fa, &st.pins);
            work += 0.5 * h * (pow_prev + pw);
            pow_prev = pw;
            rec.record(params, &star, &st, fa, pf, t, work);
        }
        if let Some(cb) = progress {
            cb((t / t_end).min(1.0));
        }
        if flexstar_model::cancel::cancelled() {
            return Err(FemError::Cancelled { t });
        }
    }
    stats.symbolic_factorisations = star.symbolic_count;
    stats.sparse_fallbacks = star.sparse_fallbacks;
    stats.last_fallback = star.last_fallback;
    Ok(History {
        samples: rec.samples,
        snapshots: rec.snapshots,
        node_x: star.node_x(),
        stats,
    })
}
