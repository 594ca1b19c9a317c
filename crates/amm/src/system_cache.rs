//! The constrained system as built for a robot, family, N and model, kept for the next solve of
//! the same process (`docs/amm.md` 2.1, "The setup"): building it (each beam's mode set, the
//! geometric stiffness's quadratures, the sleeves' tables) is the setup of every solve, and a
//! plan's, a fit's or a study's runs solve the same robot many times. A solve takes a clone of
//! the system as `System::new` left it, before any attachment or step, so what it computes is
//! what a fresh build gives, bit for bit.

use std::sync::Mutex;

use flexstar_model::{AmmModel, ModeFamily, RobotParams};

use crate::star::Weld;
use crate::system::System;

/// Systems kept (the oldest goes first): a plan or a fit uses one, a robust plan a few, a study
/// one per robot.
const CAPACITY: usize = 8;

/// What a system is built from: the family, N per beam, the mode sets' parameters (one for
/// equal beams, else three), the beams, their weld and the equations.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SystemKey {
    pub family: ModeFamily,
    pub n_modes: usize,
    pub mode_params: Vec<RobotParams>,
    pub beams: [RobotParams; 3],
    pub weld: Weld,
    pub model: AmmModel,
}

static SYSTEMS: Mutex<Vec<(SystemKey, System)>> = Mutex::new(Vec::new());

/// The system of `key`: a clone of the one kept, or `build()`'s, then kept.
pub(crate) fn system<E>(key: SystemKey, build: impl FnOnce() -> Result<System, E>) -> Result<System, E> {
    if let Some(sys) = lock().iter().find(|(k, _)| *k == key).map(|(_, s)| s.clone()) {
        return Ok(sys);
    }
    let sys = build()?;
    let mut kept = lock();
    if !kept.iter().any(|(k, _)| *k == key) {
        if kept.len() == CAPACITY {
            kept.remove(0);
        }
        kept.push((key, sys.clone()));
    }
    Ok(sys)
}

/// The kept systems (a panic elsewhere while the lock was held leaves them whole: each entry is
/// pushed or removed at once).
fn lock() -> std::sync::MutexGuard<'static, Vec<(SystemKey, System)>> {
    SYSTEMS.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}
