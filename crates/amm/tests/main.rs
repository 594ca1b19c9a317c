//! The crate's integration tests, one test binary: each file of this folder a module (one binary
//! compiles and links once instead of once per file: the test build's time, docs/python.md
//! "Build time").
//! `alloc.rs` stays a binary of its own: it installs a counting global allocator.
mod as_built;
mod attachments;
mod cancel;
mod common;
mod direct;
mod friction;
mod full_model;
mod gravity_sag;
mod gravity_start;
mod modes;
mod physics;
#[path = "../../../tests/support/rigid_forward.rs"]
#[allow(dead_code)]
mod rigid_forward;
mod short_motion;
mod sleeve_compliance;
mod work_counts;
