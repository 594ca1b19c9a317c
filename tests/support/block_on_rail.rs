//! A block on a rail with Coulomb friction pushed by a force pulse, in closed form
//! (`docs/friction.md` 4): the reference of both solvers' direct problem with rail friction
//! (`crates/fem/tests/friction.rs`, `crates/amm/tests/friction.rs`).

/// A force pulse on slider 1, `F0 sin(pi t / T)` [N] for `t < T`, zero after; nothing on the
/// other two.
pub struct Pulse {
    pub f0: f64,
    pub t_pulse: f64,
}

impl Pulse {
    fn at(&self, t: f64) -> f64 {
        if t < self.t_pulse {
            self.f0 * (std::f64::consts::PI * t / self.t_pulse).sin()
        } else {
            0.0
        }
    }
}

impl flexstar_drive::ActuatorLaw for Pulse {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], flexstar_drive::DriveError> {
        Ok([self.at(t), 0.0, 0.0])
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// The block on a rail with Coulomb friction `Fc` under [`Pulse`], in closed form: stuck until
/// `F0 sin(pi t / T) = Fc` at `t1`, then `m x'' = F(t) - Fc` while it slides, stuck again at
/// `t2` where its speed returns to zero (`F < Fc` there). Returns `t1`, `t2` [s] and the travel
/// `x(t2)` [m] (`t2` by bisection on the closed-form speed).
pub fn block_on_rail(m: f64, fc: f64, p: &Pulse) -> (f64, f64, f64) {
    use std::f64::consts::PI;
    let (f0, tp) = (p.f0, p.t_pulse);
    let t1 = tp / PI * (fc / f0).asin();
    let c1 = (PI * t1 / tp).cos();
    // speed and travel while the pulse lasts, then under Fc alone
    let v_in = |t: f64| (f0 * tp / PI * (c1 - (PI * t / tp).cos()) - fc * (t - t1)) / m;
    let x_in = |t: f64| {
        (f0 * tp / PI * (c1 * (t - t1) - tp / PI * ((PI * t / tp).sin() - (PI * t1 / tp).sin()))
            - 0.5 * fc * (t - t1).powi(2))
            / m
    };
    let v = |t: f64| if t <= tp { v_in(t) } else { v_in(tp) - fc / m * (t - tp) };
    let x = |t: f64| {
        if t <= tp {
            x_in(t)
        } else {
            x_in(tp) + v_in(tp) * (t - tp) - 0.5 * fc / m * (t - tp).powi(2)
        }
    };
    // the speed rises, then falls to zero once: bisect on its sign after its peak (t = tp - t1)
    let (mut lo, mut hi) = (tp - t1, tp + v_in(tp).max(0.0) * m / fc + 1e-9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if v(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    (t1, lo, x(lo))
}
