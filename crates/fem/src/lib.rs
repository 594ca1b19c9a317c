//! # flexstar-fem
//!
//! The independent finite-element reference model of the flexible star-triangle robot
//! (docs/paper-defects.md, "independent reference"): three co-rotational Euler-Bernoulli beams in absolute
//! coordinates welded at one node G ([`element`]), three rigid sleeves with inertia Jp pinned at
//! the revolute points of Eqs. 1-3 through which the beams slide (`star::sleeve`; with the friction of an
//! experiment's `[friction]`, stick and slip by switching constraint sets, `docs/friction.md` 8), index-3
//! generalized-alpha integration with a structured direct solver (banded beam blocks and a dense
//! border, `bordered`). The driving forces follow from the pin
//! reactions (Eq. 33). Its equations use only the robot parameters, `s_i(t)` and the start
//! configuration; the rigid (Fermat-point) kinematics appears only as initial data and in the
//! post-processing of [`solve`] (projection onto the rigid frames). [`solve`] with a law solves the
//! direct problem (`docs/fem.md` section 8): the sliders, bodies of mass `mpp + mpa`, move under an actuator law
//! (`flexstar_drive`), their coordinates unknowns of the same equations. Both carry an
//! experiment's payload at G, Rayleigh damping (Kelvin-Voigt in the beams, mass-proportional on
//! the motion relative to the rigid robot) and load at G (`docs/fem.md` section 9), skipped at
//! their zero defaults. The robot is the problem's as built: each beam with its own section,
//! length, sleeve and weld angle, each slider on its own axis (`docs/fem.md` section 10; the
//! paper's robot is one value of it, solved bit for bit as before). The formulation, the
//! convergence study behind the defaults and the deviations are in `docs/fem.md`.

#![allow(clippy::needless_range_loop)] // index loops over DOFs read like the equations

mod bordered;
pub mod element;
mod element_pass;
pub mod error;
mod integrator;
pub mod modal_solver;
pub mod pose_modes;
mod sensors;
mod solve;
mod sparse;
mod star;

pub use error::{FemError, LinearError, NewtonFailure, PivotError};
pub use integrator::{Fallback, Stats};
pub use solve::{
    beam_frequency, default_dt, default_dt_of, first_beam_frequency, solve, DEFAULT_DT, DEFAULT_RHO_INF, MIN_DEFAULT_DT,
};
pub use star::InitialState;
