//! Structured direct solver of the Newton matrix of the star (`docs/fem.md` section 6): three banded beam blocks
//! coupled only through a small border (the weld node G, and per sleeve its 7 multipliers, 3
//! contact coordinates and its rotation). What those border rows and unknowns mean, the sleeve's
//! constraint rows and coordinates, is said in `crate::star::sleeve`; this module only solves.
//!
//! With the unknowns split into beam DOFs `b` (nodes 1..ne of each beam) and border DOFs `s`
//! (36: `[nu_i (7), xi_i (3), psi_i]` per sleeve, then G; 39 in the direct problem (`docs/fem.md` section 8),
//! whose slider coordinates `s_i` couple only with their sleeve's multipliers and join the border
//! last), the symmetric matrix is
//!
//! ```text
//! [ B   E ]    B = diag(B_1, B_2, B_3),  B_i = (M + beta' K) of beam i without G:
//! [ E^T S0]    banded, half bandwidth 5, symmetric positive definite
//! ```
//!
//! Each `B_i` is factorised by a banded Cholesky `B_i = L_i L_i^T` with the beam's nodes ordered
//! from the tip to G, so that the multiplier columns of `W_i = L_i^{-1} E_i` are non-zero only
//! from the sleeve's window to the G end, and its G columns only in the last three rows. The Schur complement
//! `S = S0 - sum_i W_i^T W_i` (36 x 36) is factorised by an LU with partial pivoting that skips
//! the zeros of each pivot row: `S` is an arrowhead (the sleeve blocks couple only through G, last),
//! so without pivoting across blocks the sleeves fill in nothing between them. Work per
//! factorisation: O(ne) for the bands, O(ne x 7 columns) for `W_i`, about 3 x 11^3/3 for `S`; no
//! allocation after construction.
//!
//! **Lanes.** The three beam blocks have the same structure (same `n = 3 ne`, same band), so
//! their bands, reciprocal diagonals, multiplier columns `W_i` and work vectors are stored
//! interleaved: row j of all three beams is one [`F64x4`] per entry, beam i in lane i, and lane 3
//! holds the identity (diagonal 1, zero elsewhere) so that it never fails a pivot. One lane
//! operation then does a row of all three Cholesky factorisations and substitutions. Each lane
//! computes exactly the scalar operations of its beam, in the same order (lane operations are the
//! IEEE ones, no fused multiply-add), so the results are those of three separate scalar
//! solvers. The multiplier columns start, for all lanes, at the first row of the earliest window;
//! the rows of a beam before its own window are exact zeros, and the products with them add
//! exact zeros.
//!
//! The layout of the matrix values (element blocks, sleeve diagonals, constraint rows in window
//! columns) is the slot layout of `crate::star`, described by [`Layout`]. A non-positive Cholesky
//! pivot or a singular Schur complement is reported as an error; the caller then falls back to
//! the general sparse LU.

use flexstar_numerics::lanes::{F64x4, Real};

use crate::element_pass::Block;
use crate::error::PivotError;

/// Half bandwidth of a beam block: node DOFs couple with the next node's 3 DOFs.
const HB: usize = 5;
/// Beams, one per lane of [`F64x4`] (lane 3 is idle).
const BEAMS: usize = 3;
/// Border unknowns per sleeve: 7 multipliers, 3 contact coordinates, 1 rotation (the rows and
/// coordinates of `crate::star::sleeve`).
const SLEEVE_BORDER: usize = 11;
/// Border size of the inverse problem: G and three sleeves.
const NS_STAR: usize = 3 + 3 * SLEEVE_BORDER;
/// Border size of the direct problem: also the three slider coordinates `s_i`.
const NS_MAX: usize = NS_STAR + 3;
/// Values per slider in the slider slot group: the diagonal, then `(row r, s_i)` and
/// `(s_i, row r)` for the 6 position rows r of sleeve i.
pub(crate) const SLIDER_SLOTS: usize = 13;
/// Constraint rows per sleeve (`crate::star::sleeve::ROWS`), hence multiplier columns of `W_i`.
const ROWS: usize = 7;
/// Entries of the upper triangle of the symmetric `ROWS x ROWS` block `W_i^T W_i`.
const TRI: usize = ROWS * (ROWS + 1) / 2;

/// One row of the three bands: entry `(j, j - HB + t)` at `t`, diagonal last.
type BandRow = [F64x4; HB + 1];
/// One row of a work vector of the three beams (one column).
type VecRow = [F64x4; 1];

/// Where the values of the Newton matrix sit in the star's value array.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    /// Elements per beam.
    pub ne: usize,
    /// Nodes (1 + 3 ne) and generalized coordinates.
    pub n_nodes: usize,
    pub n_dof: usize,
    /// Offset of the sleeve diagonals `[psi_i, xi_i0, xi_i1, xi_i2]` (4 per sleeve): the sleeve's
    /// inertia Jp, and 0 for the massless contact coordinates (`crate::star::sleeve`).
    pub off_psi: usize,
    /// Offset of the constraint rows (the sleeves' rows of `crate::star::sleeve`, 7 per sleeve):
    /// per row `2 ncol` values, the row block then its transpose, columns = the window's node
    /// DOFs, then `xi`, then `psi`.
    pub off_con: usize,
    pub ncol: usize,
    /// Window width in elements (the window covers nodes `lo..=lo + ww`).
    pub ww: usize,
    /// Direct problem only: offset of the slider slot group ([`SLIDER_SLOTS`] values per slider).
    pub off_sl: Option<usize>,
    /// Offset of the multiplier block of the tangent rows ([`NU_SLOTS`] values per sleeve:
    /// `(tangent, tangent)`, `(tangent, centre x)`, `(tangent, centre y)`; Eq. S9 of
    /// `docs/fem.md` section 2.1), all within the border.
    pub off_nu: usize,
    /// With friction only: offset of the friction slot group (per sleeve, the centre
    /// coordinate's row against the sleeve's 7 multipliers, `crate::star::friction`), within
    /// the border and added to the symmetric entries there.
    pub off_fr: Option<usize>,
}

/// Values per sleeve in the multiplier-block slot group (see [`Layout::off_nu`]).
pub(crate) const NU_SLOTS: usize = 3;
/// Constraint rows (of the sleeve's 7, in the order of `crate::star::sleeve`) that the tangent
/// row's multiplier block couples with: the tangent row itself, then the centre's two position
/// rows.
pub(crate) const NU_COLUMNS: [usize; NU_SLOTS] = [6, 0, 1];

/// The factorisation and its workspaces. Beam rows are tip-first and stored `HB` rows further
/// (row j at `j + HB`), after `HB` zero pad rows, so that every row runs the same fixed-length
/// loops; all beam arrays are lane-interleaved (beam i in lane i).
pub(crate) struct Bordered {
    lay: Layout,
    /// Lower bands of the `L_i` (entry `(j, k)` at `[j + HB][HB - (j - k)]`), with `HB` zero
    /// rows before and after.
    band: Vec<BandRow>,
    /// Reciprocals of the diagonals of the `L_i` (same padding, zero in the pad rows).
    dinv: Vec<F64x4>,
    /// Multiplier columns of the `W_i`, rows `w_from..n + HB` valid (row j at `j + HB`).
    w: Vec<[F64x4; ROWS]>,
    /// G columns of `W_i` in its last three rows, `[row][G DOF]`, per beam.
    wg: [[[f64; 3]; 3]; BEAMS],
    /// First stored row of `w` in use: the padded row of the earliest window of the three
    /// (beam-local, tip-first ordering), minus the `HB` zero rows before it.
    w_from: usize,
    /// Schur complement, LU factors in place (row-major) and row permutation.
    s: Vec<f64>,
    perm: [usize; NS_MAX],
    /// Border size: 36, or 39 with the slider coordinates of the direct problem.
    ns: usize,
    /// Global unknown of every border index.
    global: [usize; NS_MAX],
    /// Work vector of the beams (same padding as the band, zero in the pad rows).
    y: Vec<VecRow>,
}

/// Border index of multiplier r (row r of `crate::star::sleeve`), contact coordinate p and
/// rotation of sleeve i.
fn border_nu(i: usize, r: usize) -> usize {
    SLEEVE_BORDER * i + r
}
fn border_xi(i: usize, p: usize) -> usize {
    SLEEVE_BORDER * i + ROWS + p
}
fn border_psi(i: usize) -> usize {
    SLEEVE_BORDER * i + ROWS + 3
}
/// Border index of the weld node's DOF c: after the sleeves, so that the dense LU of the border,
/// which eliminates in order, meets the arrowhead structure (sleeve blocks coupled only through
/// G) without fill between the sleeves.
fn border_g(c: usize) -> usize {
    3 * SLEEVE_BORDER + c
}
fn border_sl(i: usize) -> usize {
    NS_STAR + i
}

/// Position of `(a, b)` (either order) in the packed upper triangle of a symmetric
/// `ROWS x ROWS` matrix (row by row, `a <= b`).
#[inline(always)]
fn tri(a: usize, b: usize) -> usize {
    let (a, b) = (a.min(b), a.max(b));
    a * ROWS - a * (a + 1) / 2 + b
}

/// Lane value of beam i, or of the idle lane 3.
#[inline(always)]
fn beam_lanes(idle: f64, mut beam: impl FnMut(usize) -> f64) -> F64x4 {
    F64x4::from_fn(|i| if i < BEAMS { beam(i) } else { idle })
}

/// `x <- L^{-1} x` on rows `from..x.len()` (padded storage) for `C` columns at once:
/// `x[j] <- (x[j] - sum_{t<HB} L[j][j-HB+t] x[j-HB+t]) L[j][j]^{-1}`, the terms subtracted in the
/// order t = 0..HB (the newest row last). The rows before `from` must be final (or zero).
#[inline(always)]
fn forward_rows<T: Real, const C: usize>(band: &[[T; HB + 1]], dinv: &[T], x: &mut [[T; C]], from: usize) {
    let (band, dinv) = (&band[..x.len()], &dinv[..x.len()]);
    for j in from..x.len() {
        let prev: &[[T; C]; HB] = x[j - HB..j].try_into().expect("HB rows before row j");
        let l = &band[j];
        let mut row = x[j];
        for t in 0..HB {
            for a in 0..C {
                row[a] -= l[t] * prev[t][a];
            }
        }
        for v in row.iter_mut() {
            *v *= dinv[j];
        }
        x[j] = row;
    }
}

/// `x`, all of its lanes kept: a caller that reads only the beams' lanes would otherwise let
/// the compiler drop the idle lane and regroup the remaining scalar sums into badly packed
/// vectors (a hint on the code only, the values are unchanged).
#[inline(always)]
fn keep_lanes<X>(x: X) -> X {
    std::hint::black_box(x)
}

impl Bordered {
    pub fn new(lay: Layout) -> Self {
        let n = 3 * lay.ne;
        let ns = if lay.off_sl.is_some() { NS_MAX } else { NS_STAR };
        let mut global = [0usize; NS_MAX];
        for c in 0..3 {
            global[border_g(c)] = c;
        }
        for i in 0..3 {
            for r in 0..ROWS {
                global[border_nu(i, r)] = lay.n_dof + ROWS * i + r;
            }
            // the sleeve coordinates as `Star::xi`, `Star::psi` number them (`crate::star::sleeve`)
            for p in 0..3 {
                global[border_xi(i, p)] = 3 * lay.n_nodes + 3 + 3 * i + p;
            }
            global[border_psi(i)] = 3 * lay.n_nodes + i;
            // slider coordinates follow the 12 sleeve coordinates (direct problem only)
            global[border_sl(i)] = 3 * lay.n_nodes + 12 + i;
        }
        let zero = F64x4::splat(0.0);
        Bordered {
            lay,
            band: vec![[zero; HB + 1]; n + 2 * HB],
            dinv: vec![zero; n + 2 * HB],
            w: vec![[zero; ROWS]; n + HB],
            wg: [[[0.0; 3]; 3]; BEAMS],
            w_from: 0,
            s: vec![0.0; ns * ns],
            perm: [0; NS_MAX],
            ns,
            global,
            y: vec![[zero]; n + 2 * HB],
        }
    }

    /// Global DOFs of the beams' nodes 1..=ne, beam after beam (G-first within a beam).
    #[inline(always)]
    fn beam_dofs(&self) -> std::ops::Range<usize> {
        3..3 + 9 * self.lay.ne
    }

    /// The 36 values of element k of beam i.
    #[inline(always)]
    fn element_block(vals: &[f64], ne: usize, i: usize, k: usize) -> Block<'_> {
        Block::of(vals, i * ne + k)
    }
}

mod factor;
mod solve;

#[cfg(test)]
mod tests {
    use super::factor::{beam_pivots_ok, cholesky_row, pivot_ok};
    use super::solve::backward_rows;
    use super::*;

    /// A symmetric positive definite band per beam (diagonally dominant, entries from a hash of
    /// beam, row and column), padded as in [`Bordered`], `n` rows.
    fn test_band(beam: usize, n: usize) -> Vec<[f64; HB + 1]> {
        let mut band = vec![[0.0; HB + 1]; n + 2 * HB];
        for j in 0..n {
            for t in 0..HB {
                if j + t >= HB {
                    band[j + HB][t] = ((7 * beam + 3 * j + 11 * t) as f64 * 0.37).sin();
                }
            }
            band[j + HB][HB] = 6.0 + (j as f64 * 0.1 + beam as f64).cos();
        }
        band
    }

    /// Bit pattern of lane `i` of every entry.
    fn lane_bits<const C: usize>(rows: &[[F64x4; C]], i: usize) -> Vec<u64> {
        rows.iter()
            .flat_map(|r| r.iter().map(move |v| v.0[i].to_bits()))
            .collect()
    }
    fn bits<const C: usize>(rows: &[[f64; C]]) -> Vec<u64> {
        rows.iter().flat_map(|r| r.iter().map(|v| v.to_bits())).collect()
    }

    #[test]
    fn lanes_factor_and_substitute_bit_for_bit_like_each_beam_alone() {
        let n = 31;
        let scalar: Vec<Vec<[f64; HB + 1]>> = (0..BEAMS).map(|i| test_band(i, n)).collect();
        let interleave = |rows: &[Vec<[f64; HB + 1]>], idle: [f64; HB + 1]| -> Vec<BandRow> {
            (0..n + 2 * HB)
                .map(|j| std::array::from_fn(|t| beam_lanes(idle[t], |i| rows[i][j][t])))
                .collect()
        };
        let mut idle = [0.0; HB + 1];
        idle[HB] = 1.0;
        let mut band = interleave(&scalar, idle);
        let mut dinv = vec![F64x4::splat(0.0); n + 2 * HB];
        for j in HB..n + HB {
            assert!(beam_pivots_ok(cholesky_row(&mut band, &mut dinv, j)));
        }
        // right-hand sides: one column for the substitutions, three for the multi-column forward
        let rhs = |i: usize, j: usize, a: usize| {
            if (HB..n + HB).contains(&j) {
                ((i + 5 * j + 2 * a) as f64).cos()
            } else {
                0.0
            }
        };
        let mut y: Vec<VecRow> = (0..n + 2 * HB).map(|j| [beam_lanes(0.0, |i| rhs(i, j, 0))]).collect();
        let mut x: Vec<[F64x4; 3]> = (0..n + HB)
            .map(|j| std::array::from_fn(|a| beam_lanes(0.0, |i| rhs(i, j, a))))
            .collect();
        forward_rows(&band, &dinv, &mut y[..n + HB], HB);
        forward_rows(&band, &dinv, &mut x, HB + 7);
        let mut back = y.clone();
        backward_rows(&band, &dinv, &mut back);
        for (i, mut sb) in scalar.into_iter().enumerate() {
            let mut sd = vec![0.0; n + 2 * HB];
            for j in HB..n + HB {
                assert!(pivot_ok(cholesky_row(&mut sb, &mut sd, j)));
            }
            assert_eq!(lane_bits(&band, i), bits(&sb), "band of beam {i}");
            assert_eq!(
                lane_bits(&dinv.iter().map(|d| [*d]).collect::<Vec<_>>(), i),
                bits(&sd.iter().map(|d| [*d]).collect::<Vec<_>>())
            );
            let mut sy: Vec<[f64; 1]> = (0..n + 2 * HB).map(|j| [rhs(i, j, 0)]).collect();
            forward_rows(&sb, &sd, &mut sy[..n + HB], HB);
            assert_eq!(lane_bits(&y, i), bits(&sy), "forward of beam {i}");
            let mut sx: Vec<[f64; 3]> = (0..n + HB).map(|j| std::array::from_fn(|a| rhs(i, j, a))).collect();
            forward_rows(&sb, &sd, &mut sx, HB + 7);
            assert_eq!(lane_bits(&x, i), bits(&sx), "3-column forward of beam {i}");
            backward_rows(&sb, &sd, &mut sy);
            assert_eq!(lane_bits(&back, i), bits(&sy), "backward of beam {i}");
            // and the substitutions solve L L^T z = b: check against the band of A
            let a = test_band(i, n);
            for j in HB..n + HB {
                let mut az = a[j][HB] * sy[j][0];
                for t in 0..HB {
                    az += a[j][t] * sy[j - HB + t][0] + a[j + HB - t][t] * sy[j + HB - t][0];
                }
                assert!((az - rhs(i, j, 0)).abs() < 1e-12, "row {j} of beam {i}: {az}");
            }
        }
    }

    #[test]
    fn a_failing_pivot_names_its_beam_and_row() {
        let lay = Layout {
            ne: 4,
            n_nodes: 13,
            n_dof: 39,
            off_psi: 0,
            off_con: 0,
            ncol: 0,
            ww: 0,
            off_sl: None,
            off_nu: 0,
            off_fr: None,
        };
        let mut b = Bordered::new(lay);
        let n = 3 * lay.ne;
        for j in HB..n + HB {
            b.band[j][HB] = F64x4([4.0, 4.0, if j == HB + 7 { -1.0 } else { 4.0 }, 1.0]);
        }
        b.band[HB + 9][HB].0[1] = 0.0;
        let good = b.band.clone();
        assert!(!b.cholesky_fast());
        b.band.clone_from(&good);
        let err = b.cholesky().unwrap_err();
        assert_eq!(
            err,
            PivotError::BeamBlock {
                beam: 3,
                row: 7,
                pivot: -1.0
            }
        );
        assert_eq!(
            err.to_string(),
            "beam 3 block not positive definite at row 7 (pivot -1e0)"
        );
        for (bad, pivot) in [(f64::INFINITY, "inf"), (f64::NAN, "NaN"), (-0.0, "-0e0"), (1e-320, "")] {
            b.band.clone_from(&good);
            for row in &mut b.band[HB..n + HB] {
                row[HB] = F64x4::splat(4.0);
            }
            b.band[HB + 3][HB].0[1] = bad;
            let want = if pivot.is_empty() {
                Ok(())
            } else {
                Err(format!("beam 2 block not positive definite at row 3 (pivot {pivot})"))
            };
            assert_eq!(b.cholesky_fast(), want.is_ok(), "{bad:e}");
            b.band.clone_from(&good);
            for row in &mut b.band[HB..n + HB] {
                row[HB] = F64x4::splat(4.0);
            }
            b.band[HB + 3][HB].0[1] = bad;
            assert_eq!(b.cholesky().map_err(|e| e.to_string()), want, "{bad:e}");
        }
    }
}
