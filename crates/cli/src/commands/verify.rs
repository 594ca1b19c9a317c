//! `flexstar verify`: reproduce and check Table I (the main job).

use std::path::PathBuf;

use flexstar_compare::verify::{paper_configs, run_verify, VerifyOptions};

/// Run the four paper cases (three mode families + FEM, in parallel), write Table I (Markdown,
/// CSV, JSON), the figures (SVG, PNG) and report.html to DIR, and check the thresholds.
/// Exit 0 when every check holds, 1 with the list of what fails.
#[derive(clap::Args)]
pub struct Args {
    /// Output directory
    #[arg(long, default_value = "out/verify")]
    out: PathBuf,
    /// Thresholds file
    #[arg(long, default_value = "configs/thresholds.toml")]
    thresholds: PathBuf,
    /// Experiment files (default: configs/case1.toml .. case4.toml)
    #[arg(long, num_args = 1..)]
    configs: Vec<PathBuf>,
    /// Skip figures and the HTML report
    #[arg(long)]
    no_figures: bool,
    /// Skip the AMM runs at other numbers of modes (the N columns of the table)
    #[arg(long)]
    no_n_study: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let configs = if args.configs.is_empty() {
        paper_configs(std::path::Path::new("."))
    } else {
        args.configs
    };
    let opts = VerifyOptions {
        configs,
        thresholds: args.thresholds,
        out: args.out.clone(),
        figures: !args.no_figures,
        n_study: !args.no_n_study,
    };
    eprintln!(
        "verify: {} cases x (3 AMM families + FEM) on {} threads",
        opts.configs.len(),
        rayon::current_num_threads()
    );
    let outcome = run_verify(&opts)?;
    println!("{}", outcome.table.to_markdown());
    eprintln!(
        "verify: solves {:.2} s, total {:.2} s; table, figures and report.html in {}",
        outcome.solve_seconds,
        outcome.total_seconds,
        args.out.display()
    );
    if outcome.failures.is_empty() {
        eprintln!("verify: every check of the thresholds holds");
        Ok(())
    } else {
        for f in &outcome.failures {
            eprintln!("FAIL {f}");
        }
        anyhow::bail!("{} check(s) failed", outcome.failures.len())
    }
}
