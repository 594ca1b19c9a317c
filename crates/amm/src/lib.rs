//! # flexstar-amm
//!
//! The paper's constrained assumed-modes method (sections 6-7, Eqs. 30-44) for the vibration of
//! the 3-PRP star-triangle robot whose moving platform is a star of three flexible
//! Euler-Bernoulli beams sliding through sleeves.
//!
//! - [`modes`]: the mode families of Eq. 34-1 (pinned-free, slide-free, free-free, clamped-free),
//!   evaluated stably to hundreds of modes;
//! - `system` (private): the constrained linear time-varying equations (Eqs. 37, 44, 31 with the
//!   constraints of Eqs. 38-43) and their per-step linear solve;
//! - `sleeve` (private): the passive prismatic joint, its rows (Eqs. 41-43) and multipliers, the
//!   full model's material point in it and the truncation flexibility seen there (`docs/amm.md`
//!   section 1, 12.3, 12.11);
//! - [`pose_modes`]: the modes of the star held at rest at one pose, and its linearised system;
//! - [`solver`]: index-3 generalized-alpha time integration and the outputs ([`solve`]);
//! - [`direct`]: the direct problem, sliders driven by forces or a servo ([`solve`] with `Drive::Law`, `docs/amm.md` section 10);
//! - `star` (private): the AMM's view of a problem, beam by beam: the robot as built (unequal
//!   beams, other weld angles, an uneven base; `docs/amm.md` section 13, Eqs. J1-J8).
//!
//! Frames and signs follow `docs/conventions.md`; the derivation, the departures from the
//! printed paper and the convergence study are in `docs/amm.md`. SI units throughout.

// Units are written in brackets after a quantity ([m], [Hz]) as in the other flexstar crates.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod adaptive;
mod attach;
mod constraint_lu;
mod dense_lu;
pub mod direct;
pub mod error;
mod events;
mod foreshortening;
mod friction;
mod geometric;
pub mod modes;
pub mod pose_modes;
#[cfg(test)]
mod rayleigh_decay;
mod record;
mod sensors;
mod sleeve;
pub mod solver;
mod star;
mod static_start;
mod stick_slip;
mod system;
mod system_cache;
pub mod tangent;
mod third_order;

pub use direct::DIRECT_COLUMNS;
pub use error::{AmmError, RankError};
pub use modes::{ModeSet, MAX_MODES};
pub use solver::{
    beam_time_scale, parse_family, robot_step_factor, solve, solve_stepwise, tolerance_step, Stats, DEFAULT_DT,
    EXTRA_COLUMNS, RHO_INF, SHAPE_POINTS, TOLERANCE_DT,
};
pub use tangent::{sensitivities_cover, solve_with_sensitivities, Sensitivities};

/// What a mode family with a hidden support at G loses of the experiment's payload and load
/// (`docs/amm.md` 11.1 and 11.3): pinned-free (`phi(0) = 0`, `u = 0`) the transverse force and the
/// payload's translation, slide-free (`phi'(0) = 0`) the moment and the payload's rotation,
/// clamped-free both. `None` for free-free and enriched, which carry them completely, or when
/// the experiment has neither a payload nor a load.
pub fn attachments_lost(family: flexstar_model::ModeFamily, problem: &flexstar_model::Problem) -> Option<String> {
    use flexstar_model::ModeFamily;
    if problem.payload().is_none() && problem.load().is_none() && problem.gravity() == [0.0; 2] {
        return None;
    }
    let lost = match family {
        ModeFamily::PinnedFree => "the transverse force at G and the payload's elastic translation",
        ModeFamily::SlideFree => "the moment at G and the payload's elastic rotation (its J, its offset's moment)",
        ModeFamily::ClampedFree => "the force, the moment and the payload's whole elastic motion at G",
        ModeFamily::FreeFree | ModeFamily::Enriched => return None,
    };
    Some(format!(
        "the {family} family holds G by a hidden support and loses {lost} (docs/amm.md 11.1); \
         the enriched (default) or free-free family carries the payload, the load and the weights completely"
    ))
}
