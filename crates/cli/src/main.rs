//! `flexstar`: reproduce, verify and extend the vibration analysis of the flexible 3-PRP
//! star-triangle robot. A thin command line over the library crates: it parses arguments, calls
//! one library function per subcommand, prints progress and summaries to stderr and writes data
//! files. Exit code 0 on success, 1 on any error (with the reason on stderr).

mod commands;
mod progress;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "flexstar",
    version,
    about = "Vibration of the 3-PRP star-triangle robot with a flexible star: rigid kinematics, assumed modes (AMM), finite elements (FEM), Table I"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Rigid kinematics of an experiment: writes DIR/<name>/kinematics.csv
    Kinematics(commands::kinematics::Args),
    /// Run the AMM or the FEM on an experiment: writes DIR/<name>/amm-<family>.csv or fem.csv
    Run(commands::run::Args),
    /// List the assumed modes of a family: beta*L and natural frequency per mode
    Modes(commands::modes::Args),
    /// Compare the AMM with the FEM on any experiment: EVPs, figures, report in DIR/<name>/
    Compare(commands::compare::Args),
    /// Reproduce and check Table I: four cases, three families, FEM; table, figures, report
    Verify(commands::verify::Args),
    /// Design studies: sweep experiment keys over a grid or a Latin hypercube, in parallel or in
    /// shards on a cluster (`sweep merge DIR` joins the shards); results.csv, plots, study.html
    Sweep(commands::sweep::Args),
    /// Modes at a pose, AMM and FEM side by side: DIR/<name>/modal.csv, the first six shapes
    Modal(commands::modal::ModalArgs),
    /// First K frequencies over a grid of poses: DIR/<name>/freqmap.csv, heat map of f1 and f2
    Freqmap(commands::modal::FreqmapArgs),
    /// Linear state-space model about a pose, sliders free: DIR/<name>/linear/ (Matrix Market, JSON)
    Linearize(commands::modal::LinearizeArgs),
    /// The runs of a folder moving (their `*-frames.csv`): one self-contained animate.html
    Animate(commands::animate::Args),
    /// Plan a rest-to-rest motion that leaves little residual vibration ([plan], [limits]) and
    /// compare it with the plain and the ZVD-shaped quintic: DIR/<name>/plan.md, plan.toml, plan.csv
    Plan(commands::plan::Args),
    /// A run's or a plan's motion for a motion controller: DIR/setpoints.csv (t, s, v, a, j, F at
    /// k / rate) and setpoints.json
    Export(commands::export::Args),
    /// Calibrate the physical parameters of [fit] on a recording of the sensors: DIR/<name>/fit.toml
    /// (the calibrated experiment), fit.json, fit.md, report.html
    Fit(commands::fit::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Kinematics(args) => commands::kinematics::run(args),
        Command::Run(args) => commands::run::run(args),
        Command::Modes(args) => commands::modes::run(args),
        Command::Compare(args) => commands::compare::run(args),
        Command::Verify(args) => commands::verify::run(args),
        Command::Sweep(args) => commands::sweep::run(args),
        Command::Modal(args) => commands::modal::run_modal(args),
        Command::Freqmap(args) => commands::modal::run_freqmap(args),
        Command::Linearize(args) => commands::modal::run_linearize(args),
        Command::Animate(args) => commands::animate::run(args),
        Command::Plan(args) => commands::plan::run(args),
        Command::Export(args) => commands::export::run(args),
        Command::Fit(args) => commands::fit::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", message(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// The error and its causes, each cause added only when the message does not already say it
/// (library errors often repeat their source in their own text).
fn message(e: &anyhow::Error) -> String {
    let mut msg = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    msg
}
