//! The command line's contracts, one test binary: every file of this folder that runs the built
//! `flexstar` is a module here (one binary compiles and links once instead of once per file: the
//! test build's time, docs/python.md "Build time").
mod animate;
mod attachments;
mod cli;
mod common;
mod export;
mod faults;
mod fit_cli;
mod friction_cli;
mod measured_cli;
mod modal_cli;
mod motions;
mod plan;
mod plan_cycle;
mod residual;
mod sensors_cli;
mod shaping;
mod sweep;
