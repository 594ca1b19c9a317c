//! The workspace-level checks through the libraries, one test binary: each file a module (one
//! binary compiles and links once instead of once per file: the test build's time,
//! docs/python.md "Build time").
mod architecture;
mod as_built_models;
mod attachment_models;
mod cross_models;
mod direct_models;
mod friction_models;
mod measured;
mod measured_identify;
#[path = "support/models.rs"]
mod models;
mod sensors;
mod verify;
