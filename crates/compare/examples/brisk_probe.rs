//! Probes of what remains between the accurate AMM and the FEM on the `brisk` motion of
//! `tests/cross_models.rs` (`docs/amm.md` sections 8-9).
//!
//! `cargo run --release -p flexstar-compare --example brisk_probe -- PROBE [ARG]`, PROBE one of
//! - `scale S`: brisk with its displacement scaled by S (S = 1: the test's motion): FEM at its
//!   defaults against the AMM (enriched, full) at N = 53 and 100: a model error linear in the
//!   amplitude keeps its EVP as S shrinks, a geometrically nonlinear one falls like S or S^2;
//! - `fem`: the FEM refined (600 elements, half its step) and with EA x 100 against the FEM at its
//!   defaults, and the AMM (N = 53) against each of them;
//! - `modes`: the AMM at N = 53, 100, 150 against the FEM at its defaults;
//! - `paper`: the paper's model (enriched, N = 53) against the FEM, for scale.

use std::path::Path;

use flexstar_compare::evp::point_evps;
use flexstar_model::{AmmModel, AmmSettings, Experiment, FemSettings, Response};

fn brisk(scale: f64, ea_factor: f64) -> Experiment {
    let text = format!(
        r#"
name = "brisk"
[time]
t_end = 0.4
dt_out = 0.001
[trajectory]
kind = "quintic"
from = {{ Gx = 0.0, Gy = 0.0, theta = 0.0 }}
to = {{ Gx = {}, Gy = {}, theta = {} }}
t0 = 0.0
t1 = 0.2
"#,
        -0.008 * scale,
        0.006 * scale,
        -0.06 * scale
    );
    let mut exp = Experiment::from_toml_str(&text, Path::new("brisk.toml")).expect("brisk");
    if ea_factor != 1.0 {
        exp.robot.ea = Some(exp.robot.ea() * ea_factor);
    }
    exp
}

fn amm(exp: &Experiment, n: usize, model: AmmModel) -> Response {
    let settings = AmmSettings {
        modes: Some(n),
        model,
        ..AmmSettings::accurate()
    };
    let problem = exp.problem().unwrap();
    flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .expect("amm")
}

fn fem(exp: &Experiment, elements: usize, dt: Option<f64>) -> Response {
    let settings = FemSettings {
        elements,
        dt,
        ..FemSettings::default()
    };
    let problem = exp.problem().unwrap();
    flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .expect("fem")
}

fn show(what: &str, test: &Response, reference: &Response) {
    let p = point_evps(test, reference).expect("evp");
    let pts: Vec<String> = p
        .points
        .iter()
        .map(|v| v.map_or("n/a".into(), |x| format!("{x:.3}")))
        .collect();
    println!(
        "{what:<40} A B C G = {} | mean {:.3}",
        pts.join(" "),
        p.mean.unwrap_or(f64::NAN)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let probe = args.first().map(String::as_str).unwrap_or("scale");
    match probe {
        "scale" => {
            let s: f64 = args.get(1).map_or(1.0, |v| v.parse().expect("S"));
            let exp = brisk(s, 1.0);
            let reference = fem(&exp, 300, None);
            let peak_tip = (0..3)
                .map(|i| reference.w_tip[i].iter().fold(0.0f64, |a, v| a.max(v.abs())))
                .fold(0.0, f64::max);
            println!("scale {s}: largest FEM tip {:.3} mm", peak_tip * 1e3);
            for n in [53, 100] {
                show(
                    &format!("scale {s}: AMM full N = {n} vs FEM"),
                    &amm(&exp, n, AmmModel::Full),
                    &reference,
                );
            }
        }
        "fem" => {
            let exp = brisk(1.0, 1.0);
            let reference = fem(&exp, 300, None);
            let a = amm(&exp, 53, AmmModel::Full);
            show("AMM N = 53 vs FEM 300", &a, &reference);
            let variants: [(&str, Response); 3] = [
                ("FEM 600 elements", fem(&exp, 600, None)),
                ("FEM dt / 2", fem(&exp, 300, Some(2.5e-4))),
                ("FEM EA x 100", fem(&brisk(1.0, 100.0), 300, None)),
            ];
            for (name, r) in &variants {
                show(&format!("{name} vs FEM 300"), r, &reference);
                show(&format!("AMM N = 53 vs {name}"), &a, r);
            }
        }
        "modes" => {
            let exp = brisk(1.0, 1.0);
            let reference = fem(&exp, 300, None);
            for n in [53, 100, 150] {
                show(
                    &format!("AMM full N = {n} vs FEM"),
                    &amm(&exp, n, AmmModel::Full),
                    &reference,
                );
            }
        }
        "paper" => {
            let exp = brisk(1.0, 1.0);
            let reference = fem(&exp, 300, None);
            show("AMM paper N = 53 vs FEM", &amm(&exp, 53, AmmModel::Paper), &reference);
        }
        other => panic!("unknown probe {other}"),
    }
}
