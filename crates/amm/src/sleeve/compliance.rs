//! The truncation flexibility of the sleeves (`docs/amm.md` section 12, Eqs. R1-R6): the
//! quasi-static deflection that the modes left out of the basis add under the sleeve's point
//! forces and couple.
//!
//! A basis of N functions represents the beam's response to a point couple only slowly: the
//! slope under a unit couple, `sum_m phi_m'(y)^2 / (rho lambda_m)`, converges like 1/N (Eq. R1).
//! The modes beyond the basis are stiff against the motion (their frequencies are far above the
//! sleeve's excitation), so their response is the static one: with the free-free beam's
//! Green's function `h` on the elastic subspace (Eq. R2, closed form below) their part is
//!
//! ```text
//! R_ab = h(l_a, l_b) / EI - sum_{m: lambda_m > 0} l_a(phi_m) l_b(phi_m) / (rho lambda_m)     (Eq. R3)
//! ```
//! for the sleeve rows' functionals `l_a` (value at the centre and the two edges, minus the
//! slope at the centre), and each sleeve row becomes `c_a q + sum_b R_ab lambda_b = 0` (Eq. R4):
//! [`Sleeves::add_compliance`] in the step's Schur complement.

use flexstar_numerics::vector::dots;

use super::{Sleeves, B_MID, B_MSLOPE};
use crate::system::BeamRows;

/// The free-free beam (length `l`, EI = 1, unit mass density) on its elastic subspace under a
/// unit point force (`couple = false`) or a unit point couple (the functional `v -> v'(y)`,
/// `couple = true`) at `y`, balanced by the rigid-body inertia it causes and made
/// mass-orthogonal to the rigid motions (Eq. R2, `docs/amm.md` 12.3): the particular solution
/// `P(x) = s (x - y)_+^k / k! - a x^4 / 24 - b x^5 / 120` (k = 3, s = 1 for the force; k = 2,
/// s = -1 for the couple) less its rigid part `c0 + c1 x`.
struct GreenSource {
    y: f64,
    couple: bool,
    a: f64,
    b: f64,
    c0: f64,
    c1: f64,
}

impl GreenSource {
    fn new(l: f64, y: f64, couple: bool) -> Self {
        let r = l - y;
        let (r2, l2) = (r * r, l * l);
        let (r3, l4) = (r2 * r, l2 * l2);
        // the load delta - pi (force) or -delta' - d pi/dy (couple), pi(s, y) = a + b s, and the
        // moments int P, int x P of the particular solution
        let (a, b, i0, i1) = if couple {
            (-6.0 / l2, 12.0 / (l2 * l), -r3 / 6.0, -r3 * r / 8.0 - y * r3 / 6.0)
        } else {
            let e = 2.0 * y / l - 1.0;
            (
                (1.0 - 3.0 * e) / l,
                6.0 * e / l2,
                r3 * r / 24.0,
                r3 * r2 / 30.0 + y * r3 * r / 24.0,
            )
        };
        let l5 = l4 * l;
        let i0 = i0 - a * l5 / 120.0 - b * l5 * l / 720.0;
        let i1 = i1 - a * l5 * l / 144.0 - b * l5 * l2 / 840.0;
        // remove the rigid part c0 + c1 x (L2 projection on 1, x; Gram determinant L^4 / 12)
        let det = l4 / 12.0;
        GreenSource {
            y,
            couple,
            a,
            b,
            c0: (i0 * l2 * l / 3.0 - i1 * l2 / 2.0) / det,
            c1: (i1 * l - i0 * l2 / 2.0) / det,
        }
    }

    /// `[w(x), w'(x)]` [m/N, rad/N for the force; m/(N m), rad/(N m) for the couple, times EI].
    fn at(&self, x: f64) -> [f64; 2] {
        let z = (x - self.y).max(0.0);
        let (p, dp) = if self.couple {
            (-z * z / 2.0, -z)
        } else {
            (z * z * z / 6.0, z * z / 2.0)
        };
        let x3 = x * x * x;
        let p = p - x3 * x * (self.a / 24.0 + self.b * x / 120.0);
        let dp = dp - x3 * (self.a / 6.0 + self.b * x / 24.0);
        [p - self.c0 - self.c1 * x, dp - self.c1]
    }
}

/// Eq. R2: the Green's function of the free-free beam on its elastic subspace (EI = 1, unit
/// mass density, `h = sum_elastic phi_m(x) phi_m(y) / beta_m^4`) and its derivatives:
/// `[h, dh/dx, dh/dy, d2h/dx dy]` at (x, y) in [0, L]^2.
#[cfg(test)]
pub(crate) fn free_free_green(l: f64, x: f64, y: f64) -> [f64; 4] {
    let [h, hx] = GreenSource::new(l, y, false).at(x);
    let [hy, hxy] = GreenSource::new(l, y, true).at(x);
    [h, hx, hy, hxy]
}

/// The sleeve rows' functionals, in the order of the basis vectors `B_MID, B_RIGHT, B_LEFT,
/// B_MSLOPE` of [`super::rows`]: (offset from the sleeve centre in units of Lp/2, derivative order, sign).
const FUNCTIONALS: [(f64, usize, f64); 4] = [(0.0, 0, 1.0), (1.0, 0, 1.0), (-1.0, 0, 1.0), (0.0, 1, -1.0)];

/// The truncation flexibility of one robot's beams at their sleeves (Eq. R3), for a basis whose
/// span holds the free-free beam's rigid motions (free-free and enriched families).
#[derive(Debug, Clone)]
pub(crate) struct SleeveCompliance {
    l: f64,
    /// Half the sleeve length Lp/2 [m].
    hp: f64,
    /// 1 / EI [1/(N m^2)].
    inv_ei: f64,
    /// `1 / (rho lambda_m)` per basis function, 0 for the rigid ones [s^2 m/kg].
    inv_k: Vec<f64>,
    /// Workspace: the four sleeve vectors scaled by `inv_k`.
    scaled: [Vec<f64>; 4],
}

impl SleeveCompliance {
    /// For beams of length `l` [m], sleeves of half-length `hp` [m], bending stiffness `ei`
    /// [N m^2], density `rho` [kg/m] and a basis with eigenvalues `lambda` [1/s^2].
    pub(crate) fn new(l: f64, hp: f64, ei: f64, rho: f64, lambda: &[f64]) -> Self {
        let inv_k: Vec<f64> = lambda
            .iter()
            .map(|&lm| if lm > 0.0 { 1.0 / (rho * lm) } else { 0.0 })
            .collect();
        let n = inv_k.len();
        SleeveCompliance {
            l,
            hp,
            inv_ei: 1.0 / ei,
            inv_k,
            scaled: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]],
        }
    }

    /// Eq. R3 at a sleeve centred on the material point `xc` [m], with the basis vectors
    /// `v = [phi(xc), phi(xc + Lp/2), phi(xc - Lp/2), -phi'(xc)]` of the basis at these points:
    /// the 4 x 4 compliance `R_ab` [m/N, 1/N, 1/(N m)] of the rows' values to their multipliers.
    pub(crate) fn block(&mut self, xc: f64, v: [&[f64]; 4]) -> [[f64; 4]; 4] {
        for (s, vec) in self.scaled.iter_mut().zip(v) {
            for ((o, x), k) in s.iter_mut().zip(vec).zip(&self.inv_k) {
                *o = x * k;
            }
        }
        let mut r = [[0.0; 4]; 4];
        for b in 0..4 {
            // the Green's function of source b (Eq. R2) read by the functionals a <= b
            let (ob, db, sb) = FUNCTIONALS[b];
            let src = GreenSource::new(self.l, xc + ob * self.hp, db == 1);
            let kept = kept_products(&self.scaled[b], b, v);
            for a in 0..=b {
                let (oa, da, sa) = FUNCTIONALS[a];
                let h = sa * sb * src.at(xc + oa * self.hp)[da];
                let v = h * self.inv_ei - kept[a];
                r[a][b] = v;
                r[b][a] = v;
            }
        }
        r
    }
}

/// `scaled . v[a]` for the functionals a <= b (the others are not read: 0), in one pass over
/// `scaled` (`dots`: each product's sum is the same whatever the others).
fn kept_products(scaled: &[f64], b: usize, [v0, v1, v2, v3]: [&[f64]; 4]) -> [f64; 4] {
    match b {
        0 => {
            let [k0] = dots(scaled, [v0]);
            [k0, 0.0, 0.0, 0.0]
        }
        1 => {
            let [k0, k1] = dots(scaled, [v0, v1]);
            [k0, k1, 0.0, 0.0]
        }
        2 => {
            let [k0, k1, k2] = dots(scaled, [v0, v1, v2]);
            [k0, k1, k2, 0.0]
        }
        _ => dots(scaled, [v0, v1, v2, v3]),
    }
}

/// The (global row, sleeve functional, factor) of `beam`'s sleeve rows, and how many.
fn sleeve_rows(beam: &BeamRows) -> ([(usize, usize, f64); 4], usize) {
    let mut sleeve = [(0, 0, 0.0); 4];
    let mut n = 0;
    for k in 0..beam.ids.len() {
        if (B_MID..=B_MSLOPE).contains(&beam.basis[k]) && n < 4 {
            sleeve[n] = (beam.ids[k], beam.basis[k] - B_MID, beam.sc[k]);
            n += 1;
        }
    }
    (sleeve, n)
}

impl Sleeves {
    /// Eq. R4 (`docs/amm.md` 12): the truncation flexibility of the sleeve rows of `beams`, `R / bp`
    /// on their block of the Schur complement `a` (m x m, row-major; `C q + R lambda = 0` at
    /// `q = qhat + bp qdd`). No-op without it, and for the consistent initial accelerations
    /// (`bp = 0`: the rows hold at rest).
    pub(crate) fn add_compliance(&self, a: &mut [f64], m: usize, beams: &[BeamRows; 3], bp: f64) {
        if self.compliance.is_none() || bp <= 0.0 {
            return;
        }
        for (beam, res) in beams.iter().zip(&self.res) {
            let (sleeve, n) = sleeve_rows(beam);
            for &(gk, fa, sk) in &sleeve[..n] {
                for &(gs, fb, ss) in &sleeve[..n] {
                    a[gk * m + gs] += sk * ss * res[fa][fb] / bp;
                }
            }
        }
    }

    /// Eq. R4: the truncation flexibility's part `R lambda / bp` of the sleeve rows of `beams`
    /// under the multipliers `lam`, added to `rows` (one entry per constraint row); what
    /// [`Sleeves::add_compliance`] puts in the Schur complement, as a product. No-op without it.
    pub(crate) fn add_compliance_product(&self, rows: &mut [f64], beams: &[BeamRows; 3], lam: &[f64], bp: f64) {
        if self.compliance.is_none() || bp <= 0.0 {
            return;
        }
        for (beam, res) in beams.iter().zip(&self.res) {
            let (sleeve, n) = sleeve_rows(beam);
            for &(gk, fa, sk) in &sleeve[..n] {
                for &(gs, fb, ss) in &sleeve[..n] {
                    rows[gk] += sk * ss * res[fa][fb] / bp * lam[gs];
                }
            }
        }
    }

    /// Eq. R4 (`docs/amm.md` 12): the deflection `sum_b R_ab lambda_b` that the modes left out
    /// of the basis add at beam `i`'s sleeve (its rows `beam`) under the multipliers `lam` of the
    /// last solve, for the functionals `[w(xc), w(xc + Lp/2), w(xc - Lp/2), -w'(xc)]` [m, m, m,
    /// rad]; zeros without the truncation flexibility.
    #[cfg(test)]
    pub(crate) fn truncation_deflection(&self, i: usize, beam: &BeamRows, lam: &[f64]) -> [f64; 4] {
        let mut out = [0.0; 4];
        if self.compliance.is_none() {
            return out;
        }
        let mut force = [0.0; 4];
        for (k, &g) in beam.ids.iter().enumerate() {
            if (B_MID..=B_MSLOPE).contains(&beam.basis[k]) {
                force[beam.basis[k] - B_MID] += beam.sc[k] * lam[g];
            }
        }
        for (o, row) in out.iter_mut().zip(&self.res[i]) {
            *o = row.iter().zip(&force).map(|(r, f)| r * f).sum();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modes::ModeSet;
    use flexstar_model::{ModeFamily, RobotParams};

    /// The modal sum of Eq. R2 over the first `n` free-free modes, derivative orders (dx, dy).
    fn modal_sum(set: &ModeSet, x: f64, y: f64, dx: usize, dy: usize) -> f64 {
        let bl = set.beta_l();
        let l = set.length();
        (0..set.len())
            .filter(|&m| bl[m] > 0.0)
            .map(|m| set.eval(m, x)[dx] * set.eval(m, y)[dy] / (bl[m] / l).powi(4))
            .sum()
    }

    #[test]
    fn green_function_is_the_modal_sum_of_the_free_free_beam() {
        // Eq. R2 against its eigenfunction expansion (an independent construction): the value
        // kernel converges like N^-3, the slope-value ones like N^-2, the slope-slope like N^-1
        let p = RobotParams::paper();
        let l = p.l;
        let set = ModeSet::new(ModeFamily::FreeFree, 400, &p).unwrap();
        for (x, y) in [
            (0.1, 0.3),
            (0.3, 0.1),
            (0.2, 0.2),
            (0.0, 0.45),
            (0.5, 0.5),
            (0.02, 0.49),
        ] {
            let g = free_free_green(l, x, y);
            let scale = l.powi(3);
            for (k, (dx, dy), tol) in [(0, (0, 0), 1e-9), (1, (1, 0), 1e-6), (2, (0, 1), 1e-6)] {
                let s = modal_sum(&set, x, y, dx, dy);
                let sc = scale / if k > 0 { l } else { 1.0 };
                assert!((g[k] - s).abs() < tol * sc, "({x}, {y}) k {k}: {} vs {s}", g[k]);
            }
            let s = modal_sum(&set, x, y, 1, 1);
            // the slope-slope tail beyond 398 elastic modes is about l / (pi^2 398) of l^2
            assert!((g[3] - s).abs() < 2e-3 * l, "({x}, {y}): {} vs {s}", g[3]);
        }
        // symmetric, as a flexibility must be
        let (a, b) = (free_free_green(l, 0.13, 0.41), free_free_green(l, 0.41, 0.13));
        assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[2]).abs() < 1e-15 && (a[3] - b[3]).abs() < 1e-15);
    }

    /// The sleeve vectors of Eq. R3 for the first `n` modes of `set` at a sleeve centred on `xc`.
    fn sleeve_vectors(set: &ModeSet, xc: f64, hp: f64) -> Vec<Vec<f64>> {
        FUNCTIONALS
            .iter()
            .map(|&(o, d, s)| (0..set.len()).map(|m| s * set.eval(m, xc + o * hp)[d]).collect())
            .collect()
    }

    #[test]
    fn the_truncation_flexibility_is_what_the_modes_left_out_add() {
        // Eq. R3: the compliance left by 30 free-free modes minus the one left by 400 is the
        // modal sum over modes 31..400 (to round-off), and the one left by 400 is small
        let p = RobotParams::paper();
        let (l, hp, xc) = (p.l, 0.5 * p.lp, 0.23);
        let block = |n: usize| {
            let set = ModeSet::new(ModeFamily::FreeFree, n, &p).unwrap();
            let v = sleeve_vectors(&set, xc, hp);
            let mut c = SleeveCompliance::new(l, hp, p.ei(), p.rho, set.lambda());
            (c.block(xc, [&v[0], &v[1], &v[2], &v[3]]), set, v)
        };
        let (r30, _, _) = block(30);
        let (r400, big, v) = block(400);
        let lam = big.lambda();
        for a in 0..4 {
            for b in 0..4 {
                let sum: f64 = (30..400).map(|m| v[a][m] * v[b][m] / (p.rho * lam[m])).sum();
                let scale = (r30[a][a] * r30[b][b]).sqrt();
                assert!(
                    (r30[a][b] - r400[a][b] - sum).abs() < 1e-9 * scale,
                    "R[{a}][{b}]: {:e} - {:e} against modes 31..400: {sum:e}",
                    r30[a][b],
                    r400[a][b]
                );
                // what 400 modes leave is at most their share 30/400 of the slowest kernel
                assert!(r400[a][b].abs() < 0.12 * scale, "R400[{a}][{b}] = {:e}", r400[a][b]);
            }
        }
        // positive definite diagonal: the modes left out store energy
        assert!((0..4).all(|a| r30[a][a] > 0.0 && r400[a][a] > 0.0));
    }
}
