//! The accurate AMM with friction against the refined FEM (`docs/validation.md` 10): the
//! paper's four cases (their `[amm]`/`[fem]` sections replaced: the accurate AMM at its defaults)
//! and the two target moves (`configs/motions/move-centre.toml`, `move-edge.toml`), sleeve friction
//! `mu` 0.1 and 0.3 with both load models. Per case: the AMM's N and step, its mean EVP (Eq. 45)
//! against the FEM at 600 elements and 1e-4 s (the refined FEM of `compare`), its error estimate
//! and their ratio; with `--converged`, also against the FEM at 1200 elements and 2.5e-5 s.
//!
//! `cargo run --release -p flexstar-compare --example friction_accuracy -- [--converged] [FIG_DIR]`
//! (a markdown table on stdout; with FIG_DIR, the figure of the friction forces and stick phases
//! of target move 1 at `mu = 0.3`, AMM and FEM overlaid, `friction-move-centre.svg`/`.png`).

use flexstar_compare::evp::point_evps;
use flexstar_model::catalogue::paper_case;
use flexstar_model::{AmmSettings, Experiment, FemSettings, Response};
use flexstar_plot::{Figure, Panel, Series, Style, Zoom, FAMILY_COLORS, FEM_STYLE};
use rayon::prelude::*;

/// The FEM of `compare`'s refined reference and of the converged one: (elements, step [s]).
const REFINED: (usize, f64) = (600, 1e-4);
const CONVERGED: (usize, f64) = (1200, 2.5e-5);

/// The six motions, each with its accurate-AMM settings at their defaults.
fn motions() -> Vec<Experiment> {
    let mut out: Vec<Experiment> = (1..=4).map(paper_case).collect();
    for (file, text) in [
        (
            "move-centre.toml",
            include_str!("../../../configs/motions/move-centre.toml"),
        ),
        (
            "move-edge.toml",
            include_str!("../../../configs/motions/move-edge.toml"),
        ),
    ] {
        out.push(Experiment::from_toml_str(text, std::path::Path::new(file)).expect("target move"));
    }
    for e in &mut out {
        e.amm = AmmSettings::default();
    }
    out
}

/// `base` with sleeve friction `mu` and the load model `model`.
fn with_friction(base: &Experiment, mu: f64, model: &str) -> Experiment {
    let mut e = base.clone();
    e.friction = Some(toml::from_str(&format!("mu = {mu}\nmodel = \"{model}\"\n")).expect("friction"));
    e
}

fn fem(e: &Experiment, (elements, dt): (usize, f64)) -> Response {
    let settings = FemSettings {
        elements,
        dt: Some(dt),
        ..FemSettings::default()
    };
    flexstar_fem::solve(&e.problem().unwrap(), &settings, flexstar_drive::SolveRequest::motion())
        .expect("fem")
        .response
}

fn amm(e: &Experiment) -> Response {
    flexstar_amm::solve(&e.problem().unwrap(), &e.amm, flexstar_drive::SolveRequest::motion())
        .expect("amm")
        .response
}

fn mean_evp(a: &Response, f: &Response) -> f64 {
    point_evps(a, f).expect("evp").mean.expect("a point with a reference")
}

/// One row of the table: the case, the AMM's N, step and estimate, its mean EVP against the
/// refined FEM and (with `--converged`) against the converged one.
struct Row {
    name: String,
    mu: f64,
    model: &'static str,
    n: usize,
    dt: f64,
    estimate: f64,
    refined: f64,
    converged: Option<f64>,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let converged = args.iter().any(|a| a == "--converged");
    let fig_dir = args.iter().find(|a| !a.starts_with("--")).map(std::path::PathBuf::from);
    let mut cases = Vec::new();
    for base in motions() {
        for mu in [0.1, 0.3] {
            for model in ["normal", "edges"] {
                cases.push((base.name.clone(), mu, model, with_friction(&base, mu, model)));
            }
        }
    }
    let rows: Vec<Row> = cases
        .par_iter()
        .map(|(name, mu, model, e)| {
            let a = amm(e);
            Row {
                name: name.clone(),
                mu: *mu,
                model,
                n: a.info.modes.unwrap_or(0),
                dt: a.info.dt,
                estimate: a.info.error_estimate_percent.unwrap_or(f64::NAN),
                refined: mean_evp(&a, &fem(e, REFINED)),
                converged: converged.then(|| mean_evp(&a, &fem(e, CONVERGED))),
            }
        })
        .collect();
    print_table(&rows);
    if let Some(dir) = fig_dir {
        std::fs::create_dir_all(&dir).expect("figure directory");
        let e = with_friction(&motions()[4], 0.3, "normal");
        friction_figure(&e, &amm(&e), &fem(&e, REFINED))
            .write(&dir)
            .expect("figure");
    }
}

fn print_table(rows: &[Row]) {
    println!("| case | mu | load | N | AMM step [s] | mean EVP vs FEM 600 / 1e-4 s | estimate | estimate / EVP | mean EVP vs FEM 1200 / 2.5e-5 s | estimate / EVP |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let conv = r
            .converged
            .map_or("-".into(), |c| format!("{c:.3} % | {:.2}", r.estimate / c));
        let conv = if r.converged.is_some() { conv } else { "- | -".into() };
        println!(
            "| {} | {} | {} | {} | {:.3e} | {:.3} % | {:.3} % | {:.2} | {conv} |",
            r.name,
            r.mu,
            r.model,
            r.n,
            r.dt,
            r.refined,
            r.estimate,
            r.estimate / r.refined
        );
    }
}

/// The friction forces `Ff1..3` and the stick phases `stick1..3` of the AMM (colours) and the
/// FEM (black) over the run of `e`.
fn friction_figure(e: &Experiment, a: &Response, f: &Response) -> Figure {
    let series = |r: &Response, name: &str, i: usize, style: Style, label: &str, offset: f64| Series {
        label: format!("{label}, sleeve {}", i + 1),
        x: r.t.clone(),
        y: r.column(&format!("{name}{}", i + 1))
            .expect("friction column")
            .iter()
            .map(|v| v + offset)
            .collect(),
        style,
    };
    let amm_style = |i: usize| Style {
        color: FAMILY_COLORS[i],
        width: 2,
        dashed: false,
    };
    let fem_style = |_: usize| Style {
        dashed: true,
        ..FEM_STYLE
    };
    let panel = |name: &str, title: &str, y_label: &str, offset: f64| Panel {
        title: title.into(),
        x_label: "t [s]".into(),
        y_label: y_label.into(),
        series: (0..3)
            .flat_map(|i| {
                let shift = offset * i as f64;
                [
                    series(a, name, i, amm_style(i), "AMM", shift),
                    series(f, name, i, fem_style(i), "FEM", shift),
                ]
            })
            .collect(),
        equal_axes: false,
        min_y_span: 0.1,
    };
    Figure {
        zooms: vec![Zoom {
            label: "the sleeves stop after the move".into(),
            windows: vec![(0.33, 0.53)],
        }],
        name: "friction-move-centre".into(),
        title: format!(
            "{}: sleeve friction mu = 0.3, AMM (accurate, defaults) and FEM (600 elements, 1e-4 s)",
            e.name
        ),
        caption: "Left: the friction force on each beam along its axis at the sleeve (slipping: mu times the normal \
                  load, Eqs. F5, F21; stuck: the force the stick needs). Right: the stick phases, 1 stuck, 0 \
                  slipping, sleeves 2 and 3 lifted by 1.5 and 3. AMM in colour, FEM dashed black."
            .into(),
        panels: vec![
            panel("Ff", "friction force on the beam", "Ff [N]", 0.0),
            panel("stick", "stick phases (sleeve i lifted by 1.5 (i - 1))", "stuck", 1.5),
        ],
    }
}
