//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
mod as_built;
mod attachments;
#[path = "support/inertia_relief.rs"]
mod inertia_relief;
mod limits;
mod linear_checks;
mod linear_settings;
mod modal_checks;
#[path = "../../../tests/support/rigid_forward.rs"]
#[allow(dead_code)]
mod rigid_forward;
mod stuck;
