//! The page: the runs' frames as JSON in a `<script type="application/json">`, an inline SVG in
//! the fixed frame (mm) and a small script (`page.js`) that draws a frame and plays them.

use flexstar_model::RobotGeometry;
use serde_json::{json, Value};

use crate::read::RunFrames;
use crate::AnimateError;

const TEMPLATE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("page.js");

/// Frame times of two runs agree when they differ by at most this [s].
const TIME_TOL: f64 = 1e-9;

/// The default magnification M: the largest elastic displacement `|P - P_rigid|` over every
/// frame, beam point and run drawn as 10 % of the beam length L (1 when nothing deforms),
/// rounded down to two significant digits.
pub fn default_magnification(runs: &[RunFrames]) -> f64 {
    let l = beam_length(runs);
    let max = runs
        .iter()
        .flat_map(|r| r.beams.iter().flatten())
        .flat_map(|b| b.pos.iter().zip(&b.rigid))
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, f64::max);
    if max <= 0.0 || l <= 0.0 {
        return 1.0;
    }
    let m = 0.1 * l / max;
    let scale = 10f64.powf(m.log10().floor() - 1.0);
    ((m / scale).floor() * scale).max(f64::MIN_POSITIVE)
}

/// The beam length L [m]: the sidecar's, else the rigid beam from G to its tip in a frame.
fn beam_length(runs: &[RunFrames]) -> f64 {
    if let Some(l) = runs.iter().find_map(|r| r.l) {
        return l;
    }
    let b = runs.first().and_then(|r| r.beams.first()).map(|f| &f[0].rigid);
    match b {
        Some(p) if p.len() > 1 => {
            let (a, z) = (p[0], p[p.len() - 1]);
            (z[0] - a[0]).hypot(z[1] - a[1])
        }
        _ => 0.0,
    }
}

/// Refuse runs whose frame times differ (the error names the runs, their frame counts and
/// rates).
fn check_times(runs: &[RunFrames]) -> Result<(), AnimateError> {
    let first = &runs[0];
    for r in &runs[1..] {
        let same = r.times.len() == first.times.len()
            && r.times.iter().zip(&first.times).all(|(a, b)| (a - b).abs() <= TIME_TOL);
        if !same {
            let say = |r: &RunFrames| {
                let step = if r.times.len() > 1 {
                    r.times[1] - r.times[0]
                } else {
                    0.0
                };
                let rate = if step > 0.0 {
                    format!("{:.0}", 1.0 / step)
                } else {
                    "?".into()
                };
                format!("{} ({} frames, {rate} per second)", r.name, r.times.len())
            };
            return Err(AnimateError::TimesDiffer(format!(
                "{} and {}; run both with the same `frames` and `t_end`",
                say(first),
                say(r)
            )));
        }
    }
    Ok(())
}

/// Line colour of a run: the FEM black, the enriched AMM red (the study plots' colours), other
/// AMM families blue, green, orange.
fn colour(name: &str, k: usize) -> &'static str {
    if name.starts_with("fem") {
        "#000000"
    } else if name.starts_with("amm-enriched") {
        "#d62728"
    } else {
        ["#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd"][k % 4]
    }
}

fn micro(v: f64) -> i64 {
    (v * 1e6).round() as i64
}

/// One run as JSON: per frame and beam the rigid points (flat `x, y` in integer micrometres)
/// and the elastic part `P - P_rigid` (flat, integer nanometres).
fn run_json(r: &RunFrames, k: usize) -> Value {
    let rigid: Vec<Vec<Vec<i64>>> = (r.beams.iter())
        .map(|f| {
            f.iter()
                .map(|b| b.rigid.iter().flat_map(|p| [micro(p[0]), micro(p[1])]).collect())
                .collect()
        })
        .collect();
    let elastic: Vec<Vec<Vec<i64>>> = (r.beams.iter())
        .map(|f| {
            f.iter()
                .map(|b| {
                    (b.pos.iter().zip(&b.rigid))
                        .flat_map(|(p, q)| {
                            [
                                ((p[0] - q[0]) * 1e9).round() as i64,
                                ((p[1] - q[1]) * 1e9).round() as i64,
                            ]
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let g: Vec<[i64; 2]> = r.pose.iter().map(|p| [micro(p[0]), micro(p[1])]).collect();
    // the star's orientation per frame [microradians]: the payload turns with it
    let theta: Vec<i64> = r.pose.iter().map(|p| micro(p[2])).collect();
    json!({ "name": r.name, "colour": colour(&r.name, k), "rigid": rigid, "elastic": elastic, "G": g, "theta": theta })
}

/// The base triangle [um]: its three corners, where the sliders' axes meet (the end of each
/// slider's side, `docs/as-built.md` 2; `s_i = sqrt(3) d` on the paper's base); empty when the
/// sidecar does not give the robot.
fn base_json(r: &RunFrames) -> Value {
    let Some(robot) = &r.robot else {
        return json!([]);
    };
    let corners: Vec<[i64; 2]> = (0..3)
        .map(|i| robot.revolute_point(i, robot.slider_travel(i)[1]).map(micro))
        .collect();
    json!(corners)
}

/// The payload of the first run that has one: its mass [kg] and offset from G in the star's
/// frame [um]; `null` without one.
fn payload_json(runs: &[RunFrames]) -> Value {
    match runs.iter().find_map(|r| r.payload) {
        Some((mass, o)) => json!({ "mass": mass, "offset": [micro(o[0]), micro(o[1])] }),
        None => Value::Null,
    }
}

/// The rails (segments over the sliders' travel in this motion, a tenth of the base's size
/// beyond: `0.1 d` on the paper's base, d the in-radius) and the slider points per frame [um] of
/// the first run, when its sidecar gives the robot.
fn rails_json(r: &RunFrames) -> (Value, Value) {
    let Some(robot) = &r.robot else {
        return (json!([]), json!([]));
    };
    let rails: Vec<[i64; 4]> = (0..3)
        .map(|i| {
            let (lo, hi) = r
                .pose
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[3 + i]), b.max(p[3 + i])));
            // a side of the paper's base is 2 sqrt(3) d long
            let [a0, a1] = robot.slider_travel(i);
            let margin = 0.1 * (a1 - a0) / (2.0 * 3f64.sqrt());
            let (a, b) = (
                robot.revolute_point(i, lo - margin),
                robot.revolute_point(i, hi + margin),
            );
            [micro(a[0]), micro(a[1]), micro(b[0]), micro(b[1])]
        })
        .collect();
    let sliders: Vec<Vec<i64>> = (r.pose.iter())
        .map(|p| {
            (0..3)
                .flat_map(|i| robot.revolute_point(i, p[3 + i]).map(micro))
                .collect()
        })
        .collect();
    (json!(rails), json!(sliders))
}

/// The whole page of `runs` (frame times checked equal) at magnification `magnify` (default
/// [`default_magnification`]; the page's number field changes it).
pub fn build_page(runs: &[RunFrames], magnify: Option<f64>) -> Result<String, AnimateError> {
    check_times(runs)?;
    let m = magnify.unwrap_or_else(|| default_magnification(runs));
    let (rails, sliders) = rails_json(&runs[0]);
    let data = json!({
        "times": runs[0].times,
        "t_rest": runs.iter().find_map(|r| r.t_rest),
        "L_um": micro(beam_length(runs)),
        "magnify": m,
        "runs": runs.iter().enumerate().map(|(k, r)| run_json(r, k)).collect::<Vec<_>>(),
        "rails": rails,
        "sliders": sliders,
        "base": base_json(&runs[0]),
        "payload": payload_json(runs),
    });
    // `</` inside the JSON would end the script element; `<\/` is the same JSON string
    let text = data.to_string().replace("</", "<\\/");
    let names: Vec<&str> = runs.iter().map(|r| r.name.as_str()).collect();
    Ok(TEMPLATE
        .replace("@TITLE@", &escape(&names.join(" + ")))
        .replace("@DATA@", &text)
        .replace("@SCRIPT@", SCRIPT))
}

/// `&`, `<`, `>` of a text put into the HTML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::BeamPoints;

    /// A star of three straight beams along x at `t`, its beam 1 bent by `w` [m] at the tip.
    fn run(name: &str, times: &[f64], w: f64) -> RunFrames {
        let beam = |bend: f64| BeamPoints {
            rigid: vec![[0.0, 0.0], [0.25, 0.0], [0.5, 0.0]],
            pos: vec![[0.0, 0.0], [0.25, bend / 4.0], [0.5, bend]],
        };
        RunFrames {
            name: name.into(),
            times: times.to_vec(),
            beams: times.iter().map(|_| [beam(w), beam(0.0), beam(0.0)]).collect(),
            pose: times.iter().map(|_| [0.0; 6]).collect(),
            t_rest: None,
            l: Some(0.5),
            robot: None,
            payload: None,
            experiment: None,
        }
    }

    #[test]
    fn default_magnification_draws_the_largest_displacement_as_a_tenth_of_l() {
        // 2 mm at the tip: M = 0.05 m / 2 mm = 25
        let m = default_magnification(&[run("amm-enriched", &[0.0, 0.1], 0.002)]);
        assert!((m - 25.0).abs() < 1e-9, "{m}");
        assert_eq!(default_magnification(&[run("fem", &[0.0], 0.0)]), 1.0);
    }

    #[test]
    fn different_frame_times_are_refused_naming_both_runs() {
        let runs = [
            run("amm-enriched", &[0.0, 0.01, 0.02], 1e-3),
            run("fem", &[0.0, 0.02], 1e-3),
        ];
        let e = build_page(&runs, None).unwrap_err().to_string();
        assert!(
            e.contains("amm-enriched (3 frames, 100 per second)") && e.contains("fem (2 frames, 50 per second)"),
            "{e}"
        );
    }

    #[test]
    fn the_page_draws_the_base_triangle_and_the_payload() {
        let mut r = run("amm-enriched", &[0.0, 0.1], 1e-3);
        r.robot = Some(
            flexstar_model::Robot::from_params(&flexstar_model::RobotParams {
                d: 0.18,
                ..flexstar_model::RobotParams::paper()
            })
            .unwrap(),
        );
        r.payload = Some((0.5, [0.01, 0.0]));
        let html = build_page(&[r], None).unwrap();
        let start = html.find("id=\"frames-data\">").unwrap() + "id=\"frames-data\">".len();
        let end = start + html[start..].find("</script>").unwrap();
        let v: Value = serde_json::from_str(&html[start..end]).unwrap();
        // the corners of an equilateral triangle of in-radius d about O: at distance 2 d from O,
        // 120 degrees apart (independent of the geometry module: the in-radius of an
        // equilateral triangle is half its circumradius)
        let corners = v["base"].as_array().unwrap();
        assert_eq!(corners.len(), 3);
        for c in corners {
            let (x, y) = (c[0].as_f64().unwrap(), c[1].as_f64().unwrap());
            assert!((x.hypot(y) - 0.36e6).abs() <= 1.5, "{x}, {y}");
        }
        assert_eq!(v["payload"]["mass"], 0.5);
        assert_eq!(v["payload"]["offset"][0], 10_000);
        assert_eq!(v["runs"][0]["theta"].as_array().unwrap().len(), 2);
    }

    #[test]
    fn the_page_embeds_parseable_data_and_no_url() {
        let html = build_page(&[run("amm-</script>", &[0.0, 0.1], 1e-3)], Some(7.0)).unwrap();
        assert!(!html.contains("http") && !html.contains("amm-</script>"));
        let start = html.find("id=\"frames-data\">").unwrap() + "id=\"frames-data\">".len();
        let end = start + html[start..].find("</script>").unwrap();
        let v: Value = serde_json::from_str(&html[start..end]).unwrap();
        assert_eq!(v["magnify"], 7.0);
        assert_eq!(v["runs"][0]["name"], "amm-</script>");
        // elastic part in nanometres: the tip of beam 1, 1 mm in y
        assert_eq!(v["runs"][0]["elastic"][0][0][5], 1_000_000);
    }

    /// An uneven base is drawn as built: the corners where the axes meet are its vertices, so the
    /// corners' distances are the file's sides (in some order).
    #[test]
    fn an_uneven_base_is_drawn_with_its_own_sides() {
        let sides = [0.63, 0.6, 0.64];
        let p = flexstar_model::RobotParams::paper();
        let mut a = flexstar_model::robot::AsBuilt::of_paper(&p);
        a.axes = flexstar_model::ActuatorAxis::from_sides(sides).unwrap();
        let robot = flexstar_model::Robot::from_params(&flexstar_model::RobotParams { as_built: Some(a), ..p });
        let mut r = run("amm-enriched", &[0.0, 0.1], 1e-3);
        r.robot = Some(robot.unwrap());
        let corners = base_json(&r);
        let c: Vec<[f64; 2]> = corners
            .as_array()
            .unwrap()
            .iter()
            .map(|c| [c[0].as_f64().unwrap() * 1e-6, c[1].as_f64().unwrap() * 1e-6])
            .collect();
        let mut got: Vec<f64> = (0..3)
            .map(|k| {
                let (u, v) = (c[k], c[(k + 1) % 3]);
                (u[0] - v[0]).hypot(u[1] - v[1])
            })
            .collect();
        let mut want = sides.to_vec();
        got.sort_by(f64::total_cmp);
        want.sort_by(f64::total_cmp);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 3e-6, "{got:?} against {want:?}");
        }
    }
}
