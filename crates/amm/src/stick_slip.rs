//! Stick and slip in the AMM's time step (`docs/friction.md` 9.1; the rules of 8.2): the
//! contacts judged after a converged step and the step retaken with the states it calls for,
//! the rails of the direct problem, the dissipation and the friction's outputs. Only a run with
//! friction comes here.

use flexstar_kinematics::RigidState;
use flexstar_model::friction_run::{exceeds, friction_columns};
use flexstar_model::{Column, Contact, Friction, FrictionSample, FrictionTally, RailLaw, Response};

use crate::error::AmmError;
use crate::system::System;

pub(crate) use flexstar_model::friction_run::Which;
use flexstar_model::friction_run::MAX_ROUNDS;

/// The sliders on their rails in the direct problem (Eq. F17).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rails {
    pub(crate) law: [RailLaw; 3],
    pub(crate) contacts: [Contact; 3],
}

impl Rails {
    /// The rails of `law` at the sliders' start `s` [m], `sd` [m/s] (`Contact::start`).
    pub(crate) fn start(law: &Friction, s: [f64; 3], sd: [f64; 3]) -> Self {
        let law = [0, 1, 2].map(|i| law.rail(i));
        Rails {
            law,
            contacts: std::array::from_fn(|i| Contact::start(law[i].fc > 0.0, law[i].b > 0.0, s[i], sd[i])),
        }
    }

    /// The dissipated power of the rails [W] at the sliders' speeds `sd` [m/s] (Eq. F18).
    pub(crate) fn power(&self, sd: [f64; 3]) -> f64 {
        (0..3)
            .map(|i| match self.contacts[i] {
                Contact::Slip(s) => (self.law[i].fc * s + self.law[i].b * sd[i]) * sd[i],
                _ => 0.0,
            })
            .sum()
    }
}

/// The rail friction of a prescribed slider moving at `v` [m/s] (Eq. F4, `sign(0) = 0`: a
/// slider at rest is held by its actuator alone) [N].
pub(crate) fn rail_force(law: &RailLaw, v: f64) -> f64 {
    let sign = if v == 0.0 { 0.0 } else { v.signum() };
    law.fc * sign + law.b * v
}

/// What the judging of a converged step reads: each sleeve's material coordinate at the step's
/// start [m] and sliding speed at its end [m/s]; in the direct problem each slider's position
/// at the start [m], speed at the end [m/s] and the force a stuck one needs [N] (Eq. F17).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StepEnd {
    pub(crate) xi_start: [f64; 3],
    pub(crate) vs: [f64; 3],
    pub(crate) s_start: [f64; 3],
    pub(crate) sd: [f64; 3],
    pub(crate) rail_need: [f64; 3],
}

/// The contact states (sleeves, then rails; free rails in the inverse problem).
fn contacts(sys: &System, rails: Option<&Rails>) -> [Contact; 6] {
    let sleeves = sys.friction.as_ref().map_or([Contact::Free; 3], |f| f.contacts);
    let rails = rails.map_or([Contact::Free; 3], |r| r.contacts);
    std::array::from_fn(|k| if k < 3 { sleeves[k] } else { rails[k - 3] })
}

/// Set contact `which` to `c`.
fn set(sys: &mut System, rails: Option<&mut Rails>, which: Which, c: Contact) {
    match which {
        Which::Sleeve(i) => {
            if let Some(f) = sys.friction.as_mut() {
                f.contacts[i] = c;
            }
        }
        Which::Rail(i) => {
            if let Some(r) = rails {
                r.contacts[i] = c;
            }
        }
    }
}

/// The contact changes of one judging ([`changes`]): at most one per contact, held in place
/// (no allocation in the time loop).
pub(crate) struct Changes {
    list: [(Which, Contact); 6],
    len: usize,
}

impl Changes {
    fn new() -> Self {
        Changes {
            list: [(Which::Sleeve(0), Contact::Free); 6],
            len: 0,
        }
    }

    fn push(&mut self, change: (Which, Contact)) {
        self.list[self.len] = change;
        self.len += 1;
    }

    pub(crate) fn as_slice(&self) -> &[(Which, Contact)] {
        &self.list[..self.len]
    }
}

/// The contact changes a converged step calls for (`docs/friction.md` 8.2), each contact
/// switching at most once per step (`was_stuck`: stuck in any round of this step;
/// `at_start`: stuck when the step began):
/// - a slipping contact whose speed at the step's end is zero or reversed sticks where the step
///   started, unless it broke loose in this step;
/// - a contact stuck since the step began whose needed force exceeds `mu_static L` (sleeve,
///   Eq. F6 with the load of Eq. F13 at the step's multipliers) or `Fc` (rail) slips in the
///   direction of that force.
pub(crate) fn changes(
    sys: &System,
    rails: Option<&Rails>,
    end: &StepEnd,
    was_stuck: [bool; 6],
    at_start: [bool; 6],
) -> Changes {
    let mut out = Changes::new();
    if let Some(fr) = &sys.friction {
        for i in 0..3 {
            let law = fr.law.sleeve(i);
            match fr.contacts[i] {
                Contact::Slip(s) if law.mu_static > 0.0 && !was_stuck[i] && end.vs[i] * s <= 0.0 => {
                    out.push((Which::Sleeve(i), Contact::Stuck(end.xi_start[i])));
                }
                Contact::Stuck(_) if at_start[i] => {
                    let need = sys.lam[fr.stick[i]];
                    if exceeds(need, law.mu_static * fr.load_at(i, &sys.lam, need)) {
                        out.push((Which::Sleeve(i), Contact::Slip(need.signum())));
                    }
                }
                _ => {}
            }
        }
    }
    if let Some(r) = rails {
        for i in 0..3 {
            match r.contacts[i] {
                Contact::Slip(s) if r.law[i].fc > 0.0 && !was_stuck[3 + i] && end.sd[i] * s <= 0.0 => {
                    out.push((Which::Rail(i), Contact::Stuck(end.s_start[i])));
                }
                Contact::Stuck(_) if at_start[3 + i] && exceeds(end.rail_need[i], r.law[i].fc) => {
                    out.push((Which::Rail(i), Contact::Slip(end.rail_need[i].signum())));
                }
                _ => {}
            }
        }
    }
    out
}

/// Which contacts were stuck in any of the states `tried`.
fn stuck_in(tried: &[[Contact; 6]]) -> [bool; 6] {
    std::array::from_fn(|k| tried.iter().any(|c| c[k].stuck().is_some()))
}

/// One step with the switching of the contacts (module doc): `attempt(sys, rails, retake)`
/// solves the step with the current contacts (restoring the step's start first when `retake`)
/// and returns what the judging reads; the step is retaken until no contact changes. `t` [s],
/// `h` [s]: the step's end and length (for the error).
pub(crate) fn switching_step<F>(
    sys: &mut System,
    mut rails: Option<&mut Rails>,
    t: f64,
    h: f64,
    mut attempt: F,
) -> Result<StepEnd, AmmError>
where
    F: FnMut(&mut System, Option<&Rails>, bool) -> Result<StepEnd, AmmError>,
{
    // the contact states tried in this step, in order: the start's, then one per round
    // (`round + 1` of them in round `round`)
    let mut tried = [contacts(sys, rails.as_deref()); MAX_ROUNDS + 1];
    for round in 0..MAX_ROUNDS {
        let end = attempt(sys, rails.as_deref(), round > 0)?;
        let change = changes(
            sys,
            rails.as_deref(),
            &end,
            stuck_in(&tried[..round + 1]),
            stuck_in(&tried[..1]),
        );
        let change = change.as_slice();
        if change.is_empty() {
            return Ok(end);
        }
        for &(which, c) in change {
            set(sys, rails.as_deref_mut(), which, c);
        }
        let now = contacts(sys, rails.as_deref());
        if tried[..round + 1].contains(&now) {
            let reason = if h > 0.0 {
                format!("the step of {h:.3e} s finds it neither stuck nor slipping consistently: reduce amm.dt")
            } else {
                "the start is neither stuck nor slipping consistently".into()
            };
            return Err(AmmError::StickSlip {
                t,
                contact: change[0].0.name(),
                reason,
            });
        }
        tried[round + 1] = now;
    }
    Err(AmmError::StickSlip {
        t,
        contact: "a sleeve or slider".into(),
        reason: format!("more than {MAX_ROUNDS} stick-slip switches in one step of {h:.3e} s"),
    })
}

/// Whether a sleeve slips with a Coulomb term, whose force depends on the multipliers through
/// the signs of the load taken from the last solve (the consistent start repeats its solve so
/// that they are its own).
pub(crate) fn slipping_on_a_load(sys: &System) -> bool {
    sys.friction
        .as_ref()
        .is_some_and(|f| (0..3).any(|i| matches!(f.contacts[i], Contact::Slip(_)) && f.law.sleeve(i).mu > 0.0))
}

/// The friction's outputs of a run: the tally of the dissipation and the time stuck, and the
/// samples of the columns at the output times (`docs/friction.md` 7).
#[derive(Debug, Clone)]
pub(crate) struct FrictionOutput {
    tally: FrictionTally,
    samples: Vec<FrictionSample>,
}

/// The axial accelerations `u_i''` of `qdd` (`nb`, `nm`: the block size and the modes).
pub(crate) fn axial(qdd: &[f64], nb: usize, nm: usize) -> [f64; 3] {
    [0, 1, 2].map(|i| qdd[i * nb + nm])
}

/// The friction force on each beam along `e_xi` [N] at the end of the last solve (Eq. F14:
/// slipping; Eq. F16: stuck, the force the stick needs) with its accelerations `qdd`.
pub(crate) fn sleeve_forces(sys: &System, qdd: &[f64]) -> [f64; 3] {
    let udd = axial(qdd, sys.nb, sys.nm);
    [0, 1, 2].map(|i| sys.sleeve_friction_force(i, &sys.lam, udd[i], true))
}

impl FrictionOutput {
    /// The outputs of a run starting with the sleeves' forces `ff` [N] at the sliding speeds
    /// `vs` [m/s], the rails dissipating `rails_power` [W]; room for `rows` output samples.
    pub(crate) fn start(sys: &System, ff: [f64; 3], vs: [f64; 3], rails_power: f64, rows: usize) -> Self {
        FrictionOutput {
            tally: FrictionTally::start([sleeves_power(sys, ff, vs), rails_power]),
            samples: Vec::with_capacity(rows),
        }
    }

    /// One step of length `h` [s] ending with the sleeves' forces `ff` and speeds `vs` and the
    /// rails' contacts and power.
    pub(crate) fn advance(
        &mut self,
        sys: &System,
        (ff, vs): ([f64; 3], [f64; 3]),
        rails: (&[Contact; 3], f64),
        h: f64,
    ) {
        let sleeves = sys.friction.as_ref().map_or([Contact::Free; 3], |f| f.contacts);
        self.tally
            .advance([sleeves_power(sys, ff, vs), rails.1], &sleeves, rails.0, h);
    }

    /// The sample of an output time.
    pub(crate) fn sample(&mut self, sys: &System, ff: [f64; 3], vs: [f64; 3]) {
        let stuck = sys
            .friction
            .as_ref()
            .map_or([false; 3], |f| f.contacts.map(|c| c.stuck().is_some()));
        self.samples.push(FrictionSample {
            ff,
            vs,
            stuck,
            e_f: self.tally.dissipated(),
        });
    }

    /// The friction's columns after the response's others, and its summary.
    pub(crate) fn finish(self, resp: &mut Response) {
        for (name, values) in friction_columns(&self.samples) {
            resp.extra.push(Column { name, values });
        }
        resp.friction = Some(self.tally.summary());
    }
}

/// `sum F_fi v_si` over the slipping sleeves [W] (Eq. F18).
fn sleeves_power(sys: &System, ff: [f64; 3], vs: [f64; 3]) -> f64 {
    let Some(fr) = &sys.friction else {
        return 0.0;
    };
    (0..3)
        .map(|i| match fr.contacts[i] {
            Contact::Slip(_) => ff[i] * vs[i],
            _ => 0.0,
        })
        .sum()
}

/// The sleeves' material coordinates [m] at the rigid state `st` and coordinates `q`.
pub(crate) fn coordinates(sys: &System, st: &RigidState, q: &[f64]) -> [f64; 3] {
    [0, 1, 2].map(|i| sys.sliding_coordinate(i, st, q))
}

/// The sleeves' sliding speeds [m/s] at the rigid state `st` and rates `v`.
pub(crate) fn speeds(sys: &System, st: &RigidState, v: &[f64]) -> [f64; 3] {
    [0, 1, 2].map(|i| sys.sliding_speed(i, st, v))
}

#[cfg(test)]
mod tests {
    use flexstar_model::{LoadSettings, Payload, Trajectory};

    /// The energy balance with friction in the sleeves (`docs/friction.md` 4 and 9): the star
    /// held at the centre pose (sliders fixed, so the constraints do no work), paper model, a
    /// load at G from zero that slides the beams through their sleeves (its force along beam 1
    /// and a moment), Coulomb friction in both load models. The load's work is the change of
    /// kinetic and strain energy plus the friction's work on the sliding coordinates, to 1e-3
    /// of the work (`system::tests::energy_balance_of`, from the stored coordinates and
    /// multipliers, independent of the run's own tally); the friction must take a real part and
    /// the sleeves must both stick and slip.
    #[test]
    fn the_load_work_is_the_energy_and_the_friction_dissipation() {
        for model in ["normal", "edges"] {
            let mut exp = flexstar_model::catalogue::paper_case(3);
            exp.trajectory = Trajectory::Polynomial {
                s1: vec![0.0],
                s2: vec![0.0],
                s3: vec![0.0],
            };
            exp.time.t_end = 0.5;
            exp.payload = Payload {
                mass: 0.8,
                j: 3e-3,
                offset: [0.04, 0.02],
            };
            exp.load = LoadSettings::polynomials(
                Some(vec![0.0, 0.0, 400.0, -800.0]),
                Some(vec![0.0, 0.0, -60.0, 80.0]),
                Some(vec![0.0, 0.0, 8.0, -12.0]),
            );
            exp.friction = Some(toml::from_str(&format!("mu = 0.3\nmodel = \"{model}\"\n")).unwrap());
            let problem = exp.problem().unwrap();
            let settings = flexstar_model::AmmSettings::paper(flexstar_model::ModeFamily::FreeFree, 20);
            let star = crate::star::Star::new(&problem);
            let run = crate::solver::integrate(&star, &settings, 20, true, |_, _| {}).unwrap();
            let summary = run.friction.unwrap();
            let stuck = run.column("stick1").unwrap();
            let (work, dissipated, worst) = crate::system::tests::energy_balance_of(&problem, 1e-3);
            eprintln!(
                "{model}: work {work:.4e} J, dissipated {dissipated:.4e} J (the run's tally {:.4e} J), \
                 imbalance {:.2e} of the work, stuck {:?} s",
                summary.sleeves_dissipated_j,
                worst / work,
                summary.stuck_s
            );
            assert!(
                summary.sleeves_dissipated_j > 0.05 * work,
                "{model}: friction too small"
            );
            assert!(
                stuck.contains(&1.0) && stuck.contains(&0.0),
                "{model}: must stick and slip"
            );
        }
    }
}
