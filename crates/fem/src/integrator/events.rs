//! Stick and slip events located within the step (`docs/friction.md` 9.5, Eq. F24), the FEM's
//! side: a prescribed motion with friction in the sleeves. The step is taken with the contacts
//! it starts with; if the judging of `docs/friction.md` 8.2 calls for a switch, the event is
//! located by linear interpolation between the step's ends (Eq. F24: a sliding velocity's zero,
//! or a stuck force reaching its limit), the step is retaken to the event, the contacts due
//! there switch (a sleeve that stops sticks at its coordinate there) and the rest of the step
//! follows with the new contacts, judged again. Unlike the AMM the FEM takes no restart at the
//! event (Eqs. F25-F26): the consistent accelerations of its fine mesh after a point force's
//! jump carry its highest element modes, which a restart fed into the next steps until a run
//! failed, while without it the located events converge as well (9.5). After [`MAX_SPLITS`]
//! events in one step, and in the direct problem (whose sliders can stick on their rails), the
//! step falls back to the switch at its start (`switching_step`).

use super::friction::{changes, freeze, set};
use super::*;
use crate::star::Contact;
use flexstar_model::friction_events::{crossing, first_event};
use flexstar_model::friction_run::Which;

/// Events located in one step before the rest of the step falls back to the switch at its start.
const MAX_SPLITS: usize = 6;

/// What locating an event reads at the start of a step: each sleeve's sliding velocity
/// `xi_ic'` [m/s] and, stuck, its force's excess over its limit `|F_t| - mu_static L` [N].
struct Probe {
    speed: [f64; 3],
    excess: [f64; 3],
}

impl Probe {
    fn of(star: &Star, st: &State) -> Self {
        Probe {
            speed: [0, 1, 2].map(|i| st.v[star.xi(i, 0)]),
            excess: stick_excess(star, st),
        }
    }

    /// Eq. F24: the fraction of the step at which the first of the contact changes `change`
    /// falls (linear between this probe and the state `end`), and which of them fall there.
    fn first_event(
        &self,
        star: &Star,
        end: &State,
        change: &[(Which, Contact)],
        h: f64,
    ) -> (f64, Vec<(Which, Contact)>) {
        let at_end = stick_excess(star, end);
        let fraction = |&(which, c): &(Which, Contact)| -> f64 {
            let Which::Sleeve(i) = which else {
                return 0.0;
            };
            match c {
                Contact::Stuck(_) => crossing(self.speed[i], end.v[star.xi(i, 0)]),
                _ => crossing(-self.excess[i], -at_end[i]),
            }
        };
        let times: Vec<f64> = change.iter().map(fraction).collect();
        first_event(change, &times, h)
    }
}

/// Each stuck sleeve's excess of the force its stick needs over its limit, `|F_t| -
/// mu_static L` [N] (Eq. F6) at the state `st`; `-inf` for a sleeve not stuck.
fn stick_excess(star: &Star, st: &State) -> [f64; 3] {
    let Some(fr) = &star.friction else {
        return [f64::NEG_INFINITY; 3];
    };
    std::array::from_fn(|i| match fr.sleeves[i] {
        Contact::Stuck(_) => {
            let need = star.sleeve_friction_force(i, &st.q, &st.lam, &st.pins);
            let (load, _) = star.sleeve_load(i, &st.q, &st.lam, fr.law.model);
            need.abs() - fr.law.sleeve(i).mu_static * load
        }
        _ => f64::NEG_INFINITY,
    })
}

/// Which contacts are stuck now (sleeves, then rails).
fn stuck_now(star: &Star) -> [bool; 6] {
    let Some(fr) = &star.friction else {
        return [false; 6];
    };
    std::array::from_fn(|k| if k < 3 { fr.sleeves[k] } else { fr.rails[k - 3] }.stuck().is_some())
}

impl Stepper<'_, '_> {
    /// The step of length `h` to `t1` [s] with the events in it located (module doc).
    pub(super) fn event_step(&mut self, t1: f64, h: f64) -> Result<(), FemError> {
        if !matches!(self.motion, Motion::Prescribed(_)) {
            return self.switching_step(t1, h);
        }
        // the part of the step left: (start, length), the whole step first (its h exactly, so
        // that a run with no event takes the steps of 8.2 bit for bit)
        let (mut t0, mut hs) = (t1 - h, h);
        for _ in 0..MAX_SPLITS {
            let start = self.st.clone();
            let probe = Probe::of(self.star, &start);
            let stuck = stuck_now(self.star);
            step(self.motion, self.star, self.ga, self.st, self.ws, self.stats, t1, hs)?;
            let change = changes(self.motion, self.star, (&start, self.st), t1, stuck, stuck)?;
            if change.is_empty() {
                return Ok(());
            }
            let (theta, due) = probe.first_event(self.star, self.st, &change, hs);
            let tm = if theta >= 1.0 {
                t1
            } else {
                self.st.clone_from(&start);
                if theta > 0.0 {
                    let tm = t0 + theta * hs;
                    step(
                        self.motion,
                        self.star,
                        self.ga,
                        self.st,
                        self.ws,
                        self.stats,
                        tm,
                        theta * hs,
                    )?;
                    tm
                } else {
                    t0
                }
            };
            self.switch_at_event(&due);
            if theta >= 1.0 {
                return Ok(());
            }
            (t0, hs) = (tm, t1 - tm);
        }
        // the rest of the step: the switch at its start (docs/friction.md 8.2)
        self.switching_step(t1, hs)
    }

    /// The contacts `due` switch in the current state (a sleeve that stops sticks at its
    /// material coordinate there, frozen at rest, Eq. F9); the method goes on from this state
    /// (the FEM takes no restart, module doc).
    fn switch_at_event(&mut self, due: &[(Which, Contact)]) {
        for &(which, c) in due {
            let c = match (which, c) {
                (Which::Sleeve(i), Contact::Stuck(_)) => Contact::Stuck(self.st.q[self.star.xi(i, 0)]),
                _ => c,
            };
            set(self.star, which, c);
        }
        let st = &mut *self.st;
        freeze(self.star, &mut st.q, &mut st.v, &mut st.qdd);
        for (k, _) in self.star.stuck_coordinates() {
            st.a[k] = 0.0;
        }
    }
}
