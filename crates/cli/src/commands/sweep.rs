//! `flexstar sweep STUDY.toml [--out DIR] [--jobs N] [--shard K/N]` and
//! `flexstar sweep merge DIR`: design studies (thin layer over `flexstar_study`).

use std::io::IsTerminal;
use std::path::PathBuf;

use flexstar_study::{merge, run_study, write_report, RunOptions, Shard, Study};

/// Run a design study: every case of STUDY.toml in parallel, rows appended to
/// DIR/<name>/results.csv as cases finish (a rerun resumes), then plots and study.html
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    /// Study file (TOML)
    study: Option<PathBuf>,
    /// Output directory
    #[arg(long, default_value = "out/studies")]
    out: PathBuf,
    /// Worker threads (default: RAYON_NUM_THREADS or every core)
    #[arg(long)]
    jobs: Option<usize>,
    /// Run only the K-th of N disjoint slices (1 <= K <= N): DIR/<name>/results.shard-K-of-N.csv
    #[arg(long)]
    shard: Option<Shard>,
    /// Skip the plots and study.html
    #[arg(long)]
    no_plots: bool,
}

#[derive(clap::Subcommand)]
enum SweepCommand {
    /// Join DIR/results.shard-K-of-N.csv into DIR/results.csv (same study only); plots, study.html
    Merge {
        /// The study's results folder, <out>/<name>
        dir: PathBuf,
        /// Skip the plots and study.html
        #[arg(long)]
        no_plots: bool,
    },
}

pub fn run(args: Args) -> anyhow::Result<()> {
    match (args.command, args.study) {
        (Some(SweepCommand::Merge { dir, no_plots }), _) => merge_shards(dir, no_plots),
        (None, Some(study)) => sweep(&study, args.out, args.jobs, args.shard, args.no_plots),
        (None, None) => anyhow::bail!("give a study file (flexstar sweep STUDY.toml) or `merge DIR`"),
    }
}

fn sweep(
    path: &std::path::Path,
    out: PathBuf,
    jobs: Option<usize>,
    shard: Option<Shard>,
    no_plots: bool,
) -> anyhow::Result<()> {
    if jobs == Some(0) {
        anyhow::bail!("--jobs must be at least 1");
    }
    let study = Study::load(path)?;
    let cases = study.case_count();
    eprintln!(
        "{}: {cases} cases x {} solver(s){}",
        study.name,
        study.solvers.len(),
        shard.map(|s| format!(", shard {}/{}", s.k, s.n)).unwrap_or_default()
    );
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(0);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{pos}/{len} cases {bar:40} {percent:>3}% elapsed {elapsed} eta {eta}",
            )
            .expect("valid template"),
        );
        b
    });
    let tick = |done: usize, total: usize| {
        if let Some(b) = &bar {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    };
    let opts = RunOptions { out, jobs, shard };
    let outcome = run_study(&study, &opts, &tick)?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    eprintln!(
        "{}: {} cases ({} run now, {} already done) in {:.2} s; {} failed row(s); {}",
        study.name,
        outcome.cases,
        outcome.ran,
        outcome.skipped,
        outcome.seconds,
        outcome.failed_rows,
        outcome.results.display()
    );
    if shard.is_none() && !no_plots {
        let dir = outcome.results.parent().unwrap_or(std::path::Path::new("."));
        let report = write_report(dir)?;
        eprintln!(
            "{}: {} plots, {}",
            study.name,
            report.plots.len(),
            report.html.display()
        );
    }
    Ok(())
}

fn merge_shards(dir: PathBuf, no_plots: bool) -> anyhow::Result<()> {
    let r = merge(&dir)?;
    eprintln!(
        "merge: {} shards of {} joined into {} ({} rows)",
        r.shards - r.missing_shards.len(),
        r.shards,
        r.results.display(),
        r.rows
    );
    for (id, solver) in &r.duplicates {
        eprintln!("merge: duplicated: run {id} {solver} (first row kept)");
    }
    for (id, solver) in &r.unexpected {
        eprintln!("merge: not a case of its shard: run {id} {solver} (dropped)");
    }
    if !no_plots {
        let report = write_report(&dir)?;
        eprintln!("merge: {} plots, {}", report.plots.len(), report.html.display());
    }
    if !r.complete() {
        for (id, solver) in r.missing.iter().take(20) {
            eprintln!("merge: missing: run {id} {solver}");
        }
        anyhow::bail!(
            "incomplete: shard(s) {:?} missing ({} cases), {} row(s) missing in the shards present; rerun those shards, or run the whole study with the same --out to fill the gaps",
            r.missing_shards,
            r.missing_in_missing_shards,
            r.missing.len()
        );
    }
    Ok(())
}
