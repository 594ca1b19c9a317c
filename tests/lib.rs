//! # flexstar-tests
//!
//! Workspace-level checks that go through the libraries rather than the `flexstar` binary, each
//! against a reference independent of the code it checks (`docs/validation.md`):
//!
//! - `cross_models.rs`: the accurate AMM against the FEM on motions of our own;
//! - `direct_models.rs`: the direct problem in both solvers under the same actuator forces;
//! - `attachment_models.rs`: payload, damping and load in both solvers;
//! - `verify.rs`: Table I's checks (`configs/thresholds.toml`) as a test.
//!
//! The command line's contracts (files, flags, messages) are tested by `flexstar-cli`, whose tests
//! run the binary; they live in this folder too (`cli.rs`, `sweep.rs`, ...).
