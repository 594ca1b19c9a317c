//! The solvers' errors sorted into [`ApiError`] kinds (bad input, infeasible motion, failure).

use flexstar_amm::AmmError;
use flexstar_fem::FemError;

use crate::ApiError;

/// An AMM error on the experiment `file`.
pub fn from_amm(file: &str, e: AmmError) -> ApiError {
    let message = format!("{file}: {e}");
    match &e {
        AmmError::Infeasible(inf) => ApiError::infeasible(file, inf.t, &e),
        AmmError::DirectInfeasible { t, .. } => ApiError::infeasible(file, *t, &e),
        AmmError::SleeveOffBeam(off) => ApiError::infeasible(file, off.t, &e),
        AmmError::InvalidSetting { key, reason } => ApiError::config_text(file, Some(key), reason, message),
        AmmError::UnknownFamily(_) => ApiError::config_text(file, Some("amm.family"), &e.to_string(), message),
        AmmError::Cancelled { t } => ApiError::Cancelled {
            file: file.to_string(),
            t: *t,
        },
        AmmError::Model(m) => ApiError::config_text(file, None, &m.to_string(), message),
        _ => ApiError::Solver { message },
    }
}

/// An FEM error on the experiment `file`.
pub fn from_fem(file: &str, e: FemError) -> ApiError {
    let message = format!("{file}: {e}");
    match &e {
        FemError::Input(reason) => ApiError::config_text(file, None, reason, message),
        FemError::Problem(inner) => ApiError::config_text(file, None, &inner.to_string(), message),
        FemError::Scan(inner) => ApiError::config_text(file, None, &inner.to_string(), message),
        FemError::Start(inner) => ApiError::config_text(file, None, &inner.to_string(), message),
        FemError::Cancelled { t } => ApiError::Cancelled {
            file: file.to_string(),
            t: *t,
        },
        FemError::MeshTooCoarse { .. } | FemError::Elements { .. } => {
            ApiError::config_text(file, Some("fem.elements"), &e.to_string(), message)
        }
        FemError::Infeasible { t, .. }
        | FemError::SleeveOffBeam(flexstar_model::sleeve_contact::OffBeam { t, .. })
        | FemError::SliderOffBase { t, .. }
        | FemError::Trajectory { t, .. } => ApiError::infeasible(file, *t, &e),
        _ => ApiError::Solver { message },
    }
}
