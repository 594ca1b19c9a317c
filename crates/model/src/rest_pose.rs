//! A pose of the robot at rest, as data for the modal analyses of both solvers (`docs/modes.md`).

/// How the sliders are held in a modal analysis or a linear model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sliders {
    /// Revolute points I, J, K fixed (actuators locked).
    Locked,
    /// Each slider free on its rail with mass `mpp_mpa` (three rigid modes at 0 Hz).
    Free,
}

impl Sliders {
    /// The command-line name (`locked`, `free`).
    pub fn name(&self) -> &'static str {
        match self {
            Sliders::Locked => "locked",
            Sliders::Free => "free",
        }
    }
}

/// Which of the two linear systems of a robot whose sleeves can stick a modal analysis or a
/// linear model takes (`docs/modes.md`, stuck sleeves; `docs/friction.md` 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sleeves {
    /// Each beam slides through its sleeve (the frictionless rows only; today's systems).
    #[default]
    Sliding,
    /// Each sleeve holds the material point of its beam (Eq. S1 in the AMM, S2 in the FEM).
    Stuck,
}

impl Sleeves {
    /// The command-line name (`sliding`, `stuck`).
    pub fn name(&self) -> &'static str {
        match self {
            Sleeves::Sliding => "sliding",
            Sleeves::Stuck => "stuck",
        }
    }
}

/// The robot at rest at one pose: actuator coordinates and the rigid star they hold. Prepared by
/// the caller (inverse and direct rigid kinematics); the solvers take it as data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestPose {
    /// Actuator coordinates s_i [m] (Eqs. 1-3).
    pub s: [f64; 3],
    /// Centre G of the star [m], fixed frame.
    pub g: [f64; 2],
    /// Orientation theta [rad] (beam i along `e_xi(theta)`, docs/conventions.md).
    pub theta: f64,
    /// Distance from G to pin i along beam i [m].
    pub xp: [f64; 3],
}
