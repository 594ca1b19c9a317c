//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
mod as_built;
mod attachments;
mod baseline_copy;
mod beam_benchmarks;
mod convergence;
mod direct;
mod friction;
mod gravity;
mod sleeve_heavy;
mod star;
