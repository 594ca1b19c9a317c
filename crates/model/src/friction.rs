//! `[friction]`: Coulomb, viscous and Stribeck friction in the sleeves and Coulomb and viscous
//! friction on the rails (`docs/friction.md`, Eqs. F1-F7).
//!
//! ```toml
//! [friction]
//! mu = 0.1               # Coulomb coefficient of the beam sliding through the sleeve
//! c = 0.5                # N s/m, viscous, on the sliding speed
//! mu_static = 0.15       # stick limit (default: mu); with v_stribeck, the Stribeck term
//! v_stribeck = 0.005     # m/s: mu_k(v) = mu + (mu_static - mu) exp(-(v / v_stribeck)^2)
//! model = "normal"       # the sleeve's load: |N| ("normal") or its two edges' ("edges", Eq. F3)
//! [friction.rails]
//! Fc = 2.0               # N, Coulomb force of slider i on its rail
//! b = 1.0                # N s/m, viscous
//! ```
//! Every coefficient is one number (all three sleeves or sliders) or a list of three (sleeves or
//! sliders 1, 2, 3), as the beam keys of `[robot]` ([`PerBeam`]). A section whose coefficients
//! are all zero is no friction: the run is the frictionless one ([`Friction::is_none`]).

use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::robot_section::PerBeam;

/// The load that bounds a sleeve's friction (`docs/friction.md` 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NormalLoad {
    /// `|N_i|`, the resultant of the sleeve's transverse forces (Eq. F2's `N`).
    #[default]
    Normal,
    /// The sum of the two edges' loads, `|N/2 + M/Lp| + |N/2 - M/Lp| = max(|N|, 2 |M| / Lp)` (Eq. F3).
    Edges,
}

/// `[friction.rails]`: the sliders on their rails (`docs/friction.md` 1, Eq. F4).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RailFriction {
    /// Coulomb force `Fc_i` [N].
    #[serde(rename = "Fc")]
    pub fc: PerBeam,
    /// Viscous coefficient `b_i` [N s/m].
    pub b: PerBeam,
}

/// `[friction]` (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Friction {
    /// Kinetic Coulomb coefficient `mu_i` of each sleeve.
    pub mu: PerBeam,
    /// Viscous coefficient `c_i` [N s/m] of each sleeve.
    pub c: PerBeam,
    /// Static coefficient: a stuck sleeve holds while its friction stays within `mu_static L`;
    /// default `mu`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu_static: Option<PerBeam>,
    /// Stribeck speed [m/s]; none: `mu_k = mu` at every speed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v_stribeck: Option<PerBeam>,
    /// Which load bounds the friction.
    pub model: NormalLoad,
    /// The sliders on their rails; none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rails: Option<RailFriction>,
}

/// The friction law of one sleeve (`docs/friction.md` 3, Eqs. F5-F6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SleeveLaw {
    pub mu: f64,
    /// [N s/m]
    pub c: f64,
    pub mu_static: f64,
    /// [m/s]
    pub v_stribeck: Option<f64>,
}

impl SleeveLaw {
    /// The kinetic coefficient at the sliding speed `v` [m/s] (Eq. F5):
    /// `mu + (mu_static - mu) exp(-(v / v_stribeck)^2)`, or `mu` without a Stribeck speed.
    pub fn kinetic(&self, v: f64) -> f64 {
        match self.v_stribeck {
            Some(vs) => self.mu + (self.mu_static - self.mu) * (-(v / vs).powi(2)).exp(),
            None => self.mu,
        }
    }

    /// `d mu_k / d v` [s/m] at `v` (for the Newton matrix).
    pub fn kinetic_slope(&self, v: f64) -> f64 {
        match self.v_stribeck {
            Some(vs) => -2.0 * v / (vs * vs) * (self.mu_static - self.mu) * (-(v / vs).powi(2)).exp(),
            None => 0.0,
        }
    }

    /// The slipping friction force [N] at the speed `v` [m/s] under the load `load` [N] in the
    /// direction `sign` (+-1, that of `v`): `mu_k(v) load sign + c v` (Eq. F5).
    pub fn slip_force(&self, v: f64, load: f64, sign: f64) -> f64 {
        self.kinetic(v) * load * sign + self.c * v
    }
}

/// The friction law of one slider on its rail (Eq. F4): `Fc sign(v) + b v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RailLaw {
    /// [N]
    pub fc: f64,
    /// [N s/m]
    pub b: f64,
}

impl Friction {
    /// No friction at all: every coefficient zero (the section may be absent or written so).
    pub fn is_none(&self) -> bool {
        !self.sleeves_rub() && !self.rails_rub()
    }

    /// Whether a sleeve has a non-zero coefficient.
    pub fn sleeves_rub(&self) -> bool {
        let nonzero = |p: &PerBeam| p.0.iter().any(|v| *v != 0.0);
        nonzero(&self.mu) || nonzero(&self.c) || self.mu_static.as_ref().is_some_and(nonzero)
    }

    /// Whether a slider has a non-zero coefficient.
    pub fn rails_rub(&self) -> bool {
        self.rails
            .is_some_and(|r| r.fc.0.iter().chain(&r.b.0).any(|v| *v != 0.0))
    }

    /// The law of sleeve i (0-based).
    pub fn sleeve(&self, i: usize) -> SleeveLaw {
        SleeveLaw {
            mu: self.mu.0[i],
            c: self.c.0[i],
            mu_static: self.mu_static.map_or(self.mu.0[i], |m| m.0[i]),
            v_stribeck: self.v_stribeck.map(|v| v.0[i]),
        }
    }

    /// The law of slider i (0-based); zero without `[friction.rails]`.
    pub fn rail(&self, i: usize) -> RailLaw {
        let r = self.rails.unwrap_or_default();
        RailLaw {
            fc: r.fc.0[i],
            b: r.b.0[i],
        }
    }

    /// Check the coefficients (keys `friction.<name>`, `friction.<name>[k]` for one of a list).
    pub fn validate(&self) -> Result<(), ModelError> {
        let mut keys = vec![("mu", self.mu), ("c", self.c)];
        keys.extend(self.mu_static.map(|m| ("mu_static", m)));
        keys.extend(self.v_stribeck.map(|v| ("v_stribeck", v)));
        if let Some(r) = self.rails {
            keys.extend([("rails.Fc", r.fc), ("rails.b", r.b)]);
        }
        for (name, v) in keys {
            for k in 0..3 {
                if !(v.0[k].is_finite() && v.0[k] >= 0.0) {
                    return Err(ModelError::invalid(
                        key_of(name, &v, k),
                        format!("need a finite, non-negative coefficient, got {}", v.0[k]),
                    ));
                }
            }
        }
        if let Some(ms) = self.mu_static {
            if let Some(k) = (0..3).find(|&k| ms.0[k] < self.mu.0[k]) {
                return Err(ModelError::invalid(
                    key_of("mu_static", &ms, k),
                    format!(
                        "the static coefficient {} is below the kinetic mu = {} (sleeve {}): need mu_static >= mu",
                        ms.0[k],
                        self.mu.0[k],
                        k + 1
                    ),
                ));
            }
        }
        if let Some(vs) = self.v_stribeck {
            if let Some(k) = (0..3).find(|&k| vs.0[k] <= 0.0) {
                return Err(ModelError::invalid(
                    key_of("v_stribeck", &vs, k),
                    format!("the Stribeck speed must be positive (m/s), got {}", vs.0[k]),
                ));
            }
        }
        Ok(())
    }
}

/// The refusal of friction by a command or solver `by` that does not model it yet (key
/// `friction`, `docs/friction.md` 6).
pub fn unsupported(by: &str) -> ModelError {
    ModelError::invalid(
        "friction",
        format!(
            "{by} does not model friction yet (docs/friction.md 6: the FEM's run and direct run do); \
             remove [friction] or run --solver fem"
        ),
    )
}

/// What friction did over a run (the sidecar's `friction`, `docs/friction.md` 7).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct FrictionSummary {
    /// Time each sleeve spent stuck [s] (the output steps at which it was stuck, by the
    /// trapezoidal rule on the integration steps).
    pub stuck_s: [f64; 3],
    /// Time each slider spent stuck on its rail [s] (direct problem; 0 with a prescribed motion).
    pub rails_stuck_s: [f64; 3],
    /// Energy dissipated by the sleeves' friction since t = 0 [J].
    pub sleeves_dissipated_j: f64,
    /// Energy dissipated by the rails' friction since t = 0 [J].
    pub rails_dissipated_j: f64,
}

/// `friction.<name>`, or `friction.<name>[k + 1]` when the three values differ.
fn key_of(name: &str, v: &PerBeam, k: usize) -> String {
    let equal = v.0[1].to_bits() == v.0[0].to_bits() && v.0[2].to_bits() == v.0[0].to_bits();
    if equal {
        format!("friction.{name}")
    } else {
        format!("friction.{name}[{}]", k + 1)
    }
}

#[cfg(test)]
mod tests {
    use crate::Experiment;
    use std::path::Path;

    fn load(extra: &str) -> Result<Experiment, String> {
        crate::attachments::tests::load(extra, Path::new("f.toml"))
    }

    #[test]
    fn friction_reads_per_sleeve_and_defaults_to_none() {
        assert!(load("").unwrap().friction.is_none());
        let e = load("[friction]\nmu = [0.1, 0.2, 0.3]\nmu_static = 0.35\nv_stribeck = 0.01\nmodel = \"edges\"\n[friction.rails]\nFc = 2.0\n")
            .unwrap();
        let f = e.friction.unwrap();
        assert_eq!(f.sleeve(1).mu, 0.2);
        assert_eq!(f.sleeve(2).mu_static, 0.35);
        assert_eq!(f.model, super::NormalLoad::Edges);
        assert_eq!(f.rail(0).fc, 2.0);
        assert_eq!(f.rail(2).b, 0.0);
        // Stribeck: mu_static at rest, mu far above v_stribeck
        assert_eq!(f.sleeve(0).kinetic(0.0), 0.35);
        assert!((f.sleeve(0).kinetic(1.0) - 0.1).abs() < 1e-12);
        // without v_stribeck the kinetic coefficient is mu, the static one the stick limit
        let g = load("[friction]\nmu = 0.1\nmu_static = 0.2\n")
            .unwrap()
            .friction
            .unwrap();
        assert_eq!((g.sleeve(0).kinetic(0.0), g.sleeve(0).mu_static), (0.1, 0.2));
        // all zero: no friction, and the problem carries none
        let z = load("[friction]\nmu = 0.0\n[friction.rails]\nFc = 0.0\n").unwrap();
        assert!(z.friction.unwrap().is_none() && z.problem().unwrap().friction().is_none());
    }

    #[test]
    fn friction_is_written_back_only_when_present() {
        let plain = load("").unwrap();
        assert!(!toml::to_string(&plain).unwrap().contains("friction"));
        let e = load("[friction]\nmu = [0.1, 0.2, 0.3]\nc = 0.5\n[friction.rails]\nFc = 2.0\n").unwrap();
        let text = toml::to_string(&e).unwrap();
        let again = Experiment::from_toml_str(&text, Path::new("again.toml")).unwrap();
        assert_eq!(again.friction, e.friction, "{text}");
    }

    #[test]
    fn bad_friction_names_file_and_key() {
        for (extra, key, why) in [
            ("[friction]\nmu = -0.1", "friction.mu", "non-negative"),
            ("[friction]\nmu = [0.1, nan, 0.1]", "friction.mu[2]", "finite"),
            ("[friction]\nc = inf", "friction.c", "finite"),
            (
                "[friction]\nmu = 0.2\nmu_static = 0.1",
                "friction.mu_static",
                "mu_static >= mu",
            ),
            (
                "[friction]\nmu = 0.2\nmu_static = [0.3, 0.1, 0.3]",
                "friction.mu_static[2]",
                "sleeve 2",
            ),
            (
                "[friction]\nmu = 0.1\nv_stribeck = 0.0",
                "friction.v_stribeck",
                "positive",
            ),
            ("[friction]\nmodel = \"rim\"", "model", "rim"),
            ("[friction]\nmu = [0.1, 0.2]", "mu", "three"),
            ("[friction]\nnu = 0.1", "nu", "unknown"),
            ("[friction.rails]\nFc = -1.0", "friction.rails.Fc", "non-negative"),
            ("[friction.rails]\nfc = 1.0", "fc", "unknown"),
        ] {
            let e = load(extra).unwrap_err();
            assert!(
                e.contains("f.toml") && e.contains(key) && e.contains(why),
                "{extra}: {e}"
            );
        }
    }
}
