//! `flexstar verify`: [`compare`](crate::compare) over the paper's four cases (the three mode
//! families at the thresholds' N, plus the N study), then Table I beside the paper's and the
//! checks of `configs/thresholds.toml`. The cases and the thresholds are built into the binary;
//! `--configs` / `--thresholds` replace them (and drop the paper-specific notes).
//!
//! Outputs in `DIR/`: `table1.{md,csv,json}`, `checks.txt` (every check, its value and bound),
//! `report.html` (all cases), and per case `DIR/<case>/` what `compare` writes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexstar_model::output::{ensure_writable_dir, write_string_atomically};
use flexstar_model::{Experiment, ModeFamily, Provenance};
use rayon::prelude::*;

use crate::builtin::paper_experiments;
use crate::case_output::{validity_warnings, write_case, ValidityWarning};
use crate::figures::Figure;
use crate::report::{html_report, ReportCase, ReportInput};
use crate::runs::{preflight, run_cases, AmmRun, CaseSpec, ProgressFn};
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
    // flexstar's accurate reduced model beside the paper's families (issue 9): enriched family,
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
    CaseSpec { exp, amm, extra }
}

/// Run every case, write the outputs, apply the thresholds.
pub fn run_verify(opts: &VerifyOptions, progress: Option<ProgressFn>) -> Result<VerifyOutcome, Error> {
    let start = Instant::now();
    let thresholds = match &opts.thresholds {
        Some(p) => Thresholds::load(p)?,
        None => Thresholds::builtin()?,
    };
    let paper = opts.configs.is_none();
    let exps: Vec<Experiment> = match &opts.configs {
        Some(files) => files.iter().map(|c| Experiment::load(c)).collect::<Result<_, _>>()?,
        None => paper_experiments(),
    };
    let n_study: &[usize] = if opts.n_study { &thresholds.n_study } else { &[] };
    let specs: Vec<CaseSpec> = exps
        .into_iter()
        .map(|e| verify_spec(e, thresholds.modes, n_study))
        .collect();
    preflight(&specs)?;
    ensure_writable_dir(&opts.out)?;
    for s in &specs {
        ensure_writable_dir(&opts.out.join(&s.exp.name))?;
    }
    let cases = run_cases(&specs, progress)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let table = TableI::compute(&cases, paper)?;
    let checks = thresholds.check(&table);
    let failures = checks.iter().filter(|c| !c.ok).map(|c| c.to_string()).collect();

    // per case: what compare writes
    let per_case: Vec<Vec<Figure>> = specs
        .par_iter()
        .zip(cases.par_iter())
        .zip(table.rows.par_iter())
        .map(|((s, c), row)| {
            let dir = opts.out.join(&s.exp.name);
            let figs = write_case(&dir, &s.exp, c, row, &opts.provenance, opts.figures)?;
            if opts.figures {
                let html = html_report(&ReportInput {
                    title: format!("flexstar compare: {}", s.exp.name),
                    provenance: &opts.provenance,
                    table: None,
                    checks: None,
                    cases: vec![ReportCase {
                        exp: &s.exp,
                        case: c,
                        row,
                        figures: &figs,
                        dir: Path::new(""),
                    }],
                })?;
                write_string_atomically(&dir.join("report.html"), &html)?;
            }
            Ok(figs)
        })
        .collect::<Result<_, Error>>()?;

    let out = &opts.out;
    write_string_atomically(&out.join("table1.md"), &table.to_markdown())?;
    write_string_atomically(&out.join("table1.csv"), &table.to_csv())?;
    write_string_atomically(&out.join("table1.json"), &table.to_json())?;
    write_string_atomically(&out.join("checks.txt"), &checks_text(&checks))?;
    if opts.figures {
        let html = html_report(&ReportInput {
            title: if paper {
                "flexstar verify: the paper's four cases, AMM against FEM".into()
            } else {
                "flexstar verify".into()
            },
            provenance: &opts.provenance,
            table: Some(&table),
            checks: Some(&checks),
            cases: specs
                .iter()
                .zip(&cases)
                .zip(&table.rows)
                .zip(&per_case)
                .map(|(((s, c), row), figs)| ReportCase {
                    exp: &s.exp,
                    case: c,
                    row,
                    figures: figs,
                    dir: Path::new(&s.exp.name),
                })
                .collect(),
        })?;
        write_string_atomically(&out.join("report.html"), &html)?;
    }
    let warnings = specs
        .iter()
        .zip(&cases)
        .flat_map(|(s, c)| validity_warnings(&s.exp, c))
        .collect();
    Ok(VerifyOutcome {
        table,
        checks,
        failures,
        warnings,
        solve_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
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
