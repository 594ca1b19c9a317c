//! `flexstar fit CONFIG --measured FILE.csv [--out DIR]` (`docs/measured.md` section 4): the
//! physical parameters of `[fit]` calibrated on a recording.

use std::path::PathBuf;

/// Calibrate the parameters of [fit] on a recording (weighted least squares on the sensor
/// channels, the accurate AMM): DIR/<name>/fit.toml (the calibrated experiment, when converged),
/// fit.json, fit.md, report.html, the figures
#[derive(clap::Args)]
pub struct Args {
    /// Experiment with [fit] and [[sensors]]: the recorded move, the values to start from
    config: PathBuf,
    /// The recording: a CSV of t and sensor columns, read as the experiment's [measured] maps it
    /// (docs/measured.md section 1)
    #[arg(long)]
    measured: PathBuf,
    /// Output directory; results go to DIR/<name>/
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let outcome = flexstar_api::fit::fit_to_dir(&args.config, &args.measured, &args.out, &|it| {
        let theta: Vec<String> = it.theta.iter().map(|v| format!("{v:.6e}")).collect();
        eprintln!(
            "fit: iteration {:>2}: cost {:.6e}, relative offset {:.2e}, {} runs, {:.2} s: {}",
            it.iteration,
            it.cost,
            it.offset,
            it.evaluations,
            it.wall_s,
            theta.join(", ")
        );
    })?;
    for n in &outcome.notes {
        eprintln!("{n}");
    }
    if !outcome.fitted.not_recorded.is_empty() {
        eprintln!(
            "note: not in the recording, so not fitted: {}",
            outcome.fitted.not_recorded.join(", ")
        );
    }
    let fit = &outcome.fitted.fit;
    eprintln!("fit: {}", fit.reason);
    eprintln!("fit: identifiability: {}", fit.identifiability.message);
    for e in &fit.estimates {
        let interval = e
            .interval
            .map_or("n/a".to_string(), |[a, b]| format!("{a:.6e} .. {b:.6e}"));
        eprintln!(
            "fit: {:<16} {:.6e} (start {:.6e}), standard error {} (noise), {} (correlated), 95 % interval {interval}{}",
            e.key,
            e.estimate,
            e.start,
            e.standard_error.map_or("n/a".to_string(), |v| format!("{v:.3e}")),
            e.standard_error_correlated
                .map_or("n/a".to_string(), |v| format!("{v:.3e}")),
            if e.at_bound { ", at a bound" } else { "" }
        );
    }
    for c in fit.channels.iter().filter(|c| c.misfit()) {
        eprintln!(
            "warning: {}: RMS error after the fit {:.3e} {} is {:.1} times its noise level: the model misses something there",
            c.column,
            c.rms_after,
            c.unit,
            c.rms_after / c.noise
        );
    }
    eprintln!(
        "fit: {} files in {} in {:.2} s ({}; fit.md: the report)",
        outcome.files.len(),
        outcome.dir.display(),
        outcome.wall_s,
        if outcome.fitted.calibrated.is_some() {
            "fit.toml: the calibrated experiment"
        } else {
            "not calibrated: no fit.toml"
        }
    );
    Ok(())
}
