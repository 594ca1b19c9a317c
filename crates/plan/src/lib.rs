//! Motion planning for the star robot (`docs/motions.md` section 4): a
//! rest-to-rest motion between two poses that minimises the residual vibration of G after the
//! move, as the accurate AMM computes it, within slider speed, acceleration and force limits and
//! the feasible workspace; or, with `objective = "time"`, the shortest such motion whose residual
//! stays below a bound. By default a plan is smooth (4.10): its peak slider acceleration, jerk
//! and force stay within 1.5 times the plain quintic's, its progress along the path never goes
//! backwards, and a peak above the quintic's is reported as a warning.
//!
//! - [`section`]: the `[plan]` and `[limits]` sections and the plan file;
//! - [`family`]: the motions searched (a clamped quintic spline through interior via points);
//! - [`limits`]: slider peaks, the shortest move the limits allow, the refusals of 4.8;
//! - [`objective`]: one evaluation (an AMM run over the move and a residual window);
//! - [`lm`]: the Levenberg-Marquardt search; [`slopes`]: its Jacobian, from the tangent-linear
//!   AMM where it applies;
//! - [`planner`]: the residual objective; [`time`]: the time objective;
//! - [`cycle`], [`cycle_plan`]: whole cycles (4.12), planned move by move;
//! - [`uncertainty`], [`robust`], [`minimax`]: `[robust]`, the plan that holds over an
//!   uncertainty (4.11: the worst sample model's residual minimised on the epigraph).
//!
//! This crate plans; writing the files and checking the motions on the FEM is the command's
//! (`flexstar_api::plan`).

pub mod cycle;
pub mod cycle_plan;
pub mod family;
pub mod fit_uncertainty;
pub mod limits;
pub mod lm;
pub mod minimax;
pub mod objective;
pub mod planner;
pub mod qp;
pub mod robust;
pub mod section;
pub mod slopes;
pub mod time;
pub mod uncertainty;

pub use cycle::{Cycle, CycleMove};
pub use cycle_plan::{plan_cycle, PlannedCycle, PlannedMove};
pub use planner::{plan, Planned};
pub use section::{read_plan_config, Limits, Objective, PlanConfig, PlanSection, Shape};

/// Why a plan could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// Bad input: the file, the key and the reason.
    #[error(transparent)]
    Input(#[from] flexstar_model::ModelError),
    /// A motion the planner must run leaves the feasible workspace.
    #[error("{what}: infeasible at {reason}")]
    Infeasible { what: String, reason: String },
    /// A solver or the modal analysis failed.
    #[error("{0}")]
    Solver(String),
}
