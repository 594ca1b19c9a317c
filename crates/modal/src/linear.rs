//! Linear state-space model of the small motion about a pose (`docs/modes.md`, linear model and its settings):
//!
//! ```text
//! x' = A x + B u,   y = C x + D u
//! ```
//! built from the AMM's modes at the pose ([`flexstar_amm::pose_modes`]) in modal coordinates:
//! `x = [eta; eta']` with `q = Phi eta` (mass-normalised shapes; with free sliders the three
//! rigid modes first, then K elastic ones, [`ELASTIC_MODES`] by default), so
//! `A = [[0, I], [-Omega^2, 0]]`, `B = [0; Phi^T F]`, `C = [H Phi, 0]`. How the sliders are held
//! ([`Holding`]) sets the inputs:
//!
//! - **free** (open loop): inputs the actuator forces `Fa1..Fa3` [N] on the sliders along `+u_i`
//!   (Eq. 33); outputs `s1..s3` [m] (from the pose), the tip deflections `w1tip..w3tip` and
//!   `w1G..w3G` [m], both relative to the rigid star the sliders hold (the rigid kinematics'
//!   Jacobian at the pose removes the rigid part);
//! - **locked**: the revolute points move with the sliders' prescribed motion, so the states are
//!   the elastic modes of the locked star (no rigid modes, no slider states) and the inputs are the
//!   slider accelerations `sdd1..sdd3` [m/s^2] (base excitation): with `q = q_rel + R s`, where
//!   `R = dq/ds` is the rigid motion the sliders impose (from the sliders-free rigid modes),
//!   `eta'' + Omega^2 eta = -Phi^T M R s''`. Outputs `w1tip..w3tip`, `w1G..w3G` [m] (relative to
//!   the rigid star, i.e. `H Phi eta`). With stuck sleeves R is the static shapes of unit slider
//!   displacements instead (Eq. S4 of `docs/modes.md`), which deflect the star: the states gain
//!   the sliders, `s1..s3` [m] and `sd1..sd3` [m/s] (`s'' = u`), and the outputs `H (R - R_rig) s`
//!   (Eqs. S5-S6);
//! - **servo** (closed loop, sliders free): the PD servo `Fa = ff + kp (s_ref - s) + kd (s_ref' - s')`
//!   closes the loop around the slider coordinates `s = S eta` (S: the shapes' slider rows):
//!   `A = [[0, I], [-Omega^2 - kp S^T S, -kd S^T S]]`, inputs `s1ref..s3ref` [m],
//!   `sd1ref..sd3ref` [m/s] and the feedforward forces `ff1..ff3` [N] (`B = [0; kp S^T, kd S^T,
//!   S^T]`); outputs those of the free model and the tracking errors `e1..e3 = s_ref - s` [m]
//!   (`D` = 1 from `s_iref`).
//!
//! Payload, damping and load (`docs/amm.md` 11.4): the payload is in M (so in the shapes and
//! Omega); Kelvin-Voigt damping adds `Phi^T (beta K) Phi = beta Omega^2` to the velocity block,
//! `A = [[0, I], [-Omega^2, -beta Omega^2]]` (Eq. D13; with the servo's `-kd S^T S` besides);
//! with a `[load]` section the inputs end with the load at G, `Fx`, `Fy` [N] and `Mz` [N m],
//! `B_load = [0; Phi^T P_L]` (Eq. L4, `P_L` the junction rows of Eq. L1 at the pose), D gaining
//! zero columns.
//!
//! A robot as built (`docs/modes.md`, a robot as built): the modes are its own (each beam's mode
//! set and data, each slider's mass and rail), the rigid Jacobian is its generic kinematics, and
//! the outputs take each beam's own length `L_i` and normal `e_wi` of its weld angle (Eq. M1).

use std::path::Path;

use flexstar_amm::pose_modes::{PoseModel, PoseModes, PoseSystem};
use flexstar_io::output::write_atomically;
use flexstar_kinematics::RigidState;
use flexstar_model::{DriveKind, Experiment, RestPose, Robot, RobotGeometry, Sleeves, Sliders};
use num_dual::Dual2;
use sprs::{CsMat, TriMat};

use crate::analysis::amm_modes_per_beam;
use crate::ModalError;

/// Elastic modes kept in the state-space model by default (after the three rigid ones when the
/// sliders are free).
pub const ELASTIC_MODES: usize = 20;

/// How the sliders of the linear model are held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Holding {
    /// Free on their rails (mass `mpp_mpa`), pushed by the actuator forces (open loop).
    Free,
    /// Revolute points moved by the prescribed slider motion (inputs: slider accelerations).
    Locked,
    /// Free, held by the experiment's PD servo with gains `kp` [N/m], `kd` [N s/m] (closed loop).
    Servo { kp: f64, kd: f64 },
}

impl Holding {
    /// How the AMM's sliders are held for the modes.
    pub fn sliders(&self) -> Sliders {
        match self {
            Holding::Locked => Sliders::Locked,
            Holding::Free | Holding::Servo { .. } => Sliders::Free,
        }
    }

    /// The servo of an experiment, closed around free sliders; errors name the `[drive]` key.
    /// The same gains on every slider: `kp`, `kd` as given, or from `bandwidth_hz` with the
    /// slider mass, which must then be the same on the three sliders (a robot as built whose
    /// sliders' masses differ is refused, naming `drive.bandwidth_hz`: give `kp` and `kd`).
    pub fn servo_of(exp: &Experiment) -> Result<Holding, ModalError> {
        if exp.drive.kind != DriveKind::Servo {
            return Err(ModalError::Input(format!(
                "--loop closed needs a servo drive ([drive] kind = \"servo\"); this experiment's drive is kind = \"{}\"",
                drive_kind_name(exp.drive.kind)
            )));
        }
        let masses = crate::robot(exp)?.beams().map(|b| b.sleeve_mass);
        let g = exp.drive.servo_gains(masses[0])?;
        for m in &masses[1..] {
            if exp.drive.servo_gains(*m)? != g {
                return Err(flexstar_model::ModelError::invalid(
                    "drive.bandwidth_hz",
                    format!(
                        "the gains from bandwidth_hz scale with the slider mass, and the sliders' masses differ \
                         (robot.mpp_mpa = {masses:?} kg): the linear model's servo has one kp and kd, give them"
                    ),
                )
                .into());
            }
        }
        Ok(Holding::Servo { kp: g.kp, kd: g.kd })
    }

    /// The name in `statespace.json` and in messages: `free`, `locked`, `servo`.
    pub fn name(&self) -> &'static str {
        match self {
            Holding::Free => "free",
            Holding::Locked => "locked",
            Holding::Servo { .. } => "servo",
        }
    }
}

fn drive_kind_name(k: DriveKind) -> &'static str {
    match k {
        DriveKind::Motion => "motion",
        DriveKind::Forces => "forces",
        DriveKind::Servo => "servo",
    }
}

/// What the linear model keeps: K elastic modes and how the sliders are held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearSettings {
    /// Elastic modes K (1..=[`crate::MAX_K`]).
    pub modes: usize,
    /// How the sliders are held.
    pub holding: Holding,
    /// Which linear system of the sleeves (`docs/modes.md`, stuck sleeves; with locked sliders,
    /// Eqs. S4-S6).
    pub sleeves: Sleeves,
}

impl Default for LinearSettings {
    /// [`ELASTIC_MODES`] elastic modes, sliders free, open loop (the default model of `docs/modes.md`).
    fn default() -> Self {
        LinearSettings {
            modes: ELASTIC_MODES,
            holding: Holding::Free,
            sleeves: Sleeves::Sliding,
        }
    }
}

/// A named signal or state with its unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    /// Name (as the run CSVs' columns where the same quantity appears there).
    pub name: String,
    /// SI unit.
    pub unit: &'static str,
}

fn signals(names: &[&str], unit: &'static str) -> Vec<Signal> {
    names
        .iter()
        .map(|n| Signal {
            name: (*n).into(),
            unit,
        })
        .collect()
}

/// The state-space model and what it was built from.
pub struct StateSpace {
    pub a: CsMat<f64>,
    pub b: CsMat<f64>,
    pub c: CsMat<f64>,
    pub d: CsMat<f64>,
    /// The modal analysis behind it (sliders free for the free and servo models, else locked).
    pub modes: PoseModes,
    pub pose: RestPose,
    /// The settings it was built with.
    pub settings: LinearSettings,
    /// States in order: `eta1..etaN` [m kg^0.5] (modal amplitudes of the mass-normalised
    /// shapes, mode k = row k of `modal_frequencies_hz`), then their rates `etad1..etadN`; with
    /// locked sliders and stuck sleeves then `s1..s3` [m] and `sd1..sd3` [m/s] (Eq. S6).
    pub states: Vec<Signal>,
    /// Inputs in the order of B's columns (module docs).
    pub inputs: Vec<Signal>,
    /// Outputs in the order of C's rows (module docs).
    pub outputs: Vec<Signal>,
    /// The damping ratio of every mode in the model, `(Phi^T C Phi)_kk / (2 omega_k)` of the
    /// material damping (Eq. D13; Eq. D14 exactly with the sliders locked), 0 for the rigid modes;
    /// empty without `[damping]`.
    pub damping_ratios: Vec<f64>,
}

/// Derivatives of the rigid star (G [m], theta [rad]) with respect to s_j at the pose, of the
/// robot's own rigid kinematics (`docs/as-built.md` 3 on a robot as built).
fn rigid_jacobian(robot: &Robot, pose: &RestPose) -> Result<[[f64; 3]; 3], ModalError> {
    let mut jac = [[0.0; 3]; 3];
    for (j, _) in pose.s.iter().enumerate() {
        let s = [0, 1, 2].map(|i| Dual2::new(pose.s[i], if i == j { 1.0 } else { 0.0 }, 0.0));
        let st = RigidState::from_actuators(robot, s, 0.0).map_err(|e| ModalError::Infeasible(e.to_string()))?;
        jac[0][j] = st.g[0].d1;
        jac[1][j] = st.g[1].d1;
        jac[2][j] = st.theta.d1;
    }
    Ok(jac)
}

fn dense_to_cs(rows: usize, cols: usize, f: impl Fn(usize, usize) -> f64) -> CsMat<f64> {
    let mut t = TriMat::new((rows, cols));
    for r in 0..rows {
        for c in 0..cols {
            let v = f(r, c);
            if v != 0.0 {
                t.add_triplet(r, c, v);
            }
        }
    }
    t.to_csr()
}

/// Rows `h` (on the AMM coordinates, `h . q`) of the tip deflections `w_i(L_i)` then of `w_iG`,
/// relative to the rigid star (Eq. M1 of `docs/modes.md`): with free sliders the rigid part the
/// slider displacements carry (the rigid kinematics' Jacobian, projected on beam i's own `e_wi`,
/// lever `L_i` at the tip) is removed; with locked sliders the rigid star does not move.
fn deflection_rows(robot: &Robot, pose: &RestPose, sys: &PoseSystem) -> Result<Vec<Vec<f64>>, ModalError> {
    let jac = match sys.sliders {
        Sliders::Free => Some(rigid_jacobian(robot, pose)?),
        Sliders::Locked => None,
    };
    let mut h = Vec::with_capacity(6);
    for at_tip in [true, false] {
        for i in 0..3 {
            let x = if at_tip { robot.beams()[i].length } else { 0.0 };
            let lever = x;
            let mut row = sys.deflection_row(i, x);
            if let Some(jac) = &jac {
                let ew = robot.e_w(i, pose.theta);
                for (j, ((jx, jy), jt)) in jac[0].iter().zip(&jac[1]).zip(&jac[2]).enumerate() {
                    if let Some(s_j) = sys.slider_index(j) {
                        row[s_j] -= jx * ew[0] + jy * ew[1] + lever * jt;
                    }
                }
            }
            h.push(row);
        }
    }
    Ok(h)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>()
}

/// The slider rows `S[i][k]` = slider i's displacement in shape k (free sliders).
fn slider_rows(modes: &PoseModes) -> [Vec<f64>; 3] {
    let sys = &modes.system;
    [0, 1, 2].map(|i| match sys.slider_index(i) {
        Some(si) => modes.shapes.iter().map(|p| p[si]).collect(),
        None => vec![0.0; modes.shapes.len()],
    })
}

/// Inverse of a 3 x 3 matrix (cofactors); `None` when it is singular to round-off.
fn inverse3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |r: usize, k: usize| {
        let (r1, r2, k1, k2) = ((r + 1) % 3, (r + 2) % 3, (k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det: f64 = (0..3).map(|k| m[0][k] * c(0, k)).sum();
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    // a NaN determinant is singular too
    if det.is_nan() || det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    // inverse = adjugate / det, adj[k][r] = cofactor(r, k)
    Some([0, 1, 2].map(|k| [0, 1, 2].map(|r| c(r, k) / det)))
}

/// The rigid motion the sliders impose, `R_rig` as rows (`r[a][j]` = dq_a/ds_j on the locked
/// coordinates): from the three rigid modes of the sliding, sliders-free system (their beam part
/// times the inverse of their slider part).
fn rigid_motion(model: &PoseModel, pose: &RestPose, n: usize) -> Result<Vec<[f64; 3]>, ModalError> {
    // the sliding model: `model` itself unless its sleeves stick (a copy then)
    let free = match model.sleeves() {
        Sleeves::Sliding => model.modes_at(pose, Sliders::Free, 1)?,
        Sleeves::Stuck => model
            .clone()
            .with_sleeves(Sleeves::Sliding)
            .modes_at(pose, Sliders::Free, 1)?,
    };
    let rigid = &free.shapes[..free.rigid];
    let mut s = [[0.0; 3]; 3];
    for (i, row) in s.iter_mut().enumerate() {
        let si = free.system.slider_index(i).unwrap_or(0);
        for (r, shape) in rigid.iter().enumerate().take(3) {
            row[r] = shape[si];
        }
    }
    let s_inv = inverse3(&s).ok_or_else(|| {
        ModalError::Infeasible("the sliders do not determine the star's rigid motion at this pose".into())
    })?;
    Ok((0..n)
        .map(|b| [0, 1, 2].map(|j| (0..3).map(|k| rigid[k][b] * s_inv[k][j]).sum::<f64>()))
        .collect())
}

/// Locked sliders' base excitation: the columns `M R_j` on the locked coordinates, `r` the
/// motion that follows the sliders (rows, [`rigid_motion`] or the static shapes of Eq. S4).
fn mass_times(locked: &PoseSystem, r: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = locked.n;
    (0..n)
        .map(|a| [0, 1, 2].map(|j| (0..n).map(|b| locked.m[a * n + b] * r[b][j]).sum::<f64>()))
        .collect()
}

/// The AMM's modes at the pose for `settings` (K checked, enough modes in the basis).
fn amm_modes(
    exp: &Experiment,
    model: &PoseModel,
    pose: &RestPose,
    settings: &LinearSettings,
) -> Result<PoseModes, ModalError> {
    crate::check_k(settings.modes)?;
    let modes = model.modes_at(pose, settings.holding.sliders(), settings.modes)?;
    if modes.shapes.len() < modes.rigid + settings.modes {
        return Err(ModalError::Input(format!(
            "--modes {}: the AMM with N = {} modes per beam has only {} modes",
            settings.modes,
            amm_modes_per_beam(exp),
            modes.shapes.len() - modes.rigid
        )));
    }
    Ok(modes)
}

/// The model's matrices on the modal coordinates: `omega2` (nr), the loop's stiffness and
/// damping on the modes (`kp S^T S`, `kd S^T S`; none in open loop), `bm` (nr x nu, the lower
/// block of B), `cq` (ny x nr, the left block of C) and D (ny x nu, dense).
/// A dense matrix as rows.
type Matrix = Vec<Vec<f64>>;

struct Blocks {
    omega2: Vec<f64>,
    /// `Phi^T C Phi` (nr x nr) of the material damping (Eq. D13); `None` without damping.
    damping: Option<Vec<Vec<f64>>>,
    /// The loop's `(kp S^T S, kd S^T S)` on the modes; `None` in open loop.
    feedback: Option<(Matrix, Matrix)>,
    bm: Vec<Vec<f64>>,
    cq: Vec<Vec<f64>>,
    d: Vec<Vec<f64>>,
    /// The sliders as states (locked sliders, stuck sleeves: Eqs. S5-S6); `None` otherwise.
    sliders: Option<SliderStates>,
}

/// The slider states of the locked model with stuck sleeves (Eq. S6): `x = [eta; eta'; s; s']`,
/// `s'' = u` (the first three inputs).
struct SliderStates {
    /// `R - R_rig` as rows on the locked coordinates: the deflection a unit slider displacement
    /// leaves (the static shape less the rigid motion).
    elastic: Vec<[f64; 3]>,
    /// C's columns of `s`: `H (R - R_rig)` (ny x 3).
    cs: Vec<Vec<f64>>,
    /// The material damping's force on the modes from `s'`, `Phi^T C_d (R - R_rig)` (nr x 3);
    /// `None` without damping.
    coupling: Option<Vec<Vec<f64>>>,
}

impl Blocks {
    fn matrices(&self) -> [CsMat<f64>; 4] {
        let nr = self.omega2.len();
        let extra = if self.sliders.is_some() { 6 } else { 0 };
        let n = 2 * nr + extra;
        let (nu, ny) = (self.d.first().map_or(0, Vec::len), self.cq.len());
        let a = dense_to_cs(n, n, |r, c| {
            if r < nr {
                return f64::from(u8::from(c == r + nr));
            }
            if r >= 2 * nr {
                // the sliders' double integrator: s' = sd
                return f64::from(u8::from(r < 2 * nr + 3 && c == r + 3));
            }
            let k = r - nr;
            if c < nr {
                let diag = if c == k { -self.omega2[c] } else { 0.0 };
                self.feedback.as_ref().map_or(diag, |(kp, _)| diag - kp[k][c])
            } else if c < 2 * nr {
                let material = self.damping.as_ref().map_or(0.0, |d| d[k][c - nr]);
                let servo = self.feedback.as_ref().map_or(0.0, |(_, kd)| kd[k][c - nr]);
                if material == 0.0 && servo == 0.0 {
                    0.0
                } else {
                    -material - servo
                }
            } else {
                // the damping of the static shapes' deflection rate, from s'
                let coupling = self.sliders.as_ref().and_then(|x| x.coupling.as_ref());
                match coupling {
                    Some(cp) if c >= 2 * nr + 3 => -cp[k][c - 2 * nr - 3],
                    _ => 0.0,
                }
            }
        });
        let b = dense_to_cs(n, nu, |r, c| {
            if r < nr {
                0.0
            } else if r < 2 * nr {
                self.bm[r - nr][c]
            } else {
                // sd' = sdd, the first three inputs
                f64::from(u8::from(r >= 2 * nr + 3 && c == r - 2 * nr - 3))
            }
        });
        let c = dense_to_cs(ny, n, |r, c| {
            if c < nr {
                self.cq[r][c]
            } else if c >= 2 * nr && c < 2 * nr + 3 {
                self.sliders.as_ref().map_or(0.0, |x| x.cs[r][c - 2 * nr])
            } else {
                0.0
            }
        });
        let d = dense_to_cs(ny, nu, |r, c| self.d[r][c]);
        [a, b, c, d]
    }
}

/// The linear model about `pose` with free sliders, [`ELASTIC_MODES`] elastic modes, open loop
/// (the default model of `docs/modes.md`; [`linearize_with`] takes other settings).
pub fn linearize(exp: &Experiment, pose: &RestPose) -> Result<StateSpace, ModalError> {
    linearize_with(exp, pose, &LinearSettings::default())
}

/// The linear model about `pose` with K elastic modes and the sliders held as `settings` says
/// (module docs: states, inputs and outputs of each case), of the experiment's robot (the paper's
/// or one as built, [`crate::robot`]).
pub fn linearize_with(exp: &Experiment, pose: &RestPose, settings: &LinearSettings) -> Result<StateSpace, ModalError> {
    crate::check_damping(exp)?;
    let robot = crate::robot(exp)?;
    let model = crate::analysis::amm_pose_model(exp)?.with_sleeves(settings.sleeves);
    let modes = amm_modes(exp, &model, pose, settings)?;
    let phi = &modes.shapes;
    let rows = deflection_rows(&robot, pose, &modes.system)?;
    let deflections: Vec<Vec<f64>> = rows.iter().map(|r| phi.iter().map(|p| dot(r, p)).collect()).collect();
    let (mut blocks, mut inputs, outputs) = match settings.holding {
        Holding::Locked => locked_model(&model, pose, &modes, deflections, &rows)?,
        Holding::Free => free_model(&modes, deflections),
        Holding::Servo { kp, kd } => servo_model(&modes, deflections, kp, kd),
    };
    add_damping_and_load(exp, &modes, &mut blocks, &mut inputs);
    let damping_ratios = blocks.damping.as_ref().map_or_else(Vec::new, |c| {
        let omega = modes.omega2.iter().map(|w| w.max(0.0).sqrt());
        omega
            .enumerate()
            .map(|(k, w)| if w > 0.0 { c[k][k] / (2.0 * w) } else { 0.0 })
            .collect()
    });
    let [a, b, c, d] = blocks.matrices();
    let nr = phi.len();
    let mut states: Vec<Signal> = (1..=nr)
        .map(|k| Signal {
            name: format!("eta{k}"),
            unit: "m kg^0.5",
        })
        .collect();
    states.extend((1..=nr).map(|k| Signal {
        name: format!("etad{k}"),
        unit: "m kg^0.5/s",
    }));
    if blocks.sliders.is_some() {
        states.extend(signals(&["s1", "s2", "s3"], "m"));
        states.extend(signals(&["sd1", "sd2", "sd3"], "m/s"));
    }
    Ok(StateSpace {
        a,
        b,
        c,
        d,
        modes,
        pose: *pose,
        settings: *settings,
        states,
        inputs,
        outputs,
        damping_ratios,
    })
}

/// The material damping on the modal coordinates, `Phi^T C Phi` with the AMM's damping matrix
/// at rest (Eq. D13), when the experiment has a `[damping]` section; and the load channel
/// `Phi^T P_L` (Eq. L4: inputs `Fx`, `Fy`, `Mz` after the others, zero columns of D) when it has a
/// `[load]` section.
fn add_damping_and_load(exp: &Experiment, modes: &PoseModes, blocks: &mut Blocks, inputs: &mut Vec<Signal>) {
    let sys = &modes.system;
    let phi = &modes.shapes;
    if exp.damping != flexstar_model::Damping::default() {
        let (n, c) = (
            sys.n,
            sys.damping_matrix(exp.damping.alpha(), exp.damping.beta(), &phi[..modes.rigid]),
        );
        let c_phi: Vec<Vec<f64>> = phi
            .iter()
            .map(|p| (0..n).map(|a| dot(&c[a * n..(a + 1) * n], p)).collect())
            .collect();
        blocks.damping = Some(
            phi.iter()
                .map(|pk| c_phi.iter().map(|cp| dot(pk, cp)).collect())
                .collect(),
        );
        if let Some(x) = blocks.sliders.as_mut() {
            // the damping acts on the velocity relative to the rigid star, eta' and (R - R_rig) s'
            let c_e: Vec<[f64; 3]> = (0..n)
                .map(|a| [0, 1, 2].map(|j| (0..n).map(|b| c[a * n + b] * x.elastic[b][j]).sum::<f64>()))
                .collect();
            x.coupling = Some(
                phi.iter()
                    .map(|p| (0..3).map(|j| (0..n).map(|a| p[a] * c_e[a][j]).sum::<f64>()).collect())
                    .collect(),
            );
        }
    }
    if !exp.load.is_none() {
        let columns = sys.load_columns();
        for (row, p) in blocks.bm.iter_mut().zip(phi) {
            row.extend(columns.iter().map(|col| dot(p, col)));
        }
        for row in &mut blocks.d {
            row.extend([0.0; 3]);
        }
        inputs.extend(signals(&["Fx", "Fy"], "N"));
        inputs.extend(signals(&["Mz"], "N m"));
    }
}

/// Blocks, inputs and outputs of one model.
type Model = (Blocks, Vec<Signal>, Vec<Signal>);

fn zeros(rows: usize, cols: usize) -> Vec<Vec<f64>> {
    vec![vec![0.0; cols]; rows]
}

/// Locked sliders: inputs the slider accelerations, `B = -Phi^T M R` (module docs).
fn locked_model(
    model: &PoseModel,
    pose: &RestPose,
    modes: &PoseModes,
    deflections: Vec<Vec<f64>>,
    rows: &[Vec<f64>],
) -> Result<Model, ModalError> {
    let sys = &modes.system;
    let rigid = rigid_motion(model, pose, sys.n)?;
    // the motion that follows the sliders: rigid when the sleeves slide, the static shapes of
    // Eq. S4 (on the sliders-free stuck system) when they stick
    let (follows, sliders) = match sys.sleeves {
        Sleeves::Sliding => (rigid, None),
        Sleeves::Stuck => {
            let shapes = crate::static_shapes::static_shapes(&model.system_at(pose, Sliders::Free))?;
            let follows: Vec<[f64; 3]> = shapes[..sys.n].to_vec();
            let elastic: Vec<[f64; 3]> = follows
                .iter()
                .zip(&rigid)
                .map(|(f, r)| [0, 1, 2].map(|j| f[j] - r[j]))
                .collect();
            let cs = rows
                .iter()
                .map(|h| {
                    [0, 1, 2]
                        .map(|j| h.iter().zip(&elastic).map(|(hv, e)| hv * e[j]).sum::<f64>())
                        .to_vec()
                })
                .collect();
            let states = SliderStates {
                elastic,
                cs,
                coupling: None,
            };
            (follows, Some(states))
        }
    };
    let mr = mass_times(sys, &follows);
    let bm = modes
        .shapes
        .iter()
        .map(|p| {
            (0..3)
                .map(|j| -(0..sys.n).map(|a| p[a] * mr[a][j]).sum::<f64>())
                .collect()
        })
        .collect();
    let blocks = Blocks {
        omega2: modes.omega2.clone(),
        damping: None,
        feedback: None,
        bm,
        cq: deflections,
        d: zeros(6, 3),
        sliders,
    };
    Ok((
        blocks,
        signals(&["sdd1", "sdd2", "sdd3"], "m/s^2"),
        deflection_signals(),
    ))
}

/// Free sliders, open loop: inputs Fa, `B = [0; S^T]`, outputs the sliders then the deflections.
fn free_model(modes: &PoseModes, deflections: Vec<Vec<f64>>) -> Model {
    let s = slider_rows(modes);
    let nr = modes.shapes.len();
    let mut cq: Vec<Vec<f64>> = s.to_vec();
    cq.extend(deflections);
    let mut outputs = signals(&["s1", "s2", "s3"], "m");
    outputs.extend(deflection_signals());
    let bm = (0..nr).map(|k| s.iter().map(|row| row[k]).collect()).collect();
    let blocks = Blocks {
        omega2: modes.omega2.clone(),
        damping: None,
        feedback: None,
        bm,
        cq,
        d: zeros(9, 3),
        sliders: None,
    };
    (blocks, signals(&["Fa1", "Fa2", "Fa3"], "N"), outputs)
}

/// The free model with the PD servo closed around the sliders (module docs): inputs the
/// references, their rates and the feedforward forces; the tracking errors appended as outputs.
fn servo_model(modes: &PoseModes, deflections: Vec<Vec<f64>>, kp: f64, kd: f64) -> Model {
    let (mut blocks, _, mut outputs) = free_model(modes, deflections);
    let s = slider_rows(modes);
    let nr = modes.shapes.len();
    let sts: Vec<Vec<f64>> = (0..nr)
        .map(|k| {
            (0..nr)
                .map(|j| s.iter().map(|row| row[k] * row[j]).sum::<f64>())
                .collect()
        })
        .collect();
    let scaled = |g: f64| -> Vec<Vec<f64>> { sts.iter().map(|r| r.iter().map(|v| g * v).collect()).collect() };
    blocks.feedback = Some((scaled(kp), scaled(kd)));
    blocks.bm = blocks
        .bm
        .iter()
        .map(|r| {
            let ref_pos = r.iter().map(|v| kp * v);
            let ref_rate = r.iter().map(|v| kd * v);
            ref_pos.chain(ref_rate).chain(r.iter().copied()).collect()
        })
        .collect();
    blocks.d = zeros(12, 9);
    for (i, row) in s.iter().enumerate() {
        blocks.cq.push(row.iter().map(|v| -v).collect());
        blocks.d[9 + i][i] = 1.0;
    }
    outputs.extend(signals(&["e1", "e2", "e3"], "m"));
    let mut inputs = signals(&["s1ref", "s2ref", "s3ref"], "m");
    inputs.extend(signals(&["sd1ref", "sd2ref", "sd3ref"], "m/s"));
    inputs.extend(signals(&["ff1", "ff2", "ff3"], "N"));
    (blocks, inputs, outputs)
}

fn deflection_signals() -> Vec<Signal> {
    signals(&["w1tip", "w2tip", "w3tip", "w1G", "w2G", "w3G"], "m")
}

/// Write one sparse matrix as a Matrix Market file (sprs; whole or not at all).
pub fn write_mtx(path: &Path, m: &CsMat<f64>) -> Result<(), ModalError> {
    write_atomically(path, |w| {
        sprs::io::write_matrix_market_to_bufwrite(w, m)?;
        Ok(())
    })?;
    Ok(())
}

/// Read a Matrix Market file back (sprs).
pub fn read_mtx(path: &Path) -> Result<CsMat<f64>, ModalError> {
    let t: TriMat<f64> = sprs::io::read_matrix_market(path)
        .map_err(|e| ModalError::Input(format!("{}: cannot read Matrix Market: {e}", path.display())))?;
    Ok(t.to_csr())
}

/// A dense row-major matrix as a sparse one (zeros dropped).
pub fn dense(rows: usize, cols: usize, v: &[f64]) -> CsMat<f64> {
    dense_to_cs(rows, cols, |r, c| v[r * cols + c])
}

/// Header of `linear/fem-coordinates.csv` (one row per FEM coordinate, in the order of the rows
/// and columns of `M.mtx`, `K.mtx` and the columns of `Phi_q.mtx`).
pub const FEM_COORDINATES_HEADER: &str = "index,node,beam,dof,x_m";

/// The text of `fem-coordinates.csv`: `index` 1-based (the row/column number in the Matrix
/// Market files), `node` the FEM node (0 = G; empty for a sleeve's or slider's coordinate), `beam`
/// 1..3 (empty for G), `dof` ux|uy|theta|psi|xi_c|xi_l|xi_r|slider, `x_m` the position along
/// the beam from G [m] (empty for a slider).
pub fn fem_coordinates_csv(coords: &[flexstar_fem::pose_modes::Coordinate]) -> String {
    let opt = |v: Option<usize>| v.map_or(String::new(), |v| v.to_string());
    let mut text = format!("{FEM_COORDINATES_HEADER}\n");
    for c in coords {
        let x = c.x.map_or(String::new(), flexstar_io::output::fmt_number);
        text.push_str(&format!(
            "{},{},{},{},{x}\n",
            c.index + 1,
            opt(c.node),
            opt(c.beam.map(|b| b + 1)),
            c.dof.name()
        ));
    }
    text
}

fn named(list: &[Signal]) -> Vec<serde_json::Value> {
    list.iter()
        .map(|s| serde_json::json!({"name": s.name, "unit": s.unit}))
        .collect()
}

/// `statespace.json`: the model's settings, its states, inputs and outputs (names and units, in
/// the order of A, B, C, D), the pose, the modal frequencies and the files.
fn statespace_json(exp: &Experiment, ss: &StateSpace, fem: &flexstar_fem::pose_modes::PoseSystem) -> serde_json::Value {
    let h = ss.settings.holding;
    let description = match h {
        Holding::Free => "sliders free, open loop (inputs: actuator forces)",
        Holding::Locked => {
            "sliders locked, revolute points moved by the prescribed slider motion (inputs: slider accelerations)"
        }
        Holding::Servo { .. } => {
            "sliders free, PD servo loop closed (inputs: reference positions and rates, feedforward forces)"
        }
    };
    let servo = match h {
        Holding::Servo { kp, kd } => serde_json::json!({"kp": kp, "kd": kd}),
        _ => serde_json::Value::Null,
    };
    let mut json = serde_json::json!({
        "description": format!("continuous-time state-space model x' = A x + B u, y = C x + D u of the small motion about the pose, {description} (flexstar, AMM modal coordinates: x = [eta; eta'], rigid modes first when the sliders are free)"),
        "sliders": h.sliders().name(),
        "loop": if matches!(h, Holding::Servo { .. }) { "closed" } else { "open" },
        "servo": servo,
        "elastic_modes": ss.settings.modes,
        "rigid_modes": ss.modes.rigid,
        "n_states": ss.a.rows(),
        "states": named(&ss.states),
        "inputs": named(&ss.inputs),
        "outputs": named(&ss.outputs),
        "pose": {"Gx": ss.pose.g[0], "Gy": ss.pose.g[1], "theta": ss.pose.theta, "s": ss.pose.s, "xp": ss.pose.xp},
        "modal_frequencies_hz": ss.modes.freq_hz,
        "files": {"A": "A.mtx", "B": "B.mtx", "C": "C.mtx", "D": "D.mtx", "fem_mass": "M.mtx", "fem_stiffness": "K.mtx", "fem_constraint_jacobian": "Phi_q.mtx", "fem_coordinates": "fem-coordinates.csv"},
        "fem": {"coordinates": fem.n, "constraints": fem.rows, "elements": exp.fem.elements, "sliders": fem.sliders.name()},
        "payload": exp.payload,
        "damping": damping_json(exp),
        "modal_damping_ratios": (!ss.damping_ratios.is_empty()).then_some(&ss.damping_ratios),
    });
    // only a stuck model says so: the sliding one's file is as before
    if ss.settings.sleeves == Sleeves::Stuck {
        json["sleeves"] = ss.settings.sleeves.name().into();
    }
    json
}

/// The damping of the model in `statespace.json`: `null` without a `[damping]` section, else the
/// section, alpha [1/s], beta [s] and how they enter A (Eq. D13).
fn damping_json(exp: &Experiment) -> serde_json::Value {
    if exp.damping == flexstar_model::Damping::default() {
        return serde_json::Value::Null;
    }
    serde_json::json!({
        "section": exp.damping,
        "alpha_per_s": exp.damping.alpha(),
        "beta_s": exp.damping.beta(),
        "in_A": "Rayleigh: -Phi^T (alpha M_e + beta K) Phi in the velocity block, M_e the mass of the elastic coordinates (sliders locked: -(alpha I + beta Omega^2), zeta_k = alpha / (2 omega_k) + beta omega_k / 2)",
    })
}

/// Write `dir/linear/`: A, B, C, D, statespace.json, the FEM's M, K, Phi_q at the pose (sliders
/// held as the model's) and `fem-coordinates.csv` (what their rows are). Everything is computed
/// before the first file is written, and the files are published as one set
/// ([`flexstar_io::run_set::RunSet`]). The FEM's are of the experiment's robot (each sleeve's
/// own length in `fem-coordinates.csv` on a robot as built).
pub fn write_linear(dir: &Path, exp: &Experiment, ss: &StateSpace) -> Result<(), ModalError> {
    let sliders = ss.settings.holding.sliders();
    let robot = crate::robot(exp)?;
    let fem = flexstar_fem::pose_modes::pose_system_held(
        &robot,
        &exp.payload,
        &ss.pose,
        sliders,
        ss.settings.sleeves,
        exp.fem.elements,
    )?;
    let (fm, fk, fc) = (
        dense(fem.n, fem.n, &fem.m),
        dense(fem.n, fem.n, &fem.k),
        dense(fem.rows, fem.n, &fem.c),
    );
    let lp = robot.beams().map(|b| b.sleeve_length);
    let coordinates = fem_coordinates_csv(&fem.coordinates_of(ss.pose.xp, lp));
    let json = statespace_json(exp, ss, &fem);
    // the seven matrices, the coordinates and the JSON are published together (a run set, `docs/outputs.md`)
    let mut set = flexstar_io::run_set::RunSet::begin(&dir.join("linear"))?;
    for (name, m) in [
        ("A", &ss.a),
        ("B", &ss.b),
        ("C", &ss.c),
        ("D", &ss.d),
        ("M", &fm),
        ("K", &fk),
        ("Phi_q", &fc),
    ] {
        set.file(&format!("{name}.mtx"), |w| {
            sprs::io::write_matrix_market_to_bufwrite(w, m)?;
            Ok(())
        })?;
    }
    set.text("fem-coordinates.csv", &coordinates)?;
    set.text(
        "statespace.json",
        &serde_json::to_string_pretty(&json).expect("json of plain values"),
    )?;
    set.commit()?;
    Ok(())
}
