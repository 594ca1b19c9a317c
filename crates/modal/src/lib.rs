//! # flexstar-modal
//!
//! Vibration modes of the star over the workspace and linear models for control (`docs/modes.md`),
//! above both solvers and below the CLI:
//!
//! - [`pose`]: the rest pose from a time of the experiment's trajectory or a task-space pose,
//!   checked against the feasible range (the limit is named);
//! - [`analysis`]: modes at a pose from the AMM and the FEM side by side (`modal.csv`);
//! - [`freqmap`]: the first K frequencies over a grid of poses, in parallel (`freqmap.csv`);
//! - [`linear`]: the state-space model (A, B, C, D), sliders free, locked or servo-held, Matrix Market files
//!   (sprs) and `statespace.json`;
//! - [`plots`]: mode shapes and frequency heat maps (SVG, PNG).
//!
//! The physics (mass, stiffness and constraints at a pose) lives in the solvers:
//! `flexstar_amm::pose_modes` and `flexstar_fem::pose_modes`. SI units; frames as in
//! `docs/conventions.md`.
//!
//! Every analysis reads the experiment's robot as data ([`robot`]: the paper's robot or one as
//! built, `docs/as-built.md`; `docs/modes.md`, a robot as built): the rigid pose through the
//! generic kinematics, each beam's own data in both solvers and in the linear model's outputs.

pub mod analysis;
pub mod error;
pub mod freqmap;
pub mod linear;
pub mod plots;
pub mod pose;
pub mod settle;
mod static_shapes;

pub use error::ModalError;

/// Largest number of modes K a command accepts.
pub const MAX_K: usize = 50;

/// The experiment's robot as data (`Robot::from_params`): the paper's robot (whose solvers and
/// kinematics then take their compact form, bit for bit) or one as built.
pub fn robot(exp: &flexstar_model::Experiment) -> Result<flexstar_model::Robot, ModalError> {
    Ok(flexstar_model::Robot::from_params(&exp.robot)?)
}

/// A damping whose `zeta` still waits for the first frequency (`Damping::pending`) would act as
/// none: refused (resolve it first, `flexstar_shaping::shape`).
pub fn check_damping(exp: &flexstar_model::Experiment) -> Result<(), ModalError> {
    if exp.damping.pending() {
        return Err(ModalError::Input(
            "damping.zeta without f_hz holds at the first frequency at the start pose, not computed yet: \
             resolve it first (flexstar_shaping::shape)"
                .into(),
        ));
    }
    Ok(())
}

/// Check K (`--modes`): 1 <= K <= [`MAX_K`].
pub fn check_k(k: usize) -> Result<(), ModalError> {
    if k == 0 || k > MAX_K {
        return Err(ModalError::Input(format!(
            "--modes K must satisfy 1 <= K <= {MAX_K}, got {k}"
        )));
    }
    Ok(())
}
