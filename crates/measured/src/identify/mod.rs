//! Model-free identification of a measured free decay (`docs/measured.md` section 3): the
//! natural frequencies and damping ratios of the modes in a multi-channel record after the
//! motion's rest, with their standard uncertainties.
//!
//! The steps, each in its own module: the window and its checks ([`window`], 3.1, 3.5), the
//! eigensystem realization algorithm at a range of orders ([`era`], Eqs. I3-I5), the stabilisation
//! diagram that tells modes from computational poles ([`stabilise`], 3.3, Eq. I7), and the
//! maximum likelihood fit that gives the estimates and their covariance ([`refine`], Eqs. I6,
//! I8-I11; [`pole`], Eqs. I2, I12).

mod era;
mod pole;
mod refine;
mod stabilise;
mod window;

use faer::c64;

use crate::error::MeasuredError;

/// What [`identify_free_decay`] looks for (`docs/measured.md` 3.5). `Default` gives the
/// documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifyOptions {
    /// Start of the free-decay window [s] (default: the record's first time): `t_rest` plus a
    /// skip (3.1).
    pub t_start: Option<f64>,
    /// End of the window [s] (default: the record's last time).
    pub t_end: Option<f64>,
    /// The band `[f_min, f_max]` [Hz] of the modes reported (default `[0, fs / 5]`, fs the
    /// sampling rate); it also sets the ERA's stride (3.2).
    pub band_hz: Option<[f64; 2]>,
    /// At most this many modes are reported, the lowest in the band (default 6).
    pub max_modes: usize,
    /// ERA orders (state dimensions) `[lo, hi]`, the even ones realised (default `[4, 40]`).
    pub orders: [usize; 2],
    /// Candidates with a damping ratio at or above this are rejected (default 0.3).
    pub zeta_max: f64,
    /// A mode must be stable at this share of the orders or more (default 0.3).
    pub min_stable_fraction: f64,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            t_start: None,
            t_end: None,
            band_hz: None,
            max_modes: 6,
            orders: [4, 40],
            zeta_max: 0.3,
            min_stable_fraction: 0.3,
        }
    }
}

/// The default band's top as a share of the sampling rate (3.5).
pub const DEFAULT_BAND_TOP: f64 = 0.2;

impl IdentifyOptions {
    /// Refuse options out of range (3.5), naming the option.
    fn check(&self) -> Result<(), MeasuredError> {
        if self.max_modes == 0 {
            return Err(MeasuredError::input("max_modes", "must be at least 1"));
        }
        let [lo, hi] = self.orders;
        if lo < 2 || hi < lo + 2 || hi > 400 {
            return Err(MeasuredError::input(
                "orders",
                format!("[{lo}, {hi}] must satisfy 2 <= lo and lo + 2 <= hi <= 400 (two even orders at least)"),
            ));
        }
        if !(self.zeta_max > 0.0 && self.zeta_max <= 1.0) {
            return Err(MeasuredError::input(
                "zeta_max",
                format!("must lie in (0, 1], got {}", self.zeta_max),
            ));
        }
        if !(self.min_stable_fraction > 0.0 && self.min_stable_fraction <= 1.0) {
            return Err(MeasuredError::input(
                "min_stable_fraction",
                format!("must lie in (0, 1], got {}", self.min_stable_fraction),
            ));
        }
        Ok(())
    }

    /// The band [Hz] at the sampling interval `dt` [s]: as given, checked within `[0, fs / 2)`,
    /// or the default.
    fn band(&self, dt: f64) -> Result<[f64; 2], MeasuredError> {
        let fs = 1.0 / dt;
        let Some([lo, hi]) = self.band_hz else {
            return Ok([0.0, DEFAULT_BAND_TOP * fs]);
        };
        if !(lo >= 0.0 && hi > lo && hi < 0.5 * fs) {
            return Err(MeasuredError::input(
                "band_hz",
                format!(
                    "[{lo}, {hi}] Hz must satisfy 0 <= f_min < f_max < fs / 2 = {} Hz",
                    0.5 * fs
                ),
            ));
        }
        Ok([lo, hi])
    }
}

/// One identified mode (`docs/measured.md` Eqs. I1, I2, I12).
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifiedMode {
    /// Undamped natural frequency [Hz], `|s| / (2 pi)` (Eq. I2).
    pub f_hz: f64,
    /// Damping ratio [-], `-Re(s) / |s|` (Eq. I2).
    pub zeta: f64,
    /// Standard uncertainty (1 sigma) of `f_hz` [Hz] from the noise (Eqs. I10-I12).
    pub f_std_hz: f64,
    /// Standard uncertainty (1 sigma) of `zeta` [-] from the noise (Eqs. I10-I12).
    pub zeta_std: f64,
    /// Amplitude `|a_c|` of the mode in each channel at the window's start, in the channel's
    /// unit (Eq. I1: the channel reads `Re(a_c exp(s t))`).
    pub amplitude: Vec<f64>,
    /// Phase `arg(a_c)` [rad] of the mode in each channel at the window's start.
    pub phase_rad: Vec<f64>,
    /// The number of ERA orders at which the mode was stable (3.3).
    pub stable_orders: usize,
}

/// The modes of the free decay in `channels` (each sampled at the times `t` [s], uniform; any
/// unit per channel), ascending in frequency: at most `opts.max_modes`, the lowest within the
/// band (`docs/measured.md` section 3). The window is `[opts.t_start, opts.t_end]`; ERA at the
/// orders of `opts.orders` finds the modes, the maximum likelihood fit of Eq. I1 gives the
/// estimates and their standard uncertainties.
///
/// Errors (never a panic): a channel of another length than `t`, non-finite or non-uniform
/// times, a non-finite sample or a constant channel in the window, too short a window for the
/// orders, options out of range, and a record in which no mode is found.
pub fn identify_free_decay(
    t: &[f64],
    channels: &[&[f64]],
    opts: &IdentifyOptions,
) -> Result<Vec<IdentifiedMode>, MeasuredError> {
    opts.check()?;
    let window = window::select(t, channels, opts)?;
    let band = opts.band(window.dt)?;
    let plan = era::Plan::new(window.len(), window.y.len(), window.dt, band[1], opts.orders)?;
    let diagram = era::realise(&normalised(&window), window.dt, &plan)?;
    let starts = stabilise::modes(&diagram, opts.zeta_max, opts.min_stable_fraction);
    if starts.is_empty() {
        return Err(MeasuredError::NotFound(format!(
            "no mode is stable over the orders {:?} in the window from t = {} s ({} samples)",
            diagram.orders,
            window.t0,
            window.len()
        )));
    }
    let limits = refine::Limits {
        zeta_max: opts.zeta_max,
        f_max_hz: era::ALIAS_GUARD * plan.nyquist_hz(window.dt),
    };
    let fitted = refine::fit(&window, &starts, limits)?;
    Ok(report(&fitted, band, opts.max_modes))
}

/// The channels over the window divided by their RMS about the mean: the ERA's weights (3.4).
fn normalised(window: &window::Window) -> Vec<Vec<f64>> {
    window
        .y
        .iter()
        .zip(window.rms())
        .map(|(y, rms)| y.iter().map(|v| v / rms).collect())
        .collect()
}

/// The fitted modes within `band` [Hz], ascending, at most `max_modes` of them.
fn report(fitted: &[refine::Fitted], band: [f64; 2], max_modes: usize) -> Vec<IdentifiedMode> {
    let mut modes: Vec<IdentifiedMode> = fitted
        .iter()
        .map(|m| {
            let (f_std_hz, zeta_std) = pole::standard_deviations(m.s, m.cov);
            IdentifiedMode {
                f_hz: pole::frequency_hz(m.s),
                zeta: pole::damping_ratio(m.s),
                f_std_hz,
                zeta_std,
                amplitude: m.amplitude.iter().map(|a: &c64| a.norm()).collect(),
                phase_rad: m.amplitude.iter().map(|a: &c64| a.arg()).collect(),
                stable_orders: m.stable_orders,
            }
        })
        .filter(|m| m.f_hz >= band[0] && m.f_hz <= band[1])
        .collect();
    modes.sort_by(|a, b| a.f_hz.total_cmp(&b.f_hz));
    modes.truncate(max_modes);
    modes
}
