//! `flexstar export RUN_OR_PLAN_DIR --rate HZ [--run STEM]` (`docs/motions.md`, "Export for the
//! controller"): the prescribed motion of a run or a plan as a motion controller's setpoint table.

use std::path::PathBuf;

/// Write RUN_OR_PLAN_DIR/setpoints.csv (t, s, v, a, j per slider and the accurate AMM's
/// feed-forward forces F at k / rate) and setpoints.json (units, peaks, interpolation bound)
#[derive(clap::Args)]
pub struct Args {
    /// A run folder (`flexstar run`: `<stem>.json` beside `<stem>.csv`) or a plan folder
    /// (`flexstar plan`: `plan.json`); the files are written into it
    dir: PathBuf,
    /// The controller's sampling rate [Hz]: at least twice the first elastic frequency at the
    /// final pose, at most 100 kHz
    #[arg(long)]
    rate: f64,
    /// The run to export (its file stem, e.g. amm-enriched) when the folder holds several
    #[arg(long)]
    run: Option<String>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let settings = flexstar_api::export::ExportSettings {
        rate_hz: args.rate,
        run: args.run,
    };
    let outcome = flexstar_api::export::export(&args.dir, &settings)?;
    for line in outcome.summary() {
        eprintln!("{line}");
    }
    Ok(())
}
