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
use flexstar_model::{Robot, Trajectory};
use flexstar_numerics::GenAlpha;

use crate::error::PivotError;
use crate::star::{pin_forces, Attached, Factors, InitialState, Iterate, Pins, SliderRows, Star, StarFriction, ROWS};
use crate::{FemError, NewtonFailure};

mod events;
mod friction;
mod motion;
mod recorder;
mod static_start;
mod step;

use friction::friction_start;
pub(crate) use friction::FrictionLog;
pub(crate) use motion::Motion;
use motion::{pins_at, power};
use recorder::{event_times, Recorder};
pub(crate) use recorder::{FrictionSample, Sample, Snapshot};
pub(crate) use static_start::static_equilibrium;
use step::{step, Workspace};

/// Numerical settings of one run.
#[derive(Debug, Clone)]
pub(crate) struct RunSettings {
    /// Elements per beam.
    pub ne: usize,
    /// Largest time step [s].
    pub dt: f64,
    pub rho_inf: f64,
}

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Time steps taken.
    pub steps: usize,
    /// Newton iterations (imbalance evaluations and solves) in all.
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
    /// Material positions of each beam's nodes from G [m] (`k h_i`).
    pub node_x: [Vec<f64>; 3],
    pub stats: Stats,
    /// Which of the additions of `docs/fem.md` section 9 the run had: payload, load, damping,
    /// gravity (their columns).
    pub payload: bool,
    pub load: bool,
    pub damping: bool,
    pub gravity: bool,
    /// With friction: its dissipation and time stuck over the run.
    pub friction: Option<FrictionLog>,
    /// With sensors: their readings at the output times (`docs/sensors.md`).
    pub sensors: Option<flexstar_model::SensorTable>,
}

/// Work and dissipated energy since t = 0 [J], by the trapezoidal rule on the integration steps,
/// with the powers [W] at the last step: the drivers' (`Fa . s'`), the load's at G (Eq. L2's
/// `Fx x' + Fy y' + Mz phi'`) and the dissipation (Eqs. D10, D16).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Works {
    pub work: f64,
    pub w_load: f64,
    pub e_d: f64,
    powers: [f64; 3],
    /// With friction: its dissipation and time stuck (`friction.rs`).
    pub friction: Option<FrictionLog>,
}

impl Works {
    /// The powers at the state `st` (time `t`) with the drivers' forces `fa`.
    fn powers(star: &Star, st: &State, fa: &[f64; 3], t: f64) -> Result<[f64; 3], FemError> {
        Ok([
            power(fa, &st.pins),
            star.load_power(&st.v, t),
            star.dissipation_power(&st.q, &st.v, &st.pins, t)?,
        ])
    }

    /// Start at t = 0 (nothing done yet).
    fn start(star: &Star, st: &State, fa: &[f64; 3]) -> Result<Self, FemError> {
        Ok(Works {
            powers: Self::powers(star, st, fa, 0.0)?,
            friction: star.friction.is_some().then(|| FrictionLog::start(star, st)),
            ..Works::default()
        })
    }

    /// One step of length `h` [s] ending at `t` in the state `st`.
    fn advance(&mut self, star: &Star, st: &State, fa: &[f64; 3], t: f64, h: f64) -> Result<(), FemError> {
        let p = Self::powers(star, st, fa, t)?;
        self.work += 0.5 * h * (self.powers[0] + p[0]);
        self.w_load += 0.5 * h * (self.powers[1] + p[1]);
        self.e_d += 0.5 * h * (self.powers[2] + p[2]);
        self.powers = p;
        if let Some(f) = &mut self.friction {
            f.advance(star, st, h);
        }
        Ok(())
    }
}

/// The integration state at one time: coordinates, velocities, algorithmic accelerations
/// `q_dd`, the generalized-alpha acceleration variable `a`, multipliers, and the pins.
#[derive(Clone)]
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
/// rows `m s'' - u . F = Fa` in the direct problem). The start must pass through the pins: every
/// row vanishes for the undeformed start; a deflected start (Eq. G8) satisfies the tangent rows
/// with Eq. S9's interior slope, so only their position rows are checked.
fn initial_state(motion: &Motion, star: &mut Star, q: Vec<f64>, v: Vec<f64>) -> Result<State, FemError> {
    let (n_dof, n_sys) = (star.n_dof, star.n_sys);
    let l = star.length_scale();
    let zeros = vec![0.0; n_dof];
    let pins_of = |star: &Star, q: &[f64]| match motion {
        Motion::Prescribed(traj) => pins_at(star, traj, 0.0),
        Motion::Driven { .. } => Ok(star.pins_of(q, &v, &zeros)),
    };
    let pins0 = pins_of(star, &q)?;
    let phi0 = star.constraints(&q, &pins0);
    let checked = |k: &usize| !(star.attached.weighs() && k % ROWS == ROWS - 1);
    let worst = (0..phi0.len())
        .filter(checked)
        .fold(0.0f64, |m, k| m.max(phi0[k].abs()));
    if worst > 1e-9 * l {
        return Err(FemError::Input(format!(
            "the initial pose does not pass through the pins (largest constraint violation {worst:.3e})"
        )));
    }
    let mut res = vec![0.0; n_sys];
    let lam0 = vec![0.0; 3 * ROWS];
    let sl0 = motion.slider_rows(star, &pins0, 0.0, 0.0, 0.0)?;
    star.assemble(
        Iterate {
            q: &q,
            v: &v,
            qdd: &zeros,
            lam: &lam0,
            pins: &pins0,
            sliders: sl0.as_ref(),
            load: star.attached.load_at(0.0),
        },
        Factors {
            cf: 1.0,
            ck: 0.0,
            cv: 0.0,
            cm: 1.0,
        },
        &mut res,
        0.0,
        true,
    )?;
    let mut rhs: Vec<f64> = res.iter().map(|r| -r).collect();
    let conv = convective_accelerations(star, &q, &v, &phi0, &pins0, l, pins_of)?;
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

/// `Phi_dd` of the constraints at t = 0 with zero accelerations (the right-hand side of
/// [`initial_state`]'s multiplier rows): the convective part `d^2/dtau^2 Phi(q + tau v)` by
/// central differences, and `-s'' u` of the prescribed sliders.
fn convective_accelerations(
    star: &Star,
    q: &[f64],
    v: &[f64],
    phi0: &[f64],
    pins0: &Pins,
    l: f64,
    pins_of: impl Fn(&Star, &[f64]) -> Result<Pins, FemError>,
) -> Result<[f64; 3 * ROWS], FemError> {
    let vmax = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut conv = [0.0; 3 * ROWS];
    if vmax > 0.0 {
        // d^2/dtau^2 Phi(q + tau v) at tau = 0 by central differences (convective part; in the
        // direct problem the pins move with q, linearly, and add nothing)
        let tau = 1e-4 * l / vmax.max(1e-3);
        let qp: Vec<f64> = q.iter().zip(v).map(|(a, b)| a + tau * b).collect();
        let qm: Vec<f64> = q.iter().zip(v).map(|(a, b)| a - tau * b).collect();
        let fp = star.constraints(&qp, &pins_of(star, &qp)?);
        let fm = star.constraints(&qm, &pins_of(star, &qm)?);
        for k in 0..conv.len() {
            conv[k] = (fp[k] - 2.0 * phi0[k] + fm[k]) / (tau * tau);
        }
    }
    for i in 0..3 {
        let u = star.slider_direction(i);
        for r in 0..6 {
            // Phi contains -P(t): its second derivative contributes -s'' u (prescribed s only;
            // the direct problem's s'' is an unknown, zero in pins0)
            conv[ROWS * i + r] -= pins0.s[i][2] * u[r % 2];
        }
    }
    Ok(conv)
}

/// How many times a step whose Newton iteration fails is halved before the run stops: a step
/// of `dt / 2^MAX_HALVINGS` at the least. A load that jumps on a bare G (docs/fem.md 9.3) excites
/// the weld's highest modes; a shorter step resolves their first instants.
const MAX_HALVINGS: u32 = 5;

/// One step of the integration loop with everything it updates.
struct Stepper<'a, 'r> {
    motion: &'a Motion<'a>,
    star: &'a mut Star,
    ga: &'a GenAlpha,
    st: &'a mut State,
    ws: &'a mut Workspace,
    stats: &'a mut Stats,
    works: &'a mut Works,
    rec: &'a mut Recorder<'r>,
}

impl Stepper<'_, '_> {
    /// Step of length `h` to `t1` [s]; when Newton fails, the state is restored and the step
    /// taken as two halves (at most [`MAX_HALVINGS`] times nested), so a run that converges at
    /// the given step is unchanged bit for bit.
    fn step_or_halve(&mut self, backup: &mut State, t1: f64, h: f64, depth: u32) -> Result<(), FemError> {
        if depth < MAX_HALVINGS {
            backup.clone_from(self.st);
        }
        let stepped = if self.star.friction.is_some() {
            self.event_step(t1, h)
        } else {
            step(self.motion, self.star, self.ga, self.st, self.ws, self.stats, t1, h)
        };
        match stepped {
            Ok(()) => self.finish(t1, h),
            Err(FemError::Newton { .. } | FemError::NonFinite { .. }) if depth < MAX_HALVINGS => {
                self.st.clone_from(backup);
                self.step_or_halve(backup, t1 - 0.5 * h, 0.5 * h, depth + 1)?;
                self.step_or_halve(backup, t1, 0.5 * h, depth + 1)
            }
            Err(e) => Err(e),
        }
    }

    /// The checks, works and records after a converged step ending at `t` [s] of length `h`.
    fn finish(&mut self, t: f64, h: f64) -> Result<(), FemError> {
        let st = &*self.st;
        self.star.check_on_beams(&st.q, t)?;
        self.motion.check_feasible(self.star, &st.pins, t)?;
        let (fa, pf) = self.motion.forces(self.star, &st.pins, &st.lam, t)?;
        self.works.advance(self.star, st, &fa, t, h)?;
        self.rec.record(self.star, st, fa, pf, t, self.works);
        Ok(())
    }
}

/// Integrate the star of `robot` from the initial state to the last output time, the star
/// carrying `attached`'s payload, damping and load (`docs/fem.md` section 9).
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate(
    robot: &Robot,
    motion: &Motion,
    t_out: &[f64],
    snap_times: &[f64],
    init: &InitialState,
    run: &RunSettings,
    attached: &Attached,
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
    let (mut star, mut q, v) = Star::new(robot, run.ne, init, motion.slider_unknowns())?;
    star.attached = attached.clone();
    if let Some(law) = attached.friction {
        let xi = [0, 1, 2].map(|i| q[star.xi(i, 0)]);
        let xi_dot = [0, 1, 2].map(|i| v[star.xi(i, 0)]);
        star.friction = Some(StarFriction::start(law, xi, xi_dot, motion.slider_unknowns()));
    }
    if attached.weighs() {
        // Eq. G8: start in the deflected static equilibrium, the sliders held where they start
        let s0 = motion.start_sliders(&star)?;
        let (_, sag) = static_equilibrium(robot, run.ne, init, attached, s0, 0.0)?;
        q[..sag.len()].copy_from_slice(&sag);
    }
    let mut st = if star.friction.is_some() {
        friction_start(motion, &mut star, q, v)?
    } else {
        initial_state(motion, &mut star, q, v)?
    };
    motion.check_feasible(&star, &st.pins, 0.0)?;

    let t_end = *t_out.last().unwrap_or(&0.0);
    let events = event_times(t_out, snap_times);
    let ga = GenAlpha::new(run.rho_inf);
    let sensors = crate::sensors::SensorRecorder::new(&attached.sensors, attached.gravity, t_out.len());
    let mut rec = Recorder::new(t_out, snap_times, sensors);
    let mut stats = Stats::default();
    let (fa0, pf0) = motion.forces(&star, &st.pins, &st.lam, 0.0)?;
    let mut works = Works::start(&star, &st, &fa0)?;
    rec.record(&star, &st, fa0, pf0, 0.0, &works);

    let mut ws = Workspace::new(&star);
    let mut t = 0.0;
    let mut backup = st.clone();
    for w in events.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        let n_sub = ((tb - ta) / run.dt - 1e-9).ceil().max(1.0) as usize;
        let h = (tb - ta) / n_sub as f64;
        for sub in 1..=n_sub {
            let t1 = if sub == n_sub { tb } else { ta + h * sub as f64 };
            let mut run_step = Stepper {
                motion,
                star: &mut star,
                ga: &ga,
                st: &mut st,
                ws: &mut ws,
                stats: &mut stats,
                works: &mut works,
                rec: &mut rec,
            };
            run_step.step_or_halve(&mut backup, t1, h, 0)?;
            t = t1;
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
        payload: attached.payload.is_some(),
        load: attached.load.is_some(),
        damping: attached.beta > 0.0 || attached.alpha > 0.0,
        gravity: attached.weighs(),
        friction: works.friction,
        sensors: rec.sensors.map(crate::sensors::SensorRecorder::finish),
    })
}
