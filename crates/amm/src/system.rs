//! The constrained linear time-varying system of the AMM (Eqs. 30-32, 37, 44 with the constraints
//! of Eqs. 38-43) and its per-step linear solve.
//!
//! Unknowns of beam i (block of N + 2): modal coordinates `alpha_i` (N), axial displacement
//! `u_i = x_iG` and sleeve rotation `thp_i`. With orthonormal modes,
//!
//! ```text
//! M q'' + D(t) q' + K(t) q = f(t) + C(t)^T lambda,      C(t) q = 0
//! ```
//! per beam (alpha rows j, u row, thp row; Phi_j = int phi_j, Psi_j = int x phi_j):
//!
//! ```text
//! rho [alpha_j'' + (lambda_j - th'^2) alpha_j + (u th'' + 2 u' th') Phi_j] = -rho (a_G.e_w Phi_j + th'' Psi_j) + (C^T lambda)_j   (Eq. 37)
//! rho [L u'' - L th'^2 u - 2 th' Phi.alpha' - th'' Phi.alpha]     = -rho (L a_G.e_x - th'^2 L^2/2) + (C^T lambda)_u      (Eqs. 30, 44)
//! Jp thp''                                                        = -Jp th''                        + (C^T lambda)_thp    (Eq. 31)
//! ```
//! The step matrix `S = M + gamma' D + beta' K` of one beam is an arrowhead: diagonal in alpha,
//! `d_j = rho (1 + beta' (lambda_j - th'^2))`, bordered by the u row and column (`-p Phi_m`,
//! `+p Phi_j`, `p = rho (2 gamma' th' + beta' th'')`), and `Jp` for thp. It is the same for the
//! three beams (it depends on th only) and is solved in O(N). The constraints (at most 18 rows)
//! are eliminated by the Schur complement `A = C S^-1 C^T`, a small dense LU per step.

use flexstar_kinematics::RigidState;
use flexstar_model::{AmmModel, Damping, LoadSettings, Payload, RobotParams};

use crate::star::Weld;

use crate::attach::{Mat3, PayloadTerms, RigidTerms};
use crate::constraint_lu::{ConstraintLu, MAX_JUNCTION_ROWS};
use crate::error::{AmmError, RankError};
use crate::foreshortening::{Foreshortening, KEPT_ANALYTIC};
use crate::friction::SleeveFriction;
use crate::geometric::{self, GeometricStiffness};
use crate::modes::{dot, ModeSet};
use crate::sleeve::near::SleevesNear;
use crate::sleeve::{SleeveRow, Sleeves, B_MID, B_MSLOPE, SLEEVE_ROWS};
use crate::third_order::{self, ThirdOrderTerms};
use flexstar_numerics::vector::dots;

mod kkt;

/// One constraint row and its multiplier (`docs/amm.md` section 1; Eqs. 24-29, 38-43). Beams are
/// 0-based here. The multiplier is the generalized force on the beam for the row as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Row {
    /// Eq. 38: `u_i - (w_{i+2,G} - w_{i+1,G}) / sqrt3 = 0` (Eq. J4 for other welds, `docs/amm.md`
    /// 13); multiplier `F_ix` (axial force at G).
    Fix(usize),
    /// Eq. 40: `w_1G + w_2G + w_3G = 0` (Eq. J5: `sum c_i w_iG = 0` for other welds); multiplier `Fw`.
    Fw,
    /// Eqs. F16, F23 (`docs/friction.md` 9): sleeve i stuck on its beam, its material
    /// coordinate held, `xi_i(q) = xp_i(t) - u_i + f_i(x_c) = xi_i*` (u coefficient 1, alpha part
    /// `-g_i` on [`B_STICK`] in the full model); multiplier the friction force on beam i along
    /// its axis [N]. Only with friction; empty (its multiplier 0) while the sleeve is not stuck
    /// (`crate::friction`).
    Stick(usize),
    /// Eq. 39: `w_1'(0) - w_2'(0) = 0`; multiplier `M1G`.
    M1G,
    /// Eq. 39: `w_3'(0) - w_2'(0) = 0`; multiplier `M3G`.
    M3G,
    /// Eqs. 41-43: row `row` of sleeve i (`crate::sleeve::rows`): `w_i(xp_i) = 0` (`Fp_i`),
    /// `w_i(xp_i +- Lp/2) -+ Lp/2 thp_i = 0` (`FR_pi`, `FL_pi`), `thp_i - w_i'(xp_i) = 0` (`Mp_i`).
    Sleeve(usize, SleeveRow),
}

/// Basis vectors of the alpha parts of the constraint rows of one beam: every row's alpha part is
/// one of them times a scalar. The junction's two here, then the sleeve's four, `B_MID` (Fp),
/// `B_RIGHT` (FR), `B_LEFT` (FL), `B_MSLOPE` (Mp) of `crate::sleeve::rows`.
const B_PHI0: usize = 0; // phi_j(0)          (Fix, Fw)
const B_DPHI0: usize = 1; // phi_j'(0)        (MiG)
/// Basis vector of a stuck sleeve's row (Eq. F16, `docs/friction.md` 9.1): `-g`, the gradient of
/// the material coordinate's foreshortening shift (full model; zero in the paper's model and
/// while the sleeve is not stuck). Only a system with friction has it ([`BeamRows::stick`]).
pub(crate) const B_STICK: usize = B_MSLOPE + 1;
const NB: usize = B_STICK + 1;
/// Most constraint rows that touch one beam (three Fix, Fw, two slope rows, four sleeve rows,
/// and with friction the stick row of Eq. F16, `docs/friction.md` 9).
const MAX_BEAM_ROWS: usize = MAX_JUNCTION_ROWS + SLEEVE_ROWS + 1;
/// "This row has no alpha part."
pub(crate) const NONE: usize = usize::MAX;

/// A row of the form of [`BeamRows`]: (basis vector, its factor, u coefficient, thp coefficient).
pub(crate) type RowForm = (usize, f64, f64, f64);

/// The payload's three rows P of Eq. P1 in that form: `u_1`, `phi(0) . alpha_1`, `phi'(0) . alpha_1`.
const PAYLOAD_ROWS: [RowForm; 3] = [(NONE, 0.0, 1.0, 0.0), (B_PHI0, 1.0, 0.0, 0.0), (B_DPHI0, 1.0, 0.0, 0.0)];

/// The rows of C that touch one beam: row k is `sc[k] * B[basis[k]]` on alpha, `cu[k]` on u_i and
/// `ct[k]` on thp_i. The sleeve's rows are refreshed per step by `crate::sleeve::Sleeves::update`.
#[derive(Debug, Clone, Default)]
pub(crate) struct BeamRows {
    /// Global row index of each local row.
    pub(crate) ids: Vec<usize>,
    pub(crate) basis: Vec<usize>,
    pub(crate) sc: Vec<f64>,
    /// Gradient of the row in u_i (the Jacobian column; per step for the full model's sleeve rows).
    pub(crate) cu: Vec<f64>,
    /// Coefficient of u_i in the row's own value (1 for the Fix rows; 0 for the sleeve rows, where
    /// u_i enters the full model only through the material point xp_i - u_i).
    pub(crate) gu: Vec<f64>,
    pub(crate) ct: Vec<f64>,
    /// The part of each row's value at the predictor that its Jacobian entries do not give:
    /// `r(qhat) - c . qhat` (0 but for the full model's sleeve rows, Eqs. S3-S4 of `docs/amm.md`
    /// 12.11, where the gradient carries the foreshortening and the edges turn by `sin thp`).
    pub(crate) gv: Vec<f64>,
    /// The sleeve basis vectors B_MID..B_MSLOPE of this beam (refreshed per step), N each.
    pub(crate) sleeve: [Vec<f64>; 4],
    /// The stick row's basis vector [`B_STICK`] (set per step by `crate::friction`), N; empty
    /// without friction (no [`B_STICK`] row, nothing computed for it).
    pub(crate) stick: Vec<f64>,
    /// `D^-1 B_STICK` (empty without friction).
    stick_scaled: Vec<f64>,
    /// Whether [`BeamRows::stick`] may be nonzero this step (a stuck sleeve of the full model,
    /// whose row carries the foreshortening's modal part): otherwise its Gram entries and dot
    /// products are zero and are not computed (set per step by `crate::friction`).
    pub(crate) stick_live: bool,
    // per-step workspace
    /// `D^-1 B_a` for the sleeve vectors.
    scaled: [Vec<f64>; 4],
    /// Gram matrix `B_a . D^-1 B_b` of the six basis vectors.
    gram: [[f64; NB]; NB],
    /// `B_a . D^-1 Phi`.
    g: [f64; NB],
}

impl BeamRows {
    /// The products of this beam's rows with the payload's rows P (Eq. P1) at the prepared step:
    /// `H = P S^-1 P^T`, `C S^-1 P^T` (row k: `cross[k]`) and `P S^-1 C^T` (column k: `back[k]`),
    /// by the formula of [`BeamRows::add_block`], `c_k S^-1 c_s^T = (cu_k - p g_k)(cu_s + p g_s)
    /// / sigma + ct_k ct_s / Jp + sc_k sc_s gram[b_k][b_s]` (P has no thp part, so no Jp term).
    #[allow(clippy::type_complexity)]
    fn payload_products(&self, p: f64, inv_sigma: f64) -> (Mat3, [[f64; 3]; MAX_BEAM_ROWS], [[f64; 3]; MAX_BEAM_ROWS]) {
        let (g0, g1) = (self.g[B_PHI0], self.g[B_DPHI0]);
        // the u-elimination factors of the rows u_1, phi(0) . alpha_1, phi'(0) . alpha_1
        let left = [inv_sigma, -p * g0 * inv_sigma, -p * g1 * inv_sigma];
        let right = [1.0, p * g0, p * g1];
        let basis = [NONE, B_PHI0, B_DPHI0];
        let mut h = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                let gram = if a > 0 && b > 0 {
                    self.gram[basis[a]][basis[b]]
                } else {
                    0.0
                };
                h[a][b] = left[a] * right[b] + gram;
            }
        }
        let (mut cross, mut back) = ([[0.0; 3]; MAX_BEAM_ROWS], [[0.0; 3]; MAX_BEAM_ROWS]);
        for k in 0..self.ids.len() {
            let (bk, sk) = (self.basis[k], self.sc[k]);
            let gk = if bk == NONE { 0.0 } else { sk * self.g[bk] };
            let (lk, rk) = ((self.cu[k] - p * gk) * inv_sigma, self.cu[k] + p * gk);
            for a in 0..3 {
                // the Gram matrix is symmetric: one entry for both products
                let gram = if bk != NONE && a > 0 {
                    sk * self.gram[bk][basis[a]]
                } else {
                    0.0
                };
                cross[k][a] = lk * right[a] + gram;
                back[k][a] = left[a] * rk + gram;
            }
        }
        (h, cross, back)
    }

    /// The Gram matrix `B D^-1 B^T` of this beam's six vectors and `g = B D^-1 Phi` (see
    /// [`System::prepare`]): the junction entries `[g00, g01, g11]` and `[w0, w1]` are shared by
    /// the beams, the sleeve vectors are scaled by `inv_d` here.
    fn fill_gram(
        &mut self,
        [g00, g01, g11]: [f64; 3],
        [w0, w1]: [f64; 2],
        inv_d: &[f64],
        [phi0, dphi0, phi]: [&[f64]; 3],
    ) {
        for (sv, v) in self.scaled.iter_mut().zip(&self.sleeve) {
            for ((s, x), d) in sv.iter_mut().zip(v).zip(inv_d) {
                *s = x * d;
            }
        }
        let gram = &mut self.gram;
        gram[B_PHI0][B_PHI0] = g00;
        gram[B_PHI0][B_DPHI0] = g01;
        gram[B_DPHI0][B_PHI0] = g01;
        gram[B_DPHI0][B_DPHI0] = g11;
        for a in 0..4 {
            let ([p0, d0, gp], m) = sleeve_gram_row(&self.scaled[a], a, [phi0, dphi0, phi], &self.sleeve);
            gram[B_MID + a][B_PHI0] = p0;
            gram[B_MID + a][B_DPHI0] = d0;
            gram[B_PHI0][B_MID + a] = p0;
            gram[B_DPHI0][B_MID + a] = d0;
            for (b, v) in m.into_iter().enumerate().skip(a) {
                gram[B_MID + a][B_MID + b] = v;
                gram[B_MID + b][B_MID + a] = v;
            }
            self.g[B_MID + a] = gp;
        }
        self.g[B_PHI0] = w0;
        self.g[B_DPHI0] = w1;
        if self.stick_live {
            self.fill_stick_gram(inv_d, [phi0, dphi0, phi]);
        } else if !self.stick.is_empty() {
            // a zero stick vector: its Gram row, column and g are zero (the last step may have
            // left them set)
            for b in 0..NB {
                self.gram[B_STICK][b] = 0.0;
                self.gram[b][B_STICK] = 0.0;
            }
            self.g[B_STICK] = 0.0;
        }
    }

    /// The Gram entries of the stick row's vector [`B_STICK`] against the other six and itself,
    /// and its `g` (`docs/friction.md` 9.1, Eq. F16); a system with friction only.
    fn fill_stick_gram(&mut self, inv_d: &[f64], [phi0, dphi0, phi]: [&[f64]; 3]) {
        for ((s, x), d) in self.stick_scaled.iter_mut().zip(&self.stick).zip(inv_d) {
            *s = x * d;
        }
        let [s0, s1, s2, s3] = [&self.sleeve[0], &self.sleeve[1], &self.sleeve[2], &self.sleeve[3]];
        let [p0, d0, gp, m0, m1, m2, m3, ss] =
            dots(&self.stick_scaled, [phi0, dphi0, phi, s0, s1, s2, s3, &self.stick]);
        // against B_PHI0, B_DPHI0, B_MID, B_RIGHT, B_LEFT, B_MSLOPE in that order
        for (b, v) in [p0, d0, m0, m1, m2, m3].into_iter().enumerate() {
            self.gram[B_STICK][b] = v;
            self.gram[b][B_STICK] = v;
        }
        self.gram[B_STICK][B_STICK] = ss;
        self.g[B_STICK] = gp;
    }

    /// Add this beam's block of the Schur complement to `a_mat` (m x m, row-major):
    /// `A_ks = (cu_k - p g_k)(cu_s + p g_s) / sigma + ct_k ct_s / Jp + sc_k sc_s gram[b_k][b_s]`,
    /// with the rows without an alpha part (basis NONE) given g = 0 and a zero Gram row.
    fn add_block(&self, a_mat: &mut [f64], m: usize, p: f64, inv_sigma: f64, inv_jp: f64) {
        let mb = self.ids.len();
        let mut left = [0.0; MAX_BEAM_ROWS];
        let mut right = [0.0; MAX_BEAM_ROWS];
        let mut gram_rows = [[0.0; MAX_BEAM_ROWS]; NB];
        for k in 0..mb {
            let (bk, sk) = (self.basis[k], self.sc[k]);
            let gk = if bk == NONE { 0.0 } else { sk * self.g[bk] };
            left[k] = (self.cu[k] - p * gk) * inv_sigma;
            right[k] = self.cu[k] + p * gk;
            if bk != NONE {
                for (a, row) in gram_rows.iter_mut().enumerate() {
                    row[k] = sk * self.gram[a][bk];
                }
            }
        }
        let (ids, ct) = (&self.ids[..mb], &self.ct[..mb]);
        let zero = [0.0; MAX_BEAM_ROWS];
        for k in 0..mb {
            let (bk, sk) = (self.basis[k], self.sc[k]);
            let (ctk, left_k) = (ct[k] * inv_jp, left[k]);
            let a_row = &mut a_mat[ids[k] * m..(ids[k] + 1) * m];
            let gram_k = if bk == NONE { &zero } else { &gram_rows[bk] };
            // the same sums as entry by entry, without a bounds check but a_row's
            let terms = ids.iter().zip(&right[..mb]).zip(ct).zip(&gram_k[..mb]);
            for (((&col, &right_s), &ct_s), &gram_ks) in terms {
                a_row[col] += left_k * right_s + ctk * ct_s + sk * gram_ks;
            }
        }
    }
}

/// Row `a` of the sleeve vectors' part of the Gram data ([`BeamRows::fill_gram`]): the products
/// of `D^-1 B_a` (`scaled`) with the junction vectors and Phi (`[phi(0), phi'(0), Phi]`) and with
/// the sleeve vectors `B_b`, b >= a (those with b < a are the symmetric repeats of earlier rows:
/// left 0). One pass over `scaled` (`dots`: each product's sum is the same whatever the others).
fn sleeve_gram_row(
    scaled: &[f64],
    a: usize,
    [phi0, dphi0, phi]: [&[f64]; 3],
    sleeve: &[Vec<f64>; 4],
) -> ([f64; 3], [f64; 4]) {
    let [s0, s1, s2, s3] = [&sleeve[0][..], &sleeve[1], &sleeve[2], &sleeve[3]];
    match a {
        0 => {
            let [p, d, g, m0, m1, m2, m3] = dots(scaled, [phi0, dphi0, phi, s0, s1, s2, s3]);
            ([p, d, g], [m0, m1, m2, m3])
        }
        1 => {
            let [p, d, g, m1, m2, m3] = dots(scaled, [phi0, dphi0, phi, s1, s2, s3]);
            ([p, d, g], [0.0, m1, m2, m3])
        }
        2 => {
            let [p, d, g, m2, m3] = dots(scaled, [phi0, dphi0, phi, s2, s3]);
            ([p, d, g], [0.0, 0.0, m2, m3])
        }
        _ => {
            let [p, d, g, m3] = dots(scaled, [phi0, dphi0, phi, s3]);
            ([p, d, g], [0.0, 0.0, 0.0, m3])
        }
    }
}

/// One beam's modes and data, and its arrowhead of the step matrix (`docs/amm.md` 13, Eqs. J1-J2):
/// shared by the three beams when they are equal.
#[derive(Debug, Clone)]
pub(crate) struct BeamModel {
    /// The beam's mode set (Eq. J1).
    pub(crate) modes: ModeSet,
    /// Mass per length rho_i [kg/m].
    pub(crate) rho: f64,
    /// Length L_i [m].
    pub(crate) l: f64,
    /// Sleeve inertia Jp_i [kg m^2].
    pub(crate) jp: f64,
    /// Eigenvalues lambda_m [1/s^2].
    pub(crate) lambda_m: Vec<f64>,
    /// `Phi_m = int phi_m` [m^0.5].
    pub(crate) phi: Vec<f64>,
    /// `Psi_m = int x phi_m` [m^1.5].
    pub(crate) psi: Vec<f64>,
    /// `phi_m(0)` [m^-0.5].
    pub(crate) phi0: Vec<f64>,
    /// `phi_m'(0)` [m^-1.5].
    pub(crate) dphi0: Vec<f64>,
    /// `phi_m(L)` [m^-0.5].
    pub(crate) phil: Vec<f64>,
    /// Full model: the axial flexibility `L / (3 EA)` [m/N] (Eq. A2); 0 in the paper's model.
    axial_flex: f64,
    /// The viscous sleeve friction on the u diagonal of the step matrix, `c gamma'` [kg]
    /// (Eq. F14, `docs/friction.md` 9); 0 without it.
    pub(crate) u_drag: f64,
    // arrowhead data of the step (Eq. J2), per step
    /// The thp diagonal of the step matrix, `Jp (1 + gamma' alpha)` (Eq. D19).
    jp_step: f64,
    /// The alpha diagonal `d_j` of the step matrix, and its inverse.
    d: Vec<f64>,
    inv_d: Vec<f64>,
    w: Vec<f64>,
    p: f64,
    inv_sigma: f64,
    /// The u diagonal of the step matrix, `rho L (1 + gamma' alpha - beta' th'^2)` plus the
    /// sleeve's viscous drag (before the border's elimination into `inv_sigma`).
    suu: f64,
    scaled0: [Vec<f64>; 2],
    /// The junction vectors' Gram entries `[g00, g01, g11]` and `[w0, w1]` of the step.
    jgram: [f64; 3],
    jw: [f64; 2],
    /// The inputs of the last [`BeamModel::factor`] (bits of `bp, gp, th', th'', alpha, beta`
    /// and the drag), on which alone its data depend: a call with the same ones keeps them
    /// (a rigid rate that stays, as at rest, or every direction of a tangent at one state).
    factored_for: Option<[u64; 7]>,
}

impl BeamModel {
    fn new(modes: ModeSet, params: &RobotParams, model: AmmModel) -> Self {
        let nm = modes.len();
        let l = params.l;
        let (phi0, dphi0, phil) = end_values(&modes, l);
        BeamModel {
            rho: params.rho,
            l,
            jp: params.jp,
            lambda_m: modes.lambda().to_vec(),
            phi: modes.phi_integral().to_vec(),
            psi: modes.x_phi_integral().to_vec(),
            phi0,
            dphi0,
            phil,
            axial_flex: match model {
                AmmModel::Full => l / (3.0 * params.ea()),
                AmmModel::Paper => 0.0,
            },
            jp_step: params.jp,
            u_drag: 0.0,
            d: vec![0.0; nm],
            inv_d: vec![0.0; nm],
            w: vec![0.0; nm],
            p: 0.0,
            inv_sigma: 0.0,
            suu: 0.0,
            scaled0: [vec![0.0; nm], vec![0.0; nm]],
            jgram: [0.0; 3],
            jw: [0.0; 2],
            factored_for: None,
            modes,
        }
    }

    /// Arrowhead data of `S = M + gamma' D + beta' K` (Eq. J2) for the angular rate th' and
    /// acceleration th'', mass-proportional `alpha` [1/s] and Kelvin-Voigt `beta` [s], and the
    /// junction vectors' Gram entries.
    fn factor(&mut self, bp: f64, gp: f64, thd: f64, thdd: f64, alpha: f64, beta: f64) {
        let key = [bp, gp, thd, thdd, alpha, beta, self.u_drag].map(f64::to_bits);
        if self.factored_for == Some(key) {
            return;
        }
        self.factored_for = Some(key);
        let rho = self.rho;
        self.p = rho * (2.0 * gp * thd + bp * thdd);
        // Eq. D19: the mass-proportional damping alpha M scales M in S by 1 + gamma' alpha
        // (exactly 1 without it)
        let mass = 1.0 + gp * alpha;
        self.jp_step = self.jp * mass;
        let mut sigma = rho * self.l * (mass - bp * thd * thd);
        if self.u_drag != 0.0 {
            sigma += self.u_drag;
        }
        self.suu = sigma;
        let damped = gp * beta;
        for j in 0..self.lambda_m.len() {
            let d = if beta > 0.0 {
                // Eq. D3: the Kelvin-Voigt damping beta K_e on the elastic stiffness only
                rho * (mass + damped * self.lambda_m[j] + bp * (self.lambda_m[j] - thd * thd))
            } else {
                rho * (mass + bp * (self.lambda_m[j] - thd * thd))
            };
            self.d[j] = d;
            self.inv_d[j] = 1.0 / d;
            self.w[j] = self.phi[j] / d;
            sigma += self.p * self.p * self.phi[j] * self.w[j];
        }
        self.inv_sigma = 1.0 / sigma;
        // Gram data of the junction vectors
        for (sv, v) in self.scaled0.iter_mut().zip([&self.phi0, &self.dphi0]) {
            for ((s, x), d) in sv.iter_mut().zip(v.iter()).zip(&self.inv_d) {
                *s = x * d;
            }
        }
        let [g00, g01, w0] = dots(&self.scaled0[0], [&self.phi0, &self.dphi0, &self.phi]);
        let [g11, w1] = dots(&self.scaled0[1], [&self.dphi0, &self.phi]);
        self.jgram = [g00, g01, g11];
        self.jw = [w0, w1];
    }

    /// `x = S_i^-1 x` for this beam's arrowhead (N + 2 entries).
    #[inline]
    pub(crate) fn arrow_solve(&self, x: &mut [f64]) {
        let nm = self.lambda_m.len();
        let y = (x[nm] + self.p * dot(&self.w, &x[..nm])) * self.inv_sigma;
        for ((xj, pj), dj) in x[..nm].iter_mut().zip(&self.phi).zip(&self.inv_d) {
            *xj = (*xj - self.p * pj * y) * dj;
        }
        x[nm] = y;
        x[nm + 1] /= self.jp_step;
    }
}

/// Eq. A3: each Fix row `k` of `rows` with its beam's axial flexibility over `bp`, the diagonal
/// entry it adds to the Schur complement (none at `bp = 0` or without the axial flexibility).
pub(crate) fn axial_flexibilities<'a>(
    rows: &'a [Row],
    bm: &'a [BeamModel],
    bp: f64,
) -> impl Iterator<Item = (usize, f64)> + 'a {
    let on = bm[0].axial_flex != 0.0 && bp > 0.0;
    rows.iter().enumerate().filter_map(move |(k, row)| match row {
        Row::Fix(i) if on => Some((k, pick(bm, *i).axial_flex / bp)),
        _ => None,
    })
}

/// The element of `v` for beam `i`: `v` holds one (shared by the three beams) or three.
#[inline]
pub(crate) fn pick<T>(v: &[T], i: usize) -> &T {
    &v[i.min(v.len() - 1)]
}

/// Workspace of the constrained system: everything sized once, nothing allocated per step.
#[derive(Debug, Clone)]
pub(crate) struct System {
    /// The beams' modes, data and arrowheads: one (equal beams) or three (`docs/amm.md` 13).
    pub(crate) bm: Vec<BeamModel>,
    pub(crate) nm: usize,
    pub(crate) nb: usize,
    pub(crate) rows: Vec<Row>,
    pub(crate) beams: [BeamRows; 3],
    /// Full model: the geometric stiffness of the axial inertia force (Eq. 23) on the modes
    /// that carry it, and its products with the predicted modal coordinates.
    geometric: Option<GeometricStiffness>,
    /// The sleeves (`crate::sleeve`): what their rows need per step (material point, shift,
    /// truncation flexibility) and the axial direction of their forces.
    pub(crate) sleeves: Sleeves,
    /// Full model: the axial acceleration u_i'' of each beam at the last solve, part of the axial
    /// inertia force of Eq. 23 (the whole axially rigid beam accelerates with it).
    udd: [f64; 3],
    /// Per beam, the lagged accelerations the last [`System::forcing`] used: u_i'' (Eq. 23) and
    /// the acceleration part `(G2 alpha) . alpha''` of the foreshortening inertia (its u row),
    /// so that the fixed-point pass changes only those terms ([`System::refresh_lagged_forcing`]).
    lag_in_forcing: [[f64; 2]; 3],
    /// Full model: the foreshortening inertia of the bent beams in the u rows (`foreshortening`).
    fore: Option<Foreshortening>,
    // per-step buffers
    dinv_r: Vec<f64>,
    pub(crate) resid: Vec<f64>,
    pub(crate) a: Vec<f64>,
    rhs: Vec<f64>,
    /// Factors of the Schur complement `a`.
    lu: ConstraintLu,
    /// Multipliers of the last solve, in the order of `rows`.
    pub(crate) lam: Vec<f64>,
    /// The payload at G on beam 1's coordinates (Eq. P6); `None` without one.
    payload: Option<PayloadTerms>,
    /// Kelvin-Voigt retardation time beta [s] (Eqs. D2-D3); 0: undamped.
    beta: f64,
    /// Mass-proportional coefficient alpha [1/s] on the elastic coordinates (Eq. D19); 0: none.
    alpha: f64,
    /// Gravity [m/s^2], base frame: the forcing reads the rigid acceleration of G as
    /// `a_G - g` (`docs/as-built.md` 5, Eq. G1); `[0, 0]`: none.
    gravity: [f64; 2],
    /// The load at G (Eq. L1); `None` without one.
    load: Option<LoadSettings>,
    /// Workspace of the payload's Woodbury correction, N + 2.
    pay_tmp: Vec<f64>,
    /// The sleeves' friction (`crate::friction`, `docs/friction.md` 9); `None` without it.
    pub(crate) friction: Option<SleeveFriction>,
    /// Full model under gravity: the beams' third-order terms about the sag (Eqs. V5-V6,
    /// `crate::third_order`); `None` otherwise.
    third_order: Option<Vec<ThirdOrderTerms>>,
}

/// Is a vector of mode values zero to round-off? `scale[m]` is the size a non-zero entry would have.
fn negligible(v: &[f64], scale: &[f64]) -> bool {
    v.iter().zip(scale).all(|(x, s)| x.abs() <= 1e-9 * s)
}

/// Values `phi_m(0)`, slopes `phi_m'(0)` at G and tip values `phi_m(L)` of every mode.
fn end_values(modes: &ModeSet, l: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let nm = modes.len();
    let mut phi0 = vec![0.0; nm];
    let mut dphi0 = vec![0.0; nm];
    let mut phil = vec![0.0; nm];
    for m in 0..nm {
        let e0 = modes.eval(m, 0.0);
        phi0[m] = e0[0];
        dphi0[m] = e0[1];
        phil[m] = modes.eval(m, l)[0];
    }
    (phi0, dphi0, phil)
}

/// The constraint rows kept for a family whose modes have (`has_w0`) a non-zero value at G and
/// (`has_slope0`) a non-zero slope there.
fn constraint_rows(has_w0: bool, has_slope0: bool) -> Vec<Row> {
    let mut rows = vec![Row::Fix(0), Row::Fix(1), Row::Fix(2)];
    if has_w0 {
        rows.push(Row::Fw);
    }
    if has_slope0 {
        rows.push(Row::M1G);
        rows.push(Row::M3G);
    }
    for i in 0..3 {
        rows.extend(SleeveRow::ALL.map(|r| Row::Sleeve(i, r)));
    }
    rows
}

/// Block of constraint row `row` on beam b: (basis vector, its factor, u coefficient, thp
/// coefficient), `None` where the block is zero; `hp` is half the sleeve length [m].
/// The junction's coefficients are those of `weld` (Eqs. 38, 40; J4, J5).
fn row_entry(row: Row, b: usize, has_w0: bool, hp: f64, weld: &Weld) -> Option<RowForm> {
    match row {
        Row::Fix(i) if b == i => Some((NONE, 0.0, 1.0, 0.0)),
        Row::Fix(i) if has_w0 => Some((
            B_PHI0,
            if b == (i + 1) % 3 {
                weld.fix[i][0]
            } else {
                weld.fix[i][1]
            },
            0.0,
            0.0,
        )),
        Row::Fix(_) => None,
        Row::Fw => Some((B_PHI0, weld.fw[b], 0.0, 0.0)),
        Row::M1G | Row::M3G => {
            let first = if row == Row::M1G { 0 } else { 2 };
            match b {
                1 => Some((B_DPHI0, -1.0, 0.0, 0.0)),
                _ if b == first => Some((B_DPHI0, 1.0, 0.0, 0.0)),
                _ => None,
            }
        }
        Row::Sleeve(i, row) => (b == i).then(|| row.form(hp)),
        Row::Stick(i) => (b == i).then_some((B_STICK, 0.0, 0.0, 0.0)),
    }
}

/// The rows of each beam: which constraint rows touch it and how ([`row_entry`]), with the
/// workspaces for `nm` modes; `hp`: each beam's half sleeve length [m].
fn beam_rows(rows: &[Row], has_w0: bool, hp: [f64; 3], nm: usize, weld: &Weld) -> [BeamRows; 3] {
    let mut beams: [BeamRows; 3] = std::array::from_fn(|_| BeamRows {
        ids: Vec::new(),
        basis: Vec::new(),
        sc: Vec::new(),
        cu: Vec::new(),
        gu: Vec::new(),
        ct: Vec::new(),
        gv: Vec::new(),
        sleeve: std::array::from_fn(|_| vec![0.0; nm]),
        stick: Vec::new(),
        stick_scaled: Vec::new(),
        stick_live: false,
        scaled: std::array::from_fn(|_| vec![0.0; nm]),
        gram: [[0.0; NB]; NB],
        g: [0.0; NB],
    });
    for (k, row) in rows.iter().enumerate() {
        for (b, beam) in beams.iter_mut().enumerate() {
            let entry = row_entry(*row, b, has_w0, hp[b], weld);
            if let Some((basis, sc, cu, ct)) = entry {
                beam.ids.push(k);
                beam.basis.push(basis);
                beam.sc.push(sc);
                beam.cu.push(cu);
                beam.gu.push(cu);
                beam.ct.push(ct);
                beam.gv.push(0.0);
                if basis == B_STICK {
                    (beam.stick, beam.stick_scaled) = (vec![0.0; nm], vec![0.0; nm]);
                }
            }
        }
    }
    beams
}

impl System {
    /// Build the system for `modes` (one mode set shared by three equal beams, or one per beam,
    /// of the same family and N) on the beams `params` (0-based) welded as `weld`
    /// (`docs/amm.md` 13), keeping the constraint rows that do not vanish identically for the
    /// family (pinned-free: no `Fw`; slide-free: no slope equalities; clamped-free: neither).
    pub(crate) fn new(modes: Vec<ModeSet>, params: &[RobotParams; 3], weld: &Weld, model: AmmModel) -> Self {
        debug_assert!(modes.len() == 1 || modes.len() == 3);
        let nm = modes[0].len();
        let nb = nm + 2;
        // the rows kept: a family property, read on beam 1's modes
        let (has_w0, has_slope0) = {
            let (m0, l) = (&modes[0], params[0].l);
            let sl = 1.0 / l.sqrt();
            let bl = m0.beta_l();
            let (phi0, dphi0, _) = end_values(m0, l);
            // a non-zero value is O(1/sqrt L), a non-zero slope O(max(1, beta L) / L^1.5)
            let val_scale = vec![sl; nm];
            let slope_scale: Vec<f64> = bl.iter().map(|b| b.max(1.0) * sl / l).collect();
            (!negligible(&phi0, &val_scale), !negligible(&dphi0, &slope_scale))
        };

        let rows = constraint_rows(has_w0, has_slope0);
        let hp = params.map(|p| 0.5 * p.lp);
        let beams = beam_rows(&rows, has_w0, hp, nm, weld);
        debug_assert!(beams.iter().all(|b| b.ids.len() <= MAX_BEAM_ROWS));
        let m = rows.len();
        let n = 3 * nb;
        let (geometric, fore) = match model {
            AmmModel::Full => {
                let geo = GeometricStiffness::new(&modes, geometric::KEPT_ANALYTIC);
                let g2: Vec<Vec<f64>> = (0..modes.len()).map(|i| geo.g2(i)).collect();
                let fore = Foreshortening::new(&modes[0], geo.kept(), &g2, KEPT_ANALYTIC);
                (Some(geo), Some(fore))
            }
            AmmModel::Paper => (None, None),
        };
        let sleeves = Sleeves::new(&modes, params, model);
        let bm = modes
            .into_iter()
            .zip(params.iter())
            .map(|(modes, p)| BeamModel::new(modes, p, model))
            .collect();
        System {
            fore,
            sleeves,
            geometric,
            udd: [0.0; 3],
            lag_in_forcing: [[0.0; 2]; 3],
            nm,
            nb,
            bm,
            rows,
            beams,
            dinv_r: vec![0.0; nm],
            resid: vec![0.0; n],
            a: vec![0.0; m * m],
            rhs: vec![0.0; m],
            lu: ConstraintLu::new(m),
            lam: vec![0.0; m],
            payload: None,
            beta: 0.0,
            alpha: 0.0,
            gravity: [0.0; 2],
            load: None,
            pay_tmp: vec![0.0; nb],
            friction: None,
            third_order: None,
        }
    }

    /// Beam i's modes, data and arrowhead (0-based; shared when the beams are equal).
    #[inline]
    pub(crate) fn beam(&self, i: usize) -> &BeamModel {
        pick(&self.bm, i)
    }

    /// `docs/amm.md` section 11: the payload welded at G (Eqs. P1-P6, on beam 1's
    /// coordinates), the Rayleigh damping of the elastic coordinates, Kelvin-Voigt `beta` [s]
    /// (Eqs. D2-D3) and mass-proportional `alpha` [1/s] (Eq. D19), and the load at G (Eq. L1,
    /// fixed frame), and gravity `[gx, gy]` [m/s^2] (Eq. G1). What is absent (no mass nor J,
    /// alpha = beta = 0, no load, no gravity) adds no code path (gravity subtracts exact zeros),
    /// so the bare star's results stay bit for bit.
    pub(crate) fn attach(&mut self, payload: &Payload, damping: &Damping, load: &LoadSettings, gravity: [f64; 2]) {
        self.gravity = gravity;
        self.third_order = third_order::carried(gravity, self.geometric.is_some()).then(|| {
            // equal beams share one beam model: its tables are built once, each beam keeps its
            // own lagged accelerations
            let built: Vec<ThirdOrderTerms> = self
                .bm
                .iter()
                .map(|b| ThirdOrderTerms::new(&b.modes, b.rho * b.modes.ei_over_rho(), b.rho))
                .collect();
            (0..3).map(|i| pick(&built, i).clone()).collect()
        });
        self.payload = PayloadTerms::new(payload, self.beams[0].ids.len());
        (self.alpha, self.beta) = damping.coefficients();
        self.load = (!load.is_none()).then(|| load.clone());
    }

    /// The run's largest `beta' = beta h^2` [s^2], which decides the modes the beams' third-order
    /// terms act on (`crate::third_order`); call before the static start. No-op without them.
    pub(crate) fn set_third_order_step(&mut self, bp: f64) {
        if let Some(terms) = self.third_order.as_mut() {
            terms.iter_mut().for_each(|t| t.set_step(bp));
        }
    }

    /// Friction in the sleeves (`docs/friction.md` 9): the stick rows of Eq. F16 (one per
    /// sleeve, after the others; they border the Schur complement, `constraint_lu`) and the law. Call
    /// before [`System::attach`] (the payload's workspaces are sized by beam 1's rows); `params`
    /// and `weld` those of [`System::new`].
    pub(crate) fn attach_friction(&mut self, law: flexstar_model::Friction, params: &[RobotParams; 3], weld: &Weld) {
        let has_w0 = self.rows.contains(&Row::Fw);
        let first = self.rows.len();
        self.rows.extend((0..3).map(Row::Stick));
        let hp = params.map(|p| 0.5 * p.lp);
        self.beams = beam_rows(&self.rows, has_w0, hp, self.nm, weld);
        let m = self.rows.len();
        (self.a, self.rhs, self.lam) = (vec![0.0; m * m], vec![0.0; m], vec![0.0; m]);
        self.lu = ConstraintLu::bordered(m);
        let index = |r: Row| self.rows.iter().position(|x| *x == r).expect("a sleeve row");
        let rows = std::array::from_fn(|i| SleeveRow::ALL.map(|r| index(Row::Sleeve(i, r))));
        let stick = [first, first + 1, first + 2];
        let ea = params.map(|p| p.ea());
        self.friction = Some(SleeveFriction::new(law, (rows, stick), hp, ea, self.nb));
    }

    /// The system with Eq. 23's product on the first `analytic` analytic modes (and the junction
    /// shapes) instead of [`geometric::KEPT_ANALYTIC`], for the test of that truncation.
    #[cfg(test)]
    pub(crate) fn with_geometric_kept(mut self, analytic: usize) -> Self {
        let modes: Vec<ModeSet> = self.bm.iter().map(|b| b.modes.clone()).collect();
        self.geometric = Some(GeometricStiffness::new(&modes, analytic));
        self
    }

    /// Number of unknowns, 3 (N + 2).
    pub(crate) fn dim(&self) -> usize {
        3 * self.nb
    }

    /// Basis vector `a` of beam `i` (rows `beam`).
    pub(crate) fn basis<'s>(&'s self, i: usize, beam: &'s BeamRows, a: usize) -> &'s [f64] {
        match a {
            B_PHI0 => &self.beam(i).phi0,
            B_DPHI0 => &self.beam(i).dphi0,
            B_STICK => &beam.stick,
            _ => &beam.sleeve[a - B_MID],
        }
    }

    /// Eqs. 41-43: refresh the sleeve rows for the sleeve positions xp_i(t) [m], about the
    /// predictor `qhat` in the full model ([`Sleeves::update`]).
    pub(crate) fn update_sleeve_rows(&mut self, xp: [f64; 3], qhat: &[f64]) {
        let modes: [&ModeSet; 3] = std::array::from_fn(|i| &pick(&self.bm, i).modes);
        self.sleeves.update(&mut self.beams, &self.rows, modes, xp, qhat);
    }

    /// Eq. A3 (`docs/amm.md` 12.12): the beams' axial flexibility on the Fix rows, whose
    /// multiplier F_ix is the axial force on beam i at G and whose u_i is the beam's mean axial
    /// displacement: its root is at `u_i + L / (3 EA) F_ix`, so `a_kk += L / (3 EA) / bp` on the
    /// row's diagonal of the Schur complement. No-op in the paper's model and for the consistent
    /// initial accelerations (`bp = 0`).
    fn add_axial_flexibility(&mut self, bp: f64) {
        let m = self.rows.len();
        for (k, f) in axial_flexibilities(&self.rows, &self.bm, bp) {
            self.a[k * m + k] += f;
        }
    }

    /// Arrowhead data of each beam's block of `S = M + gamma' D + beta' K` (Eq. J2) for the
    /// angular rate th' and acceleration th'': one for equal beams.
    fn factor_s(&mut self, bp: f64, gp: f64, thd: f64, thdd: f64) {
        let (alpha, beta) = (self.alpha, self.beta);
        for b in self.bm.iter_mut() {
            b.factor(bp, gp, thd, thdd, alpha, beta);
        }
    }

    /// One linear solve of the index-3 generalized-alpha step (or of the consistent initial
    /// accelerations when `bp = gp = 0`): with `q = qhat + bp qdd`, `q' = vhat + gp qdd`,
    ///
    /// ```text
    /// S qdd - C^T lambda = f - D vhat - K qhat,     C qdd = -C qhat / bp   (0 when bp = 0)
    /// ```
    /// at the rigid state `st`. Writes `qdd` and `self.lam`: [`System::prepare`], then
    /// [`System::forcing`] and [`System::solve_prepared`].
    pub(crate) fn solve(
        &mut self,
        st: &RigidState,
        bp: f64,
        gp: f64,
        qhat: &[f64],
        vhat: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), AmmError> {
        if self.friction.is_some() {
            self.predict_friction(st, vhat, (bp, gp));
        }
        self.prepare(st, bp, gp, qhat)?;
        self.forcing(st, qhat, vhat);
        self.solve_prepared(bp, Some(qhat), qdd);
        self.set_axial_acceleration(qdd);
        if self.iterates_lagged_accelerations() {
            self.refresh_lagged_forcing();
            self.solve_prepared(bp, Some(qhat), qdd);
            self.set_axial_acceleration(qdd);
        }
        Ok(())
    }

    /// Whether each step takes one fixed-point pass on the full model's lagged accelerations
    /// (Eq. 23's u'', the u row's foreshortening inertia): those two terms again from the
    /// accelerations just solved ([`System::refresh_lagged_forcing`]), the same factors. Under
    /// gravity the sag makes their u-alpha
    /// coupling first order, and taken from the last solve alone it diverges at fine steps
    /// (`docs/amm.md` 12.14, "A divergence at fine steps under gravity"). Without gravity the
    /// coupling is second order and no pass is taken.
    pub(crate) fn iterates_lagged_accelerations(&self) -> bool {
        self.gravity != [0.0; 2] && self.fore.is_some()
    }

    /// The fixed-point pass's forcing ([`System::iterates_lagged_accelerations`]): the forcing
    /// of the last [`System::forcing`] with its two lagged-acceleration terms taken again from
    /// the accelerations remembered since ([`System::set_axial_acceleration`]): Eq. 23's
    /// `rho u_i'' G2 alpha` in the alpha rows and the acceleration part `rho (G2 alpha) . alpha''`
    /// of the u row's foreshortening inertia, each changed by the change of its acceleration. The
    /// rest of the forcing, the beams' third-order terms included (their own lag, 12.14), is
    /// unchanged, so the pass costs a few dot products of the kept modes and one substitution.
    pub(crate) fn refresh_lagged_forcing(&mut self) {
        let (nm, nb) = (self.nm, self.nb);
        let Some(geo) = &self.geometric else {
            return;
        };
        for i in 0..3 {
            let rho = pick(&self.bm, i).rho;
            let o = i * nb;
            let [udd_used, acc_used] = self.lag_in_forcing[i];
            let g2a = geo.g2_alpha(i);
            let d_udd = self.udd[i] - udd_used;
            for (k, &j) in geo.kept().iter().enumerate() {
                self.resid[o + j] += rho * d_udd * g2a[k];
            }
            let mut acc = acc_used;
            if let Some(fore) = self.fore.as_ref() {
                acc = fore.acceleration_part(i, geo.kept(), g2a);
                self.resid[o + nm] += rho * (acc - acc_used);
            }
            self.lag_in_forcing[i] = [self.udd[i], acc];
        }
    }

    /// The forcing of the last [`System::forcing`] (per beam: alpha rows, u row, thp row), for a
    /// caller that substitutes other right-hand sides before the fixed-point pass.
    pub(crate) fn forcing_values(&self) -> &[f64] {
        &self.resid
    }

    /// Put back a forcing kept with [`System::forcing_values`].
    pub(crate) fn restore_forcing(&mut self, values: &[f64]) {
        self.resid.copy_from_slice(values);
    }

    /// Remember the axial accelerations u_i'' of `qdd` (the full model's Eq. 23 term of the next
    /// step) and the modal accelerations (its foreshortening term).
    pub(crate) fn set_axial_acceleration(&mut self, qdd: &[f64]) {
        let (nm, nb) = (self.nm, self.nb);
        for i in 0..3 {
            self.udd[i] = qdd[i * nb + nm];
            if let Some(fore) = self.fore.as_mut() {
                fore.remember(i, &qdd[i * nb..i * nb + nm]);
            }
            if let Some(terms) = self.third_order.as_mut() {
                terms[i].remember(&qdd[i * nb..i * nb + nm]);
            }
        }
    }

    /// The forcing `r = f - D vhat - K qhat` of the step at the rigid state `st`, into the
    /// workspace (per beam: Eq. 37 alpha rows, Eqs. 30/44 u row, Eq. 31 thp row).
    pub(crate) fn forcing(&mut self, st: &RigidState, qhat: &[f64], vhat: &[f64]) {
        let (nm, nb) = (self.nm, self.nb);
        let thd = st.theta.d1;
        let thdd = st.theta.d2;
        let ag = self.apparent_a_g(st);
        if let Some(geo) = self.geometric.as_mut() {
            geo.multiply(qhat, nb);
        }
        let iterates = self.iterates_lagged_accelerations();
        let mut lagged = [[0.0; 2]; 3];
        for (i, lag) in lagged.iter_mut().enumerate() {
            let bm = pick(&self.bm, i);
            let (rho, l) = (bm.rho, bm.l);
            // Eqs. 11-12: e_x = [sin a, -cos a], e_w = [cos a, sin a], one sin/cos pair
            let ex = st.e_x(i);
            let ew = [-ex[1], ex[0]];
            let aw = ag[0] * ew[0] + ag[1] * ew[1];
            let ax = ag[0] * ex[0] + ag[1] * ex[1];
            let o = i * nb;
            let (qa, qu) = (&qhat[o..o + nm], qhat[o + nm]);
            let (va, vu) = (&vhat[o..o + nm], vhat[o + nm]);
            let r = &mut self.resid[o..o + nb];
            // no reduction in the loop (it vectorises); Phi . alpha and Phi . alpha' apart
            let c_phi = -rho * aw - 2.0 * rho * thd * vu - rho * thdd * qu;
            let (c_psi, c_q, thd2) = (-rho * thdd, -rho, thd * thd);
            let rows = r[..nm].iter_mut().zip(&bm.phi[..nm]).zip(&bm.psi[..nm]);
            for (((rj, &pj), &sj), (&lj, &qj)) in rows.zip(bm.lambda_m[..nm].iter().zip(qa)) {
                *rj = c_phi * pj + c_psi * sj + c_q * (lj - thd2) * qj;
            }
            let [phi_q, phi_v] = [dot(&bm.phi, qa), dot(&bm.phi, va)];
            r[nm] = -rho * (l * ax - thd * thd * l * l / 2.0)
                + 2.0 * rho * thd * phi_v
                + rho * thdd * phi_q
                + rho * l * thd * thd * qu;
            r[nm + 1] = -bm.jp * thdd;
            if let Some(geo) = &self.geometric {
                // Eq. 23: - rho (th'^2 G1 - a_x G2) alpha, at the predictor (docs/amm.md section 8)
                let (c1, c2) = (rho * thd * thd, -rho * (ax + self.udd[i]));
                let (g1a, g2a) = (geo.g1_alpha(i), geo.g2_alpha(i));
                for (k, &j) in geo.kept().iter().enumerate() {
                    r[j] -= c1 * g1a[k] + c2 * g2a[k];
                }
                // foreshortening inertia of the bent beam in its u row: + rho E''
                if let Some(fore) = self.fore.as_mut() {
                    r[nm] += rho * fore.second_derivative(i, geo.kept(), g2a, va);
                    if iterates {
                        *lag = [self.udd[i], fore.acceleration_part(i, geo.kept(), g2a)];
                    }
                }
            }
        }
        self.lag_in_forcing = lagged;
        if let Some(terms) = self.third_order.as_mut() {
            for (i, t) in terms.iter_mut().enumerate() {
                let o = i * nb;
                t.add_forces(&qhat[o..o + nm], &vhat[o..o + nm], &mut self.resid[o..o + nm]);
            }
        }
        if self.beta > 0.0 {
            self.damping_forcing(vhat);
        }
        if self.alpha > 0.0 {
            self.mass_damping_forcing(vhat);
        }
        if self.payload.is_some() || self.load.is_some() {
            self.attachment_forcing(st, qhat, vhat, None);
        }
        if self.friction.is_some() {
            self.friction_forcing();
        }
    }

    /// Eq. D2: the Kelvin-Voigt force `- beta rho lambda_j alpha_j'` at the predictor `vhat` on
    /// every beam's alpha rows (the `D vhat` part of the step's forcing) [N].
    fn damping_forcing(&mut self, vhat: &[f64]) {
        let (nm, nb) = (self.nm, self.nb);
        for i in 0..3 {
            let bm = pick(&self.bm, i);
            let c = self.beta * bm.rho;
            let o = i * nb;
            let rows = self.resid[o..o + nm].iter_mut().zip(&vhat[o..o + nm]);
            for ((r, v), l) in rows.zip(&bm.lambda_m) {
                *r -= c * l * v;
            }
        }
    }

    /// Eq. D19: the mass-proportional force `- alpha M vhat` on the elastic coordinates at the
    /// predictor: `- alpha rho alpha_j'` on the alpha rows, `- alpha rho L u'` on the u row,
    /// `- alpha Jp thp'` on the thp row (the payload's `- alpha M_p P vhat` is added with its
    /// other terms, `attachment_forcing`) [N, N, N m].
    fn mass_damping_forcing(&mut self, vhat: &[f64]) {
        let (nm, nb) = (self.nm, self.nb);
        for i in 0..3 {
            let bm = pick(&self.bm, i);
            let c = self.alpha * bm.rho;
            let o = i * nb;
            for (r, v) in self.resid[o..o + nm].iter_mut().zip(&vhat[o..o + nm]) {
                *r -= c * v;
            }
            self.resid[o + nm] -= c * bm.l * vhat[o + nm];
            self.resid[o + nm + 1] -= self.alpha * bm.jp * vhat[o + nm + 1];
        }
    }

    /// `P q_1` (Eq. P1): `(u_1, phi(0) . alpha_1, phi'(0) . alpha_1)` of beam 1's block of `q`.
    pub(crate) fn payload_coordinates(&self, q: &[f64]) -> [f64; 3] {
        let (nm, b) = (self.nm, &self.bm[0]);
        [q[nm], dot(&b.phi0, &q[..nm]), dot(&b.dphi0, &q[..nm])]
    }

    /// Gravity `[gx, gy]` [m/s^2], base frame.
    pub(crate) fn gravity(&self) -> [f64; 2] {
        self.gravity
    }

    /// Eq. G1: the rigid acceleration of G less gravity, `a_G - g` [m/s^2], base frame: the
    /// weight of every mass element of the star and the payload enters the equations as a
    /// uniform acceleration of the base, opposite to g.
    fn apparent_a_g(&self, st: &RigidState) -> [f64; 2] {
        let a = st.a_g();
        [a[0] - self.gravity[0], a[1] - self.gravity[1]]
    }

    /// The rigid quantities of the payload's terms ([`RigidTerms`]) on beam 1's frame at `st`.
    fn payload_motion(&self, st: &RigidState) -> RigidTerms {
        self.payload_motion_along(st, st.e_x(0))
    }

    /// [`System::payload_motion`] with beam 1's axis `ex = e_x1` given (gravity in, Eq. G1).
    fn payload_motion_along(&self, st: &RigidState, ex: [f64; 2]) -> RigidTerms {
        let ag = self.apparent_a_g(st);
        let ew = [-ex[1], ex[0]];
        let thd = st.theta.d1;
        [
            ag[0] * ex[0] + ag[1] * ex[1],
            ag[0] * ew[0] + ag[1] * ew[1],
            st.theta.d2,
            thd,
            thd * thd,
        ]
    }

    /// The payload (Eq. P6: `P^T (f_p - D_p P vhat - K_p P qhat)`) and the load (Eq. L1: `F . e_x1`
    /// on u_1, `(F . e_w1) phi(0) + Mz phi'(0)` on alpha_1) added to beam 1's rows of the forcing.
    /// `change`: the derivative of the payload's part along a change of the motion instead
    /// ([`RigidTerms`]; the load's projection is frozen at the predicted angle, `docs/amm.md` 11.3).
    fn attachment_forcing(&mut self, st: &RigidState, qhat: &[f64], vhat: &[f64], change: Option<RigidTerms>) {
        let nm = self.nm;
        let ex = st.e_x(0);
        let ew = [-ex[1], ex[0]];
        let mut rp = [0.0; 3];
        if let Some(pl) = &self.payload {
            let x = change.unwrap_or_else(|| self.payload_motion_along(st, ex));
            let (zq, zv) = (self.payload_coordinates(qhat), self.payload_coordinates(vhat));
            rp = pl.forcing(x, zq, zv);
            if change.is_none() && self.alpha > 0.0 {
                // Eq. D19 on the payload: - alpha M_p z_v (not a rate of the rigid motion)
                let m = pl.mass_matrix();
                for (a, r) in rp.iter_mut().enumerate() {
                    *r -= self.alpha * (0..3).map(|b| m[a][b] * zv[b]).sum::<f64>();
                }
            }
        }
        if let (Some(load), None) = (&self.load, change) {
            let [fx, fy, mz] = load.at(st.t);
            rp[0] += fx * ex[0] + fy * ex[1];
            rp[1] += fx * ew[0] + fy * ew[1];
            rp[2] += mz;
        }
        let r = &mut self.resid[..nm + 1];
        r[nm] += rp[0];
        let b = &self.bm[0];
        for ((rj, p0), d0) in r[..nm].iter_mut().zip(&b.phi0).zip(&b.dphi0) {
            *rj += rp[1] * p0 + rp[2] * d0;
        }
    }

    /// The derivative of [`System::forcing`] along a change of the rigid motion: `d_ag` of a_G
    /// [m/s^2], `d_thd` of theta' [rad/s], `d_thdd` of theta'' [rad/s^2] (the direct dynamics'
    /// sensitivity to the sliders' accelerations, `docs/amm.md` section 10), into the workspace.
    /// The step matrix is not changed (it is frozen at the predictor). Call after
    /// [`System::forcing`] with the same `st`, `qhat`, `vhat`.
    pub(crate) fn forcing_derivative(
        &mut self,
        st: &RigidState,
        d_ag: [f64; 2],
        d_thd: f64,
        d_thdd: f64,
        qhat: &[f64],
        vhat: &[f64],
    ) {
        let (nm, nb) = (self.nm, self.nb);
        let thd = st.theta.d1;
        for i in 0..3 {
            let bm = pick(&self.bm, i);
            let (rho, l) = (bm.rho, bm.l);
            // Eqs. 11-12: e_x = [sin a, -cos a], e_w = [cos a, sin a], one sin/cos pair
            let ex = st.e_x(i);
            let ew = [-ex[1], ex[0]];
            let daw = d_ag[0] * ew[0] + d_ag[1] * ew[1];
            let dax = d_ag[0] * ex[0] + d_ag[1] * ex[1];
            let o = i * nb;
            let (qa, qu) = (&qhat[o..o + nm], qhat[o + nm]);
            let (va, vu) = (&vhat[o..o + nm], vhat[o + nm]);
            let r = &mut self.resid[o..o + nb];
            let mut phi_q = 0.0;
            let mut phi_v = 0.0;
            for j in 0..nm {
                let pj = bm.phi[j];
                r[j] = -rho * (daw * pj + d_thdd * bm.psi[j]) - 2.0 * rho * d_thd * pj * vu
                    + 2.0 * rho * thd * d_thd * qa[j]
                    - rho * d_thdd * pj * qu;
                phi_q += pj * qa[j];
                phi_v += pj * va[j];
            }
            r[nm] = -rho * (l * dax - thd * d_thd * l * l)
                + 2.0 * rho * d_thd * phi_v
                + rho * d_thdd * phi_q
                + 2.0 * rho * l * thd * d_thd * qu;
            r[nm + 1] = -bm.jp * d_thdd;
            if let Some(geo) = &self.geometric {
                // G1 alpha, G2 alpha of the last forcing (the same qhat)
                let (c1, c2) = (2.0 * rho * thd * d_thd, -rho * dax);
                let (g1a, g2a) = (geo.g1_alpha(i), geo.g2_alpha(i));
                for (k, &j) in geo.kept().iter().enumerate() {
                    r[j] -= c1 * g1a[k] + c2 * g2a[k];
                }
            }
        }
        if self.payload.is_some() {
            // Eqs. P3-P5 are linear in (a1, a2, theta'', theta', theta'^2): their change along
            // the motion's change, with e_x1 frozen at the predictor as for the beams
            let ex = st.e_x(0);
            let ew = [-ex[1], ex[0]];
            let change = [
                d_ag[0] * ex[0] + d_ag[1] * ex[1],
                d_ag[0] * ew[0] + d_ag[1] * ew[1],
                d_thdd,
                d_thd,
                2.0 * thd * d_thd,
            ];
            self.attachment_forcing(st, qhat, vhat, Some(change));
        }
    }

    /// Build and factor the step matrix at the rigid state `st`: sleeve rows at xp(st) (about the
    /// predictor `qhat` for the full model), the arrowhead data of S, and the LU factors of the
    /// Schur complement `A = C S^-1 C^T` (kept for [`System::solve_prepared`]).
    ///
    /// `A` is assembled without forming `S^-1 C^T`. Block elimination of the u row
    /// of the arrowhead gives, for rows k and s of one beam (alpha part `ca`, u and thp
    /// coefficients `cu`, `ct`),
    /// `A_ks = ca_k D^-1 ca_s + (cu_k - p g_k)(cu_s + p g_s) / sigma + ct_k ct_s / Jp`, with
    /// `g_k = ca_k . D^-1 Phi` and `sigma = s_uu + p^2 Phi D^-1 Phi`; and every alpha part is a
    /// multiple of one of six vectors (phi(0), phi'(0), phi at the three sleeve points, phi'(xp)),
    /// so only their 6x6 Gram matrix `B D^-1 B^T` is computed (21 dot products of length N, and
    /// the six `B D^-1 Phi`).
    pub(crate) fn prepare(&mut self, st: &RigidState, bp: f64, gp: f64, qhat: &[f64]) -> Result<(), AmmError> {
        self.prepare_rows(st, (bp, gp), qhat, None)?;
        let m = self.rows.len();
        self.a.iter_mut().for_each(|v| *v = 0.0);
        // disjoint borrows of the fields (no copy of the beams' workspaces)
        let (beams, a_mat, bm) = (&mut self.beams, &mut self.a, &self.bm);
        for (i, beam) in beams.iter_mut().enumerate() {
            let b = pick(bm, i);
            let (p, inv_sigma, inv_jp) = (b.p, b.inv_sigma, 1.0 / b.jp_step);
            beam.fill_gram(b.jgram, b.jw, &b.inv_d, [&b.phi0, &b.dphi0, &b.phi]);
            beam.add_block(a_mat, m, p, inv_sigma, inv_jp);
        }
        self.sleeves.add_compliance(&mut self.a, m, &self.beams, bp);
        self.add_axial_flexibility(bp);
        if self.payload.is_some() {
            self.payload_block(st)?;
        }
        if self.friction.is_some() {
            self.add_friction_to_schur();
        }
        self.lu
            .factor(&self.a)
            .map_err(|source| AmmError::SingularConstraints { t: st.t, source })
    }

    /// The first part of [`System::prepare`], what the step's equations need before their
    /// Schur complement: the sleeve rows at xp(st) (about the predictor `qhat` in the full
    /// model; `near`: to first order about the values a step's system kept, the tangent's
    /// probe, `sleeve::near`), the friction terms, each beam's arrowhead of S with the Gram data
    /// of its junction vectors (once for equal beams), and the payload's step matrix `S_p`.
    pub(crate) fn prepare_rows(
        &mut self,
        st: &RigidState,
        (bp, gp): (f64, f64),
        qhat: &[f64],
        near: Option<&SleevesNear>,
    ) -> Result<(), AmmError> {
        let xp = [st.xp[0].v, st.xp[1].v, st.xp[2].v];
        match near {
            Some(near) => self.sleeves.update_near(&mut self.beams, &self.rows, xp, qhat, near),
            None => self.update_sleeve_rows(xp, qhat),
        }
        self.sleeves.on_beams(st.t)?;
        if self.friction.is_some() {
            self.friction_terms(qhat);
        }
        self.factor_s(bp, gp, st.theta.d1, st.theta.d2);
        if self.payload.is_some() {
            let x = self.payload_motion(st);
            let c_m = 1.0 + gp * self.alpha;
            if let Some(pl) = self.payload.as_mut() {
                pl.sp = pl.step_matrix(x, (bp, gp, c_m));
            }
        }
        Ok(())
    }

    /// Keep each step's sleeve values for a tangent's probe (`sleeve::near`).
    pub(crate) fn keep_sleeve_values(&mut self) {
        self.sleeves.keep_values(self.nm);
    }

    /// The derivatives in the material points of the sleeve values `base` kept at its step
    /// about the predictor `qhat`, evaluated on this system (a probe) as workspace.
    pub(crate) fn linearise_sleeves(&mut self, base: &mut System, qhat: &[f64]) {
        let modes: [&ModeSet; 3] = std::array::from_fn(|i| &pick(&self.bm, i).modes);
        self.sleeves.linearise(&mut self.beams, modes, &mut base.sleeves, qhat);
    }

    /// The payload's Woodbury correction of beam 1's block of the Schur complement (module docs of
    /// `attach`): `A_0 -= (C_0 S^-1 P^T) W (P S^-1 C_0^T)`, every product from the Gram data of
    /// the step ([`BeamRows::product`]) and the payload's `S_p` of [`System::prepare_rows`]; sets
    /// `W` and `C_0 S^-1 P^T` for the substitution.
    fn payload_block(&mut self, st: &RigidState) -> Result<(), AmmError> {
        let (beam, m) = (&self.beams[0], self.rows.len());
        let Some(pl) = self.payload.as_mut() else {
            return Ok(());
        };
        let (h, cross, back) = beam.payload_products(self.bm[0].p, self.bm[0].inv_sigma);
        if !pl.set_woodbury(&h) {
            return Err(AmmError::SingularConstraints {
                t: st.t,
                source: RankError::Payload,
            });
        }
        let mb = beam.ids.len();
        // W (P S^-1 C_0^T), 3 x mb
        let mut wg = [[0.0; 3]; MAX_BEAM_ROWS];
        for (w, b) in wg.iter_mut().zip(&back).take(mb) {
            *w = pl.apply_w(*b);
        }
        for ((k, &c), saved) in cross.iter().enumerate().zip(pl.cross.iter_mut()).take(mb) {
            *saved = c;
            let row = &mut self.a[beam.ids[k] * m..(beam.ids[k] + 1) * m];
            for (s, w) in wg.iter().enumerate().take(mb) {
                row[beam.ids[s]] -= c[0] * w[0] + c[1] * w[1] + c[2] * w[2];
            }
        }
        Ok(())
    }

    /// `W P S^-1 r` of beam 1's block of the forcing `r` (`y_r`, `D^-1 r` against the basis
    /// `bdr`, as in [`System::solve_prepared`]): the payload's correction of `C_0 S^-1 r`.
    /// `p`, `inv_jp`: the step's border and `1 / Jp`; `r_thp`: the thp row of r.
    fn payload_rhs(
        pl: &PayloadTerms,
        beam: &BeamRows,
        (p, inv_jp): (f64, f64),
        r_thp: f64,
        y_r: f64,
        bdr: &[f64; NB],
    ) -> [f64; 3] {
        let pz = PAYLOAD_ROWS.map(|(b, s, u, t)| {
            let g = if b == NONE { 0.0 } else { s * beam.g[b] };
            let mut v = (u - p * g) * y_r + t * r_thp * inv_jp;
            if b != NONE {
                v += s * bdr[b];
            }
            v
        });
        pl.apply_w(pz)
    }

    /// Beam 1's block `x = S^-1 v` becomes `(S + P^T S_p P)^-1 v = x - S^-1 P^T W P x` (Woodbury,
    /// module docs of `attach`); a no-op without a payload.
    pub(crate) fn payload_correct(&mut self, x: &mut [f64]) {
        let Some(pl) = self.payload.as_ref() else {
            return;
        };
        let nm = self.nm;
        let c = pl.apply_w(self.payload_coordinates(x));
        let mut tmp = std::mem::take(&mut self.pay_tmp);
        let b = &self.bm[0];
        for ((t, p0), d0) in tmp[..nm].iter_mut().zip(&b.phi0).zip(&b.dphi0) {
            *t = c[1] * p0 + c[2] * d0;
        }
        tmp[nm] = c[0];
        tmp[nm + 1] = 0.0;
        b.arrow_solve(&mut tmp);
        for (xi, t) in x.iter_mut().zip(&tmp) {
            *xi -= t;
        }
        self.pay_tmp = tmp;
    }

    /// Solve the prepared step for the forcing in the workspace ([`System::forcing`] or
    /// [`System::forcing_derivative`]): `S qdd - C^T lambda = r`, `C qdd = -C qhat / bp` with
    /// `qhat` given (and `bp > 0`), `C qdd = 0` without. Writes `qdd` and `self.lam`.
    pub(crate) fn solve_prepared(&mut self, bp: f64, qhat: Option<&[f64]>, qdd: &mut [f64]) {
        self.solve_factored(bp, qhat, None, qdd);
    }

    /// [`System::solve_prepared`], or with `given` the constraint rows' values (one per row,
    /// in place of those of the predictor `qhat`): `C S^-1 r + given` on the right side.
    fn solve_factored(&mut self, bp: f64, qhat: Option<&[f64]>, given: Option<&[f64]>, qdd: &mut [f64]) {
        let (nm, nb) = (self.nm, self.nb);
        match given {
            Some(g) => self.rhs.iter_mut().zip(g).for_each(|(v, gk)| *v = -gk),
            None => self.rhs.iter_mut().for_each(|v| *v = 0.0),
        }
        // disjoint borrows of the fields (no copy of the beams' workspaces)
        let (beams, resid, dinv_r, rhs) = (&self.beams, &self.resid, &mut self.dinv_r, &mut self.rhs);
        for (i, beam) in beams.iter().enumerate() {
            let b = pick(&self.bm, i);
            let (p, inv_sigma, inv_jp) = (b.p, b.inv_sigma, 1.0 / b.jp_step);
            let (w, inv_d, phi0, dphi0) = (&b.w, &b.inv_d, &b.phi0, &b.dphi0);
            let o = i * nb;
            // c_k . S^-1 r = ca_k D^-1 r_a + (cu_k - p g_k) y_r + ct_k r_thp / Jp, and c_k . qhat
            let r = &resid[o..o + nb];
            let y_r = (r[nm] + p * dot(w, &r[..nm])) * inv_sigma;
            for ((d, x), di) in dinv_r.iter_mut().zip(&r[..nm]).zip(inv_d) {
                *d = x * di;
            }
            // every basis vector against D^-1 r and against qhat, one pass each (the unused ones
            // are never read)
            let basis = [
                &phi0[..],
                &dphi0[..],
                &beam.sleeve[0][..],
                &beam.sleeve[1][..],
                &beam.sleeve[2][..],
                &beam.sleeve[3][..],
            ];
            let mut bdr = [0.0; NB];
            bdr[..B_STICK].copy_from_slice(&dots(dinv_r, basis));
            let mut bq = [0.0; NB];
            if let Some(qh) = qhat {
                bq[..B_STICK].copy_from_slice(&dots(&qh[o..o + nm], basis));
            }
            if beam.stick_live {
                bdr[B_STICK] = dot(dinv_r, &beam.stick);
                bq[B_STICK] = qhat.map_or(0.0, |qh| dot(&qh[o..o + nm], &beam.stick));
            }
            // the payload's part of beam 1's C_0 S1^-1 r (Woodbury): - (C_0 S^-1 P^T) W P S^-1 r
            let corr = match (&self.payload, i) {
                (Some(pl), 0) => Some((pl, Self::payload_rhs(pl, beam, (p, inv_jp), r[nm + 1], y_r, &bdr))),
                _ => None,
            };
            for k in 0..beam.ids.len() {
                let (bk, sk) = (beam.basis[k], beam.sc[k]);
                let gk = if bk == NONE { 0.0 } else { sk * beam.g[bk] };
                let mut cz = (beam.cu[k] - p * gk) * y_r + beam.ct[k] * r[nm + 1] * inv_jp;
                if bk != NONE {
                    cz += sk * bdr[bk];
                }
                if let Some((pl, c)) = corr {
                    cz -= (0..3).map(|a| pl.cross[k][a] * c[a]).sum::<f64>();
                }
                let cq = match qhat {
                    Some(qh) if bp > 0.0 => {
                        let mut cq = beam.gu[k] * qh[o + nm] + beam.ct[k] * qh[o + nm + 1] + beam.gv[k];
                        if bk != NONE {
                            cq += sk * bq[bk];
                        }
                        cq / bp
                    }
                    _ => 0.0,
                };
                rhs[beam.ids[k]] -= cz + cq;
            }
        }
        self.lu.solve(&mut self.rhs);
        self.lam.copy_from_slice(&self.rhs);
        self.substitute(qdd);
    }

    /// `qdd = S^-1 (r + C^T lambda)` for the multipliers `self.lam` of the step's solve, beam 1
    /// with the payload's Woodbury correction.
    fn substitute(&mut self, qdd: &mut [f64]) {
        let (nm, nb) = (self.nm, self.nb);
        // collect the multipliers per basis vector, then one axpy each
        qdd.copy_from_slice(&self.resid);
        if self.friction.is_some() {
            self.add_coulomb(&self.lam, qdd);
        }
        for (i, beam) in self.beams.iter().enumerate() {
            let o = i * nb;
            let mut coef = [0.0; NB];
            for (k, &g) in beam.ids.iter().enumerate() {
                let lam = self.lam[g];
                if beam.basis[k] != NONE {
                    coef[beam.basis[k]] += lam * beam.sc[k];
                }
                qdd[o + nm] += lam * beam.cu[k];
                qdd[o + nm + 1] += lam * beam.ct[k];
            }
            for (a, &c) in coef.iter().enumerate() {
                if c != 0.0 {
                    for (q, v) in qdd[o..o + nm].iter_mut().zip(self.basis(i, beam, a)) {
                        *q += c * v;
                    }
                }
            }
        }
        for i in 0..3 {
            self.beam(i).arrow_solve(&mut qdd[i * nb..(i + 1) * nb]);
        }
        self.payload_correct(&mut qdd[..nb]);
    }

    /// The sleeve rows evaluated exactly at the state q, for tests ([`Sleeves::gaps`]) [m, -].
    #[cfg(test)]
    pub(crate) fn sleeve_gaps(&self, q: &[f64], lp: [f64; 3]) -> [f64; 5] {
        let modes: [&ModeSet; 3] = std::array::from_fn(|i| &self.beam(i).modes);
        self.sleeves.gaps(modes, &self.beams, &self.lam, q, lp)
    }

    /// The constraint Jacobian C (rows x 3 (N + 2), row-major) at the last sleeve update: the
    /// rows of Eqs. 38-43 as written in [`Row`] (for the modal analysis at a pose).
    pub(crate) fn constraint_matrix(&self) -> Vec<f64> {
        let (nm, nb, n) = (self.nm, self.nb, self.dim());
        let mut c = vec![0.0; self.rows.len() * n];
        for (i, beam) in self.beams.iter().enumerate() {
            let o = i * nb;
            for (k, &g) in beam.ids.iter().enumerate() {
                let row = &mut c[g * n..(g + 1) * n];
                row[o + nm] += beam.cu[k];
                row[o + nm + 1] += beam.ct[k];
                if beam.basis[k] != NONE {
                    for (r, v) in row[o..o + nm].iter_mut().zip(self.basis(i, beam, beam.basis[k])) {
                        *r += beam.sc[k] * v;
                    }
                }
            }
        }
        c
    }

    /// Largest |C q| over the rows (constraint violation, for tests).
    #[cfg(test)]
    pub(crate) fn constraint_violation(&self, q: &[f64]) -> f64 {
        let (nm, nb) = (self.nm, self.nb);
        let mut r = vec![0.0; self.rows.len()];
        for (i, beam) in self.beams.iter().enumerate() {
            let o = i * nb;
            for (k, &g) in beam.ids.iter().enumerate() {
                let mut v = beam.gu[k] * q[o + nm] + beam.ct[k] * q[o + nm + 1] + beam.gv[k];
                if beam.basis[k] != NONE {
                    v += beam.sc[k] * dot(self.basis(i, beam, beam.basis[k]), &q[o..o + nm]);
                }
                r[g] += v;
            }
        }
        r.iter().fold(0.0f64, |a, v| a.max(v.abs()))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::solver::integrate;
    use flexstar_model::{AmmSettings, ModeFamily, Trajectory};

    /// A sleeve carried off its beam stops the step with the sleeve, the contact point and its
    /// coordinate named (`flexstar_model::sleeve_contact`), checked against the geometry: on the
    /// paper's robot (L = 0.5 m, Lp = 0.03 m) the right edge of a sleeve whose centre is put at
    /// `L - Lp/4` lies at `L + Lp/4`, the left edge of one at `Lp/4` at `-Lp/4`; at the rigid
    /// pose of the motion every point is on its beam.
    #[test]
    fn a_sleeve_off_its_beam_is_named() {
        let exp = flexstar_model::catalogue::paper_case(3);
        let problem = exp.problem().unwrap();
        let star = crate::star::Star::new(&problem);
        let settings = AmmSettings::paper(ModeFamily::FreeFree, 10);
        let mut sys = crate::solver::build_system(&settings, 10, &star).unwrap();
        let q = vec![0.0; sys.dim()];
        let st = star.state(0.1).unwrap();
        let (bp, gp) = (1e-8, 1e-4);
        assert!(sys.prepare(&st, bp, gp, &q).is_ok());
        let (l, lp) = (0.5, 0.03);
        for (i, xc, point, edge) in [
            (1, l - lp / 4.0, "right edge", l + lp / 4.0),
            (2, lp / 4.0, "left edge", -lp / 4.0),
        ] {
            let mut off = st;
            off.xp[i].v = xc;
            match sys.prepare(&off, bp, gp, &q) {
                Err(AmmError::SleeveOffBeam(e)) => {
                    assert_eq!((e.sleeve, e.point, e.l, e.t), (i + 1, point, l, 0.1));
                    assert!((e.xi - edge).abs() < 1e-15, "{e}");
                }
                other => panic!("sleeve {} at {xc}: {other:?}", i + 1),
            }
        }
    }

    #[test]
    fn energy_balance_at_a_locked_pose() {
        // Kelvin-Voigt alone, then Rayleigh (the mass-proportional part dissipating as much)
        energy_balance_with(Damping::with_beta(3e-3));
        energy_balance_with(Damping::rayleigh(4.0, 1.5e-3));
    }

    fn energy_balance_with(damping: Damping) {
        // docs/amm.md 11.5, Eq. C6 where it is exact for the AMM: the star held at the centre pose
        // (sliders fixed: theta' = theta'' = 0, a_G = 0, time-invariant constraints that do no
        // work), paper model, a payload off G, damping and a load from zero. Kinetic energy
        // (beams, sleeves, payload: Eq. P2) + strain energy + dissipated (Eqs. D4, D20) = load
        // work, from the stored coordinates (central differences, midpoint rule: O(h^2)).
        let mut exp = flexstar_model::catalogue::paper_case(3);
        exp.trajectory = Trajectory::Polynomial {
            s1: vec![0.0],
            s2: vec![0.0],
            s3: vec![0.0],
        };
        exp.time.t_end = 0.5;
        exp.payload = Payload {
            mass: 0.8,
            j: 3e-3,
            offset: [0.04, 0.02],
        };
        exp.damping = damping;
        // from zero with zero rate, on the time scale of the first period (0.25 s)
        exp.load = LoadSettings::polynomials(
            Some(vec![0.0, 0.0, 100.0, -200.0]),
            Some(vec![0.0, 0.0, -60.0, 80.0]),
            Some(vec![0.0, 0.0, 8.0, -12.0]),
        );
        let problem = exp.problem().unwrap();
        energy_balance_on(&problem);
    }

    /// The energy balance of `problem` run with the sliders held (its trajectory constant).
    pub(crate) fn energy_balance_on(problem: &flexstar_model::Problem) {
        energy_balance_of(problem, 1e-4);
    }

    /// The energy balance of `problem` with the sliders held, to `tolerance` of the largest work:
    /// the load's work is the change of kinetic and strain energy plus the dissipation of the
    /// damping (Eqs. D4, D20) and the work of the sleeves' friction forces on the sliding
    /// coordinates, `int F_fi d xi_i` (Eq. F18 while slipping; while stuck, the energy the stick
    /// row's compliance stores, Eq. F16). Returns (largest work, dissipated, worst imbalance) [J].
    pub(crate) fn energy_balance_of(problem: &flexstar_model::Problem, tolerance: f64) -> (f64, f64, f64) {
        let exp = crate::star::Star::new(problem);
        let st0 = exp.state(0.0).unwrap();
        let (ex, ew) = (st0.e_x(0), st0.e_w(0));
        let settings = AmmSettings::paper(ModeFamily::FreeFree, 20);
        let mut qs: Vec<Vec<f64>> = vec![vec![0.0; 3 * 22]];
        // the friction forces at each step (Coulomb and stick only: no u'' term, c = 0)
        let mut forces: Vec<[f64; 3]> = vec![[0.0; 3]];
        let mut sys_copy = None;
        integrate(&exp, &settings, 20, true, |sys, q| {
            qs.push(q.to_vec());
            forces.push([0, 1, 2].map(|i| sys.sleeve_friction_force(i, &sys.lam, 0.0, true)));
            sys_copy.get_or_insert_with(|| sys.clone());
        })
        .unwrap();
        assert!(exp.friction.is_none_or(|f| f.c.0 == [0.0; 3]), "the test takes c = 0");
        let sys = sys_copy.unwrap();
        let h = exp.time.t_end / (qs.len() - 1) as f64;
        let (nm, nb) = (sys.nm, sys.nb);
        let pl = PayloadTerms::new(exp.payload, 0).unwrap();
        let mp = pl.mass_matrix();
        // the kinetic energy of velocities v: v^T M v / 2 (beams, sleeves, payload)
        let kinetic = |v: &[f64]| {
            let mut e = 0.0;
            for i in 0..3 {
                let (o, b) = (i * nb, sys.beam(i));
                e += 0.5 * b.rho * v[o..o + nm].iter().map(|x| x * x).sum::<f64>();
                e += 0.5 * (b.rho * b.l * v[o + nm].powi(2) + b.jp * v[o + nm + 1].powi(2));
            }
            let zv = sys.payload_coordinates(v);
            e + 0.5
                * (0..3)
                    .map(|a| (0..3).map(|b| zv[a] * mp[a][b] * zv[b]).sum::<f64>())
                    .sum::<f64>()
        };
        // T + V at step n (central velocity), P_d and the load's power on [n, n+1] (midpoint)
        let energy = |n: usize| {
            let v: Vec<f64> = (0..qs[n].len())
                .map(|k| (qs[n + 1][k] - qs[n - 1][k]) / (2.0 * h))
                .collect();
            let mut e = kinetic(&v);
            for i in 0..3 {
                let b = sys.beam(i);
                for j in 0..nm {
                    e += 0.5 * b.rho * b.lambda_m[j] * qs[n][i * nb + j].powi(2);
                }
            }
            e
        };
        let (alpha, beta) = exp.damping.coefficients();
        let (mut work, mut dissipated, mut worst, mut work_max) = (0.0, 0.0, 0.0f64, 0.0f64);
        for n in 0..qs.len() - 2 {
            let dq: Vec<f64> = (0..qs[n].len()).map(|k| qs[n + 1][k] - qs[n][k]).collect();
            let dz = sys.payload_coordinates(&dq);
            // (F . e_x1, F . e_w1, Mz) on beam 1's coordinates (Eq. L1) at the held pose
            let [fx, fy, mz] = exp.load.at((n as f64 + 0.5) * h);
            work += (fx * ex[0] + fy * ex[1]) * dz[0] + (fx * ew[0] + fy * ew[1]) * dz[1] + mz * dz[2];
            for i in 0..3 {
                let b = sys.beam(i);
                for j in 0..nm {
                    dissipated += beta * b.rho * b.lambda_m[j] * dq[i * nb + j].powi(2) / h;
                }
            }
            // Eq. D20: alpha v^T M v, with v = dq / h on the step
            let v: Vec<f64> = dq.iter().map(|d| d / h).collect();
            dissipated += alpha * 2.0 * kinetic(&v) * h;
            // the friction's work on xi_i = xp_i - u_i (xp_i held): trapezoidal on the step
            for i in 0..3 {
                dissipated -= 0.5 * (forces[n][i] + forces[n + 1][i]) * dq[i * nb + nm];
            }
            if n >= 1 {
                worst = worst.max((energy(n + 1) + dissipated - work).abs());
                work_max = work_max.max(work.abs());
            }
        }
        eprintln!("load work {work:e} J, dissipated {dissipated:e} J, worst imbalance {worst:e} J");
        assert!(
            dissipated > 0.01 * work_max,
            "the damping must matter: {dissipated:e} of {work_max:e}"
        );
        assert!(
            worst < tolerance * work_max,
            "imbalance {worst:e} J against the work {work_max:e} J"
        );
        (work_max, dissipated, worst)
    }
}
