//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
mod envelope;
mod envelope_as_built;
#[path = "support/envelope_cases.rs"]
mod envelope_cases;
mod per_beam;
mod study;
#[path = "support/tiny_study.rs"]
mod tiny_study;
