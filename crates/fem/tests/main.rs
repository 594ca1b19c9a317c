//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
mod as_built;
mod attachments;
mod baseline_copy;
mod beam_benchmarks;
mod convergence;
mod direct;
#[path = "support/fit.rs"]
mod fit;
mod friction;
mod gravity;
#[path = "../../../tests/support/rigid_forward.rs"]
#[allow(dead_code)]
mod rigid_forward;
#[path = "support/run.rs"]
mod run;
mod sleeve_heavy;
mod star;
