//! Residual vibration and settling per dwell (`docs/motions.md` 2.5): the moves of a trajectory,
//! the dwells between them, and the measures of 2.2-2.3 (peak and RMS of |dG| and of the tips,
//! settling in the band) restricted to each dwell, from the fixed columns every solver writes.
//!
//! The measures are computed here again, not through [`crate::residual::residual_after`], so that
//! the last dwell, whose window is `residual_after`'s, is a check of both (the equality is tested
//! through the binary, `tests/residual.rs`).

use crate::friction_rest::FrictionRest;
use flexstar_model::sidecar::DwellKeys;
use flexstar_model::{Response, Trajectory};

use crate::residual::dg_magnitude;

/// Tolerance [s] of a time comparison between output times and the motion's times (the output
/// grid is built by multiplication, so an output time meant to equal a via point's may differ in
/// the last bits).
const TIME_EPS: f64 = 1e-12;

/// The intervals `(start, end)` [s] in which the trajectory moves, in time order
/// (`docs/motions.md` 2.5): a quintic's `[t0, t1]`; a `via` with `rest = true`, each segment
/// between consecutive points whose poses differ (an equal pose is a dwell); one move from the
/// first to the last point or row for a `via` with `rest = false` and a `table` (they do not stop
/// in between); a shaped motion, each move of its base lengthened by the shaper's duration, moves
/// that then overlap merged. None for a polynomial (it never comes to rest) or a table not read.
pub fn moves(traj: &Trajectory) -> Vec<(f64, f64)> {
    match traj {
        Trajectory::Polynomial { .. } => Vec::new(),
        Trajectory::Quintic { t0, t1, .. } => vec![(*t0, *t1)],
        Trajectory::Via(v) if v.rest => v
            .points
            .windows(2)
            .filter(|p| (p[0].gx, p[0].gy, p[0].theta) != (p[1].gx, p[1].gy, p[1].theta))
            .map(|p| (p[0].t, p[1].t))
            .collect(),
        Trajectory::Via(_) | Trajectory::Table(_) => match traj.t_rest() {
            Some(t_rest) => vec![(traj.t_start(), t_rest)],
            None => Vec::new(),
        },
        Trajectory::Shaped(sh) => {
            let d = flexstar_model::shaper::duration(&sh.impulses);
            let mut out: Vec<(f64, f64)> = Vec::new();
            for (a, b) in moves(&sh.base) {
                match out.last_mut() {
                    // the base's next move starts before this one's shaped tail has ended
                    Some(last) if a < last.1 => last.1 = last.1.max(b + d),
                    _ => out.push((a, b + d)),
                }
            }
            out
        }
    }
}

/// One dwell: the move before it `[move_start, move_end]` and the dwell `[move_end, t_end]` [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DwellWindow {
    /// 1-based number.
    pub dwell: usize,
    pub move_start: f64,
    /// The end of the move, the start of the dwell [s].
    pub move_end: f64,
    /// The end of the dwell [s]: the next move's start or the run's last output time.
    pub t_end: f64,
}

/// The dwells after `moves` (from [`moves`]) in a run that ends at `t_end` [s] (the last output
/// time): one after every move that ends before `t_end`, to the next move's start or `t_end`.
pub fn dwell_windows(moves: &[(f64, f64)], t_end: f64) -> Vec<DwellWindow> {
    moves
        .iter()
        .enumerate()
        .take_while(|(_, m)| m.1 < t_end - TIME_EPS)
        .map(|(k, &(a, b))| DwellWindow {
            dwell: k + 1,
            move_start: a,
            move_end: b,
            t_end: moves.get(k + 1).map_or(t_end, |next| next.0.min(t_end)),
        })
        .collect()
}

/// What [`dwell_residual`] measures |dG| and the tips about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Baseline {
    /// The response's `rest_offset` (the static sag at the final pose under gravity; zero
    /// without gravity): the dwell is at the final pose, or the run has no gravity.
    RestPose,
    /// Under gravity at a pose other than the final one: the sag there is not known, so the dwell
    /// is not measured (motions.md 2.5).
    Unknown,
}

/// The residual of `r` in the dwell `w` (`docs/motions.md` 2.5), in the band `settle_tol` [m],
/// with the hold `hold` [s] (one period of the first mode at the dwell's pose). `g_pinned`: the
/// run's modes pin G (pinned-free AMM), so the G measures and the settling are null. A dwell
/// holding fewer than two output times is listed with null measures and a note.
pub fn dwell_residual(
    r: &Response,
    w: &DwellWindow,
    settle_tol: f64,
    hold: f64,
    baseline: Baseline,
    g_pinned: bool,
) -> DwellKeys {
    let mut keys = DwellKeys {
        dwell: w.dwell,
        move_start: w.move_start,
        move_end: w.move_end,
        t_start: w.move_end,
        t_end: w.t_end,
        g_peak_m: None,
        g_rms_m: None,
        tip_peak_m: None,
        tip_rms_m: None,
        settle_s: None,
        settled: None,
        settle_hold_s: Some(hold),
        note: None,
    };
    let (t0, t1) = (w.move_end, w.t_end);
    let rows: Vec<usize> = (0..r.len())
        .filter(|&k| r.t[k] >= t0 - TIME_EPS && r.t[k] <= t1 + TIME_EPS)
        .collect();
    if rows.len() < 2 {
        let step = r.t.windows(2).map(|p| p[1] - p[0]).next().unwrap_or(f64::NAN);
        keys.note = Some(if t1 - t0 <= TIME_EPS {
            "no dwell: the next move starts as this one ends; not measured".to_string()
        } else {
            format!(
                "the dwell lasts {} s, less than the output step {} s: not measured",
                flexstar_io::output::fmt_sig(t1 - t0, 4),
                flexstar_io::output::fmt_sig(step, 4)
            )
        });
        return keys;
    }
    if baseline == Baseline::Unknown {
        keys.note = Some(
            "under gravity the static sag at this dwell's pose is not computed (only at the final pose): \
             not measured"
                .to_string(),
        );
        return keys;
    }
    // with friction about the rest state the dwell ends in, once every sleeve has stuck
    // (docs/friction.md 5)
    let rest = crate::friction_rest::friction_rest_before(r, t1, hold);
    let offset = match rest {
        Some(FrictionRest::Stuck(o)) => o,
        _ => r.rest_offset.unwrap_or_default(),
    };
    let t: Vec<f64> = rows.iter().map(|&k| r.t[k]).collect();
    let dg: Vec<f64> = rows
        .iter()
        .map(|&k| dg_magnitude([0, 1, 2].map(|i| r.w_g[i][k] - offset.w_g[i])))
        .collect();
    let tip = |i: usize, k: usize| r.w_tip[i][k] - offset.w_tip[i];
    let tip_mean: Vec<f64> = rows
        .iter()
        .map(|&k| ((0..3).map(|i| tip(i, k).powi(2)).sum::<f64>() / 3.0).sqrt())
        .collect();
    keys.tip_peak_m = Some(
        rows.iter()
            .flat_map(|&k| (0..3).map(move |i| (i, k)))
            .fold(0.0f64, |m, (i, k)| m.max(tip(i, k).abs())),
    );
    keys.tip_rms_m = Some(trapezoid_rms(&t, &tip_mean));
    if g_pinned {
        keys.note = Some("G is pinned in this family".to_string());
        return keys;
    }
    keys.g_peak_m = Some(dg.iter().fold(0.0f64, |m, v| m.max(*v)));
    keys.g_rms_m = Some(trapezoid_rms(&t, &dg));
    // motions.md 2.3 within the dwell: the last excursion above the band, then a quiet hold
    let t_last = t
        .iter()
        .zip(&dg)
        .filter(|(_, d)| **d > settle_tol)
        .map(|(t, _)| *t)
        .next_back()
        .unwrap_or(t0);
    let t_stop = t[t.len() - 1];
    let settled = t_stop - t_last >= hold - TIME_EPS;
    keys.settled = Some(settled);
    keys.settle_s = settled.then_some(t_last);
    if !settled && t_stop - t0 < hold - TIME_EPS {
        keys.note = Some(format!(
            "the dwell ({} s) is shorter than one period of the first mode at its pose ({} s): too short to judge \
             settling",
            flexstar_io::output::fmt_sig(t_stop - t0, 4),
            flexstar_io::output::fmt_sig(hold, 4)
        ));
    }
    keys
}

/// `sqrt(1/(t_n - t_0) int f^2 dt)` by the trapezoidal rule over the samples (at least two).
fn trapezoid_rms(t: &[f64], f: &[f64]) -> f64 {
    let span = t[t.len() - 1] - t[0];
    if span <= 0.0 {
        return f[0].abs();
    }
    let sum: f64 = (1..t.len())
        .map(|k| 0.5 * (t[k] - t[k - 1]) * (f[k - 1] * f[k - 1] + f[k] * f[k]))
        .sum();
    (sum / span).sqrt()
}

/// One line per dwell for a report (`dwell 1, 0.4-0.7 s (after the move from 0 s): peak |dG| =
/// 1.234e-4 m, RMS 5.6e-5 m, peak |tip| = ..., settled at 0.612 s`).
pub fn dwell_text(d: &DwellKeys) -> String {
    let secs = |t: f64| flexstar_io::output::fmt_sig(t, 4);
    let head = format!(
        "dwell {}, {}-{} s (after the move from {} s)",
        d.dwell,
        secs(d.t_start),
        secs(d.t_end),
        secs(d.move_start)
    );
    let (Some(tip), Some(tip_rms)) = (d.tip_peak_m, d.tip_rms_m) else {
        return format!("{head}: {}", d.note.as_deref().unwrap_or("not measured"));
    };
    let g = match (d.g_peak_m, d.g_rms_m) {
        (Some(p), Some(rms)) => format!("peak |dG| = {p:.3e} m, RMS {rms:.3e} m"),
        _ => "|dG| n/a (G pinned)".to_string(),
    };
    let settle = match (d.settle_s, d.settled) {
        (Some(t), _) => format!("settled at {t:.3} s"),
        (None, Some(false)) => match &d.note {
            Some(n) => format!("not settled within the dwell: {n}"),
            None => "not settled within the dwell".to_string(),
        },
        _ => "settling n/a".to_string(),
    };
    format!("{head}: {g}, peak |tip| = {tip:.3e} m, RMS {tip_rms:.3e} m, {settle}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::motion::{ViaMotion, ViaPoint};
    use flexstar_model::Pose;

    fn via(points: &[(f64, f64)], rest: bool) -> Trajectory {
        let p = points
            .iter()
            .map(|&(t, gx)| ViaPoint {
                t,
                gx,
                gy: 0.0,
                theta: 0.0,
            })
            .collect();
        Trajectory::Via(ViaMotion::new(p, rest))
    }

    #[test]
    fn the_moves_of_each_kind() {
        let pose = |gx: f64| Pose {
            gx,
            gy: 0.0,
            theta: 0.0,
        };
        let q = Trajectory::Quintic {
            from: pose(0.0),
            to: pose(0.01),
            t0: 0.1,
            t1: 0.4,
        };
        assert_eq!(moves(&q), vec![(0.1, 0.4)]);
        // pick-and-place: out, dwell, back; then two moves back to back
        let cycle = via(&[(0.0, 0.0), (0.4, 0.03), (0.7, 0.03), (1.1, 0.0), (1.3, 0.01)], true);
        assert_eq!(moves(&cycle), vec![(0.0, 0.4), (0.7, 1.1), (1.1, 1.3)]);
        // the spline does not stop between its points
        let spline = via(&[(0.1, 0.0), (0.4, 0.03), (0.7, 0.03), (1.1, 0.0)], false);
        assert_eq!(moves(&spline), vec![(0.1, 1.1)]);
        assert!(moves(&Trajectory::quadratic([0.0; 3])).is_empty());
        // shaped: each move lengthened by the shaper's 0.5 s; the first then overlaps the second
        let shaped = |base: Trajectory| {
            Trajectory::Shaped(flexstar_model::trajectory::ShapedMotion {
                base: Box::new(base),
                impulses: vec![
                    flexstar_model::shaper::Impulse { a: 0.5, t: 0.0 },
                    flexstar_model::shaper::Impulse { a: 0.5, t: 0.5 },
                ],
            })
        };
        assert_eq!(moves(&shaped(cycle.clone())), vec![(0.0, 1.8)]);
        let apart = via(&[(0.0, 0.0), (0.4, 0.03), (1.0, 0.03), (1.4, 0.0)], true);
        assert_eq!(moves(&shaped(apart)), vec![(0.0, 0.9), (1.0, 1.9)]);
    }

    #[test]
    fn dwells_run_from_a_move_end_to_the_next_start_or_the_end_of_the_run() {
        let m = [(0.0, 0.4), (0.7, 1.1), (1.1, 1.3)];
        let w = dwell_windows(&m, 1.5);
        let spans: Vec<(usize, f64, f64, f64)> =
            w.iter().map(|d| (d.dwell, d.move_start, d.move_end, d.t_end)).collect();
        assert_eq!(spans, vec![(1, 0.0, 0.4, 0.7), (2, 0.7, 1.1, 1.1), (3, 1.1, 1.3, 1.5)]);
        // a move that ends at t_end has no dwell after it
        assert_eq!(dwell_windows(&m, 1.3).len(), 2);
    }

    /// A response whose |dG| is `g(t)` (a vector along x, projected on the frames of theta = 0)
    /// and whose three tips are `tip(t)`.
    fn response(ts: &[f64], g: impl Fn(f64) -> f64, tip: impl Fn(f64) -> f64) -> Response {
        let mut r = Response::with_capacity("x", ts.len());
        for &t in ts {
            let w_g: [f64; 3] = std::array::from_fn(|i| {
                let phi = i as f64 * 2.0 * std::f64::consts::PI / 3.0;
                -phi.sin() * g(t)
            });
            r.push(t, w_g, [tip(t); 3], [0.0; 3]);
        }
        r
    }

    fn grid(t_end: f64, dt: f64) -> Vec<f64> {
        (0..=(t_end / dt).round() as usize).map(|k| k as f64 * dt).collect()
    }

    #[test]
    fn each_dwell_has_the_peak_rms_and_settling_of_its_own_decaying_vibration() {
        // |dG| = A_k exp(-s (t - t_k)) |cos(w (t - t_k))| in dwell k (t_k its start), a large
        // value during the moves. Analytic: peak A_k at t_k; the band is left for good at the
        // last crest of |cos| before the envelope crosses it, t* = t_k + ln(A_k / tol) / s; over
        // a dwell of D = 0.6 s (2 w D a multiple of 2 pi) the mean square is exactly
        // A_k^2 (1 - exp(-2 s D)) / (4 s D) (1 + s^2 / (s^2 + w^2)).
        let (s, f, tol) = (6.0, 10.0, 1e-4);
        let w = 2.0 * std::f64::consts::PI * f;
        let dwells = [(0.4, 1.0, 2e-3), (1.4, 2.0, 5e-4)];
        let g = |t: f64| {
            for &(a, b, amp) in &dwells {
                if t >= a - 1e-12 && t <= b + 1e-12 {
                    return amp * (-s * (t - a)).exp() * (w * (t - a)).cos().abs();
                }
            }
            5e-2
        };
        let ts = grid(2.0, 1e-4);
        let r = response(&ts, g, |t| 0.5 * g(t));
        let windows = dwell_windows(&[(0.0, 0.4), (1.0, 1.4)], 2.0);
        assert_eq!(windows.len(), 2);
        let hold = 0.1;
        for (win, &(a, b, amp)) in windows.iter().zip(&dwells) {
            let d = dwell_residual(&r, win, tol, hold, Baseline::RestPose, false);
            assert_eq!((d.t_start, d.t_end), (a, b));
            assert!((d.g_peak_m.unwrap() - amp).abs() < 1e-15, "{d:?}");
            // tips: each 0.5 |dG|, so peak 0.5 A and RMS of the three 0.5 RMS(|dG|)
            assert!((d.tip_peak_m.unwrap() - 0.5 * amp).abs() < 1e-15);
            let span = b - a;
            let rms =
                amp * ((1.0 - (-2.0 * s * span).exp()) / (4.0 * s * span) * (1.0 + s * s / (s * s + w * w))).sqrt();
            let got = d.g_rms_m.unwrap();
            // cos^2 is smooth: the trapezoidal rule's error at 1e-4 s is about (2 w dt)^2 / 12
            assert!((got - rms).abs() < 1e-4 * rms, "rms {got} vs {rms}");
            assert!((d.tip_rms_m.unwrap() - 0.5 * got).abs() < 1e-12 * got);
            // the envelope crosses the band at t_env; the last sample above it is the last
            // crest of |cos| before that, within a half period
            let t_env = a + (amp / tol).ln() / s;
            let settle = d.settle_s.expect("settles");
            assert!(settle <= t_env && t_env - settle < 0.5 / f, "{settle} vs {t_env}");
            assert_eq!(d.settled, Some(true));
            assert!(d.note.is_none());
        }
        // the first dwell with a hold longer than its quiet end does not settle; a dwell shorter
        // than the hold says so
        let d = dwell_residual(&r, &windows[0], tol, 0.59, Baseline::RestPose, false);
        assert_eq!((d.settle_s, d.settled), (None, Some(false)));
        assert!(d.note.is_none(), "{d:?}");
        let d = dwell_residual(&r, &windows[0], tol, 0.7, Baseline::RestPose, false);
        assert_eq!((d.settle_s, d.settled), (None, Some(false)));
        assert!(d.note.as_deref().unwrap().contains("too short to judge"), "{d:?}");
        // pinned G: no G measures, the tips still
        let d = dwell_residual(&r, &windows[0], tol, hold, Baseline::RestPose, true);
        assert!(d.g_peak_m.is_none() && d.settled.is_none() && d.tip_peak_m.is_some());
        // under gravity at another pose: listed, not measured
        let d = dwell_residual(&r, &windows[0], tol, hold, Baseline::Unknown, false);
        assert!(d.g_peak_m.is_none() && d.tip_peak_m.is_none());
        assert!(d.note.unwrap().contains("gravity"));
    }

    #[test]
    fn a_dwell_shorter_than_the_output_step_is_listed_not_measured() {
        let ts = grid(1.0, 1e-3);
        let r = response(&ts, |t| 1e-3 * t, |_| 0.0);
        // 0.4 s to 0.4005 s holds the one output time 0.4; two moves back to back hold none
        let m = [(0.0, 0.4), (0.4005, 0.6), (0.6, 0.8)];
        let w = dwell_windows(&m, 1.0);
        let short = dwell_residual(&r, &w[0], 1e-4, 0.1, Baseline::RestPose, false);
        assert!(short.g_peak_m.is_none() && short.settled.is_none());
        let note = short.note.clone().unwrap();
        assert!(
            note.contains("0.0005 s") && note.contains("output step 0.001 s"),
            "{note}"
        );
        let zero = dwell_residual(&r, &w[1], 1e-4, 0.1, Baseline::RestPose, false);
        assert!(zero.note.unwrap().starts_with("no dwell"));
        assert!(dwell_text(&short).contains("less than the output step"));
        // the last dwell is measured: |dG| = 1e-3 t grows, so its peak is at t_end
        let last = dwell_residual(&r, &w[2], 1e-4, 0.1, Baseline::RestPose, false);
        assert!((last.g_peak_m.unwrap() - 1e-3).abs() < 1e-15);
        assert_eq!(last.settled, Some(false));
    }
}
