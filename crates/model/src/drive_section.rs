//! `[drive]` section of an experiment (`docs/drives.md`): what moves the sliders.
//!
//! ```toml
//! [drive]
//! kind = "motion"          # default: the [trajectory] is imposed (the inverse problem)
//!
//! [drive]
//! kind = "forces"          # Fa_i(t) given; s(0), s'(0) from the [trajectory] at t = 0
//! file = "fa.csv"          # relative to this file; header starts with t and names Fa1, Fa2, Fa3
//! # or Fa1 = [...], Fa2 = [...], Fa3 = [...]   (N, coefficients of 1, t, t^2, ...)
//!
//! [drive]
//! kind = "servo"           # PD loop per slider tracking the [trajectory]
//! kp = 1e5                 # N/m  } or bandwidth_hz = 20 (Hz) and damping_ratio = 0.7 with the
//! kd = 1e3                 # N s/m} slider mass mpp_mpa
//! feedforward = "rigid"    # rigid-body inverse dynamics of the reference, or "none"
//! ```
//! Unknown keys, and keys that do not belong to the kind, are rejected. The forces file is read
//! and checked when the experiment is loaded, before any work.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{ModelError, SampleError};

/// Which drive (`drive.kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DriveKind {
    /// The trajectory is imposed (inverse problem, Eq. 33 gives Fa).
    #[default]
    Motion,
    /// The actuator forces are given (direct problem).
    Forces,
    /// A PD servo on each slider tracks the trajectory (direct problem).
    Servo,
}

/// Feedforward of the servo (`drive.feedforward`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Feedforward {
    /// The rigid-body inverse dynamics of the reference (Eq. 33 with a rigid star).
    #[default]
    Rigid,
    /// No feedforward: the PD terms alone.
    None,
}

/// `Fa_i(t)` [N] sampled at increasing times [s] (a forces file as read).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ForceSamples {
    /// Sample times [s], finite and strictly increasing.
    pub t: Vec<f64>,
    /// `Fa1, Fa2, Fa3` [N] at each time.
    pub fa: Vec<[f64; 3]>,
}

impl ForceSamples {
    /// Check samples: as many rows as times, at least two, finite values, strictly increasing
    /// times. The error names the (1-based) row and the reason.
    pub fn check(t: &[f64], fa: &[[f64; 3]]) -> Result<(), SampleError> {
        if t.len() != fa.len() {
            return Err(SampleError::Lengths {
                times: t.len(),
                rows: fa.len(),
            });
        }
        if t.len() < 2 {
            return Err(SampleError::TooFew(t.len()));
        }
        for (k, (tk, f)) in t.iter().zip(fa).enumerate() {
            if !tk.is_finite() || f.iter().any(|v| !v.is_finite()) {
                return Err(SampleError::NonFinite { row: k + 1 });
            }
            if k > 0 && *tk <= t[k - 1] {
                return Err(SampleError::NotIncreasing {
                    row: k + 1,
                    t: *tk,
                    previous: t[k - 1],
                });
            }
        }
        Ok(())
    }

    /// Check that samples starting at `first` and ending at `last` cover `[t0, t1]` [s], with a
    /// relative slack of 1e-9 for times written with fewer digits than the solver keeps.
    pub fn check_covers(first: f64, last: f64, t0: f64, t1: f64) -> Result<(), SampleError> {
        let slack = 1e-9 * t1.abs().max(1.0);
        if first > t0 + slack || last < t1 - slack {
            return Err(SampleError::Span { first, last, t0, t1 });
        }
        Ok(())
    }

    /// Read a forces CSV: first column `t`, columns `Fa1`, `Fa2`, `Fa3` found by name (a file of
    /// exactly `t,Fa1,Fa2,Fa3` or any flexstar solver output). Errors name the file, `key` and
    /// the row or column.
    pub fn read_csv(path: &Path, key: &str) -> Result<Self, ModelError> {
        Self::read_columns(path, key, ["Fa1", "Fa2", "Fa3"], "forces")
    }

    /// Read a CSV whose first column is `t` and whose three `columns` are found by name (the
    /// forces file of `[drive]`, the load file of `[load]`); `what` names the file in messages
    /// (`the forces file`). Errors name the file, `key` and the row or column.
    pub fn read_columns(path: &Path, key: &str, columns: [&str; 3], what: &str) -> Result<Self, ModelError> {
        let bad = |reason: String| ModelError::Invalid {
            file: path.to_path_buf(),
            key: key.to_string(),
            reason,
        };
        let expected = format!("t,{}", columns.join(","));
        // a solver output of flexstar's own: its folder recovered from an interrupted writer first
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            flexstar_io::run_set::recover(dir)?;
        }
        let mut rd = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(path)
            .map_err(|e| bad(format!("cannot read the {what} file: {e}")))?;
        let header = rd
            .headers()
            .map_err(|e| bad(format!("cannot read the header: {e}")))?
            .clone();
        if header.get(0) != Some("t") {
            return Err(bad(format!(
                "the header must start with `{expected}` (or be a solver output with t first), got `{}`",
                header.iter().collect::<Vec<_>>().join(",")
            )));
        }
        let col = |name: &str| {
            header.iter().position(|h| h == name).ok_or_else(|| {
                bad(format!(
                    "the header has no column `{name}` (it must start `{expected}`)"
                ))
            })
        };
        let idx = [col(columns[0])?, col(columns[1])?, col(columns[2])?];
        let (mut t, mut fa) = (Vec::new(), Vec::new());
        for (k, rec) in rd.records().enumerate() {
            let row = k + 1;
            let rec = rec.map_err(|e| bad(format!("row {row}: {e}")))?;
            let num = |c: usize| -> Result<f64, ModelError> {
                let s = rec.get(c).unwrap_or("");
                s.parse::<f64>()
                    .map_err(|_| bad(format!("row {row}: `{s}` is not a number")))
            };
            t.push(num(0)?);
            fa.push([num(idx[0])?, num(idx[1])?, num(idx[2])?]);
        }
        Self::check(&t, &fa).map_err(|e| bad(e.to_string()))?;
        Ok(ForceSamples { t, fa })
    }

    /// The three channels at `t` [s]: linear between samples, held constant outside the span.
    /// Samples must have passed [`ForceSamples::check`] (at least two, increasing times).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let n = self.t.len();
        if t <= self.t[0] {
            return self.fa[0];
        }
        if t >= self.t[n - 1] {
            return self.fa[n - 1];
        }
        let k = self.t.partition_point(|&tk| tk <= t).min(n - 1);
        let (t0, t1) = (self.t[k - 1], self.t[k]);
        let r = (t - t0) / (t1 - t0);
        let (f0, f1) = (self.fa[k - 1], self.fa[k]);
        [0, 1, 2].map(|i| f0[i] + r * (f1[i] - f0[i]))
    }
}

/// `[drive]` section as written (every key optional; [`DriveSettings::validate`] checks which
/// belong to the kind). The forces file is read into `samples` at load time.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveSettings {
    /// `motion` (default), `forces` or `servo`.
    pub kind: DriveKind,
    /// Forces: CSV file of `Fa_i(t)`, relative to the experiment file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Forces: `Fa1(t)` [N] as polynomial coefficients of 1, t, t^2, ... (t in s).
    #[serde(rename = "Fa1", skip_serializing_if = "Option::is_none")]
    pub fa1: Option<Vec<f64>>,
    /// Forces: `Fa2(t)` [N].
    #[serde(rename = "Fa2", skip_serializing_if = "Option::is_none")]
    pub fa2: Option<Vec<f64>>,
    /// Forces: `Fa3(t)` [N].
    #[serde(rename = "Fa3", skip_serializing_if = "Option::is_none")]
    pub fa3: Option<Vec<f64>>,
    /// Servo: proportional gain [N/m], the same for the three sliders.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kp: Option<f64>,
    /// Servo: derivative gain [N s/m].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kd: Option<f64>,
    /// Servo: closed-loop bandwidth [Hz] of a slider of mass `mpp_mpa` (instead of kp, kd).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bandwidth_hz: Option<f64>,
    /// Servo: damping ratio with `bandwidth_hz`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    /// Servo: `rigid` (default) or `none`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feedforward: Option<Feedforward>,
    /// The forces file as read at load time (not a TOML key).
    #[serde(skip)]
    pub samples: Option<ForceSamples>,
}

/// Servo gains from a closed-loop bandwidth `f_bw` [Hz] and damping ratio `zeta` for a slider of
/// mass `m` [kg] treated as a free mass: `kp = m (2 pi f_bw)^2` [N/m], `kd = 2 zeta m (2 pi f_bw)`
/// [N s/m] (poles of `m s'' + kd s' + kp s = 0` at natural frequency `2 pi f_bw`, damping
/// `zeta`). The one place of this formula.
pub fn gains_from_bandwidth(m: f64, f_bw: f64, zeta: f64) -> (f64, f64) {
    let wn = 2.0 * std::f64::consts::PI * f_bw;
    (m * wn * wn, 2.0 * zeta * m * wn)
}

/// Servo gains resolved from `kp`, `kd` or from `bandwidth_hz`, `damping_ratio`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoGains {
    /// [N/m]
    pub kp: f64,
    /// [N s/m]
    pub kd: f64,
}

const FORCE_KEYS: [&str; 4] = ["file", "Fa1", "Fa2", "Fa3"];
const SERVO_KEYS: [&str; 5] = ["kp", "kd", "bandwidth_hz", "damping_ratio", "feedforward"];

impl DriveSettings {
    /// A forces drive from a file (the `--forces FILE` shorthand), read now.
    pub fn forces_file(path: &Path) -> Result<Self, ModelError> {
        let mut d = DriveSettings {
            kind: DriveKind::Forces,
            file: Some(path.to_path_buf()),
            ..DriveSettings::default()
        };
        d.samples = Some(ForceSamples::read_csv(path, "--forces")?);
        Ok(d)
    }

    /// Is this the direct problem (forces or servo)?
    pub fn is_direct(&self) -> bool {
        self.kind != DriveKind::Motion
    }

    /// The keys present, by TOML name.
    fn present(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        let flags = [
            ("file", self.file.is_some()),
            ("Fa1", self.fa1.is_some()),
            ("Fa2", self.fa2.is_some()),
            ("Fa3", self.fa3.is_some()),
            ("kp", self.kp.is_some()),
            ("kd", self.kd.is_some()),
            ("bandwidth_hz", self.bandwidth_hz.is_some()),
            ("damping_ratio", self.damping_ratio.is_some()),
            ("feedforward", self.feedforward.is_some()),
        ];
        for (k, on) in flags {
            if on {
                v.push(k);
            }
        }
        v
    }

    /// The forces file of a forces drive, resolved against the experiment file `config`.
    pub fn file_path(&self, config: &Path) -> Option<PathBuf> {
        let f = self.file.as_ref().filter(|_| self.kind == DriveKind::Forces)?;
        let dir = config.parent().unwrap_or_else(|| Path::new(""));
        Some(if f.is_absolute() { f.clone() } else { dir.join(f) })
    }

    /// Read the forces file (path relative to the experiment file `config`); a no-op for other
    /// drives. Errors name the experiment file, `drive.file` and the forces file.
    pub fn read_file(&mut self, config: &Path) -> Result<(), ModelError> {
        if self.kind != DriveKind::Forces {
            return Ok(());
        }
        if let Some(path) = self.file_path(config) {
            let samples = ForceSamples::read_csv(&path, "drive.file").map_err(|e| match e {
                ModelError::Invalid { key, reason, .. } => ModelError::Invalid {
                    file: config.to_path_buf(),
                    key,
                    reason: format!("{}: {reason}", path.display()),
                },
                other => other,
            })?;
            self.samples = Some(samples);
        }
        Ok(())
    }

    /// Check the keys against the kind and the values (keys named `drive.<key>`); `t_end` [s]
    /// is the span a forces file must cover, `slider_masses` [kg] each slider's `mpp_mpa` (a
    /// servo's gains from a bandwidth, [`DriveSettings::slider_gains`]).
    pub fn validate(&self, t_end: f64, slider_masses: [f64; 3]) -> Result<(), ModelError> {
        let allowed: &[&str] = match self.kind {
            DriveKind::Motion => &[],
            DriveKind::Forces => &FORCE_KEYS,
            DriveKind::Servo => &SERVO_KEYS,
        };
        if let Some(k) = self.present().into_iter().find(|k| !allowed.contains(k)) {
            return Err(ModelError::invalid(
                format!("drive.{k}"),
                format!("does not belong to kind = \"{}\"", self.kind_name()),
            ));
        }
        match self.kind {
            DriveKind::Motion => Ok(()),
            DriveKind::Forces => self.validate_forces(t_end),
            DriveKind::Servo => self.slider_gains(slider_masses).map(|_| ()),
        }
    }

    fn kind_name(&self) -> &'static str {
        match self.kind {
            DriveKind::Motion => "motion",
            DriveKind::Forces => "forces",
            DriveKind::Servo => "servo",
        }
    }

    fn validate_forces(&self, t_end: f64) -> Result<(), ModelError> {
        let polys = [&self.fa1, &self.fa2, &self.fa3];
        let n_polys = polys.iter().filter(|p| p.is_some()).count();
        match (&self.file, n_polys) {
            (Some(f), 0) => {
                let Some(s) = &self.samples else {
                    return Err(ModelError::invalid("drive.file", "the forces file was not read"));
                };
                ForceSamples::check_covers(s.t[0], s.t[s.t.len() - 1], 0.0, t_end)
                    .map_err(|r| ModelError::invalid("drive.file", format!("{}: {r}", f.display())))
            }
            (None, 3) => {
                for (k, p) in FORCE_KEYS[1..].iter().zip(polys) {
                    let p = p.as_ref().expect("counted");
                    if p.is_empty() || p.iter().any(|c| !c.is_finite()) {
                        return Err(ModelError::invalid(
                            format!("drive.{k}"),
                            "need at least one finite coefficient",
                        ));
                    }
                }
                Ok(())
            }
            (Some(_), _) => Err(ModelError::invalid(
                "drive.file",
                "give either file or Fa1, Fa2, Fa3, not both",
            )),
            (None, _) => Err(ModelError::invalid(
                "drive.Fa1",
                "a forces drive needs file = \"...\" or all three of Fa1, Fa2, Fa3",
            )),
        }
    }

    /// The servo gains of each slider (`docs/as-built.md` 7.6): [`DriveSettings::servo_gains`]
    /// on each slider's own mass `slider_masses[i]` = `mpp_mpa_i` [kg] (`kp`, `kd` given hold
    /// for all three). Errors name the key, and the slider when the masses differ.
    pub fn slider_gains(&self, slider_masses: [f64; 3]) -> Result<[ServoGains; 3], ModelError> {
        let equal = slider_masses.iter().all(|m| m.to_bits() == slider_masses[0].to_bits());
        let mut gains = [ServoGains { kp: 0.0, kd: 0.0 }; 3];
        for (i, (g, m)) in gains.iter_mut().zip(slider_masses).enumerate() {
            *g = self.servo_gains(m).map_err(|e| match e {
                ModelError::Invalid { file, key, reason } if !equal => ModelError::Invalid {
                    file,
                    key,
                    reason: format!("slider {}: {reason}", i + 1),
                },
                other => other,
            })?;
        }
        Ok(gains)
    }

    /// Servo gains: `kp` and `kd`, or `bandwidth_hz` and `damping_ratio` with the slider mass
    /// `m` [kg] (`kp = m (2 pi f)^2`, `kd = 2 zeta m 2 pi f`). Errors name the key.
    pub fn servo_gains(&self, m: f64) -> Result<ServoGains, ModelError> {
        let positive = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(ModelError::invalid(
                    format!("drive.{key}"),
                    format!("must be positive and finite, got {v}"),
                ))
            }
        };
        match (self.kp, self.kd, self.bandwidth_hz, self.damping_ratio) {
            (Some(kp), Some(kd), None, None) => Ok(ServoGains {
                kp: positive("kp", kp)?,
                kd: positive("kd", kd)?,
            }),
            (None, None, Some(f), Some(z)) => {
                let (f, z) = (positive("bandwidth_hz", f)?, positive("damping_ratio", z)?);
                if !(m.is_finite() && m > 0.0) {
                    return Err(ModelError::invalid(
                        "drive.bandwidth_hz",
                        format!(
                            "the gains from bandwidth_hz scale with the slider mass robot.mpp_mpa = {m} kg, \
                             which would give kp = kd = 0: give a positive robot.mpp_mpa, or kp and kd"
                        ),
                    ));
                }
                let (kp, kd) = gains_from_bandwidth(m, f, z);
                Ok(ServoGains { kp, kd })
            }
            (Some(_), Some(_), _, _) => Err(ModelError::invalid(
                "drive.bandwidth_hz",
                "give either kp and kd, or bandwidth_hz and damping_ratio, not both",
            )),
            (kp, _, f, _) => {
                let missing = if kp.is_some() {
                    "kd"
                } else if f.is_some() {
                    "damping_ratio"
                } else if self.damping_ratio.is_some() {
                    "bandwidth_hz"
                } else {
                    "kp"
                };
                Err(ModelError::invalid(
                    format!("drive.{missing}"),
                    "a servo needs kp and kd [N/m, N s/m], or bandwidth_hz and damping_ratio",
                ))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::Experiment;
    use std::path::Path;

    const BASE: &str = r#"
name = "d"
[time]
t_end = 0.2
[trajectory]
kind = "polynomial"
s1 = [0.0, 0.0, 1.0]
s2 = [0.0]
s3 = [0.0, 0.0, 0.5]
"#;

    fn load(drive: &str, config: &Path) -> Result<Experiment, String> {
        let text = format!("{BASE}[drive]\n{drive}\n");
        Experiment::from_toml_str(&text, config).map_err(|e| e.to_string())
    }

    fn err(drive: &str) -> String {
        load(drive, Path::new("exp.toml")).unwrap_err()
    }

    #[test]
    fn servo_gains_from_bandwidth_use_the_slider_mass() {
        // kp = m (2 pi f)^2, kd = 2 zeta m (2 pi f): m = 0.2 kg, f = 10 Hz, zeta = 0.5
        let e = load(
            "kind = \"servo\"\nbandwidth_hz = 10.0\ndamping_ratio = 0.5",
            Path::new("e.toml"),
        )
        .unwrap();
        let g = e.drive.servo_gains(e.robot.mpp_mpa).unwrap();
        let wn = 20.0 * std::f64::consts::PI;
        assert!((g.kp - 0.2 * wn * wn).abs() < 1e-9 && (g.kd - 0.2 * wn).abs() < 1e-12);
        assert!(e.drive.is_direct());
        let e = load(
            "kind = \"servo\"\nkp = 100.0\nkd = 2.0\nfeedforward = \"none\"",
            Path::new("e.toml"),
        )
        .unwrap();
        assert_eq!(e.drive.servo_gains(0.2).unwrap().kp, 100.0);
        assert!(!load("", Path::new("e.toml")).unwrap().drive.is_direct());
    }

    #[test]
    fn bandwidth_with_a_massless_slider_is_refused() {
        // kp = m (2 pi f)^2 is zero for m = 0: refused, naming both keys, instead of a servo that
        // does nothing; kp and kd given directly stay accepted with m = 0.
        let text = format!(
            "{}[drive]\nkind = \"servo\"\nbandwidth_hz = 10.0\ndamping_ratio = 0.7\n",
            BASE.replace("[time]", "[robot]\nmpp_mpa = 0.0\n[time]")
        );
        let e = Experiment::from_toml_str(&text, Path::new("m0.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m0.toml") && e.contains("drive.bandwidth_hz") && e.contains("robot.mpp_mpa"),
            "{e}"
        );
        let text = format!(
            "{}[drive]\nkind = \"servo\"\nkp = 10.0\nkd = 1.0\n",
            BASE.replace("[time]", "[robot]\nmpp_mpa = 0.0\n[time]")
        );
        assert!(Experiment::from_toml_str(&text, Path::new("m0.toml")).is_ok());
    }

    /// Sliders of different masses (`[robot] mpp_mpa` as a list): the gains from a bandwidth on
    /// each slider's own mass, the same law; a massless one is refused naming the slider.
    #[test]
    fn each_slider_takes_the_gains_of_its_own_mass() {
        let with = |masses: &str| {
            let text = format!(
                "{}[drive]\nkind = \"servo\"\nbandwidth_hz = 10.0\ndamping_ratio = 0.5\n",
                BASE.replace("[time]", &format!("[robot]\nmpp_mpa = {masses}\n[time]"))
            );
            Experiment::from_toml_str(&text, Path::new("m.toml")).map_err(|e| e.to_string())
        };
        let e = with("[0.2, 0.25, 0.3]").unwrap();
        let g = e.drive.slider_gains([0.2, 0.25, 0.3]).unwrap();
        let wn = 20.0 * std::f64::consts::PI;
        for (gi, m) in g.iter().zip([0.2, 0.25, 0.3]) {
            assert!(
                (gi.kp - m * wn * wn).abs() < 1e-9 && (gi.kd - m * wn).abs() < 1e-12,
                "{gi:?}"
            );
        }
        let e = with("[0.2, 0.0, 0.3]").unwrap_err();
        assert!(
            e.contains("m.toml") && e.contains("drive.bandwidth_hz") && e.contains("slider 2"),
            "{e}"
        );
    }

    #[test]
    fn bad_drives_name_file_and_key() {
        for (drive, key) in [
            ("kind = \"servo\"\nkp = 0.0\nkd = 1.0", "drive.kp"),
            ("kind = \"servo\"\nkp = 10.0\nkd = -1.0", "drive.kd"),
            ("kind = \"servo\"\nkp = 10.0", "drive.kd"),
            (
                "kind = \"servo\"\nbandwidth_hz = -5.0\ndamping_ratio = 0.7",
                "drive.bandwidth_hz",
            ),
            (
                "kind = \"servo\"\nbandwidth_hz = 5.0\ndamping_ratio = 0.7\nkp = 1.0\nkd = 1.0",
                "drive.bandwidth_hz",
            ),
            ("kind = \"servo\"\nkp = 1.0\nkd = 1.0\nfile = \"fa.csv\"", "drive.file"),
            ("kind = \"forces\"\nFa1 = [1.0]\nFa2 = [1.0]", "drive.Fa1"),
            (
                "kind = \"forces\"\nFa1 = [1.0]\nFa2 = [1.0]\nFa3 = [1.0]\nkp = 3.0",
                "drive.kp",
            ),
            ("kind = \"motion\"\nkd = 3.0", "drive.kd"),
        ] {
            let e = err(drive);
            assert!(e.contains("exp.toml") && e.contains(key), "{drive}: {e}");
        }
        // unknown key and unknown kind, named by the TOML parser
        assert!(err("kind = \"servo\"\ngain = 1.0").contains("gain"));
        assert!(err("kind = \"torque\"").contains("torque"));
        assert!(err("kind = \"servo\"\nkp = 1.0\nkd = 1.0\nfeedforward = \"full\"").contains("full"));
    }

    #[test]
    fn forces_file_is_read_relative_to_the_config_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("exp.toml");
        let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
        write("ok.csv", "t,Fa1,Fa2,Fa3\n0,1,2,3\n0.1,1,2,3\n0.2,4,5,6\n");
        // a solver output: t first, Fa columns further right
        write("solver.csv", "t,w1G,Fa1,Fa2,Fa3,x\n0,0,1,2,3,9\n0.2,0,4,5,6,9\n");
        write("nohead.csv", "t,F1,F2,F3\n0,1,2,3\n0.2,1,2,3\n");
        write("notime.csv", "time,Fa1,Fa2,Fa3\n0,1,2,3\n0.2,1,2,3\n");
        write("decr.csv", "t,Fa1,Fa2,Fa3\n0,1,2,3\n0.1,1,2,3\n0.1,1,2,3\n0.2,1,2,3\n");
        write("nan.csv", "t,Fa1,Fa2,Fa3\n0,1,2,3\nnan,1,2,3\n");
        write("short.csv", "t,Fa1,Fa2,Fa3\n0,1,2,3\n0.15,1,2,3\n");
        write("text.csv", "t,Fa1,Fa2,Fa3\n0,1,x,3\n0.2,1,2,3\n");
        let e = load("kind = \"forces\"\nfile = \"ok.csv\"", &config).unwrap();
        let s = e.drive.samples.as_ref().unwrap();
        assert_eq!(s.t, vec![0.0, 0.1, 0.2]);
        assert_eq!(s.fa[2], [4.0, 5.0, 6.0]);
        let e = load("kind = \"forces\"\nfile = \"solver.csv\"", &config).unwrap();
        assert_eq!(e.drive.samples.unwrap().fa[1], [4.0, 5.0, 6.0]);
        for (file, why) in [
            ("nohead.csv", "Fa1"),
            ("notime.csv", "start with"),
            ("decr.csv", "row 3"),
            ("nan.csv", "row 2"),
            ("short.csv", "span"),
            ("text.csv", "row 1"),
            ("missing.csv", "cannot read"),
        ] {
            let e = load(&format!("kind = \"forces\"\nfile = \"{file}\""), &config).unwrap_err();
            assert!(
                e.contains("exp.toml") && e.contains("drive.file") && e.contains(file) && e.contains(why),
                "{file}: {e}"
            );
        }
    }
}
