//! Where a run with friction comes to rest (`docs/friction.md` section 5): Coulomb friction can
//! hold the star strained once every sleeve has stuck, so the residual vibration is measured
//! about that rest state, which is read from the run itself: the mean of `w_iG` and of the tips
//! over the last hold window (one period of the first mode), provided every sleeve stays stuck
//! throughout it.

use serde::Serialize;

use flexstar_model::{Response, RestOffset};

/// The columns that say whether each sleeve is stuck (1) or slipping (0) (`docs/friction.md` 7).
const STICK: [&str; 3] = ["stick1", "stick2", "stick3"];

/// How a run with friction ends.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionRest {
    /// Every sleeve stuck over the last hold window: the rest state's `w_iG` and tips [m], the
    /// means over that window.
    Stuck(RestOffset),
    /// Sleeve `sleeve` (1-based) still slips at `t` [s], the last such output time in the last
    /// hold window: no rest state yet.
    Slipping { sleeve: usize, t: f64 },
}

/// The rest state of `r` over its last `hold` [s] (at least two output times); `None` for a run
/// without the stick columns (no friction) or a hold that covers fewer than two output times.
pub fn friction_rest(r: &Response, hold: f64) -> Option<FrictionRest> {
    friction_rest_before(r, *r.t.last()?, hold)
}

/// [`friction_rest`] over the `hold` [s] that ends at `t_end` [s] (a dwell's end, `docs/motions.md`
/// 2.5).
pub fn friction_rest_before(r: &Response, t_end: f64, hold: f64) -> Option<FrictionRest> {
    let stick: Vec<&[f64]> = STICK.iter().map(|c| r.column(c)).collect::<Option<_>>()?;
    let first = r.t.partition_point(|&t| t < t_end - hold - 1e-12);
    let end = r.t.partition_point(|&t| t <= t_end + 1e-12);
    if end < first + 2 {
        return None;
    }
    let slipping = (first..end)
        .rev()
        .find_map(|k| (0..3).find(|&i| stick[i][k] < 0.5).map(|i| (i, k)));
    if let Some((i, k)) = slipping {
        return Some(FrictionRest::Slipping {
            sleeve: i + 1,
            t: r.t[k],
        });
    }
    let mean = |col: &[f64]| window_mean(&r.t[first..end], &col[first..end]);
    Some(FrictionRest::Stuck(RestOffset {
        t_rest: r.t[first],
        w_g: std::array::from_fn(|i| mean(&r.w_g[i])),
        w_tip: std::array::from_fn(|i| mean(&r.w_tip[i])),
    }))
}

/// The time mean of `f` over the samples `t` (trapezoidal rule, the rule of the EVP).
fn window_mean(t: &[f64], f: &[f64]) -> f64 {
    let span = t[t.len() - 1] - t[0];
    let integral: f64 = t
        .windows(2)
        .zip(f.windows(2))
        .map(|(tt, ff)| 0.5 * (tt[1] - tt[0]) * (ff[0] + ff[1]))
        .sum();
    integral / span
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::residual::residual_after;

    /// A run whose `w_1G` oscillates as `c + a exp(-t) cos(40 t)` about the constant `c`, its
    /// sleeves all stuck from `t_stick` on (slipping before) and `slipping` slipping to the end.
    fn run(c: f64, a: f64, t_stick: f64, slipping: Option<usize>) -> Response {
        let ts: Vec<f64> = (0..=4000).map(|k| k as f64 * 1e-3).collect();
        let mut r = Response::with_capacity("x", ts.len());
        for &t in &ts {
            let w = c + a * (-t).exp() * (40.0 * t).cos();
            r.push(t, [w, 0.0, 0.0], [2.0 * w, 0.0, 0.0], [0.0; 3]);
        }
        let stick: Vec<Vec<f64>> = (0..3)
            .map(|i| {
                ts.iter()
                    .map(|&t| {
                        if t >= t_stick && slipping != Some(i + 1) {
                            1.0
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect();
        r.set_extra(&STICK, stick);
        r
    }

    #[test]
    fn a_stuck_star_is_judged_about_the_offset_it_holds() {
        // the mean over the last 0.5 s is c to within the oscillation's integral over it, at
        // most a e^-3.5 * 2 / 40, over 0.5 s: 6.0e-6
        let (c, a, hold) = (3e-3, 2e-3, 0.5);
        let bound = a * (-3.5f64).exp() * 2.0 / 40.0 / hold;
        let r = run(c, a, 1.0, None);
        let Some(FrictionRest::Stuck(o)) = friction_rest(&r, hold) else {
            panic!("all stuck")
        };
        assert!((o.w_g[0] - c).abs() < bound, "{}", o.w_g[0]);
        assert!((o.w_tip[0] - 2.0 * c).abs() < 2.0 * bound, "{}", o.w_tip[0]);
        // about the offset the vibration decays into a 1e-4 band: |dG| = sqrt(2/3) a e^-t
        // crosses it at t = ln(sqrt(2/3) a / 1e-4) = 2.79 s at the latest
        let res = residual_after(&r, 0.5, 1e-4, hold).unwrap();
        assert!(res.settled(), "{res:?}");
        assert!(res.settle_s.unwrap() < 2.8, "{res:?}");
        // the same run without its stick columns is measured about zero and never settles
        let mut bare = r.clone();
        bare.set_extra::<&str>(&[], vec![]);
        assert!(!residual_after(&bare, 0.5, 1e-4, hold).unwrap().settled());
    }

    #[test]
    fn a_slipping_sleeve_is_named_and_the_star_judged_about_the_rest_without_friction() {
        let r = run(0.0, 2e-3, 1.0, Some(2));
        assert_eq!(
            friction_rest(&r, 0.5),
            Some(FrictionRest::Slipping { sleeve: 2, t: 4.0 })
        );
        let res = residual_after(&r, 0.5, 1e-4, 0.5).unwrap();
        assert!(res.settled(), "about zero it decays into the band: {res:?}");
        // a dwell ending before the sleeves stuck: slipping there
        assert!(matches!(
            friction_rest_before(&r, 0.8, 0.5),
            Some(FrictionRest::Slipping { t, .. }) if (t - 0.8).abs() < 1e-9
        ));
        assert_eq!(friction_rest(&run(0.0, 1e-3, 1.0, None), 0.0005), None, "one sample");
    }
}
