//! The automatic shaper over an uncertainty (`docs/motions.md` 4.11): the groups the `"auto"`
//! rule of 3.5 chooses on the nominal model, each widened to its band of final-pose frequencies
//! over the sample models, covered by specified-insensitivity shapers (Eq. H3 of 3.1).

use flexstar_model::shaper::ShaperKind;
use flexstar_model::{Experiment, ModelError, ShaperSection};

/// Elastic modes of the final pose compared between the models.
const MODES: usize = 12;
/// A nominal mode belongs to a chosen frequency when it lies within ZVD's 5 % band of it
/// (`docs/motions.md` 3.2: 0.856-1.144).
const MEMBER: (f64, f64) = (0.856, 1.144);

/// The shaped motion over the uncertainty and how it was designed.
#[derive(Debug, Clone)]
pub struct Covering {
    /// The nominal experiment with the motion shaped (`[shaper] kind = "si"`).
    pub exp: Experiment,
    /// The frequencies the nominal `"auto"` rule chose [Hz].
    pub nominal_hz: Vec<f64>,
    /// Each one's band over the models `(f_lo, f_hi)` [Hz].
    pub bands: Vec<(f64, f64)>,
    /// The half-width of the shapers' bands, in % of their centres (the widest band's).
    pub half_width_percent: f64,
}

/// Shape `exp`'s motion (rest-to-rest, unshaped, no `[shaper]`) so that the residual factor of
/// 3.2 stays at most `v_tol` = 5 % over the band of every chosen group across `models` (each the
/// same motion on another robot, payload or stiffness; the nominal model among them or not).
/// Errors name the key `shaper.f_hz` (the nominal rule) or `shaper.insensitivity` (a band no
/// shaper of four periods covers).
pub fn shape_over(exp: &Experiment, models: &[Experiment]) -> Result<Covering, ModelError> {
    let choice = {
        let mut probe = exp.clone();
        probe.shaper = Some(ShaperSection::auto(ShaperKind::Zvd));
        crate::auto::resolve_auto(&probe).map_err(|e| ModelError::invalid("shaper.f_hz", format!("\"auto\": {e}")))?
    };
    let nominal = frequencies(exp)?;
    let others: Vec<Vec<f64>> = models.iter().map(frequencies).collect::<Result<_, _>>()?;
    let bands: Vec<(f64, f64)> = choice
        .frequencies_hz
        .iter()
        .map(|&f| band(f, &nominal, &others))
        .collect();
    let half = bands.iter().map(|(lo, hi)| (hi - lo) / (hi + lo)).fold(0.0, f64::max);
    let centres: Vec<f64> = bands.iter().map(|(lo, hi)| 0.5 * (lo + hi)).collect();
    let mut section = ShaperSection::new(ShaperKind::Si, &centres);
    // rounded up to 0.1 %: the band written covers the computed one
    let percent = (1000.0 * half).ceil() / 10.0;
    section.insensitivity = Some(toml::Value::String(format!("+-{percent} %")));
    let mut shaped = exp.clone();
    shaped.shaper = Some(section);
    shaped.apply_shaper()?;
    shaped.validate()?;
    Ok(Covering {
        exp: shaped,
        nominal_hz: choice.frequencies_hz,
        bands,
        half_width_percent: percent,
    })
}

/// The first [`MODES`] elastic frequencies at the final pose (accurate AMM, sliders locked).
fn frequencies(exp: &Experiment) -> Result<Vec<f64>, ModelError> {
    flexstar_modal::analysis::final_pose_frequencies(exp, MODES)
        .map_err(|e| ModelError::invalid("shaper.f_hz", format!("modes at the final pose: {e}")))?
        .ok_or_else(|| ModelError::invalid("shaper.f_hz", "the motion never comes to rest"))
}

/// The band of the chosen frequency `f` [Hz]: the nominal modes within [`MEMBER`] of it (the
/// nearest one when none is), their frequencies at the same indices over every model.
pub fn band(f: f64, nominal: &[f64], models: &[Vec<f64>]) -> (f64, f64) {
    let mut members: Vec<usize> = (0..nominal.len())
        .filter(|&j| nominal[j] >= MEMBER.0 * f && nominal[j] <= MEMBER.1 * f)
        .collect();
    if members.is_empty() {
        let nearest = (0..nominal.len()).min_by(|&a, &b| (nominal[a] - f).abs().total_cmp(&(nominal[b] - f).abs()));
        members.extend(nearest);
    }
    let values = members
        .iter()
        .flat_map(|&j| std::iter::once(nominal[j]).chain(models.iter().filter_map(move |m| m.get(j).copied())));
    let (lo, hi) = values.fold((f, f), |(lo, hi), v| (lo.min(v), hi.max(v)));
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band of a chosen frequency spans its member modes over every model (the nominal's
    /// included), and a frequency with no member takes the nearest mode.
    #[test]
    fn bands_span_the_member_modes_over_the_models() {
        let nominal = [3.17, 3.56, 6.56, 9.5];
        let models = vec![vec![2.61, 3.07, 6.14, 8.0], vec![4.0, 4.16, 7.06, 12.1]];
        assert_eq!(band(3.365, &nominal, &models), (2.61, 4.16));
        assert_eq!(band(6.56, &nominal, &models), (6.14, 7.06));
        assert_eq!(band(20.0, &nominal, &models), (8.0, 20.0));
    }
}
