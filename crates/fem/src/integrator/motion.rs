//! The prescribed motion of the sliders or the actuator law, and the forces and power at the
//! pins.

use super::*;

/// The pins of the prescribed motion at time `t` [s]: `s_i(t)` and its derivatives from the
/// trajectory, the revolute points on `star`'s actuator axes.
pub(super) fn pins_at(star: &Star, traj: &Trajectory, t: f64) -> Result<Pins, FemError> {
    let j = star
        .jets(traj, t)
        .map_err(|source| FemError::Trajectory { t, source })?;
    Ok(Pins::new(&star.robot, j.map(|x| [x.v, x.d1, x.d2])))
}

/// Driving force (Eq. 33): `Fa_i = (mpp + mpa)_i s_i'' - F_i . u_i`, F_i the force of the beam on
/// sleeve i (the sleeve is translationally massless: F_i passes through the pin to the slider);
/// under gravity less the weight of sleeve and slider along the rail, `- (mpp + mpa)_i g . u_i`
/// (Eqs. G2, G7); with rail friction plus `Fc_i sign(s_i') + b_i s_i'` (Eq. F4).
pub(super) fn driving_forces(star: &Star, pins: &Pins, lam: &[f64]) -> ([f64; 3], [[f64; 2]; 3]) {
    let f = pin_forces(lam);
    let mut fa = [0, 1, 2].map(|i| {
        let u = star.slider_direction(i);
        star.beam(i).sleeve_mass * pins.s[i][2] - (f[i][0] * u[0] + f[i][1] * u[1])
    });
    if star.attached.weighs() {
        for (i, fa) in fa.iter_mut().enumerate() {
            *fa -= star.beam(i).sleeve_mass * star.gravity_along(i);
        }
    }
    if star.friction.is_some() {
        // the rails' friction against the prescribed sliding (Eq. F4)
        for (i, fa) in fa.iter_mut().enumerate() {
            *fa += star.rail_force(i, pins.s[i][1]);
        }
    }
    (fa, f)
}

pub(super) fn power(fa: &[f64; 3], pins: &Pins) -> f64 {
    (0..3).map(|i| fa[i] * pins.s[i][1]).sum()
}

/// What moves the sliders.
pub(crate) enum Motion<'a> {
    /// Inverse problem: `s_i(t)` prescribed by the trajectory, `Fa_i` from Eq. 33.
    Prescribed(&'a Trajectory),
    /// Direct problem: each slider a body of mass `mpp + mpa` on its rail pushed along `+u_i` by
    /// the law's `Fa_i(t, s_i, s_i')`, starting at `s0` [m] with speeds `v0` [m/s].
    Driven {
        law: &'a dyn ActuatorLaw,
        s0: [f64; 3],
        v0: [f64; 3],
    },
}

impl Motion<'_> {
    /// `[s_i, s_i']` at t = 0 of the slider unknowns (direct problem only).
    pub(super) fn slider_unknowns(&self) -> Option<[[f64; 2]; 3]> {
        match self {
            Motion::Prescribed(_) => None,
            Motion::Driven { s0, v0, .. } => Some([0, 1, 2].map(|i| [s0[i], v0[i]])),
        }
    }

    /// Prescribed pins at time `t` (inverse problem), `None` in the direct problem, where the
    /// pins follow the Newton iterate. Checks that the prescribed sliders stay on their sides
    /// (strictly between the side's corners, [`Star::slider_travel`]).
    pub(super) fn prescribed_pins(&self, star: &Star, t: f64) -> Result<Option<Pins>, FemError> {
        let Motion::Prescribed(traj) = self else {
            return Ok(None);
        };
        let pins = pins_at(star, traj, t)?;
        for i in 0..3 {
            let travel = star.slider_travel[i];
            let s = pins.s[i][0];
            if !(s > travel[0] && s < travel[1]) {
                return Err(FemError::SliderOffBase {
                    t,
                    slider: i + 1,
                    s,
                    travel,
                });
            }
        }
        Ok(Some(pins))
    }

    /// The actuator law at the sliders' state of `pins`.
    pub(super) fn law_forces(law: &dyn ActuatorLaw, pins: &Pins, t: f64) -> Result<[f64; 3], FemError> {
        law.force(t, pins.s.map(|s| s[0]), pins.s.map(|s| s[1]))
            .map_err(|source| FemError::Drive { t, source })
    }

    /// The sliders' rows at one iterate of the direct problem (`bp = beta'`, `gp = gamma'`, both
    /// zero for the initial accelerations); `None` in the inverse problem.
    pub(super) fn slider_rows(
        &self,
        star: &Star,
        pins: &Pins,
        t: f64,
        bp: f64,
        gp: f64,
    ) -> Result<Option<SliderRows>, FemError> {
        let Motion::Driven { law, .. } = self else {
            return Ok(None);
        };
        let (kp, kd) = (law.stiffness(), law.damping());
        Ok(Some(SliderRows {
            fa: Self::law_forces(*law, pins, t)?,
            diag: [0, 1, 2].map(|i| star.beam(i).sleeve_mass + bp * kp[i] + gp * kd[i]),
        }))
    }

    /// `Fa` [N] and the pin forces at a converged state of `star`: Eq. 33 with Eq. G7 (inverse),
    /// the law (direct).
    pub(super) fn forces(
        &self,
        star: &Star,
        pins: &Pins,
        lam: &[f64],
        t: f64,
    ) -> Result<([f64; 3], [[f64; 2]; 3]), FemError> {
        match self {
            Motion::Prescribed(_) => Ok(driving_forces(star, pins, lam)),
            Motion::Driven { law, .. } => Ok((Self::law_forces(*law, pins, t)?, pin_forces(lam))),
        }
    }

    /// Where the sliders are held for the static equilibrium of the start (Eq. G8): `s(0)` [m]
    /// of the trajectory (inverse) or of the initial data (direct).
    pub(super) fn start_sliders(&self, star: &Star) -> Result<[f64; 3], FemError> {
        match self {
            Motion::Prescribed(traj) => Ok(pins_at(star, traj, 0.0)?.s.map(|s| s[0])),
            Motion::Driven { s0, .. } => Ok(*s0),
        }
    }

    /// Direct problem: the simulated configuration must stay feasible (the limits of
    /// `flexstar_kinematics::feasibility`, applied to the simulated s: a check, not an equation).
    pub(super) fn check_feasible(&self, star: &Star, pins: &Pins, t: f64) -> Result<(), FemError> {
        if let Motion::Prescribed(_) = self {
            return Ok(());
        }
        star.check_configuration(pins.s.map(|s| s[0]))
            .map_err(|violation| FemError::Infeasible { t, violation })
    }
}
