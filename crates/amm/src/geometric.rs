//! Geometric stiffness of the axial inertia force (Eq. 23, full model; `docs/amm.md` section 8)
//! on the modes that carry it.
//!
//! The alpha rows gain `- rho (th'^2 G1 - a_x G2) alpha` at the predictor, with `G1`, `G2` from
//! [`ModeSet::axial_stiffening`]. The product is taken on the first [`KEPT_ANALYTIC`] analytic
//! modes and the junction shapes (rows and columns). The modes left out are those that resolve
//! the sleeve: their stiffness `lambda_j` is 10^3-10^6 times the centrifugal and axial-inertia
//! loads `th'^2`, `a_x / L` of the paper's motions, and their coordinates are the small quasi-static
//! response to the sleeve's forces, so both what they would receive and what they would give is
//! negligible: on the paper's four cases and the two own motions the responses move by EVP
//! below 1e-3 % against the product on all N modes (`docs/amm.md` section 8, test
//! `few_modes_carry_the_geometric_stiffness`), for a product 8 times smaller at N = 53.

use faer::linalg::matmul::matmul;
use faer::{Accum, ColRef, Mat, Par};

use crate::modes::ModeSet;

/// Analytic modes (rigid ones included) kept in the product of Eq. 23.
pub(crate) const KEPT_ANALYTIC: usize = 16;

/// `[G1; G2]` on the kept modes and its products with the three beams' modal coordinates.
#[derive(Debug, Clone)]
pub(crate) struct GeometricStiffness {
    /// Indices of the kept modes, increasing.
    kept: Vec<usize>,
    /// `[G1; G2]` on the kept modes (2k x k): G1 [-], G2 [1/m]; one for equal beams, else one
    /// per beam (`docs/amm.md` 13, Eq. J6).
    g12: Vec<Mat<f64>>,
    /// The kept coordinates of the three beams as columns (k x 3).
    alpha: Mat<f64>,
    /// `[G1; G2] alpha` for the three beams (2k x 3).
    products: Mat<f64>,
}

impl GeometricStiffness {
    /// For `modes` (one set shared by equal beams, or one per beam, of one family and N),
    /// keeping the first `analytic` analytic modes and every junction shape
    /// ([`GeometricStiffness::kept_modes`]): G1 and G2 on those modes only.
    pub(crate) fn new(modes: &[ModeSet], analytic: usize) -> Self {
        let kept = Self::kept_modes(&modes[0], analytic);
        let k = kept.len();
        let g12 = modes
            .iter()
            .map(|m| {
                let (g1, g2) = m.axial_stiffening_on(&kept);
                Mat::from_fn(2 * k, k, |r, c| if r < k { g1[r * k + c] } else { g2[(r - k) * k + c] })
            })
            .collect();
        GeometricStiffness {
            kept,
            g12,
            alpha: Mat::zeros(k, 3),
            products: Mat::zeros(2 * k, 3),
        }
    }

    /// The first `analytic` analytic modes of `modes` and its junction shapes, in order.
    pub(crate) fn kept_modes(modes: &ModeSet, analytic: usize) -> Vec<usize> {
        let na = modes.analytic_len();
        (0..na.min(analytic)).chain(na..modes.len()).collect()
    }

    /// G2 of beam `beam`'s modes on the kept modes, row-major (k x k) [1/m].
    pub(crate) fn g2(&self, beam: usize) -> Vec<f64> {
        let k = self.kept.len();
        let g12 = &self.g12[beam.min(self.g12.len() - 1)];
        (0..k * k).map(|e| g12[(k + e / k, e % k)]).collect()
    }

    /// The kept modes' indices.
    pub(crate) fn kept(&self) -> &[usize] {
        &self.kept
    }

    /// `[G1; G2] alpha_i` for the three beams at once (one matrix product), `alpha_i` read from
    /// `q` (beam i's coordinates start at `i * stride`).
    pub(crate) fn multiply(&mut self, q: &[f64], stride: usize) {
        for i in 0..3 {
            let mut col = self.alpha.col_mut(i);
            for (r, &j) in self.kept.iter().enumerate() {
                col[r] = q[i * stride + j];
            }
        }
        if let [g12] = &self.g12[..] {
            matmul(
                self.products.as_mut(),
                Accum::Replace,
                g12.as_ref(),
                self.alpha.as_ref(),
                1.0,
                Par::Seq,
            );
        } else {
            for (i, g12) in self.g12.iter().enumerate() {
                matmul(
                    self.products.as_mut().subcols_mut(i, 1),
                    Accum::Replace,
                    g12.as_ref(),
                    self.alpha.as_ref().subcols(i, 1),
                    1.0,
                    Par::Seq,
                );
            }
        }
    }

    /// `G1 alpha_i` on the kept rows, from the last [`GeometricStiffness::multiply`].
    pub(crate) fn g1_alpha(&self, beam: usize) -> ColRef<'_, f64> {
        self.products.col(beam).subrows(0, self.kept.len())
    }

    /// `G2 alpha_i` on the kept rows, from the last [`GeometricStiffness::multiply`].
    pub(crate) fn g2_alpha(&self, beam: usize) -> ColRef<'_, f64> {
        let k = self.kept.len();
        self.products.col(beam).subrows(k, k)
    }
}

#[cfg(test)]
mod tests {
    use flexstar_metrics::evp::point_evps;
    use flexstar_model::{AmmSettings, Experiment};

    use crate::solver::{build_system, integrate_system};
    use crate::TOLERANCE_DT;

    #[test]
    fn few_modes_carry_the_geometric_stiffness() {
        // Eq. 23 on the kept modes against the product on all N = 53 modes, along the brisk
        // motion (tests/cross_models.rs) at the accurate model's step. Measured: mean EVP 8.9e-4 %,
        // largest point 2.5e-3 % (1e-2 % keeping 10 analytic modes, 5.7e-2 % keeping 4)
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
            dt: Some(TOLERANCE_DT),
            ..AmmSettings::accurate()
        };
        let run = |sys| {
            let started = std::time::Instant::now();
            integrate_system(
                &exp,
                &settings,
                sys,
                TOLERANCE_DT,
                started,
                |_: &crate::system::System, _: &[f64]| {},
            )
            .unwrap()
        };
        let sys = build_system(&settings, n, &exp).unwrap();
        let kept = run(sys.clone());
        let all = run(sys.with_geometric_kept(n));
        let e = point_evps(&kept, &all).unwrap();
        let worst = e.points.iter().flatten().fold(0.0f64, |a, b| a.max(*b));
        eprintln!(
            "kept-mode Eq. 23: mean EVP {:e} %, largest point {worst:e} %",
            e.mean.unwrap()
        );
        assert!(e.mean.unwrap() < 5e-3 && worst < 1e-2, "{e:?}");
        // and the truncation is a truncation: keeping fewer modes moves the response more
        let fewer = run(build_system(&settings, n, &exp).unwrap().with_geometric_kept(4));
        assert!(point_evps(&fewer, &all).unwrap().mean.unwrap() > 3.0 * e.mean.unwrap());
    }
}
