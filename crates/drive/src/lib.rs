//! Actuator drives of the 3-PRP star-triangle robot (issue 10: direct dynamics).
//!
//! The paper solves the inverse problem (motion given, Eq. 33 gives the forces). In the direct
//! problem the slider positions `s_i` are unknowns and each slider is pushed along `+u_i` by a
//! force `Fa_i` that depends on time and, for a servo, on the slider's own state. Both solvers
//! (AMM and FEM) take the drive as an [`ActuatorLaw`], so they never need to know which kind of
//! drive it is.
//!
//! Sign convention (docs/conventions.md, "Forces"): `Fa_i` [N] is the force actuator `i` applies to
//! its slider along `+u_i`.

/// A drive: the actuator forces as a function of time and of the sliders' state.
///
/// The law is diagonal: `Fa_i` depends on `s_i` and `s_i'` only (each actuator sees its own
/// slider), which is what a per-axis servo does and what a prescribed force profile does
/// trivially (no dependence at all).
pub trait ActuatorLaw: Send + Sync {
    /// `Fa_i` [N] at time `t` [s] with slider positions `s` [m] and speeds `v` [m/s].
    fn force(&self, t: f64, s: [f64; 3], v: [f64; 3]) -> [f64; 3];

    /// `-dFa_i/ds_i` [N/m], constant: the servo's `kp`, zero for prescribed forces. Implicit
    /// integrators put it in their iteration matrix.
    fn stiffness(&self) -> [f64; 3];

    /// `-dFa_i/ds_i'` [N s/m], constant: the servo's `kd`, zero for prescribed forces.
    fn damping(&self) -> [f64; 3];
}
