//! Error estimate and automatic number of modes (`docs/amm.md` section 9).
//!
//! The solver estimates the EVP (Eq. 45, mean over A, B, C and G with the n/a rule of
//! `flexstar_metrics::evp`) of its own modal truncation from two runs: N_prev and N = ~1.15 N_prev.
//! If the error falls like N^-p, the difference d between the two runs is
//! `e(N_prev) - e(N) = e(N) ((N / N_prev)^p - 1)`, so `e(N) = d / ((N / N_prev)^p - 1)`
//! (Richardson). The rate [`RATE`] is measured: between N = 46 and 53 the truncation EVP of the
//! paper's four cases against N = 150 falls by 2.4-2.9 times, p = 6.1-7.6 (`docs/amm.md`
//! section 9; `cargo run --release -p flexstar-amm --example convergence -- truncation`).
//! N starts where the modes first resolve the sleeve (wavelength 2L/N below Lp, `docs/amm.md`
//! section 3, plus a margin) and grows by 15 % until the estimate is below the tolerance, up to
//! [`MAX_AUTO_MODES`].
//!
//! The pair runs at [`ESTIMATE_STEP_FACTOR`] times the delivered step: d is a difference of two
//! runs at the same step, and their time errors (2-6 % at that step) cancel in it. On the paper's
//! cases and the two motions of `configs/motions/`, d at 8 h is 0.97-1.00 times d at h
//! (`cargo run --release -p flexstar-amm --example coarse_estimate -- 8 16`); at 16 h,
//! with time errors of 8-21 %, 0.87-0.99. The chosen N then runs once at the delivered step,
//! and the time error of the coarse step is checked against it: above
//! [`MAX_ESTIMATE_TIME_ERROR`] the pairs are run again at the delivered step.
//!
//! With friction the pairs are the robot's without it (`docs/amm.md` 12.16), and the chosen N runs
//! with friction at 2 h and h.
//!
//! The truncation part reported is not Richardson's but the direct pair's: the chosen N against
//! N + [`DIRECT_PAIR_MODES`] at the time check's step 2 h ([`direct_truncation`], Eq. E1 of
//! `docs/amm.md` 12.18), which reads the own truncation (N against N + 25 at h) to a few per
//! cent where Richardson's on the coarse pair reads 0.5-4 times it; Richardson's stays where
//! there is no time check, where the pairs ran at the delivered step, and with friction.
//!
//! The reported estimate is the truncation plus the delivered run's time error, from one more run
//! of the chosen N at 2 h ([`time_error_estimate`], Eq. T1 of `docs/amm.md` 12.10; also on spans
//! too short for the coarse grid, 12.13), plus the geometric part the AMM leaves out
//! ([`geometric_part`], Eq. G1, 12.9). Under gravity the vibration about the sag needs no part
//! of its own: the full model carries the terms that made its error (12.14, Eqs. V5-V6).

use flexstar_metrics::evp::point_evps;
use flexstar_model::{Problem, Response};

use crate::error::AmmError;
use crate::star::Star;

/// Largest N the automatic choice tries (stable to N = 200).
pub const MAX_AUTO_MODES: usize = 200;

/// Growth of N between two runs of the automatic choice.
pub const GROWTH: f64 = 1.15;

/// Convergence rate p of the truncation EVP, `e(N) ~ N^-p`, that turns the difference of two
/// runs into the estimate (module docs): the median of the rates measured on the paper's cases
/// between N = 46 and 53 (6.1, 6.8, 7.2, 7.6).
pub const RATE: f64 = 7.0;

/// Step of the estimate's runs over the delivered step (module docs).
pub const ESTIMATE_STEP_FACTOR: f64 = 8.0;

/// Largest time error of the estimate's step [%]: the mean EVP (Eq. 45) of the chosen N's run at
/// that step against its run at the delivered step. At 16 times the step the paper's cases reach
/// 8-21 % and their pair differences 0.87-0.99 times those at the delivered step (module docs).
pub const MAX_ESTIMATE_TIME_ERROR: f64 = 10.0;

/// Step of the time check's run over the delivered step (`docs/amm.md` 12.10): the
/// chosen N once more at `2 h`, on the finest output grid that step allows
/// ([`time_check_grid`]), for the delivered run's time error ([`time_error_estimate`]).
pub const TIME_CHECK_STEP_FACTOR: f64 = 2.0;

/// `E(2 h, h) / e(h)`, the time check's difference over the delivered run's time error, with
/// which [`time_error_estimate`] turns one into the other (`docs/amm.md` 12.10): `2^p - 1`, 3
/// for the integrator's order p = 2; measured 2.1-3.0 (p = 1.6-2.0; e(h) against the same N at
/// h / 16) on the paper's cases 1 and 3, `smooth`, `brisk` and the five robots of `docs/amm.md`
/// section 12 (`cargo run --release -p flexstar-amm --example time_order -- FILES`), where the coarse step's
/// `E(8 h, h) / e(h)` spread over 11.6-61.7 (12.5) and `E(4 h, h) / e(h)` over 5.2-14.8. 2.5, the
/// geometric middle, keeps the time part within 0.83-1.2 times the true one there.
pub const TIME_CHECK_RATIO: f64 = 2.5;

/// Estimated time error [%] of the delivered run at step h (`docs/amm.md` 12.10, Eq. T1):
/// `e(h) = E(2 h, h) / TIME_CHECK_RATIO`, `e_check = E(2 h, h)` the mean EVP (Eq. 45) of the chosen
/// N's run at 2 h against its run at h on the time check's output grid ([`time_check_grid`]).
pub fn time_error_estimate(e_check: f64) -> f64 {
    e_check / TIME_CHECK_RATIO
}

/// `E(2 h, h) / e(h)` of a run with friction in the sleeves (`docs/amm.md` 12.15, Eq. T2): its
/// stick and slip events, located within the step (`docs/friction.md` 9.5), still leave part of
/// the error falling at first order (`2^1 - 1 = 1`) where the events crowd. Measured 1.06-2.98 on
/// the paper's four cases and the two target moves at `mu` = 0.1 and 0.3, both load models
/// (`cargo run --release -p flexstar-amm --example time_order`, e(h) against h / 16); 1.75, the
/// geometric middle, keeps the time part within 0.6-1.7 times the true one there.
pub const FRICTION_TIME_CHECK_RATIO: f64 = 1.75;

/// With friction in the sleeves, the share of the tolerance above which the time part (Eq. T2)
/// halves the delivered step (`docs/amm.md` 12.15): a run whose events crowd can carry a time error
/// of several per cent at the tolerance's step, which the tolerance on N does not see.
pub const FRICTION_TIME_SHARE: f64 = 0.5;

/// Most halvings of the delivered step with friction (h / 16 at the least).
pub const MAX_FRICTION_HALVINGS: u32 = 4;

/// The time check's ratio of a problem: [`FRICTION_TIME_CHECK_RATIO`] with friction in the
/// sleeves, else [`TIME_CHECK_RATIO`].
fn time_check_ratio(problem: &Star) -> f64 {
    if problem.friction.is_some() {
        FRICTION_TIME_CHECK_RATIO
    } else {
        TIME_CHECK_RATIO
    }
}

/// Coefficient `C_G` of the estimate's geometric part, Eq. G1 of `docs/amm.md` 12.9:
/// `e_geom = C_G * 100 * (A / L)^2` [%], A the largest elastic tip or junction displacement of
/// the run. What the AMM still misses against the converged co-rotational FEM grows like the
/// square of the deflection (12.9); with the material point in the sleeve drawn out by the
/// foreshortening (Eqs. S1-S4, 12.11) it is about half of what it was, and C_G = 0.5, chosen on
/// the envelope's seed-21 draw, is checked on the seed-22 draw (`docs/validation.md` 8; checked
/// again with the slope row of Eq. S5 and the direct pair, 12.17-12.18). For the full model
/// without the beams' third-order terms (no gravity).
pub const GEOMETRIC_COEFF: f64 = 0.5;

/// `C_G` of Eq. G1 for the full model with the beams' third-order terms (under gravity,
/// `docs/amm.md` 12.14, Eqs. V5-V6) and the sleeve's exact slope row (Eq. S5, 12.17): they
/// restore most of what G1 stood for. Chosen on the in-range cases of the as-built envelope's
/// seed-31 draw (every one under gravity; 0.1 the only value of 0.05-0.25 that leaves none of them
/// outside [0.5, 2] with the direct pair of 12.18), checked on its seed-32 draw
/// (`docs/validation.md` 9).
pub const GEOMETRIC_COEFF_THIRD_ORDER: f64 = 0.1;

/// Eq. G1 [%]: the estimate's part for the geometric nonlinearity the AMM leaves out, from the
/// run `r` of `problem` (tips w_i(L) and junction values w_iG [m], each beam's L_i [m]: the
/// largest `A_i / L_i`, `docs/amm.md` 13, Eq. J8), with [`GEOMETRIC_COEFF_THIRD_ORDER`] where
/// the run is the full model's under gravity and [`GEOMETRIC_COEFF`] otherwise.
pub fn geometric_part(problem: &Problem, r: &Response) -> f64 {
    geometric_part_of(&Star::new(problem), r)
}

/// [`geometric_part`] of the AMM's view of a problem.
pub(crate) fn geometric_part_of(problem: &Star, r: &Response) -> f64 {
    let largest = |h: &Vec<f64>| h.iter().fold(0.0f64, |m, w| m.max(w.abs()));
    let a = (0..3)
        .map(|i| largest(&r.w_tip[i]).max(largest(&r.w_g[i])) / problem.beam(i).l)
        .fold(0.0f64, f64::max);
    let coeff = if crate::third_order::carried(problem.gravity, r.info.model.as_deref() == Some("full")) {
        GEOMETRIC_COEFF_THIRD_ORDER
    } else {
        GEOMETRIC_COEFF
    };
    coeff * 100.0 * a * a
}

/// Fewest output rows of the estimate's coarse grid; shorter spans run their pairs at the
/// delivered step.
pub const MIN_ESTIMATE_ROWS: usize = 20;

/// The coarse output grid of the estimate's runs for a delivered step `h` [s]: its interval is
/// `every` times `problem.time.dt_out`, the first multiple at least [`ESTIMATE_STEP_FACTOR`] h, so that
/// its times are a subset of the delivered ones. `None` (pairs at the delivered step) when that grid
/// would have fewer than [`MIN_ESTIMATE_ROWS`] rows. With friction the pairs on this grid are the
/// robot's without it ([`Pass::BareEstimate`], `docs/amm.md` 12.16: at the coarse step the stick
/// and slip events, not the truncation, would decide a pair's difference, 12.15).
pub fn estimate_grid(problem: &Problem, h: f64) -> Option<usize> {
    estimate_grid_of(&Star::new(problem), h)
}

/// [`estimate_grid`] of the AMM's view of a problem.
pub(crate) fn estimate_grid_of(problem: &Star, h: f64) -> Option<usize> {
    let every = output_multiple(problem, ESTIMATE_STEP_FACTOR * h);
    let rows = (problem.time.t_end / (every as f64 * problem.time.dt_out) - 1e-9).ceil() + 1.0;
    (rows >= MIN_ESTIMATE_ROWS as f64).then_some(every)
}

/// The time check's output grid for a delivered step `h` [s]: every `k`-th delivered output time,
/// `k` the smallest with `k dt_out >= 2 h` (1 where `2 h <= dt_out`: the delivered grid itself).
/// Its EVP is measured where the delivered run's own EVP is: on the estimate's coarser grid a
/// response with fast components (w_G) can read a difference 1.5 times larger or smaller
/// (`docs/amm.md` 12.10).
pub fn time_check_grid(problem: &Problem, h: f64) -> usize {
    time_check_grid_of(&Star::new(problem), h)
}

/// [`time_check_grid`] of the AMM's view of a problem.
pub(crate) fn time_check_grid_of(problem: &Star, h: f64) -> usize {
    output_multiple(problem, TIME_CHECK_STEP_FACTOR * h)
}

/// The smallest k >= 1 with `k problem.time.dt_out >= step` (to round-off): the output grid, a
/// subset of the delivered one, that a run at `step` [s] can fill.
fn output_multiple(problem: &Star, step: f64) -> usize {
    ((step / problem.time.dt_out) - 1e-9).ceil().max(1.0) as usize
}

/// Modes beyond the sleeve resolution `2 L / Lp` with which the automatic choice starts: at
/// `2 L / Lp + 6` the paper's cases are still 1.6-2.1 % off the FEM, at `+ 12` about 1 %
/// (`docs/amm.md` section 8), so a start below `+ 12` buys a run that no useful tolerance accepts.
pub const START_MARGIN: usize = 12;

/// First N of the automatic choice: the modes resolve the sleeve (`2 L / Lp`, the largest over
/// the beams, `docs/amm.md` 13, Eq. J8) plus [`START_MARGIN`], at least 8 and at most
/// [`MAX_AUTO_MODES`]. One N serves the three beams.
pub fn first_modes(problem: &Problem) -> usize {
    first_modes_of(&Star::new(problem))
}

/// [`first_modes`] of the AMM's view of a problem.
pub(crate) fn first_modes_of(problem: &Star) -> usize {
    let resolve = (0..3)
        .map(|i| (2.0 * problem.beam(i).l / problem.beam(i).lp).ceil())
        .fold(0.0f64, f64::max);
    let n = if resolve.is_finite() {
        resolve as usize
    } else {
        MAX_AUTO_MODES
    };
    (n + START_MARGIN).clamp(8, MAX_AUTO_MODES)
}

/// The N after `n` in the automatic sequence.
pub fn next_modes(n: usize) -> usize {
    ((n as f64 * GROWTH).ceil() as usize).max(n + 2).min(MAX_AUTO_MODES)
}

/// Estimated truncation EVP [%] of `fine` (N = `n_fine`) from the coarser run `coarse`
/// (N = `n_coarse`): the mean point EVP of `coarse` against `fine` divided by
/// `(n_fine / n_coarse)^RATE - 1` (see the module docs). `None` when no point has a reference.
pub fn truncation_estimate(coarse: &Response, fine: &Response, n_coarse: usize, n_fine: usize) -> Option<f64> {
    let richardson = (n_fine as f64 / n_coarse as f64).powf(RATE) - 1.0;
    mean_evp_of(coarse, fine).map(|d| d / richardson)
}

/// Modes the direct pair adds to the chosen N (`docs/amm.md` 12.18).
pub const DIRECT_PAIR_MODES: usize = 25;

/// N of the direct pair's second run for the chosen `n`: [`DIRECT_PAIR_MODES`] more, at most
/// [`MAX_AUTO_MODES`].
pub fn pair_modes(n: usize) -> usize {
    (n + DIRECT_PAIR_MODES).min(MAX_AUTO_MODES)
}

/// The truncation EVP [%] of the chosen N = `n` from the direct pair (`docs/amm.md` 12.18, Eq.
/// E1): the mean point EVP of its run `run` against the run `pair` at N = `n_pair` > n, both at
/// the time check's step on its grid, over `1 - (n / n_pair)^RATE`, the share of `e(n)` the
/// difference holds when the error falls like `N^-RATE`. `None` when no point has a reference or
/// `n_pair <= n`.
pub fn direct_truncation(run: &Response, pair: &Response, n: usize, n_pair: usize) -> Option<f64> {
    if n_pair <= n {
        return None;
    }
    let share = 1.0 - (n as f64 / n_pair as f64).powf(RATE);
    mean_evp_of(run, pair).map(|d| d / share)
}

/// The step a run of the automatic choice takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pass {
    /// A run of the estimate's pair: step [`ESTIMATE_STEP_FACTOR`] times the delivered one, on
    /// an output grid `every` times coarser (module docs).
    Estimate { every: usize },
    /// With friction in the sleeves, a run of the estimate's pair of the robot without it
    /// (`Star::without_friction`) at the step and on the grid of [`Pass::Estimate`]
    /// (`docs/amm.md` 12.16).
    BareEstimate { every: usize },
    /// The time check's run: step [`TIME_CHECK_STEP_FACTOR`] times the delivered one, on an
    /// output grid `every` times coarser ([`time_check_grid`]).
    TimeCheck { every: usize },
    /// A run at the delivered step and output grid.
    Deliver,
    /// With friction, a run at the delivered step halved `halvings` times, on the delivered
    /// output grid; it becomes the delivered run (`docs/amm.md` 12.15).
    Refined { halvings: u32 },
}

/// The estimate's pair at N_prev and N, found by raising N from [`first_modes`] at `pass` until
/// the estimate of the N-run is below `tol`: `(N, estimate, the N-run, wall time of all runs)`.
fn raise_until_below<F>(
    problem: &Star,
    tol: f64,
    pass: Pass,
    run: &mut F,
) -> Result<(usize, f64, Response, f64), AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let mut n = first_modes_of(problem);
    let mut prev = run(n, pass)?;
    let mut wall = prev.info.wall_s;
    let mut reached = f64::NAN;
    loop {
        let n_next = next_modes(n);
        if n_next == n {
            return Err(AmmError::invalid(
                "amm.tol",
                format!(
                    "the tolerance {tol} % is not reached with N = {MAX_AUTO_MODES} modes: the estimated truncation EVP there is {reached:.3} %; raise tol"
                ),
            ));
        }
        let next = run(n_next, pass)?;
        wall += next.info.wall_s;
        reached = truncation_estimate(&prev, &next, n, n_next).unwrap_or(0.0);
        if reached <= tol {
            return Ok((n_next, reached, next, wall));
        }
        n = n_next;
        prev = next;
    }
}

/// Raise N from [`first_modes`] until the estimate is below `tol` [%]; `run(n, pass)` solves at
/// N = n with the step of `pass`. With `every = Some(k)` the pairs run at the coarse step
/// ([`Pass::Estimate`], output grid k times coarser), then the chosen N at twice the delivered
/// step ([`Pass::TimeCheck`] on the grid `check_every`, [`time_check_grid`]; its difference gives the
/// time part, Eq. T1) and once at
/// the delivered step; if the coarse step's own time error, the EVP of the chosen N's two runs, is above
/// [`MAX_ESTIMATE_TIME_ERROR`], or with `every = None`, the pairs run at the delivered step.
/// With `every = None` (a span too short for the coarse grid) the time check follows the pairs:
/// the chosen N at 2 h after its delivered run (`docs/amm.md` 12.13), so that there the delivered
/// run is the last at the delivered step, not the last run. With friction and a time check, the
/// pairs are first the robot's without friction on the coarse grid `every`
/// ([`friction_with_bare_pairs`], `docs/amm.md` 12.16), then (that failing, or with `every =
/// None`) the robot's with friction at the time check's step, the chosen N's run of the pair the
/// time check ([`friction_pairs_at_check_step`], 12.15); at the delivered step only when both
/// fail. `check_every = None`: no time check (the direct problem's pairs, which
/// run at the delivered step only).
/// Returns the delivered run with `info.modes`, `info.error_estimate_percent` and
/// `info.tol_percent` set, its wall time the sum over the runs. Fails with the estimate reached
/// when the tolerance is not met at [`MAX_AUTO_MODES`].
pub(crate) fn solve_to_tolerance<F>(
    problem: &Star,
    tol: f64,
    every: Option<usize>,
    check_every: Option<usize>,
    mut run: F,
) -> Result<Response, AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let mut wall = 0.0;
    // the delivered run's time error from the time check at 2 h (Eq. T1)
    let mut time_part = None;
    if let (true, Some(k)) = (problem.friction.is_some(), check_every) {
        if let Some(every) = every {
            if let Some(done) = friction_with_bare_pairs(problem, tol, (every, k), &mut run, &mut wall)? {
                return Ok(done);
            }
        }
        if let Some(done) = friction_pairs_at_check_step(problem, tol, k, &mut run, &mut wall)? {
            return Ok(done);
        }
    }
    // with friction, what is left runs its pairs at the delivered step (docs/amm.md 12.15)
    if let Some(every) = every.filter(|_| problem.friction.is_none()) {
        let pass = Pass::Estimate { every };
        let (n, estimate, coarse, pair_wall) = raise_until_below(problem, tol, pass, &mut run)?;
        // the time check before the delivered run, so that the delivered run is the last one
        let check = check_every.map(|k| run(n, Pass::TimeCheck { every: k })).transpose()?;
        // the truncation part from the direct pair at the time check's step (docs/amm.md 12.18);
        // Richardson's on the coarse pairs where there is no time check or the pair's run fails
        // (none at the cap, where N + 25 would be N itself)
        let truncation = match (&check, check_every) {
            (Some(check), Some(k)) if pair_modes(n) > n => match run(pair_modes(n), Pass::TimeCheck { every: k }) {
                Ok(pair) => {
                    wall += pair.info.wall_s;
                    direct_truncation(check, &pair, n, pair_modes(n)).unwrap_or(estimate)
                }
                Err(_) => estimate,
            },
            _ => estimate,
        };
        let delivered = run(n, Pass::Deliver)?;
        wall += pair_wall + delivered.info.wall_s;
        let on_coarse_grid = delivered.every_nth(every);
        let time_error = mean_evp(&coarse, &on_coarse_grid);
        // (also the fallback's time part: its delivered run takes the same step h)
        if let (Some(check), Some(k)) = (check, check_every) {
            wall += check.info.wall_s;
            time_part = Some(time_check_part(&check, &delivered, k, time_check_ratio(problem)));
        }
        if time_error <= MAX_ESTIMATE_TIME_ERROR {
            return Ok(finish(
                problem,
                delivered,
                truncation + time_part.unwrap_or(0.0),
                tol,
                wall,
            ));
        }
    }
    let (n, estimate, mut delivered, pair_wall) = raise_until_below(problem, tol, Pass::Deliver, &mut run)?;
    wall += pair_wall;
    if let (None, Some(k)) = (time_part, check_every) {
        match run(n, Pass::TimeCheck { every: k }) {
            Ok(check) => {
                wall += check.info.wall_s;
                time_part = Some(time_check_part(&check, &delivered, k, time_check_ratio(problem)));
            }
            // with friction a run at 2 h may diverge where h holds (a coarse stick or slip):
            // the step is halved instead, the run at h the time check of the run at h / 2
            // (`refine_step`, docs/amm.md 12.15)
            Err(_) if problem.friction.is_some() => time_part = Some(f64::INFINITY),
            Err(e) => return Err(e),
        }
    }
    if problem.friction.is_some() {
        if let Some(part) = time_part.as_mut() {
            wall += refine_step(problem, tol, n, &mut run, (&mut delivered, part))?;
        }
    }
    Ok(finish(
        problem,
        delivered,
        estimate + time_part.unwrap_or(0.0),
        tol,
        wall,
    ))
}

/// With friction (`docs/amm.md` 12.16): the truncation part from the estimate's pairs of the
/// robot without friction at the coarse step on the grid `every` ([`Pass::BareEstimate`]), then
/// the chosen N with friction at the time check's step 2 h on its grid `check_every` (Eq. T2) and
/// at the delivered step h, and the step's halvings of [`refine_step`]. `None` (the runs' wall
/// time still added to `wall`) when a pair's run fails or the tolerance is not reached without
/// friction, or when the chosen N's runs at 2 h and h differ by more than
/// [`MAX_ESTIMATE_TIME_ERROR`]: the pairs then take the sleeves' friction
/// ([`friction_pairs_at_check_step`]).
fn friction_with_bare_pairs<F>(
    problem: &Star,
    tol: f64,
    (every, check_every): (usize, usize),
    run: &mut F,
    wall: &mut f64,
) -> Result<Option<Response>, AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let Ok((n, estimate, _, pair_wall)) = raise_until_below(problem, tol, Pass::BareEstimate { every }, run) else {
        return Ok(None);
    };
    *wall += pair_wall;
    // a run at 2 h that fails (rows that lose rank at a coarse event) sends the pairs on
    let Ok(check) = run(n, Pass::TimeCheck { every: check_every }) else {
        return Ok(None);
    };
    *wall += check.info.wall_s;
    deliver_with_friction(problem, tol, (n, estimate), (&check, check_every), run, wall)
}

/// With friction (`docs/amm.md` 12.15, "The pairs at the time check's step"): the estimate's pairs
/// at the time check's step 2 h on its grid `check_every` ([`Pass::TimeCheck`]), the chosen N's
/// run of the pair serving as the time check (Eq. T2), then the delivered run at h and the step's
/// halvings of [`refine_step`]. `None` (the runs' wall time still added to `wall`) when the
/// chosen N's runs at 2 h and h differ by more than [`MAX_ESTIMATE_TIME_ERROR`]: the pairs then
/// run at the delivered step.
fn friction_pairs_at_check_step<F>(
    problem: &Star,
    tol: f64,
    check_every: usize,
    run: &mut F,
    wall: &mut f64,
) -> Result<Option<Response>, AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let pass = Pass::TimeCheck { every: check_every };
    // a run at 2 h that fails (a divergence, rows that lose rank at a coarse event) sends the
    // pairs to the delivered step, as does a tolerance not reached there
    let Ok((n, estimate, check, pair_wall)) = raise_until_below(problem, tol, pass, run) else {
        return Ok(None);
    };
    *wall += pair_wall;
    deliver_with_friction(problem, tol, (n, estimate), (&check, check_every), run, wall)
}

/// With friction: the chosen N = `n` at the delivered step h after its time check `check` at 2 h
/// (on every `check_every`-th output time): the time part (Eq. T2), the step's halvings of
/// [`refine_step`], and the delivered run reported with `estimate` (the pairs' truncation) plus
/// that part. `None` (the runs' wall time still added to `wall`) when the runs at 2 h and h
/// differ by more than [`MAX_ESTIMATE_TIME_ERROR`].
fn deliver_with_friction<F>(
    problem: &Star,
    tol: f64,
    (n, estimate): (usize, f64),
    (check, check_every): (&Response, usize),
    run: &mut F,
    wall: &mut f64,
) -> Result<Option<Response>, AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let mut delivered = run(n, Pass::Deliver)?;
    *wall += delivered.info.wall_s;
    let e_check = mean_evp(check, &delivered.every_nth(check_every));
    if e_check > MAX_ESTIMATE_TIME_ERROR {
        return Ok(None);
    }
    let mut part = e_check / FRICTION_TIME_CHECK_RATIO;
    *wall += refine_step(problem, tol, n, run, (&mut delivered, &mut part))?;
    Ok(Some(finish(problem, delivered, estimate + part, tol, *wall)))
}

/// Eq. T1 [%] from the time check's run `check` (the chosen N at 2 h on every `check_every`-th
/// output time) and the `delivered` run at h: their mean EVP over `ratio` ([`TIME_CHECK_RATIO`],
/// with friction [`FRICTION_TIME_CHECK_RATIO`]).
fn time_check_part(check: &Response, delivered: &Response, check_every: usize, ratio: f64) -> f64 {
    mean_evp(check, &delivered.every_nth(check_every)) / ratio
}

/// With friction (`docs/amm.md` 12.15): while the time part `part` (Eq. T2) is above
/// [`FRICTION_TIME_SHARE`] of the tolerance `tol`, N = `n` runs again at half the step
/// ([`Pass::Refined`], at most [`MAX_FRICTION_HALVINGS`] times) and becomes the `delivered` run,
/// the run before it its time check at twice its step (on the finest grid that step fills).
/// Returns the wall time of the runs [s].
fn refine_step<F>(
    problem: &Star,
    tol: f64,
    n: usize,
    run: &mut F,
    (delivered, part): (&mut Response, &mut f64),
) -> Result<f64, AmmError>
where
    F: FnMut(usize, Pass) -> Result<Response, AmmError>,
{
    let mut wall = 0.0;
    let mut halvings = 0;
    while *part > FRICTION_TIME_SHARE * tol && halvings < MAX_FRICTION_HALVINGS {
        halvings += 1;
        let finer = run(n, Pass::Refined { halvings })?;
        wall += finer.info.wall_s;
        let every = output_multiple(problem, TIME_CHECK_STEP_FACTOR * finer.info.dt);
        *part = mean_evp(&delivered.every_nth(every), &finer.every_nth(every)) / FRICTION_TIME_CHECK_RATIO;
        *delivered = finer;
    }
    Ok(wall)
}

/// Mean EVP [%] (Eq. 45) of `run` against `reference` on the reference's times; `None` when the
/// times differ or no point has a reference.
fn mean_evp_of(run: &Response, reference: &Response) -> Option<f64> {
    point_evps(run, reference).ok().and_then(|e| e.mean)
}

/// [`mean_evp_of`], infinite where it has none (a difference that cannot be measured is taken
/// as too large).
fn mean_evp(run: &Response, reference: &Response) -> f64 {
    mean_evp_of(run, reference).unwrap_or(f64::INFINITY)
}

/// The delivered run with the automatic choice's report: `estimate` (truncation and time) plus
/// the geometric part of the delivered run ([`geometric_part`]). Under gravity the model's error
/// about the sag is not estimated but removed: the full model restores the terms that made it
/// (`docs/amm.md` 12.14, Eqs. V5-V6).
fn finish(problem: &Star, mut delivered: Response, estimate: f64, tol: f64, wall: f64) -> Response {
    let reported = estimate + geometric_part_of(problem, &delivered);
    delivered.info.error_estimate_percent = Some(reported);
    delivered.info.tol_percent = Some(tol);
    delivered.info.wall_s = wall;
    delivered
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::catalogue::paper_case;

    #[test]
    fn sequence_starts_at_the_sleeve_resolution_and_ends_at_the_cap() {
        // paper robot: 2 L / Lp = 2 * 0.5 / 0.03 = 33.3 -> 34 modes resolve the sleeve
        let exp = paper_case(1);
        let problem = exp.problem().unwrap();
        assert_eq!(first_modes(&problem), 34 + START_MARGIN);
        let mut n = first_modes(&problem);
        let mut steps = 0;
        while next_modes(n) != n {
            assert!(next_modes(n) > n);
            n = next_modes(n);
            steps += 1;
        }
        assert_eq!(n, MAX_AUTO_MODES);
        assert!(steps < 20, "{steps}");
    }

    /// A model response on `exp`'s grid (every `every`-th row): tips `(1 + e) sin(2 pi t)` with a
    /// truncation error e = 0.3 % (53 / N)^7 (so that N = 53 is the first whose estimate, exactly
    /// 0.3 % for a pure power law, is below 0.5 %) plus `time_error`.
    fn model(exp: &Star, every: usize, n: usize, time_error: f64) -> Response {
        let e = 0.003 * (53.0 / n as f64).powi(7) + time_error;
        let mut r = Response::with_capacity("model", 0);
        for t in exp.time.output_times() {
            let w = (1.0 + e) * (2.0 * std::f64::consts::PI * t / exp.time.t_end).sin();
            r.push(t, [w; 3], [w; 3], [0.0; 3]);
        }
        r.every_nth(every)
    }

    /// Paper case 3 with Coulomb friction `mu = 0.1` in the sleeves.
    fn case3_with_friction() -> Problem {
        let mut exp = paper_case(3);
        exp.friction = Some(toml::from_str("mu = 0.1\n").unwrap());
        exp.problem().unwrap()
    }

    /// [`model`] of the robot with friction: its truncation twice the frictionless one, plus
    /// `time_error`.
    fn rubbing(star: &Star, n: usize, every: usize, time_error: f64) -> Response {
        model(star, every, n, 0.003 * (53.0 / n as f64).powi(7) + time_error)
    }

    #[test]
    fn coarse_pairs_then_one_delivered_run_or_the_fallback_when_the_coarse_step_is_too_rough() {
        let exp = paper_case(3);
        let problem = exp.problem().unwrap();
        let exp = Star::new(&problem);
        let every = estimate_grid(&problem, 5e-4).expect("0.5 s at 1 ms outputs gives a coarse grid");
        assert_eq!(every, 4, "8 x 0.5 ms = 4 ms on a 1 ms output grid");
        // time error c (k h)^p, 2^p - 1 = TIME_CHECK_RATIO, c set by the coarse run's E(8 h, h)
        let order = (TIME_CHECK_RATIO + 1.0).log2();
        for (coarse_time_error, delivered_runs) in [(0.02, 1), (0.3, 3)] {
            let c = coarse_time_error / (8f64.powf(order) - 1.0);
            let mut passes = Vec::new();
            let r = solve_to_tolerance(&exp, 0.5, Some(every), Some(1), |n, pass| {
                passes.push((n, pass));
                Ok(match pass {
                    Pass::Estimate { every } => model(&exp, every, n, c * 8f64.powf(order)),
                    Pass::TimeCheck { every } => model(&exp, every, n, c * 2f64.powf(order)),
                    Pass::Deliver => model(&exp, 1, n, c),
                    Pass::Refined { .. } | Pass::BareEstimate { .. } => unreachable!("no friction"),
                })
            })
            .unwrap();
            let count = |want: fn(&Pass) -> bool| passes.iter().filter(|(_, p)| want(p)).count();
            // 2 % coarse time error: the pair (46, 53) coarse, 53 and the direct pair's 78 at
            // 2 h, 53 delivered; 30 %: the check fails and the pair runs again at the delivered
            // step (46, 53 delivered), whose truncation part is Richardson's on that pair
            assert_eq!(count(|p| *p == Pass::Deliver), delivered_runs, "{passes:?}");
            assert_eq!(count(|p| matches!(p, Pass::Estimate { .. })), 2);
            let at_check: Vec<usize> = passes
                .iter()
                .filter(|(_, p)| matches!(p, Pass::TimeCheck { .. }))
                .map(|(n, _)| *n)
                .collect();
            assert_eq!(at_check, [53, pair_modes(53)], "{passes:?}");
            assert_eq!(
                passes.last().map(|p| p.1),
                Some(Pass::Deliver),
                "the delivered run is the last"
            );
            assert_eq!(r.len(), exp.time.output_times().len());
            // Richardson and the direct pair (Eq. E1) are exact for the power law: 0.3 % (to the
            // EVP's trapezoidal rule), plus the time part, the delivered run's own time error c
            // (Eq. T1), plus Eq. G1
            let est = r.info.error_estimate_percent.unwrap() - geometric_part(&problem, &r);
            let time_part = 100.0 * c;
            assert!(
                (est - 0.3 - time_part).abs() < 0.01 + 0.02 * time_part,
                "{est} {time_part}"
            );
        }
        // too short a span for 20 coarse rows: pairs at the delivered step
        let mut short = paper_case(3);
        short.time.t_end = 0.05;
        let problem = short.problem().unwrap();
        assert_eq!(estimate_grid(&problem, 5e-4), None);
    }

    /// The truncation part from the direct pair at the time check's step (`docs/amm.md` 12.18,
    /// Eq. E1): where the error falls faster than `RATE` says, `e(N) = 0.3 % (53 / N)^10`,
    /// Richardson on the coarse pair (46, 53), then (53, 61), chooses N = 61 and reads its
    /// truncation 0.0734 % as 0.135 %; the pair (61, 86) at 2 h reads `(e(61) - e(86)) /
    /// (1 - (61 / 86)^7)` = 0.078 %. When the pair's run fails, Richardson's part stands.
    #[test]
    fn the_truncation_part_comes_from_the_direct_pair_at_the_time_checks_step() {
        let problem = paper_case(3).problem().unwrap();
        let exp = Star::new(&problem);
        let every = estimate_grid(&problem, 5e-4).unwrap();
        // model() adds 0.3 % (53 / N)^7; the extra error turns it into 0.3 % (53 / N)^10
        let faster = |n: usize, every: usize| {
            let r = 53.0 / n as f64;
            model(&exp, every, n, 0.003 * (r.powi(10) - r.powi(7)))
        };
        for pair_fails in [false, true] {
            let mut passes = Vec::new();
            let r = solve_to_tolerance(&exp, 0.5, Some(every), Some(1), |n, pass| {
                passes.push((n, pass));
                match pass {
                    Pass::TimeCheck { .. } if pair_fails && n == pair_modes(61) => {
                        Err(AmmError::NonFinite { t: 0.1, dt: 1e-3 })
                    }
                    Pass::Estimate { every } | Pass::TimeCheck { every } => Ok(faster(n, every)),
                    Pass::Deliver => Ok(faster(n, 1)),
                    Pass::Refined { .. } | Pass::BareEstimate { .. } => unreachable!("no friction"),
                }
            })
            .unwrap();
            assert_eq!(passes.last(), Some(&(61, Pass::Deliver)), "{passes:?}");
            let est = r.info.error_estimate_percent.unwrap() - geometric_part(&problem, &r);
            let e = |n: f64| 0.3 * (53.0 / n).powi(10);
            let (richardson, direct) = (
                (e(53.0) - e(61.0)) / ((61.0f64 / 53.0).powf(RATE) - 1.0),
                (e(61.0) - e(86.0)) / (1.0 - (61.0f64 / 86.0).powf(RATE)),
            );
            let want = if pair_fails { richardson } else { direct };
            assert!(
                (est - want).abs() < 0.005,
                "{est} against {want} (pair fails: {pair_fails})"
            );
            assert!((direct - e(61.0)).abs() < 0.1 * e(61.0) && richardson > 1.5 * e(61.0));
        }
    }

    /// With friction and no coarse grid (`docs/amm.md` 12.15) the pairs run at the time check's
    /// step 2 h, the chosen N's run of the pair the time check, and the step halves while the time part (Eq. T2) is above half the tolerance, each
    /// halving's run the delivered one and the run before it its time check. A model with a time
    /// error of first order, `c h / h0` (c = 1 %): T2 reads 1 / 1.75 = 0.57 % at h0, 0.29 % at
    /// h0 / 2, 0.14 % at h0 / 4, so the step halves twice.
    #[test]
    fn with_friction_the_step_halves_until_the_time_part_is_below_half_the_tolerance() {
        let mut exp = paper_case(3);
        exp.friction = Some(toml::from_str("mu = 0.1\n").unwrap());
        let problem = exp.problem().unwrap();
        let star = Star::new(&problem);
        // the coarse grid is the frictionless pairs' (docs/amm.md 12.16); without it, as on a
        // span too short for it, the pairs take the friction
        assert_eq!(estimate_grid(&problem, 5e-4), Some(4));
        let c = 0.01;
        let mut passes = Vec::new();
        let r = solve_to_tolerance(&star, 0.5, None, Some(1), |n, pass| {
            passes.push(pass);
            Ok(match pass {
                Pass::TimeCheck { every } => model(&star, every, n, 2.0 * c),
                Pass::Deliver => model(&star, 1, n, c),
                Pass::Refined { halvings } => model(&star, 1, n, c / f64::from(1u32 << halvings)),
                Pass::Estimate { .. } | Pass::BareEstimate { .. } => unreachable!("no coarse grid"),
            })
        })
        .unwrap();
        let refined: Vec<Pass> = passes
            .iter()
            .copied()
            .filter(|p| matches!(p, Pass::Refined { .. }))
            .collect();
        assert_eq!(
            refined,
            [Pass::Refined { halvings: 1 }, Pass::Refined { halvings: 2 }],
            "{passes:?}"
        );
        assert_eq!(passes.last(), Some(&Pass::Refined { halvings: 2 }));
        // the estimate: the truncation (0.3 %, exact for the power law) plus the last time part,
        // E(h0 / 2, h0 / 4) / 1.75 = 100 (c / 2 - c / 4) / 1.75 %, plus Eq. G1
        let time_part = 100.0 * (c / 2.0 - c / 4.0) / FRICTION_TIME_CHECK_RATIO;
        let est = r.info.error_estimate_percent.unwrap() - geometric_part(&problem, &r);
        assert!(
            (est - 0.3 - time_part).abs() < 0.01,
            "{est} against {}",
            0.3 + time_part
        );
    }

    /// With friction and a coarse grid (`docs/amm.md` 12.16) the pairs are the frictionless
    /// robot's at the coarse step, then the chosen N runs with friction at 2 h and at h; the
    /// estimate is their truncation plus Eq. T2. When a frictionless pair's run fails, or the
    /// chosen N's runs at 2 h and h differ by more than `MAX_ESTIMATE_TIME_ERROR`, the pairs
    /// take the friction at 2 h (12.15) and the estimate is theirs.
    #[test]
    fn with_friction_the_truncation_comes_from_the_frictionless_pairs_at_the_coarse_step() {
        let problem = case3_with_friction();
        let star = Star::new(&problem);
        let every = estimate_grid(&problem, 5e-4).unwrap();
        // the frictionless robot's truncation 0.3 % (53 / N)^7 (its pairs at the coarse step with
        // no time error of their own) and the friction run's twice it: the pairs with friction
        // then go on to N = 61; a time error of 0.1 % at h
        let c = 0.001;
        let bare_model = |n: usize, every: usize| model(&star, every, n, 0.0);
        let rubbing = |n: usize, every: usize, time_error: f64| rubbing(&star, n, every, time_error);
        for (bare_fails, check_error, pairs) in [
            (false, 4.0 * c, "bare"),
            (true, 4.0 * c, "rubbing"),
            (false, 0.3, "rubbing"),
        ] {
            let mut passes = Vec::new();
            let r = solve_to_tolerance(&star, 0.5, Some(every), Some(1), |n, pass| {
                passes.push((n, pass));
                match pass {
                    Pass::BareEstimate { .. } if bare_fails && n > 46 => Err(AmmError::NonFinite { t: 0.1, dt: 4e-3 }),
                    Pass::BareEstimate { every } => Ok(bare_model(n, every)),
                    Pass::TimeCheck { every } => Ok(rubbing(n, every, check_error)),
                    Pass::Deliver => Ok(rubbing(n, 1, c)),
                    Pass::Refined { halvings } => Ok(rubbing(n, 1, c / f64::from(1u32 << halvings))),
                    Pass::Estimate { .. } => unreachable!("with friction the coarse pairs are frictionless"),
                }
            })
            .unwrap();
            let count = |want: fn(&Pass) -> bool| passes.iter().filter(|(_, p)| want(p)).count();
            let est = r.info.error_estimate_percent.unwrap() - geometric_part(&problem, &r);
            let last_at_h = passes
                .iter()
                .rev()
                .find(|(_, p)| matches!(p, Pass::Deliver | Pass::Refined { .. }));
            if pairs == "bare" {
                assert_eq!(count(|p| matches!(p, Pass::BareEstimate { .. })), 2, "{passes:?}");
                assert_eq!(count(|p| matches!(p, Pass::TimeCheck { .. })), 1, "{passes:?}");
                assert_eq!(count(|p| *p == Pass::Deliver), 1, "{passes:?}");
                // the frictionless pair's truncation, exact for the power law, and Eq. T2
                let time_part = 100.0 * (check_error - c) / FRICTION_TIME_CHECK_RATIO;
                assert!((est - 0.3 - time_part).abs() < 0.01, "{est}");
            } else {
                // the pairs with friction (at 2 h, or at h after a time check too far off), whose
                // truncation reaches the tolerance at N = 61 only
                assert_eq!(last_at_h.map(|p| p.0), Some(61), "{passes:?}");
            }
        }
    }

    /// With friction, a time check at 2 h that fails on the last path (the pairs at h) halves the
    /// step instead of stopping the run (`docs/amm.md` 12.15, "A time check that fails"): the run
    /// at h is the time check of the delivered run at h / 2, and its time part is Eq. T2 on that
    /// pair. Without friction the failure still stops the run.
    #[test]
    fn with_friction_a_failing_time_check_halves_the_step() {
        let problem = case3_with_friction();
        let star = Star::new(&problem);
        let every = estimate_grid(&problem, 5e-4).unwrap();
        let c = 0.001;
        let rubbing = |n: usize, every: usize, time_error: f64| rubbing(&star, n, every, time_error);
        let fails = || AmmError::NonFinite { t: 0.3, dt: 1e-3 };
        let mut passes = Vec::new();
        let r = solve_to_tolerance(&star, 0.5, Some(every), Some(1), |n, pass| {
            passes.push((n, pass));
            match pass {
                Pass::BareEstimate { every } => Ok(model(&star, every, n, 0.0)),
                Pass::TimeCheck { .. } => Err(fails()),
                Pass::Deliver => Ok(rubbing(n, 1, c)),
                Pass::Refined { halvings } => Ok(rubbing(n, 1, c / f64::from(1u32 << halvings))),
                Pass::Estimate { .. } => unreachable!("with friction the coarse pairs are frictionless"),
            }
        })
        .unwrap();
        let last = passes.last().unwrap();
        assert_eq!(last.1, Pass::Refined { halvings: 1 }, "{passes:?}");
        // the truncation of the pairs at h plus Eq. T2 on the runs at h and h / 2
        let est = r.info.error_estimate_percent.unwrap() - geometric_part(&problem, &r);
        let time_part = 100.0 * (c - c / 2.0) / FRICTION_TIME_CHECK_RATIO;
        assert!(
            est > time_part && est < time_part + 0.5,
            "{est} against the time part {time_part}"
        );
        // without friction the failing time check stops the run
        let bare_problem = paper_case(3).problem().unwrap();
        let bare = Star::new(&bare_problem);
        let stopped = solve_to_tolerance(&bare, 0.5, None, Some(1), |n, pass| match pass {
            Pass::TimeCheck { .. } => Err(fails()),
            _ => Ok(model(&bare, 1, n, 0.003 * (53.0 / n as f64).powi(7))),
        });
        assert!(stopped.is_err());
    }
}
