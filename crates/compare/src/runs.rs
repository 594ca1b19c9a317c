//! The solver runs behind `flexstar compare` and `flexstar verify`: per experiment, the FEM
//! reference and a list of AMM runs, each a (label, [`AmmSettings`]) pair, run in parallel (rayon)
//! after every check that can be made before the work.
//!
//! A new AMM variant (e.g. flexstar's accurate model) is one more [`AmmRun`] in the list; the
//! EVPs, Table I, the figures and the report pick it up by its label.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use flexstar_kinematics::{check_motion, preflight_step, CheckedMotion};
use flexstar_model::{AmmSettings, Experiment, ModeFamily, Response};
use flexstar_solve::{Settings, SolveError};
use rayon::prelude::*;

/// One AMM run of an experiment: a label (unique within the experiment, used as column name,
/// `compare.csv` model and file name `amm-<label>.csv`) and the solver settings.
#[derive(Debug, Clone, PartialEq)]
pub struct AmmRun {
    pub label: String,
    pub settings: AmmSettings,
}

impl AmmRun {
    /// The run of one mode family with the experiment's other `[amm]` settings (model, N or tol,
    /// step, snapshots), labelled by the family's name.
    pub fn family(exp_settings: &AmmSettings, family: ModeFamily) -> Self {
        AmmRun {
            label: family.name().to_string(),
            settings: AmmSettings {
                family,
                ..exp_settings.clone()
            },
        }
    }

    /// The paper's setting (`AmmSettings::paper`) for `family` with N modes, keeping the
    /// experiment's step and snapshots, labelled by the family's name.
    pub fn paper(exp_settings: &AmmSettings, family: ModeFamily, modes: usize) -> Self {
        AmmRun {
            label: family.name().to_string(),
            settings: AmmSettings {
                snapshots: exp_settings.snapshots.clone(),
                dt: exp_settings.dt,
                ..AmmSettings::paper(family, modes)
            },
        }
    }

    /// File stem of the run's outputs: `amm-<label>`.
    pub fn file_stem(&self) -> String {
        format!("amm-{}", self.label)
    }
}

/// What to run for one experiment.
#[derive(Debug, Clone)]
pub struct CaseSpec {
    pub exp: Experiment,
    /// The AMM runs compared with the FEM (EVPs, figures, table columns).
    pub amm: Vec<AmmRun>,
    /// Further AMM runs reported as mean EVPs only (the N study of `verify`).
    pub extra: Vec<AmmRun>,
    /// A refined FEM that error estimates are judged against (`verify`, `docs/validation.md`
    /// section 8: the estimate is compared with the true EVP against the converged FEM); `None`:
    /// no such run.
    pub reference: Option<flexstar_model::FemSettings>,
}

/// Solver results of one experiment.
#[derive(Debug, Clone)]
pub struct CaseResults {
    pub name: String,
    pub description: String,
    /// Beam length L [m] (lever arm of the slope at G, small-deflection bound).
    pub beam_length: f64,
    pub fem: Response,
    /// The compared AMM runs, in the order of [`CaseSpec::amm`].
    pub amm: Vec<(AmmRun, Response)>,
    /// The further runs of [`CaseSpec::extra`].
    pub extra: Vec<(AmmRun, Response)>,
    /// The run of [`CaseSpec::reference`].
    pub fem_reference: Option<Response>,
}

/// Errors that stop the runs (each names the experiment file).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{file}: {reason}")]
    Input { file: String, reason: String },
    /// The motion leaves the feasible range (the preflight's scan).
    #[error("{file}: {source}")]
    Infeasible {
        file: String,
        #[source]
        source: flexstar_kinematics::Infeasible,
    },
    #[error("{file}: AMM {label}: {source}")]
    Amm {
        file: String,
        label: String,
        #[source]
        source: Box<flexstar_amm::AmmError>,
    },
    #[error("{file}: FEM: {source}")]
    Fem {
        file: String,
        #[source]
        source: Box<flexstar_fem::FemError>,
    },
}

/// Progress of a batch of runs, as reported to the caller's callback.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Runs finished.
    pub done: usize,
    /// Runs in all.
    pub total: usize,
    /// Fraction of the whole work done, 0..1 (FEM runs report partial progress, AMM runs count
    /// when they finish).
    pub fraction: f64,
    /// Seconds since the start.
    pub elapsed: f64,
}

/// Callback receiving [`Progress`]; called from worker threads.
pub type ProgressFn<'a> = &'a (dyn Fn(Progress) + Sync);

/// Experiments that passed [`preflight`]: the only input [`run_cases`] takes, so that the checks
/// run once per batch.
#[derive(Debug, Clone)]
pub struct Checked<'a> {
    specs: &'a [CaseSpec],
    /// Per spec: the proof of its feasibility scan, handed to the solvers.
    motions: Vec<CheckedMotion>,
    /// Per spec: the problem the solvers take, built once from its experiment.
    problems: Vec<flexstar_model::Problem>,
}

impl<'a> Checked<'a> {
    /// The checked experiments, in the order given to [`preflight`].
    pub fn specs(&self) -> &'a [CaseSpec] {
        self.specs
    }
}

/// Everything that can be checked before the work, for every experiment and run: the settings
/// of each AMM run (keys named relative to the experiment file), unique labels, and the
/// feasibility of the trajectory over the whole span.
pub fn preflight(specs: &[CaseSpec]) -> Result<Checked<'_>, RunError> {
    let mut motions = Vec::with_capacity(specs.len());
    let mut problems = Vec::with_capacity(specs.len());
    for spec in specs {
        let exp = &spec.exp;
        let file = exp.source.display().to_string();
        let input = |reason: String| RunError::Input {
            file: file.clone(),
            reason,
        };
        for run in spec.amm.iter().chain(&spec.extra) {
            run.settings
                .validate(exp.time.dt_out)
                .map_err(|e| input(format!("AMM {}: {}", run.label, e.detail())))?;
        }
        for (k, run) in spec.amm.iter().enumerate() {
            if spec.amm[..k].iter().any(|r| r.label == run.label) {
                return Err(input(format!("two AMM runs labelled {}", run.label)));
            }
        }
        let motion = check_motion(
            &exp.robot,
            &exp.trajectory,
            exp.time.t_end,
            preflight_step(exp.time.dt_out),
        )
        .map_err(|source| RunError::Infeasible {
            file: file.clone(),
            source,
        })?;
        motions.push(motion);
        let problem = exp.problem().map_err(|e| input(e.detail()))?;
        // a sensor where a sleeve passes (docs/sensors.md Eq. S10)
        flexstar_kinematics::check_sensor_mounts(exp, problem.sensors()).map_err(|e| input(e.detail()))?;
        problems.push(problem);
    }
    Ok(Checked {
        specs,
        motions,
        problems,
    })
}

enum Job {
    Fem(usize),
    /// The refined FEM of [`CaseSpec::reference`].
    Reference(usize),
    Amm(usize, usize),
    Extra(usize, usize),
}

/// Weight of a FEM run in the progress fraction, against 1 for an AMM run (the FEM takes about
/// twenty times as long as one AMM run at the paper's settings).
const FEM_WEIGHT: f64 = 20.0;
/// Weight of the refined reference FEM (four times the elements, an eighth of the step).
const REFERENCE_WEIGHT: f64 = 32.0 * FEM_WEIGHT;

struct Tracker<'a> {
    start: Instant,
    total: usize,
    /// Per job: its weight in the progress fraction.
    weights: Vec<f64>,
    done: AtomicUsize,
    /// Per job: fraction done, as f64 bits.
    fractions: Vec<AtomicU64>,
    callback: Option<ProgressFn<'a>>,
    last: Mutex<f64>,
}

impl Tracker<'_> {
    fn set(&self, job: usize, f: f64, finished: bool) {
        self.fractions[job].store(f.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
        if finished {
            self.done.fetch_add(1, Ordering::Relaxed);
        }
        let Some(cb) = self.callback else { return };
        let elapsed = self.start.elapsed().as_secs_f64();
        // at most ten reports a second, and every finished run
        {
            let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
            if !finished && elapsed - *last < 0.1 {
                return;
            }
            *last = elapsed;
        }
        let sum: f64 = self
            .fractions
            .iter()
            .zip(&self.weights)
            .map(|(a, w)| w * f64::from_bits(a.load(Ordering::Relaxed)))
            .sum();
        let all: f64 = self.weights.iter().sum();
        cb(Progress {
            done: self.done.load(Ordering::Relaxed),
            total: self.total,
            fraction: if all > 0.0 { sum / all } else { 1.0 },
            elapsed,
        });
    }
}

fn run_error(file: String, label: &str, e: SolveError) -> RunError {
    match e {
        SolveError::Amm(source) => RunError::Amm {
            file,
            label: label.to_string(),
            source: Box::new(source),
        },
        SolveError::Fem(source) => RunError::Fem {
            file,
            source: Box::new(source),
        },
        SolveError::Drive(e) | SolveError::Tracking(e) => RunError::Input {
            file,
            reason: e.to_string(),
        },
        SolveError::Robot(e) => RunError::Input {
            file,
            reason: e.to_string(),
        },
    }
}

/// The jobs of a batch: AMM runs first (they are short, and a failing one stops the batch
/// early), then the further runs, the FEM runs and the refined references.
fn jobs_of(specs: &[CaseSpec]) -> Vec<Job> {
    let mut jobs = Vec::new();
    for (k, s) in specs.iter().enumerate() {
        jobs.extend((0..s.amm.len()).map(|j| Job::Amm(k, j)));
    }
    for (k, s) in specs.iter().enumerate() {
        jobs.extend((0..s.extra.len()).map(|j| Job::Extra(k, j)));
    }
    jobs.extend((0..specs.len()).map(Job::Fem));
    jobs.extend(
        (0..specs.len())
            .filter(|k| specs[*k].reference.is_some())
            .map(Job::Reference),
    );
    jobs
}

/// The results of the jobs, sorted into their cases.
fn assemble(specs: &[CaseSpec], jobs: &[Job], results: Vec<Response>) -> Vec<CaseResults> {
    let mut cases: Vec<CaseResults> = specs
        .iter()
        .map(|s| CaseResults {
            name: s.exp.name.clone(),
            description: s.exp.description.clone(),
            beam_length: s.exp.robot.l,
            fem: Response::default(),
            amm: Vec::new(),
            extra: Vec::new(),
            fem_reference: None,
        })
        .collect();
    for (job, r) in jobs.iter().zip(results) {
        match *job {
            Job::Fem(k) => cases[k].fem = r,
            Job::Reference(k) => cases[k].fem_reference = Some(r),
            Job::Amm(k, i) => cases[k].amm.push((specs[k].amm[i].clone(), r)),
            Job::Extra(k, i) => cases[k].extra.push((specs[k].extra[i].clone(), r)),
        }
    }
    cases
}

/// Run every FEM and AMM run of the experiments that passed [`preflight`], in parallel. Results
/// come back in the order of the specs.
pub fn run_cases(checked: Checked, progress: Option<ProgressFn>) -> Result<Vec<CaseResults>, RunError> {
    let specs = checked.specs();
    let jobs = jobs_of(specs);
    let tracker = Tracker {
        start: Instant::now(),
        total: jobs.len(),
        weights: jobs
            .iter()
            .map(|j| match j {
                Job::Fem(_) => FEM_WEIGHT,
                Job::Reference(_) => REFERENCE_WEIGHT,
                _ => 1.0,
            })
            .collect(),
        done: AtomicUsize::new(0),
        fractions: (0..jobs.len()).map(|_| AtomicU64::new(0)).collect(),
        callback: progress,
        last: Mutex::new(f64::NEG_INFINITY),
    };
    let file = |k: usize| specs[k].exp.source.display().to_string();
    // the caller's stop token (Ctrl-C in Python) goes to every worker thread: the solvers poll it
    let token = flexstar_model::cancel::current();
    let results: Vec<Response> = jobs
        .par_iter()
        .enumerate()
        .map(|(j, job)| {
            let r = flexstar_model::cancel::with_cancel(token.as_ref(), || match *job {
                Job::Fem(k) => {
                    let exp = &specs[k].exp;
                    let tick = |f: f64| tracker.set(j, f, false);
                    let problem = &checked.problems[k];
                    flexstar_solve::response(problem, Settings::Fem(&exp.fem), Some(&checked.motions[k]), Some(&tick))
                        .map_err(|e| run_error(file(k), "fem", e))
                }
                Job::Reference(k) => {
                    let exp = &specs[k].exp;
                    let settings = specs[k].reference.as_ref().unwrap_or(&exp.fem);
                    let tick = |f: f64| tracker.set(j, f, false);
                    let problem = &checked.problems[k];
                    flexstar_solve::response(problem, Settings::Fem(settings), Some(&checked.motions[k]), Some(&tick))
                        .map_err(|e| run_error(file(k), "fem (refined reference)", e))
                }
                Job::Amm(k, i) | Job::Extra(k, i) => {
                    let run = match job {
                        Job::Amm(..) => &specs[k].amm[i],
                        _ => &specs[k].extra[i],
                    };
                    let settings = Settings::Amm(&run.settings);
                    flexstar_solve::response(&checked.problems[k], settings, Some(&checked.motions[k]), None)
                        .map_err(|e| run_error(file(k), &run.label, e))
                }
            })?;
            if let Some(reason) = r.not_finite_reason() {
                let k = match *job {
                    Job::Fem(k) | Job::Reference(k) | Job::Amm(k, _) | Job::Extra(k, _) => k,
                };
                return Err(RunError::Input { file: file(k), reason });
            }
            tracker.set(j, 1.0, true);
            Ok(r)
        })
        .collect::<Result<_, RunError>>()?;

    Ok(assemble(specs, &jobs, results))
}
