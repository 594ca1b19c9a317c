//! Foreshortening inertia of the bent beams (full model; `docs/amm.md` section 8).
//!
//! An inextensible beam that bends draws its material towards G: the material point x sits at
//! `x + u - f(x)` along `e_x`, with `f(x) = 1/2 int_0^x w'^2 ds`. The axial inertia of the whole
//! beam (the u row, Eqs. 30/44) then carries
//!
//! ```text
//! - rho int_0^L f'' dx = - rho E'',   E = int_0^L f dx = 1/2 int_0^L (L - s) w'(s)^2 ds = 1/2 alpha^T G2 alpha,
//! E'' = alpha'^T G2 alpha' + alpha^T G2 alpha''
//! ```
//! with `G2` the geometric stiffness matrix of Eq. 23 (`ModeSet::axial_stiffening`): the force the
//! beam's foreshortening needs from G, second order in the deflection and at twice its frequency.
//! It is the reciprocal partner of the `-u'' G2 alpha` term already in the alpha rows (both come
//! from `rho int a_x delta f dx` in the virtual work of the inertia forces).
//!
//! Cost per beam and step: `G2 alpha` is the product the alpha rows already compute at the
//! predictor, so `alpha^T G2 alpha''` (with alpha'' of the previous step, as the Eq. 23 term takes
//! u'') is one dot product of length N; the velocity part `alpha'^T G2 alpha'` is taken on a few
//! modes, the first [`KEPT_ANALYTIC`] analytic ones and the junction shapes (a 12 x 12 form for the
//! enriched family), since the modal velocities of the high modes that resolve the sleeve are
//! small (`tests`: RMS difference 0.22 % of the full form over the brisk motion at N = 53; the
//! responses of the six motions of `docs/amm.md` section 8 change by EVP below 0.01 %).

use faer::ColRef;

use crate::modes::ModeSet;

/// Analytic modes (rigid ones included) kept in the velocity part `alpha'^T G2 alpha'`.
pub(crate) const KEPT_ANALYTIC: usize = 10;

/// The foreshortening term of one system (three equal beams).
#[derive(Debug, Clone)]
pub(crate) struct Foreshortening {
    /// Indices of the modes kept in the velocity part.
    kept: Vec<usize>,
    /// `G2` on the kept modes, row-major [1/m]: one for equal beams, else one per beam.
    g2_kept: Vec<Vec<f64>>,
    /// Modal accelerations alpha'' of each beam at the last solve (3 N).
    alpha_dd: Vec<f64>,
    /// Scratch: the kept modal velocities.
    v: Vec<f64>,
}

impl Foreshortening {
    /// For `modes` (beam 1's; the family and N of all three) with the geometric stiffness
    /// matrices `g2` (one shared by equal beams, or one per beam, `docs/amm.md` 13) given on the
    /// modes `rows` (k x k, row-major; `rows` must hold the kept ones), keeping the first
    /// `analytic` analytic modes and every junction shape in the velocity part.
    pub(crate) fn new(modes: &ModeSet, rows: &[usize], g2: &[Vec<f64>], analytic: usize) -> Self {
        let n = modes.len();
        let na = modes.analytic_len();
        let k = rows.len();
        let kept: Vec<usize> = (0..na.min(analytic)).chain(na..n).collect();
        let at: Vec<usize> = kept
            .iter()
            .map(|j| {
                rows.iter()
                    .position(|r| r == j)
                    .expect("the kept modes are among the rows")
            })
            .collect();
        let g2_kept = g2
            .iter()
            .map(|g2| {
                at.iter()
                    .flat_map(|&a| at.iter().map(move |&b| g2[a * k + b]))
                    .collect()
            })
            .collect();
        Foreshortening {
            v: vec![0.0; kept.len()],
            kept,
            g2_kept,
            alpha_dd: vec![0.0; 3 * n],
        }
    }

    /// `E''` of beam `beam` [m^2/s^2]: `alpha'^T G2 alpha'` on the kept modes at the velocity
    /// `va`, plus `(G2 alpha) . alpha''` with `g2_alpha = G2 alpha` on the modes `rows` (those of
    /// Eq. 23's product, `geometric`) and alpha'' of the last solve. The u row of the beam gains
    /// `+rho E''` on its right-hand side.
    pub(crate) fn second_derivative(
        &mut self,
        beam: usize,
        rows: &[usize],
        g2_alpha: ColRef<'_, f64>,
        va: &[f64],
    ) -> f64 {
        let n = va.len();
        let add = &self.alpha_dd[beam * n..(beam + 1) * n];
        let mut e2: f64 = rows.iter().enumerate().map(|(k, &j)| add[j] * g2_alpha[k]).sum();
        for (vk, &j) in self.v.iter_mut().zip(&self.kept) {
            *vk = va[j];
        }
        let k = self.kept.len();
        let g2_kept = &self.g2_kept[beam.min(self.g2_kept.len() - 1)];
        for (row, vj) in g2_kept.chunks_exact(k).zip(&self.v) {
            let gv: f64 = row.iter().zip(&self.v).map(|(g, v)| g * v).sum();
            e2 += vj * gv;
        }
        e2
    }

    /// The acceleration part of [`Foreshortening::second_derivative`]: `(G2 alpha) . alpha''` on
    /// the modes `rows`, with alpha'' of the last solve [m^2/s^2]; the same sum in the same order.
    pub(crate) fn acceleration_part(&self, beam: usize, rows: &[usize], g2_alpha: ColRef<'_, f64>) -> f64 {
        let n = self.alpha_dd.len() / 3;
        let add = &self.alpha_dd[beam * n..(beam + 1) * n];
        rows.iter().enumerate().map(|(k, &j)| add[j] * g2_alpha[k]).sum()
    }

    /// Remember the modal accelerations of beam `beam` at the last solve.
    pub(crate) fn remember(&mut self, beam: usize, alpha_dd: &[f64]) {
        let n = alpha_dd.len();
        self.alpha_dd[beam * n..(beam + 1) * n].copy_from_slice(alpha_dd);
    }

    /// The velocity part on the kept modes and on all N modes, for the test of the few-mode form.
    #[cfg(test)]
    pub(crate) fn velocity_forms(&self, g2: &[f64], va: &[f64]) -> (f64, f64) {
        let n = va.len();
        let k = self.kept.len();
        let mut kept = 0.0;
        for (a, &j) in self.kept.iter().enumerate() {
            for (b, &m) in self.kept.iter().enumerate() {
                kept += va[j] * self.g2_kept[0][a * k + b] * va[m];
            }
        }
        let mut full = 0.0;
        for j in 0..n {
            for m in 0..n {
                full += va[j] * g2[j * n + m] * va[m];
            }
        }
        (kept, full)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::{AmmSettings, Experiment, ModeFamily, RobotParams};

    #[test]
    fn a_rigidly_swinging_beam_needs_its_centripetal_force() {
        // w = psi x (the beam turned rigidly about G by psi): its material draws in by
        // x (1 - cos psi), so E = psi^2 L^2 / 4 and rho E'' = rho L^2 / 2 (psi'^2 + psi psi''),
        // the axial force that makes the beam's mass rho L swing about G with its centre at L/2
        // (Newton; second order in psi)
        let p = RobotParams::paper();
        for family in [ModeFamily::Enriched, ModeFamily::FreeFree] {
            let modes = ModeSet::new(family, 20, &p).unwrap();
            let (_, g2) = modes.axial_stiffening();
            let all: Vec<usize> = (0..modes.len()).collect();
            let mut fore = Foreshortening::new(&modes, &all, std::slice::from_ref(&g2), KEPT_ANALYTIC);
            // alpha of w = x: its projections (x lies in the span of the two rigid modes)
            let shape = modes.x_phi_integral().to_vec();
            let (psi, psid, psidd) = (0.03, 2.0, -50.0);
            let n = shape.len();
            let g2_alpha: Vec<f64> = (0..n)
                .map(|j| psi * (0..n).map(|m| g2[j * n + m] * shape[m]).sum::<f64>())
                .collect();
            let va: Vec<f64> = shape.iter().map(|s| psid * s).collect();
            let add: Vec<f64> = shape.iter().map(|s| psidd * s).collect();
            fore.remember(1, &add);
            let e = 0.5 * psi * dot(&g2_alpha, &shape);
            let l = p.l;
            assert!((e - psi * psi * l * l / 4.0).abs() < 1e-8 * e, "{family}: E = {e}");
            let all: Vec<usize> = (0..n).collect();
            let e2 = fore.second_derivative(1, &all, faer::ColRef::from_slice(&g2_alpha), &va);
            let exact = l * l / 2.0 * (psid * psid + psi * psidd);
            assert!(
                (e2 - exact).abs() < 1e-8 * exact.abs(),
                "{family}: E'' = {e2}, exact {exact}"
            );
        }
    }

    #[test]
    fn few_modes_carry_the_velocity_part() {
        // the velocity part alpha'^T G2 alpha' on the kept modes against all N = 53 modes, along
        // the brisk motion (tests/cross_models.rs), velocities from the steps' positions.
        // Measured: RMS difference 2.2e-3 of the full form; the whole term moves brisk's w_G by
        // about 2 % of it (docs/amm.md section 8), so the truncation is below 1e-4 there
        let exp = Experiment::from_toml_str(
            include_str!("../../../configs/motions/brisk.toml"),
            std::path::Path::new("brisk.toml"),
        )
        .unwrap();
        let problem = exp.problem().unwrap();
        let exp = crate::star::Star::new(&problem);
        let n = 53;
        let settings = AmmSettings {
            modes: Some(n),
            ..AmmSettings::accurate()
        };
        let modes = ModeSet::new(settings.family, n, exp.beam(0)).unwrap();
        let (_, g2) = modes.axial_stiffening();
        let all: Vec<usize> = (0..n).collect();
        let fore = Foreshortening::new(&modes, &all, std::slice::from_ref(&g2), KEPT_ANALYTIC);
        let h = crate::DEFAULT_DT;
        let mut prev: Option<Vec<f64>> = None;
        let (mut err2, mut ref2) = (0.0, 0.0);
        crate::solver::integrate(&exp, &settings, n, true, |sys, q| {
            if let Some(p) = &prev {
                for b in 0..3 {
                    let o = b * sys.nb;
                    let va: Vec<f64> = (0..n).map(|j| (q[o + j] - p[o + j]) / h).collect();
                    let (kept, full) = fore.velocity_forms(&g2, &va);
                    err2 += (kept - full).powi(2);
                    ref2 += full * full;
                }
            }
            prev = Some(q.to_vec());
        })
        .unwrap();
        let rel = (err2 / ref2).sqrt();
        eprintln!("kept-mode velocity part: RMS difference {rel:e} of the full form");
        assert!(rel < 5e-3, "{rel}");
    }

    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }
}
