//! Modes at one pose from both solvers, side by side (`modal.csv`).

use flexstar_amm::pose_modes::DEFAULT_MODAL_MODES;
use flexstar_io::output::{fmt_number, Dest};
use flexstar_model::ModeFamily;
use flexstar_model::{Experiment, RestPose, Sleeves, Sliders};

use crate::ModalError;

/// Header of `modal.csv` (exactly; `docs/outputs.md`).
pub const MODAL_HEADER: &str = "mode,f_amm_hz,f_fem_hz,rel_diff";

/// The columns `modal.csv` gains after [`MODAL_HEADER`] when the experiment has a `[damping]`
/// section (`docs/modes.md`, payload, damping and loads): each model's damping ratio of the mode,
/// `beta omega_k / 2` (Eq. D11).
pub const DAMPING_COLUMNS: &str = "zeta_amm,zeta_fem";

/// The AMM basis of the modal analyses: always the accurate one (the enriched family, `docs/amm.md` section 7),
/// whatever family `[amm]` asks for the time-domain runs (the paper's families miss the modes
/// badly at some poses: pinned-free puts f1 79 % above the FEM at case 4's end pose). N per beam:
/// `[amm] modes` when the config itself asks for the enriched family with a fixed N, else
/// [`DEFAULT_MODAL_MODES`].
pub fn amm_basis(exp: &Experiment) -> (ModeFamily, usize) {
    let n = match (exp.amm.family, exp.amm.modes) {
        (ModeFamily::Enriched, Some(n)) => n,
        _ => DEFAULT_MODAL_MODES,
    };
    (ModeFamily::Enriched, n)
}

/// The AMM's model at a pose for an experiment: the basis of [`amm_basis`] and the experiment's
/// payload at G (`docs/amm.md` 11.4), of its robot as data (`PoseModel::of_robot`: each beam its
/// own mode set and data on a robot as built, `docs/amm.md` 13; the paper's compact form on the
/// paper's robot).
pub fn amm_pose_model(exp: &Experiment) -> Result<flexstar_amm::pose_modes::PoseModel, ModalError> {
    let (family, nm) = amm_basis(exp);
    Ok(flexstar_amm::pose_modes::PoseModel::of_robot_with_payload(
        &crate::robot(exp)?,
        &exp.payload,
        family,
        nm,
    )?)
}

/// The FEM's modes at a pose for an experiment (`[fem] elements`, the payload at G), of its
/// robot as data (`docs/fem.md` 10 on a robot as built).
pub fn fem_pose_modes(
    exp: &Experiment,
    pose: &RestPose,
    sliders: Sliders,
    k: usize,
) -> Result<flexstar_fem::pose_modes::PoseModes, ModalError> {
    fem_pose_modes_held(exp, pose, sliders, Sleeves::Sliding, k)
}

/// [`fem_pose_modes`] with the sleeves held as `sleeves` (`docs/modes.md`, stuck sleeves, Eq. S2).
pub fn fem_pose_modes_held(
    exp: &Experiment,
    pose: &RestPose,
    sliders: Sliders,
    sleeves: Sleeves,
    k: usize,
) -> Result<flexstar_fem::pose_modes::PoseModes, ModalError> {
    Ok(flexstar_fem::pose_modes::pose_modes_held(
        &crate::robot(exp)?,
        &exp.payload,
        pose,
        sliders,
        sleeves,
        exp.fem.elements,
        k,
    )?)
}

/// Modes per beam of the AMM for an experiment (see [`amm_basis`]).
pub fn amm_modes_per_beam(exp: &Experiment) -> usize {
    amm_basis(exp).1
}

/// Both analyses at one pose.
pub struct Modal {
    pub amm: flexstar_amm::pose_modes::PoseModes,
    pub fem: flexstar_fem::pose_modes::PoseModes,
    /// K requested (elastic modes); the rigid ones come first when the sliders are free.
    pub k: usize,
    /// The experiment's `[damping]`, resolved, when it has one (`None`: no damping columns).
    pub damping: Option<flexstar_model::Damping>,
}

impl Modal {
    /// Rows of `modal.csv`: mode number (1-based, rigid ones included), AMM and FEM frequency
    /// [Hz], `(f_amm - f_fem) / f_fem` (0 for the rigid modes, which are 0 Hz in both).
    pub fn rows(&self) -> Vec<(usize, f64, f64, f64)> {
        let n = self.amm.rigid + self.k;
        (0..n)
            .map(|j| {
                let (a, f) = (self.amm.freq_hz[j], self.fem.freq_hz[j]);
                let rel = if j < self.amm.rigid { 0.0 } else { (a - f) / f };
                (j + 1, a, f, rel)
            })
            .collect()
    }
}

/// Modes at `pose` from the AMM (the experiment's family, N from [`amm_modes_per_beam`]) and the
/// FEM (`[fem] elements`): the first `k` elastic modes, after the three rigid ones when the
/// sliders are free.
pub fn modal(exp: &Experiment, pose: &RestPose, sliders: Sliders, k: usize) -> Result<Modal, ModalError> {
    modal_held(exp, pose, sliders, Sleeves::Sliding, k)
}

/// [`modal`] with the sleeves held as `sleeves`: sliding (the frictionless systems, [`modal`]) or
/// stuck (each sleeve holds its beam's material point: Eq. S1 in the AMM, S2 in the FEM,
/// `docs/modes.md`; no rigid modes are then reported first). Friction's coefficients do not
/// enter either system: they only say which one holds (`docs/modes.md`, stuck sleeves).
pub fn modal_held(
    exp: &Experiment,
    pose: &RestPose,
    sliders: Sliders,
    sleeves: Sleeves,
    k: usize,
) -> Result<Modal, ModalError> {
    crate::check_k(k)?;
    crate::check_damping(exp)?;
    let amm = amm_pose_model(exp)?.with_sleeves(sleeves).modes_at(pose, sliders, k)?;
    let fem = fem_pose_modes_held(exp, pose, sliders, sleeves, k)?;
    if amm.freq_hz.len() < amm.rigid + k {
        return Err(ModalError::Input(format!(
            "--modes {k}: the AMM with N = {} modes per beam has only {} modes",
            amm_modes_per_beam(exp),
            amm.freq_hz.len() - amm.rigid
        )));
    }
    let damping = (exp.damping != flexstar_model::Damping::default()).then_some(exp.damping);
    Ok(Modal { amm, fem, k, damping })
}

impl Modal {
    /// The damping ratios `(zeta_amm, zeta_fem)` of the rows of [`Modal::rows`]:
    /// `alpha / (2 omega_k) + beta omega_k / 2` of each model's own frequency (Eq. D11: at rest
    /// with the sliders locked the damping matrix is `alpha M + beta K` in both models, so the
    /// undamped modes diagonalize it; with free sliders the mass-proportional part acts on the
    /// elastic coordinates only and the ratio is that of the formula, `docs/modes.md`; 0 for the
    /// rigid modes); `None` without a `[damping]` section.
    pub fn damping_ratios(&self) -> Option<Vec<(f64, f64)>> {
        let damping = self.damping?;
        let zeta = |f: f64| if f > 0.0 { damping.zeta_at(f) } else { 0.0 };
        Some(self.rows().iter().map(|&(_, a, f, _)| (zeta(a), zeta(f))).collect())
    }
}

/// Write `modal.csv` (whole or not at all) to `dest`: a file of its own or a file of a run set.
/// With damping the columns [`DAMPING_COLUMNS`] follow today's.
pub fn write_modal_csv(dest: Dest<'_>, modal: &Modal) -> Result<(), ModalError> {
    let zetas = modal.damping_ratios();
    dest.write(|w| {
        match zetas {
            Some(_) => writeln!(w, "{MODAL_HEADER},{DAMPING_COLUMNS}")?,
            None => writeln!(w, "{MODAL_HEADER}")?,
        }
        for (j, (m, a, f, r)) in modal.rows().into_iter().enumerate() {
            write!(w, "{m},{},{},{}", fmt_number(a), fmt_number(f), fmt_number(r))?;
            if let Some(z) = &zetas {
                write!(w, ",{},{}", fmt_number(z[j].0), fmt_number(z[j].1))?;
            }
            writeln!(w)?;
        }
        Ok(())
    })?;
    Ok(())
}

/// The first `count` elastic natural frequencies [Hz] of the accurate AMM ([`amm_basis`], the
/// payload at G) at the start pose of the experiment's motion (t = 0), sliders locked: the robot's
/// own frequencies where every run begins (a tolerance study's `f1_hz`, `docs/studies.md`).
pub fn start_pose_frequencies(exp: &Experiment, count: usize) -> Result<Vec<f64>, ModalError> {
    let pose = crate::pose::pose_at_time(exp, 0.0)?;
    Ok(amm_pose_model(exp)?.frequencies_at(&pose, Sliders::Locked, count)?)
}

/// The first `count` elastic natural frequencies [Hz] of the accurate AMM ([`amm_basis`], the
/// payload at G) at the final pose of the experiment's rest-to-rest motion, sliders locked
/// (`docs/motions.md` 3.5, 3.6: the modes a shaper is designed for and judged against);
/// `None` when the motion never comes to rest.
pub fn final_pose_frequencies(exp: &Experiment, count: usize) -> Result<Option<Vec<f64>>, ModalError> {
    let Some(t_rest) = exp.trajectory.t_rest() else {
        return Ok(None);
    };
    let pose = crate::pose::pose_of_motion(exp, &crate::robot(exp)?, t_rest)?;
    let f = amm_pose_model(exp)?.frequencies_at(&pose, Sliders::Locked, count)?;
    Ok(Some(f))
}
