//! # flexstar-solve
//!
//! One way to solve an experiment: the choice of model ([`Solver`], the one enum of the
//! workspace) and the one dispatch ([`solve`]) over the solver and the experiment's drive
//! (prescribed motion, actuator forces or a servo). Every front (`run`, `compare`, `verify`,
//! studies, the Python package) solves through [`solve`]; each solver has one entry point of the
//! shape of `flexstar_drive::SolveRequest` (`docs/architecture.md`, "One way to solve").

mod sensor_slopes;

pub use sensor_slopes::{sensor_slopes, SensorSlopes};

use flexstar_drive::{ActuatorLaw, Drive, Progress, SolveRequest, Solved};
use flexstar_kinematics::CheckedMotion;
use flexstar_model::{AmmSettings, DriveKind, Experiment, FemSettings, ModelError, Problem, Response};

/// Which model solves an experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// The paper's constrained assumed-modes method
    Amm,
    /// The independent finite-element reference
    Fem,
}

impl Solver {
    /// Both solvers, AMM first.
    pub const ALL: [Solver; 2] = [Solver::Amm, Solver::Fem];

    /// Name in files, on the command line and in Python: `amm` or `fem`.
    pub fn name(&self) -> &'static str {
        match self {
            Solver::Amm => "amm",
            Solver::Fem => "fem",
        }
    }
}

impl std::fmt::Display for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Solver {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Solver::ALL
            .into_iter()
            .find(|x| x.name() == s)
            .ok_or_else(|| format!("unknown solver `{s}`: expected amm or fem"))
    }
}

/// A solver with its settings (the experiment's `[amm]` or `[fem]` after any override).
#[derive(Debug, Clone, Copy)]
pub enum Settings<'a> {
    Amm(&'a AmmSettings),
    Fem(&'a FemSettings),
}

impl<'a> Settings<'a> {
    /// The experiment's own settings of `solver` (`exp.amm` or `exp.fem`).
    pub fn of(exp: &'a Experiment, solver: Solver) -> Self {
        match solver {
            Solver::Amm => Settings::Amm(&exp.amm),
            Solver::Fem => Settings::Fem(&exp.fem),
        }
    }

    /// Which solver these settings are for.
    pub fn solver(&self) -> Solver {
        match self {
            Settings::Amm(_) => Solver::Amm,
            Settings::Fem(_) => Solver::Fem,
        }
    }
}

/// The work counters of a solve, each solver's own.
#[derive(Debug, Clone, PartialEq)]
pub enum Stats {
    Amm(flexstar_amm::Stats),
    Fem(flexstar_fem::Stats),
}

/// Why a solve of an experiment failed: the solver's typed error, or the `[drive]` that could not
/// become an actuator law.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Amm(#[from] flexstar_amm::AmmError),
    #[error(transparent)]
    Fem(#[from] flexstar_fem::FemError),
    /// The `[drive]` could not become an actuator law.
    #[error(transparent)]
    Drive(#[from] flexstar_drive::DriveError),
    /// A servo's tracking errors could not be evaluated (its reference, at a time).
    #[error(transparent)]
    Tracking(flexstar_drive::DriveError),
    /// The problem's robot is not one a part of the solve models yet (`Problem::equal_beams`),
    /// or a sensor sits where a sleeve of that robot passes (`docs/sensors.md` Eq. S10).
    #[error(transparent)]
    Robot(#[from] ModelError),
}

/// Solve `problem` with `settings` for its drive: the prescribed motion (inverse
/// problem) when `[drive]` is a motion, else the direct problem under its actuator law (forces or
/// a servo; a servo's response gains its tracking errors `e1..e3` [m], after its other columns).
///
/// `proof`: the preflight's proof that the motion (a servo's reference) is feasible over the span
/// (the solver then does not scan it again); `None`: the solver scans it. `progress` receives the
/// fraction of the span done (see `flexstar_drive::SolveRequest`).
pub fn solve(
    problem: &Problem,
    settings: Settings,
    proof: Option<&CheckedMotion>,
    progress: Option<Progress>,
) -> Result<Solved<Stats>, SolveError> {
    // a sensor on the problem's own robot where a sleeve passes (docs/sensors.md Eq. S10): the
    // robot may differ from the file's (`Problem::with_robot`, a study's case)
    flexstar_kinematics::check_problem_sensor_mounts(problem)?;
    let law = flexstar_drive::law_for(problem)?;
    let mut solved = solve_under(problem, settings, law.as_deref(), proof, progress)?;
    if law.is_some() && problem.drive().kind == DriveKind::Servo {
        flexstar_drive::add_tracking_errors(&mut solved.response, problem).map_err(SolveError::Tracking)?;
    }
    acquire_sensors(problem, &mut solved.response);
    Ok(solved)
}

/// The sensors' readings at the output times, which the solver returns, replaced by what the
/// data acquisition records of them (`docs/sensors.md` section 6: filter, sampling, noise).
pub(crate) fn acquire_sensors(problem: &Problem, response: &mut Response) {
    if let Some(raw) = response.sensors.take() {
        response.sensors = Some(problem.sensors().acquire(&raw, problem.time().t_end));
    }
}

/// [`solve`] with the drive given: `law` (the direct problem) or `None` (the prescribed motion).
fn solve_under(
    problem: &Problem,
    settings: Settings,
    law: Option<&dyn ActuatorLaw>,
    proof: Option<&CheckedMotion>,
    progress: Option<Progress>,
) -> Result<Solved<Stats>, SolveError> {
    let drive = law.map_or(Drive::Motion, Drive::Law);
    let request = SolveRequest { drive, proof, progress };
    Ok(match settings {
        Settings::Amm(s) => {
            let r = flexstar_amm::solve(problem, s, request)?;
            Solved {
                response: r.response,
                stats: Stats::Amm(r.stats),
            }
        }
        Settings::Fem(s) => {
            let r = flexstar_fem::solve(problem, s, request)?;
            Solved {
                response: r.response,
                stats: Stats::Fem(r.stats),
            }
        }
    })
}

/// [`solve`]'s response only.
pub fn response(
    problem: &Problem,
    settings: Settings,
    proof: Option<&CheckedMotion>,
    progress: Option<Progress>,
) -> Result<Response, SolveError> {
    solve(problem, settings, proof, progress).map(|s| s.response)
}

/// The refined FEM that the accurate model's error estimate is judged against
/// (`docs/validation.md` section 8: "never below half the true EVP against the converged FEM"):
/// four times the elements (a multiple of 3 when `[fem] elements` is one, as the FEM requires:
/// the same count on each beam) and an eighth of the step, `[fem] dt` or the FEM's
/// robot-dependent default ([`flexstar_fem::default_dt_of`], Eq. S10 of `docs/fem.md` 4.1 at the
/// stiffest beam of a robot as built, section 10; on the paper's form exactly
/// [`flexstar_fem::default_dt`] of its parameters). *Measured* on case 4, the accurate model's
/// mean EVP against it is 0.1273 % (0.1218 % at a quarter of the step, 0.2 % at the default FEM:
/// the reference's own error is of the size of the model's), about 2 % below the Richardson
/// limit of the two. A robot that does not validate keeps beam 1's step here; the FEM refuses
/// it with the reason.
pub fn reference_fem(exp: &Experiment) -> FemSettings {
    let default_dt = || match flexstar_model::Robot::from_params(&exp.robot) {
        Ok(robot) => flexstar_fem::default_dt_of(&robot),
        Err(_) => flexstar_fem::default_dt(&exp.robot),
    };
    FemSettings {
        elements: 4 * exp.fem.elements,
        dt: Some(exp.fem.dt.unwrap_or_else(default_dt) / 8.0),
        snapshots: Vec::new(),
        frames: 0,
        ..exp.fem.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solver_names_round_trip() {
        for s in Solver::ALL {
            assert_eq!(s.name().parse::<Solver>().unwrap(), s);
            assert_eq!(s.to_string(), s.name());
        }
        assert!("abaqus".parse::<Solver>().unwrap_err().contains("expected amm or fem"));
    }

    /// The refined FEM of a robot as built steps at an eighth of the default of its stiffest beam:
    /// beam 3 at 0.3 m (the paper's section) has `omega_1` `(0.5 / 0.3)^2` times the paper's, so
    /// Eq. S10 gives `5e-4 (0.3 / 0.5)^3` s; the elements stay a multiple of 3. The paper's robot
    /// keeps `default_dt / 8` bit for bit.
    #[test]
    fn the_reference_steps_at_the_stiffest_beam_of_a_robot_as_built() {
        let text = |robot: &str| {
            format!(
                "name = \"p\"\n{robot}[time]\nt_end = 0.01\n[trajectory]\nkind = \"polynomial\"\n\
                 s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n"
            )
        };
        let built =
            Experiment::from_toml_str(&text("[robot]\nL = [0.5, 0.5, 0.3]\n"), std::path::Path::new("p.toml")).unwrap();
        let r = reference_fem(&built);
        let expected = 5e-4 * 0.6f64.powi(3) / 8.0;
        assert!(
            (r.dt.unwrap() / expected - 1.0).abs() < 1e-12,
            "{:?} vs {expected}",
            r.dt
        );
        assert!(r.elements.is_multiple_of(3) && r.elements == 4 * built.fem.elements);
        let paper = Experiment::from_toml_str(&text(""), std::path::Path::new("p.toml")).unwrap();
        assert_eq!(
            reference_fem(&paper).dt.unwrap().to_bits(),
            (flexstar_fem::default_dt(&paper.robot) / 8.0).to_bits()
        );
    }

    /// A loaded `f_hz = "auto"` waits for the explicit shaping step: it does not become a
    /// problem before (the solvers would run the unshaped motion), and the error names the key.
    #[test]
    fn a_pending_shaper_is_refused() {
        let text = "name = \"q\"\n[time]\nt_end = 0.6\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
                    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.05, Gy = 0.0, theta = 0.0 }\n\
                    t0 = 0.0\nt1 = 0.3\n[shaper]\nkind = \"zvd\"\nf_hz = \"auto\"\n";
        let exp = Experiment::from_toml_str(text, std::path::Path::new("q.toml")).unwrap();
        assert!(exp.shaper_pending());
        let e = exp.problem().unwrap_err();
        assert!(e.to_string().contains("shaper.f_hz"), "{e}");
    }

    /// Friction reaches the problem, and both solvers take it (`docs/friction.md` 9): each
    /// response carries the friction's summary and columns.
    #[test]
    fn both_solvers_take_friction() {
        let exp = Experiment::from_toml_str(
            "name = \"f\"\n[time]\nt_end = 0.01\n[trajectory]\nkind = \"polynomial\"\n\
             s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n[friction]\nmu = 0.1\n",
            std::path::Path::new("f.toml"),
        )
        .unwrap();
        let problem = exp.problem().unwrap();
        assert_eq!(problem.friction().map(|f| f.sleeve(0).mu), Some(0.1));
        for solver in [Solver::Amm, Solver::Fem] {
            let r = solve(&problem, Settings::of(&exp, solver), None, None)
                .unwrap()
                .response;
            assert!(r.friction.is_some() && r.column("stick1").is_some(), "{solver:?}");
        }
    }

    /// A robot other than the paper's form (here beam 3 shorter, its slider heavier) is solved by
    /// both solvers: at rest without gravity it stays at rest; under gravity a servo holds it at
    /// rest with its rigid feed-forward (`docs/as-built.md` 7: the robot as built's weights),
    /// its tracking errors a small part of the sag a servo without feed-forward leaves
    /// (`Fa / kp` on each slider).
    #[test]
    fn a_robot_as_built_is_solved_under_a_motion_and_under_a_servo() {
        let exp = Experiment::from_toml_str(
            "name = \"p\"\n[time]\nt_end = 0.01\n[trajectory]\nkind = \"polynomial\"\n\
             s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n",
            std::path::Path::new("p.toml"),
        )
        .unwrap();
        let paper = exp.problem().unwrap();
        let mut beams = *paper.robot().beams();
        beams[2].length -= 0.002;
        beams[2].sleeve_mass = 0.26;
        let robot = flexstar_model::Robot::new(beams, *paper.robot().axes()).unwrap();
        let problem = paper.with_robot(robot.clone()).unwrap();
        for solver in Solver::ALL {
            let r = solve(&problem, Settings::of(&exp, solver), None, None)
                .unwrap()
                .response;
            let peak = r
                .w_g
                .iter()
                .flatten()
                .chain(r.w_tip.iter().flatten())
                .fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(peak < 1e-12, "{solver}: at rest, peak {peak}");
        }
        let servo_error = |feedforward: flexstar_model::Feedforward, solver: Solver| {
            let mut servo = exp.clone();
            servo.time.t_end = 0.2;
            servo.gravity = flexstar_model::Gravity::new([0.0, -9.81]);
            servo.drive.kind = DriveKind::Servo;
            servo.drive.bandwidth_hz = Some(20.0);
            servo.drive.damping_ratio = Some(0.7);
            servo.drive.feedforward = Some(feedforward);
            let problem = servo.problem().unwrap().with_robot(robot.clone()).unwrap();
            let r = solve(&problem, Settings::of(&servo, solver), None, None)
                .unwrap()
                .response;
            ["e1", "e2", "e3"]
                .iter()
                .flat_map(|e| r.column(e).unwrap().iter())
                .fold(0.0f64, |m, v| m.max(v.abs()))
        };
        for solver in Solver::ALL {
            let held = servo_error(flexstar_model::Feedforward::Rigid, solver);
            let sag = servo_error(flexstar_model::Feedforward::None, solver);
            eprintln!("{solver}: tracking error {held:.3e} m with the feed-forward, {sag:.3e} m without");
            assert!(held < 1e-2 * sag, "{solver}: {held} m against {sag} m");
        }
    }
}
