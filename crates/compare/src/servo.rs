//! The servo of a `compare` whose experiment has `[drive] kind = "servo"`: its gains and how
//! closely each run's sliders followed the reference (the `[trajectory]`), as `compare.md`, the
//! report and the CLI show it.

use std::fmt::Write as _;

use flexstar_model::{DriveKind, Experiment, Feedforward, Response};

use crate::case_output::runs_of;
use crate::runs::CaseResults;

/// Tracking error of one run: `e_i = s_ref,i - s_i` over the three axes and every output time.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Tracking {
    /// Run file stem (`fem`, `amm-<label>`).
    pub run: String,
    /// Largest `|e_i|` [m].
    pub max_m: f64,
    /// Root mean square of `e_i` over the axes and the output times [m].
    pub rms_m: f64,
}

/// The servo of an experiment and the tracking error of every run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ServoSummary {
    /// Closed-loop bandwidth [Hz] and damping ratio, when the gains were given that way.
    pub bandwidth_hz: Option<f64>,
    pub damping_ratio: Option<f64>,
    /// The gains used [N/m], [N s/m] (slider 1's).
    pub kp: f64,
    pub kd: f64,
    /// Each slider's gains `[kp, kd]` when they differ (a robot as built whose sliders' masses
    /// differ, the gains from a bandwidth: `docs/as-built.md` 7); absent when all three are equal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub per_slider: Option<[[f64; 2]; 3]>,
    /// `rigid` (the rigid-body inverse dynamics of the reference) or `none`.
    pub feedforward: &'static str,
    /// Every run, the FEM first.
    pub tracking: Vec<Tracking>,
}

/// `max |e|` and the RMS of `e` over the columns `e1..e3` of `r` [m] (`NaN` without them).
pub fn tracking_error(r: &Response) -> (f64, f64) {
    let cols: Vec<&[f64]> = ["e1", "e2", "e3"].iter().filter_map(|c| r.column(c)).collect();
    let n = cols.iter().map(|c| c.len()).sum::<usize>();
    if cols.len() != 3 || n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let values = || cols.iter().flat_map(|c| c.iter());
    let max = values().fold(0.0f64, |m, e| m.max(e.abs()));
    let rms = (values().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    (max, rms)
}

/// The servo summary of a case, `None` unless the experiment's drive is a servo.
pub fn servo_summary(exp: &Experiment, case: &CaseResults) -> Option<ServoSummary> {
    if exp.drive.kind != DriveKind::Servo {
        return None;
    }
    let robot = flexstar_model::Robot::from_params(&exp.robot).ok()?;
    let gains = exp.drive.slider_gains(robot.beams().map(|b| b.sleeve_mass)).ok()?;
    let per_slider = gains.map(|g| [g.kp, g.kd]);
    let equal = per_slider.iter().all(|g| *g == per_slider[0]);
    let tracking = runs_of(case)
        .into_iter()
        .map(|(run, r)| {
            let (max_m, rms_m) = tracking_error(r);
            Tracking { run, max_m, rms_m }
        })
        .collect();
    Some(ServoSummary {
        bandwidth_hz: exp.drive.bandwidth_hz,
        damping_ratio: exp.drive.damping_ratio,
        kp: gains[0].kp,
        kd: gains[0].kd,
        per_slider: (!equal).then_some(per_slider),
        feedforward: match exp.drive.feedforward.unwrap_or_default() {
            Feedforward::Rigid => "rigid",
            Feedforward::None => "none",
        },
        tracking,
    })
}

impl ServoSummary {
    /// One line on the servo: bandwidth and damping (when given), gains, feedforward.
    pub fn gains_line(&self) -> String {
        let mut s = String::from("servo: ");
        if let (Some(f), Some(z)) = (self.bandwidth_hz, self.damping_ratio) {
            let _ = write!(s, "bandwidth {f} Hz, damping ratio {z}, so ");
        }
        match self.per_slider {
            None => {
                let _ = write!(s, "kp = {:.4e} N/m, kd = {:.4e} N s/m", self.kp, self.kd);
            }
            Some(g) => {
                for (i, [kp, kd]) in g.iter().enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    let _ = write!(s, "{sep}slider {}: kp = {kp:.4e} N/m, kd = {kd:.4e} N s/m", i + 1);
                }
            }
        }
        let _ = write!(s, "; feedforward {}", self.feedforward);
        s
    }

    /// One line per run: `tracking error <run>: max .. mm, RMS .. mm` (e = reference - slider).
    pub fn tracking_lines(&self) -> Vec<String> {
        self.tracking
            .iter()
            .map(|t| {
                format!(
                    "tracking error {}: max {:.4} mm, RMS {:.4} mm",
                    t.run,
                    t.max_m * 1e3,
                    t.rms_m * 1e3
                )
            })
            .collect()
    }

    /// The `## Servo` section of `compare.md` (Markdown).
    pub fn markdown(&self) -> String {
        let mut s = String::from("## Servo\n\n");
        let _ = writeln!(
            s,
            "{}. The sliders follow the `[trajectory]` as the servo's reference (drawn dashed in the \
             sliders figure); tracking error `e_i = s_ref,i - s_i` over the three axes and every output time:\n",
            capitalised(&self.gains_line())
        );
        s.push_str("| run | max abs(e) [mm] | RMS e [mm] |\n|---|---|---|\n");
        for t in &self.tracking {
            let _ = writeln!(s, "| {} | {:.4} | {:.4} |", t.run, t.max_m * 1e3, t.rms_m * 1e3);
        }
        s.push('\n');
        s
    }
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracking_error_is_the_max_and_rms_over_axes_and_times() {
        let mut r = Response::with_capacity("x", 2);
        r.push(0.0, [0.0; 3], [0.0; 3], [0.0; 3]);
        r.push(1.0, [0.0; 3], [0.0; 3], [0.0; 3]);
        r.set_extra(
            &["e1", "e2", "e3"],
            vec![vec![3e-3, 0.0], vec![0.0, -4e-3], vec![0.0, 0.0]],
        );
        let (max, rms) = tracking_error(&r);
        assert_eq!(max, 4e-3);
        assert!((rms - (25e-6f64 / 6.0).sqrt()).abs() < 1e-15);
        let (max, _) = tracking_error(&Response::with_capacity("y", 0));
        assert!(max.is_nan());
    }
}
