//! Stick and slip events located within the step (`docs/friction.md` 9.5, Eqs. F24-F26): a
//! prescribed motion with friction in the sleeves. Only a run with friction comes here.
//!
//! A step is first taken with the contacts it starts with. If the judging of `docs/friction.md`
//! 8.2 calls for a switch, the event is located within the step (Eq. F24: the sliding speed's
//! zero, or the stuck force reaching its limit, interpolated linearly between the step's ends),
//! the step is retaken to the event with the old contacts, the contacts due there switch, the
//! accelerations and multipliers jump to the new contacts' at the same state (Eq. F26) and the
//! generalized-alpha method restarts from them (its acceleration variable set to the new
//! accelerations, as at t = 0); the rest of the step follows with the new contacts, judged
//! again. After [`MAX_SPLITS`] events in one step the rest of the step falls back to the switch
//! at the step's start (`stick_slip::switching_step`).

use flexstar_kinematics::RigidState;
use flexstar_model::friction_events::{crossing, first_event};
use flexstar_model::Contact;
use flexstar_numerics::GenAlpha;

use crate::error::AmmError;
use crate::stick_slip::{self, FrictionOutput, StepEnd, Which};
use crate::system::System;

/// Events located in one step before the rest of the step falls back to the switch at its start.
const MAX_SPLITS: usize = 6;

/// The material coordinates a located step's judging carries for a sleeve that stops: none, for
/// such a sleeve sticks at its coordinate at the event, which [`EventStepper::switch_at_event`]
/// takes (the step-start coordinates, a sum over the modes per sleeve, are computed only for the
/// switch at the step's start of the fallback).
const AT_THE_EVENT: [f64; 3] = [f64::NAN; 3];

/// The generalized-alpha state of a run: coordinates, rates, the acceleration variable and
/// the accelerations (each 3 (N + 2)).
pub(crate) struct State<'a> {
    pub(crate) q: &'a mut [f64],
    pub(crate) v: &'a mut [f64],
    pub(crate) acc: &'a mut [f64],
    pub(crate) qdd: &'a mut [f64],
}

/// What locating an event reads at the start of a step: each sleeve's sliding speed [m/s] and,
/// stuck, its force's excess over its limit `|F_t| - mu_static L` [N] (Eq. F6).
#[derive(Debug, Clone, Copy)]
struct Probe {
    speed: [f64; 3],
    excess: [f64; 3],
}

impl Probe {
    /// The probe of `sys` at the rigid state `st` with the rates `v` and the last multipliers.
    fn of(sys: &System, st: &RigidState, v: &[f64]) -> Self {
        Probe {
            speed: stick_slip::speeds(sys, st, v),
            excess: stick_excess(sys),
        }
    }

    /// Eq. F24: the fraction of the step `theta` in [0, 1] at which the first of the contact
    /// changes `change` falls, linearly between the step's start (this probe) and its end
    /// (`end`, `sys` at the end), and which of them fall there (within 1e-9 of the step).
    fn first_event(
        &self,
        sys: &System,
        change: &[(Which, Contact)],
        end: &StepEnd,
        h: f64,
    ) -> (f64, Vec<(Which, Contact)>) {
        let at_end = stick_excess(sys);
        let fraction = |&(which, c): &(Which, Contact)| -> f64 {
            let Which::Sleeve(i) = which else {
                return 0.0;
            };
            let (a, b) = match c {
                // a slipping sleeve stops: its speed crosses zero
                Contact::Stuck(_) => (self.speed[i], end.vs[i]),
                // a stuck sleeve breaks loose: its force's excess crosses zero
                _ => (-self.excess[i], -at_end[i]),
            };
            crossing(a, b)
        };
        let times: Vec<f64> = change.iter().map(fraction).collect();
        first_event(change, &times, h)
    }
}

/// Each stuck sleeve's excess of the force its stick needs over its limit, `|F_t| -
/// mu_static L` [N] (Eqs. F6, F21) at the last multipliers; `-inf` for a sleeve not stuck.
fn stick_excess(sys: &System) -> [f64; 3] {
    let Some(fr) = &sys.friction else {
        return [f64::NEG_INFINITY; 3];
    };
    std::array::from_fn(|i| match fr.contacts[i] {
        Contact::Stuck(_) => {
            let need = sys.lam[fr.stick[i]];
            need.abs() - fr.law.sleeve(i).mu_static * fr.load_at(i, &sys.lam, need)
        }
        _ => f64::NEG_INFINITY,
    })
}

impl System {
    /// Eqs. F25-F26: the accelerations `qdd` and the multipliers (`self.lam`) at the rigid state
    /// `st` with the star at `q`, `v`, right after the contacts switched, from the equations of
    /// motion and the rows at the acceleration level at that state (`beta' = 0`, as the
    /// consistent start), not from the step's `q''`: the index-3 step's `q''` carries its rows'
    /// position correction divided by its `beta'`, large after a short part step. A stuck
    /// sleeve's force is that of its compliance at the state (Eq. F16), which the switch does
    /// not change: a sleeve stuck before keeps its row's last multiplier `stuck_force`, one that
    /// sticks now starts from zero (it sticks where it is, its compliance unstrained); these are
    /// known forces along `b_i` (Eq. F20), not unknowns. A sleeve that slips has the Coulomb
    /// force of the new multipliers (Eq. F15, the load's signs from `self.lam`).
    fn jump(&mut self, st: &RigidState, (q, v): (&[f64], &[f64]), qdd: &mut [f64]) -> Result<(), AmmError> {
        let nb = self.nb;
        let Some(fr) = self.friction.as_ref() else {
            return Ok(());
        };
        let (stick, contacts) = (fr.stick, fr.contacts);
        let stuck_force: [f64; 3] = std::array::from_fn(|i| match contacts[i] {
            Contact::Stuck(_) => self.lam[stick[i]],
            _ => 0.0,
        });
        self.solve(st, 0.0, 0.0, q, v, qdd)?;
        if stuck_force.iter().any(|&f| f != 0.0) {
            // the stuck sleeves' forces along b_i: the same system, forced by them alone
            self.resid.iter_mut().for_each(|r| *r = 0.0);
            let mut b = vec![0.0; nb];
            for (i, &f) in stuck_force.iter().enumerate() {
                if f != 0.0 {
                    self.friction_direction(i, &mut b);
                    for (r, x) in self.resid[i * nb..(i + 1) * nb].iter_mut().zip(&b) {
                        *r += f * x;
                    }
                }
            }
            let lam = self.lam.clone();
            let mut dqdd = vec![0.0; qdd.len()];
            self.solve_prepared(0.0, None, &mut dqdd);
            qdd.iter_mut().zip(&dqdd).for_each(|(a, d)| *a += d);
            self.lam.iter_mut().zip(&lam).for_each(|(l, old)| *l += old);
        }
        for (i, f) in stuck_force.iter().enumerate() {
            self.lam[stick[i]] = *f;
        }
        self.set_axial_acceleration(qdd);
        Ok(())
    }
}

/// The event stepping of a prescribed motion with friction and its workspaces (allocated once
/// per run).
pub(crate) struct EventStepper {
    ga: GenAlpha,
    /// q, v, acc, qdd at the start of the (part) step being taken.
    start: [Vec<f64>; 4],
    /// The predictors q^, v^ and the acceleration variable's part.
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    a_part: Vec<f64>,
    /// Multipliers at the start of the (part) step.
    lam: Vec<f64>,
    /// The coordinates at the start of the grid step (for [`EventStepper::diverged`]'s report).
    grid_q: Vec<f64>,
}

impl EventStepper {
    /// Workspaces for `n` coordinates and `m` multipliers.
    pub(crate) fn new(ga: GenAlpha, n: usize, m: usize) -> Self {
        EventStepper {
            ga,
            start: std::array::from_fn(|_| vec![0.0; n]),
            qhat: vec![0.0; n],
            vhat: vec![0.0; n],
            a_part: vec![0.0; n],
            lam: vec![0.0; m],
            grid_q: vec![0.0; n],
        }
    }

    fn save(&mut self, sys: &System, x: &State) {
        for (s, y) in self.start.iter_mut().zip([&*x.q, &*x.v, &*x.acc, &*x.qdd]) {
            s.copy_from_slice(y);
        }
        self.lam.copy_from_slice(&sys.lam);
    }

    fn restore(&self, sys: &mut System, x: &mut State) {
        for (s, y) in self.start.iter().zip([&mut *x.q, &mut *x.v, &mut *x.acc, &mut *x.qdd]) {
            y.copy_from_slice(s);
        }
        sys.lam.copy_from_slice(&self.lam);
        sys.set_axial_acceleration(x.qdd);
    }

    /// One step of length `h` from the saved start to the rigid state `st` with the current
    /// contacts, accepted into `x`; what the judging reads (`xi_start`: the sleeves' material
    /// coordinates at the start).
    fn attempt(
        &mut self,
        sys: &mut System,
        st: &RigidState,
        h: f64,
        x: &mut State,
        xi_start: [f64; 3],
    ) -> Result<StepEnd, AmmError> {
        let ga = self.ga;
        let (bp, gp) = (ga.beta_prime(h), ga.gamma_prime(h));
        let [q0, v0, a0, d0] = &self.start;
        let predicted = self
            .a_part
            .iter_mut()
            .zip(self.qhat.iter_mut())
            .zip(self.vhat.iter_mut());
        for (((ap, qh), vh), (((&qi, &vi), &ai), &di)) in predicted.zip(q0.iter().zip(v0).zip(a0).zip(d0)) {
            (*ap, *qh, *vh) = ga.predict(h, qi, vi, ai, di);
        }
        sys.solve(st, bp, gp, &self.qhat, &self.vhat, x.qdd)?;
        let predicted = (&self.qhat[..], &self.vhat[..], &self.a_part[..]);
        if !crate::solver::accept(&ga, (bp, gp), predicted, x.qdd, (x.q, x.v, x.acc)) {
            return Err(AmmError::NonFinite { t: st.t, dt: h });
        }
        Ok(StepEnd {
            xi_start,
            vs: stick_slip::speeds(sys, st, x.v),
            ..StepEnd::default()
        })
    }

    /// A singular constraint system `e` met in the grid step of length `h` to the rigid state
    /// `st` is a divergence ([`AmmError::Diverged`]) when the same rows at the rigid pose (every
    /// elastic coordinate zero) are regular: the rows' rank depends on the pose, not on the small
    /// deflections, so then the coordinates (`at`, or the step's last predictor) have left the
    /// solution and no row lost rank. Any other error is returned as it is.
    fn diverged(&self, sys: &mut System, st: &RigidState, h: f64, at: &[f64], e: AmmError) -> AmmError {
        let AmmError::SingularConstraints { t, source } = e else {
            return e;
        };
        let rigid = vec![0.0; at.len()];
        if sys
            .prepare(st, self.ga.beta_prime(h), self.ga.gamma_prime(h), &rigid)
            .is_err()
        {
            return AmmError::SingularConstraints { t, source };
        }
        let largest = |q: &[f64]| q.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        AmmError::Diverged {
            t,
            dt: h,
            reached: largest(at).max(largest(&self.qhat)),
            start: largest(&self.grid_q),
            source,
        }
    }

    /// One step of the run's grid, from `st` (at its start, the rigid state at `t1` on return)
    /// to `t1` [s], with the events in it located ([`EventStepper::step_events`]); a singular
    /// constraint system met on the way is reported as a divergence where the same rows at the
    /// undeformed pose are regular ([`EventStepper::diverged`]).
    pub(crate) fn step<K>(
        &mut self,
        sys: &mut System,
        kin: &K,
        (st, t1): (&mut RigidState, f64),
        x: &mut State,
        out: &mut FrictionOutput,
        rails: &dyn Fn(&RigidState) -> f64,
    ) -> Result<(), AmmError>
    where
        K: Fn(f64) -> Result<RigidState, AmmError>,
    {
        self.grid_q.copy_from_slice(x.q);
        let h = t1 - st.t;
        match self.step_events(sys, kin, (st, t1), x, out, rails) {
            Err(e @ AmmError::SingularConstraints { .. }) => {
                let end = kin(t1)?;
                Err(self.diverged(sys, &end, h, x.q, e))
            }
            other => other,
        }
    }

    /// One step of the run's grid, from `st` (at its start, the rigid state at `t1` on return)
    /// to `t1` [s], with the events in it located (module doc); the friction's tally advanced
    /// over each part.
    fn step_events<K>(
        &mut self,
        sys: &mut System,
        kin: &K,
        (st, t1): (&mut RigidState, f64),
        x: &mut State,
        out: &mut FrictionOutput,
        rails: &dyn Fn(&RigidState) -> f64,
    ) -> Result<(), AmmError>
    where
        K: Fn(f64) -> Result<RigidState, AmmError>,
    {
        let end_st = kin(t1)?;
        for split in 0..=MAX_SPLITS {
            let h = t1 - st.t;
            self.save(sys, x);
            let probe = Probe::of(sys, st, x.v);
            let stuck = stuck_now(sys);
            let end = self.attempt(sys, &end_st, h, x, AT_THE_EVENT)?;
            let changes = stick_slip::changes(sys, None, &end, stuck, stuck);
            let change = changes.as_slice();
            if change.is_empty() {
                advance(sys, out, x, (end.vs, rails(&end_st)), h);
                *st = end_st;
                return Ok(());
            }
            if split == MAX_SPLITS {
                break;
            }
            let (theta, due) = probe.first_event(sys, change, &end, h);
            if theta >= 1.0 {
                advance(sys, out, x, (end.vs, rails(&end_st)), h);
                *st = end_st;
            } else {
                self.restore(sys, x);
                if theta > 0.0 {
                    let mid = kin(st.t + theta * h)?;
                    let end = self.attempt(sys, &mid, theta * h, x, AT_THE_EVENT)?;
                    advance(sys, out, x, (end.vs, rails(&mid)), theta * h);
                    *st = mid;
                }
            }
            self.switch_at_event(sys, st, x, &due)?;
            if theta >= 1.0 {
                return Ok(());
            }
        }
        // the rest of the step: the switch at its start (docs/friction.md 8.2)
        self.restore(sys, x);
        let h = t1 - st.t;
        let xi_start = stick_slip::coordinates(sys, st, x.q);
        let end = stick_slip::switching_step(sys, None, t1, h, |sys, _, retake| {
            if retake {
                self.restore(sys, x);
            }
            self.attempt(sys, &end_st, h, x, xi_start)
        })?;
        advance(sys, out, x, (end.vs, rails(&end_st)), h);
        *st = end_st;
        Ok(())
    }

    /// The contacts `due` switch at the rigid state `st` (a sleeve that stops sticks at its
    /// material coordinate there, its force starting from zero) and the accelerations and
    /// multipliers jump to theirs (Eq. F26); the method restarts from them, its acceleration
    /// variable the new accelerations (Eq. F25).
    fn switch_at_event(
        &mut self,
        sys: &mut System,
        st: &RigidState,
        x: &mut State,
        due: &[(Which, Contact)],
    ) -> Result<(), AmmError> {
        if sys.friction.is_none() {
            return Ok(());
        }
        let xi = stick_slip::coordinates(sys, st, x.q);
        if let Some(fr) = sys.friction.as_mut() {
            for &(which, c) in due {
                if let Which::Sleeve(i) = which {
                    fr.contacts[i] = match c {
                        Contact::Stuck(_) => Contact::Stuck(xi[i]),
                        other => other,
                    };
                }
            }
        }
        sys.jump(st, (x.q, x.v), x.qdd)?;
        x.acc.copy_from_slice(x.qdd);
        Ok(())
    }
}

/// Which contacts are stuck now (sleeves, then the inverse problem's free rails).
fn stuck_now(sys: &System) -> [bool; 6] {
    let sleeves = sys.friction.as_ref().map_or([Contact::Free; 3], |f| f.contacts);
    std::array::from_fn(|k| k < 3 && sleeves[k].stuck().is_some())
}

/// The friction's tally over a (part) step of length `h` ending in the state `x`, with the
/// sleeves' speeds `vs` and the rails' power.
fn advance(sys: &System, out: &mut FrictionOutput, x: &State, (vs, rails): ([f64; 3], f64), h: f64) {
    let ff = stick_slip::sleeve_forces(sys, x.qdd);
    out.advance(sys, (ff, vs), (&[Contact::Free; 3], rails), h);
}
