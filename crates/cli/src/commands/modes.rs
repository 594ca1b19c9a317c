//! `flexstar modes --family F -n N`: the assumed modes of a family (Eq. 34-1).

use std::path::PathBuf;

use flexstar_model::{ModeFamily, RobotParams};

/// Print beta*L and the natural frequency of each mode of a family (rigid modes included).
#[derive(clap::Args)]
pub struct Args {
    /// Mode family: pinned-free, slide-free, free-free, clamped-free, enriched (its last two are the junction shapes)
    #[arg(long)]
    family: ModeFamily,
    /// Number of modes N, rigid ones included
    #[arg(short = 'n', long = "modes")]
    n: usize,
    /// Take E, I, rho, L from this experiment file instead of the paper's values
    #[arg(long)]
    config: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let params = match &args.config {
        Some(c) => super::load(c)?.robot,
        None => RobotParams::paper(),
    };
    let (bl, f) = flexstar_api::modes::mode_table(args.family, args.n, &params)?;
    println!("{}", flexstar_api::modes::header(args.family, &params));
    println!("{:>4} {:>18} {:>16}", "mode", "beta*L", "f [Hz]");
    for k in 0..bl.len() {
        println!("{:>4} {:>18.12} {:>16.6}", k + 1, bl[k], f[k]);
    }
    Ok(())
}
