//! Input shapers (`docs/motions.md` section 3): the ZV and ZVD shapers of
//! Singer and Seering (ASME J. Dyn. Syst. Meas. Control 112(1), 76-82, 1990), the EI shaper of
//! Singhose, Seering and Singer (ASME J. Mech. Des. 116(2), 654-659, 1994), their convolution
//! for several modes (section 3.3), their residual vibration (section 3.2), and the `[shaper]`
//! section of an experiment (section 3.7).

use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::trajectory::{ShapedMotion, Trajectory};

/// One impulse of a shaper: time `t` [s] after the start of the command and amplitude `A` [-].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impulse {
    /// Time [s] (the first impulse is at 0).
    pub t: f64,
    /// Amplitude [-]; the amplitudes of a shaper sum to 1.
    #[serde(rename = "A")]
    pub a: f64,
}

/// The shaper kinds of `[shaper] kind` (`docs/motions.md` 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShaperKind {
    /// Zero vibration: two impulses over half a damped period.
    Zv,
    /// Zero vibration and derivative: three impulses over one damped period.
    Zvd,
    /// Extra-insensitive: three impulses over one damped period, residual `v_tol` at the design
    /// frequency with zero slope.
    Ei,
    /// Two-hump extra-insensitive: four impulses over 1.5 damped periods, residual `v_tol` at two
    /// humps around the design frequency and zero at it (Singhose et al. 1997).
    #[serde(rename = "2hump_ei")]
    TwoHumpEi,
    /// Three-hump extra-insensitive: five impulses over two damped periods, residual `v_tol` at
    /// three humps, the middle one at the design frequency (Singhose et al. 1997).
    #[serde(rename = "3hump_ei")]
    ThreeHumpEi,
    /// Specified insensitivity: the shortest train on a grid of an eighth of a damped period
    /// whose residual stays at most `v_tol` over a given band (`insensitivity`), by a cone program
    /// (`docs/motions.md` 3.1, Eq. H3).
    Si,
}

impl ShaperKind {
    /// The kinds with a tolerable residual `v_tol` (the extra-insensitive family).
    pub fn has_tolerance(self) -> bool {
        matches!(
            self,
            ShaperKind::Ei | ShaperKind::TwoHumpEi | ShaperKind::ThreeHumpEi | ShaperKind::Si
        )
    }

    /// The name of `[shaper] kind`.
    pub fn name(self) -> &'static str {
        match self {
            ShaperKind::Zv => "zv",
            ShaperKind::Zvd => "zvd",
            ShaperKind::Ei => "ei",
            ShaperKind::TwoHumpEi => "2hump_ei",
            ShaperKind::ThreeHumpEi => "3hump_ei",
            ShaperKind::Si => "si",
        }
    }
}

/// Eq. H1 of `docs/motions.md` 3.1: the undamped amplitudes of the two-hump EI shaper of
/// tolerance `v` (Singhose, Seering and Singer 1997): `X = (v^2 (sqrt(1 - v^2) + 1))^(1/3)`,
/// `A1 = A4 = (3 X^2 + 2 X + 3 v^2) / (16 X)`, `A2 = A3 = 1/2 - A1`, half a period apart.
fn two_hump(v: f64) -> [f64; 4] {
    let x = (v * v * ((1.0 - v * v).sqrt() + 1.0)).cbrt();
    let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v * v) / (16.0 * x);
    [a1, 0.5 - a1, 0.5 - a1, a1]
}

/// Eq. H2 of `docs/motions.md` 3.1: the undamped amplitudes of the three-hump EI shaper of
/// tolerance `v`: `A1 = A5 = (1 + 3 v + 2 sqrt(2 v (v + 1))) / 16`, `A2 = A4 = (1 - v) / 4`,
/// `A3 = 1 - 2 (A1 + A2)`, half a period apart.
fn three_hump(v: f64) -> [f64; 5] {
    let a1 = (1.0 + 3.0 * v + 2.0 * (2.0 * v * (v + 1.0)).sqrt()) / 16.0;
    let a2 = (1.0 - v) / 4.0;
    [a1, a2, 1.0 - 2.0 * (a1 + a2), a2, a1]
}

/// The EI shaper's tolerable residual when `v_tol` is not given (5 %, the papers' standard).
pub const EI_V_TOL: f64 = 0.05;

/// The impulses of one shaper of `kind` for a mode of natural frequency `f_hz` [Hz] and damping
/// ratio `zeta` [-] (0 <= zeta < 1); `v_tol` is the extra-insensitive kinds' tolerable residual
/// (ignored otherwise). Formulas of `docs/motions.md` 3.1: ZV and ZVD from Singer and Seering
/// (1990), EI from Singhose, Seering and Singer (1994), the two- and three-hump EI from Singhose,
/// Seering and Singer (1997), the EI kinds' amplitudes weighted by `K^j` when damped.
pub fn single(kind: ShaperKind, f_hz: f64, zeta: f64, v_tol: f64) -> Vec<Impulse> {
    if kind == ShaperKind::Si {
        // the default band; a section's own band goes through `specified_insensitivity`
        let band = (f_hz * (1.0 - SI_BAND), f_hz * (1.0 + SI_BAND));
        if let Ok(s) = specified_insensitivity(f_hz, zeta, band, v_tol) {
            return s;
        }
        return single(ShaperKind::Ei, f_hz, zeta, v_tol);
    }
    let root = (1.0 - zeta * zeta).sqrt();
    let t_d = 1.0 / (f_hz * root);
    let k = (-zeta * std::f64::consts::PI / root).exp();
    let raw: Vec<f64> = match kind {
        ShaperKind::Zv => vec![1.0, k],
        ShaperKind::Zvd => vec![1.0, 2.0 * k, k * k],
        ShaperKind::Ei => vec![
            (1.0 + v_tol) / 4.0,
            (1.0 - v_tol) / 2.0 * k,
            (1.0 + v_tol) / 4.0 * k * k,
        ],
        ShaperKind::TwoHumpEi => damped(&two_hump(v_tol), k),
        ShaperKind::ThreeHumpEi => damped(&three_hump(v_tol), k),
        ShaperKind::Si => unreachable!("designed above"),
    };
    let sum: f64 = raw.iter().sum();
    raw.iter()
        .enumerate()
        .map(|(j, a)| Impulse {
            t: j as f64 * t_d / 2.0,
            a: a / sum,
        })
        .collect()
}

/// The specified-insensitivity shaper's default band: +-20 % of its frequency (EI's 5 % band).
pub const SI_BAND: f64 = 0.2;

/// Grid of the specified-insensitivity design: impulse times every `T_d / SI_GRID`.
const SI_GRID: usize = 8;

/// The longest specified-insensitivity shaper tried: four damped periods.
const SI_PERIODS: usize = 4;

/// Eq. H3 of `docs/motions.md` 3.1: the shortest impulse train on the grid `t_j = j T_d / 8`
/// (`T_d` the damped period at `f_hz` [Hz]) whose residual (section 3.2's formula, damping ratio
/// `zeta`) is at most `v_tol` at every frequency of `band` = `(f_lo, f_hi)` [Hz]: for n = 2, 3, ...
/// impulses, the amplitudes minimising the largest residual over 64 frequencies of the band
/// (a second-order cone program, `flexstar_numerics::minimax`), accepted when that residual,
/// checked on a four times finer sampling, is at most `v_tol`. Errors (key `shaper.insensitivity`)
/// when four damped periods do not suffice.
pub fn specified_insensitivity(f_hz: f64, zeta: f64, band: (f64, f64), v_tol: f64) -> Result<Vec<Impulse>, ModelError> {
    let t_d = 1.0 / (f_hz * (1.0 - zeta * zeta).sqrt());
    let dt = t_d / SI_GRID as f64;
    let sample = |count: usize| -> Vec<f64> {
        (0..count)
            .map(|k| band.0 + (band.1 - band.0) * k as f64 / (count - 1) as f64)
            .collect()
    };
    let (coarse, fine) = (sample(64), sample(256));
    for n in 2..=SI_GRID * SI_PERIODS + 1 {
        let t_n = (n - 1) as f64 * dt;
        let forms: Vec<Vec<(f64, f64)>> = coarse
            .iter()
            .map(|&f| {
                let w = 2.0 * std::f64::consts::PI * f;
                let wd = w * (1.0 - zeta * zeta).sqrt();
                (0..n)
                    .map(|j| {
                        let t = j as f64 * dt;
                        let e = (zeta * w * (t - t_n)).exp();
                        (e * (wd * t).cos(), e * (wd * t).sin())
                    })
                    .collect()
            })
            .collect();
        let Some(best) = flexstar_numerics::minimax::minimax_weights(&forms) else {
            continue;
        };
        if best.largest > v_tol {
            continue;
        }
        let train: Vec<Impulse> = best
            .weights
            .iter()
            .enumerate()
            .map(|(j, &a)| Impulse { t: j as f64 * dt, a })
            .collect();
        if fine.iter().all(|&f| residual(&train, f, zeta) <= v_tol * (1.0 + 1e-6)) {
            return Ok(train);
        }
    }
    Err(ModelError::invalid(
        "shaper.insensitivity",
        format!(
            "no shaper up to {SI_PERIODS} damped periods keeps the residual at or below v_tol = {v_tol} over \
             {:.4}-{:.4} Hz around {f_hz} Hz: widen v_tol or narrow the band",
            band.0, band.1
        ),
    ))
}

/// Undamped amplitudes `a_j` weighted by `K^j` (the damped form of the EI kinds, `docs/motions.md`
/// 3.1).
fn damped(a: &[f64], k: f64) -> Vec<f64> {
    a.iter().zip(0..).map(|(a, j)| a * k.powi(j)).collect()
}

/// The convolution of two impulse trains (`docs/motions.md` 3.3): every pair `(A_i A_j, t_i +
/// t_j)`, sorted by time, impulses closer than 1e-12 s merged.
pub fn convolve(a: &[Impulse], b: &[Impulse]) -> Vec<Impulse> {
    let mut out: Vec<Impulse> = a
        .iter()
        .flat_map(|p| {
            b.iter().map(move |q| Impulse {
                t: p.t + q.t,
                a: p.a * q.a,
            })
        })
        .collect();
    out.sort_by(|p, q| p.t.total_cmp(&q.t));
    let mut merged: Vec<Impulse> = Vec::with_capacity(out.len());
    for p in out {
        match merged.last_mut() {
            Some(last) if (p.t - last.t).abs() < 1e-12 => last.a += p.a,
            _ => merged.push(p),
        }
    }
    merged
}

/// The shaper for several modes: one shaper per `(f_hz, zeta)` pair, convolved
/// (`docs/motions.md` 3.3). An empty list gives the identity (one unit impulse at 0).
pub fn multi(kind: ShaperKind, modes: &[(f64, f64)], v_tol: f64) -> Vec<Impulse> {
    let unit = vec![Impulse { t: 0.0, a: 1.0 }];
    modes
        .iter()
        .fold(unit, |acc, &(f, z)| convolve(&acc, &single(kind, f, z, v_tol)))
}

/// Singer and Seering's percentage residual vibration (`docs/motions.md` 3.2): the residual
/// amplitude of a mode of frequency `f_hz` [Hz] and damping ratio `zeta` after the impulse train,
/// relative to that after a single unit impulse at 0, both taken at the last impulse.
pub fn residual(impulses: &[Impulse], f_hz: f64, zeta: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let t_n = impulses.last().map_or(0.0, |p| p.t);
    let (c, s) = impulses.iter().fold((0.0, 0.0), |(c, s), p| {
        let e = p.a * (zeta * w * (p.t - t_n)).exp();
        (c + e * (wd * p.t).cos(), s + e * (wd * p.t).sin())
    });
    (c * c + s * s).sqrt()
}

/// The duration of an impulse train [s]: its last impulse's time, by which a shaped motion is
/// longer than its base (the time penalty, `docs/motions.md` 3.3).
pub fn duration(impulses: &[Impulse]) -> f64 {
    impulses.last().map_or(0.0, |p| p.t)
}

/// The `[shaper]` section (`docs/motions.md` 3.7) as written, plus what it resolved to (the
/// `frequencies_hz`, `zeta_used`, `impulses` and `penalty_s` keys, written to the run's sidecar
/// with the resolved experiment, never read).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaperSection {
    /// `"zv"`, `"zvd"`, `"ei"`, `"2hump_ei"` or `"3hump_ei"`.
    pub kind: ShaperKind,
    /// `"auto"`, a frequency [Hz] or a list of them.
    pub f_hz: toml::Value,
    /// Damping ratio [-]: a number or a list as long as `f_hz`; default from `[damping]`
    /// (`Damping::zeta_at(f)`), else 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta: Option<toml::Value>,
    /// The EI kinds and SI only: the tolerable residual [-], default 0.05.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_tol: Option<f64>,
    /// SI only: the band of frequencies [Hz] over which the residual stays below `v_tol`:
    /// `[f_lo, f_hi]` (one frequency inside it), or `"+-x %"` around each frequency; default
    /// `"+-20 %"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub insensitivity: Option<toml::Value>,
    /// The frequencies used [Hz] (resolved).
    #[serde(default, skip_deserializing)]
    pub frequencies_hz: Vec<f64>,
    /// The damping ratio used per frequency [-] (resolved).
    #[serde(default, skip_deserializing)]
    pub zeta_used: Vec<f64>,
    /// The impulses `{t, A}` of the convolved shaper (resolved).
    #[serde(default, skip_deserializing)]
    pub impulses: Vec<Impulse>,
    /// The time penalty [s]: the shaped motion's `t_rest` minus the unshaped one's (resolved).
    #[serde(default, skip_deserializing)]
    pub penalty_s: f64,
    /// `f_hz = "auto"` only: how the frequencies were chosen (`docs/motions.md` 3.5, resolved).
    #[serde(default, skip_deserializing, skip_serializing_if = "Option::is_none")]
    pub auto: Option<AutoChoice>,
}

/// One frequency group of the unshaped residual of G (`docs/motions.md` 3.5, step 2-3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoMode {
    /// The group's frequency [Hz] (modes of the final pose closer than the fit resolves, merged).
    pub f_hz: f64,
    /// Its share of the mean square of the unshaped residual of G [-].
    pub share: f64,
    /// The LTI residual factor the chosen shaper leaves on it, `V(f)` [-].
    pub predicted_factor: f64,
}

/// What `f_hz = "auto"` chose and why (`docs/motions.md` 3.5, step 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoChoice {
    /// The shaper frequencies [Hz], in the order chosen.
    pub frequencies_hz: Vec<f64>,
    /// The frequency groups of the unshaped residual of G, by frequency.
    pub modes: Vec<AutoMode>,
    /// `R_pred / R_0`: the LTI prediction of the shaped residual over the unshaped one [-].
    pub predicted_ratio: f64,
    /// How it was computed (one sentence, for the sidecar's reader).
    pub method: String,
}

/// What `f_hz` asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum FrequencySpec {
    /// `"auto"`: from the modal analysis at the final pose (`docs/motions.md` 3.5).
    Auto,
    /// Given frequencies [Hz], each positive and finite.
    Given(Vec<f64>),
}

impl ShaperSection {
    /// A section with `kind` and given frequencies, nothing resolved yet.
    pub fn new(kind: ShaperKind, f_hz: &[f64]) -> Self {
        ShaperSection {
            kind,
            f_hz: toml::Value::Array(f_hz.iter().map(|&f| toml::Value::Float(f)).collect()),
            zeta: None,
            v_tol: None,
            insensitivity: None,
            frequencies_hz: Vec::new(),
            zeta_used: Vec::new(),
            impulses: Vec::new(),
            penalty_s: 0.0,
            auto: None,
        }
    }

    /// A section with `kind` and `f_hz = "auto"` (docs/motions.md 3.5), nothing resolved yet.
    pub fn auto(kind: ShaperKind) -> Self {
        ShaperSection {
            f_hz: toml::Value::String("auto".into()),
            ..Self::new(kind, &[])
        }
    }

    /// `f_hz` checked: `"auto"` or positive finite numbers (keys `shaper.f_hz`).
    pub fn frequency_spec(&self) -> Result<FrequencySpec, ModelError> {
        let bad = |got: String| {
            ModelError::invalid(
                "shaper.f_hz",
                format!("frequencies must be positive and finite (or \"auto\"), got {got}"),
            )
        };
        match &self.f_hz {
            toml::Value::String(s) if s == "auto" => Ok(FrequencySpec::Auto),
            toml::Value::Array(a) if a.is_empty() => Err(bad("an empty list".into())),
            toml::Value::Array(a) => a
                .iter()
                .map(|v| positive(v).ok_or_else(|| bad(v.to_string())))
                .collect::<Result<_, _>>()
                .map(FrequencySpec::Given),
            v => positive(v)
                .map(|f| FrequencySpec::Given(vec![f]))
                .ok_or_else(|| bad(v.to_string())),
        }
    }

    /// The damping ratio per frequency of `f_hz`: the `zeta` key (a number, or a list as long as
    /// `f_hz`), else `default(f)` (from `[damping]`); each in [0, 1) (keys `shaper.zeta`).
    pub fn zetas(&self, f_hz: &[f64], default: impl Fn(f64) -> f64) -> Result<Vec<f64>, ModelError> {
        let zs: Vec<f64> = match &self.zeta {
            None => f_hz.iter().map(|&f| default(f)).collect(),
            Some(toml::Value::Array(a)) => {
                if a.len() != f_hz.len() {
                    return Err(ModelError::invalid(
                        "shaper.zeta",
                        format!("a list of {} damping ratios for {} frequencies", a.len(), f_hz.len()),
                    ));
                }
                a.iter().map(|v| number(v).unwrap_or(f64::NAN)).collect()
            }
            Some(v) => vec![number(v).unwrap_or(f64::NAN); f_hz.len()],
        };
        if let Some(z) = zs.iter().find(|z| !(0.0..1.0).contains(*z)) {
            return Err(ModelError::invalid(
                "shaper.zeta",
                format!("damping ratios must lie in [0, 1), got {z}"),
            ));
        }
        Ok(zs)
    }

    /// The EI kinds' tolerance: `v_tol` in (0, 1) (0.5 at most for the multi-hump kinds, whose
    /// amplitudes are positive only up to there), only with an EI kind (key `shaper.v_tol`).
    pub fn v_tol(&self) -> Result<f64, ModelError> {
        let most = if matches!(self.kind, ShaperKind::Ei | ShaperKind::Si) {
            1.0
        } else {
            0.5
        };
        match (self.kind.has_tolerance(), self.v_tol) {
            (true, None) => Ok(EI_V_TOL),
            (true, Some(v)) if v > 0.0 && v < most => Ok(v),
            (true, Some(v)) => Err(ModelError::invalid(
                "shaper.v_tol",
                format!("need 0 < v_tol < {most} for kind = \"{}\", got {v}", self.kind.name()),
            )),
            (false, Some(_)) => Err(ModelError::invalid(
                "shaper.v_tol",
                "v_tol belongs to the extra-insensitive kinds and si only (\"ei\", \"2hump_ei\", \"3hump_ei\", \"si\")",
            )),
            (false, None) => Ok(0.0),
        }
    }

    /// SI's band around the frequency `f` [Hz] of `f_hz` (`n` of them) from `insensitivity`
    /// (key `shaper.insensitivity`; only with kind = "si").
    pub fn band(&self, f: f64, n: usize) -> Result<(f64, f64), ModelError> {
        let bad = |why: String| ModelError::invalid("shaper.insensitivity", why);
        let value = match (&self.insensitivity, self.kind) {
            (None, _) => return Ok((f * (1.0 - SI_BAND), f * (1.0 + SI_BAND))),
            (Some(_), k) if k != ShaperKind::Si => return Err(bad("belongs to kind = \"si\" only".into())),
            (Some(v), _) => v,
        };
        match value {
            toml::Value::String(s) => {
                let x: f64 = s
                    .trim()
                    .trim_start_matches("+-")
                    .trim_start_matches('\u{b1}')
                    .trim_end_matches('%')
                    .trim()
                    .parse()
                    .map_err(|_| bad(format!("\"{s}\": write \"+-x %\" (x in 0..100) or [f_lo, f_hi] in Hz")))?;
                if !(x > 0.0 && x < 100.0 && s.trim().starts_with(['+', '\u{b1}'])) {
                    return Err(bad(format!("\"{s}\": write \"+-x %\" with 0 < x < 100")));
                }
                Ok((f * (1.0 - x / 100.0), f * (1.0 + x / 100.0)))
            }
            toml::Value::Array(a) if a.len() == 2 => {
                let lo = number(&a[0]).unwrap_or(f64::NAN);
                let hi = number(&a[1]).unwrap_or(f64::NAN);
                if !(lo > 0.0 && hi > lo && hi.is_finite()) {
                    return Err(bad(format!("[{lo}, {hi}]: need 0 < f_lo < f_hi, finite, in Hz")));
                }
                if n != 1 {
                    return Err(bad(format!(
                        "a band in Hz goes with one frequency; with {n}, write \"+-x %\" around each"
                    )));
                }
                if !(lo <= f && f <= hi) {
                    return Err(bad(format!(
                        "the band [{lo}, {hi}] Hz must contain the frequency {f} Hz"
                    )));
                }
                Ok((lo, hi))
            }
            v => Err(bad(format!("{v}: write \"+-x %\" or [f_lo, f_hi] in Hz"))),
        }
    }

    /// Resolve for the frequencies `f_hz` [Hz]: fill `frequencies_hz`, `zeta_used`, `impulses`
    /// and `penalty_s`, with the damping ratios from the section or `default(f)`.
    pub fn resolve(&mut self, f_hz: &[f64], default: impl Fn(f64) -> f64) -> Result<(), ModelError> {
        let zetas = self.zetas(f_hz, default)?;
        let v_tol = self.v_tol()?;
        let modes: Vec<(f64, f64)> = f_hz.iter().copied().zip(zetas.iter().copied()).collect();
        self.impulses = if self.kind == ShaperKind::Si {
            let mut train = vec![Impulse { t: 0.0, a: 1.0 }];
            for &(f, z) in &modes {
                let band = self.band(f, modes.len())?;
                train = convolve(&train, &specified_insensitivity(f, z, band, v_tol)?);
            }
            train
        } else {
            self.band(0.0, 0)?;
            multi(self.kind, &modes, v_tol)
        };
        self.penalty_s = duration(&self.impulses);
        self.frequencies_hz = f_hz.to_vec();
        self.zeta_used = zetas;
        Ok(())
    }
}

impl crate::Experiment {
    /// Shape the motion with `[shaper]` (`docs/motions.md` 3.4, 3.7): check the section and that
    /// the motion can be shaped (rest-to-rest, in task space, not a forces drive), resolve the
    /// impulses (`zeta` defaults to `[damping]`'s `zeta_at(f)`), and replace `trajectory` by the
    /// [`Trajectory::Shaped`] motion. A no-op without `[shaper]` or when already shaped.
    ///
    /// `f_hz = "auto"` needs the accurate AMM, which this crate does not run: it is checked here
    /// (a prescribed motion, not a servo) and left pending ([`Self::shaper_pending`]) for the
    /// explicit step `flexstar_shaping::shape`, which calls [`Self::apply_auto_shaper`].
    pub fn apply_shaper(&mut self) -> Result<(), ModelError> {
        let Some(section) = self.shaper.clone() else {
            return Ok(());
        };
        if matches!(self.trajectory, Trajectory::Shaped(_)) {
            return Ok(());
        }
        self.check_shapeable()?;
        match section.frequency_spec()? {
            FrequencySpec::Given(f_hz) => self.shape_with(section, &f_hz),
            FrequencySpec::Auto => {
                section.v_tol()?;
                self.check_auto()
            }
        }
    }

    /// Whether `[shaper] f_hz = "auto"` still waits for its frequencies (the motion unshaped):
    /// what `flexstar_shaping::shape` resolves, and what the solvers refuse to run.
    pub fn shaper_pending(&self) -> bool {
        !matches!(self.trajectory, Trajectory::Shaped(_))
            && self
                .shaper
                .as_ref()
                .is_some_and(|s| matches!(s.frequency_spec(), Ok(FrequencySpec::Auto)))
    }

    /// Apply a pending `f_hz = "auto"` shaper with the frequencies `choice` found
    /// (`docs/motions.md` 3.5; `flexstar_shaping::shape`), recorded in the section's `auto`.
    pub fn apply_auto_shaper(&mut self, choice: AutoChoice) -> Result<(), ModelError> {
        let Some(mut section) = self.shaper.clone() else {
            return Err(ModelError::invalid("shaper", "no [shaper] section to apply"));
        };
        self.check_shapeable()?;
        self.check_auto()?;
        let f_hz = choice.frequencies_hz.clone();
        section.auto = Some(choice);
        self.shape_with(section, &f_hz)
    }

    /// Resolve `section` at the frequencies `f_hz` [Hz] and shape the motion with it.
    fn shape_with(&mut self, mut section: ShaperSection, f_hz: &[f64]) -> Result<(), ModelError> {
        let damping = self.damping;
        section.resolve(f_hz, |f| damping.zeta_at(f))?;
        self.trajectory = Trajectory::Shaped(ShapedMotion {
            base: Box::new(self.trajectory.clone()),
            impulses: section.impulses.clone(),
        });
        self.shaper = Some(section);
        Ok(())
    }

    /// `f_hz = "auto"` is refused with a servo (`docs/motions.md` 8.5; key `shaper.f_hz`).
    fn check_auto(&self) -> Result<(), ModelError> {
        if self.drive.kind != crate::DriveKind::Motion {
            return Err(ModelError::invalid(
                "shaper.f_hz",
                "\"auto\" needs a prescribed motion (drive.kind = \"motion\"); with a servo give the \
                 frequencies [Hz]",
            ));
        }
        Ok(())
    }

    /// The motion a shaper may act on: valid, rest-to-rest, with a task-space pose, and moved by
    /// the trajectory or a servo (key `shaper`).
    fn check_shapeable(&self) -> Result<(), ModelError> {
        self.robot.validate()?;
        self.trajectory.validate(&self.robot)?;
        if self.drive.kind == crate::DriveKind::Forces {
            return Err(ModelError::invalid(
                "shaper",
                "with drive.kind = \"forces\" there is no motion to shape",
            ));
        }
        if self.trajectory.t_rest().is_none() {
            return Err(ModelError::invalid(
                "shaper",
                "a shaper needs a rest-to-rest motion (quintic, via, table); kind = \"polynomial\" \
                 never comes to rest",
            ));
        }
        if self.trajectory.pose(0.0)?.is_none() {
            return Err(ModelError::invalid(
                "shaper",
                "a slider-space table (columns s1,s2,s3) cannot be shaped yet; give the table in \
                 task space (t,Gx,Gy,theta)",
            ));
        }
        Ok(())
    }
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn positive(v: &toml::Value) -> Option<f64> {
    number(v).filter(|f| f.is_finite() && *f > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Envelope of a damped oscillator's free response at time `t` after the impulses, from the
    /// sum of the analytic impulse responses `h(tau) = exp(-zeta w tau) sin(wd tau) / wd`
    /// (independent of [`residual`]); divided by the envelope of a unit impulse given at the last
    /// impulse (Singer and Seering's percentage residual vibration).
    fn envelope_ratio(imp: &[Impulse], f: f64, zeta: f64) -> f64 {
        let w = 2.0 * PI * f;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let t = duration(imp) + 0.1;
        let (mut x, mut v) = (0.0, 0.0);
        for p in imp {
            let tau = t - p.t;
            let e = (-zeta * w * tau).exp();
            x += p.a * e * (wd * tau).sin() / wd;
            v += p.a * e * ((wd * tau).cos() - zeta * w / wd * (wd * tau).sin());
        }
        let env = (x * x + ((v + zeta * w * x) / wd).powi(2)).sqrt();
        // a unit impulse at the last impulse's time has envelope exp(-zeta w (t - t_n)) / wd
        env / ((-zeta * w * (t - duration(imp))).exp() / wd)
    }

    const KINDS: [ShaperKind; 5] = [
        ShaperKind::Zv,
        ShaperKind::Zvd,
        ShaperKind::Ei,
        ShaperKind::TwoHumpEi,
        ShaperKind::ThreeHumpEi,
    ];

    #[test]
    fn amplitudes_sum_to_one_and_start_at_zero() {
        for kind in KINDS {
            for zeta in [0.0, 0.05, 0.3] {
                let s = single(kind, 3.9, zeta, EI_V_TOL);
                assert!((s.iter().map(|p| p.a).sum::<f64>() - 1.0).abs() < 1e-15);
                assert_eq!(s[0].t, 0.0);
                assert!(s.iter().all(|p| p.a > 0.0));
            }
        }
    }

    #[test]
    fn zv_and_zvd_leave_no_residual_at_the_design_frequency() {
        for kind in [ShaperKind::Zv, ShaperKind::Zvd] {
            for zeta in [0.0, 0.02, 0.2, 0.6] {
                let s = single(kind, 6.8, zeta, 0.0);
                let r = envelope_ratio(&s, 6.8, zeta);
                assert!(r < 1e-12, "{kind:?} zeta {zeta}: {r}");
                assert!((residual(&s, 6.8, zeta) - r).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn zvd_has_zero_slope_at_the_design_frequency() {
        let (f, h) = (3.9, 1e-4);
        for zeta in [0.0, 0.05] {
            let zvd = single(ShaperKind::Zvd, f, zeta, 0.0);
            let zv = single(ShaperKind::Zv, f, zeta, 0.0);
            let slope = |s: &[Impulse]| {
                (envelope_ratio(s, f * (1.0 + h), zeta) - envelope_ratio(s, f * (1.0 - h), zeta)) / (2.0 * h)
            };
            let side = |s: &[Impulse]| envelope_ratio(s, f * (1.0 + h), zeta) / h;
            // ZVD: residual quadratic in the error (side/h -> 0); ZV: linear (side -> pi/2)
            assert!(side(&zvd) < 1e-2 && slope(&zvd).abs() < 1e-3, "{}", side(&zvd));
            if zeta == 0.0 {
                assert!((side(&zv) - PI / 2.0).abs() < 1e-3, "{}", side(&zv));
            } else {
                assert!(side(&zv) > 1.0, "{}", side(&zv));
            }
        }
    }

    #[test]
    fn ei_residual_is_its_tolerance_at_design_and_below_over_its_band() {
        let f = 5.0;
        let s = single(ShaperKind::Ei, f, 0.0, EI_V_TOL);
        assert!((envelope_ratio(&s, f, 0.0) - EI_V_TOL).abs() < 1e-12);
        // docs/motions.md 3.2: V <= 5 % for r in 0.800..1.200 (rounded): checked inside 0.81..1.19
        for k in 0..=380 {
            let r = 0.81 + k as f64 * 1e-3;
            assert!(envelope_ratio(&s, f * r, 0.0) <= EI_V_TOL + 1e-12, "r = {r}");
        }
        assert!(envelope_ratio(&s, f * 0.78, 0.0) > EI_V_TOL);
        // damped form (docs/motions.md 3.1, Open 8.6): at the design frequency the residual is
        // V K^2 / sum(raw amplitudes), a little below V (4.2 % at zeta = 0.05)
        let (zeta, v) = (0.05, EI_V_TOL);
        let sd = single(ShaperKind::Ei, f, zeta, v);
        let k = (-zeta * PI / (1.0 - zeta * zeta).sqrt()).exp();
        let want = v * k * k / ((1.0 + v) / 4.0 * (1.0 + k * k) + (1.0 - v) / 2.0 * k);
        assert!((envelope_ratio(&sd, f, zeta) - want).abs() < 1e-12);
        assert!(want < v && want > 0.8 * v);
    }

    /// The defining property of the multi-hump EI shapers (Singhose, Seering and Singer 1997),
    /// independent of their closed forms: over their band the undamped residual rises to exactly
    /// `v_tol` at two (three) humps, one of them at the design frequency for the three-hump
    /// shaper and zero there for the two-hump one, and stays below `v_tol` in between; each band
    /// is wider than the one before (EI 0.40, two-hump 0.72, three-hump 0.96 of the design
    /// frequency at 5 %).
    #[test]
    fn multi_hump_shapers_touch_their_tolerance_at_every_hump() {
        let f = 4.0;
        for (kind, humps, width) in [
            (ShaperKind::Ei, 1, 0.399),
            (ShaperKind::TwoHumpEi, 2, 0.724),
            (ShaperKind::ThreeHumpEi, 3, 0.963),
        ] {
            for v in [0.05, 0.1] {
                let s = single(kind, f, 0.0, v);
                assert_eq!(s.len(), humps + 2);
                let curve = |r: f64| envelope_ratio(&s, f * r, 0.0);
                // the band of residual <= v around the design frequency
                let (mut lo, mut hi) = (1.0, 1.0);
                while curve(lo - 1e-4) <= v + 1e-12 {
                    lo -= 1e-4;
                }
                while curve(hi + 1e-4) <= v + 1e-12 {
                    hi += 1e-4;
                }
                let grid: Vec<f64> = (0..=2000).map(|k| lo + (hi - lo) * k as f64 / 2000.0).collect();
                let peaks: Vec<f64> = grid
                    .windows(3)
                    .filter(|w| curve(w[1]) >= curve(w[0]) && curve(w[1]) > curve(w[2]))
                    .map(|w| w[1])
                    .collect();
                assert_eq!(peaks.len(), humps, "{kind:?} v = {v}: humps at {peaks:?}");
                for p in &peaks {
                    // the hump's top, refined by golden-section-free bisection on the slope
                    let (mut a, mut b) = (p - 2e-3, p + 2e-3);
                    for _ in 0..60 {
                        let m = 0.5 * (a + b);
                        if curve(m + 1e-9) > curve(m - 1e-9) {
                            a = m;
                        } else {
                            b = m;
                        }
                    }
                    let top = curve(0.5 * (a + b));
                    assert!((top - v).abs() < 1e-9, "{kind:?} v = {v}: hump {top} at r = {a}");
                }
                if v == 0.05 {
                    assert!((hi - lo - width).abs() < 2e-3, "{kind:?}: band {lo}..{hi}");
                }
                match kind {
                    ShaperKind::TwoHumpEi => assert!(curve(1.0) < 1e-12),
                    _ => assert!((curve(1.0) - v).abs() < 1e-12),
                }
            }
        }
    }

    /// Eq. H3 against what it promises and against the closed forms it must not lose to: the
    /// residual (section 3.2's formula, checked against the closed forms below) at most v_tol on
    /// 1001 frequencies of the band; no longer than the EI shaper for a band inside EI's own
    /// (+-15 % at 5 %: EI covers +-20 %), no longer than ZV's half period for a band inside ZV's
    /// (+-2 %: ZV covers +-3.2 %); damped too.
    #[test]
    fn specified_insensitivity_meets_its_band_no_later_than_the_closed_forms() {
        let f = 4.0;
        for (zeta, x, v, longest) in [
            (0.0, 0.15, 0.05, 1.0),
            (0.0, 0.02, 0.05, 0.5),
            (0.05, 0.3, 0.05, 2.0),
            (0.0, 0.5, 0.02, 4.0),
        ] {
            let band = (f * (1.0 - x), f * (1.0 + x));
            let s = specified_insensitivity(f, zeta, band, v).unwrap();
            let t_d = 1.0 / (f * (1.0 - zeta * zeta).sqrt());
            assert!((s.iter().map(|p| p.a).sum::<f64>() - 1.0).abs() < 1e-12 && s.iter().all(|p| p.a >= 0.0));
            let worst = (0..=1000)
                .map(|k| residual(&s, band.0 + (band.1 - band.0) * k as f64 / 1000.0, zeta))
                .fold(0.0, f64::max);
            eprintln!(
                "+-{x} at zeta {zeta}, v {v}: {} impulses over {:.3} T_d, worst residual {worst:.5}",
                s.len(),
                duration(&s) / t_d
            );
            assert!(worst <= v * (1.0 + 1e-4), "+-{x}: {worst}");
            assert!(
                duration(&s) <= longest * t_d + 1e-12,
                "+-{x}: {} periods",
                duration(&s) / t_d
            );
        }
        assert!(specified_insensitivity(f, 0.0, (0.4, 7.6), 0.01)
            .unwrap_err()
            .to_string()
            .contains("shaper.insensitivity"));
    }

    #[test]
    fn the_band_is_read_relative_or_in_hz_and_checked() {
        let mut s = ShaperSection::new(ShaperKind::Si, &[4.0]);
        assert_eq!(s.band(4.0, 1).unwrap(), (3.2, 4.8));
        s.insensitivity = Some(toml::Value::String("+-10 %".into()));
        let (lo, hi) = s.band(4.0, 2).unwrap();
        assert!((lo - 3.6).abs() < 1e-12 && (hi - 4.4).abs() < 1e-12);
        s.insensitivity = Some(toml::Value::Array(vec![
            toml::Value::Float(3.5),
            toml::Value::Float(4.6),
        ]));
        assert_eq!(s.band(4.0, 1).unwrap(), (3.5, 4.6));
        for (value, n, why) in [
            (
                toml::Value::Array(vec![toml::Value::Float(4.5), toml::Value::Float(5.0)]),
                1,
                "contain",
            ),
            (
                toml::Value::Array(vec![toml::Value::Float(3.5), toml::Value::Float(4.5)]),
                2,
                "one frequency",
            ),
            (toml::Value::String("10 %".into()), 1, "+-x %"),
            (toml::Value::String("+-150 %".into()), 1, "0 < x < 100"),
            (toml::Value::Float(0.2), 1, "+-x %"),
        ] {
            s.insensitivity = Some(value);
            let e = s.band(4.0, n).unwrap_err().to_string();
            assert!(e.contains("shaper.insensitivity") && e.contains(why), "{e}");
        }
        let mut z = ShaperSection::new(ShaperKind::Zvd, &[4.0]);
        z.insensitivity = Some(toml::Value::String("+-10 %".into()));
        assert!(z
            .resolve(&[4.0], |_| 0.0)
            .unwrap_err()
            .to_string()
            .contains("kind = \"si\" only"));
    }

    #[test]
    fn sensitivity_matches_the_closed_forms() {
        let f = 4.0;
        for k in 0..=60 {
            let r = 0.4 + k as f64 * 0.02;
            let c = (PI * r / 2.0).cos();
            let ei = ((1.0 - EI_V_TOL) / 2.0 + (1.0 + EI_V_TOL) / 2.0 * (PI * r).cos()).abs();
            for (kind, want) in [
                (ShaperKind::Zv, c.abs()),
                (ShaperKind::Zvd, c * c),
                (ShaperKind::Ei, ei),
            ] {
                let s = single(kind, f, 0.0, EI_V_TOL);
                let got = envelope_ratio(&s, f * r, 0.0);
                assert!((got - want).abs() < 1e-12, "{kind:?} r = {r}: {got} vs {want}");
                assert!((residual(&s, f * r, 0.0) - want).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn convolved_shapers_cancel_every_design_mode() {
        let modes = [(3.85, 0.01), (6.8, 0.02), (11.4, 0.0)];
        for kind in [ShaperKind::Zv, ShaperKind::Zvd] {
            let s = multi(kind, &modes, 0.0);
            assert!((s.iter().map(|p| p.a).sum::<f64>() - 1.0).abs() < 1e-14);
            let per: f64 = modes.iter().map(|&(f, z)| duration(&single(kind, f, z, 0.0))).sum();
            assert!((duration(&s) - per).abs() < 1e-14);
            for &(f, z) in &modes {
                assert!(envelope_ratio(&s, f, z) < 1e-12, "{kind:?} {f}");
            }
        }
        assert_eq!(multi(ShaperKind::Zvd, &modes[..2], 0.0).len(), 9);
        assert_eq!(multi(ShaperKind::Zv, &[], 0.0), vec![Impulse { t: 0.0, a: 1.0 }]);
    }

    #[test]
    fn section_values_are_checked_by_key() {
        let mut s = ShaperSection::new(ShaperKind::Zv, &[3.9]);
        assert_eq!(s.frequency_spec().unwrap(), FrequencySpec::Given(vec![3.9]));
        s.f_hz = toml::Value::Float(-3.0);
        assert!(s.frequency_spec().unwrap_err().to_string().contains("shaper.f_hz"));
        s.f_hz = toml::Value::String("often".into());
        assert!(s.frequency_spec().is_err());
        s.f_hz = toml::Value::Array(vec![]);
        assert!(s.frequency_spec().is_err());
        s.zeta = Some(toml::Value::Float(1.0));
        assert!(s
            .zetas(&[3.9], |_| 0.0)
            .unwrap_err()
            .to_string()
            .contains("shaper.zeta"));
        s.zeta = Some(toml::Value::Array(vec![toml::Value::Float(0.1)]));
        assert!(s.zetas(&[3.9, 6.8], |_| 0.0).is_err());
        s.zeta = None;
        assert_eq!(s.zetas(&[2.0], |f| 0.01 * f).unwrap(), vec![0.02]);
        s.v_tol = Some(0.05);
        assert!(s.v_tol().unwrap_err().to_string().contains("shaper.v_tol"));
    }
}
