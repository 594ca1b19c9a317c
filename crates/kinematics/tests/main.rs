//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
mod as_built;
mod as_built_dynamics;
mod motions;
#[path = "support/quintic.rs"]
mod quintic;
mod references;
