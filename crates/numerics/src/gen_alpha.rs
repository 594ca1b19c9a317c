//! Coefficients of the generalized-alpha method (Chung & Hulbert 1993, J. Appl. Mech. 60:371),
//! in the form used for constrained mechanical systems by Arnold & Bruls (2007, Multibody Syst.
//! Dyn. 18:185): with the acceleration-like variable `a`,
//!
//! ```text
//! q_{n+1}  = q_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
//! v_{n+1}  = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
//! (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n
//! ```
//! where `qdd` is the true acceleration that satisfies the equations of motion at t_{n+1}.

/// Generalized-alpha parameters for a given spectral radius at infinity `rho_inf`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenAlpha {
    pub rho_inf: f64,
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl GenAlpha {
    /// Second-order accurate, unconditionally stable parameters with high-frequency dissipation
    /// set by `rho_inf` in [0, 1] (1: no dissipation, trapezoidal rule; 0: asymptotic annihilation).
    pub fn new(rho_inf: f64) -> Self {
        let r = rho_inf.clamp(0.0, 1.0);
        let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
        let alpha_f = r / (r + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        GenAlpha {
            rho_inf: r,
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }

    /// Predictor of one unknown over a step h (Arnold & Bruls 2007), from its position `q`,
    /// velocity `v`, pseudo-acceleration `a` and acceleration `qdd` at the start of the step:
    /// returns `(a_part, qhat, vhat)` with `a_part = (alpha_f qdd - alpha_m a) / (1 - alpha_m)`,
    /// `qhat = q + h v + h^2 ((1/2 - beta) a + beta a_part)`, `vhat = v + h ((1 - gamma) a + gamma a_part)`;
    /// the step then sets `q = qhat + beta' qdd_new`, `v = vhat + gamma' qdd_new`,
    /// `a = a_part + a_per_qdd qdd_new`.
    #[inline]
    pub fn predict(&self, h: f64, q: f64, v: f64, a: f64, qdd: f64) -> (f64, f64, f64) {
        let a_part = (self.alpha_f * qdd - self.alpha_m * a) * (1.0 / (1.0 - self.alpha_m));
        let qhat = q + h * v + h * h * ((0.5 - self.beta) * a + self.beta * a_part);
        let vhat = v + h * ((1.0 - self.gamma) * a + self.gamma * a_part);
        (a_part, qhat, vhat)
    }

    /// `d a_{n+1} / d qdd_{n+1}` = (1 - alpha_f) / (1 - alpha_m).
    pub fn a_per_qdd(&self) -> f64 {
        (1.0 - self.alpha_f) / (1.0 - self.alpha_m)
    }

    /// `d q_{n+1} / d qdd_{n+1}` for step h: `beta' = h^2 beta (1 - alpha_f) / (1 - alpha_m)`.
    pub fn beta_prime(&self, h: f64) -> f64 {
        h * h * self.beta * self.a_per_qdd()
    }

    /// `d v_{n+1} / d qdd_{n+1}` for step h: `gamma' = h gamma (1 - alpha_f) / (1 - alpha_m)`.
    pub fn gamma_prime(&self, h: f64) -> f64 {
        h * self.gamma * self.a_per_qdd()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_one_is_trapezoidal_rule() {
        // rho_inf = 1: alpha_m = alpha_f = 1/2, gamma = 1/2, beta = 1/4 (average acceleration).
        let g = GenAlpha::new(1.0);
        assert!((g.alpha_m - 0.5).abs() < 1e-15 && (g.alpha_f - 0.5).abs() < 1e-15);
        assert!((g.gamma - 0.5).abs() < 1e-15 && (g.beta - 0.25).abs() < 1e-15);
    }

    #[test]
    fn free_oscillator_is_second_order() {
        // q'' + q = 0, q(0) = 1: compare with cos t at t = 1 for two steps; error ratio ~ 4.
        let err = |n: usize| {
            let g = GenAlpha::new(0.8);
            let h = 1.0 / n as f64;
            let (mut q, mut v, mut qdd) = (1.0f64, 0.0f64, -1.0f64);
            let mut a = qdd;
            for _ in 0..n {
                // solve q_{n+1} + qdd_{n+1} = 0 with q_{n+1} = qp + beta' qdd_{n+1}
                let a_part = (g.alpha_f * qdd - g.alpha_m * a) / (1.0 - g.alpha_m);
                let qp = q + h * v + h * h * ((0.5 - g.beta) * a + g.beta * a_part);
                let vp = v + h * ((1.0 - g.gamma) * a + g.gamma * a_part);
                let qdd1 = -qp / (1.0 + g.beta_prime(h));
                q = qp + g.beta_prime(h) * qdd1;
                v = vp + g.gamma_prime(h) * qdd1;
                a = a_part + g.a_per_qdd() * qdd1;
                qdd = qdd1;
            }
            (q - 1f64.cos()).abs()
        };
        let ratio = err(100) / err(200);
        assert!((ratio - 4.0).abs() < 0.3, "ratio {ratio}");
    }
}
