//! Stick and slip in the time step (`docs/friction.md` 3 and 8): the stuck contacts frozen in
//! the predictor and the Newton updates, the switch between the stuck and sliding constraint
//! sets after a converged step (the step then taken again), the consistent start, and the
//! friction's dissipation and time stuck. Only a run with friction comes here.

use super::*;
use crate::star::Contact;

use flexstar_model::friction_run::{exceeds, Which, MAX_ROUNDS};
use flexstar_model::FrictionTally;

/// Hold every stuck coordinate of `star` at its value, at rest (Eq. F9): `q = q*`, `v = q_dd = 0`.
#[inline]
pub(super) fn freeze(star: &Star, q: &mut [f64], v: &mut [f64], qdd: &mut [f64]) {
    for (k, at) in star.stuck_coordinates() {
        q[k] = at;
        v[k] = 0.0;
        qdd[k] = 0.0;
    }
}

/// The contact changes a converged state `end` (from `start`) calls for (`docs/friction.md`
/// 8.2), each contact switching at most once per step (`was_stuck`: stuck in any round of this
/// step; `stuck_at_start`: stuck when the step began; sleeves then rails):
/// - a slipping contact whose velocity reached zero or reversed sticks where the step started,
///   unless it broke loose in this step (at the threshold its first slipping velocity is of
///   round-off size; it sticks in the next step if it still reverses);
/// - a contact stuck since the step began whose needed force exceeds `mu_static L` (sleeve) or
///   `Fc` (rail) slips in the direction of that force. One that stuck in this step keeps its
///   stick for the step: its force then includes stopping its slip within one step, not a load
///   it holds; from the next step on it is judged at rest.
pub(super) fn changes(
    motion: &Motion,
    star: &Star,
    (start, end): (&State, &State),
    t: f64,
    was_stuck: [bool; 6],
    stuck_at_start: [bool; 6],
) -> Result<Vec<(Which, Contact)>, FemError> {
    let Some(fr) = &star.friction else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for i in 0..3 {
        let xc = star.xi(i, 0);
        let law = fr.law.sleeve(i);
        match fr.sleeves[i] {
            Contact::Slip(s) if law.mu_static > 0.0 && !was_stuck[i] && end.v[xc] * s <= 0.0 => {
                out.push((Which::Sleeve(i), Contact::Stuck(start.q[xc])));
            }
            Contact::Stuck(_) if stuck_at_start[i] => {
                let need = star.sleeve_friction_force(i, &end.q, &end.lam, &end.pins);
                let (load, _) = star.sleeve_load(i, &end.q, &end.lam, fr.law.model);
                if exceeds(need, law.mu_static * load) {
                    out.push((Which::Sleeve(i), Contact::Slip(need.signum())));
                }
            }
            _ => {}
        }
    }
    if star.direct {
        let (fa, pin) = motion.forces(star, &end.pins, &end.lam, t)?;
        for i in 0..3 {
            let si = star.slider(i);
            let law = fr.law.rail(i);
            match fr.rails[i] {
                Contact::Slip(s) if law.fc > 0.0 && !was_stuck[3 + i] && end.v[si] * s <= 0.0 => {
                    out.push((Which::Rail(i), Contact::Stuck(start.q[si])));
                }
                Contact::Stuck(_) if stuck_at_start[3 + i] => {
                    let need = star.rail_stick_force(i, fa[i], pin[i]);
                    if exceeds(need, law.fc) {
                        out.push((Which::Rail(i), Contact::Slip(need.signum())));
                    }
                }
                _ => {}
            }
        }
    }
    Ok(out)
}

/// Set contact `which` of `star` to `c`.
pub(super) fn set(star: &mut Star, which: Which, c: Contact) {
    if let Some(fr) = &mut star.friction {
        match which {
            Which::Sleeve(i) => fr.sleeves[i] = c,
            Which::Rail(i) => fr.rails[i] = c,
        }
    }
}

/// The contact states of `star` (sleeves, then rails).
fn contacts(star: &Star) -> [Contact; 6] {
    let fr = star.friction.as_ref().expect("a run with friction");
    [fr.sleeves, fr.rails].concat().try_into().expect("six contacts")
}

/// Which contacts were stuck in any of the states `tried`.
fn stuck_in(tried: &[[Contact; 6]]) -> [bool; 6] {
    std::array::from_fn(|k| tried.iter().any(|c| c[k].stuck().is_some()))
}

impl Stepper<'_, '_> {
    /// [`step`] with the switching of the contacts (module doc): the step is retaken from its
    /// start with the contact states the converged step calls for, until none changes.
    pub(super) fn switching_step(&mut self, t1: f64, h: f64) -> Result<(), FemError> {
        let start = self.st.clone();
        let mut tried: Vec<[Contact; 6]> = vec![contacts(self.star)];
        for _ in 0..MAX_ROUNDS {
            step(self.motion, self.star, self.ga, self.st, self.ws, self.stats, t1, h)?;
            let change = changes(
                self.motion,
                self.star,
                (&start, self.st),
                t1,
                stuck_in(&tried),
                stuck_in(&tried[..1]),
            )?;
            if change.is_empty() {
                return Ok(());
            }
            for &(which, c) in &change {
                set(self.star, which, c);
            }
            let now = contacts(self.star);
            if tried.contains(&now) {
                return Err(unresolved(change[0].0, t1, h));
            }
            tried.push(now);
            self.st.clone_from(&start);
        }
        Err(FemError::StickSlip {
            t: t1,
            contact: "a sleeve or slider".into(),
            reason: format!("more than {MAX_ROUNDS} stick-slip switches in one step of {h:.3e} s"),
        })
    }
}

/// The error of a step whose contacts return to states they had in it.
fn unresolved(which: Which, t: f64, h: f64) -> FemError {
    FemError::StickSlip {
        t,
        contact: which.name(),
        reason: format!("the step of {h:.3e} s finds it neither stuck nor slipping consistently: reduce fem.dt"),
    }
}

/// The consistent start with friction: the contacts at rest stuck, the rest slipping
/// ([`StarFriction::start`]); the initial accelerations and multipliers corrected for the
/// friction forces (which depend on the multipliers, [`correct_start`]), and a stuck contact
/// that cannot hold released in the direction it is pulled, the start then solved again.
pub(super) fn friction_start(motion: &Motion, star: &mut Star, q: Vec<f64>, v: Vec<f64>) -> Result<State, FemError> {
    let mut tried: Vec<[Contact; 6]> = vec![contacts(star)];
    for _ in 0..MAX_ROUNDS {
        let mut st = initial_state(motion, star, q.clone(), v.clone())?;
        if slipping_on_a_load(star) {
            correct_start(motion, star, &mut st)?;
        }
        let change = changes(motion, star, (&st, &st), 0.0, stuck_in(&tried), stuck_in(&tried[..1]))?;
        if change.is_empty() {
            return Ok(st);
        }
        for &(which, c) in &change {
            set(star, which, c);
        }
        let now = contacts(star);
        if tried.contains(&now) {
            return Err(FemError::StickSlip {
                t: 0.0,
                contact: change[0].0.name(),
                reason: "the start is neither stuck nor slipping consistently".into(),
            });
        }
        tried.push(now);
    }
    Err(FemError::StickSlip {
        t: 0.0,
        contact: "a sleeve or slider".into(),
        reason: "the start's stick-slip states do not settle".into(),
    })
}

/// Whether a sleeve slips with a Coulomb term, whose force depends on the multipliers (the
/// only friction force [`initial_state`]'s linear solve does not take exactly).
fn slipping_on_a_load(star: &Star) -> bool {
    star.friction
        .as_ref()
        .is_some_and(|f| (0..3).any(|i| matches!(f.sleeves[i], Contact::Slip(_)) && f.law.sleeve(i).mu > 0.0))
}

/// Newton corrections of the consistent start for the friction forces: the accelerations'
/// equations `M q_dd + Phi_q^T lambda + F_f(lambda) = -f` are linear in `(q_dd, lambda)` but for
/// the load's sign, so [`initial_state`]'s solve (linearised about `lambda = 0`) is corrected
/// with the imbalance at its own result (the constraint rows, linear, already hold).
fn correct_start(motion: &Motion, star: &mut Star, st: &mut State) -> Result<(), FemError> {
    let (n_dof, n_sys) = (star.n_dof, star.n_sys);
    let mut res = vec![0.0; n_sys];
    for _ in 0..4 {
        let sl = motion.slider_rows(star, &st.pins, 0.0, 0.0, 0.0)?;
        star.assemble(
            Iterate {
                q: &st.q,
                v: &st.v,
                qdd: &st.qdd,
                lam: &st.lam,
                pins: &st.pins,
                sliders: sl.as_ref(),
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
        star.factor(0.0)?;
        let mut dx: Vec<f64> = res[..n_dof]
            .iter()
            .map(|r| -r)
            .chain(std::iter::repeat_n(0.0, n_sys - n_dof))
            .collect();
        star.solve(&mut dx);
        for k in 0..n_dof {
            st.qdd[k] += dx[k];
        }
        for k in 0..n_sys - n_dof {
            st.lam[k] += dx[n_dof + k];
        }
        st.a.clone_from(&st.qdd);
        if let Motion::Driven { .. } = motion {
            st.pins = star.pins_of(&st.q, &st.v, &st.qdd);
        }
    }
    Ok(())
}

/// Dissipation and time stuck of the friction since t = 0 (trapezoidal rule on the steps,
/// [`FrictionTally`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FrictionLog {
    pub tally: FrictionTally,
}

impl FrictionLog {
    /// The dissipated powers [W] at the state `st`: `sum F_fi v_si` of the sleeves (Eq. F7),
    /// and of the rails `(Fc sign(s') + b s') s'` (zero for a stuck slider).
    fn powers(star: &Star, st: &State) -> [f64; 2] {
        let Some(fr) = &star.friction else {
            return [0.0; 2];
        };
        let sleeves = (0..3)
            .map(|i| {
                let v = st.v[star.xi(i, 0)];
                match fr.sleeves[i] {
                    Contact::Free | Contact::Stuck(_) => 0.0,
                    Contact::Slip(_) => star.sleeve_friction_force(i, &st.q, &st.lam, &st.pins) * v,
                }
            })
            .sum();
        let rails = (0..3)
            .map(|i| {
                let v = st.pins.s[i][1];
                let law = fr.law.rail(i);
                match (star.direct, fr.rails[i]) {
                    (false, _) => star.rail_force(i, v) * v,
                    (true, Contact::Slip(s)) => (law.fc * s + law.b * v) * v,
                    (true, _) => 0.0,
                }
            })
            .sum();
        [sleeves, rails]
    }

    pub(super) fn start(star: &Star, st: &State) -> Self {
        FrictionLog {
            tally: FrictionTally::start(Self::powers(star, st)),
        }
    }

    /// One step of length `h` [s] ending in the state `st`.
    pub(super) fn advance(&mut self, star: &Star, st: &State, h: f64) {
        if let Some(fr) = &star.friction {
            self.tally.advance(Self::powers(star, st), &fr.sleeves, &fr.rails, h);
        }
    }
}

impl Star {
    /// The rail friction force on slider i moving at `v` [m/s], against the motion (Eq. F4):
    /// `Fc sign(v) + b v` [N] (0 at rest: a prescribed slider at rest is held by its actuator
    /// alone, `docs/friction.md` 8.4); 0 without friction.
    pub fn rail_force(&self, i: usize, v: f64) -> f64 {
        let Some(fr) = &self.friction else {
            return 0.0;
        };
        let law = fr.law.rail(i);
        let sign = if v == 0.0 { 0.0 } else { v.signum() };
        law.fc * sign + law.b * v
    }
}
