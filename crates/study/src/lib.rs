//! # flexstar-study
//!
//! Design studies: how sleeve length, sleeve inertia, beam stiffness, motion speed or the number
//! of modes change the vibration of the star and the accuracy of the reduced model.
//!
//! A study file ([`spec`]) names a base experiment, the solvers and the keys to vary; [`sample`]
//! expands it into cases (full-factorial grid or Latin hypercube) with stable run ids; [`patch`]
//! sets each case's values in the base experiment's TOML document, so that every key the
//! experiment format accepts can be varied and the experiment loader rejects the others; [`run`]
//! runs the cases in parallel (rayon), appending one row per case and solver to `results.csv`
//! as they finish and skipping those already there (resume); [`shard`] slices a study for
//! clusters and [`merge`] joins the slices; [`report`] draws the plots and `study.html`.
//! A key may name one beam of a per-beam key, `robot.L[2]` ([`key`]).
//! Metrics are in [`metrics`]: peaks of the tips, of G and of the driving forces, the residual
//! vibration after a rest-to-rest motion, and the AMM's mean EVP against the FEM (Eq. 45).

pub mod derived;
pub mod error;
/// The hash of run ids and study fingerprints (it lives in the model crate, shared with the
/// sidecars).
pub use flexstar_model::hash;
pub mod in_range;
pub mod key;
pub mod merge;
pub mod metrics;
pub mod patch;
pub mod plots;
pub mod report;
pub mod run;
pub mod sag;
pub mod sample;
pub mod shard;
pub mod spec;
pub mod table;
pub mod tie;

pub use error::StudyError;
pub use merge::{merge, MergeReport};
pub use report::write_report;
pub use run::{run_study, RunOptions, RunOutcome};
pub use sample::Case;
pub use shard::Shard;
pub use spec::{FemReference, Sampling, Solver, Study};
