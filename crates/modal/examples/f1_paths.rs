//! f1 and f2 of the star (AMM, enriched family, N = 60, sliders locked: the actuators prescribe
//! s_i(t)) along the paper's four motions, every 5 ms of each span; for docs/modes.md.
//!
//! ```sh
//! cargo run --release -p flexstar-modal --example f1_paths -- OUT_DIR
//! ```
//! Writes `OUT_DIR/f1-paths.csv` (`case,t,Gx,Gy,theta,xp1,xp2,xp3,f1_hz,f2_hz`) and
//! `OUT_DIR/f1-paths.svg/.png`. Each case's file is read with the solver settings replaced by the
//! defaults (the paper's families are for the time-domain comparison, not for modes).

use flexstar_amm::pose_modes::{PoseModel, DEFAULT_MODAL_MODES};
use flexstar_io::output::{fmt_number, write_atomically};
use flexstar_modal::plots::PATH_COLORS;
use flexstar_modal::pose::pose_at_time;
use flexstar_model::{AmmSettings, Sliders};
use flexstar_plot::{Figure, Panel, Series, Style};

const STEP: f64 = 0.005;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "out/f1-paths".into()));
    flexstar_io::output::ensure_writable_dir(&out)?;
    let mut rows = Vec::new();
    let mut panels: Vec<Panel> = ["f1", "f2"]
        .iter()
        .map(|f| Panel {
            title: format!("{f} along the paper's motions (sliders locked)"),
            x_label: "t [s]".into(),
            y_label: format!("{f} [Hz]"),
            series: vec![],
            equal_axes: false,
            min_y_span: 0.1,
        })
        .collect();
    for k in 1..=4 {
        let mut exp = flexstar_model::catalogue::paper_case(k);
        exp.amm = AmmSettings::default();
        let model = PoseModel::new(&exp.robot, exp.amm.family, DEFAULT_MODAL_MODES)?;
        let n = (exp.time.t_end / STEP).round() as usize;
        let (mut t, mut f1, mut f2) = (vec![], vec![], vec![]);
        for j in 0..=n {
            let tj = (j as f64 * STEP).min(exp.time.t_end);
            let pose = pose_at_time(&exp, tj)?;
            let f = model.frequencies_at(&pose, Sliders::Locked, 2)?;
            rows.push(format!(
                "{k},{},{},{},{},{},{},{},{},{}",
                fmt_number(tj),
                fmt_number(pose.g[0]),
                fmt_number(pose.g[1]),
                fmt_number(pose.theta),
                fmt_number(pose.xp[0]),
                fmt_number(pose.xp[1]),
                fmt_number(pose.xp[2]),
                fmt_number(f[0]),
                fmt_number(f[1])
            ));
            t.push(tj);
            f1.push(f[0]);
            f2.push(f[1]);
        }
        let (lo, hi) = f1
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(*v), b.max(*v)));
        let mean = f1.iter().sum::<f64>() / f1.len() as f64;
        eprintln!(
            "case {k}: f1 from {:.3} to {:.3} Hz (mean {mean:.3} Hz, at t_end {:.3} Hz)",
            lo, hi, f1[n]
        );
        let style = Style {
            color: PATH_COLORS[k - 1],
            width: 2,
            dashed: false,
        };
        for (p, y) in panels.iter_mut().zip([f1, f2]) {
            p.series.push(Series {
                label: format!("case {k}"),
                x: t.clone(),
                y,
                style,
            });
        }
    }
    write_atomically(&out.join("f1-paths.csv"), |w| {
        writeln!(w, "case,t,Gx,Gy,theta,xp1,xp2,xp3,f1_hz,f2_hz")?;
        for r in &rows {
            writeln!(w, "{r}")?;
        }
        Ok(())
    })?;
    Figure {
        zooms: Vec::new(),
        name: "f1-paths".into(),
        title: "First two frequencies of the star along the paper's four motions (AMM, N = 60)".into(),
        caption: String::new(),
        panels,
    }
    .write(&out)?;
    eprintln!("{}", out.display());
    Ok(())
}
