//! `flexstar animate RUN_DIR [--out FILE] [--magnify M]` (`docs/motions.md` section 5): the
//! frames files of a run folder as one self-contained HTML page.

use std::path::PathBuf;

/// Draw every run of RUN_DIR with frames (`[amm] frames`, `[fem] frames`) moving, overlaid.
#[derive(clap::Args)]
pub struct Args {
    /// A run folder (`out/<name>/`) holding `<stem>-frames.csv` files
    run_dir: PathBuf,
    /// The page to write (default RUN_DIR/animate.html)
    #[arg(long)]
    out: Option<PathBuf>,
    /// Magnification M of the elastic part (default: the largest elastic displacement drawn as
    /// 10 % of L)
    #[arg(long)]
    magnify: Option<f64>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let (path, runs) = flexstar_animate::animate(&args.run_dir, args.out.as_deref(), args.magnify)?;
    eprintln!("animate: {} ({})", path.display(), runs.join(", "));
    Ok(())
}
