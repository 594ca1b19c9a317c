//! The beams' third-order terms about the sag under gravity (`docs/amm.md` 12.14, Eqs. V1, V4-V6):
//! the inextensible beam's exact curvature and the foreshortening's own inertia.
//!
//! On beam i with transverse displacement `w(x) = sum_j phi_j(x) alpha_j` (beam frame, x the
//! material coordinate from G, [m]) the bending energy to fourth order is
//! `EI/2 int w''^2 (1 + w'^2) dx` (Eq. V1) and the axial velocity of the section at x holds the
//! foreshortening's rate `f_t = int_0^x w' w_t' ds`, whose kinetic energy `rho/2 int f_t^2 dx` the
//! rest of the full model leaves out (Eq. V4). Their forces on the alpha rows [N m^-1/2 ... the
//! rows' units, as `K alpha`] are
//!
//! ```text
//! Q_j^V = - EI int (w'' w'^2 phi_j'' + w''^2 w' phi_j') dx                          (V5)
//! Q_j^f = - rho int w'(s) phi_j'(s) F(s) ds,  F(s) = int_s^L f_tt dx
//!       = (L - s) int_0^s h + int_s^L (L - r) h(r) dr,   h = w_t'^2 + w' w_tt'          (V6)
//! ```
//!
//! taken at the step's predictor (alpha, alpha') and the last solve's modal accelerations
//! (`w_tt`, lagged like the full model's other acceleration terms), on the modes that carry the
//! deflection: the first [`KEPT_ANALYTIC`] analytic modes (Eq. 23 keeps these too; the junction
//! shapes are left out here, `docs/amm.md` 12.14: their slopes carry every analytic mode's share,
//! which the points do not resolve, and with them a run at N = 80 and 6e-6 s diverged). The integrals use Gauss-Legendre points on [`PANELS`] equal
//! panels of [`POINTS`] points. Without gravity they are third order in the motion's own
//! deflection and left out (12.14, "Only under gravity"); under gravity the star vibrates about
//! its sag and they change its stiffness and mass at first order in the vibration (Eq. V2).

use crate::geometric::KEPT_ANALYTIC;
use crate::modes::ModeSet;

/// Whether a run carries these terms: under gravity (`gravity` [m/s^2], base frame) and in the
/// full model, whose geometric stiffness they extend (12.14). The one rule for the system that
/// attaches them and for the estimate that calibrates what they leave (Eq. G1).
pub(crate) fn carried(gravity: [f64; 2], full_model: bool) -> bool {
    gravity != [0.0; 2] && full_model
}

/// Equal panels along each beam (12.14: 4 and 100 panels agree to 0.001 % mean EVP on the
/// as-built cases measured there).
pub(crate) const PANELS: usize = 10;
/// Gauss-Legendre points per panel.
pub(crate) const POINTS: usize = 5;
/// Largest `beta' lambda_j` of a mode a run takes ([`ThirdOrderTerms::set_step`]): `h omega_j`
/// up to about 0.9 at `rho_inf = 0.8`.
pub(crate) const STEP_LIMIT: f64 = 0.25;

/// One beam's tables and state for Eqs. V5-V6.
#[derive(Debug, Clone)]
pub(crate) struct ThirdOrderTerms {
    /// Bending stiffness EI [N m^2] and mass per length rho [kg/m].
    ei: f64,
    rho: f64,
    /// Beam length L [m].
    l: f64,
    /// The kept modes' indices among the beam's N, and their eigenvalues lambda_j [1/s^2].
    kept: Vec<usize>,
    lambda: Vec<f64>,
    /// How many of the kept modes (the first ones) the step takes ([`ThirdOrderTerms::set_step`]).
    active: usize,
    /// Quadrature points x_q [m] and weights [m].
    x: Vec<f64>,
    weight: Vec<f64>,
    /// Panel length [m] and the panel's integration matrix: `cum[q][p]` is the integral from the
    /// panel's start to its point q of the Lagrange polynomial through its points that is 1 at
    /// point p, per unit panel length (exact for h of degree below [`POINTS`] on the panel).
    panel: f64,
    cum: [[f64; POINTS]; POINTS],
    /// `phi_j'(x_q)` and `phi_j''(x_q)`, mode-major: row j holds kept mode j at every point
    /// (so that each sum runs along the points, in vector lanes).
    slopes: Vec<f64>,
    curvatures: Vec<f64>,
    /// The kept modal accelerations of the last solve [m^1/2 s^-2].
    acc: Vec<f64>,
    // per step: the kept coordinates and velocities, and per point w', w'', w_t', w_tt', h, and
    // the two weights of the back projection
    alpha: Vec<f64>,
    vel: Vec<f64>,
    slope: Vec<f64>,
    curv: Vec<f64>,
    slope_rate: Vec<f64>,
    slope_acc: Vec<f64>,
    h: Vec<f64>,
    on_slope: Vec<f64>,
    on_curv: Vec<f64>,
}

impl ThirdOrderTerms {
    /// Tables for a beam with modes `modes`, bending stiffness `ei` [N m^2] and mass per length
    /// `rho` [kg/m].
    pub(crate) fn new(modes: &ModeSet, ei: f64, rho: f64) -> Self {
        let kept: Vec<usize> = (0..modes.analytic_len().min(KEPT_ANALYTIC)).collect();
        let l = modes.length();
        let (xs, ws) = flexstar_numerics::quadrature::gauss_legendre_rule(POINTS);
        let h = l / PANELS as f64;
        let (mut x, mut weight) = (Vec::new(), Vec::new());
        for p in 0..PANELS {
            let c = (p as f64 + 0.5) * h;
            for (xi, wi) in xs.iter().zip(&ws) {
                x.push(c + 0.5 * h * xi);
                weight.push(0.5 * h * wi);
            }
        }
        let cum = integration_matrix(&xs);
        let k = kept.len();
        let nq = x.len();
        let (mut slopes, mut curvatures) = (vec![0.0; k * nq], vec![0.0; k * nq]);
        for (j, &m) in kept.iter().enumerate() {
            for (q, &xq) in x.iter().enumerate() {
                let e = modes.eval(m, xq);
                slopes[j * nq + q] = e[1];
                curvatures[j * nq + q] = e[2];
            }
        }
        let lambda = kept.iter().map(|&m| modes.lambda()[m]).collect();
        ThirdOrderTerms {
            lambda,
            active: k,
            ei,
            rho,
            l,
            acc: vec![0.0; k],
            alpha: vec![0.0; k],
            vel: vec![0.0; k],
            slope: vec![0.0; nq],
            curv: vec![0.0; nq],
            h: vec![0.0; nq],
            slope_rate: vec![0.0; nq],
            slope_acc: vec![0.0; nq],
            on_slope: vec![0.0; nq],
            on_curv: vec![0.0; nq],
            kept,
            x,
            weight,
            panel: h,
            cum,
            slopes,
            curvatures,
        }
    }

    /// The run's largest `beta' = beta h^2` [s^2]: the run takes the kept modes with
    /// `beta' lambda_j <= STEP_LIMIT`, the modes its step resolves, in its static start and in
    /// every step alike (the forces are explicit, at the predictor: on a mode the step does not
    /// resolve a relative stiffness change of a few w'^2 grows from step to step, `docs/amm.md`
    /// 12.14). Before a call, all kept modes.
    pub(crate) fn set_step(&mut self, bp: f64) {
        self.active = self.lambda.iter().take_while(|&&l| l * bp <= STEP_LIMIT).count();
    }

    /// Remember the modal accelerations `qdd` (the beam's N) of the last solve.
    pub(crate) fn remember(&mut self, qdd: &[f64]) {
        for (a, &m) in self.acc.iter_mut().zip(&self.kept) {
            *a = qdd[m];
        }
    }

    /// Add `Q^V + Q^f` (Eqs. V5-V6) at modal coordinates `alpha` and velocities `vel` (the
    /// beam's N) to the alpha rows `r`.
    pub(crate) fn add_forces(&mut self, alpha: &[f64], vel: &[f64], r: &mut [f64]) {
        for (k, &m) in self.kept.iter().enumerate() {
            self.alpha[k] = alpha[m];
            self.vel[k] = vel[m];
        }
        self.point_values();
        self.point_weights();
        self.project(r);
    }

    /// w', w'' and h = w_t'^2 + w' w_tt' at every point.
    fn point_values(&mut self) {
        let nq = self.x.len();
        let (wtp, wttp) = (&mut self.slope_rate, &mut self.slope_acc);
        for v in [&mut self.slope, &mut self.curv, &mut *wtp, &mut *wttp] {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
        for j in 0..self.active {
            let (dp, ddp) = (
                &self.slopes[j * nq..(j + 1) * nq],
                &self.curvatures[j * nq..(j + 1) * nq],
            );
            let (a, v, acc) = (self.alpha[j], self.vel[j], self.acc[j]);
            for q in 0..nq {
                self.slope[q] += a * dp[q];
                wtp[q] += v * dp[q];
                wttp[q] += acc * dp[q];
                self.curv[q] += a * ddp[q];
            }
        }
        for q in 0..nq {
            self.h[q] = wtp[q] * wtp[q] + self.slope[q] * wttp[q];
        }
    }

    /// The weights of phi_j' and phi_j'' at every point in `- Q_j` (Eqs. V5-V6), with F(x_q) of
    /// Eq. V6 from the integrals of h and (L - x) h up to each point, panel by panel.
    fn point_weights(&mut self) {
        let l = self.l;
        let total_arm: f64 = (0..self.x.len())
            .map(|q| self.weight[q] * self.h[q] * (l - self.x[q]))
            .sum();
        let (mut before, mut before_arm) = (0.0, 0.0);
        for p in 0..PANELS {
            let o = p * POINTS;
            for q in 0..POINTS {
                let (mut part, mut part_arm) = (0.0, 0.0);
                for k in 0..POINTS {
                    let hk = self.h[o + k];
                    part += self.cum[q][k] * hk;
                    part_arm += self.cum[q][k] * hk * (l - self.x[o + k]);
                }
                let below = before + self.panel * part;
                let above_arm = total_arm - (before_arm + self.panel * part_arm);
                let f = (l - self.x[o + q]) * below + above_arm;
                let (w, wp, wpp) = (self.weight[o + q], self.slope[o + q], self.curv[o + q]);
                self.on_slope[o + q] = w * (self.ei * wpp * wpp * wp + self.rho * wp * f);
                self.on_curv[o + q] = w * self.ei * wpp * wp * wp;
            }
            for k in 0..POINTS {
                let wh = self.weight[o + k] * self.h[o + k];
                before += wh;
                before_arm += wh * (l - self.x[o + k]);
            }
        }
    }

    /// `r_j -= sum_q (on_slope_q phi_j'(x_q) + on_curv_q phi_j''(x_q))` on the active kept rows.
    fn project(&self, r: &mut [f64]) {
        let nq = self.x.len();
        for (j, &m) in self.kept.iter().enumerate().take(self.active) {
            let (dp, ddp) = (
                &self.slopes[j * nq..(j + 1) * nq],
                &self.curvatures[j * nq..(j + 1) * nq],
            );
            let s: f64 = (0..nq)
                .map(|q| self.on_slope[q] * dp[q] + self.on_curv[q] * ddp[q])
                .sum();
            r[m] -= s;
        }
    }

    /// The extra bending energy `EI/2 int w''^2 w'^2 dx` [J] of Eq. V1 at `alpha` (the beam's N),
    /// on the same points.
    #[cfg(test)]
    fn curvature_energy(&self, alpha: &[f64]) -> f64 {
        let nq = self.x.len();
        let field = |table: &[f64], q: usize| -> f64 {
            self.kept
                .iter()
                .enumerate()
                .map(|(j, &m)| table[j * nq + q] * alpha[m])
                .sum()
        };
        (0..nq)
            .map(|q| {
                let (wp, wpp) = (field(&self.slopes, q), field(&self.curvatures, q));
                0.5 * self.weight[q] * self.ei * wpp * wpp * wp * wp
            })
            .sum()
    }
}

/// `cum[q][p]`: the integral over [-1, xi_q] of the Lagrange polynomial on the points `xi` that
/// is 1 at xi_p, halved (per unit length of a panel mapped onto [-1, 1]); by the same
/// Gauss-Legendre rule on [-1, xi_q], exact for the polynomial's degree.
fn integration_matrix(xi: &[f64]) -> [[f64; POINTS]; POINTS] {
    let lagrange = |p: usize, t: f64| {
        (0..POINTS)
            .filter(|&k| k != p)
            .map(|k| (t - xi[k]) / (xi[p] - xi[k]))
            .product::<f64>()
    };
    let mut cum = [[0.0; POINTS]; POINTS];
    for (row, &xq) in cum.iter_mut().zip(xi) {
        let half = 0.5 * (xq + 1.0);
        for (p, entry) in row.iter_mut().enumerate() {
            let integral: f64 = xi
                .iter()
                .zip(flexstar_numerics::quadrature::gauss_legendre(POINTS).1)
                .map(|(&t, w)| w * lagrange(p, -1.0 + half * (t + 1.0)))
                .sum::<f64>()
                * half;
            *entry = 0.5 * integral;
        }
    }
    cum
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::params::RobotParams;
    use flexstar_model::ModeFamily;

    fn beam() -> (ModeSet, f64, f64) {
        let p = RobotParams::default();
        let modes = ModeSet::new(ModeFamily::Enriched, 30, &p).unwrap();
        (modes, p.e * p.i, p.rho)
    }

    /// A deflection of a few kept modes, of slope about 1e-2.
    fn deflection(n: usize) -> Vec<f64> {
        (0..n)
            .map(|j| if j < 8 { 1e-3 / (1.0 + j as f64) } else { 0.0 })
            .collect()
    }

    /// Eq. V5 is the gradient of the energy of Eq. V1: against central differences of that
    /// energy, at rest (no inertia part), on every kept mode.
    #[test]
    fn the_curvature_force_is_the_gradient_of_its_energy() {
        let (modes, ei, rho) = beam();
        let n = modes.len();
        let mut t = ThirdOrderTerms::new(&modes, ei, rho);
        let alpha = deflection(n);
        let mut r = vec![0.0; n];
        t.add_forces(&alpha, &vec![0.0; n], &mut r);
        let kept = t.kept.clone();
        for &m in &kept {
            // small: the high modes' curvatures make the energy's higher derivatives large
            let step = 1e-9;
            let energy = |d: f64| {
                let mut a = alpha.clone();
                a[m] += d;
                t.curvature_energy(&a)
            };
            // fourth-order central differences
            let gradient =
                (8.0 * (energy(step) - energy(-step)) - (energy(2.0 * step) - energy(-2.0 * step))) / (12.0 * step);
            let scale = r.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            assert!(
                (r[m] + gradient).abs() <= 1e-6 * scale,
                "mode {m}: force {} against - dU/dalpha {}",
                r[m],
                -gradient
            );
        }
    }

    /// Eq. V6 against its definition evaluated another way: `- rho int f_tt g_j dx` with
    /// `g_j(x) = int_0^x w' phi_j'` and `f_tt(x) = int_0^x h` by nested trapezoid rules on a
    /// uniform grid of 4000 intervals, for a beam deflected, moving and accelerating in its
    /// modes; the curvature part (Eq. V5) is removed by subtracting the same deflection at rest.
    #[test]
    fn the_foreshortening_inertia_matches_its_double_integral() {
        let (modes, ei, rho) = beam();
        let n = modes.len();
        let mut t = ThirdOrderTerms::new(&modes, ei, rho);
        let alpha = deflection(n);
        let vel: Vec<f64> = (0..n)
            .map(|j| if j < 6 { 0.05 * (j as f64 - 2.5) } else { 0.0 })
            .collect();
        let acc: Vec<f64> = (0..n)
            .map(|j| if j < 6 { 3.0 / (1.0 + j as f64) } else { 0.0 })
            .collect();
        let (mut with, mut without) = (vec![0.0; n], vec![0.0; n]);
        t.remember(&vec![0.0; n]);
        t.add_forces(&alpha, &vec![0.0; n], &mut without);
        t.remember(&acc);
        t.add_forces(&alpha, &vel, &mut with);
        // the reference on a uniform grid of 4000 intervals
        let l = modes.length();
        let m_grid = 4_000;
        let dx = l / m_grid as f64;
        let field = |x: f64, c: &[f64], d: usize| (0..n).map(|j| modes.eval(j, x)[d] * c[j]).sum::<f64>();
        let xs: Vec<f64> = (0..=m_grid).map(|i| i as f64 * dx).collect();
        let wp: Vec<f64> = xs.iter().map(|&x| field(x, &alpha, 1)).collect();
        let h: Vec<f64> = xs
            .iter()
            .zip(&wp)
            .map(|(&x, &s)| field(x, &vel, 1).powi(2) + s * field(x, &acc, 1))
            .collect();
        let cumulative = |v: &[f64]| {
            let mut c = vec![0.0; v.len()];
            for i in 1..v.len() {
                c[i] = c[i - 1] + 0.5 * dx * (v[i - 1] + v[i]);
            }
            c
        };
        let ftt = cumulative(&h);
        for &m in &t.kept.clone() {
            let dphi: Vec<f64> = xs.iter().map(|&x| modes.eval(m, x)[1]).collect();
            let integrand: Vec<f64> = wp.iter().zip(&dphi).map(|(a, b)| a * b).collect();
            let g = cumulative(&integrand);
            let prod: Vec<f64> = ftt.iter().zip(&g).map(|(a, b)| a * b).collect();
            let reference = -rho * cumulative(&prod)[m_grid];
            let got = with[m] - without[m];
            // 10 panels of 5 points resolve the kept modes' products to 2e-4 (measured)
            assert!(
                (got - reference).abs() <= 1e-3 * reference.abs().max(1e-3 * rho * l),
                "mode {m}: {got:e} against {reference:e}"
            );
        }
    }
}
