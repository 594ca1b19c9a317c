//! The sleeve rows near a step's own, to first order (`docs/amm.md` 2.2, "The sleeve rows to
//! first order"): what the tangent's probe needs of them without evaluating the modes anew.
//!
//! A direction moves each sleeve's material point `x_c` (through the rigid state, u and the
//! foreshortening) and the beam's coordinates by `eps` times their tangents. The rows' vectors
//! (the modes at the centre and edges and the slope at the centre) depend on `x_c` alone, their
//! bending sums on `x_c` and linearly on alpha, the truncation flexibility block on `x_c`. So,
//! per step, the values at the step's own `x_c` (kept by its update) and their derivatives in
//! `x_c` (central differences at `x_c +- NEAR_STEP`, shared by every direction) give each
//! direction's rows as `v + dx v'`, with `dx` its own material point less the step's; the rest
//! of the update (the material point and the shift, the u gradients, Eqs. S3-S5) is evaluated
//! exactly as in [`super::Sleeves::update`].

use super::Sleeves;
use crate::modes::ModeSet;
use crate::system::BeamRows;

/// Half the step of the central differences in `x_c` [m]: their truncation is `(NEAR_STEP
/// beta)^2 / 6` of a mode's derivative (2e-8 at the largest `beta` of the accurate model's
/// default, about 330 1/m), their round-off about `1e-16 / NEAR_STEP` of its value.
pub(crate) const NEAR_STEP: f64 = 1e-6;

/// A step's sleeve values and their derivatives in the material point, per beam.
#[derive(Debug, Clone)]
pub(crate) struct SleevesNear {
    /// The material points of the update [m].
    xc: [f64; 3],
    /// Each beam's coordinates alpha at the update (the step's predictor).
    alpha: [Vec<f64>; 3],
    /// Each beam's vectors `[mid, right, left, slope]` at `xc` (the slope as the modes give it,
    /// before the slope row's sign), then their derivatives in `xc` [1/m].
    v: [[Vec<f64>; 4]; 3],
    dv: [[Vec<f64>; 4]; 3],
    /// The bending sums `[w'(left), w'(right), w''(mid)]` and their derivatives in `xc`.
    bent: [[f64; 3]; 3],
    dbent: [[f64; 3]; 3],
    /// The truncation flexibility blocks (Eq. R3) and their derivatives in `xc`.
    res: [[[f64; 4]; 4]; 3],
    dres: [[[f64; 4]; 4]; 3],
    /// Workspace: a slope vector with the slope row's sign.
    minus_slope: Vec<f64>,
}

impl SleevesNear {
    /// Workspaces for beams of `nm` coordinates.
    pub(crate) fn new(nm: usize) -> Self {
        let vecs = || std::array::from_fn(|_| std::array::from_fn(|_| vec![0.0; nm]));
        SleevesNear {
            xc: [0.0; 3],
            alpha: std::array::from_fn(|_| vec![0.0; nm]),
            v: vecs(),
            dv: vecs(),
            bent: [[0.0; 3]; 3],
            dbent: [[0.0; 3]; 3],
            res: [[[0.0; 4]; 4]; 3],
            dres: [[[0.0; 4]; 4]; 3],
            minus_slope: vec![0.0; nm],
        }
    }

    /// Keep an update's values: the beams' vectors just evaluated at `xc` [m] (slope not yet
    /// negated), their bending sums, and the coordinates of `qhat`.
    pub(super) fn keep(
        &mut self,
        beams: &[BeamRows; 3],
        bent: &[crate::modes::SleeveBending; 3],
        xc: [f64; 3],
        qhat: &[f64],
        nm: usize,
    ) {
        let nb = nm + 2;
        self.xc = xc;
        for i in 0..3 {
            for (v, s) in self.v[i].iter_mut().zip(&beams[i].sleeve) {
                v.copy_from_slice(s);
            }
            self.alpha[i].copy_from_slice(&qhat[i * nb..i * nb + nm]);
            let b = &bent[i];
            self.bent[i] = [b.slope_left, b.slope_right, b.curvature];
        }
    }
}

impl Sleeves {
    /// The derivatives in `x_c` of the values `base` kept at its last update (with its blocks
    /// `base.res`), by central differences at `x_c +- NEAR_STEP` evaluated on these sleeves and
    /// `beams` (a probe's, used as workspace) with the coordinates of `qhat` (the step's
    /// predictor). No-op where `base` keeps nothing.
    pub(crate) fn linearise(
        &mut self,
        beams: &mut [BeamRows; 3],
        modes: [&ModeSet; 3],
        base: &mut Sleeves,
        qhat: &[f64],
    ) {
        let res = base.res;
        let Some(near) = base.kept.as_deref_mut() else {
            return;
        };
        near.res = res;
        let inv = 0.5 / NEAR_STEP;
        for sign in [1.0, -1.0] {
            let xc = near.xc.map(|x| x + sign * NEAR_STEP);
            self.evaluate_modes(beams, modes, xc, qhat);
            for (i, beam) in beams.iter().enumerate() {
                let scaled = sign * inv;
                let first = sign > 0.0;
                for (d, v) in near.dv[i].iter_mut().zip(&beam.sleeve) {
                    for (d, v) in d.iter_mut().zip(v) {
                        *d = if first { scaled * v } else { *d + scaled * v };
                    }
                }
                let b = &self.bent[i];
                for (d, v) in near.dbent[i].iter_mut().zip([b.slope_left, b.slope_right, b.curvature]) {
                    *d = if first { scaled * v } else { *d + scaled * v };
                }
                let [mid, right, left, slope] = &beam.sleeve;
                for (m, s) in near.minus_slope.iter_mut().zip(slope) {
                    *m = -s;
                }
                if let Some(block) = self.compliance_block(i, xc[i], [mid, right, left, &near.minus_slope]) {
                    for (drow, brow) in near.dres[i].iter_mut().zip(block) {
                        for (d, v) in drow.iter_mut().zip(brow) {
                            *d = if first { scaled * v } else { *d + scaled * v };
                        }
                    }
                }
            }
        }
    }

    /// [`Sleeves::update`] about the values `near` kept at a step's update, to first order in
    /// the moved material points and coordinates (module docs): the rows for the sleeve
    /// positions `xp` [m] about the predictor `qhat`.
    pub(crate) fn update_near(
        &mut self,
        beams: &mut [BeamRows; 3],
        rows: &[crate::system::Row],
        xp: [f64; 3],
        qhat: &[f64],
        near: &SleevesNear,
    ) {
        let nm = beams[0].sleeve[0].len();
        let nb = nm + 2;
        let shifts = self.place(xp, qhat, nm);
        let full = self.is_full();
        let mut res = near.res;
        for (i, beam) in beams.iter_mut().enumerate() {
            let dx = self.xc[i] - near.xc[i];
            for ((out, v), d) in beam.sleeve.iter_mut().zip(&near.v[i]).zip(&near.dv[i]) {
                for ((o, v), d) in out.iter_mut().zip(v).zip(d) {
                    *o = v + dx * d;
                }
            }
            if full {
                // the sums' change in alpha: the derivative vectors of the edges' values and of
                // the centre's slope against the coordinates' change
                let alpha = &qhat[i * nb..i * nb + nm];
                let [_, right, left, slope] = &near.dv[i];
                let mut change = [0.0; 3];
                for (j, (a, a0)) in alpha.iter().zip(&near.alpha[i]).enumerate() {
                    let da = a - a0;
                    change[0] += left[j] * da;
                    change[1] += right[j] * da;
                    change[2] += slope[j] * da;
                }
                let sums = std::array::from_fn::<f64, 3, _>(|k| near.bent[i][k] + dx * near.dbent[i][k] + change[k]);
                let b = &mut self.bent[i];
                [b.slope_left, b.slope_right, b.curvature] = sums;
            }
            for (r, d) in res[i].iter_mut().zip(&near.dres[i]) {
                for (r, d) in r.iter_mut().zip(d) {
                    *r += dx * d;
                }
            }
        }
        let res = (!self.own_flexibility).then_some(&res);
        self.finish(beams, rows, qhat, shifts, res);
    }
}
