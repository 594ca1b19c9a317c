//! Running a study: every case of the study (or of one shard) in parallel with rayon, each case's
//! rows appended to the results table as soon as it finishes, cases already in the table skipped
//! (an interrupted study resumes), and the finished table rewritten in the study's case order.

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use flexstar_model::{Experiment, Response};
use rayon::prelude::*;

use crate::error::StudyError;
use crate::metrics::{largest_point_evp, peaks, residual_columns};
use crate::patch::value_text;
use crate::sample::Case;
use crate::shard::{meta_file, results_file, write_pair, Meta, Shard};
use crate::spec::{FemReference, Sampling, Solver, Study};
use crate::table::{header, records_bytes, Row, Table, OK};
use flexstar_solve::Settings;

/// Where and how to run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Results go to `<out>/<study name>/`.
    pub out: PathBuf,
    /// Worker threads; `None` uses rayon's default (`RAYON_NUM_THREADS` or every core).
    pub jobs: Option<usize>,
    /// Run only this slice of the cases.
    pub shard: Option<Shard>,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// The results table written.
    pub results: PathBuf,
    /// Cases this table holds (the whole study or the shard).
    pub cases: usize,
    /// Cases found already done in the table and skipped.
    pub skipped: usize,
    /// Cases run now.
    pub ran: usize,
    /// Rows of the finished table whose status is not `ok`.
    pub failed_rows: usize,
    /// Wall-clock time of the run [s].
    pub seconds: f64,
}

/// Run `study` as `opts` say; `progress(done, total)` is called after each case of this run.
///
/// Errors are raised before any case runs (keys, an existing table of another study) or when a
/// file cannot be written; a case that fails is a row whose `status` says why.
pub fn run_study(
    study: &Study,
    opts: &RunOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RunOutcome, StudyError> {
    let started = Instant::now();
    // the worker threads first: a --jobs the system refuses writes nothing
    let pool = opts.jobs.map(|n| worker_pool(study, n)).transpose()?;
    let mine: Vec<Case> = study.shard_cases(opts.shard).collect();
    let dir = opts.out.join(&study.name);
    let results = results_file(&dir, opts.shard);
    let meta = meta_of(study, study.case_count(), &mine, opts.shard);
    let done = prepare_table(&results, &meta, &header(&study.keys()))?;
    let todo: Vec<&Case> = mine
        .iter()
        .filter(|c| {
            !study
                .solvers
                .iter()
                .all(|s| done.contains(&(c.run_id.clone(), s.name().to_string())))
        })
        .collect();

    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(&results)
        .map_err(|e| write_error(&results, e.to_string()))?;
    let file = Mutex::new(file);
    let finished = AtomicUsize::new(0);
    // a stop on request is polled between cases (the worker threads do not share the caller's)
    let cancel = flexstar_model::cancel::current();
    let work = || {
        todo.par_iter().try_for_each(|case| {
            if cancel.as_ref().is_some_and(flexstar_model::Cancel::is_cancelled) {
                let done = finished.load(Ordering::Relaxed);
                return Err(StudyError::Cancelled {
                    results: results.clone(),
                    done,
                    total: todo.len(),
                });
            }
            let rows: Vec<Vec<String>> = run_case(study, case).iter().map(Row::record).collect();
            let bytes = records_bytes(&rows).map_err(|e| write_error(&results, e.to_string()))?;
            {
                let mut f = file.lock().unwrap_or_else(|p| p.into_inner());
                f.write_all(&bytes)
                    .and_then(|_| f.flush())
                    .map_err(|e| write_error(&results, e.to_string()))?;
            }
            progress(finished.fetch_add(1, Ordering::Relaxed) + 1, todo.len());
            Ok::<(), StudyError>(())
        })
    };
    match pool {
        Some(pool) => pool.install(work)?,
        None => work()?,
    }
    drop(file);

    let table = finish_table(&results, &mine, &study.solvers)?;
    let status = table.column("status").unwrap_or(0);
    Ok(RunOutcome {
        failed_rows: table.rows.iter().filter(|r| r[status] != OK).count(),
        results,
        cases: mine.len(),
        skipped: mine.len() - todo.len(),
        ran: todo.len(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Most worker threads `--jobs` may ask for.
pub const MAX_JOBS: usize = 1024;

/// The thread pool of `--jobs n` (1..=[`MAX_JOBS`]).
fn worker_pool(study: &Study, n: usize) -> Result<rayon::ThreadPool, StudyError> {
    let bad = |reason: String| StudyError::invalid(&study.file, "--jobs", reason);
    if n == 0 || n > MAX_JOBS {
        return Err(bad(format!("{n}: give 1 to {MAX_JOBS} worker threads")));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| bad(format!("{n} worker threads: {e}")))
}

fn write_error(file: &std::path::Path, reason: String) -> StudyError {
    StudyError::Write(flexstar_model::ModelError::Write {
        file: file.to_path_buf(),
        reason,
    })
}

fn meta_of(study: &Study, total: usize, mine: &[Case], shard: Option<Shard>) -> Meta {
    Meta {
        study: study.name.clone(),
        hash: study.hash.clone(),
        study_file: study.file.display().to_string(),
        keys: study.keys(),
        solvers: study.solvers.iter().map(|s| s.name().to_string()).collect(),
        grid_levels: match study.sampling {
            Sampling::Grid => study.vary.iter().map(|v| v.grid_values().len()).collect(),
            Sampling::Lhs { .. } | Sampling::Random { .. } => Vec::new(),
        },
        shard: shard.map(|s| [s.k, s.n]),
        total_cases: total,
        cases: mine.iter().map(|c| c.run_id.clone()).collect(),
    }
}

/// Create the table (header only) and its sidecar, or check that an existing one belongs to this
/// study and return the `(run_id, solver)` pairs it already holds. A last line cut short by an
/// interruption is removed so that appending starts on a fresh line.
fn prepare_table(
    results: &std::path::Path,
    meta: &Meta,
    header: &[String],
) -> Result<HashSet<(String, String)>, StudyError> {
    let meta_path = meta_file(results);
    if let Some(dir) = results.parent() {
        flexstar_io::run_set::recover(dir)?;
    }
    if !results.exists() {
        let empty = Table {
            header: header.to_vec(),
            rows: Vec::new(),
        };
        write_pair(results, &empty, meta)?;
        return Ok(HashSet::new());
    }
    let other = |reason: String| StudyError::Results {
        file: results.to_path_buf(),
        reason,
    };
    if !meta_path.exists() {
        return Err(other(format!(
            "exists without its sidecar {}: cannot tell which study wrote it (move it away to start afresh)",
            meta_path.display()
        )));
    }
    let old = Meta::read(&meta_path)?;
    if old.hash != meta.hash || old.shard != meta.shard {
        return Err(other(format!(
            "was written by another study or split (hash {}{}; this run: hash {}{}): \
             give another --out or move it away",
            old.hash,
            old.shard_text(),
            meta.hash,
            meta.shard_text()
        )));
    }
    let text_len = std::fs::metadata(results).map(|m| m.len()).unwrap_or(0);
    let table = Table::read(results)?;
    if table.header != header {
        return Err(other("its header is not this study's".into()));
    }
    let whole = records_bytes(std::iter::once(&table.header).chain(&table.rows)).map_err(|e| other(e.to_string()))?;
    if whole.len() as u64 != text_len {
        table.write(results)?; // drop a cut-short last line
    }
    let (id, solver) = (0, table.column("solver").unwrap_or(0));
    Ok(table.rows.iter().map(|r| (r[id].clone(), r[solver].clone())).collect())
}

/// Rewrite the table in the study's case order (solvers in the study's order), keeping the last
/// row of any (run_id, solver) pair written twice.
fn finish_table(results: &std::path::Path, mine: &[Case], solvers: &[Solver]) -> Result<Table, StudyError> {
    let mut table = Table::read(results)?;
    let solver_col = table.column("solver").unwrap_or(0);
    let order: HashMap<&str, usize> = mine.iter().map(|c| (c.run_id.as_str(), c.index)).collect();
    let solver_rank = |s: &str| solvers.iter().position(|x| x.name() == s).unwrap_or(usize::MAX);
    let mut last: HashMap<(String, String), Vec<String>> = HashMap::new();
    for r in table.rows.drain(..) {
        last.insert((r[0].clone(), r[solver_col].clone()), r);
    }
    let mut rows: Vec<Vec<String>> = last.into_values().collect();
    rows.sort_by_key(|r| {
        (
            order.get(r[0].as_str()).copied().unwrap_or(usize::MAX),
            solver_rank(&r[solver_col]),
        )
    });
    table.rows = rows;
    table.write(results)?;
    Ok(table)
}

/// A solver's outcome: the response or why there is none, and the wall time [s].
type Solved = (Result<Response, Failure>, f64);

/// Why a case has no response for a solver: its status in the table.
#[derive(Debug, thiserror::Error)]
enum Failure {
    /// The case's experiment could not be built from the study's values.
    #[error("invalid: {0}")]
    Invalid(String),
    /// The solver stopped with an error.
    #[error("failed: {0}")]
    Solver(#[from] flexstar_solve::SolveError),
    /// The solver panicked (its message, if it had one).
    #[error("failed: the solver panicked: {0}")]
    Panicked(String),
}

fn solve(exp: &Experiment, solver: Solver, fem_reference: FemReference) -> Solved {
    let started = Instant::now();
    let fem = match fem_reference {
        FemReference::Defaults => exp.fem.clone(),
        FemReference::Refined => flexstar_solve::reference_fem(exp),
    };
    // the case's sensors on the case's robot: beyond a beam (`problem`), where a sleeve passes
    // (Eq. S10 of docs/sensors.md): an invalid case with the reason, never read
    let problem = match exp
        .problem()
        .and_then(|p| flexstar_kinematics::check_problem_sensor_mounts(&p).map(|()| p))
    {
        Ok(p) => p,
        Err(e) => return (Err(Failure::Invalid(e.detail())), started.elapsed().as_secs_f64()),
    };
    let result = catch_unwind(AssertUnwindSafe(|| match solver {
        // each solver scans the case's motion itself: a case's solvers may run in different shards
        Solver::Amm => flexstar_solve::response(&problem, Settings::Amm(&exp.amm), None, None),
        Solver::Fem => flexstar_solve::response(&problem, Settings::Fem(&fem), None, None),
    }));
    let result = match result {
        Ok(r) => r.map_err(Failure::from),
        Err(panic) => Err(Failure::Panicked(panic_text(&panic))),
    };
    (result, started.elapsed().as_secs_f64())
}

/// The modal metrics of a case, once per case: the end of the motion with the settling hold
/// (`residual_*`, `settle_s`) and the first frequency at the start pose (`f1_hz`). A metric that
/// fails (a modal analysis that refuses the robot, a pose it cannot hold) leaves its columns
/// empty and says why on stderr, naming the study and the case; the solver columns stay.
fn case_metrics(study: &Study, case: &Case, exp: &Experiment) -> (Option<(f64, f64)>, Option<f64>) {
    let note = |columns: &str, reason: String| {
        eprintln!(
            "{}: case {}: {columns} left empty: {}",
            study.file.display(),
            case.run_id,
            reason.replace(['\n', '\r'], " ")
        );
    };
    let guarded = |f: &dyn Fn() -> Result<Option<f64>, String>| -> Result<Option<f64>, String> {
        catch_unwind(AssertUnwindSafe(f))
            .unwrap_or_else(|p| Err(format!("the modal analysis panicked: {}", panic_text(&p))))
    };
    let rest = flexstar_modal::settle::motion_end(exp).and_then(|t_rest| {
        match guarded(&|| flexstar_modal::settle::settle_hold_s(exp).map_err(|e| e.to_string())) {
            Ok(hold) => hold.map(|h| (t_rest, h)),
            Err(e) => {
                note("residual_tip_m, residual_G_m, settle_s", e);
                None
            }
        }
    });
    let f1 = guarded(&|| {
        flexstar_modal::analysis::start_pose_frequencies(exp, 1)
            .map(|f| f.first().copied())
            .map_err(|e| e.to_string())
    });
    let f1_hz = f1.unwrap_or_else(|e| {
        note("f1_hz", e);
        None
    });
    (rest, f1_hz)
}

/// The message of a caught panic.
fn panic_text(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| panic.downcast_ref::<&str>().copied())
        .unwrap_or("(no message)")
        .to_string()
}

/// Run every solver of the study on one case and make its rows (one per solver).
pub fn run_case(study: &Study, case: &Case) -> Vec<Row> {
    let values: Vec<String> = case.values.iter().map(value_text).collect();
    let exp = study.experiment(&case.values);
    let solved: Vec<(Solver, Solved)> = study
        .solvers
        .iter()
        .map(|&s| {
            let out = match &exp {
                Ok(e) => solve(e, s, study.fem_reference),
                Err(reason) => (Err(Failure::Invalid(reason.clone())), 0.0),
            };
            (s, out)
        })
        .collect();
    let response = |want: Solver| {
        solved
            .iter()
            .find(|(s, _)| *s == want)
            .and_then(|(_, (r, _))| r.as_ref().ok())
    };
    let evp = match (response(Solver::Amm), response(Solver::Fem)) {
        (Some(a), Some(f)) => flexstar_metrics::evp::point_evps(a, f).ok(),
        _ => None,
    };
    let exp = exp.as_ref().ok();
    let (rest, f1_hz) = match exp {
        Some(e) => case_metrics(study, case, e),
        None => (None, None),
    };
    solved
        .iter()
        .map(|(solver, (result, wall_s))| {
            let mut row = Row {
                run_id: case.run_id.clone(),
                values: values.clone(),
                solver: solver.name().to_string(),
                status: OK.to_string(),
                peak_tip_m: None,
                peak_wg_m: None,
                peak_fa_n: None,
                evp_percent: None,
                wall_s: *wall_s,
                residual_tip_m: None,
                modes: None,
                error_estimate_percent: None,
                residual_g_m: None,
                settle_s: None,
                evp_max_percent: None,
                f1_hz,
            };
            match result {
                Ok(r) => {
                    let p = peaks(r);
                    row.peak_tip_m = Some(p.tip_m);
                    row.peak_wg_m = Some(p.w_g_m);
                    row.peak_fa_n = Some(p.fa_n);
                    if *solver == Solver::Amm {
                        row.evp_percent = evp.as_ref().and_then(|e| e.mean);
                        row.evp_max_percent = evp.as_ref().and_then(largest_point_evp);
                    }
                    if let (Some(exp), Some(rest)) = (exp, rest) {
                        let pinned = *solver == Solver::Amm && exp.amm.family == flexstar_model::ModeFamily::PinnedFree;
                        (row.residual_tip_m, row.residual_g_m, row.settle_s) = residual_columns(exp, r, rest, pinned);
                    }
                    row.modes = r.info.modes;
                    row.error_estimate_percent = r.info.error_estimate_percent;
                }
                // one line per row of the table
                Err(failure) => row.status = failure.to_string().replace(['\n', '\r'], " "),
            }
            row
        })
        .collect()
}
