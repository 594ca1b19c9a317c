//! What point G actually does in a case, classified from the FEM reference (Table I, column
//! "actual behaviour of point G"), and which mode families can represent it.
//!
//! A family is *correct* when its boundary conditions at G can represent the actual behaviour
//! (docs/paper-defects.md, Table I): pinned-free forces `w_G = 0`, slide-free forces a zero slope at G,
//! free-free forces neither (only zero moment and shear, which the junction constraints relax).

use flexstar_model::{ModeFamily, Response};
use serde::{Deserialize, Serialize};

use crate::evp::g_norm;
use flexstar_numerics::measures::max_abs;

/// Behaviour of the junction G.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Behaviour {
    /// G does not move elastically (`w_G = 0`) while the beams turn at G (slope != 0).
    Pinned,
    /// G moves (`w_G != 0`) while the slope at G stays ~ 0.
    Slide,
    /// Both displacement and slope at G are present.
    General,
}

impl Behaviour {
    pub fn name(&self) -> &'static str {
        match self {
            Behaviour::Pinned => "pinned",
            Behaviour::Slide => "slide",
            Behaviour::General => "general",
        }
    }
}

/// A displacement of G below this fraction of the largest tip peak counts as zero.
pub const W_G_ZERO: f64 = 1e-2;
/// A slope at G whose lever arm `|slope| L` stays below this fraction of the largest tip peak
/// counts as zero.
pub const SLOPE_ZERO: f64 = 5e-2;

/// The measures behind the classification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct JunctionMeasures {
    /// Peak |w_G| (2-D elastic displacement of G) over the peak tip |w_i(L)|.
    pub w_g_rel: f64,
    /// Peak |slope at G| times L over the peak tip |w_i(L)|; `None` if the reference has no
    /// `slopeG` column.
    pub slope_rel: Option<f64>,
}

/// Measure the junction in a reference response (`slopeG` extra column: elastic rotation of the
/// beams at G relative to the rigid star [rad]).
pub fn measure(reference: &Response, beam_length: f64) -> JunctionMeasures {
    let tip = (0..3)
        .map(|i| max_abs(&reference.w_tip[i]))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let g: Vec<f64> = (0..reference.len())
        .map(|k| g_norm([reference.w_g[0][k], reference.w_g[1][k], reference.w_g[2][k]]))
        .collect();
    let wg = max_abs(&g);
    let slope = reference.column("slopeG").map(|v| max_abs(v) * beam_length / tip);
    JunctionMeasures {
        w_g_rel: wg / tip,
        slope_rel: slope,
    }
}

/// Classify the junction from its measures (thresholds [`W_G_ZERO`], [`SLOPE_ZERO`]).
pub fn classify(m: &JunctionMeasures) -> Behaviour {
    let moves = m.w_g_rel >= W_G_ZERO;
    let turns = m.slope_rel.map(|s| s >= SLOPE_ZERO).unwrap_or(true);
    match (moves, turns) {
        (false, _) => Behaviour::Pinned,
        (true, false) => Behaviour::Slide,
        (true, true) => Behaviour::General,
    }
}

/// Can `family`'s boundary conditions at G represent `behaviour`?
pub fn is_correct(family: ModeFamily, behaviour: Behaviour) -> bool {
    match family {
        ModeFamily::PinnedFree => behaviour == Behaviour::Pinned,
        ModeFamily::SlideFree => behaviour == Behaviour::Slide,
        // neither displacement nor slope imposed at G; enriched also carries moment and shear there
        ModeFamily::FreeFree | ModeFamily::Enriched => true,
        // clamped at G: neither displacement nor slope
        ModeFamily::ClampedFree => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdict_rules_of_the_paper() {
        // docs/paper-defects.md, Table I: the marks of the paper's text for the three behaviours.
        use Behaviour::*;
        use ModeFamily::*;
        assert!(is_correct(PinnedFree, Pinned) && !is_correct(SlideFree, Pinned) && is_correct(FreeFree, Pinned));
        assert!(!is_correct(PinnedFree, Slide) && is_correct(SlideFree, Slide) && is_correct(FreeFree, Slide));
        assert!(!is_correct(PinnedFree, General) && !is_correct(SlideFree, General) && is_correct(FreeFree, General));
    }

    #[test]
    fn classification() {
        let m = |w, s| JunctionMeasures {
            w_g_rel: w,
            slope_rel: Some(s),
        };
        assert_eq!(classify(&m(1e-6, 0.5)), Behaviour::Pinned);
        assert_eq!(classify(&m(0.3, 1e-6)), Behaviour::Slide);
        assert_eq!(classify(&m(0.3, 0.5)), Behaviour::General);
    }
}
