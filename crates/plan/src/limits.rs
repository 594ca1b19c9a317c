//! The limits of a plan (`docs/motions.md` 4.4, 4.8): the slider speeds and accelerations of a
//! motion, exact from the jets of the rigid inverse kinematics; the shortest duration the limits
//! allow any rest-to-rest motion; and the refusal of limits the plain quintic already breaks.

use flexstar_model::geometry::inverse_kinematics;
use flexstar_model::trajectory::Jet;
use flexstar_model::{ModelError, RobotParams, Trajectory};

use crate::family::Family;
use crate::section::Limits;

/// The largest value of one quantity over a motion, where and for which slider.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Peak {
    /// The value (|s'| [m/s], |s''| [m/s^2] or |Fa| [N]).
    pub value: f64,
    /// Slider 1..3.
    pub slider: usize,
    /// Time [s].
    pub t: f64,
}

impl Peak {
    fn none() -> Self {
        Peak {
            value: 0.0,
            slider: 1,
            t: 0.0,
        }
    }

    fn take(&mut self, value: f64, slider: usize, t: f64) {
        if value > self.value {
            *self = Peak { value, slider, t };
        }
    }
}

/// The slider jets `(s_i, s_i', s_i'')` of `traj` over `[t0, t1]`, sampled every `step` [s]
/// and at `extra` times (the knots), with their times.
pub fn slider_samples(
    params: &RobotParams,
    traj: &Trajectory,
    (t0, t1): (f64, f64),
    step: f64,
    extra: &[f64],
) -> Result<Vec<(f64, [Jet; 3])>, ModelError> {
    let n = ((t1 - t0) / step).ceil() as usize;
    (0..=n)
        .map(|k| (t0 + k as f64 * step).min(t1))
        .chain(extra.iter().copied())
        .map(|t| Ok((t, traj.jets(params, t)?)))
        .collect()
}

/// The peaks of `|s_i'|` and `|s_i''|` over samples of [`slider_samples`].
pub fn peaks_of(samples: &[(f64, [Jet; 3])]) -> (Peak, Peak) {
    let (mut v, mut a) = (Peak::none(), Peak::none());
    for (t, jets) in samples {
        for (i, jet) in jets.iter().enumerate() {
            v.take(jet.d1.abs(), i + 1, *t);
            a.take(jet.d2.abs(), i + 1, *t);
        }
    }
    (v, a)
}

/// The peaks of `|s_i'|` and `|s_i''|` of `traj` over `[t0, t1]` ([`slider_samples`]).
pub fn kinematic_peaks(
    params: &RobotParams,
    traj: &Trajectory,
    span: (f64, f64),
    step: f64,
    extra: &[f64],
) -> Result<(Peak, Peak), ModelError> {
    Ok(peaks_of(&slider_samples(params, traj, span, step, extra)?))
}

/// The slider travels `|s_i(to) - s_i(from)|` [m] of a move (rigid inverse kinematics).
pub fn travels(params: &RobotParams, family: &Family) -> Result<[f64; 3], ModelError> {
    let ik = |p: flexstar_model::Pose| inverse_kinematics(params, [p.gx, p.gy], p.theta);
    let (a, b) = (ik(family.from)?, ik(family.to)?);
    Ok([0, 1, 2].map(|i| (b[i] - a[i]).abs()))
}

/// The fastest rest-to-rest motion of one axis over `delta` [m] under `|s''| <= a_max` and
/// `|s'| <= v_max` (bang-bang, or bang-coast-bang when the speed limit is reached): no motion of
/// any shape does better (`docs/motions.md` 4.8).
pub fn fastest_axis_move(delta: f64, v_max: Option<f64>, a_max: Option<f64>) -> f64 {
    match (v_max, a_max) {
        (None, None) => 0.0,
        (Some(v), None) => delta / v,
        (None, Some(a)) => 2.0 * (delta / a).sqrt(),
        (Some(v), Some(a)) if delta <= v * v / a => 2.0 * (delta / a).sqrt(),
        (Some(v), Some(a)) => delta / v + v / a,
    }
}

/// The shortest move the limits allow (the largest over the sliders of
/// [`fastest_axis_move`]), with the slider and its travel.
pub fn shortest_move(travel: [f64; 3], limits: &Limits) -> (f64, usize, f64) {
    (0..3)
        .map(|i| {
            (
                fastest_axis_move(travel[i], limits.v_max, limits.a_max),
                i + 1,
                travel[i],
            )
        })
        .fold((0.0, 1, 0.0), |best, c| if c.0 > best.0 { c } else { best })
}

/// Refuse a `t_move` shorter than the limits allow (key `plan.t_move`).
pub fn check_t_move(t_move: f64, travel: [f64; 3], limits: &Limits) -> Result<(), ModelError> {
    let (t_min, slider, delta) = shortest_move(travel, limits);
    if t_move >= t_min {
        return Ok(());
    }
    let mut with = Vec::new();
    if let Some(a) = limits.a_max {
        with.push(format!("a_max = {a} m/s^2"));
    }
    if let Some(v) = limits.v_max {
        with.push(format!("v_max = {v} m/s"));
    }
    Err(ModelError::invalid(
        "plan.t_move",
        format!(
            "{t_move} s is shorter than the limits allow: slider {slider} travels {:.1} mm, which with {} takes at least {t_min:.3} s",
            1e3 * delta,
            with.join(" and ")
        ),
    ))
}

/// Refuse slider limits that the plain quintic of duration `t_move` already breaks, with the
/// shortest quintic within them (`|s'|` scales as `1/T`, `|s''|` as `1/T^2` at a fixed path).
pub fn check_quintic_kinematics(t_move: f64, peaks: (Peak, Peak), limits: &Limits) -> Result<(), ModelError> {
    let (v, a) = peaks;
    let t_v = limits.v_max.map_or(0.0, |m| t_move * v.value / m);
    let t_a = limits.a_max.map_or(0.0, |m| t_move * (a.value / m).sqrt());
    let t_min = t_v.max(t_a);
    let checks = [
        ("limits.a_max", "|s''|", "m/s^2", a, limits.a_max),
        ("limits.v_max", "|s'|", "m/s", v, limits.v_max),
    ];
    for (key, what, unit, peak, max) in checks {
        if let Some(max) = max.filter(|m| peak.value > *m) {
            return Err(ModelError::invalid(
                key,
                quintic_breaks(t_move, what, unit, peak, max, Some(t_min)),
            ));
        }
    }
    Ok(())
}

/// The message of a limit the plain quintic breaks; `t_min` the shortest quintic within the
/// limits when known.
pub fn quintic_breaks(t_move: f64, what: &str, unit: &str, peak: Peak, max: f64, t_min: Option<f64>) -> String {
    let name = match what {
        "|s''|" => "a_max",
        "|s'|" => "v_max",
        _ => "Fa_max",
    };
    let tail = t_min.map_or(String::new(), |t| {
        format!("; a quintic within the limits needs t_move >= {t:.3} s")
    });
    format!(
        "the plain quintic in t_move = {t_move} s reaches {what} = {:.3} {unit} (slider {}, t = {:.3} s), {:.0} % above {name} = {max} {unit}{tail}",
        peak.value,
        peak.slider,
        peak.t,
        100.0 * (peak.value / max - 1.0)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bang-bang time of a double integrator, and its bang-coast-bang form: the coast phase
    /// starts exactly where the speed limit is reached (continuity at `delta = v^2 / a`).
    #[test]
    fn fastest_axis_move_is_the_textbook_minimum_time() {
        // 0.1 m at 2 m/s^2: t = 2 sqrt(0.05) = 0.4472 s, top speed a t / 2 = 0.447 m/s
        assert!((fastest_axis_move(0.1, None, Some(2.0)) - 0.447_213_595_5).abs() < 1e-9);
        assert!((fastest_axis_move(0.1, Some(0.5), Some(2.0)) - 0.447_213_595_5).abs() < 1e-9);
        // with v_max = 0.2: 0.1 / 0.2 + 0.2 / 2 = 0.6 s
        assert!((fastest_axis_move(0.1, Some(0.2), Some(2.0)) - 0.6).abs() < 1e-12);
        let (v, a) = (0.3, 1.5);
        let d = v * v / a;
        let left = fastest_axis_move(d * (1.0 - 1e-12), Some(v), Some(a));
        let right = fastest_axis_move(d * (1.0 + 1e-12), Some(v), Some(a));
        assert!((left - right).abs() < 1e-9);
    }
}
