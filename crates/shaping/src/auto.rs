//! `[shaper] f_hz = "auto"` (`docs/motions.md` 3.5): the shaper frequencies from the accurate AMM,
//! resolved by the explicit step [`crate::shape`].
//!
//! The rule (3.5 as implemented): the frequencies of the accurate AMM at the final pose (sliders
//! locked) are grouped where the fit below cannot tell them apart; one accurate AMM run of the
//! unshaped motion continues `W` seconds past `t_rest`, where the AMM's response is a free
//! vibration of the final pose's modes; a least-squares fit of `w_1G..w_3G` by a cosine and a sine
//! per group gives each group's amplitude at G, `|a_g|`; the shapers are chosen greedily against
//! the LTI prediction (3.5 step 4).

use flexstar_model::shaper::{multi, residual, AutoChoice, AutoMode, ShaperKind};
use flexstar_model::{AmmSettings, Experiment, ModeFamily, ShaperSection};

/// Elastic modes of the final pose looked at.
const MODES: usize = 12;
/// Target of the greedy choice: predicted residual over unshaped (1 %, amended from 3 % in
/// docs/motions.md 3.5: the LTI prediction was ten times optimistic on `move-turn`).
const TARGET: f64 = 0.01;
/// Most shapers convolved.
const MAX_SHAPERS: usize = 4;
/// A neighbour group is merged into one shaper when its remaining amplitude is at least this
/// share of the largest one's.
const MERGE_SHARE: f64 = 0.5;

/// The largest ratio `f_hi / f_lo` of two modes that one shaper at their mean keeps below 5 %
/// residual (the table of `docs/motions.md` 3.2).
fn merge_ratio(kind: ShaperKind) -> f64 {
    match kind {
        ShaperKind::Zv => 1.066,
        ShaperKind::Zvd => 1.335,
        ShaperKind::Ei => 1.499,
        ShaperKind::TwoHumpEi => 2.136,
        ShaperKind::ThreeHumpEi => 2.860,
        // its default band, +-20 % (a section's own band shapes each chosen frequency)
        ShaperKind::Si => 1.5,
    }
}

/// Why `f_hz = "auto"` could not be resolved (`docs/motions.md` 3.5); each step's own error.
#[derive(Debug, thiserror::Error)]
pub enum AutoError {
    #[error("no [shaper] section")]
    NoSection,
    #[error("the motion never comes to rest")]
    NoRest,
    #[error("modes at the final pose: {0}")]
    Modes(#[source] flexstar_modal::ModalError),
    #[error("no elastic mode at the final pose")]
    NoElasticMode,
    /// The unshaped experiment is not a problem the AMM can take.
    #[error("the unshaped AMM run: {0}")]
    Problem(#[source] flexstar_model::ModelError),
    #[error("the unshaped AMM run: {0}")]
    Run(#[source] flexstar_amm::AmmError),
    /// The least-squares fit of the residual's modal amplitudes (3.5 step 2) is singular.
    #[error("the residual fit is singular")]
    SingularFit,
    /// The shaper section's damping or tolerance cannot be used.
    #[error("{0}")]
    Section(#[source] flexstar_model::ModelError),
    #[error("the unshaped motion leaves no residual at G to shape")]
    NoResidual,
}

/// The choice of `f_hz = "auto"`: modes, the unshaped AMM run, the fit, the greedy choice.
pub(crate) fn resolve_auto(exp: &Experiment) -> Result<AutoChoice, AutoError> {
    let section = exp.shaper.as_ref().ok_or(AutoError::NoSection)?;
    let t_rest = exp.trajectory.t_rest().ok_or(AutoError::NoRest)?;
    let freqs = flexstar_modal::analysis::final_pose_frequencies(exp, MODES)
        .map_err(AutoError::Modes)?
        .ok_or(AutoError::NoRest)?;
    let f1 = freqs
        .first()
        .copied()
        .filter(|f| *f > 0.0)
        .ok_or(AutoError::NoElasticMode)?;
    let window = (6.0 / f1).max(1.0);
    let f_max = 0.25 / exp.time.dt_out;
    let groups = group(&freqs, 1.0 / window, f_max);
    let response = unshaped_run(exp, t_rest + window)?;
    let amps = fit_amplitudes(&response, t_rest, window, &groups)?;
    let chosen = greedy(section, exp, &groups, &amps)?;
    record(section, exp, &groups, &amps, chosen, window)
}

/// The frequencies below `f_max` [Hz], those closer than `df` [Hz] merged to their mean.
fn group(freqs: &[f64], df: f64, f_max: f64) -> Vec<f64> {
    let mut groups: Vec<Vec<f64>> = Vec::new();
    for &f in freqs.iter().filter(|f| **f > 0.0 && **f < f_max) {
        match groups.last_mut() {
            Some(g) if f - g[g.len() - 1] < df => g.push(f),
            _ => groups.push(vec![f]),
        }
    }
    groups.iter().map(|g| g.iter().sum::<f64>() / g.len() as f64).collect()
}

/// The accurate AMM (enriched family, the experiment's other `[amm]` settings) of the unshaped
/// motion up to `t_end` [s].
fn unshaped_run(exp: &Experiment, t_end: f64) -> Result<flexstar_model::Response, AutoError> {
    let mut x = exp.clone();
    x.shaper = None;
    x.time.t_end = t_end;
    let settings = AmmSettings {
        family: ModeFamily::Enriched,
        snapshots: Vec::new(),
        ..exp.amm.clone()
    };
    let problem = x.problem().map_err(AutoError::Problem)?;
    flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .map_err(AutoError::Run)
}

/// `|a_g|` [m] per group: the least-squares fit of `w_iG(t_rest + tau)`, tau in [0, window], by
/// `c_0 + sum_g c_ig cos(w_g tau) + s_ig sin(w_g tau)`; `|a_g|^2 = 2/3 sum_i (c_ig^2 + s_ig^2)`,
/// the squared norm of the group's complex amplitude `a_g` in C^2 of 3.5 step 2 (its part of dG
/// has the mean square `|a_g|^2 / 2`, since `|dG|^2 = 2/3 sum w_iG^2`, docs/motions.md section 2).
fn fit_amplitudes(
    r: &flexstar_model::Response,
    t_rest: f64,
    window: f64,
    groups: &[f64],
) -> Result<Vec<f64>, AutoError> {
    let n = 1 + 2 * groups.len();
    let rows: Vec<usize> = (0..r.t.len())
        .filter(|&k| r.t[k] >= t_rest - 1e-12 && r.t[k] <= t_rest + window + 1e-12)
        .collect();
    let basis = |tau: f64| {
        let mut b = vec![1.0];
        for f in groups {
            let w = 2.0 * std::f64::consts::PI * f;
            b.extend([(w * tau).cos(), (w * tau).sin()]);
        }
        b
    };
    let mut ata = vec![0.0; n * n];
    let mut aty = vec![vec![0.0; n]; 3];
    for &k in &rows {
        let b = basis(r.t[k] - t_rest);
        for p in 0..n {
            for q in 0..n {
                ata[p * n + q] += b[p] * b[q];
            }
            for (i, rhs) in aty.iter_mut().enumerate() {
                rhs[p] += b[p] * r.w_g[i][k];
            }
        }
    }
    let mut amp2 = vec![0.0; groups.len()];
    for rhs in aty {
        let c = solve_dense(n, ata.clone(), rhs).ok_or(AutoError::SingularFit)?;
        for (g, a) in amp2.iter_mut().enumerate() {
            *a += 2.0 / 3.0 * (c[1 + 2 * g].powi(2) + c[2 + 2 * g].powi(2));
        }
    }
    Ok(amp2.iter().map(|a| a.sqrt()).collect())
}

/// Gaussian elimination with partial pivoting of the `n x n` row-major `a x = b`.
fn solve_dense(n: usize, mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))?;
        if a[p * n + c].abs() < 1e-12 * a[0].abs().max(1e-300) {
            return None;
        }
        for j in 0..n {
            a.swap(c * n + j, p * n + j);
        }
        b.swap(c, p);
        for i in c + 1..n {
            let m = a[i * n + c] / a[c * n + c];
            for j in c..n {
                a[i * n + j] -= m * a[c * n + j];
            }
            b[i] -= m * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i * n + j] * x[j]).sum();
        x[i] = (b[i] - s) / a[i * n + i];
    }
    Some(x)
}

/// The LTI residual factor of each group after the shapers at `chosen` [Hz] (3.3: the convolved
/// train's residual, the modes' damping from `[damping]`).
fn factors(section: &ShaperSection, exp: &Experiment, chosen: &[f64], groups: &[f64]) -> Result<Vec<f64>, AutoError> {
    let zetas = section
        .zetas(chosen, |f| exp.damping.zeta_at(f))
        .map_err(AutoError::Section)?;
    let v_tol = section.v_tol().map_err(AutoError::Section)?;
    let modes: Vec<(f64, f64)> = chosen.iter().copied().zip(zetas).collect();
    let train = multi(section.kind, &modes, v_tol);
    Ok(groups
        .iter()
        .map(|&f| residual(&train, f, exp.damping.zeta_at(f)))
        .collect())
}

/// The greedy covering of 3.5 step 4: take the group of largest remaining amplitude; one shaper
/// at the mean frequency with its neighbour when that neighbour keeps at least [`MERGE_SHARE`]
/// of the amplitude and lies within [`merge_ratio`], else at its own frequency; until the
/// predicted ratio is at most [`TARGET`] or [`MAX_SHAPERS`] shapers.
fn greedy(section: &ShaperSection, exp: &Experiment, groups: &[f64], amps: &[f64]) -> Result<Vec<f64>, AutoError> {
    let r0 = amps.iter().map(|a| a * a).sum::<f64>().sqrt();
    if r0 == 0.0 {
        return Err(AutoError::NoResidual);
    }
    let mut chosen: Vec<f64> = Vec::new();
    while chosen.len() < MAX_SHAPERS {
        let v = factors(section, exp, &chosen, groups)?;
        let rem: Vec<f64> = amps.iter().zip(&v).map(|(a, v)| a * v).collect();
        if rem.iter().map(|a| a * a).sum::<f64>().sqrt() <= TARGET * r0 {
            break;
        }
        let g = (0..rem.len()).max_by(|&i, &j| rem[i].total_cmp(&rem[j])).unwrap_or(0);
        let partner = (0..rem.len())
            .filter(|&h| h != g && rem[h] >= MERGE_SHARE * rem[g])
            .filter(|&h| groups[h].max(groups[g]) / groups[h].min(groups[g]) <= merge_ratio(section.kind))
            .max_by(|&i, &j| rem[i].total_cmp(&rem[j]));
        chosen.push(match partner {
            Some(h) => 0.5 * (groups[g] + groups[h]),
            None => groups[g],
        });
    }
    Ok(chosen)
}

/// The sidecar's record of the choice.
fn record(
    section: &ShaperSection,
    exp: &Experiment,
    groups: &[f64],
    amps: &[f64],
    chosen: Vec<f64>,
    window: f64,
) -> Result<AutoChoice, AutoError> {
    let v = factors(section, exp, &chosen, groups)?;
    let total: f64 = amps.iter().map(|a| a * a).sum();
    let pred: f64 = amps.iter().zip(&v).map(|(a, v)| (a * v).powi(2)).sum();
    Ok(AutoChoice {
        modes: groups
            .iter()
            .zip(amps)
            .zip(&v)
            .map(|((&f_hz, a), &factor)| AutoMode {
                f_hz,
                share: a * a / total,
                predicted_factor: factor,
            })
            .collect(),
        predicted_ratio: (pred / total).sqrt(),
        frequencies_hz: chosen,
        method: format!(
            "accurate AMM (enriched) modes at the final pose, sliders locked; unshaped AMM run to t_rest + {window:.3} s, \
             w_1G..w_3G fitted by one cosine and sine per mode group; greedy shapers until the LTI prediction <= {:.0} %",
            100.0 * TARGET
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The fit recovers the amplitudes of a known sum of sinusoids (independent: the signal is
    /// built from them), with an offset and different phases per beam.
    #[test]
    fn fit_recovers_known_amplitudes() {
        let groups = [3.9, 6.5, 11.8];
        let amp = [4e-4, 2e-4, 1e-4];
        let t: Vec<f64> = (0..1500).map(|k| 0.2 + k as f64 * 1e-3).collect();
        let mut r = flexstar_model::Response {
            t: t.clone(),
            ..Default::default()
        };
        for i in 0..3 {
            // w_iG = e_i . dG with dG = sum_g a_g (cos, sin) rotating: the beams 120 deg apart
            let phi = 2.0 * PI * i as f64 / 3.0;
            r.w_g[i] = t
                .iter()
                .map(|&tt| {
                    let tau = tt - 0.2;
                    1e-6 + groups
                        .iter()
                        .zip(amp)
                        .map(|(f, a)| a * (2.0 * PI * f * tau + phi).cos())
                        .sum::<f64>()
                })
                .collect();
        }
        let got = fit_amplitudes(&r, 0.2, 1.4, &groups).unwrap();
        for (g, a) in got.iter().zip(amp) {
            // dG of each group turns on a circle of radius a (|dG| = a for all tau), whose
            // complex amplitude (1, -i) a has the norm sqrt(2) a (mean square |a_g|^2 / 2 = a^2)
            assert!((g / (2f64.sqrt() * a) - 1.0).abs() < 1e-9, "{got:?} against {amp:?}");
        }
    }

    /// Grouping merges only modes closer than the resolution, and the merge ratios are the 5 %
    /// bands of the closed-form sensitivity curves (docs/motions.md 3.2: ZVD cos^2(pi r / 2) at
    /// r = 2 / (1 + ratio) is 5 %).
    #[test]
    fn grouping_and_merge_ratios() {
        assert_eq!(
            group(&[3.95, 3.96, 6.5, 11.6, 11.99, 80.0], 0.5, 50.0),
            vec![3.955, 6.5, 11.795]
        );
        for kind in [ShaperKind::Zv, ShaperKind::Zvd, ShaperKind::Ei] {
            let q = merge_ratio(kind);
            let r = 2.0 / (1.0 + q);
            let v = match kind {
                ShaperKind::Zv => (PI * r / 2.0).cos().abs(),
                ShaperKind::Zvd => (PI * r / 2.0).cos().powi(2),
                ShaperKind::Ei => (0.475 + 0.525 * (PI * r).cos()).abs(),
                _ => unreachable!(),
            };
            assert!((v - 0.05).abs() < 2e-3, "{kind:?}: {v}");
        }
        // the multi-hump kinds: their sensitivity curves (undamped) at the band's lower edge
        for kind in [ShaperKind::TwoHumpEi, ShaperKind::ThreeHumpEi] {
            let r = 2.0 / (1.0 + merge_ratio(kind));
            let s = flexstar_model::shaper::single(kind, 1.0, 0.0, 0.05);
            let v = flexstar_model::shaper::residual(&s, r, 0.0);
            assert!((v - 0.05).abs() < 2e-3, "{kind:?}: {v}");
        }
    }
}
