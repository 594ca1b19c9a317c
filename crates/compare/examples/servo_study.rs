//! The paper's four cases driven by a servo instead of an ideal motion:
//! tracking error and tip vibration beside the prescribed-motion run, and how they change with
//! the servo's bandwidth relative to the star's first frequencies. Results in `docs/drives.md`.
//!
//! `cargo run --release -p flexstar-compare --example servo_study -- OUT_DIR`
//! (markdown tables on stdout, figures in OUT_DIR).

use flexstar_compare::figures::{figure_tips, Run};
use flexstar_drive::Servo;
use flexstar_metrics::evp::point_evps;
use flexstar_model::catalogue::paper_case;
use flexstar_model::rest_pose::{RestPose, Sliders};
use flexstar_model::{AmmSettings, Experiment, ModeFamily, Response};
use flexstar_plot::{Figure, Panel, Series, Style, FAMILY_COLORS, FEM_STYLE};
use rayon::prelude::*;

const BANDWIDTHS: [f64; 8] = [2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 1000.0];
const ZETA: f64 = 0.7;

fn peak(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn servo_run(exp: &Experiment, settings: &AmmSettings, f_bw: f64) -> Response {
    let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, f_bw, ZETA);
    let law = Servo {
        kp: [kp; 3],
        kd: [kd; 3],
        rigid_feedforward: true,
        reference: exp.trajectory.clone(),
        params: exp.robot,
        attached: Default::default(),
    };
    let problem = exp.problem().unwrap();
    flexstar_amm::solve(&problem, settings, flexstar_drive::SolveRequest::law(&law))
        .map(|s| s.response)
        .expect("servo run")
}

/// Largest |s_ref - s| [m] over the run.
fn tracking_error(exp: &Experiment, r: &Response) -> f64 {
    let mut worst = 0.0f64;
    for (k, &t) in r.t.iter().enumerate() {
        let s = exp.trajectory.s(&exp.robot, t).expect("reference");
        for (i, name) in ["s1", "s2", "s3"].iter().enumerate() {
            worst = worst.max((r.column(name).expect("s column")[k] - s[i]).abs());
        }
    }
    worst
}

struct Outcome {
    f_bw: f64,
    tracking_mm: f64,
    peak_tip_mm: f64,
    tip_evp: f64,
}

fn study_case(exp: &Experiment, settings: &AmmSettings, ideal: &Response) -> Vec<(Outcome, Response)> {
    BANDWIDTHS
        .par_iter()
        .map(|&f_bw| {
            let r = servo_run(exp, settings, f_bw);
            let evps = point_evps(&r, ideal).expect("evp");
            let tip_evp = evps.points[..3].iter().flatten().fold(0.0f64, |m, v| m.max(*v));
            let o = Outcome {
                f_bw,
                tracking_mm: tracking_error(exp, &r) * 1e3,
                peak_tip_mm: (0..3).map(|i| peak(&r.w_tip[i])).fold(0.0, f64::max) * 1e3,
                tip_evp,
            };
            (o, r)
        })
        .collect()
}

fn star_frequencies(exp: &Experiment) -> (Vec<f64>, Vec<f64>) {
    let st = flexstar_kinematics::RigidState::at(&exp.robot, &exp.trajectory, 0.0).expect("start");
    let pose = RestPose {
        s: st.s.map(|j| j.v),
        g: st.g.map(|j| j.v),
        theta: st.theta.v,
        xp: st.xp.map(|j| j.v),
    };
    let f = |sliders| {
        flexstar_amm::pose_modes::pose_modes(&exp.robot, &pose, sliders, ModeFamily::Enriched, 60, 6)
            .expect("modes")
            .freq_hz
    };
    (f(Sliders::Locked), f(Sliders::Free))
}

fn main() {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "out/servo-study".into()));
    std::fs::create_dir_all(&out).expect("output directory");
    let settings = AmmSettings {
        modes: Some(53),
        ..AmmSettings::accurate()
    };
    let cases: Vec<Experiment> = (1..=4).map(paper_case).collect();
    let (locked, free) = star_frequencies(&cases[0]);
    println!("Star at the start pose (G = O): sliders locked f = {locked:.2?} Hz; free f = {free:.2?} Hz\n");
    println!("| case | bandwidth [Hz] | peak tracking error [mm] | peak tip, servo [mm] | peak tip, ideal motion [mm] | tip EVP servo vs ideal [%] |");
    println!("|---|---|---|---|---|---|");
    let mut curves: Vec<(String, Vec<Outcome>)> = Vec::new();
    for (k, exp) in cases.iter().enumerate() {
        let problem = exp.problem().unwrap();
        let ideal = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .expect("ideal run");
        let ideal_tip = (0..3).map(|i| peak(&ideal.w_tip[i])).fold(0.0, f64::max) * 1e3;
        let runs = study_case(exp, &settings, &ideal);
        for (o, _) in &runs {
            println!(
                "| {} | {} | {:.4} | {:.3} | {:.3} | {:.2} |",
                k + 1,
                o.f_bw,
                o.tracking_mm,
                o.peak_tip_mm,
                ideal_tip,
                o.tip_evp
            );
        }
        let servo20 = &runs.iter().find(|(o, _)| o.f_bw == 20.0).expect("20 Hz").1;
        let pair = [
            Run {
                label: "ideal motion".into(),
                response: &ideal,
                style: FEM_STYLE,
            },
            Run {
                label: "servo 20 Hz, zeta 0.7, rigid feedforward".into(),
                response: servo20,
                style: Style {
                    color: FAMILY_COLORS[4],
                    width: 2,
                    dashed: false,
                },
            },
        ];
        let mut fig = figure_tips(&exp.name, &pair);
        fig.name = format!("servo-{}-tips", exp.name);
        fig.title = format!("{}: tip deflections, ideal motion against a 20 Hz servo", exp.name);
        fig.caption = "The accurate AMM (N = 53) with the motion prescribed (black) and with the sliders driven by a \
                       PD servo of 20 Hz bandwidth and rigid feedforward tracking the same motion (orange)."
            .into();
        fig.write(&out).expect("figure");
        curves.push((exp.name.clone(), runs.into_iter().map(|(o, _)| o).collect()));
    }
    bandwidth_figure(&curves, locked[0]).write(&out).expect("figure");
}

/// Peak tracking error and tip EVP against log10 of the bandwidth, one curve per case.
fn bandwidth_figure(curves: &[(String, Vec<Outcome>)], f1_locked: f64) -> Figure {
    let panel = |title: &str, y_label: &str, pick: &dyn Fn(&Outcome) -> f64| Panel {
        title: title.into(),
        x_label: format!("log10(bandwidth / Hz); star's f1 (sliders locked) = {f1_locked:.2} Hz"),
        y_label: y_label.into(),
        series: curves
            .iter()
            .enumerate()
            .map(|(k, (name, v))| Series {
                label: name.clone(),
                x: v.iter().map(|o| o.f_bw.log10()).collect(),
                y: v.iter().map(|o| pick(o).max(1e-12).log10()).collect(),
                style: Style {
                    color: FAMILY_COLORS[k],
                    width: 2,
                    dashed: false,
                },
            })
            .collect(),
        equal_axes: false,
        min_y_span: 0.1,
    };
    Figure {
        zooms: Vec::new(),
        name: "servo-bandwidth".into(),
        title: "Servo bandwidth against tracking error and tip vibration (paper cases, AMM)".into(),
        caption: "Both axes logarithmic. Left: largest tracking error. Right: how far the tip vibration is from the \
                  ideal-motion run (largest tip EVP). Both fall as the bandwidth rises past the star's first \
                  frequencies."
            .into(),
        panels: vec![
            panel("peak tracking error", "log10(error / mm)", &|o| o.tracking_mm),
            panel("tips: servo vs ideal motion", "log10(EVP / %)", &|o| o.tip_evp),
        ],
    }
}
