//! Errors of the finite-element solver: every message says when (time), where (element, sleeve)
//! and why.

use flexstar_model::ModelError;

/// Everything that stops the FEM. No partial output is produced after an error.
#[derive(Debug, thiserror::Error)]
pub enum FemError {
    /// The experiment or the settings are unusable (message names the key and the bound).
    #[error("invalid FEM input: {0}")]
    Input(String),
    /// The mesh is too coarse to hold a sleeve: fewer than 2 elements across Lp.
    #[error(
        "mesh too coarse: {per_beam} elements per beam give an element length {h:.4e} m, but a sleeve of length Lp = {lp} m needs at least 2 elements across it (at least {needed} elements per beam, {} in all)",
        3 * needed
    )]
    MeshTooCoarse {
        per_beam: usize,
        h: f64,
        lp: f64,
        needed: usize,
    },
    /// The trajectory could not be evaluated.
    #[error("trajectory at t = {t} s: {source}")]
    Trajectory {
        t: f64,
        #[source]
        source: ModelError,
    },
    /// Newton's method did not converge within the iteration limit.
    #[error("Newton failure at t = {t} s (step {h:.3e} s): {reason}")]
    Newton { t: f64, h: f64, reason: String },
    /// The sparse LU factorisation failed (singular iteration matrix).
    #[error("linear solver failure at t = {t} s: {reason}")]
    LinearSolver { t: f64, reason: String },
    /// A sleeve contact point left the beam: its material coordinate is outside (0, L).
    #[error(
        "sleeve {sleeve} slid off beam {sleeve} at t = {t} s: the {point} contact point is at material coordinate {xi:.5} m, outside (0, L = {l} m)"
    )]
    SleeveOffBeam {
        t: f64,
        sleeve: usize,
        point: &'static str,
        xi: f64,
        l: f64,
    },
    /// A slider left its side of the base triangle (|s_i| >= sqrt(3) d).
    #[error(
        "slider {slider} left its base side at t = {t} s: s = {s:.5} m, |s| must stay below sqrt(3) d = {limit:.5} m"
    )]
    SliderOffBase { t: f64, slider: usize, s: f64, limit: f64 },
    /// The simulated configuration of a direct run left the feasible range (the reason names
    /// the limit: slider off its base side, sleeve at G or off the tip, no Fermat point).
    #[error("direct run left the feasible range at t = {t} s: {reason}")]
    Infeasible { t: f64, reason: String },
    /// The actuator law could not be evaluated (e.g. a servo reference outside its range).
    #[error("actuator law at t = {t} s: {reason}")]
    Drive { t: f64, reason: String },
    /// Post-processing with the rigid kinematics failed (no rigid configuration at an output time).
    #[error("post-processing at t = {t} s: {reason}")]
    PostProcessing { t: f64, reason: String },
    /// A non-finite number appeared (element index given when known).
    #[error("non-finite value at t = {t} s in element {element}: {reason}")]
    NonFinite { t: f64, element: usize, reason: String },
}
