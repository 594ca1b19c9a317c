//! The AMM's view of a problem: the robot as built, beam by beam (`docs/amm.md` section 13,
//! Eqs. J1-J8).
//!
//! A [`Star`] holds each beam's data in the one-beam form the mode sets and the sleeves take
//! (`RobotParams`, one per beam), the weld's junction coefficients (Eqs. J3-J5) and the rails'
//! projections (Eq. J7), and the rest of the problem by reference. A robot in the paper's form
//! (`flexstar_model::Problem::equal_beams`) keeps the paper's exact constants (Eqs. 38, 40 and
//! 33), so its runs are bit for bit those of the equal-beam model; three equal beams share one
//! mode set and one arrowhead of the step (`shared`), whatever their welds and base.

use flexstar_kinematics::{check_configuration, check_trajectory, CheckedMotion, Infeasible, RigidState};
use flexstar_model::trajectory::Jet;
use flexstar_model::{
    Damping, DriveSettings, LoadSettings, Payload, Problem, Robot, RobotParams, TimeSpan, Trajectory,
};
use num_dual::Dual2;

use crate::error::AmmError;

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// The junction's coefficients and the rails' geometry (`docs/amm.md` 13, Eqs. J3-J7), beams
/// 0-based, angles relative to the star (independent of theta).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Weld {
    /// Fix row i (Eq. J4): the coefficients `[-f_ij, -f_ik]` of `w_jG`, `w_kG`, j = i + 1,
    /// k = i + 2 (mod 3) [-]; `[1/sqrt3, -1/sqrt3]` on the paper's robot (Eq. 38).
    pub(crate) fix: [[f64; 2]; 3],
    /// The Fw row's coefficients `c_i` (Eq. J5) [-]; `[1, 1, 1]` on the paper's robot (Eq. 40).
    pub(crate) fw: [f64; 3],
    /// Eq. J7: `phi_i - a_i`, the weld angle less the rail's angle [rad]; `None` on the paper's
    /// robot, where Eq. 33 reads `cos(theta + thp_i)` exactly.
    pub(crate) rail_offset: Option<[f64; 3]>,
    /// The rails' unit directions `u_i` (fixed frame).
    pub(crate) rails: [[f64; 2]; 3],
}

impl Weld {
    /// The paper's constants: 120-degree welds on the equilateral base (Eqs. 38, 40, 33).
    pub(crate) fn paper() -> Self {
        Weld {
            fix: [[1.0 / SQRT3, -1.0 / SQRT3]; 3],
            fw: [1.0; 3],
            rail_offset: None,
            rails: std::array::from_fn(flexstar_model::geometry::slider_direction),
        }
    }

    /// Eqs. J3-J5 and J7 for the robot's welds (gaps below pi, checked by the robot) and rails.
    pub(crate) fn of(robot: &Robot) -> Self {
        let gaps = robot.gaps();
        let fix = std::array::from_fn(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let s = gaps[i].sin();
            // u_i = f_ij w_jG + f_ik w_kG, f_ij = cos g_(j) / sin g_(i), f_ik = -cos g_(k) / sin g_(i)
            [-gaps[j].cos() / s, gaps[k].cos() / s]
        });
        let sines = gaps.map(f64::sin);
        let mean = (sines[0] + sines[1] + sines[2]) / 3.0;
        let rails = robot.axes().map(|a| a.direction);
        let welds = robot.weld_angles();
        Weld {
            fix,
            fw: sines.map(|s| s / mean),
            rail_offset: Some(std::array::from_fn(|i| welds[i] - rails[i][1].atan2(rails[i][0]))),
            rails,
        }
    }

    /// Eq. J7: the cosine of the angle between the sleeve's normal `e_w(theta + phi_i + thp)` and
    /// rail i, for the rigid orientation `theta` and the sleeve rotation `thp` [rad].
    pub(crate) fn normal_along_rail(&self, i: usize, theta: f64, thp: f64) -> f64 {
        match self.rail_offset {
            None => (theta + thp).cos(),
            Some(off) => (theta + off[i] + thp).cos(),
        }
    }

    /// `u_i . e_xi = sin(theta + phi_i - a_i + thp)`: rail i along the sleeve's axis (Eq. J7's
    /// companion, `e_x = [sin b, -cos b]`, `u_i = [cos a_i, sin a_i]`); `sin(theta + thp)` on the
    /// paper's robot. The slide of the sleeve along its beam per unit slider displacement.
    pub(crate) fn axial_along_rail(&self, i: usize, theta: f64, thp: f64) -> f64 {
        match self.rail_offset {
            None => (theta + thp).sin(),
            Some(off) => (theta + off[i] + thp).sin(),
        }
    }

    /// `g . u_i` [m/s^2]: gravity `g` along each rail (Eq. G2).
    pub(crate) fn along_rails(&self, g: [f64; 2]) -> [f64; 3] {
        self.rails.map(|u| g[0] * u[0] + g[1] * u[1])
    }

    /// The elastic displacement of G [m, fixed frame] from the three `w_iG` [m] and the beams'
    /// normals `e_w` (Eq. J7's last paragraph): `2/3 sum w_iG e_wi` on the paper's robot
    /// ([`flexstar_metrics::residual::dg_vector`]), else `(sum e_wi e_wi^T)^-1 sum w_iG e_wi`.
    pub(crate) fn dg(&self, w_g: [f64; 3], e_w: [[f64; 2]; 3]) -> [f64; 2] {
        if self.rail_offset.is_none() {
            return flexstar_metrics::residual::dg_vector(w_g, e_w);
        }
        let (mut a, mut b) = ([0.0; 3], [0.0; 2]);
        for (w, e) in w_g.iter().zip(&e_w) {
            a[0] += e[0] * e[0];
            a[1] += e[0] * e[1];
            a[2] += e[1] * e[1];
            b[0] += w * e[0];
            b[1] += w * e[1];
        }
        let det = a[0] * a[2] - a[1] * a[1];
        [(a[2] * b[0] - a[1] * b[1]) / det, (a[0] * b[1] - a[1] * b[0]) / det]
    }
}

/// Each beam of `robot` in the one-beam form of the mode sets and sleeves (`d` = 0: the base is
/// the robot's axes).
pub(crate) fn beam_params(robot: &Robot) -> [RobotParams; 3] {
    robot.beams().map(|b| b.params(0.0))
}

/// Whether the three beams share one mode set and one arrowhead: their data are equal and no
/// sleeve has viscous friction (which puts each sleeve's own term on its beam's arrowhead, Eq. F14).
fn shares_modes(beams: &[RobotParams; 3], friction: Option<&flexstar_model::Friction>) -> bool {
    let viscous = friction.is_some_and(|f| f.c.0.iter().any(|c| *c != 0.0));
    beams[1] == beams[0] && beams[2] == beams[0] && !viscous
}

/// The problem as the AMM solves it (module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Star<'a> {
    /// The robot as built.
    pub(crate) robot: &'a Robot,
    /// The robot in the paper's form, when it is the paper's robot.
    pub(crate) paper: Option<&'a RobotParams>,
    /// Each beam's data in the one-beam form (`d` is 0 unless the robot is the paper's).
    pub(crate) beams: [RobotParams; 3],
    /// One mode set and one arrowhead for the three beams (their data are equal).
    pub(crate) shared: bool,
    /// Eqs. J3-J7.
    pub(crate) weld: Weld,
    pub(crate) time: TimeSpan,
    pub(crate) trajectory: &'a Trajectory,
    pub(crate) drive: &'a DriveSettings,
    pub(crate) payload: &'a Payload,
    pub(crate) damping: &'a Damping,
    pub(crate) load: &'a LoadSettings,
    /// Gravity `[gx, gy]` [m/s^2], base frame.
    pub(crate) gravity: [f64; 2],
    /// The sensors read at the output times (`docs/sensors.md`; empty without).
    pub(crate) sensors: &'a flexstar_model::sensors::Sensors,
    /// Friction in the sleeves and on the rails (`docs/friction.md` 9); `None`: none.
    pub(crate) friction: Option<&'a flexstar_model::Friction>,
}

impl<'a> Star<'a> {
    /// The AMM's view of `problem`.
    pub(crate) fn new(problem: &'a Problem) -> Self {
        let robot = problem.robot();
        let paper = robot.equal_beams().ok();
        let beams = match paper {
            Some(p) => [*p; 3],
            None => beam_params(robot),
        };
        let friction = problem.friction();
        Star {
            robot,
            paper,
            beams,
            shared: shares_modes(&beams, friction),
            weld: if paper.is_some() {
                Weld::paper()
            } else {
                Weld::of(robot)
            },
            time: *problem.time(),
            trajectory: problem.trajectory(),
            drive: problem.drive(),
            payload: problem.payload(),
            damping: problem.damping(),
            load: problem.load(),
            gravity: problem.gravity(),
            sensors: problem.sensors(),
            friction,
        }
    }

    /// Whether `other` is the same robot in the same setting (payload, damping, load, drive,
    /// gravity, friction): at most its motion differs.
    pub(crate) fn same_physics(&self, other: &Star) -> bool {
        self.robot == other.robot
            && self.payload == other.payload
            && self.damping == other.damping
            && self.load == other.load
            && self.drive == other.drive
            && self.gravity == other.gravity
            && self.friction == other.friction
    }

    /// Whether `other`'s modes are this problem's: the mode sets depend on the family and N
    /// (the solver's) and each beam's length alone, the sleeve rows' points on the sleeves'
    /// lengths (`docs/amm.md` 2.2, "Physical parameters").
    pub(crate) fn same_basis(&self, other: &Star) -> bool {
        self.beams
            .iter()
            .zip(&other.beams)
            .all(|(a, b)| a.l == b.l && a.lp == b.lp)
    }

    /// The same problem with a mode set and an arrowhead per beam even where the beams are
    /// equal: the general layout, for the test that it reproduces the shared one.
    #[cfg(test)]
    pub(crate) fn per_beam(mut self) -> Self {
        self.shared = false;
        self
    }

    /// The same problem without friction in the sleeves or on the rails: the robot of the
    /// estimate's pairs of a run with friction (`docs/amm.md` 12.16).
    pub(crate) fn without_friction(mut self) -> Self {
        self.friction = None;
        self.shared = shares_modes(&self.beams, None);
        self
    }

    /// The parameters of beam i (0-based).
    pub(crate) fn beam(&self, i: usize) -> &RobotParams {
        &self.beams[i]
    }

    /// The parameters of the mode sets: one (shared) or three.
    pub(crate) fn mode_params(&self) -> &[RobotParams] {
        if self.shared {
            &self.beams[..1]
        } else {
            &self.beams
        }
    }

    /// The rigid kinematics' robot (`flexstar_model::RobotGeometry`: the paper's formulas on
    /// the paper's robot, `docs/as-built.md` 3 on one as built).
    fn kin(&self) -> &'a Robot {
        self.robot
    }

    /// The rigid state of the trajectory at `t` [s].
    pub(crate) fn state(&self, t: f64) -> Result<RigidState, AmmError> {
        RigidState::at(self.kin(), self.trajectory, t).map_err(|source| AmmError::Kinematics { t, source })
    }

    /// The rigid state for actuator coordinates as second-order dual numbers in time.
    pub(crate) fn state_from(&self, s: [Dual2<f64>; 3], t: f64) -> Result<RigidState, AmmError> {
        RigidState::from_actuators(self.kin(), s, t).map_err(|source| AmmError::Kinematics { t, source })
    }

    /// The trajectory's actuator coordinates with two derivatives at `t` [s].
    pub(crate) fn jets(&self, t: f64) -> Result<[Jet; 3], AmmError> {
        Ok(self.trajectory.jets(self.kin(), t)?)
    }

    /// The trajectory's actuator coordinates at `t` [s].
    pub(crate) fn s_at(&self, t: f64) -> Result<[f64; 3], AmmError> {
        Ok(self.trajectory.s(self.kin(), t)?)
    }

    /// Feasibility of the trajectory over the span, scanned at `scan_step` [s].
    pub(crate) fn check_trajectory(&self, scan_step: f64) -> Result<(), AmmError> {
        Ok(check_trajectory(
            self.kin(),
            self.trajectory,
            self.time.t_end,
            scan_step,
        )?)
    }

    /// Feasibility of the configuration `s` [m] (a violation as found at `t` [s]).
    pub(crate) fn check_configuration(&self, s: [f64; 3]) -> Result<(), flexstar_kinematics::Violation> {
        check_configuration(self.kin(), s)
    }

    /// Does `checked` cover the scan of this problem's trajectory at `scan_step` [s]?
    pub(crate) fn covered_by(&self, checked: &CheckedMotion, scan_step: f64) -> bool {
        checked.covers(self.kin(), self.trajectory, self.time.t_end, scan_step)
    }

    /// The configuration check as an infeasibility at `t` [s].
    pub(crate) fn check_start(&self, s: [f64; 3], t: f64) -> Result<(), AmmError> {
        self.check_configuration(s)
            .map_err(|violation| Infeasible { t, violation }.into())
    }
}

/// A robot as built for the tests: three different beams (every datum of each differs), welds at
/// 0, 117 and 243.5 degrees, the base from the sides 0.626, 0.618, 0.631 m; the beams' E times
/// `stiff`.
#[cfg(test)]
pub(crate) fn as_built_robot(stiff: f64) -> Robot {
    use flexstar_model::robot::{ActuatorAxis, Beam};
    let p = RobotParams::paper();
    let welds = [0.0, 117f64.to_radians(), 243.5f64.to_radians()];
    let f = |k: [f64; 3], i: usize| k[i];
    let beams = std::array::from_fn(|i| Beam {
        youngs_modulus: p.e * stiff * f([1.0, 1.2, 0.85], i),
        second_moment: p.i * f([1.0, 0.9, 1.1], i),
        axial_stiffness: p.ea() * f([1.0, 1.1, 0.95], i),
        mass_per_length: p.rho * f([1.0, 1.15, 0.9], i),
        length: p.l * f([1.0, 0.92, 1.06], i),
        sleeve_length: p.lp * f([1.0, 1.2, 0.9], i),
        sleeve_mass: p.mpp_mpa * f([1.0, 1.3, 0.8], i),
        sleeve_inertia: p.jp * f([1.0, 0.7, 1.4], i),
        weld_angle: welds[i],
    });
    Robot::new(beams, ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap()).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::build_system;
    use flexstar_model::{AmmSettings, ModeFamily};

    #[test]
    fn the_junction_coefficients_of_120_degree_welds_are_the_papers() {
        // Eqs. J3-J5 for gaps of 120 degrees against Eqs. 38 and 40
        let problem = flexstar_model::catalogue::paper_case(1).problem().unwrap();
        let (general, paper) = (Weld::of(problem.robot()), Weld::paper());
        for i in 0..3 {
            for k in 0..2 {
                assert!((general.fix[i][k] - paper.fix[i][k]).abs() < 1e-15, "{general:?}");
            }
            assert!((general.fw[i] - 1.0).abs() < 1e-15);
            assert!((general.rails[i][0] - paper.rails[i][0]).abs() < 1e-15);
            assert!((general.rails[i][1] - paper.rails[i][1]).abs() < 1e-15);
        }
        // the projection of Eq. J7 is the paper's cos(theta + thp) there
        for (th, thp) in [(0.3, 0.01), (-1.1, -0.02)] {
            for i in 0..3 {
                let (a, b) = (
                    general.normal_along_rail(i, th, thp),
                    paper.normal_along_rail(i, th, thp),
                );
                assert!((a - b).abs() < 1e-14, "{a} {b}");
            }
        }
    }

    #[test]
    fn the_weld_rows_hold_for_any_rigid_displacement_of_g() {
        // Eq. J3: for any displacement dG of G, u_i = dG . e_xi and w_iG = dG . e_wi satisfy the
        // Fix rows (Eq. J4) and the Fw row (Eq. J5); the normals' inverse (Eq. J7) returns dG
        let robot = as_built_robot(1.0);
        let weld = Weld::of(&robot);
        let phi = robot.weld_angles();
        for (theta, dg) in [(0.0, [1.0, 0.0]), (0.4, [0.3, -0.7]), (-2.0, [-0.2, 0.5])] {
            let ex = phi.map(|p| [(theta + p).sin(), -(theta + p).cos()]);
            let ew = phi.map(|p| [(theta + p).cos(), (theta + p).sin()]);
            let u = ex.map(|e| dg[0] * e[0] + dg[1] * e[1]);
            let w = ew.map(|e| dg[0] * e[0] + dg[1] * e[1]);
            for (i, ui) in u.iter().enumerate() {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let fix = ui + weld.fix[i][0] * w[j] + weld.fix[i][1] * w[k];
                assert!(fix.abs() < 1e-14, "Fix {i}: {fix}");
            }
            let fw: f64 = (0..3).map(|i| weld.fw[i] * w[i]).sum();
            assert!(fw.abs() < 1e-14, "Fw: {fw}");
            let back = weld.dg(w, ew);
            assert!((back[0] - dg[0]).abs() < 1e-14 && (back[1] - dg[1]).abs() < 1e-14);
        }
        assert!((weld.fw.iter().sum::<f64>() - 3.0).abs() < 1e-14);
    }

    /// The roots b of a characteristic function `f` in `[lo, hi]` by bisection.
    fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
        assert!(f(lo) * f(hi) < 0.0, "no sign change in [{lo}, {hi}]");
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(lo) * f(mid) <= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn each_beam_has_the_modes_of_its_own_euler_bernoulli_beam() {
        // docs/amm.md 13, Eq. J1: beam i's modes in the system are the free-free (clamped-free)
        // beam's of its own L_i, EI_i, rho_i: eigenvalues from the characteristic equation
        // cos b cosh b = 1 (-1) solved here by bisection, orthonormal in rho_i-free form by
        // Simpson's rule on [0, L_i], and free ends (clamped root)
        let robot = as_built_robot(1.0);
        let problem = flexstar_model::catalogue::paper_case(1)
            .problem()
            .unwrap()
            .with_robot(robot.clone())
            .unwrap();
        let star = Star::new(&problem);
        assert!(!star.shared);
        for (family, sign, rigid) in [(ModeFamily::FreeFree, 1.0, 2), (ModeFamily::ClampedFree, -1.0, 0)] {
            let n = 10;
            let sys = build_system(&AmmSettings::paper(family, n), n, &star).unwrap();
            for (i, b) in robot.beams().iter().enumerate() {
                let bm = sys.beam(i);
                let (l, ei, rho) = (b.length, b.bending_stiffness(), b.mass_per_length);
                assert_eq!((bm.l, bm.rho, bm.jp), (l, rho, b.sleeve_inertia));
                let char_eq = |x: f64| x.cos() * x.cosh() - sign;
                for m in rigid..n {
                    // the k-th elastic root near (2k + 1) pi / 2 (free-free) or (2k - 1) pi / 2
                    let k = (m - rigid) as f64;
                    let centre = if rigid == 2 { k + 1.5 } else { k + 0.5 } * std::f64::consts::PI;
                    let root = bisect(|x| char_eq(x) / x.cosh(), centre - 0.6, centre + 0.6);
                    let lambda = ei / rho * (root / l).powi(4);
                    assert!(
                        (bm.lambda_m[m] - lambda).abs() < 1e-10 * lambda,
                        "{family} beam {} mode {m}: {} vs {lambda}",
                        i + 1,
                        bm.lambda_m[m]
                    );
                    // free tip: phi''(L) = phi'''(L) = 0 against the mode's scale there
                    let e = bm.modes.eval(m, l);
                    let scale = root.powi(3) / l.powi(3) / l.sqrt();
                    assert!(e[2].abs() < 1e-9 * scale && e[3].abs() < 1e-9 * scale, "{e:?}");
                    let e0 = bm.modes.eval(m, 0.0);
                    if rigid == 0 {
                        assert!(e0[0].abs() < 1e-9 / l.sqrt() && e0[1].abs() < 1e-9 * scale);
                    } else {
                        assert!(e0[2].abs() < 1e-9 * scale && e0[3].abs() < 1e-9 * scale);
                    }
                }
                // orthonormal on [0, L_i] (Simpson, 4000 panels)
                let np = 4000;
                let h = l / np as f64;
                for a in 0..n {
                    for c in a..n {
                        let mut s = 0.0;
                        for k in 0..=np {
                            let w = if k == 0 || k == np {
                                1.0
                            } else if k % 2 == 1 {
                                4.0
                            } else {
                                2.0
                            };
                            let x = k as f64 * h;
                            s += w * bm.modes.eval(a, x)[0] * bm.modes.eval(c, x)[0];
                        }
                        s *= h / 3.0;
                        let want = if a == c { 1.0 } else { 0.0 };
                        assert!((s - want).abs() < 1e-8, "beam {} <{a}, {c}> = {s}", i + 1);
                    }
                }
            }
        }
    }

    #[test]
    fn energy_balance_of_a_robot_as_built_held_at_a_pose() {
        // docs/amm.md 11.5, Eq. C6 on the robot as built (unequal beams, other welds, uneven
        // base): the star held at s = 0, a payload off G, Rayleigh damping, a load from zero
        let mut exp = flexstar_model::catalogue::paper_case(3);
        exp.trajectory = flexstar_model::Trajectory::Polynomial {
            s1: vec![0.0],
            s2: vec![0.0],
            s3: vec![0.0],
        };
        exp.time.t_end = 0.5;
        exp.payload = flexstar_model::Payload {
            mass: 0.8,
            j: 3e-3,
            offset: [0.04, 0.02],
        };
        exp.damping = flexstar_model::Damping::rayleigh(4.0, 1.5e-3);
        exp.load = flexstar_model::LoadSettings::polynomials(
            Some(vec![0.0, 0.0, 100.0, -200.0]),
            Some(vec![0.0, 0.0, -60.0, 80.0]),
            Some(vec![0.0, 0.0, 8.0, -12.0]),
        );
        let problem = exp.problem().unwrap().with_robot(as_built_robot(1.0)).unwrap();
        assert!(Star::new(&problem).paper.is_none());
        crate::system::tests::energy_balance_on(&problem);
    }
}
