//! `flexstar verify`: [`compare`](crate::compare) over the paper's four cases (the three mode
//! families at the thresholds' N, plus the N study), then Table I beside the paper's and the
//! checks of `configs/thresholds.toml`. The cases and the thresholds are built into the binary;
//! `--configs` / `--thresholds` replace them (and drop the paper-specific notes).
//!
//! Outputs in `DIR/`: `table1.{md,csv,json}`, `checks.txt` (every check, its value and bound),
//! `report.html` (all cases), and per case `DIR/<case>/` what `compare` writes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_io::output::{ensure_writable_dir, write_string_atomically};
use flexstar_model::{Experiment, ModeFamily, Provenance};
use rayon::prelude::*;

use crate::builtin::paper_experiments;
use crate::case_output::{write_case, ValidityWarning, WrittenCase};
use crate::report::{case_report, html_report, ReportCase, ReportInput};
use crate::runs::{preflight, run_cases, AmmRun, CaseResults, CaseSpec, ProgressFn};
use crate::table::TableI;
use crate::thresholds::{Check, Thresholds};
use crate::Error;

/// Kept for callers of the previous API.
pub type VerifyError = Error;

/// What to verify and where to write.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    /// Experiment files, one per case; `None`: the paper's four cases built into the binary.
    pub configs: Option<Vec<PathBuf>>,
    /// Thresholds file; `None`: the built-in `configs/thresholds.toml`.
    pub thresholds: Option<PathBuf>,
    /// Output directory.
    pub out: PathBuf,
    /// Draw figures and the reports (the CI regression test checks numbers only).
    pub figures: bool,
    /// Also run the AMM at the `n_study` mode counts of the thresholds file (table columns only).
    pub n_study: bool,
    /// Version, commit and date written into every output.
    pub provenance: Provenance,
}

/// The result of a verify run.
#[derive(Debug)]
pub struct VerifyOutcome {
    pub table: TableI,
    /// Every check with its value and bound.
    pub checks: Vec<Check>,
    /// The failed checks, as sentences; empty when everything holds.
    pub failures: Vec<String>,
    /// Runs that leave the small-deflection range of the AMM.
    pub warnings: Vec<ValidityWarning>,
    /// Wall time of the solves and of the whole run [s].
    pub solve_seconds: f64,
    pub total_seconds: f64,
}

/// The AMM runs of a paper case: the three families of Table I at N = `modes` (the paper's
/// equations), and the N study. flexstar's own models are added to `amm` as further
/// [`AmmRun`]s.
pub fn verify_spec(exp: Experiment, modes: usize, n_study: &[usize]) -> CaseSpec {
    let mut amm: Vec<AmmRun> = ModeFamily::PAPER
        .iter()
        .map(|f| AmmRun::paper(&exp.amm, *f, modes))
        .collect();
    // flexstar's accurate reduced model beside the paper's families (docs/amm.md sections 7-9): enriched family,
    // full model, automatic N at the default tolerance
    amm.push(AmmRun {
        label: ModeFamily::Enriched.name().to_string(),
        settings: flexstar_model::AmmSettings {
            snapshots: exp.amm.snapshots.clone(),
            ..flexstar_model::AmmSettings::accurate()
        },
    });
    let extra = ModeFamily::PAPER
        .iter()
        .flat_map(|f| {
            n_study
                .iter()
                .filter(|n| **n != modes)
                .map(|n| AmmRun::paper(&exp.amm, *f, *n))
                .collect::<Vec<_>>()
        })
        .collect();
    let reference = Some(flexstar_solve::reference_fem(&exp));
    CaseSpec {
        exp,
        amm,
        extra,
        reference,
    }
}

/// Run every case, write the outputs, apply the thresholds.
pub fn run_verify(opts: &VerifyOptions, progress: Option<ProgressFn>) -> Result<VerifyOutcome, Error> {
    let start = Instant::now();
    let thresholds = match &opts.thresholds {
        Some(p) => Thresholds::load(p)?,
        None => Thresholds::builtin()?,
    };
    let specs = load_specs(opts, &thresholds)?;
    let checked = preflight(&specs)?;
    ensure_writable_dir(&opts.out)?;
    for s in &specs {
        ensure_writable_dir(&opts.out.join(&s.exp.name))?;
    }
    let cases = run_cases(checked, progress)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let table = TableI::compute(&cases, opts.configs.is_none())?;
    let checks = thresholds.check(&table);
    let failures = checks.iter().filter(|c| !c.ok).map(|c| c.to_string()).collect();
    let verified = Verified {
        specs: &specs,
        cases: &cases,
        table: &table,
        checks: &checks,
    };
    let per_case = write_cases(opts, &verified)?;
    write_summary(opts, &verified, &per_case)?;
    let warnings = per_case.into_iter().flat_map(|w| w.warnings).collect();
    Ok(VerifyOutcome {
        table,
        checks,
        failures,
        warnings,
        solve_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The cases to verify: the experiment files given, or the paper's four built-in cases, each
/// with the runs of [`verify_spec`].
fn load_specs(opts: &VerifyOptions, thresholds: &Thresholds) -> Result<Vec<CaseSpec>, Error> {
    let exps: Vec<Experiment> = match &opts.configs {
        Some(files) => files
            .iter()
            .map(|c| Experiment::load(c).and_then(flexstar_shaping::shape_loaded))
            .collect::<Result<_, _>>()?,
        None => paper_experiments(),
    };
    let n_study: &[usize] = if opts.n_study { &thresholds.n_study } else { &[] };
    Ok(exps
        .into_iter()
        .map(|e| verify_spec(e, thresholds.modes, n_study))
        .collect())
}

/// What a verify run computed, handed to the writers.
struct Verified<'a> {
    specs: &'a [CaseSpec],
    cases: &'a [CaseResults],
    table: &'a TableI,
    checks: &'a [Check],
}

/// Per case, in parallel: what compare writes, and the case's own report.
fn write_cases(opts: &VerifyOptions, v: &Verified) -> Result<Vec<WrittenCase>, Error> {
    v.specs
        .par_iter()
        .zip(v.cases.par_iter())
        .zip(v.table.rows.par_iter())
        .map(|((s, c), row)| {
            let dir = opts.out.join(&s.exp.name);
            let written = write_case(&dir, &s.exp, c, row, &opts.provenance, opts.figures)?;
            if opts.figures {
                let html = case_report(&s.exp, c, row, &written, &opts.provenance);
                write_string_atomically(&dir.join("report.html"), &html)?;
            }
            Ok(written)
        })
        .collect()
}

/// Table I, the checks and (with figures) the report of all cases, in `opts.out`.
fn write_summary(opts: &VerifyOptions, v: &Verified, per_case: &[WrittenCase]) -> Result<(), Error> {
    let out = &opts.out;
    write_string_atomically(&out.join("table1.md"), &v.table.to_markdown())?;
    write_string_atomically(&out.join("table1.csv"), &v.table.to_csv())?;
    write_string_atomically(&out.join("table1.json"), &v.table.to_json())?;
    write_string_atomically(&out.join("checks.txt"), &checks_text(v.checks))?;
    if opts.figures {
        let html = html_report(&ReportInput {
            title: if opts.configs.is_none() {
                "flexstar verify: the paper's four cases, AMM against FEM".into()
            } else {
                "flexstar verify".into()
            },
            provenance: &opts.provenance,
            table: Some(v.table),
            checks: Some(v.checks),
            cases: v
                .specs
                .iter()
                .zip(v.cases)
                .zip(&v.table.rows)
                .zip(per_case)
                .map(|(((s, c), row), written)| ReportCase {
                    exp: &s.exp,
                    case: c,
                    row,
                    figures: &written.figures,
                    warnings: &written.warnings,
                    checks: &written.checks,
                    dir: Path::new(&s.exp.name),
                    residuals: written.residuals.as_deref(),
                    dwells: &written.dwells,
                    measured: written.measured_markdown.as_deref(),
                })
                .collect(),
        });
        write_string_atomically(&out.join("report.html"), &html)?;
    }
    Ok(())
}

/// `checks.txt`: one line per check, `PASS` or `FAIL`, the value found and the bound, then a
/// summary line.
pub fn checks_text(checks: &[Check]) -> String {
    let mut s: String = checks.iter().map(|c| format!("{c}\n")).collect();
    let failed = checks.iter().filter(|c| !c.ok).count();
    s.push_str(&format!(
        "{} checks, {} passed, {} failed\n",
        checks.len(),
        checks.len() - failed,
        failed
    ));
    s
}
