//! `flexstar verify`: reproduce and check Table I (the main job), from any directory.

use std::path::PathBuf;

use flexstar_compare::verify::{run_verify, VerifyOptions};

use crate::progress::Reporter;

/// Run the four paper cases (three mode families + FEM, in parallel; built into the binary),
/// write Table I (Markdown, CSV, JSON), checks.txt, report.html and per case what `compare`
/// writes to DIR, and check the thresholds (built in). Exit 0 when every check holds, 1 with the
/// list of what fails.
#[derive(clap::Args)]
pub struct Args {
    /// Output directory
    #[arg(long, default_value = "out/verify")]
    out: PathBuf,
    /// Thresholds file (default: configs/thresholds.toml, built into the binary)
    #[arg(long)]
    thresholds: Option<PathBuf>,
    /// Experiment files (default: the paper's cases configs/case1.toml .. case4.toml, built into
    /// the binary); with this option the report has no paper-specific notes
    #[arg(long, num_args = 1..)]
    configs: Vec<PathBuf>,
    /// Skip figures and the HTML reports
    #[arg(long)]
    no_figures: bool,
    /// Skip the AMM runs at other numbers of modes (the N columns of the table)
    #[arg(long)]
    no_n_study: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let opts = VerifyOptions {
        configs: (!args.configs.is_empty()).then_some(args.configs),
        thresholds: args.thresholds,
        out: args.out.clone(),
        figures: !args.no_figures,
        n_study: !args.no_n_study,
        provenance: super::provenance(),
    };
    eprintln!(
        "verify: {} cases x (3 AMM families + FEM) on {} threads",
        opts.configs.as_ref().map(Vec::len).unwrap_or(4),
        rayon::current_num_threads()
    );
    let reporter = Reporter::new("verify");
    let tick = |p| reporter.update(p);
    let outcome = run_verify(&opts, Some(&tick));
    reporter.finish();
    let outcome = outcome?;
    super::print_warnings(&outcome.warnings);
    println!("{}", outcome.table.to_markdown());
    eprintln!(
        "verify: solves {:.2} s, total {:.2} s; table, checks, figures and report.html in {}",
        outcome.solve_seconds,
        outcome.total_seconds,
        args.out.display()
    );
    let failed = outcome.failures.len();
    eprintln!(
        "verify: {} checks, {} hold (all listed in {})",
        outcome.checks.len(),
        outcome.checks.len() - failed,
        args.out.join("checks.txt").display()
    );
    if failed == 0 {
        Ok(())
    } else {
        for f in &outcome.failures {
            eprintln!("{f}");
        }
        anyhow::bail!("{failed} check(s) failed")
    }
}
