//! Evaluation of every mode at a point by the trigonometric recurrence about nominal roots
//! `pi` apart, and the sleeve triplets of the full model.

use super::*;

impl ModeSet {
    /// All modes at x [m]: `val[m] = phi_m(x)` and, if given, `slope[m] = phi_m'(x)`.
    /// One sin/cos pair and one exponential per elastic mode below beta L = 40, the recurrence of
    /// [`ModeSet::triplet_at`] above; no allocation.
    pub fn values_at(&self, x: f64, val: &mut [f64], mut slope: Option<&mut [f64]>) {
        let xi = x / self.l;
        let s = 1.0 / self.l.sqrt();
        let sd = s / self.l;
        let mut trig = ModeTrig::new(xi, &self.roots);
        for (m, sh) in self.shapes.iter().enumerate() {
            match *sh {
                Shape::Rigid { a, b } => {
                    val[m] = (a + b * xi) * s;
                    if let Some(d) = slope.as_deref_mut() {
                        d[m] = b * sd;
                    }
                }
                Shape::Elastic { bl, c, .. } => {
                    let [sn, cs, e1, e2] = trig.next(m, bl);
                    val[m] = (c[0] * cs + c[1] * sn + c[2] * e1 + c[3] * e2) * s;
                    if let Some(d) = slope.as_deref_mut() {
                        d[m] = bl * (-c[0] * sn + c[1] * cs - c[2] * e1 + c[3] * e2) * sd;
                    }
                }
            }
        }
        let na = self.analytic_len();
        for (j, sh) in self.junction.iter().enumerate() {
            let (p, dp) = junction::poly_value_slope(sh.p, xi);
            val[na + j] = p * s - dot(&sh.c, &val[..na]);
            if let Some(d) = slope.as_deref_mut() {
                d[na + j] = dp * sd - dot(&sh.c, &d[..na]);
            }
        }
    }

    /// The slopes `phi_m'(x)` [1/m^1.5] of every mode at `x` [m], as [`ModeSet::values_at`]
    /// computes them (the set-up of Eq. 23 needs no values).
    pub(super) fn slopes_at(&self, x: f64, slope: &mut [f64]) {
        let xi = x / self.l;
        let sd = 1.0 / (self.l.sqrt() * self.l);
        let mut trig = ModeTrig::new(xi, &self.roots);
        for (m, (sh, d)) in self.shapes.iter().zip(slope.iter_mut()).enumerate() {
            *d = match *sh {
                Shape::Rigid { b, .. } => b * sd,
                Shape::Elastic { bl, c, .. } => {
                    let [sn, cs, e1, e2] = trig.next(m, bl);
                    bl * (-c[0] * sn + c[1] * cs - c[2] * e1 + c[3] * e2) * sd
                }
            };
        }
        let na = self.analytic_len();
        let (analytic, junction) = slope.split_at_mut(na);
        for (sh, d) in self.junction.iter().zip(junction) {
            let (_, dp) = junction::poly_value_slope(sh.p, xi);
            *d = dp * sd - dot(&sh.c, analytic);
        }
    }
}

/// Largest root offset `|delta|` evaluated by the Taylor series of [`ModeTrig`]: the first
/// neglected terms, `x^5 / 120` (sin, exp) and `x^6 / 720` (cos), stay below 1e-17 for `|x| <= 1e-3`.
pub(super) const TAYLOR_DELTA: f64 = 1e-3;

/// The elastic roots `beta_k L = nu_k + delta_k` (k the elastic index) about nominal roots
/// `nu_k = c0 + k pi` exactly `pi` apart. Consecutive roots of every family approach `pi` apart
/// up to `exp(-beta L)` terms, so with `c0` taken from the highest root the offsets `delta_k`
/// fall below 1e-3 after the first one or two modes.
#[derive(Debug, Clone)]
pub(super) struct NominalRoots {
    c0: f64,
    /// `delta` per mode index (0 for the rigid modes, which are not evaluated here).
    pub(super) delta: Vec<f64>,
}

impl NominalRoots {
    pub(super) fn new(shapes: &[Shape]) -> Self {
        let elastic: Vec<(usize, f64)> = shapes
            .iter()
            .enumerate()
            .filter_map(|(m, s)| {
                if let Shape::Elastic { bl, .. } = s {
                    Some((m, *bl))
                } else {
                    None
                }
            })
            .collect();
        let c0 = elastic
            .last()
            .map_or(0.0, |&(_, bl)| bl - (elastic.len() - 1) as f64 * PI);
        let mut delta = vec![0.0; shapes.len()];
        for (k, &(m, bl)) in elastic.iter().enumerate() {
            let d = bl - (c0 + k as f64 * PI);
            // offsets at the level of the roots' own rounding are exactly zero (no correction)
            delta[m] = if d.abs() <= 1e-14 * bl { 0.0 } else { d };
        }
        NominalRoots { c0, delta }
    }
}

/// `exp(-x)` for `|x| <= TAYLOR_DELTA`, to round-off.
#[inline]
pub(super) fn exp_neg_small(x: f64) -> f64 {
    1.0 - x * (1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0))))
}

/// `sin(b xi)`, `cos(b xi)`, `exp(-b xi)`, `exp(-b (1 - xi))` of the elastic modes in order.
/// The nominal roots `nu_k` ([`NominalRoots`]) advance by one rotation by `pi xi` and two products
/// per mode; the offset `delta_k xi` is added by the angle-addition formulas with a Taylor series
/// (to round-off for `|delta| <= TAYLOR_DELTA`), and a mode with a larger offset (the first one
/// or two of some families) is evaluated directly. Two `sin_cos` and four `exp` per point instead
/// of one each per mode; the recurrence's rounding grows like k eps (2e-14 at N = 200, checked
/// against direct evaluation at N = 400 in the tests).
pub(super) struct ModeTrig<'r> {
    pub(super) roots: &'r NominalRoots,
    pub(super) xi: f64,
    pub(super) rot: (f64, f64),
    pub(super) q: (f64, f64),
    /// The four values at the next nominal root.
    pub(super) nominal: [f64; 4],
}

impl<'r> ModeTrig<'r> {
    pub(super) fn new(xi: f64, roots: &'r NominalRoots) -> Self {
        let c0 = roots.c0;
        let (s0, co) = (c0 * xi).sin_cos();
        ModeTrig {
            roots,
            xi,
            rot: (PI * xi).sin_cos(),
            q: ((-PI * xi).exp(), (-PI * (1.0 - xi)).exp()),
            nominal: [s0, co, (-c0 * xi).exp(), (-c0 * (1.0 - xi)).exp()],
        }
    }

    /// The four values for mode `m` with root `bl`; elastic modes must come in order.
    #[inline]
    pub(super) fn next(&mut self, m: usize, bl: f64) -> [f64; 4] {
        self.advance(self.roots.delta[m], bl)
    }

    /// [`ModeTrig::next`] for the next elastic mode, given its root offset `d` and root `bl`.
    #[inline(always)]
    pub(super) fn advance(&mut self, d: f64, bl: f64) -> [f64; 4] {
        let [sn, cs, e1, e2] = self.nominal;
        let (rs, rc) = self.rot;
        let tiny = |e: f64, f: f64| if e > 1e-290 { e * f } else { 0.0 };
        self.nominal = [
            sn * rc + cs * rs,
            cs * rc - sn * rs,
            tiny(e1, self.q.0),
            tiny(e2, self.q.1),
        ];
        if d == 0.0 {
            [sn, cs, e1, e2]
        } else if d.abs() <= TAYLOR_DELTA {
            let x = d * self.xi;
            let x2 = x * x;
            let (sx, cx) = (x * (1.0 - x2 * (1.0 / 6.0)), 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0)));
            [
                sn * cx + cs * sx,
                cs * cx - sn * sx,
                e1 * exp_neg_small(x),
                e2 * exp_neg_small(d * (1.0 - self.xi)),
            ]
        } else {
            let (sn, cs) = (bl * self.xi).sin_cos();
            [sn, cs, (-bl * self.xi).exp(), (-bl * (1.0 - self.xi)).exp()]
        }
    }
}

/// Output slices of [`elastic_triplets`], all of the elastic modes' length.
pub(super) struct TripletOut<'o> {
    pub(super) left: &'o mut [f64],
    pub(super) mid: &'o mut [f64],
    pub(super) right: &'o mut [f64],
    pub(super) slope: &'o mut [f64],
}

/// The elastic part of [`ModeSet::triplet_at`]: values at `x - h`, `x`, `x + h` and the slope at
/// `x` (unscaled by `s`, `sd` until stored), and with `BENT` the sums
/// `bend += [sum a_m phi_m'(x - h), sum a_m phi_m'(x + h), sum a_m phi_m''(x)]` over the elastic
/// modes (in units of `sd`, `sd`, `sd / L`). One pass over modes read in order, no bounds checks.
#[inline(never)]
pub(super) fn elastic_triplets<const BENT: bool>(
    tri: &Triplet,
    mut trig: ModeTrig<'_>,
    out: TripletOut<'_>,
    alpha_eff: &[f64],
    s: f64,
    sd: f64,
    bend: &mut [f64; 3],
) {
    let n = out.mid.len();
    let (bl, c, f, delta) = (&tri.bl[..n], &tri.c[..n], &tri.f[..n], &tri.delta[..n]);
    let (left, mid, right, slope) = (
        &mut out.left[..n],
        &mut out.mid[..n],
        &mut out.right[..n],
        &mut out.slope[..n],
    );
    let alpha_eff = if BENT { &alpha_eff[..n] } else { &[][..] };
    let (mut sl, mut sr, mut cv) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let b = bl[k];
        let [sn, cs, e1, e2] = trig.advance(delta[k], b);
        let [c0, c1, c2, c3] = c[k];
        let [f0, f1, f2, f3] = f[k];
        let p = c0 * cs + c1 * sn;
        let q = c1 * cs - c0 * sn;
        let (g1, g2) = (c2 * e1, c3 * e2);
        mid[k] = (p + g1 + g2) * s;
        slope[k] = b * (q - g1 + g2) * sd;
        let (pc, qs) = (p * f0, q * f1);
        right[k] = (pc + qs + g1 * f2 + g2 * f3) * s;
        left[k] = (pc - qs + g1 * f3 + g2 * f2) * s;
        if BENT {
            let (qc, ps) = (q * f0, p * f1);
            let ba = b * alpha_eff[k];
            sr += ba * (qc - ps - g1 * f2 + g2 * f3);
            sl += ba * (qc + ps - g1 * f3 + g2 * f2);
            cv += b * ba * (g1 + g2 - p);
        }
    }
    bend[0] += sl;
    bend[1] += sr;
    bend[2] += cv;
}

/// Precomputed per-mode factors for evaluating the modes at `x - h`, `x`, `x + h` together
/// (the sleeve points of Eqs. 41-43, `h = Lp/2` fixed): `[cos(beta h), sin(beta h), exp(-beta h), exp(beta h)]`.
#[derive(Debug, Clone)]
pub(crate) struct Triplet {
    h: f64,
    /// Per elastic mode (in order, after the rigid ones): the factors above.
    pub(super) f: Vec<[f64; 4]>,
    /// Per elastic mode: beta L, the stable-basis coefficients and the root offset (see
    /// [`NominalRoots`]), gathered so that the kernel reads them in order.
    pub(super) bl: Vec<f64>,
    pub(super) c: Vec<[f64; 4]>,
    pub(super) delta: Vec<f64>,
}

impl Triplet {
    /// The half-width h [m] (half the sleeve length).
    pub(crate) fn half_length(&self) -> f64 {
        self.h
    }
}

impl ModeSet {
    /// Factors for [`ModeSet::triplet_at`] with half-width `h` [m].
    pub(crate) fn triplet(&self, h: f64) -> Triplet {
        let eta = h / self.l;
        let mut tri = Triplet {
            h,
            f: Vec::new(),
            bl: Vec::new(),
            c: Vec::new(),
            delta: Vec::new(),
        };
        for (m, sh) in self.shapes.iter().enumerate() {
            if let Shape::Elastic { bl, c, .. } = *sh {
                let (sn, cs) = (bl * eta).sin_cos();
                tri.f.push([cs, sn, (-bl * eta).exp(), (bl * eta).exp()]);
                tri.bl.push(bl);
                tri.c.push(c);
                tri.delta.push(self.roots.delta[m]);
            }
        }
        tri
    }

    /// `phi_m(x - h)`, `phi_m(x)`, `phi_m(x + h)` and `phi_m'(x)` for every mode [1/sqrt(m),
    /// 1/m^1.5], by angle addition with the factors of `tri`, the sin, cos and exponentials at x
    /// coming from the nominal-root recurrence of [`ModeTrig`] (two `sin_cos` and four `exp` per
    /// call). Needs `0 <= x - h`, `x + h <= L`. With `bent = (alpha, out)`, also the beam's
    /// bending at the sleeve, `w'(x - h)`, `w'(x + h)` and `w''(x)` for `w = sum alpha_m phi_m`
    /// (the full model's gradients of the sleeve rows in u, `docs/amm.md` section 8).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn triplet_at(
        &self,
        tri: &Triplet,
        x: f64,
        left: &mut [f64],
        mid: &mut [f64],
        right: &mut [f64],
        slope: &mut [f64],
        bent: Option<(&[f64], &mut SleeveBending)>,
    ) {
        let at = TripletPoint::new(self, tri, x);
        let bent = bent.map(|(alpha, bn)| {
            self.fold_junction(alpha, bn);
            (alpha, bn)
        });
        let mut bend = self.rigid_triplet(
            &at,
            [left, mid, right, slope],
            bent.as_ref().map(|b| &b.1.alpha_eff[..]),
        );
        let (r0, na) = (self.rigid, self.analytic_len());
        let out = TripletOut {
            left: &mut left[r0..na],
            mid: &mut mid[r0..na],
            right: &mut right[r0..na],
            slope: &mut slope[r0..na],
        };
        let trig = ModeTrig::new(at.xi, &self.roots);
        let (s, sd) = (at.s, at.sd);
        match bent.as_ref() {
            Some((_, bn)) => elastic_triplets::<true>(tri, trig, out, &bn.alpha_eff[r0..na], s, sd, &mut bend),
            None => elastic_triplets::<false>(tri, trig, out, &[], s, sd, &mut bend),
        }
        self.junction_triplet(&at, [left, mid, right, slope], bent, bend);
    }

    /// [`ModeSet::triplet_at`] with the bending for three beams on this set (equal beams): beam
    /// i's sleeve at `x[i]` [m], its outputs `out[i] = [left, mid, right, slope]` and `bent[i]`.
    /// The elastic modes run in the lanes of AVX where the processor has it (`lanes`: the same
    /// values bit for bit), else beam by beam.
    pub(crate) fn triplets_at3(
        &self,
        tri: &Triplet,
        x: [f64; 3],
        out: [[&mut [f64]; 4]; 3],
        bent: [(&[f64], &mut SleeveBending); 3],
    ) {
        #[cfg(target_arch = "x86_64")]
        if lanes::available() {
            let (mut out, mut bent) = (out, bent);
            let at = x.map(|x| TripletPoint::new(self, tri, x));
            let (r0, na) = (self.rigid, self.analytic_len());
            let mut bend = [[0.0; 3]; 3];
            for (i, (o, (alpha, bn))) in out.iter_mut().zip(bent.iter_mut()).enumerate() {
                self.fold_junction(alpha, bn);
                let [l, m, r, d] = o;
                bend[i] = self.rigid_triplet(&at[i], [l, m, r, d], Some(&bn.alpha_eff[..]));
            }
            {
                let kernel_out = out.each_mut().map(|[l, m, r, d]| TripletOut {
                    left: &mut l[r0..na],
                    mid: &mut m[r0..na],
                    right: &mut r[r0..na],
                    slope: &mut d[r0..na],
                });
                let trig = at.each_ref().map(|a| ModeTrig::new(a.xi, &self.roots));
                let alpha_eff = bent.each_ref().map(|b| &b.1.alpha_eff[r0..na]);
                // SAFETY: the processor has AVX (lanes::available, just above)
                unsafe {
                    lanes::elastic_triplets_x3(tri, trig, kernel_out, alpha_eff, (at[0].s, at[0].sd), &mut bend);
                }
            }
            for (i, (o, b)) in out.into_iter().zip(bent).enumerate() {
                self.junction_triplet(&at[i], o, Some(b), bend[i]);
            }
            return;
        }
        for (i, ([l, m, r, d], (alpha, bn))) in out.into_iter().zip(bent).enumerate() {
            self.triplet_at(tri, x[i], l, m, r, d, Some((alpha, bn)));
        }
    }

    /// The bending outputs are dot products with the beam's modal coordinates; the junction
    /// shapes' parts fold into effective coordinates of the analytic modes:
    /// `sum_m v_m a_m + sum_j v_(na+j) a_(na+j)` with `v_(na+j) = P_j - c_j . v`
    /// is `sum_m v_m (a_m - sum_j a_(na+j) c_jm) + sum_j a_(na+j) P_j`: `bn.alpha_eff`.
    fn fold_junction(&self, alpha: &[f64], bn: &mut SleeveBending) {
        let na = self.analytic_len();
        bn.alpha_eff.copy_from_slice(&alpha[..na]);
        for (j, sh) in self.junction.iter().enumerate() {
            let aj = alpha[na + j];
            for (e, c) in bn.alpha_eff.iter_mut().zip(&sh.c) {
                *e -= aj * c;
            }
        }
    }

    /// The rigid modes (first) of [`ModeSet::triplet_at`] into `[left, mid, right, slope]`, and
    /// their bending sums (with `alpha_eff`), in units of `sd` (the elastic kernel's).
    fn rigid_triplet(
        &self,
        at: &TripletPoint,
        [left, mid, right, slope]: [&mut [f64]; 4],
        alpha_eff: Option<&[f64]>,
    ) -> [f64; 3] {
        let (xi, eta, s, sd) = (at.xi, at.eta, at.s, at.sd);
        let mut bend = [0.0; 3];
        for (m, sh) in self.shapes[..self.rigid].iter().enumerate() {
            if let Shape::Rigid { a, b } = *sh {
                mid[m] = (a + b * xi) * s;
                left[m] = (a + b * (xi - eta)) * s;
                right[m] = (a + b * (xi + eta)) * s;
                slope[m] = b * sd;
                if let Some(alpha_eff) = alpha_eff {
                    bend[0] += b * alpha_eff[m];
                    bend[1] += b * alpha_eff[m];
                }
            }
        }
        bend
    }

    /// The junction shapes (last) of [`ModeSet::triplet_at`], from the analytic modes' values
    /// already in `[left, mid, right, slope]`, and the bending's end: the sums `bend` of the
    /// analytic modes with the junction shapes' own parts, scaled into `bent`.
    fn junction_triplet(
        &self,
        at: &TripletPoint,
        [left, mid, right, slope]: [&mut [f64]; 4],
        bent: Option<(&[f64], &mut SleeveBending)>,
        [mut sl, mut sr, mut cv]: [f64; 3],
    ) {
        let (xi, eta, s, sd) = (at.xi, at.eta, at.s, at.sd);
        let na = self.analytic_len();
        for (j, sh) in self.junction.iter().enumerate() {
            let c = &sh.c[..];
            let at = |z: f64| junction::poly_value_slope(sh.p, z);
            let ((pl, dl), (pm, dm), (pr, dr)) = (at(xi - eta), at(xi), at(xi + eta));
            left[na + j] = pl * s - dot(c, &left[..na]);
            mid[na + j] = pm * s - dot(c, &mid[..na]);
            right[na + j] = pr * s - dot(c, &right[..na]);
            slope[na + j] = dm * sd - dot(c, &slope[..na]);
            if let Some((alpha, _)) = bent.as_ref() {
                let aj = alpha[na + j];
                sl += aj * dl;
                sr += aj * dr;
                cv += aj * junction::poly_curvature(sh.p, xi);
            }
        }
        if let Some((_, bn)) = bent {
            // the analytic parts carry the factor sd (slopes) and sd / L (curvature) as well
            bn.slope_left = sl * sd;
            bn.slope_right = sr * sd;
            bn.curvature = cv * sd / self.l;
        }
    }
}

/// The point of a sleeve triplet on a beam: `xi = x / L`, `eta = h / L` and the scales
/// `s = 1 / sqrt(L)`, `sd = s / L` of the values and slopes.
struct TripletPoint {
    xi: f64,
    eta: f64,
    s: f64,
    sd: f64,
}

impl TripletPoint {
    fn new(modes: &ModeSet, tri: &Triplet, x: f64) -> Self {
        let s = 1.0 / modes.l.sqrt();
        TripletPoint {
            xi: x / modes.l,
            eta: tri.h / modes.l,
            s,
            sd: s / modes.l,
        }
    }
}

/// The full model's bending of one beam at its sleeve (see [`ModeSet::triplet_at`]): with
/// `w = sum alpha_m phi_m`, the slopes `w'(x - h)`, `w'(x + h)` [-] and the curvature `w''(x)`
/// [1/m] (the gradients of the sleeve rows in u, `docs/amm.md` section 8).
#[derive(Debug, Clone, Default)]
pub(crate) struct SleeveBending {
    pub(crate) slope_left: f64,
    pub(crate) slope_right: f64,
    pub(crate) curvature: f64,
    /// Workspace: the modal coordinates of the analytic modes with the junction shapes' parts folded in.
    alpha_eff: Vec<f64>,
}

impl SleeveBending {
    /// Workspace for a set whose analytic modes number `n_analytic`.
    pub(crate) fn new(n_analytic: usize) -> Self {
        SleeveBending {
            alpha_eff: vec![0.0; n_analytic],
            ..SleeveBending::default()
        }
    }
}
