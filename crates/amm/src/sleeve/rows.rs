//! The four constraint rows of a sleeve (Eqs. 41-43, `docs/amm.md` section 1), their form on
//! the beam's coordinates, their full-model corrections (Eqs. S3-S4, `docs/amm.md` 12.11) and
//! the force their multipliers transmit to the slider (Eq. 33).
//!
//! Row k of a beam's constraint rows is `sc_k B[basis_k] . alpha + cu_k u + ct_k thp` (the
//! row form of `system`); the sleeve's rows use the four basis vectors [`B_MID`], [`B_RIGHT`],
//! [`B_LEFT`], [`B_MSLOPE`], numbered after the junction's two (`B_PHI0`, `B_DPHI0` of
//! `system`). Their multipliers are the generalized forces of the sleeve on the beam for the rows
//! as written: normal forces along `+e_wi` [N] at the centre and the edges, and a couple [N m].

use crate::star::Weld;
use flexstar_kinematics::RigidState;

use crate::system::{BeamRows, Row, RowForm};

/// Basis vector `phi_j(xp)` of the centre's row (Fp).
pub(crate) const B_MID: usize = 2;
/// Basis vector `phi_j(xp + Lp/2)` of the right edge's row (FR).
pub(crate) const B_RIGHT: usize = 3;
/// Basis vector `phi_j(xp - Lp/2)` of the left edge's row (FL).
pub(crate) const B_LEFT: usize = 4;
/// Basis vector `-phi_j'(xp)` of the slope row (Mp).
pub(crate) const B_MSLOPE: usize = 5;

/// One of the four rows of a sleeve, in the order of the constraint matrix (and of the sleeve
/// blocks of `constraint_lu`). The beam is that of [`Row::Sleeve`]; `xp`, `Lp` are the sleeve's
/// position on it and length [m].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SleeveRow {
    /// Eq. 41: `w_i(xp_i) = 0`; multiplier `Fp_i` [N], the normal force of the pin on the beam.
    Fp,
    /// Eq. 42: `w_i(xp_i + Lp/2) - Lp/2 thp_i = 0`; multiplier `FR_pi` [N] at the right edge.
    FR,
    /// Eq. 42: `w_i(xp_i - Lp/2) + Lp/2 thp_i = 0`; multiplier `FL_pi` [N] at the left edge.
    FL,
    /// Eq. 43: `thp_i - w_i'(xp_i) = 0` (full model: `sin thp_i - w_i'(x_c) = 0`, Eq. S5 of
    /// `docs/amm.md` 12.17); multiplier `Mp_i` [N m], the moment of the beam on the sleeve.
    Mp,
}

/// Rows of one sleeve (hence of one beam's sleeve block of the Schur complement, `constraint_lu`).
pub(crate) const SLEEVE_ROWS: usize = SleeveRow::ALL.len();

impl SleeveRow {
    /// The rows of a sleeve in the order of the constraint matrix.
    pub(crate) const ALL: [SleeveRow; 4] = [SleeveRow::Fp, SleeveRow::FR, SleeveRow::FL, SleeveRow::Mp];

    /// The row's block on its own beam, as written in Eqs. 41-43 (the paper's rigid material
    /// points): (basis vector, its factor, u coefficient, thp coefficient); `hp = Lp/2` [m].
    pub(crate) fn form(self, hp: f64) -> RowForm {
        match self {
            SleeveRow::Fp => (B_MID, 1.0, 0.0, 0.0),
            SleeveRow::FR => (B_RIGHT, 1.0, 0.0, -hp),
            SleeveRow::FL => (B_LEFT, 1.0, 0.0, hp),
            SleeveRow::Mp => (B_MSLOPE, 1.0, 0.0, 1.0),
        }
    }
}

/// What [`shift_rows`] needs of a beam's foreshortening at the predictor.
pub(super) struct ShiftTerms<'a> {
    /// The kept modes of `g` (indices into the beam's alpha).
    pub(super) kept: &'a [usize],
    /// `g = F(x_c) alpha` (Eq. S3) on them [-].
    pub(super) g: &'a [f64],
    /// `2 f(x_c) = g . alpha` [m].
    pub(super) two_f: f64,
    /// The sleeve rotation at the predictor [rad].
    pub(super) thp: f64,
    /// Half the sleeve length [m].
    pub(super) hp: f64,
    /// The beam's slope `w'` at the pin and at the right and left edges [-].
    pub(super) slopes: [f64; 3],
    /// The beam's curvature `w''` at the pin [1/m].
    pub(super) curvature: f64,
}

/// Eqs. S3-S5 (`docs/amm.md` 12.11, 12.17), after the rows' vectors were set at the material
/// point `x_c`: each sleeve row `r(x_c)` of `beam` gains the alpha gradient `r'(x_c) g` (`w'` at
/// the pin and the edges, `-w''` for the slope row); the edges' rows `w(x_c +- hp) -+ hp sin thp`
/// and the slope row `sin thp - w'(x_c)` (Eq. S5: the beam's tangent turns by `asin w'`, so a
/// straight beam in the sleeve meets all four rows) take their exact thp gradient (`-+ hp cos
/// thp`, `cos thp`); the rows' values stay `r(qhat)` through `gv`.
pub(super) fn shift_rows(beam: &mut BeamRows, rows: &[Row], t: ShiftTerms) {
    let [slope_mid, slope_right, slope_left] = t.slopes;
    let coef = [slope_mid, slope_right, slope_left, -t.curvature];
    for (v, c) in beam.sleeve.iter_mut().zip(coef) {
        for (&j, g) in t.kept.iter().zip(t.g) {
            v[j] += c * g;
        }
    }
    let (sin, cos) = t.thp.sin_cos();
    for (k, id) in beam.ids.iter().enumerate() {
        let Row::Sleeve(_, row) = rows[*id] else {
            continue;
        };
        let (c, arm) = match row {
            SleeveRow::Fp => (coef[0], 0.0),
            SleeveRow::FR => (coef[1], -t.hp),
            SleeveRow::FL => (coef[2], t.hp),
            SleeveRow::Mp => (coef[3], 1.0),
        };
        beam.gv[k] = -beam.sc[k] * c * t.two_f;
        if arm != 0.0 {
            beam.ct[k] = arm * cos;
            beam.gv[k] += arm * (sin - t.thp * cos);
        }
    }
}

/// Full model (`docs/amm.md` section 8): the u gradient of a sleeve row at the material point in
/// the sleeve, `-w'` at the pin and the edges (the axial components of their normal forces),
/// `+w''` at the pin for the slope row; `slope_mid`, `slope_right`, `slope_left` [-] and
/// `curvature` [1/m] of the beam there.
pub(super) fn u_gradient(row: SleeveRow, [slope_mid, slope_right, slope_left]: [f64; 3], curvature: f64) -> f64 {
    match row {
        SleeveRow::Fp => -slope_mid,
        SleeveRow::FR => -slope_right,
        SleeveRow::FL => -slope_left,
        SleeveRow::Mp => curvature,
    }
}

/// Eq. 33 without the slider's inertia: the component along `+u_i` of the force of sleeve i on
/// beam i [N] at the rigid state `st`, linear in the multipliers `[Fp, FL, FR]` [N]. Paper model
/// (`full == false`): `(Fp + FL + FR) cos(theta + thp_i)` with the sleeve rotation `thp` [rad];
/// full model: along the forces its rows carry, each row's force on the beam being
/// `lambda (e_w + c_u e_x)` with `c_u` its u gradient (`axial` = `[c_Fp, c_FR, c_FL]`, -w').
///
/// The rail's direction and the paper model's projection are those of `weld` (Eq. J7,
/// `docs/amm.md` 13: `cos(theta + phi_i + thp_i - a_i)`, `cos(theta + thp_i)` on the paper's robot).
pub(crate) fn push(
    full: bool,
    i: usize,
    st: &RigidState,
    thp: f64,
    [fp, fl, fr]: [f64; 3],
    axial: [f64; 3],
    weld: &Weld,
) -> f64 {
    if full {
        let d = weld.rails[i];
        let (ew, ex) = (st.e_w(i), st.e_x(i));
        let (wd, xd) = (ew[0] * d[0] + ew[1] * d[1], ex[0] * d[0] + ex[1] * d[1]);
        let [cp, cr, cl] = axial;
        (fp + fl + fr) * wd + (fp * cp + fr * cr + fl * cl) * xd
    } else {
        (fp + fl + fr) * weld.normal_along_rail(i, st.theta.v, thp)
    }
}
