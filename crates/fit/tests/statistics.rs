//! The search and its statistics against closed forms (`docs/measured.md` 4.10): ordinary least
//! squares of a straight line (estimates, covariance, standard errors, correlation, t quantile,
//! the bounded optimum), the coverage of the 95 % intervals of a damped sinusoid over seeds, and
//! the identifiability check on parameters that only enter as a product.

use flexstar_fit::{fit, Param, Problem, Settings, Stop, Verdict};
use flexstar_model::sensors::daq::Normal;
use flexstar_model::SensorTable;

/// A one-channel table `y(t)` on the times `t`.
fn table(t: &[f64], mut y: impl FnMut(f64) -> f64) -> SensorTable {
    let mut s = SensorTable::new(t.to_vec());
    s.push_column("y".into(), "m", t.iter().map(|&t| y(t)).collect());
    s
}

fn param(key: &str, lo: f64, hi: f64, start: f64) -> Param {
    Param {
        key: key.into(),
        lo,
        hi,
        start,
    }
}

fn quiet(_: &flexstar_fit::Iteration) {}

/// `y = a + b t` with white noise of 0.3 on 100 points: the search lands on the normal
/// equations' solution and its statistics are the textbook ones (Draper & Smith): with
/// `Sxx = sum (t - tm)^2`, `b = Sxy / Sxx`, `a = ym - b tm`, `s^2 = RSS / (n - 2)`,
/// `var b = s^2 / Sxx`, `var a = s^2 (1/n + tm^2 / Sxx)`, `cov(a, b) = -tm s^2 / Sxx`; the
/// t quantile at 98 degrees of freedom is 1.984467 (tables).
#[test]
fn straight_line_matches_ordinary_least_squares() {
    let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
    let mut noise = Normal::new(11, 0);
    let data: Vec<f64> = t.iter().map(|&t| 0.7 - 1.3 * t + 0.3 * noise.draw()).collect();
    let rec = {
        let mut s = SensorTable::new(t.clone());
        s.push_column("y".into(), "m", data.clone());
        s
    };
    let problem = Problem::with_sigmas(
        vec![param("a", -5.0, 5.0, 0.0), param("b", -5.0, 5.0, 0.0)],
        &rec,
        &[1.0],
        &[1.0],
    )
    .unwrap();
    let model = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |x| th[0] + th[1] * x)) };
    let f = fit(&problem, &model, &Settings::default(), &quiet).unwrap();
    assert!(f.converged(), "{}", f.reason);

    let n = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / n, data.iter().sum::<f64>() / n);
    let sxx: f64 = t.iter().map(|x| (x - tm).powi(2)).sum();
    let sxy: f64 = t.iter().zip(&data).map(|(x, y)| (x - tm) * (y - ym)).sum();
    let b = sxy / sxx;
    let a = ym - b * tm;
    let rss: f64 = t.iter().zip(&data).map(|(x, y)| (y - a - b * x).powi(2)).sum();
    let s2 = rss / (n - 2.0);
    let (var_a, var_b, cov_ab) = (s2 * (1.0 / n + tm * tm / sxx), s2 / sxx, -tm * s2 / sxx);

    let th = f.theta();
    // the search stops at a relative offset of 1e-3: within 1e-3 standard errors
    assert!((th[0] - a).abs() < 2e-3 * var_a.sqrt(), "{} vs {a}", th[0]);
    assert!((th[1] - b).abs() < 2e-3 * var_b.sqrt(), "{} vs {b}", th[1]);
    let st = &f.statistics;
    assert_eq!((st.n, st.dof), (100, 98));
    assert!((st.s2 / s2 - 1.0).abs() < 1e-6, "{} vs {s2}", st.s2);
    let rel = |x: Option<f64>, y: f64| (x.unwrap() / y - 1.0).abs();
    // the forward-difference Jacobian of a linear model is exact to rounding
    assert!(rel(st.covariance[0][0], var_a) < 1e-6);
    assert!(rel(st.covariance[1][1], var_b) < 1e-6);
    assert!(rel(st.covariance[0][1], cov_ab) < 1e-6);
    assert!(rel(st.standard_errors[1], var_b.sqrt()) < 1e-6);
    assert!(rel(st.correlation[0][1], cov_ab / (var_a * var_b).sqrt()) < 1e-6);
    assert!((st.t_quantile - 1.984467).abs() < 1e-5, "{}", st.t_quantile);
    let [lo, hi] = f.estimates[1].interval.unwrap();
    assert!((0.5 * (hi - lo) / (1.984467 * var_b.sqrt()) - 1.0).abs() < 1e-5);
    assert_eq!(f.identifiability.verdict, Verdict::Identifiable);
    // the channel's RMS error after the fit is sqrt(RSS / n)
    assert!((f.channels[0].rms_after / (rss / n).sqrt() - 1.0).abs() < 1e-6);
}

/// The same line with the slope's box ending below the unconstrained optimum: the slope stops
/// on its bound and the intercept is the constrained least-squares one, `mean(y - hi t)`.
#[test]
fn an_optimum_outside_the_box_stops_on_its_bound() {
    let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.02).collect();
    let mut noise = Normal::new(3, 0);
    let data: Vec<f64> = t.iter().map(|&t| 0.2 + 2.0 * t + 0.05 * noise.draw()).collect();
    let mut rec = SensorTable::new(t.clone());
    rec.push_column("y".into(), "m", data.clone());
    let problem = Problem::with_sigmas(
        vec![param("a", -1.0, 1.0, 0.0), param("b", 0.0, 1.5, 1.0)],
        &rec,
        &[1.0],
        &[0.05],
    )
    .unwrap();
    let model = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |x| th[0] + th[1] * x)) };
    let f = fit(&problem, &model, &Settings::default(), &quiet).unwrap();
    assert!(f.converged(), "{}", f.reason);
    let n = t.len() as f64;
    let a = t.iter().zip(&data).map(|(x, y)| y - 1.5 * x).sum::<f64>() / n;
    assert_eq!(f.estimates[1].estimate, 1.5);
    assert!(f.estimates[1].at_bound && f.estimates[1].standard_error.is_none());
    assert!(
        (f.estimates[0].estimate - a).abs() < 1e-3 * 0.05 / n.sqrt(),
        "{}",
        f.estimates[0].estimate
    );
    // the free intercept keeps its statistics: s / sqrt(n) with one parameter free
    let rss: f64 = t.iter().zip(&data).map(|(x, y)| (y - a - 1.5 * x).powi(2)).sum();
    let se = (rss / 0.05f64.powi(2) / (n - 1.0)).sqrt() * 0.05 / n.sqrt();
    assert!((f.estimates[0].standard_error.unwrap() / se - 1.0).abs() < 1e-6);
}

/// A damped sinusoid `A exp(-z w t) sin(w sqrt(1 - z^2) t)` with noise of 2 % of its peak, over
/// 200 seeds: each parameter's true value lies inside its 95 % interval in 95 % of the fits,
/// within the binomial spread (3 standard deviations of 200 draws: 0.95 -+ 0.046). The noise
/// level is the one estimated from each recording (Eq. LS2), as the command does.
#[test]
fn intervals_of_a_damped_sinusoid_cover_the_truth_95_percent_of_the_time() {
    let truth = [1.0, 2.0 * std::f64::consts::PI * 5.0, 0.03];
    let t: Vec<f64> = (0..400).map(|k| k as f64 * 2e-3).collect();
    let wave =
        |th: &[f64], x: f64| th[0] * (-th[2] * th[1] * x).exp() * (th[1] * (1.0 - th[2] * th[2]).sqrt() * x).sin();
    let params = vec![
        param("A", 0.5, 2.0, 0.8),
        param("w", 25.0, 38.0, 33.0),
        param("z", 0.0, 0.2, 0.05),
    ];
    let model = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |x| wave(th, x))) };
    let seeds = 200;
    let mut inside = [0usize; 3];
    let mut s2_sum = 0.0;
    for seed in 0..seeds {
        let mut noise = Normal::new(seed, 0);
        let rec = table(&t, |x| wave(&truth, x) + 0.02 * noise.draw());
        let problem = Problem::new(params.clone(), &rec, &[1.0]).unwrap();
        let f = fit(&problem, &model, &Settings::default(), &quiet).unwrap();
        assert!(f.converged(), "seed {seed}: {}", f.reason);
        for (k, e) in f.estimates.iter().enumerate() {
            let [lo, hi] = e.interval.unwrap();
            inside[k] += usize::from(lo <= truth[k] && truth[k] <= hi);
        }
        s2_sum += f.statistics.s2;
    }
    let s2 = s2_sum / seeds as f64;
    eprintln!("coverage of the 95 % intervals over {seeds} seeds (A, w, z): {inside:?}; mean s^2 = {s2:.4}");
    for (k, n) in inside.iter().enumerate() {
        let share = *n as f64 / seeds as f64;
        assert!(
            (share - 0.95).abs() <= 0.046,
            "parameter {k}: {share} of the intervals hold the truth"
        );
    }
    // the estimated noise levels make the weighted residuals of unit variance
    assert!((s2 - 1.0).abs() < 0.05, "mean s^2 = {s2}");
}

/// `y = a b exp(-t)`: only the product enters. The start's Jacobian is rank-deficient and the
/// fit is refused, naming the pair and the product the data fix. With a small term in `a` alone
/// the two separate poorly: the fit runs and flags the same combination.
#[test]
fn parameters_that_enter_as_a_product_are_named() {
    let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
    let mut noise = Normal::new(5, 0);
    let rec = table(&t, |x| 2.0 * (-x).exp() + 0.01 * noise.draw());
    let params = vec![param("a", 0.5, 4.0, 1.0), param("b", 0.5, 4.0, 1.5)];
    let product = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |x| th[0] * th[1] * (-x).exp())) };
    let problem = Problem::new(params.clone(), &rec, &[1.0]).unwrap();
    let e = fit(&problem, &product, &Settings::default(), &quiet)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("rank-deficient") && e.contains("d ln a = +0.707") && e.contains("d ln b = -0.707"),
        "{e}"
    );
    assert!(e.contains("only a^1.00 x b^1.00 is determined"), "{e}");
    // nearly a product: a term 1e-3 as large in a alone
    let nearly = |th: &[f64]| -> Result<SensorTable, String> {
        Ok(table(&t, |x| th[0] * th[1] * (-x).exp() + 1e-3 * th[0] * x))
    };
    let f = fit(&problem, &nearly, &Settings::default(), &quiet).unwrap();
    assert_eq!(
        f.identifiability.verdict,
        Verdict::IllConditioned,
        "{}",
        f.identifiability.message
    );
    let c = f.identifiability.combination.as_ref().unwrap();
    let keys: Vec<&str> = c.entries.iter().map(|(k, _, _)| k.as_str()).collect();
    assert_eq!(keys.len(), 2, "{:?}", c.entries);
    assert!(keys.contains(&"a") && keys.contains(&"b"));
    let corr = f.statistics.correlation[0][1].unwrap();
    eprintln!("nearly a product: {}; correlation {corr:.6}", f.identifiability.message);
    assert!(
        corr < -0.999,
        "the estimates of a and b move against each other: {corr}"
    );
}

/// One iteration on a problem that needs several: not converged, and it says so.
#[test]
fn a_search_cut_short_says_it_did_not_converge() {
    let t: Vec<f64> = (0..300).map(|k| k as f64 * 2e-3).collect();
    let wave = |th: &[f64], x: f64| (-th[1] * x).exp() * (th[0] * x).sin();
    let mut noise = Normal::new(1, 0);
    let rec = table(&t, |x| wave(&[30.0, 1.0], x) + 0.01 * noise.draw());
    let problem = Problem::new(
        vec![param("w", 20.0, 40.0, 26.0), param("d", 0.0, 5.0, 2.0)],
        &rec,
        &[1.0],
    )
    .unwrap();
    let model = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |x| wave(th, x))) };
    let short = Settings {
        max_iterations: 1,
        ..Settings::default()
    };
    let f = fit(&problem, &model, &short, &quiet).unwrap();
    assert!(
        !f.converged() && matches!(f.stop, Stop::MaxIterations { .. }),
        "{:?}",
        f.stop
    );
    assert!(f.reason.starts_with("not converged"), "{}", f.reason);
    let full = fit(&problem, &model, &Settings::default(), &quiet).unwrap();
    assert!(full.converged(), "{}", full.reason);
    assert!((full.theta()[0] - 30.0).abs() < 0.05, "{:?}", full.theta());
}

/// The mean `a` of AR(1) residuals `e_k = rho e_(k-1) + u_k` (rho = 0.8, 100 000 samples): the
/// noise's standard error (Eq. LS12) is the white one, `sd(e) / sqrt(n)`, and the correlated one of
/// Eq. LS18 (bandwidth 400 samples) the long-run one, `sd(e) sqrt((1 + rho) / (1 - rho) / n)`
/// (Hamilton, Time Series Analysis, 7.2), three times larger; for white residuals the two agree.
/// Tolerances: the Bartlett estimate's own spread at this bandwidth, `sqrt(4 L / 3 n)` = 7.3 % in
/// variance, 3.7 % in the standard error (12 % asserted: three of those).
#[test]
fn correlated_residuals_widen_the_standard_error_to_the_long_run_one() {
    let n = 100_000;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    for (rho, seed) in [(0.8, 21), (0.0, 22)] {
        let mut noise = Normal::new(seed, 0);
        let mut e = 0.0;
        let data: Vec<f64> = (0..n)
            .map(|_| {
                e = rho * e + noise.draw();
                1.5 + e
            })
            .collect();
        let rec = {
            let mut s = SensorTable::new(t.clone());
            s.push_column("y".into(), "m", data.clone());
            s
        };
        let problem = Problem::with_sigmas(vec![param("a", -5.0, 5.0, 0.0)], &rec, &[1.0], &[1.0]).unwrap();
        let model = |th: &[f64]| -> Result<SensorTable, String> { Ok(table(&t, |_| th[0])) };
        let settings = Settings {
            correlation_samples: 400,
            ..Settings::default()
        };
        let f = fit(&problem, &model, &settings, &quiet).unwrap();
        assert!(f.converged(), "{}", f.reason);
        let e = &f.estimates[0];
        let mean = data.iter().sum::<f64>() / n as f64;
        let sd = (data.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        let white = sd / (n as f64).sqrt();
        let long_run = white * ((1.0 + rho) / (1.0 - rho)).sqrt();
        let (se, se_corr) = (e.standard_error.unwrap(), e.standard_error_correlated.unwrap());
        eprintln!("rho {rho}: se {se:.4e} (white {white:.4e}), correlated {se_corr:.4e} (long-run {long_run:.4e})");
        assert!((se / white - 1.0).abs() < 1e-3, "{se} vs {white}");
        assert!((se_corr / long_run - 1.0).abs() < 0.12, "{se_corr} vs {long_run}");
        let [lo, hi] = e.interval.unwrap();
        let half = 0.5 * (hi - lo);
        assert!((half / (f.statistics.t_quantile * se.max(se_corr)) - 1.0).abs() < 1e-12);
    }
}

/// A sinusoid's frequency from a start far from it: `y = sin(2 pi f t)` over 2 s (f = 3.3 Hz,
/// noise 0.05) has a cost with a local minimum between every pair of the truth's neighbouring
/// half-cycle counts, so the search from 1 Hz stops in one of them, far from the truth; with
/// eight starts (`docs/measured.md` 4.6) the Halton points of the box [0.5, 6] Hz reach the
/// truth's basin (half a cycle over the record wide: 0.25 Hz) and the fit lands on 3.3 Hz within
/// its 95 % interval, the chosen start flagged and the lowest cost of those that converged.
#[test]
fn several_starts_find_the_frequency_one_start_misses() {
    let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.005).collect();
    let truth = 3.3;
    let mut noise = Normal::new(31, 0);
    let rec = table(&t, |x| {
        (2.0 * std::f64::consts::PI * truth * x).sin() + 0.05 * noise.draw()
    });
    let problem = Problem::with_sigmas(vec![param("f", 0.5, 6.0, 1.0)], &rec, &[1.0], &[0.05]).unwrap();
    let model = |th: &[f64]| -> Result<SensorTable, String> {
        Ok(table(&t, |x| (2.0 * std::f64::consts::PI * th[0] * x).sin()))
    };
    let one = fit(&problem, &model, &Settings::default(), &quiet).unwrap();
    let f_one = one.estimates[0].estimate;
    eprintln!("one start: f = {f_one} ({})", one.reason);
    assert!((f_one - truth).abs() > 0.2, "one start already found {f_one}");
    assert_eq!(one.starts.len(), 1);
    let settings = Settings {
        starts: 8,
        ..Settings::default()
    };
    let many = fit(&problem, &model, &settings, &quiet).unwrap();
    let e = &many.estimates[0];
    let [lo, hi] = e.interval.unwrap();
    eprintln!("eight starts: f = {} [{lo}, {hi}]", e.estimate);
    for s in &many.starts {
        eprintln!(
            "  from {:.3} to {:.4}: cost {:.4e} {}{}",
            s.start[0],
            s.end[0],
            s.cost,
            s.reason,
            if s.chosen { " (chosen)" } else { "" }
        );
    }
    assert!(many.converged(), "{}", many.reason);
    assert!((lo..=hi).contains(&truth), "{} [{lo}, {hi}]", e.estimate);
    assert_eq!(many.starts.len(), 8);
    let chosen: Vec<_> = many.starts.iter().filter(|s| s.chosen).collect();
    assert_eq!(chosen.len(), 1);
    let least = many
        .starts
        .iter()
        .filter(|s| s.converged)
        .map(|s| s.cost)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(chosen[0].cost, least);
    assert_eq!(chosen[0].end[0], e.estimate);
}
