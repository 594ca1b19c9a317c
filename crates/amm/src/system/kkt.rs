//! The step's equations as a residual, and their solve for a given residual with the step's
//! factors: what the tangent-linear step of `crate::tangent` needs (`docs/amm.md` 2.2, Eqs.
//! T-2, T-3).
//!
//! A prepared step ([`System::prepare`], [`System::forcing`]) solves, per beam and row,
//!
//! ```text
//! S q'' - C^T lambda = r,      grad c_k . q'' + (c_k(qhat) + sum_s F_ks lambda_s) / bp = 0
//! ```
//! (with a payload, `S` includes beam 1's `P^T S_p P`, `crate::attach`), with `c_k(qhat)` the
//! row's value at the predictor (its `gu`, `gv` parts included) and `F`
//! the truncation flexibility of the sleeve rows (Eq. R4) and the axial flexibility of the Fix
//! rows (Eq. A3); at `bp = 0` (the consistent start) the rows read `grad c_k . q'' = 0`.

use super::{axial_flexibilities, pick, System, NONE};
use crate::modes::dot;
use flexstar_numerics::vector::dots;

impl System {
    /// Whether the step's equations are all in [`System::step_residual`]: not with friction or
    /// gravity (the stick rows and the fixed-point pass under gravity are not). A payload's
    /// step matrix is (`P^T S_p P`), and a load is forcing only.
    pub(crate) fn has_tangent(&self) -> bool {
        self.friction.is_none() && self.gravity == [0.0; 2]
    }

    /// A tangent's probe at other physical parameters than the run's: its sleeve rows, taken to
    /// first order about the run's, evaluate their truncation flexibility on its own beams
    /// (`sleeve::near`).
    pub(crate) fn evaluate_own_flexibility(&mut self) {
        self.sleeves.evaluate_own_flexibility();
    }

    /// The residual of the prepared step's equations (module docs) at the accelerations `qdd`
    /// and multipliers `lam`: `primal = S qdd - C^T lam - r` (per beam: alpha rows, u row, thp
    /// row) and `rows` per constraint row. Zero, to round-off, at the step's own solution.
    pub(crate) fn step_residual(
        &self,
        bp: f64,
        qhat: &[f64],
        (qdd, lam): (&[f64], &[f64]),
        primal: &mut [f64],
        rows: &mut [f64],
    ) {
        let (nm, nb) = (self.nm, self.nb);
        rows.iter_mut().for_each(|v| *v = 0.0);
        for (i, beam) in self.beams.iter().enumerate() {
            let b = pick(&self.bm, i);
            let o = i * nb;
            let (qa, qu, qt) = (&qdd[o..o + nm], qdd[o + nm], qdd[o + nm + 1]);
            let out = &mut primal[o..o + nb];
            // the arrowhead S: alpha rows d_j a_j + p Phi_j u'', u row -p Phi . a + s_uu u''
            let rows_a = out[..nm].iter_mut().zip(&self.resid[o..o + nm]);
            for (((x, r), (&d, &a)), &phi) in rows_a.zip(b.d.iter().zip(qa)).zip(&b.phi) {
                *x = d * a + b.p * phi * qu - r;
            }
            out[nm] = -b.p * dot(&b.phi, qa) + b.suu * qu - self.resid[o + nm];
            out[nm + 1] = b.jp_step * qt - self.resid[o + nm + 1];
            // each basis vector against q'' and qhat (one pass each), then the rows
            let basis: [&[f64]; 6] = [
                &b.phi0,
                &b.dphi0,
                &beam.sleeve[0],
                &beam.sleeve[1],
                &beam.sleeve[2],
                &beam.sleeve[3],
            ];
            let on_qdd = dots(qa, basis);
            let on_qhat = dots(&qhat[o..o + nm], basis);
            let mut coef = [0.0; 6];
            for k in 0..beam.ids.len() {
                let (g, bk, sk) = (beam.ids[k], beam.basis[k], beam.sc[k]);
                let l = lam[g];
                out[nm] -= l * beam.cu[k];
                out[nm + 1] -= l * beam.ct[k];
                let mut row = beam.cu[k] * qu + beam.ct[k] * qt;
                let mut value = beam.gu[k] * qhat[o + nm] + beam.ct[k] * qhat[o + nm + 1] + beam.gv[k];
                if bk != NONE {
                    coef[bk] += l * sk;
                    row += sk * on_qdd[bk];
                    value += sk * on_qhat[bk];
                }
                rows[g] += if bp > 0.0 { row + value / bp } else { row };
            }
            // - C^T lambda on the alpha rows, one pass per basis vector used
            for (c, v) in coef.iter().zip(basis) {
                if *c != 0.0 {
                    for (x, vj) in out[..nm].iter_mut().zip(v) {
                        *x -= c * vj;
                    }
                }
            }
        }
        if let Some(pl) = &self.payload {
            // beam 1's P^T S_p P q'' (Eq. P6; `crate::attach`)
            let z = self.payload_coordinates(qdd);
            let y: [f64; 3] = std::array::from_fn(|a| (0..3).map(|b| pl.sp[a][b] * z[b]).sum());
            let (nm, b) = (self.nm, &self.bm[0]);
            primal[nm] += y[0];
            for ((x, p0), d0) in primal[..nm].iter_mut().zip(&b.phi0).zip(&b.dphi0) {
                *x += y[1] * p0 + y[2] * d0;
            }
        }
        if bp > 0.0 {
            self.sleeves.add_compliance_product(rows, &self.beams, lam, bp);
            for (k, f) in axial_flexibilities(&self.rows, &self.bm, bp) {
                rows[k] += f * lam[k];
            }
        }
    }

    /// The correction `dqdd` that solves the prepared step's equations linearised about a
    /// point whose residual is `(primal, rows)` ([`System::step_residual`]), with the step's own
    /// factors: `S dqdd - C^T dlam = -primal`, `grad C dqdd + F / bp dlam = -rows`. Takes
    /// `minus_primal` (= `-primal`) and a buffer `dlam` of one entry per row (it receives the
    /// multipliers' correction), swapped in for the step's forcing and multipliers and back, so
    /// that both are kept; a payload's Woodbury terms are the step's. Not with friction (its
    /// stick rows are not in [`System::step_residual`]).
    pub(crate) fn solve_correction(
        &mut self,
        bp: f64,
        (minus_primal, rows): (&mut Vec<f64>, &[f64]),
        dlam: &mut Vec<f64>,
        dqdd: &mut [f64],
    ) {
        debug_assert!(self.friction.is_none());
        std::mem::swap(&mut self.resid, minus_primal);
        std::mem::swap(&mut self.lam, dlam);
        self.solve_factored(bp, None, Some(rows), dqdd);
        std::mem::swap(&mut self.resid, minus_primal);
        std::mem::swap(&mut self.lam, dlam);
    }
}
