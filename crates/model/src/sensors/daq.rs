//! The data acquisition of the sensors (`docs/sensors.md` section 6): a causal 4th-order
//! Butterworth anti-aliasing filter (Eqs. S11, S12), sampling on one clock, white noise (Eq. S13).

use super::table::SensorTable;
use super::Sensors;

/// One biquad section `y = (b0 x + b1 x1 + b2 x2) - a1 y1 - a2 y2` (direct form I).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

/// The quality factors of the two pole pairs of a 4th-order Butterworth filter:
/// `1 / (2 cos(pi/8))` and `1 / (2 cos(3 pi/8))`.
const BUTTERWORTH_Q: [f64; 2] = [0.541_196_100_146_197, 1.306_562_964_876_376_5];

/// The two sections of Eq. S11 for the -3 dB frequency `fc` [Hz] at the step `dt` [s] (the
/// bilinear transform prewarped at `fc`).
fn butterworth(fc: f64, dt: f64) -> [Biquad; 2] {
    let k = (std::f64::consts::PI * fc * dt).tan();
    let k2 = k * k;
    BUTTERWORTH_Q.map(|q| {
        let a0 = 1.0 + k / q + k2;
        Biquad {
            b: [k2 / a0, 2.0 * k2 / a0, k2 / a0],
            a: [2.0 * (k2 - 1.0) / a0, (1.0 - k / q + k2) / a0],
        }
    })
}

/// Eq. S12: the gain of the discrete filter of [`lowpass`] at the frequency `f` [Hz] below the
/// Nyquist frequency `1 / (2 dt)`.
pub fn lowpass_gain(f: f64, fc: f64, dt: f64) -> f64 {
    let r = (std::f64::consts::PI * f * dt).tan() / (std::f64::consts::PI * fc * dt).tan();
    1.0 / (1.0 + r.powi(8)).sqrt()
}

/// The 4th-order Butterworth low-pass of Eq. S11 with -3 dB frequency `fc` [Hz], applied
/// forward only (causal, as a DAQ's analog filter) to `x` sampled at the times `t` [s]; each
/// step's sections are those of its own length (the last output step may be shorter). The
/// filter starts in its steady state for `x[0]` (unit gain at zero frequency).
pub fn lowpass(t: &[f64], x: &[f64], fc: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    if x.len() < 2 {
        return y;
    }
    for stage in 0..2 {
        let input = y.clone();
        // steady state for a constant input: every past value equals the first
        let (mut x1, mut x2, mut y1, mut y2) = (input[0], input[0], input[0], input[0]);
        let mut sections = butterworth(fc, t[1] - t[0]);
        let mut h_prev = t[1] - t[0];
        for k in 1..input.len() {
            let h = t[k] - t[k - 1];
            if (h - h_prev).abs() > 1e-9 * h_prev {
                sections = butterworth(fc, h);
                h_prev = h;
            }
            let s = sections[stage];
            let out = s.b[0] * input[k] + s.b[1] * x1 + s.b[2] * x2 - s.a[0] * y1 - s.a[1] * y2;
            (x2, x1, y2, y1) = (x1, input[k], y1, out);
            y[k] = out;
        }
    }
    y
}

/// The sampling times `k / rate` [s], k = 0, 1, ..., up to `t_end` (within 1e-9 of a sample).
pub fn sample_times(rate_hz: f64, t_end: f64) -> Vec<f64> {
    let n = (t_end * rate_hz * (1.0 + 1e-12) + 1e-9).floor() as usize;
    (0..=n).map(|k| k as f64 / rate_hz).collect()
}

/// `y` at the times `at`, interpolated linearly between the times `t` (increasing; `at` within
/// them).
pub fn interpolate(t: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let mut j = 0;
    at.iter()
        .map(|&s| {
            while j + 2 < t.len() && t[j + 1] < s {
                j += 1;
            }
            if t.len() < 2 {
                return y[0];
            }
            let (t0, t1) = (t[j], t[j + 1]);
            let w = ((s - t0) / (t1 - t0)).clamp(0.0, 1.0);
            y[j] + w * (y[j + 1] - y[j])
        })
        .collect()
}

/// A SplitMix64 stream (Steele, Lea & Flood 2014) with standard normal draws by Box-Muller:
/// the noise of Eq. S13, reproducible from its seed.
#[derive(Debug, Clone)]
pub struct Normal {
    state: u64,
    spare: Option<f64>,
}

impl Normal {
    /// The stream of `seed` for the channel `channel` (its column's position among the sensors').
    pub fn new(seed: u64, channel: u64) -> Self {
        let mut n = Normal {
            state: seed ^ channel.wrapping_mul(0xD1B5_4A32_D192_ED03),
            spare: None,
        };
        n.next_u64();
        n
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform draw in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// A standard normal draw.
    pub fn draw(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

impl Sensors {
    /// What the data acquisition records from the readings `raw` at the output times
    /// (`docs/sensors.md` section 6): each channel filtered (Eq. S11, when its sensor has
    /// `lowpass_hz`), sampled at `k / rate_hz` up to `t_end` [s] (the output times without a
    /// rate) and its noise added (Eq. S13).
    pub fn acquire(&self, raw: &SensorTable, t_end: f64) -> SensorTable {
        self.acquire_with(raw, t_end, true)
    }

    /// The derivative of what the data acquisition records, from the derivatives `raw` of the
    /// readings at the output times along a parameter: the filter and the sampling are linear,
    /// the noise does not move with the parameter, so [`Sensors::acquire`] without the noise.
    pub fn acquire_derivative(&self, raw: &SensorTable, t_end: f64) -> SensorTable {
        self.acquire_with(raw, t_end, false)
    }

    /// [`Sensors::acquire`], the noise added when `noise`.
    fn acquire_with(&self, raw: &SensorTable, t_end: f64, noise: bool) -> SensorTable {
        let t = match self.rate_hz() {
            Some(rate) => sample_times(rate, t_end),
            None => raw.t.clone(),
        };
        let mut out = SensorTable::new(t.clone());
        let mut channel = 0u64;
        for s in self.list() {
            for (axis, name) in s.columns().into_iter().enumerate() {
                let x = raw.column(&name).unwrap_or_default();
                let filtered = match s.daq.lowpass_hz {
                    Some(fc) => lowpass(&raw.t, x, fc),
                    None => x.to_vec(),
                };
                let mut y = match self.rate_hz() {
                    Some(_) => interpolate(&raw.t, &filtered, &t),
                    None => filtered,
                };
                let sigma = s.daq.noise[axis];
                if noise && sigma > 0.0 {
                    let mut n = Normal::new(s.daq.seed, channel);
                    y.iter_mut().for_each(|v| *v += sigma * n.draw());
                }
                out.push_column(name, s.unit(), y);
                channel += 1;
            }
        }
        out
    }
}
