//! The sleeve: the passive prismatic joint through which beam i slides, pinned at the revolute
//! point `P_i` of slider i (Eqs. 1-3) and free to turn about it.
//!
//! **In the AMM.** The sleeve's position on its beam, `xp_i(t)` [m] from G along `e_xi`, is the
//! rigid kinematics' (prescribed, not an unknown). Its one unknown is its rotation `thp_i` [rad]
//! relative to the rigid beam direction, the last coordinate of beam i's block (`alpha_i, u_i,
//! thp_i`, `system`), with the equation `Jp thp'' = -Jp th'' + (C^T lambda)_thp` (Eq. 31,
//! `Jp` [kg m^2]). The sleeve holds the beam by four constraint rows ([`rows`], Eqs. 41-43,
//! `docs/amm.md` section 1), homogeneous and linear in the beam's coordinates, whose multipliers
//! are the forces of the sleeve on the beam: the normal forces `Fp_i` at the pin, `FR_pi`, `FL_pi`
//! at the edges [N] along `+e_wi`, and the couple `Mp_i` [N m]. Frames: the moving beam frame
//! `(e_xi, e_wi)` of Eqs. 11-12 (`docs/conventions.md`); SI units.
//!
//! - paper model: the rows at the rigid material points `xp_i`, `xp_i +- Lp/2`, no u_i term;
//! - full model (`docs/amm.md` section 8): at the material point that sits in the sleeve, drawn
//!   out by the foreshortening, `x_c = xp_i - u_i + f(x_c)` ([`shift`], Eqs. S1-S4,
//!   `docs/amm.md` 12.11), linearised about the step's predictor ([`Sleeves::update`]); each
//!   normal force then acts along `e_w - w' e_x` (the u gradient `-w'`, [`Sleeves::axial`]);
//! - full model with the enriched family: the truncation flexibility of the modes left out of the
//!   basis, seen at the sleeve's four functionals ([`compliance`], Eqs. R1-R4, `docs/amm.md` 12.3),
//!   `C q + R lambda = 0`.
//!
//! The force the sleeve passes through its pin to the slider enters the driving force of Eq. 33
//! ([`rows::push`]).
//!
//! **Friction** (`docs/friction.md` 9, `crate::friction`): the sleeve's rows carry no force
//! along the beam; friction is the generalized force `F_fi` on beam i's `u_i` (its material
//! coordinate in the sleeve being `xp_i - u_i`), its load the multipliers of these rows (Eq.
//! F13), and a stuck sleeve a row of its own (`system::Row::Stick`, Eq. F16).

mod compliance;
pub(crate) mod near;
pub(crate) mod rows;
mod shift;

use flexstar_model::sleeve_contact::{on_beam, OffBeam};
use flexstar_model::{AmmModel, ModeFamily, RobotParams};

use crate::foreshortening::KEPT_ANALYTIC;
use crate::geometric::GeometricStiffness;
use crate::modes::{dot, ModeSet, SleeveBending, Triplet};
use crate::system::{pick, BeamRows, Row};
use compliance::SleeveCompliance;
use rows::ShiftTerms;
pub(crate) use rows::{SleeveRow, B_MID, B_MSLOPE, SLEEVE_ROWS};
use shift::SleeveShift;

/// A beam's foreshortening at the material point in its sleeve (Eqs. S1-S3).
pub(crate) struct ShiftAt<'a> {
    /// The kept modes (indices into the beam's alpha).
    pub(crate) kept: &'a [usize],
    /// `g = F(x_c) alpha` on them [-].
    pub(crate) g: &'a [f64],
    /// `f(x_c)` [m].
    pub(crate) f: f64,
}

/// The three sleeves of a system: what their rows need beyond the rows' form (`system::BeamRows`),
/// refreshed per step by [`Sleeves::update`].
#[derive(Debug, Clone)]
pub(crate) struct Sleeves {
    /// Full model: the rows at the material point in the sleeve.
    full: bool,
    /// Factors of the modes' values at the sleeve's centre and edges and slope at its centre
    /// (half-width Lp/2): one for equal beams, else one per beam (`docs/amm.md` 13, Eq. J6).
    tri: Vec<Triplet>,
    /// Full model, per beam: the beam's slopes at the sleeve's edges and curvature at its centre.
    bent: [SleeveBending; 3],
    /// Full model: the material point in the sleeve drawn out by the foreshortening
    /// ([`shift`], Eqs. S1-S3): one table for equal beams, else one per beam.
    shift: Option<Vec<SleeveShift>>,
    /// Full model, enriched family: the truncation flexibility of the sleeves (Eqs. R3-R4,
    /// `docs/amm.md` 12), one for equal beams, else one per beam; `None` otherwise.
    compliance: Option<Vec<SleeveCompliance>>,
    /// Per beam: the truncation flexibility `R_ab` of the sleeve rows (Eq. R3, `docs/amm.md` 12), a,
    /// b over `B_MID..=B_MSLOPE`, at the last update (with [`Sleeves::compliance`]).
    res: [[[f64; 4]; 4]; 3],
    /// Sleeve positions xp_i of the last update [m].
    xp: [f64; 3],
    /// Full model: the shift `f(x_c)` of each beam at the last update [m] (Eq. S1).
    f: [f64; 3],
    /// Full model: u_i-gradients of the rows Fp_i, FR_i, FL_i at the last update (`-w'` at the
    /// material point in the sleeve; 0 in the paper's model): the axial direction of their forces.
    axial: [[f64; 3]; 3],
    /// Each sleeve's material centre `xp - u + f` at the last update [m] (Eq. S1; `xp` in the
    /// paper's model).
    xc: [f64; 3],
    /// The beams' lengths L_i [m].
    lengths: [f64; 3],
    /// The mode values of each update kept for the tangent's probe ([`Sleeves::keep_values`]);
    /// `None` in a plain run.
    kept: Option<Box<near::SleevesNear>>,
    /// A tangent's probe at other physical parameters: [`Sleeves::update_near`] evaluates the
    /// truncation flexibility block on these sleeves instead of taking the run's to first order.
    own_flexibility: bool,
}

impl Sleeves {
    /// The sleeves of the beams `params` (0-based) on `modes` (one mode set shared by equal
    /// beams, or one per beam), in `model`.
    pub(crate) fn new(modes: &[ModeSet], params: &[RobotParams; 3], model: AmmModel) -> Self {
        let full = model == AmmModel::Full;
        let n_bent = if full { modes[0].analytic_len() } else { 0 };
        let per_beam = modes.iter().zip(params.iter());
        let shift = full.then(|| {
            modes
                .iter()
                .map(|m| SleeveShift::new(m, &GeometricStiffness::kept_modes(m, KEPT_ANALYTIC)))
                .collect()
        });
        let compliance = (full && modes[0].family() == ModeFamily::Enriched).then(|| {
            per_beam
                .clone()
                .map(|(m, p)| SleeveCompliance::new(p.l, 0.5 * p.lp, p.ei(), p.rho, m.lambda()))
                .collect()
        });
        Sleeves {
            full,
            tri: per_beam.map(|(m, p)| m.triplet(0.5 * p.lp)).collect(),
            bent: std::array::from_fn(|_| SleeveBending::new(n_bent)),
            shift,
            compliance,
            res: [[[0.0; 4]; 4]; 3],
            xp: [0.0; 3],
            f: [0.0; 3],
            axial: [[0.0; 3]; 3],
            xc: [0.0; 3],
            lengths: std::array::from_fn(|i| params[i].l),
            kept: None,
            own_flexibility: false,
        }
    }

    /// Full model: the u_i-gradients `[c_Fp, c_FR, c_FL]` of each beam's rows at the last update
    /// (`-w'`; zeros in the paper's model), the axial direction of the sleeve forces (Eq. 33,
    /// [`rows::push`]).
    pub(crate) fn axial(&self) -> &[[f64; 3]; 3] {
        &self.axial
    }

    /// Full model: beam i's foreshortening at the material point in the sleeve at the last
    /// update (Eqs. S1-S3, at the step's predictor); `None` in the paper's model.
    pub(crate) fn shift_at_update(&self, i: usize) -> Option<ShiftAt<'_>> {
        self.shift.as_ref().map(|s| {
            let s = pick(s, i);
            ShiftAt {
                kept: s.kept(),
                g: s.gradient(i),
                f: self.f[i],
            }
        })
    }

    /// Full model: the shift `f(x)` [m] of beam i with coordinates `alpha` at the material
    /// point `x` [m] (Eq. S2); 0 in the paper's model.
    pub(crate) fn shift_of(&self, i: usize, x: f64, alpha: &[f64]) -> f64 {
        self.shift.as_ref().map_or(0.0, |s| pick(s, i).value(x, alpha))
    }

    /// The sleeves' contact points at the last update (centre `xc`, edges `xc -+ Lp/2`) inside
    /// their beams at time `t` [s] (`flexstar_model::sleeve_contact`): a sleeve that the elastic
    /// motion carries off its beam, where the rigid pose was checked before the run.
    pub(crate) fn on_beams(&self, t: f64) -> Result<(), OffBeam> {
        for (i, (&xc, &l)) in self.xc.iter().zip(&self.lengths).enumerate() {
            let h = pick(&self.tri, i).half_length();
            on_beam(t, i, [xc, xc - h, xc + h], l)?;
        }
        Ok(())
    }

    /// Eqs. 41-43: refresh the sleeve rows of `beams` (the rows `rows`, beam i on `modes[i]`)
    /// for the sleeve positions xp_i(t) [m].
    ///
    /// Paper model: the rows at the rigid material points xp_i, xp_i +- Lp/2, constant in u_i.
    /// Full model (`docs/amm.md` section 8): at the material point that sits in the sleeve,
    /// `xp_i - u_i`, linearised about the predictor `qhat` (one Newton step of the nonlinear rows
    /// per time step, exact to O(h^4)): alpha part `phi(xp - u^ + e)`, u gradient
    /// `-w^'(xp - u^ + e)` (`+w^''` for the slope row), while the rows' values keep no u term.
    /// The material point is drawn out by the foreshortening, `e = f(xp - u^)` (Eq. S1,
    /// `docs/amm.md` 12.11), and the rows gain its gradient and the edges' `sin thp`
    /// ([`rows::shift_rows`]).
    pub(crate) fn update(
        &mut self,
        beams: &mut [BeamRows; 3],
        rows: &[Row],
        modes: [&ModeSet; 3],
        xp: [f64; 3],
        qhat: &[f64],
    ) {
        let nm = modes[0].len();
        let shifts = self.place(xp, qhat, nm);
        self.evaluate_modes(beams, modes, self.xc, qhat);
        if let Some(kept) = self.kept.as_mut() {
            kept.keep(beams, &self.bent, self.xc, qhat, nm);
        }
        self.finish(beams, rows, qhat, shifts, None);
    }

    /// Keep each update's mode values at the material points (`near::SleevesNear`), for the
    /// tangent's linearised sleeve rows ([`Sleeves::update_near`]).
    pub(crate) fn keep_values(&mut self, nm: usize) {
        self.kept = Some(Box::new(near::SleevesNear::new(nm)));
    }

    /// See the field `own_flexibility`.
    pub(crate) fn evaluate_own_flexibility(&mut self) {
        self.own_flexibility = true;
    }

    /// The values kept at the last update ([`Sleeves::keep_values`]).
    pub(crate) fn kept(&self) -> Option<&near::SleevesNear> {
        self.kept.as_deref()
    }

    /// The material point in each sleeve (Eq. S1) about the predictor `qhat` and its
    /// foreshortening shift: sets `xp`, `f`, `xc`; returns the shifts [m].
    #[inline]
    fn place(&mut self, xp: [f64; 3], qhat: &[f64], nm: usize) -> [f64; 3] {
        let nb = nm + 2;
        let full = self.full;
        self.xp = xp;
        let alpha = |i: usize| &qhat[i * nb..i * nb + nm];
        let mut shifts = [0.0; 3];
        for (i, (sh, &x)) in shifts.iter_mut().zip(&xp).enumerate() {
            let u_hat = if full { qhat[i * nb + nm] } else { 0.0 };
            *sh = self.shift.as_mut().map_or(0.0, |s| {
                let n = s.len();
                s[i.min(n - 1)].evaluate(i, x - u_hat, alpha(i))
            });
        }
        self.f = shifts;
        self.xc = std::array::from_fn(|i| {
            let u_hat = if full { qhat[i * nb + nm] } else { 0.0 };
            xp[i] - u_hat + shifts[i]
        });
        shifts
    }

    /// The modes at the sleeve points about the material points `xc` [m]: each beam's vectors
    /// `[mid, right, left, slope]` (the slope not yet negated) and, in the full model, its
    /// bending sums with the coordinates of `qhat`; the three beams at once on a shared set.
    #[inline]
    pub(super) fn evaluate_modes(
        &mut self,
        beams: &mut [BeamRows; 3],
        modes: [&ModeSet; 3],
        xc: [f64; 3],
        qhat: &[f64],
    ) {
        let nm = modes[0].len();
        let nb = nm + 2;
        let full = self.full;
        let alpha = |i: usize| &qhat[i * nb..i * nb + nm];
        let together = full && self.tri.len() == 1;
        if together {
            let out = beams.each_mut().map(|b| {
                let [mid, right, left, mslope] = &mut b.sleeve;
                [&mut left[..], &mut mid[..], &mut right[..], &mut mslope[..]]
            });
            let bent = self.bent.each_mut().map(|bn| &mut *bn);
            let [b0, b1, b2] = bent;
            modes[0].triplets_at3(&self.tri[0], xc, out, [(alpha(0), b0), (alpha(1), b1), (alpha(2), b2)]);
            return;
        }
        for (i, beam) in beams.iter_mut().enumerate() {
            let [mid, right, left, mslope] = &mut beam.sleeve;
            let bent = &mut self.bent[i];
            let tri = pick(&self.tri, i);
            modes[i].triplet_at(
                tri,
                xc[i],
                left,
                mid,
                right,
                mslope,
                full.then_some((alpha(i), &mut *bent)),
            );
        }
    }

    /// The rows' coefficients from the modes at the material points ([`Sleeves::evaluate_modes`]):
    /// the u gradients and the forces' axial directions, the slope row's sign, the truncation
    /// flexibility block (Eq. R3; `res`: given, linearised, instead of evaluated) and the
    /// foreshortening's terms (Eqs. S3-S5).
    #[inline]
    pub(super) fn finish(
        &mut self,
        beams: &mut [BeamRows; 3],
        rows: &[Row],
        qhat: &[f64],
        shifts: [f64; 3],
        res: Option<&[[[f64; 4]; 4]; 3]>,
    ) {
        let nm = beams[0].sleeve[0].len();
        let nb = nm + 2;
        let full = self.full;
        for (i, beam) in beams.iter_mut().enumerate() {
            let (alpha, shift, xc) = (&qhat[i * nb..i * nb + nm], shifts[i], self.xc[i]);
            let [mid, right, left, mslope] = &mut beam.sleeve;
            let bent = &mut self.bent[i];
            let tri = pick(&self.tri, i);
            if full {
                let slope_mid = dot(mslope, alpha);
                let slopes = [slope_mid, bent.slope_right, bent.slope_left];
                for (k, id) in beam.ids.iter().enumerate() {
                    if let Row::Sleeve(_, row) = rows[*id] {
                        beam.cu[k] = rows::u_gradient(row, slopes, bent.curvature);
                    }
                }
                self.axial[i] = slopes.map(|s| -s);
            }
            mslope.iter_mut().for_each(|v| *v = -*v);
            if let Some(c) = self.compliance.as_mut() {
                let n = c.len();
                self.res[i] = match res {
                    Some(r) => r[i],
                    None => c[i.min(n - 1)].block(xc, [mid, right, left, mslope]),
                };
            }
            if let Some(s) = self.shift.as_ref() {
                let s = pick(s, i);
                let terms = ShiftTerms {
                    kept: s.kept(),
                    g: s.gradient(i),
                    two_f: 2.0 * shift,
                    thp: qhat[i * nb + nm + 1],
                    hp: tri.half_length(),
                    slopes: self.axial[i].map(|c| -c),
                    curvature: bent.curvature,
                };
                rows::shift_rows(beam, rows, terms);
            }
        }
    }

    /// The truncation flexibility block of beam i (Eq. R3) at the material point `xc` [m] with
    /// the basis vectors `v` (`[mid, right, left, -slope]`); `None` without it.
    pub(super) fn compliance_block(&mut self, i: usize, xc: f64, v: [&[f64]; 4]) -> Option<[[f64; 4]; 4]> {
        self.compliance.as_mut().map(|c| {
            let n = c.len();
            c[i.min(n - 1)].block(xc, v)
        })
    }

    /// Whether the rows carry the full model's bending sums.
    pub(super) fn is_full(&self) -> bool {
        self.full
    }

    /// The sleeve rows of Eqs. 41-42 evaluated exactly at the state q, for tests, with the
    /// foreshortening computed here by brute force (Gauss quadrature of `1/2 int_0^x w'^2` over
    /// every mode, not the table of [`shift`]): largest `|w_i(x_c + e) - sin(thp_i) e|` over
    /// the beams and e in {0, +-Lp/2}, at the material point `x_c = xp - u + f(x_c)` of Eq. S1;
    /// the same at `xp - u` (no foreshortening, as before Eq. S1); and `|w_i(xp_i + e) - e thp_i|`
    /// (the rigid material points, as the paper takes them) [m]; and the slope row of Eq. S5,
    /// `|sin(thp_i) - w_i'(x_c)|` [-], then as Eq. 43 writes it, `|thp_i - w_i'(x_c)|`.
    /// `beams`, `lam`: the rows and the multipliers of the last solve (for the truncation
    /// flexibility's deflection).
    #[cfg(test)]
    pub(crate) fn gaps(
        &self,
        modes: [&ModeSet; 3],
        beams: &[BeamRows; 3],
        lam: &[f64],
        q: &[f64],
        lp: [f64; 3],
    ) -> [f64; 5] {
        let nm = modes[0].len();
        let nb = nm + 2;
        let mut v = vec![0.0; nm];
        let mut gaps = [0.0f64; 5];
        for (i, beam) in beams.iter().enumerate() {
            let o = i * nb;
            let (alpha, u, thp) = (&q[o..o + nm], q[o + nm], q[o + nm + 1]);
            let mut xc = self.xp[i] - u;
            let (modes, lp) = (modes[i], lp[i]);
            for _ in 0..3 {
                xc = self.xp[i] - u + modes.half_squared_slope_integral(alpha, xc);
            }
            // the truncation flexibility's deflection at the left edge, centre, right edge (Eq. R4)
            let res = self.truncation_deflection(i, beam, lam);
            for (e, r) in [-0.5 * lp, 0.0, 0.5 * lp].into_iter().zip([res[2], res[0], res[1]]) {
                for (gap, x, side, rr) in [
                    (0, xc + e, e * thp.sin(), r),
                    (1, self.xp[i] - u + e, e * thp, r),
                    (2, self.xp[i] + e, e * thp, 0.0),
                ] {
                    modes.values_at(x, &mut v, None);
                    gaps[gap] = gaps[gap].max((dot(&v, alpha) + rr - side).abs());
                }
            }
            // the slope at x_c, the truncation flexibility's part being -res[3] (Eq. R4)
            let mut slope = vec![0.0; nm];
            modes.values_at(xc, &mut v, Some(&mut slope));
            let w_slope = dot(&slope, alpha) - res[3];
            gaps[3] = gaps[3].max((thp.sin() - w_slope).abs());
            gaps[4] = gaps[4].max((thp - w_slope).abs());
        }
        gaps
    }
}
