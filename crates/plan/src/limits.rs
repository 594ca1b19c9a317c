//! The limits of a plan (`docs/motions.md` 4.4, 4.8): the slider speeds and accelerations of a
//! motion, exact from the jets of the rigid inverse kinematics; the shortest duration the limits
//! allow any rest-to-rest motion; and the refusal of limits the plain quintic already breaks.

use flexstar_model::geometry::inverse_kinematics;
use flexstar_model::trajectory::Jet4;
use flexstar_model::{ModelError, RobotParams, Trajectory};

use crate::family::Family;
use crate::section::Limits;

/// The largest value of one quantity over a motion, where and for which slider.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Peak {
    /// The value (|s'| [m/s], |s''| [m/s^2], |s'''| [m/s^3] or |Fa| [N]).
    pub value: f64,
    /// Slider 1..3.
    pub slider: usize,
    /// Time [s].
    pub t: f64,
}

impl Peak {
    /// No value yet (zero, slider 1, t = 0).
    pub fn none() -> Self {
        Peak {
            value: 0.0,
            slider: 1,
            t: 0.0,
        }
    }

    /// Keep `value` of `slider` at `t` if it is the largest so far.
    pub fn take(&mut self, value: f64, slider: usize, t: f64) {
        if value > self.value {
            *self = Peak { value, slider, t };
        }
    }
}

/// Where the samples of a motion over `[t0, t1]` fall: every `step` [s] from `t0`, the end `t1`,
/// the `extra` times (the knots), and just inside both ends (`t0 + eps`, `t1 - eps`, `eps` =
/// 1e-9 of the span): the jerk of a rest-to-rest quintic jumps at its ends, where a sample at
/// the end itself takes the resting side (`docs/motions.md` 4.10).
pub fn sample_times(t0: f64, t1: f64, step: f64, extra: &[f64]) -> Vec<f64> {
    let n = ((t1 - t0) / step).ceil() as usize;
    let eps = 1e-9 * (t1 - t0);
    (0..=n)
        .map(|k| (t0 + k as f64 * step).min(t1))
        .chain(extra.iter().copied())
        .chain([t0 + eps, t1 - eps])
        .collect()
}

/// The slider jets `(s_i, s_i', s_i'', s_i''', s_i'''')` of `traj` at the [`sample_times`] of
/// `[t0, t1]`, with their times (exact, `Trajectory::jets4`).
pub fn slider_samples(
    params: &RobotParams,
    traj: &Trajectory,
    (t0, t1): (f64, f64),
    step: f64,
    extra: &[f64],
) -> Result<Vec<(f64, [Jet4; 3])>, ModelError> {
    sample_times(t0, t1, step, extra)
        .into_iter()
        .map(|t| Ok((t, traj.jets4(params, t)?)))
        .collect()
}

/// The kinematic peaks of a motion: `|s_i'|` [m/s], `|s_i''|` [m/s^2], `|s_i'''|` [m/s^3].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KinematicPeaks {
    pub v: Peak,
    pub a: Peak,
    pub j: Peak,
}

/// The peaks of `|s_i'|`, `|s_i''|` and `|s_i'''|` over samples of [`slider_samples`].
pub fn peaks_of(samples: &[(f64, [Jet4; 3])]) -> KinematicPeaks {
    let (mut v, mut a, mut j) = (Peak::none(), Peak::none(), Peak::none());
    for (t, jets) in samples {
        for (i, jet) in jets.iter().enumerate() {
            v.take(jet.d1.abs(), i + 1, *t);
            a.take(jet.d2.abs(), i + 1, *t);
            j.take(jet.d3.abs(), i + 1, *t);
        }
    }
    KinematicPeaks { v, a, j }
}

/// The peaks of `|s_i'|`, `|s_i''|`, `|s_i'''|` of `traj` over `[t0, t1]` ([`slider_samples`]).
pub fn kinematic_peaks(
    params: &RobotParams,
    traj: &Trajectory,
    span: (f64, f64),
    step: f64,
    extra: &[f64],
) -> Result<KinematicPeaks, ModelError> {
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
/// shortest quintic within them (`|s'|` scales as `1/T`, `|s''|` as `1/T^2`, `|s'''|` as `1/T^3`
/// at a fixed path: `docs/motions.md` 4.8, 4.10).
pub fn check_quintic_kinematics(t_move: f64, peaks: KinematicPeaks, limits: &Limits) -> Result<(), ModelError> {
    let KinematicPeaks { v, a, j } = peaks;
    let t_v = limits.v_max.map_or(0.0, |m| t_move * v.value / m);
    let t_a = limits.a_max.map_or(0.0, |m| t_move * (a.value / m).sqrt());
    let t_j = limits.j_max.map_or(0.0, |m| t_move * (j.value / m).cbrt());
    let t_min = t_v.max(t_a).max(t_j);
    let checks = [
        ("limits.a_max", "|s''|", "m/s^2", a, limits.a_max),
        ("limits.j_max", "|s'''|", "m/s^3", j, limits.j_max),
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
        "|s'''|" => "j_max",
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
    use crate::planner::{family_of, knot_times};
    use crate::section::plan_config_from_str;

    fn centre() -> crate::section::PlanConfig {
        let text =
            "name = \"t\"\n[time]\nt_end = 1.5\ndt_out = 0.001\n[plan]\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\n\
                    to = { Gx = 0.03, Gy = -0.02, theta = 0.2 }\nt_move = 0.42\n";
        plan_config_from_str(text, std::path::Path::new("t.toml")).unwrap()
    }

    /// The slider jerk of the plain quintic just inside its ends is `J(q) (q_to - q_from) 60 /
    /// T^3` (there `q' = q'' = 0`, so `s''' = J q'''` and `b'''(0) = b'''(1) = 60`), with the
    /// Jacobian `J = ds/dq` of the inverse kinematics by central differences: the sampled peak
    /// catches the jump (`docs/motions.md` 4.10) and is at least the larger end value.
    #[test]
    fn the_quintic_jerk_at_its_ends_is_the_analytic_jump() {
        let cfg = centre();
        let family = family_of(&cfg);
        let t: f64 = 0.42;
        let ik = |q: [f64; 3]| inverse_kinematics(&cfg.exp.robot, [q[0], q[1]], q[2]).unwrap();
        let (a, b) = ([0.0, 0.0, 0.0], [0.03, -0.02, 0.2]);
        let dq: Vec<f64> = (0..3).map(|k| b[k] - a[k]).collect();
        let end_jerk = |q: [f64; 3]| {
            let h = 1e-6;
            let (p, m) = (
                ik([0, 1, 2].map(|k| q[k] + h * dq[k])),
                ik([0, 1, 2].map(|k| q[k] - h * dq[k])),
            );
            [0, 1, 2].map(|i| (p[i] - m[i]) / (2.0 * h) * 60.0 / t.powi(3))
        };
        let traj = family.quintic(t);
        let start = traj.jets4(&cfg.exp.robot, 1e-9).unwrap();
        let end = traj.jets4(&cfg.exp.robot, t - 1e-9).unwrap();
        let (js, je) = (end_jerk(a), end_jerk(b));
        for i in 0..3 {
            assert!(
                (start[i].d3 - js[i]).abs() < 1e-6 * js[i].abs().max(1.0),
                "{i}: {} vs {}",
                start[i].d3,
                js[i]
            );
            assert!(
                (end[i].d3 - je[i]).abs() < 1e-6 * je[i].abs().max(1.0),
                "{i}: {} vs {}",
                end[i].d3,
                je[i]
            );
        }
        let peaks = kinematic_peaks(&cfg.exp.robot, &traj, (0.0, t), 1e-3, &knot_times(&family, t)).unwrap();
        let ends = js.iter().chain(&je).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(peaks.j.value >= ends * (1.0 - 1e-6), "{} vs {ends}", peaks.j.value);
    }

    /// A `j_max` below the plain quintic's jerk is refused with the excess, and the shortest
    /// quintic it names (`T (j / j_max)^(1/3)`) reaches exactly `j_max` when sampled afresh at
    /// that duration (a second computation of the jerk scaling law).
    #[test]
    fn a_jerk_limit_the_quintic_breaks_names_the_shortest_quintic_within_it() {
        let cfg = centre();
        let family = family_of(&cfg);
        let peaks_at = |t: f64| kinematic_peaks(&cfg.exp.robot, &family.quintic(t), (0.0, t), 1e-4, &[]).unwrap();
        let j_q = peaks_at(0.42).j.value;
        let limits = Limits {
            j_max: Some(0.8 * j_q),
            ..Limits::default()
        };
        let msg = check_quintic_kinematics(0.42, peaks_at(0.42), &limits)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("limits.j_max") && msg.contains("25 % above j_max"),
            "{msg}"
        );
        let t_min = 0.42 * (1.0f64 / 0.8).cbrt();
        assert!(msg.contains(&format!("t_move >= {t_min:.3} s")), "{msg}");
        assert!((peaks_at(t_min).j.value / (0.8 * j_q) - 1.0).abs() < 1e-9);
        assert!(check_quintic_kinematics(
            0.42,
            peaks_at(0.42),
            &Limits {
                j_max: Some(j_q * 1.001),
                ..limits
            }
        )
        .is_ok());
    }

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
