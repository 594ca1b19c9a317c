//! What flexstar adds to the paper's robot (`docs/amm.md` section 11, `docs/fem.md` section 9): a
//! payload welded at the junction G (`[payload]`), damping of the elastic motion (`[damping]`,
//! [`crate::damping`]) and an external load at G (`[load]`).
//!
//! ```toml
//! [payload]            # a rigid body welded at G (docs/amm.md 11.1, docs/fem.md 9.1)
//! mass = 0.5           # kg
//! J = 1e-3             # kg m^2, about its own centre of mass
//! offset = [0.01, 0.0] # m, its centre of mass from G in the star's frame (x along beam 1)
//!
//! [damping]            # Rayleigh: alpha M + beta K on the elastic motion (crate::damping)
//! beta = 8e-4          # s; or zeta = 0.01 (at f_hz, default the first mode), or zeta = [z1, z2]
//!
//! [load]               # force and moment at G in the fixed frame (Eqs. L1, L2)
//! file = "load.csv"    # header t,Fx,Fy,Mz (N, N, N m), linear in between
//! # or Fx = [...], Fy = [...], Mz = [...]  (coefficients of 1, t, t^2, ...; a missing one is 0)
//! ```
//! Every key defaults to zero (no payload, no damping, no load), which leaves every solver's
//! equations exactly as they were. Signs and frames: `docs/conventions.md`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use crate::damping::Damping;
use crate::drive_section::ForceSamples;
use crate::error::ModelError;

/// `[payload]`: a rigid body welded to the junction G (`docs/amm.md` 11.1, Eqs. P1-P9).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Payload {
    /// Mass m [kg].
    pub mass: f64,
    /// Rotational inertia J [kg m^2] about the payload's own centre of mass.
    #[serde(rename = "J")]
    pub j: f64,
    /// Offset `(ox, oy)` [m] of the centre of mass from G, in the star's rigid frame
    /// `(e_x1, e_w1)` (x along beam 1, y a quarter turn counter-clockwise from it).
    pub offset: [f64; 2],
}

impl Payload {
    /// No payload (mass and inertia zero): the solvers add nothing.
    pub fn is_none(&self) -> bool {
        self.mass == 0.0 && self.j == 0.0
    }

    /// Rotational inertia about G [kg m^2]: `J + m |offset|^2`.
    pub fn inertia_about_g(&self) -> f64 {
        self.j + self.mass * (self.offset[0].powi(2) + self.offset[1].powi(2))
    }

    /// Check the values (keys named `payload.<key>`).
    pub fn validate(&self) -> Result<(), ModelError> {
        for (key, v) in [("payload.mass", self.mass), ("payload.J", self.j)] {
            if !v.is_finite() || v < 0.0 {
                return Err(ModelError::invalid(
                    key,
                    format!("must be a finite number >= 0, got {v}"),
                ));
            }
        }
        if self.offset.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::invalid(
                "payload.offset",
                format!("must be two finite lengths [x, y] in m, got {:?}", self.offset),
            ));
        }
        Ok(())
    }
}

/// The columns of a load file after `t`.
pub const LOAD_COLUMNS: [&str; 3] = ["Fx", "Fy", "Mz"];

/// `[load]`: a force `(Fx, Fy)` [N] in the fixed frame and a moment `Mz` [N m] (counter-clockwise
/// positive) applied at G, functions of time: a table linearly interpolated, or polynomials in t.
/// A force at a tool point `G + t` is the same force at G plus the moment `t x F` (Eq. L3).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoadSettings {
    /// CSV file `t,Fx,Fy,Mz`, relative to the experiment file (exclusive with the polynomials).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// `Fx(t)` [N] as coefficients of 1, t, t^2, ... (t in s); missing: 0.
    #[serde(rename = "Fx", skip_serializing_if = "Option::is_none")]
    pub fx: Option<Vec<f64>>,
    /// `Fy(t)` [N].
    #[serde(rename = "Fy", skip_serializing_if = "Option::is_none")]
    pub fy: Option<Vec<f64>>,
    /// `Mz(t)` [N m].
    #[serde(rename = "Mz", skip_serializing_if = "Option::is_none")]
    pub mz: Option<Vec<f64>>,
    /// The load file as read at load time (not a TOML key).
    #[serde(skip)]
    pub samples: Option<ForceSamples>,
}

impl LoadSettings {
    /// A load given by polynomials (`None`: zero).
    pub fn polynomials(fx: Option<Vec<f64>>, fy: Option<Vec<f64>>, mz: Option<Vec<f64>>) -> Self {
        LoadSettings {
            fx,
            fy,
            mz,
            ..LoadSettings::default()
        }
    }

    /// No load at all (no file, no polynomial): the solvers add nothing.
    pub fn is_none(&self) -> bool {
        self.file.is_none() && self.fx.is_none() && self.fy.is_none() && self.mz.is_none()
    }

    /// `(Fx, Fy, Mz)` [N, N, N m] at time `t` [s]: the table linearly interpolated (held
    /// constant outside its span), or the polynomials.
    pub fn at(&self, t: f64) -> [f64; 3] {
        if let Some(s) = &self.samples {
            return s.at(t);
        }
        let horner = |c: &Option<Vec<f64>>| {
            c.as_ref()
                .map_or(0.0, |c| c.iter().rev().fold(0.0, |acc, c| acc * t + c))
        };
        [horner(&self.fx), horner(&self.fy), horner(&self.mz)]
    }

    /// The load file resolved against the experiment file `config`.
    pub fn file_path(&self, config: &Path) -> Option<PathBuf> {
        let f = self.file.as_ref()?;
        let dir = config.parent().unwrap_or_else(|| Path::new(""));
        Some(if f.is_absolute() { f.clone() } else { dir.join(f) })
    }

    /// Read the load file (relative to the experiment file `config`); a no-op without one.
    /// Errors name the experiment file, `load.file` and the load file.
    pub fn read_file(&mut self, config: &Path) -> Result<(), ModelError> {
        let Some(path) = self.file_path(config) else {
            return Ok(());
        };
        let samples = ForceSamples::read_columns(&path, "load.file", LOAD_COLUMNS, "load").map_err(|e| match e {
            ModelError::Invalid { key, reason, .. } => ModelError::Invalid {
                file: config.to_path_buf(),
                key,
                reason: format!("{}: {reason}", path.display()),
            },
            other => other,
        })?;
        self.samples = Some(samples);
        Ok(())
    }

    /// Check the keys and values (keys named `load.<key>`); a file must cover `[0, t_end]` [s].
    pub fn validate(&self, t_end: f64) -> Result<(), ModelError> {
        let polys = [("load.Fx", &self.fx), ("load.Fy", &self.fy), ("load.Mz", &self.mz)];
        if let Some(f) = &self.file {
            if let Some((key, _)) = polys.iter().find(|(_, p)| p.is_some()) {
                return Err(ModelError::invalid(
                    *key,
                    "give either file or the polynomials Fx, Fy, Mz, not both",
                ));
            }
            let Some(s) = &self.samples else {
                return Err(ModelError::invalid("load.file", "the load file was not read"));
            };
            return ForceSamples::check_covers(s.t[0], s.t[s.t.len() - 1], 0.0, t_end)
                .map_err(|r| ModelError::invalid("load.file", format!("{}: {r}", f.display())));
        }
        for (key, p) in polys {
            if let Some(p) = p.as_ref().filter(|p| p.is_empty() || p.iter().any(|c| !c.is_finite())) {
                return Err(ModelError::invalid(
                    key,
                    format!("need at least one finite coefficient (of 1, t, t^2, ...), got {p:?}"),
                ));
            }
        }
        Ok(())
    }
}

/// The payload, the load and gravity of an experiment together: what a rigid-body dynamics of
/// the star needs beyond [`crate::RobotParams`] (the damping does no work on a rigid motion).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Attachments {
    /// The payload welded at G.
    pub payload: Payload,
    /// The load at G.
    pub load: LoadSettings,
    /// Gravity in the plane (`docs/as-built.md` 5).
    pub gravity: crate::Gravity,
}

impl Attachments {
    /// The payload, load and gravity of an experiment.
    pub fn of(exp: &crate::Experiment) -> Self {
        Attachments {
            payload: exp.payload,
            load: exp.load.clone(),
            gravity: exp.gravity,
        }
    }

    /// Neither payload nor load nor gravity: the paper's bare star.
    pub fn is_none(&self) -> bool {
        self.payload.is_none() && self.load.is_none() && self.gravity.is_none()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::Experiment;
    use std::path::Path;

    const BASE: &str = r#"
name = "p"
[time]
t_end = 0.2
[trajectory]
kind = "polynomial"
s1 = [0.0, 0.0, 1.0]
s2 = [0.0]
s3 = [0.0, 0.0, 0.5]
"#;

    /// A small experiment with the sections `extra`, read as if from `config` (the model's tests
    /// of the optional sections share it).
    pub(crate) fn load(extra: &str, config: &Path) -> Result<Experiment, String> {
        Experiment::from_toml_str(&format!("{BASE}{extra}\n"), config).map_err(|e| e.to_string())
    }

    #[test]
    fn defaults_are_nothing_at_all() {
        let e = load("", Path::new("e.toml")).unwrap();
        assert!(e.payload.is_none() && e.load.is_none());
        assert!(e.damping.is_none());
        assert_eq!(e.load.at(0.1), [0.0; 3]);
    }

    #[test]
    fn sections_parse() {
        let e = load(
            "[payload]\nmass = 2.0\nJ = 0.01\noffset = [0.1, -0.2]\n[damping]\nzeta = 0.02\nf_hz = 4.0\n\
             [load]\nFx = [1.0, 2.0]\nMz = [0.0, 0.0, 3.0]",
            Path::new("e.toml"),
        )
        .unwrap();
        assert_eq!(
            (e.payload.mass, e.payload.j, e.payload.offset),
            (2.0, 0.01, [0.1, -0.2])
        );
        // J + m |o|^2 = 0.01 + 2 (0.01 + 0.04)
        assert!((e.payload.inertia_about_g() - 0.11).abs() < 1e-15);
        assert_eq!(e.load.at(0.5), [2.0, 0.0, 0.75]);
    }

    #[test]
    fn bad_sections_name_file_and_key() {
        for (extra, key) in [
            ("[payload]\nmass = -1.0", "payload.mass"),
            ("[payload]\nJ = nan", "payload.J"),
            ("[payload]\noffset = [0.0, inf]", "payload.offset"),
            ("[load]\nFx = []", "load.Fx"),
            ("[load]\nMz = [nan]", "load.Mz"),
        ] {
            let e = load(extra, Path::new("bad.toml")).unwrap_err();
            assert!(e.contains("bad.toml") && e.contains(key), "{extra}: {e}");
        }
        for (extra, key) in [("[payload]\nmas = 1.0", "mas"), ("[load]\nFz = [1.0]", "Fz")] {
            let e = load(extra, Path::new("bad.toml")).unwrap_err();
            assert!(e.contains("bad.toml") && e.contains(key), "{extra}: {e}");
        }
    }

    #[test]
    fn load_file_is_read_relative_to_the_config_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("exp.toml");
        let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
        write("ok.csv", "t,Fx,Fy,Mz\n0,1,2,3\n0.1,1,2,3\n0.2,3,4,5\n");
        write("nocol.csv", "t,Fx,Fy\n0,1,2\n0.2,1,2\n");
        write("decr.csv", "t,Fx,Fy,Mz\n0,1,2,3\n0.1,1,2,3\n0.05,1,2,3\n0.2,1,2,3\n");
        write("nan.csv", "t,Fx,Fy,Mz\n0,1,2,3\n0.1,nan,2,3\n0.2,1,2,3\n");
        write("short.csv", "t,Fx,Fy,Mz\n0,1,2,3\n0.15,1,2,3\n");
        let e = load("[load]\nfile = \"ok.csv\"", &config).unwrap();
        // linear between the samples at 0.1 and 0.2 s
        let f = e.load.at(0.15);
        assert!((f[0] - 2.0).abs() < 1e-12 && (f[2] - 4.0).abs() < 1e-12, "{f:?}");
        for (file, why) in [
            ("nocol.csv", "Mz"),
            ("decr.csv", "row 3"),
            ("nan.csv", "row 2"),
            ("short.csv", "span"),
            ("missing.csv", "cannot read"),
        ] {
            let e = load(&format!("[load]\nfile = \"{file}\""), &config).unwrap_err();
            assert!(
                e.contains("exp.toml") && e.contains("load.file") && e.contains(file) && e.contains(why),
                "{file}: {e}"
            );
        }
        let e = load("[load]\nfile = \"ok.csv\"\nFx = [1.0]", &config).unwrap_err();
        assert!(e.contains("load.Fx") && e.contains("not both"), "{e}");
    }
}
