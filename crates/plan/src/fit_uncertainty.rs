//! `[robust] fit = "fit.json"` (`docs/motions.md` 4.11): the uncertainty left by a calibration
//! (`flexstar fit`, `docs/measured.md` 4.7) as the ranges of a robust plan.
//!
//! The fit's estimates `theta` have the covariance C; their joint 95 % confidence region is the
//! ellipsoid `(x - theta)^T C^-1 (x - theta) <= chi2_p(0.95)` (p parameters). Its extent along
//! parameter j is `theta_j -+ sqrt(chi2_p(0.95)) se_j` (the ellipsoid's shadow on axis j,
//! whatever the correlations), so the box of those ranges is the smallest box that holds the
//! region: the robust plan then holds over every model the data leave plausible. `se_j` is the
//! wider of the fit's two standard errors (Eq. LS19: the noise's and the correlated one), and each
//! range is cut to the fit's own box `[lo, hi]` (the values the parameter may physically take).

use std::path::Path;

use flexstar_model::ModelError;
use serde_json::Value;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The confidence level of the region.
pub const LEVEL: f64 = 0.95;

/// An error under `robust.fit`.
fn bad(file: &Path, reason: impl Into<String>) -> ModelError {
    ModelError::invalid("robust.fit", reason).in_file(file)
}

/// `sqrt(chi2_p(LEVEL))`: the half-width of the region's shadow in standard errors.
pub fn shadow_factor(p: usize) -> Option<f64> {
    let chi2 = ChiSquared::new(p as f64).ok()?;
    Some(chi2.inverse_cdf(LEVEL).sqrt())
}

/// The ranges `(key, [lo, hi])` of the fit named by `value` (a path, relative to the experiment
/// file `file`'s folder), one per fitted parameter; refused when the file cannot be read, is no
/// `fit.json`, or its fit is no calibration (not converged, or a parameter without a standard
/// error: at a bound, or not identifiable).
pub fn ranges(value: &toml::Value, file: &Path) -> Result<Vec<(String, toml::Value)>, ModelError> {
    let name = value
        .as_str()
        .ok_or_else(|| bad(file, format!("the path of a fit.json, got {value}")))?;
    let path = file.parent().unwrap_or(Path::new(".")).join(name);
    let text = std::fs::read_to_string(&path).map_err(|e| bad(file, format!("{}: {e}", path.display())))?;
    let json: Value = serde_json::from_str(&text).map_err(|e| bad(file, format!("{}: {e}", path.display())))?;
    let at = |why: String| bad(file, format!("{}: {why}", path.display()));
    if json["calibrated"] != Value::Bool(true) {
        return Err(at(format!(
            "the fit is no calibration ({}): its uncertainty is not known",
            json["reason"].as_str().unwrap_or("no \"calibrated\": true")
        )));
    }
    let params = json["parameters"]
        .as_array()
        .filter(|p| !p.is_empty())
        .ok_or_else(|| at("no \"parameters\": not a fit.json of flexstar fit".into()))?;
    let factor = shadow_factor(params.len()).ok_or_else(|| at("no parameters".into()))?;
    params.iter().map(|p| one_range(p, factor).map_err(&at)).collect()
}

/// One parameter's range: `estimate -+ factor max(se, se_corr)` within its box.
fn one_range(p: &Value, factor: f64) -> Result<(String, toml::Value), String> {
    let key = p["key"].as_str().ok_or("a parameter without \"key\"")?;
    let num = |field: &str| p[field].as_f64();
    let (Some(estimate), Some(lo), Some(hi)) = (num("estimate"), num("lo"), num("hi")) else {
        return Err(format!("{key}: no estimate or box"));
    };
    let se = match (num("standard_error"), num("standard_error_correlated")) {
        (Some(a), Some(b)) => a.max(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => return Err(format!("{key}: no standard error (at a bound, or not identifiable)")),
    };
    let range = [(estimate - factor * se).max(lo), (estimate + factor * se).min(hi)];
    let value = toml::Value::Array(range.iter().map(|v| toml::Value::Float(*v)).collect());
    Ok((key.to_string(), value))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `chi2_p(0.95)` from the tables (Abramowitz & Stegun 26.8): 3.8415 (p = 1), 5.9915 (2),
    /// 9.4877 (4).
    #[test]
    fn the_shadow_factor_is_the_chi_square_quantile() {
        for (p, chi2) in [(1, 3.8415), (2, 5.9915), (4, 9.4877)] {
            let f = shadow_factor(p).unwrap();
            assert!((f * f - chi2).abs() < 1e-4, "p = {p}: {}", f * f);
        }
    }
}
