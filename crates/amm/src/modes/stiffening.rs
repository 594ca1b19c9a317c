//! Geometric stiffness of the axial inertia force (Eq. 23, full model).

use super::*;

impl ModeSet {
    /// Geometric stiffness of the axial inertia force (Eq. 23, full model; `docs/amm.md`
    /// section 8): with `N(x) = rho [th'^2 (L^2 - x^2)/2 - a_x (L - x)]`, the tension of the part
    /// of the beam between x and the free tip, `int N phi_j' phi_m' dx = rho (th'^2 G1 - a_x G2)`.
    /// Returns `(G1, G2)`, row-major N x N: `G1_jm = int (L^2 - x^2)/2 phi_j' phi_m' dx` [-] and
    /// `G2_jm = int (L - x) phi_j' phi_m' dx` [1/m].
    pub fn axial_stiffening(&self) -> (Vec<f64>, Vec<f64>) {
        let all: Vec<usize> = (0..self.len()).collect();
        self.axial_stiffening_on(&all)
    }

    /// [`ModeSet::axial_stiffening`] on the modes `on` (indices, k of them): `(G1, G2)` k x k,
    /// row-major, entry (a, b) for the modes `on[a]`, `on[b]`.
    pub fn axial_stiffening_on(&self, on: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let n = on.len();
        let (x, w) = junction::composite_rule(junction::panels_for(self.analytic_beta_max()));
        let nq = x.len();
        // slopes at the nodes (column q: the modes `on` at node q), and the same columns weighted
        // by the two axial force profiles: G = D diag(f) D^T, two matrix products
        let mut d = Mat::<f64>::zeros(n, nq);
        let mut d1 = Mat::<f64>::zeros(n, nq);
        let mut d2 = Mat::<f64>::zeros(n, nq);
        let mut slope = vec![0.0; self.len()];
        for (q, (&xi, &wq)) in x.iter().zip(&w).enumerate() {
            let xm = xi * self.l;
            self.slopes_at(xm, &mut slope);
            let col = d.col_mut(q).try_as_col_major_mut().expect("contiguous").as_slice_mut();
            for (c, &m) in col.iter_mut().zip(on) {
                *c = slope[m];
            }
            // dx = L dxi
            let f1 = wq * self.l * 0.5 * (self.l * self.l - xm * xm);
            let f2 = wq * self.l * (self.l - xm);
            let col = d.col(q).try_as_col_major().expect("contiguous").as_slice();
            for (f, dk) in [(f1, &mut d1), (f2, &mut d2)] {
                let out = dk.col_mut(q).try_as_col_major_mut().expect("contiguous").as_slice_mut();
                for (o, v) in out.iter_mut().zip(col) {
                    *o = f * v;
                }
            }
        }
        let product = |weighted: &Mat<f64>| {
            let mut g = Mat::<f64>::zeros(n, n);
            matmul(
                g.as_mut(),
                Accum::Replace,
                d.as_ref(),
                weighted.transpose(),
                1.0,
                Par::Seq,
            );
            // row-major, exactly symmetric
            let mut out = vec![0.0; n * n];
            for j in 0..n {
                for m in 0..n {
                    out[j * n + m] = 0.5 * (g[(j, m)] + g[(m, j)]);
                }
            }
            out
        };
        (product(&d1), product(&d2))
    }
}

impl ModeSet {
    /// The running slope Gram matrix `F(x_n)_ab = int_0^{x_n} phi_a' phi_b' ds` [1/m] of the modes
    /// `on` (k of them) at the panel ends `x_n = n L / panels`, n = 0..=panels: (panels + 1) k x k
    /// matrices, row-major, one after the other. Each panel by the 4-point Gauss rule, exact to
    /// round-off where `2 beta_max L / panels` stays below about 1 (the caller's choice of
    /// panels). Eq. S2 of `docs/amm.md` 12.11: `f(x) = 1/2 alpha^T F(x) alpha`.
    pub(crate) fn slope_gram_table(&self, on: &[usize], panels: usize) -> Vec<f64> {
        let k = on.len();
        let (pts, wts) = flexstar_numerics::quadrature::gauss_legendre_rule(4);
        let h = self.l / panels as f64;
        let mut table = vec![0.0; (panels + 1) * k * k];
        let mut slope = vec![0.0; self.len()];
        let mut kept = vec![0.0; k];
        for n in 0..panels {
            let (done, next) = table.split_at_mut((n + 1) * k * k);
            let next = &mut next[..k * k];
            next.copy_from_slice(&done[n * k * k..]);
            for (p, w) in pts.iter().zip(&wts) {
                self.slopes_at((n as f64 + 0.5 * (p + 1.0)) * h, &mut slope);
                for (c, &m) in kept.iter_mut().zip(on) {
                    *c = slope[m];
                }
                let wh = 0.5 * h * w;
                for (row, &sa) in next.chunks_exact_mut(k).zip(&kept) {
                    for (e, &sb) in row.iter_mut().zip(&kept) {
                        *e += wh * sa * sb;
                    }
                }
            }
        }
        table
    }
}

#[cfg(test)]
impl ModeSet {
    /// `1/2 int_0^x w'^2 ds` for `w = sum alpha_m phi_m` over every mode, by a composite 10-point
    /// Gauss rule of 40 panels (tests: the brute-force reference for the table of
    /// `slope_gram_table` and for the sleeve's foreshortening, `docs/amm.md` 12.11).
    pub(crate) fn half_squared_slope_integral(&self, alpha: &[f64], x: f64) -> f64 {
        let (pts, wts) = flexstar_numerics::quadrature::gauss_legendre_rule(10);
        let (mut v, mut d) = (vec![0.0; self.len()], vec![0.0; self.len()]);
        let panels = 40;
        let h = x / panels as f64;
        let mut f = 0.0;
        for p in 0..panels {
            for (z, w) in pts.iter().zip(&wts) {
                self.values_at((p as f64 + 0.5 * (z + 1.0)) * h, &mut v, Some(&mut d));
                let wp = dot(&d, alpha);
                f += 0.25 * h * w * wp * wp;
            }
        }
        f
    }
}
