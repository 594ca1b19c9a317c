//! What both solvers share when they run with friction (`docs/friction.md` 3, 7, 8.2 and 9):
//! the state of a contact, the stick test of Eq. F6, the output columns `Ff1..3`, `vs1..3`,
//! `stick1..3`, `E_f` and the sidecar's summary ([`FrictionSummary`]) with its tally of the
//! dissipation and the time stuck.

use crate::friction::FrictionSummary;

/// The state of one frictional contact (a sleeve on its beam, a slider on its rail).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// No friction coefficient: frictionless.
    Free,
    /// Stuck at the coordinate [m] (the sleeve's material coordinate on its beam, the slider's
    /// position on its rail).
    Stuck(f64),
    /// Slipping in the direction `+1` or `-1` (of the sliding velocity); also a contact with
    /// only viscous friction (it never sticks), whose sign is then unused.
    Slip(f64),
}

impl Contact {
    /// The coordinate it is stuck at [m], if stuck.
    pub fn stuck(&self) -> Option<f64> {
        match self {
            Contact::Stuck(at) => Some(*at),
            _ => None,
        }
    }

    /// The contact at the start of a run (`docs/friction.md` 8.2): one with a Coulomb limit
    /// (`coulomb`) stuck at `x` [m] when at rest (`|v| <=` [`V_REST`]), slipping along its
    /// velocity `v` [m/s] otherwise; one with only viscous friction slips; one with neither is free.
    pub fn start(coulomb: bool, viscous: bool, x: f64, v: f64) -> Self {
        match (coulomb, viscous) {
            (false, false) => Contact::Free,
            (false, true) => Contact::Slip(1.0),
            (true, _) if v.abs() <= V_REST => Contact::Stuck(x),
            _ => Contact::Slip(v.signum()),
        }
    }
}

/// A contact moving slower than this [m/s] at the start is at rest (sticks if it can).
pub const V_REST: f64 = 1e-12;

/// A stuck contact breaks loose when the force it needs exceeds its limit `F_lim` by more than
/// Rounds of switching allowed in one step of either solver (each retakes the step with the new
/// contact states): a contact switches at most once in a step, so six contacts need at most 7
/// rounds; beyond, the event is unresolved (`docs/friction.md` 3).
pub const MAX_ROUNDS: usize = 7;

/// One contact that can stick: sleeve i or slider i on its rail (0-based).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Which {
    Sleeve(usize),
    Rail(usize),
}

impl Which {
    /// The contact as messages name it: `sleeve 2`, `slider 3 on its rail` (1-based).
    pub fn name(&self) -> String {
        match self {
            Which::Sleeve(i) => format!("sleeve {}", i + 1),
            Which::Rail(i) => format!("slider {} on its rail", i + 1),
        }
    }
}

/// `FORCE_TOL (1 + F_lim / 1 N)` [N]: the resolution of the multipliers (at rest with no load
/// both the limit and the force the stick needs are zero to that level).
pub const FORCE_TOL: f64 = 1e-6;

/// Whether the force `need` [N] a stuck contact needs exceeds its limit `limit` [N] beyond
/// [`FORCE_TOL`] (Eq. F6; `Fc` on a rail).
pub fn exceeds(need: f64, limit: f64) -> bool {
    need.abs() > limit + FORCE_TOL * (1.0 + limit)
}

/// The sleeves' friction at one output time (`docs/friction.md` 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionSample {
    /// Friction force of sleeve i on beam i along its tangent [N] (stuck: the force the stick needs).
    pub ff: [f64; 3],
    /// Sliding speed of sleeve i along beam i [m/s] (Eq. F1, > 0: towards the tip).
    pub vs: [f64; 3],
    /// Whether sleeve i is stuck.
    pub stuck: [bool; 3],
    /// Energy dissipated by the friction of the sleeves and rails since t = 0 [J].
    pub e_f: f64,
}

/// The friction columns of a run, after all its others (`docs/friction.md` 7): `Ff1..3` [N],
/// `vs1..3` [m/s], `stick1..3` (1 stuck, 0 slipping), `E_f` [J], one value per sample.
pub fn friction_columns(rows: &[FrictionSample]) -> Vec<(String, Vec<f64>)> {
    let mut cols = Vec::new();
    for (name, value) in [
        (
            "Ff",
            (|f: &FrictionSample, i: usize| f.ff[i]) as fn(&FrictionSample, usize) -> f64,
        ),
        ("vs", |f, i| f.vs[i]),
        ("stick", |f, i| if f.stuck[i] { 1.0 } else { 0.0 }),
    ] {
        for i in 0..3 {
            cols.push((format!("{name}{}", i + 1), rows.iter().map(|f| value(f, i)).collect()));
        }
    }
    cols.push(("E_f".to_string(), rows.iter().map(|f| f.e_f).collect()));
    cols
}

/// Dissipation and time stuck of the friction since t = 0 (trapezoidal rule on the steps): the
/// sidecar's [`FrictionSummary`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrictionTally {
    /// Energy dissipated by the sleeves' friction [J].
    pub sleeves_j: f64,
    /// Energy dissipated by the rails' friction [J].
    pub rails_j: f64,
    /// Time each sleeve was stuck [s] (a step counts when it ends stuck).
    pub sleeves_stuck_s: [f64; 3],
    /// Time each slider was stuck on its rail [s].
    pub rails_stuck_s: [f64; 3],
    /// The dissipated powers `[sleeves, rails]` [W] at the end of the last step.
    powers: [f64; 2],
}

impl FrictionTally {
    /// The tally at t = 0, with the powers `[sleeves, rails]` [W] there.
    pub fn start(powers: [f64; 2]) -> Self {
        FrictionTally {
            powers,
            ..Self::default()
        }
    }

    /// One step of length `h` [s] ending with the dissipated powers `powers` [W] (Eq. F7) and
    /// the contacts `sleeves`, `rails`.
    pub fn advance(&mut self, powers: [f64; 2], sleeves: &[Contact; 3], rails: &[Contact; 3], h: f64) {
        self.sleeves_j += 0.5 * h * (self.powers[0] + powers[0]);
        self.rails_j += 0.5 * h * (self.powers[1] + powers[1]);
        self.powers = powers;
        for i in 0..3 {
            if sleeves[i].stuck().is_some() {
                self.sleeves_stuck_s[i] += h;
            }
            if rails[i].stuck().is_some() {
                self.rails_stuck_s[i] += h;
            }
        }
    }

    /// The energy dissipated so far by the sleeves and the rails [J] (the column `E_f`).
    pub fn dissipated(&self) -> f64 {
        self.sleeves_j + self.rails_j
    }

    /// The sidecar's summary.
    pub fn summary(&self) -> FrictionSummary {
        FrictionSummary {
            stuck_s: self.sleeves_stuck_s,
            rails_stuck_s: self.rails_stuck_s,
            sleeves_dissipated_j: self.sleeves_j,
            rails_dissipated_j: self.rails_j,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tally_integrates_the_power_by_the_trapezoidal_rule() {
        // a power rising linearly from 0 to 2 W over 1 s dissipates 1 J by any step
        let mut t = FrictionTally::start([0.0, 0.0]);
        let free = [Contact::Free; 3];
        let stuck = [Contact::Stuck(0.0), Contact::Free, Contact::Slip(1.0)];
        for k in 1..=4 {
            t.advance([0.5 * k as f64, 0.25 * k as f64], &stuck, &free, 0.25);
        }
        assert!((t.sleeves_j - 1.0).abs() < 1e-15 && (t.rails_j - 0.5).abs() < 1e-15);
        assert_eq!(t.summary().stuck_s, [1.0, 0.0, 0.0]);
        assert_eq!(t.dissipated(), 1.5);
    }

    #[test]
    fn the_columns_are_named_and_ordered_as_documented() {
        let s = FrictionSample {
            ff: [1.0, 2.0, 3.0],
            vs: [4.0, 5.0, 6.0],
            stuck: [true, false, true],
            e_f: 7.0,
        };
        let cols = friction_columns(&[s]);
        let names: Vec<&str> = cols.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(
            names,
            ["Ff1", "Ff2", "Ff3", "vs1", "vs2", "vs3", "stick1", "stick2", "stick3", "E_f"]
        );
        let values: Vec<f64> = cols.iter().map(|c| c.1[0]).collect();
        assert_eq!(values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 1.0, 0.0, 1.0, 7.0]);
        assert!(Contact::start(true, false, 0.1, 0.0) == Contact::Stuck(0.1));
        assert!(Contact::start(true, true, 0.1, -1.0) == Contact::Slip(-1.0));
        assert!(exceeds(1.01, 1.0) && !exceeds(1.0 + 1e-7, 1.0));
    }
}
