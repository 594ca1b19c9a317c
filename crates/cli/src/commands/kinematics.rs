//! `flexstar kinematics CONFIG [--out DIR]`.

use std::path::PathBuf;

use flexstar_io::output::fmt_fixed;

/// Rigid kinematics of an experiment (Eqs. 1-12): G, theta, xp_i and their derivatives.
#[derive(clap::Args)]
pub struct Args {
    /// Experiment file (TOML), e.g. configs/case1.toml
    config: PathBuf,
    /// Output directory; the table goes to DIR/<name>/kinematics.csv
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let exp = super::load(&args.config)?;
    super::note_other_experiment(&args.out, &exp);
    let states = flexstar_api::kinematics::table(&exp, &args.config.display().to_string())?;
    let path = flexstar_api::kinematics::write(&args.out, &exp, &states)?;
    let last = states.last().expect("output times are never empty");
    eprintln!(
        "{}: {} rows to {} (t_end = {} s: G = ({}, {}) m, theta = {} rad, xp = {}/{}/{} m)",
        exp.name,
        states.len(),
        path.display(),
        last.t,
        fmt_fixed(last.g[0].v, 5),
        fmt_fixed(last.g[1].v, 5),
        fmt_fixed(last.theta.v, 5),
        fmt_fixed(last.xp[0].v, 4),
        fmt_fixed(last.xp[1].v, 4),
        fmt_fixed(last.xp[2].v, 4)
    );
    Ok(())
}
