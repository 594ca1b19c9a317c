//! Where a trajectory leaves the feasible range (docs/conventions.md, Feasible range).
//!
//! A motion is physically possible while, for every beam and slider,
//! `Lp_i/2 < xp_i` (the sleeve does not reach the junction G), `xp_i + Lp_i/2 < L_i` (it does not
//! slide off the tip), `s_i` within its side of the base (`|s_i| < sqrt(3) d` on the paper's) and
//! every angle of IJK is below the gap G must see its opposite side under (120 degrees on the
//! paper's robot: the Fermat point exists; `docs/as-built.md` 3). Every function here takes the
//! paper's robot or one as built ([`RobotGeometry`]).

use flexstar_model::{FeasibilityKey, RobotGeometry, Trajectory};

use crate::as_built::{angle_at, rigid_pose};
use crate::direct::largest_angle;

/// Which limit is violated.
#[derive(Debug, Clone, PartialEq)]
pub enum Violation {
    /// Sleeve i reaches the junction G: `xp_i <= Lp/2`.
    SleeveAtJunction { beam: usize, xp: f64 },
    /// Sleeve i slides off the tip: `xp_i + Lp/2 >= L`.
    SleeveOffTip { beam: usize, xp: f64 },
    /// Slider i leaves its side of the base: `|s_i| >= sqrt(3) d` on the paper's robot, the
    /// side's end `limit` [m] on one as built.
    SliderOffBase { slider: usize, s: f64 },
    /// An angle of IJK reaches 120 degrees: no Fermat point.
    NoFermatPoint { vertex: usize, angle_deg: f64 },
    /// An angle of the revolute points' triangle reaches the gap between the other two beams
    /// (a robot as built, `docs/as-built.md` 3): no pose assembles the star.
    NoAssembly {
        vertex: usize,
        angle_deg: f64,
        gap_deg: f64,
    },
    /// The trajectory could not be evaluated (e.g. inverse kinematics of a task-space pose).
    Trajectory(String),
    /// A limit reached at a given via point or table row, or between two of them: `at` names
    /// where (`trajectory.file: path: row 42 (s1 = ..)`, `between points 2 and 3`).
    Located { at: String, violation: Box<Violation> },
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Violation::SleeveAtJunction { beam, xp } => {
                write!(
                    f,
                    "sleeve {beam} reaches the junction G (xp{beam} = {xp:.5} m, limit Lp/2)"
                )
            }
            Violation::SleeveOffTip { beam, xp } => {
                write!(
                    f,
                    "sleeve {beam} slides off the tip of beam {beam} (xp{beam} = {xp:.5} m, limit L - Lp/2)"
                )
            }
            Violation::SliderOffBase { slider, s } => {
                write!(
                    f,
                    "slider {slider} leaves its side of the base (s{slider} = {s:.5} m, limit sqrt(3) d)"
                )
            }
            Violation::NoFermatPoint { vertex, angle_deg } => write!(
                f,
                "triangle IJK has an angle of {angle_deg:.2} degrees at {} (no Fermat point beyond 120)",
                ["I", "J", "K"][*vertex]
            ),
            Violation::NoAssembly {
                vertex,
                angle_deg,
                gap_deg,
            } => write!(
                f,
                "the revolute points' triangle has an angle of {angle_deg:.2} degrees at {}, not below the gap of \
                 {gap_deg:.2} degrees between the other two beams (no pose assembles the star)",
                ["I", "J", "K"][*vertex]
            ),
            Violation::Trajectory(msg) => write!(f, "{msg}"),
            Violation::Located { at, violation } => write!(f, "{at}: {violation}"),
        }
    }
}

/// The trajectory leaves the feasible range at time `t`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("trajectory infeasible at t = {t:.4} s: {violation}")]
pub struct Infeasible {
    /// First time at which a limit is reached [s] (to 1e-9 s).
    pub t: f64,
    pub violation: Violation,
}

/// Smallest feasibility margin at time t and the limit it belongs to; negative means violated.
fn margin<K: RobotGeometry + ?Sized>(params: &K, traj: &Trajectory, t: f64) -> (f64, Violation) {
    match traj.s(params, t) {
        Ok(s) => configuration_margin(params, s),
        Err(e) => (-1.0, Violation::Trajectory(e.to_string())),
    }
}

/// Smallest feasibility margin of the configuration `s` [m] (a length [m]; the angle limit is
/// scaled by Lp) and the limit it belongs to; negative or zero means violated.
fn configuration_margin<K: RobotGeometry + ?Sized>(params: &K, s: [f64; 3]) -> (f64, Violation) {
    let mut worst = (f64::INFINITY, Violation::Trajectory(String::new()));
    let mut take = |m: f64, v: Violation| {
        if m < worst.0 {
            worst = (m, v);
        }
    };
    for (i, si) in s.iter().enumerate() {
        let [lo, hi] = params.slider_travel(i);
        let m = if params.paper_form().is_some() {
            hi - si.abs()
        } else {
            (si - lo).min(hi - si)
        };
        take(m, Violation::SliderOffBase { slider: i + 1, s: *si });
    }
    let pts: [[f64; 2]; 3] = std::array::from_fn(|i| params.revolute_point(i, s[i]));
    // angle margin scaled to a length so that the margins are comparable
    if let Some(p) = params.paper_form() {
        let (ang, k) = largest_angle(&pts);
        take(
            (2.0 * std::f64::consts::FRAC_PI_3 - ang) * p.lp,
            Violation::NoFermatPoint {
                vertex: k,
                angle_deg: ang.to_degrees(),
            },
        );
    } else {
        let gaps = params.gaps();
        for (k, gap) in gaps.iter().enumerate() {
            let ang = angle_at(&pts, k);
            take(
                (gap - ang) * params.sleeve_length(k),
                Violation::NoAssembly {
                    vertex: k,
                    angle_deg: ang.to_degrees(),
                    gap_deg: gap.to_degrees(),
                },
            );
        }
    }
    if let Some(pose) = rigid_pose(params, s) {
        for (i, xp) in pose.xp.iter().enumerate() {
            let (l, lp) = (params.beam_length(i), params.sleeve_length(i));
            take(xp - lp / 2.0, Violation::SleeveAtJunction { beam: i + 1, xp: *xp });
            take(l - lp / 2.0 - xp, Violation::SleeveOffTip { beam: i + 1, xp: *xp });
        }
    }
    worst
}

/// Check `[0, t_end]`: `Ok` if the motion stays feasible, otherwise the first time a limit is
/// reached (scanned at steps of at most `scan_step` and refined by bisection) and the reason.
///
/// The given poses of a `via` or `table` trajectory (its [`Trajectory::knots`]) are checked
/// first, each by [`check_configuration`], so that an infeasible row or point is named as such;
/// a limit reached between them names the two it lies between (`docs/motions.md` section 1.6).
pub fn check_trajectory<K: RobotGeometry + ?Sized>(
    params: &K,
    traj: &Trajectory,
    t_end: f64,
    scan_step: f64,
) -> Result<(), Infeasible> {
    check_knots(params, traj)?;
    scan_trajectory(params, traj, t_end, scan_step).map_err(|e| match traj.between(e.t) {
        Some(at) => Infeasible {
            t: e.t,
            violation: Violation::Located {
                at,
                violation: Box::new(e.violation),
            },
        },
        None => e,
    })
}

/// Every via point or table row of `traj` inside the feasible range.
fn check_knots<K: RobotGeometry + ?Sized>(params: &K, traj: &Trajectory) -> Result<(), Infeasible> {
    for knot in traj.knots() {
        let at = |violation| Infeasible {
            t: knot.t,
            violation: Violation::Located {
                at: knot.label.clone(),
                violation: Box::new(violation),
            },
        };
        let s = traj
            .s(params, knot.t)
            .map_err(|e| at(Violation::Trajectory(e.to_string())))?;
        check_configuration(params, s).map_err(at)?;
    }
    Ok(())
}

fn scan_trajectory<K: RobotGeometry + ?Sized>(
    params: &K,
    traj: &Trajectory,
    t_end: f64,
    scan_step: f64,
) -> Result<(), Infeasible> {
    let n = ((t_end / scan_step.min(t_end / 200.0)).ceil() as usize).max(1);
    let (m0, v0) = margin(params, traj, 0.0);
    if m0 <= 0.0 {
        return Err(Infeasible { t: 0.0, violation: v0 });
    }
    let mut t_ok = 0.0;
    for k in 1..=n {
        let t = t_end * k as f64 / n as f64;
        let (m, _) = margin(params, traj, t);
        if m <= 0.0 {
            let (mut lo, mut hi) = (t_ok, t);
            while hi - lo > 1e-10 {
                let mid = 0.5 * (lo + hi);
                if margin(params, traj, mid).0 <= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let (_, violation) = margin(params, traj, hi);
            return Err(Infeasible { t: hi, violation });
        }
        t_ok = t;
    }
    Ok(())
}

/// The scan step of the preflight every solver and command uses: the output step, at most 1 ms.
pub fn preflight_step(dt_out: f64) -> f64 {
    dt_out.min(1e-3)
}

/// A motion that [`check_motion`] found feasible over `[0, t_end]`: the proof a solver takes in
/// place of its own scan (the preflight runs once). It holds what was checked
/// (robot, trajectory, span, scan step), so that a solver can tell whether it covers the run it
/// is given; it can only be made by the check.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedMotion {
    robot: FeasibilityKey,
    trajectory: Trajectory,
    t_end: f64,
    scan_step: f64,
}

impl CheckedMotion {
    /// Does this check cover a run of `traj` on `params` over `[0, t_end]` scanned at
    /// `scan_step` or coarser (same robot and trajectory, a span and a step no larger)?
    pub fn covers<K: RobotGeometry + ?Sized>(&self, params: &K, traj: &Trajectory, t_end: f64, scan_step: f64) -> bool {
        self.robot == params.feasibility_key()
            && self.trajectory == *traj
            && t_end <= self.t_end
            && self.scan_step <= scan_step
    }
}

/// [`check_trajectory`], returning the proof of the check on success.
pub fn check_motion<K: RobotGeometry + ?Sized>(
    params: &K,
    traj: &Trajectory,
    t_end: f64,
    scan_step: f64,
) -> Result<CheckedMotion, Infeasible> {
    check_trajectory(params, traj, t_end, scan_step)?;
    Ok(CheckedMotion {
        robot: params.feasibility_key(),
        trajectory: traj.clone(),
        t_end,
        scan_step,
    })
}

/// Is `s` (at rest) inside the feasible range? Used by property tests and samplers.
pub fn is_feasible_configuration<K: RobotGeometry + ?Sized>(params: &K, s: [f64; 3]) -> bool {
    check_configuration(params, s).is_ok()
}

/// Check one configuration `s` [m] (e.g. a state of a direct-dynamics run, where the motion is
/// not known in advance): `Err` names the limit reached.
pub fn check_configuration<K: RobotGeometry + ?Sized>(params: &K, s: [f64; 3]) -> Result<(), Violation> {
    match configuration_margin(params, s) {
        (m, _) if m > 0.0 => Ok(()),
        (_, violation) => Err(violation),
    }
}
