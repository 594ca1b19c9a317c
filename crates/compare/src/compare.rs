//! `flexstar compare CONFIG`: the AMM (the experiment's `[amm]` settings, plus any mode families
//! asked) and the FEM on any experiment, written to `DIR/<name>/`: the runs' CSVs and sidecars,
//! `compare.md`, `compare.csv`, `compare.json`, the figure set and `report.html`; with
//! `--measured FILE.csv` a recording laid over the runs ([`crate::measured`]).

use std::path::PathBuf;
use std::time::Instant;

use flexstar_io::output::{ensure_writable_dir, write_string_atomically};
use flexstar_model::{AmmSettings, Experiment, ModeFamily, Provenance};

use crate::case_output::{write_case_measured, ValidityWarning};
use crate::report::case_report;
use crate::runs::{preflight, run_cases, AmmRun, CaseSpec, ProgressFn};
use crate::servo::{servo_summary, ServoSummary};
use crate::table::{TableI, TableRow};
use crate::Error;

/// What to compare and where to write.
#[derive(Debug, Clone)]
pub struct CompareOptions {
    /// The experiment file.
    pub config: PathBuf,
    /// Mode families run besides the experiment's own `[amm]` family (same other settings).
    pub families: Vec<ModeFamily>,
    /// Modes per beam N for every AMM run (overrides `[amm] modes` / `tol`).
    pub modes: Option<usize>,
    /// Output directory; results go to `out/<name>/`.
    pub out: PathBuf,
    /// Draw the figures and the report.
    pub figures: bool,
    /// Version, commit and date written into every output.
    pub provenance: Provenance,
    /// A recording of the real robot laid over the runs (`--measured`, `docs/measured.md`).
    pub measured: Option<PathBuf>,
}

/// The result of a comparison.
#[derive(Debug)]
pub struct CompareOutcome {
    /// Where the outputs are.
    pub dir: PathBuf,
    pub row: TableRow,
    /// Runs that leave the small-deflection range of the AMM.
    pub warnings: Vec<ValidityWarning>,
    /// The text of `compare.csv` as written (header and one row per AMM run).
    pub compare_csv: String,
    /// The servo and each run's tracking error, for an experiment driven by a servo.
    pub servo: Option<ServoSummary>,
    /// Notes for the user: the output folder held results of another experiment with the same
    /// name ([`flexstar_model::identity::other_experiment_note`]).
    pub notes: Vec<String>,
    /// Wall time of the solves and of the whole command [s].
    pub solve_seconds: f64,
    pub total_seconds: f64,
}

/// The AMM runs of a comparison: the experiment's own settings first, then every family asked
/// that is not already there, all with N = `modes` when given.
pub fn compare_runs(exp: &Experiment, families: &[ModeFamily], modes: Option<usize>) -> Vec<AmmRun> {
    let base = AmmSettings {
        modes: modes.or(exp.amm.modes),
        tol: if modes.is_some() { None } else { exp.amm.tol },
        ..exp.amm.clone()
    };
    let mut runs = vec![AmmRun::family(&base, base.family)];
    for f in families {
        if !runs.iter().any(|r| r.settings.family == *f) {
            runs.push(AmmRun::family(&base, *f));
        }
    }
    runs
}

/// Check the command-line overrides against the experiment (errors name the file and the flag).
fn check_flags(exp: &Experiment, modes: Option<usize>) -> Result<(), Error> {
    if let Some(n) = modes {
        let probe = AmmSettings {
            modes: Some(n),
            tol: None,
            ..exp.amm.clone()
        };
        probe.validate(exp.time.dt_out).map_err(|e| Error::Input {
            file: exp.source.display().to_string(),
            reason: format!("--modes {n}: {}", e.to_string().trim_start_matches(": ")),
        })?;
    }
    Ok(())
}

/// Run the comparison: every check first (experiment, flags, feasibility, output directory),
/// then the solves in parallel, then the outputs.
pub fn run_compare(opts: &CompareOptions, progress: Option<ProgressFn>) -> Result<CompareOutcome, Error> {
    let start = Instant::now();
    let exp = flexstar_shaping::shape_loaded(Experiment::load(&opts.config)?)?;
    check_flags(&exp, opts.modes)?;
    let recording = match &opts.measured {
        Some(path) => Some(crate::measured::read_recording(&exp, path)?),
        None => None,
    };
    let spec = CaseSpec {
        amm: compare_runs(&exp, &opts.families, opts.modes),
        extra: Vec::new(),
        reference: None,
        exp,
    };
    let checked = preflight(std::slice::from_ref(&spec))?;
    let dir = opts.out.join(&spec.exp.name);
    ensure_writable_dir(&opts.out)?;
    ensure_writable_dir(&dir)?;
    let notes = flexstar_model::identity::other_experiment_note(&dir, &spec.exp)
        .into_iter()
        .collect();
    let cases = run_cases(checked, progress)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let case = &cases[0];
    let table = TableI::compute(&cases, false)?;
    let row = &table.rows[0];
    let measured = match recording {
        Some(rec) => Some(crate::measured::overlay(&spec.exp, case, rec)?),
        None => None,
    };
    let written = write_case_measured(
        &dir,
        &spec.exp,
        case,
        row,
        (&opts.provenance, opts.figures),
        measured.as_ref(),
    )?;
    if opts.figures {
        let html = case_report(&spec.exp, case, row, &written, &opts.provenance);
        write_string_atomically(&dir.join("report.html"), &html)?;
    }
    Ok(CompareOutcome {
        servo: servo_summary(&spec.exp, case),
        warnings: written.warnings,
        notes,
        compare_csv: written.compare_csv,
        dir,
        row: row.clone(),
        solve_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
}
