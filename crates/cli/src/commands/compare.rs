//! `flexstar compare CONFIG [--families F,...] [--modes N] [--out DIR] [--measured FILE.csv]`.

use std::path::PathBuf;

use flexstar_compare::compare::{run_compare, CompareOptions};
use flexstar_model::ModeFamily;

use crate::progress::Reporter;

/// Run the AMM (the experiment's [amm] settings, plus any families asked) and the FEM on an
/// experiment and compare them: writes DIR/<name>/compare.md, compare.csv, compare.json, the
/// figures, report.html, and every run's CSV and sidecar JSON.
#[derive(clap::Args)]
pub struct Args {
    /// Experiment file (TOML)
    config: PathBuf,
    /// Further mode families to run, comma-separated: pinned-free, slide-free, free-free,
    /// clamped-free, enriched
    #[arg(long, value_delimiter = ',')]
    families: Vec<ModeFamily>,
    /// Modes per beam N for every AMM run (overrides [amm] modes / tol)
    #[arg(long)]
    modes: Option<usize>,
    /// Output directory; results go to DIR/<name>/
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Skip the figures and the HTML report
    #[arg(long)]
    no_figures: bool,
    /// A recording of the real robot (CSV: t and sensor columns, mapped by [measured]) laid over
    /// the runs: its error against each run, its spectra (docs/measured.md)
    #[arg(long, value_name = "FILE.csv")]
    measured: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let opts = CompareOptions {
        config: args.config,
        families: args.families,
        modes: args.modes,
        out: args.out,
        figures: !args.no_figures,
        provenance: super::provenance(),
        measured: args.measured,
    };
    let reporter = Reporter::new("compare");
    let tick = |p| reporter.update(p);
    let outcome = run_compare(&opts, Some(&tick));
    reporter.finish();
    let outcome = outcome?;
    for n in &outcome.notes {
        eprintln!("{n}");
    }
    super::print_warnings(&outcome.warnings);
    println!("{}", outcome.compare_csv.trim_end());
    if let Some(servo) = &outcome.servo {
        // after the CSV and a blank line, so that the table above still reads as compare.csv
        println!("\n{}", servo.gains_line());
        for line in servo.tracking_lines() {
            println!("{line}");
        }
    }
    eprintln!(
        "compare: solves {:.2} s, total {:.2} s; behaviour of G: {}; closest to the FEM: {}; outputs in {}",
        outcome.solve_seconds,
        outcome.total_seconds,
        outcome.row.behaviour.name(),
        outcome.row.most_accurate.as_deref().unwrap_or("-"),
        outcome.dir.display()
    );
    Ok(())
}
