//! `[[sensors]]` as written in an experiment file, and its validation into [`Sensor`]s
//! (`docs/sensors.md` sections 1 and 5).

use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::robot::Robot;

/// One `[[sensors]]` table as written: every key optional here, checked against its `kind` by
/// [`SensorSpec::validate`]. Unknown keys are refused when the file is read.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Column stem (letters, digits, `_`, `-`), unique among the sensors.
    pub name: String,
    /// `accelerometer`, `strain`, `encoder` or `force`.
    pub kind: String,
    /// `"G"` or `"payload"` (an accelerometer not on a beam).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<String>,
    /// Beam 1..3 of a point on a beam.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beam: Option<usize>,
    /// Material coordinate of the point from G along its beam [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    /// A payload point from G [m], in the payload's frame (as `[payload] offset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<[f64; 2]>,
    /// `body` (default) or `fixed`: the axes of an accelerometer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes: Option<String>,
    /// Distance of a strain gauge from the neutral axis [m], > 0 on the `+e_w` side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c: Option<f64>,
    /// Slider 1..3 of an encoder or a force cell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slider: Option<usize>,
    /// Sampling rate [Hz]; default: the output times.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    /// Standard deviation of the added white noise, in the sensor's unit; default 0. One value
    /// for every column, or `[nx, ny]` for an accelerometer's two axes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<Noise>,
    /// Seed of the noise; default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// -3 dB frequency of the anti-aliasing filter [Hz] (4th-order Butterworth, Eq. S11);
    /// default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lowpass_hz: Option<f64>,
}

/// Where an accelerometer sits (`docs/sensors.md` section 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    /// The material point at `x` [m] from G of beam `beam` (0-based).
    Beam { beam: usize, x: f64 },
    /// G: beam 1's point at x = 0, with beam 1's tangent there.
    G,
    /// A point of the payload at `offset` [m] from G in the payload's frame (Eq. S6).
    Payload { offset: [f64; 2] },
}

/// The frame of an accelerometer's two columns (Eq. S5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axes {
    /// Along the tangent towards the tip (`_x`) and its normal, +90 degrees (`_y`).
    Body,
    /// The base frame X, Y.
    Fixed,
}

/// What a sensor measures, and where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// The specific force `r'' - g` [m/s^2] (Eqs. S4-S6).
    Accelerometer { place: Place, axes: Axes },
    /// The surface strain `-c kappa` [m/m] at `x` [m] of beam `beam` (0-based; Eq. S7).
    Strain { beam: usize, x: f64, c: f64 },
    /// Slider `slider`'s position `s_i` [m] (0-based).
    Encoder { slider: usize },
    /// Actuator `slider`'s force `Fa_i` [N] (Eq. 33; 0-based).
    Force { slider: usize },
}

/// `noise` as written: one standard deviation, or one per accelerometer axis `[nx, ny]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Noise {
    One(f64),
    PerAxis([f64; 2]),
}

/// The data acquisition of one sensor (`docs/sensors.md` section 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Acquisition {
    /// Sampling rate [Hz]; `None`: the output times.
    pub rate_hz: Option<f64>,
    /// Standard deviation of the white noise of each column, in the sensor's unit (Eq. S13):
    /// `[x, y]` for an accelerometer, the first entry alone for the others.
    pub noise: [f64; 2],
    /// Seed of the noise.
    pub seed: u64,
    /// -3 dB frequency of the 4th-order Butterworth anti-aliasing filter [Hz] (Eq. S11).
    pub lowpass_hz: Option<f64>,
}

/// A checked sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    pub name: String,
    pub kind: Kind,
    pub daq: Acquisition,
}

impl Sensor {
    /// Its columns in the sensors' file: `<name>_x, <name>_y` for an accelerometer, else `<name>`.
    pub fn columns(&self) -> Vec<String> {
        match self.kind {
            Kind::Accelerometer { .. } => vec![format!("{}_x", self.name), format!("{}_y", self.name)],
            _ => vec![self.name.clone()],
        }
    }

    /// The unit of its columns.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            Kind::Accelerometer { .. } => "m/s^2",
            Kind::Strain { .. } => "m/m",
            Kind::Encoder { .. } => "m",
            Kind::Force { .. } => "N",
        }
    }

    /// The beam point it is mounted on, `(beam, x)` (0-based beam), if any: what Eq. S10 checks.
    pub fn beam_point(&self) -> Option<(usize, f64)> {
        match self.kind {
            Kind::Accelerometer {
                place: Place::Beam { beam, x },
                ..
            }
            | Kind::Strain { beam, x, .. } => Some((beam, x)),
            _ => None,
        }
    }
}

/// `docs/sensors.md` section 5: the point `x` [m] from G of beam `beam` (0-based) lies on that
/// beam of `robot`, `0 <= x <= L_i`; the error names `key` (`sensors[k].x`).
pub(crate) fn check_on_beam(beam: usize, x: f64, robot: &Robot, key: &str) -> Result<(), ModelError> {
    let l = robot.beams()[beam].length;
    if !(x.is_finite() && (0.0..=l).contains(&x)) {
        return Err(ModelError::invalid(
            key,
            format!("x = {x} m lies beyond beam {} (it spans 0..L = {l} m from G)", beam + 1),
        ));
    }
    Ok(())
}

/// What the checks of a sensor need to know about the experiment.
pub(crate) struct Context<'a> {
    pub robot: &'a Robot,
    pub has_payload: bool,
    /// The output step [s] (the finest signal a sensor sees).
    pub dt_out: f64,
}

const KINDS: &str = "accelerometer, strain, encoder or force";

impl SensorSpec {
    /// The checked sensor of the `k`-th (1-based) `[[sensors]]` table; keys named
    /// `sensors[k].<key>`.
    pub(crate) fn validate(&self, k: usize, cx: &Context) -> Result<Sensor, ModelError> {
        let key = |name: &str| format!("sensors[{k}].{name}");
        let bad = |name: &str, reason: String| ModelError::invalid(key(name), reason);
        check_name(&self.name).map_err(|r| bad("name", r))?;
        let kind = match self.kind.as_str() {
            "accelerometer" => self.accelerometer(cx, &key)?,
            "strain" => {
                self.only(&["beam", "x", "c"], &key)?;
                let (beam, x) = self.beam_x(cx, &key)?;
                let c = self.c.ok_or_else(|| {
                    bad(
                        "c",
                        "a strain gauge needs c, its distance from the neutral axis [m]".into(),
                    )
                })?;
                if !c.is_finite() {
                    return Err(bad("c", format!("must be finite, got {c}")));
                }
                Kind::Strain { beam, x, c }
            }
            "encoder" | "force" => {
                self.only(&["slider"], &key)?;
                let slider = index(self.slider, "slider", &key)?;
                if self.kind == "encoder" {
                    Kind::Encoder { slider }
                } else {
                    Kind::Force { slider }
                }
            }
            other => return Err(bad("kind", format!("unknown kind {other:?}: expected {KINDS}"))),
        };
        Ok(Sensor {
            name: self.name.clone(),
            kind,
            daq: self.acquisition(cx, &key)?,
        })
    }

    fn accelerometer(&self, cx: &Context, key: &dyn Fn(&str) -> String) -> Result<Kind, ModelError> {
        let axes = match self.axes.as_deref() {
            None | Some("body") => Axes::Body,
            Some("fixed") => Axes::Fixed,
            Some(other) => {
                return Err(ModelError::invalid(
                    key("axes"),
                    format!("unknown axes {other:?}: expected \"body\" or \"fixed\""),
                ))
            }
        };
        let place = match self.at.as_deref() {
            None => {
                self.only(&["beam", "x", "axes"], key)?;
                let (beam, x) = self.beam_x(cx, key)?;
                Place::Beam { beam, x }
            }
            Some("G") => {
                self.only(&["at", "axes"], key)?;
                Place::G
            }
            Some("payload") => {
                self.only(&["at", "offset", "axes"], key)?;
                if !cx.has_payload {
                    return Err(ModelError::invalid(
                        key("at"),
                        "\"payload\": the experiment has no [payload] to mount it on",
                    ));
                }
                let offset = self.offset.ok_or_else(|| {
                    ModelError::invalid(key("offset"), "a payload point needs offset = [ox, oy] [m] from G")
                })?;
                if offset.iter().any(|v| !v.is_finite()) {
                    return Err(ModelError::invalid(
                        key("offset"),
                        format!("must be finite, got {offset:?}"),
                    ));
                }
                Place::Payload { offset }
            }
            Some(other) => {
                return Err(ModelError::invalid(
                    key("at"),
                    format!("unknown place {other:?}: expected \"G\", \"payload\", or beam = i with x"),
                ))
            }
        };
        Ok(Kind::Accelerometer { place, axes })
    }

    /// `beam` and `x` of a point on a beam: `0 <= x <= L_i`.
    fn beam_x(&self, cx: &Context, key: &dyn Fn(&str) -> String) -> Result<(usize, f64), ModelError> {
        let beam = index(self.beam, "beam", key)?;
        let x = self
            .x
            .ok_or_else(|| ModelError::invalid(key("x"), "a point on a beam needs x [m] from G"))?;
        check_on_beam(beam, x, cx.robot, &key("x"))?;
        Ok((beam, x))
    }

    /// Refuse the placement keys that do not belong to this kind (`allowed` lists those that do).
    fn only(&self, allowed: &[&str], key: &dyn Fn(&str) -> String) -> Result<(), ModelError> {
        let given = [
            ("at", self.at.is_some()),
            ("beam", self.beam.is_some()),
            ("x", self.x.is_some()),
            ("offset", self.offset.is_some()),
            ("axes", self.axes.is_some()),
            ("c", self.c.is_some()),
            ("slider", self.slider.is_some()),
        ];
        match given.iter().find(|(k, set)| *set && !allowed.contains(k)) {
            Some((k, _)) => Err(ModelError::invalid(
                key(k),
                format!(
                    "does not apply to this {}{} (its keys: {})",
                    self.kind,
                    self.at.as_deref().map_or(String::new(), |a| format!(" at {a:?}")),
                    allowed.join(", ")
                ),
            )),
            None => Ok(()),
        }
    }

    fn acquisition(&self, cx: &Context, key: &dyn Fn(&str) -> String) -> Result<Acquisition, ModelError> {
        let out_rate = 1.0 / cx.dt_out;
        if let Some(r) = self.rate_hz {
            if !(r.is_finite() && r > 0.0) {
                return Err(ModelError::invalid(
                    key("rate_hz"),
                    format!("must be positive, got {r}"),
                ));
            }
            if r > out_rate * (1.0 + 1e-9) {
                return Err(ModelError::invalid(
                    key("rate_hz"),
                    format!(
                        "{r} Hz exceeds the output rate 1 / dt_out = {out_rate} Hz: sensors are read at the \
                         output times; lower time.dt_out"
                    ),
                ));
            }
        }
        let noise = match self.noise {
            None => [0.0; 2],
            Some(Noise::One(n)) => [n; 2],
            Some(Noise::PerAxis(pair)) if self.kind == "accelerometer" => pair,
            Some(Noise::PerAxis(_)) => {
                return Err(ModelError::invalid(
                    key("noise"),
                    format!(
                        "a {} has one column: give one standard deviation (a pair [nx, ny] is for an \
                         accelerometer's two axes)",
                        self.kind
                    ),
                ))
            }
        };
        if let Some(n) = noise.iter().find(|n| !(n.is_finite() && **n >= 0.0)) {
            return Err(ModelError::invalid(
                key("noise"),
                format!("the standard deviation must be >= 0, got {n}"),
            ));
        }
        if let Some(f) = self.lowpass_hz {
            if !(f.is_finite() && f > 0.0 && f < 0.5 * out_rate) {
                return Err(ModelError::invalid(
                    key("lowpass_hz"),
                    format!(
                        "must lie between 0 and the Nyquist frequency of the output step, 1 / (2 dt_out) = {} Hz, \
                         got {f}",
                        0.5 * out_rate
                    ),
                ));
            }
        }
        Ok(Acquisition {
            rate_hz: self.rate_hz,
            noise,
            seed: self.seed.unwrap_or(0),
            lowpass_hz: self.lowpass_hz,
        })
    }
}

/// A beam or slider number 1..3 as a 0-based index.
fn index(v: Option<usize>, name: &str, key: &dyn Fn(&str) -> String) -> Result<usize, ModelError> {
    match v {
        Some(i @ 1..=3) => Ok(i - 1),
        Some(i) => Err(ModelError::invalid(key(name), format!("must be 1, 2 or 3, got {i}"))),
        None => Err(ModelError::invalid(
            key(name),
            format!("this kind needs {name} = 1, 2 or 3"),
        )),
    }
}

/// A name that makes column names: letters, digits, `_`, `-`, starting with a letter.
fn check_name(name: &str) -> Result<(), String> {
    let ok = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if ok {
        Ok(())
    } else {
        Err(format!(
            "must start with a letter and hold only letters, digits, '_', '-' (it names columns), got {name:?}"
        ))
    }
}
