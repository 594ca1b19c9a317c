//! Structured direct solver of the Newton matrix of the star (issue 13): three banded beam blocks
//! coupled only through a small border (the weld node G, and per sleeve its 7 multipliers, 3
//! contact coordinates and its rotation).
//!
//! With the unknowns split into beam DOFs `b` (nodes 1..ne of each beam) and border DOFs `s`
//! (36: `[nu_i (7), xi_i (3), psi_i]` per sleeve, then G; 39 in the direct problem of issue 10,
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
/// Border unknowns per sleeve: 7 multipliers, 3 contact coordinates, 1 rotation.
const SLEEVE_BORDER: usize = 11;
/// Border size of the inverse problem: G and three sleeves.
const NS_STAR: usize = 3 + 3 * SLEEVE_BORDER;
/// Border size of the direct problem: also the three slider coordinates `s_i`.
const NS_MAX: usize = NS_STAR + 3;
/// Values per slider in the slider slot group: the diagonal, then `(row r, s_i)` and
/// `(s_i, row r)` for the 6 position rows r of sleeve i.
pub(crate) const SLIDER_SLOTS: usize = 13;
/// Constraint rows per sleeve, hence multiplier columns of `W_i`.
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
    /// Offset of the sleeve diagonals `[psi_i, xi_i0, xi_i1, xi_i2]` (4 per sleeve).
    pub off_psi: usize,
    /// Offset of the constraint rows: per row `2 ncol` values, the row block then its transpose,
    /// columns = the window's node DOFs, then `xi`, then `psi`.
    pub off_con: usize,
    pub ncol: usize,
    /// Window width in elements (the window covers nodes `lo..=lo + ww`).
    pub ww: usize,
    /// Direct problem only: offset of the slider slot group ([`SLIDER_SLOTS`] values per slider).
    pub off_sl: Option<usize>,
}

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

/// Border index of multiplier r, contact coordinate p and rotation of sleeve i.
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

/// Entry t of row c of node m (tip-first rows, see [`Bordered::fill_band`]) of a beam block,
/// from the element blocks `prev` (element m - 1, whose second node is m) and `next` (element m,
/// whose first node is m; zero at the tip): `t = 2 - c + c'` couples with DOF c' of node m + 1
/// (the `prev`-side neighbour in tip-first order), `t = HB - c + c'` (`c' <= c`) with node m.
#[inline(always)]
fn band_entry(prev: Block, next: Block, c: usize, t: usize) -> f64 {
    if t + c >= HB {
        let cc = c + t - HB;
        prev[6 * (3 + c) + 3 + cc] + next[6 * c + cc]
    } else if t + c >= 2 {
        next[6 * c + 3 + (t + c - 2)]
    } else {
        0.0
    }
}

/// Row j (padded storage) of a banded Cholesky factorisation `A = L L^T` in place: with `a` the
/// row of `A`, `L[j][k] = (a[k] - sum_{m<k} L[j][m] L[k][m]) / L[k][k]` for `k = j - HB..j`, then
/// `L[j][j] = sqrt(a[j] - sum_{k<j} L[j][k]^2)` and its reciprocal. The pad rows are zero, so every
/// row runs the same fixed loops. Returns the pivot `a[j] - sum L[j][k]^2` (the row is garbage
/// where it is not positive). Generic so that the lanes can be checked against `f64`.
#[inline(always)]
fn cholesky_row<T: Real>(band: &mut [[T; HB + 1]], dinv: &mut [T], j: usize) -> T {
    let mut row = band[j];
    // entry t of the row is column k = j - HB + t; row k holds (k, m) at HB - (k - m)
    let prev: &[[T; HB + 1]; HB] = band[j - HB..j].try_into().expect("HB rows before row j");
    let dprev: &[T; HB] = dinv[j - HB..j].try_into().expect("HB rows before row j");
    for t in 0..HB {
        let rk = &prev[t];
        let mut v = row[t];
        for u in 0..t {
            v -= row[u] * rk[HB - t + u];
        }
        row[t] = v * dprev[t];
    }
    let mut d = row[HB];
    for u in 0..HB {
        d -= row[u] * row[u];
    }
    row[HB] = d.sqrt();
    dinv[j] = T::splat(1.0) / row[HB];
    band[j] = row;
    d
}

/// Whether a Cholesky pivot is usable: positive and finite.
#[inline(always)]
fn pivot_ok(d: f64) -> bool {
    d > 0.0 && d < f64::INFINITY
}

/// Whether the pivots of all three beams are usable (lane by lane, without branches).
#[inline(always)]
fn beam_pivots_ok(d: F64x4) -> bool {
    (0..BEAMS).fold(true, |ok, i| ok & pivot_ok(d.0[i]))
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

/// Upper triangle of `X^T X` (packed, see [`tri`]) of the rows `x` of `ROWS` columns, each entry
/// summed over the rows in order.
#[inline(always)]
fn gram_upper<T: Real>(x: &[[T; ROWS]]) -> [T; TRI] {
    let mut acc = [T::splat(0.0); TRI];
    for row in x {
        let mut k = 0;
        for a in 0..ROWS {
            for b in a..ROWS {
                acc[k] += row[a] * row[b];
                k += 1;
            }
        }
    }
    keep_lanes(acc)
}

/// `x`, all of its lanes kept: a caller that reads only the beams' lanes would otherwise let
/// the compiler drop the idle lane and regroup the remaining scalar sums into badly packed
/// vectors (a hint on the code only, the values are unchanged).
#[inline(always)]
fn keep_lanes<X>(x: X) -> X {
    std::hint::black_box(x)
}

/// `y <- L^{-T} y` on rows `HB..y.len() - HB` (padded storage, the `HB` rows after are zero):
/// `y[j] <- (y[j] - sum_{t=HB..1} L[j+t][j] y[j+t]) L[j][j]^{-1}`, the farthest row first.
#[inline(always)]
fn backward_rows<T: Real>(band: &[[T; HB + 1]], dinv: &[T], y: &mut [[T; 1]]) {
    let len = y.len();
    let (band, dinv) = (&band[..len], &dinv[..len]);
    for j in (HB..len - HB).rev() {
        let next: &[[T; 1]; HB] = y[j + 1..j + 1 + HB].try_into().expect("HB rows after row j");
        let below: &[[T; HB + 1]; HB] = band[j + 1..j + 1 + HB].try_into().expect("HB rows after row j");
        let mut v = y[j][0];
        for t in (0..HB).rev() {
            v -= below[t][HB - 1 - t] * next[t][0];
        }
        y[j][0] = v * dinv[j];
    }
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

    /// Factorise the matrix whose values are `vals` (star slot layout) with the windows `win`
    /// (first element of the window of each contact point, [sleeve][point]). `Err` names the
    /// failing pivot.
    pub fn factor(&mut self, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), PivotError> {
        let this = self;
        flexstar_numerics::dispatch_avx2!(fn(this: &mut Bordered, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), PivotError> {
            this.factor_inline(vals, win)
        })
    }

    /// [`Bordered::factor`], inlined into its AVX2 and baseline copies.
    #[inline(always)]
    fn factor_inline(&mut self, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), PivotError> {
        let ns = self.ns;
        self.s.fill(0.0);
        self.fill_band(vals);
        if !self.cholesky_fast() {
            self.name_failing_pivot(vals)?;
        }
        self.border_columns(vals, win);
        let l = self.lay;
        for i in 0..3 {
            self.s[border_psi(i) * (ns + 1)] += vals[l.off_psi + 4 * i];
            for p in 0..3 {
                self.s[border_xi(i, p) * (ns + 1)] += vals[l.off_psi + 4 * i + 1 + p];
            }
        }
        if let Some(off) = l.off_sl {
            self.slider_border(off, vals);
        }
        self.lu_schur()
    }

    /// Direct problem: the slider coordinates' diagonal and their coupling with the position
    /// rows of their sleeve (`-u_i`), all within the border.
    #[inline(always)]
    fn slider_border(&mut self, off: usize, vals: &[f64]) {
        let ns = self.ns;
        for i in 0..3 {
            let base = off + SLIDER_SLOTS * i;
            let bs = border_sl(i);
            self.s[bs * (ns + 1)] += vals[base];
            for r in 0..6 {
                let nu = border_nu(i, r);
                self.s[nu * ns + bs] += vals[base + 1 + 2 * r];
                self.s[bs * ns + nu] += vals[base + 2 + 2 * r];
            }
        }
    }

    /// Bands of the three beams from their element blocks, every row written once: node m
    /// (tip-first rows `3 (ne - m) + c`) sums the second-node block of element m - 1 and the
    /// first-node block of element m (none at the tip) and couples with node m + 1 through
    /// element m. The G-G parts of the elements 0 go to the border.
    #[inline(always)]
    fn fill_band(&mut self, vals: &[f64]) {
        let (ns, ne) = (self.ns, self.lay.ne);
        let tip = Block::zero();
        let rows = &mut self.band[HB..HB + 3 * ne];
        for (node, r) in rows.chunks_exact_mut(3).enumerate() {
            let m = ne - node;
            // explicit loops: the closures of std::array::from_fn are not always inlined here
            let mut prev = [tip; BEAMS];
            let mut next = [tip; BEAMS];
            for i in 0..BEAMS {
                prev[i] = Self::element_block(vals, ne, i, m - 1);
                if m < ne {
                    next[i] = Self::element_block(vals, ne, i, m);
                }
            }
            for (c, row) in r.iter_mut().enumerate() {
                for t in 0..=HB {
                    let idle = if t == HB { 1.0 } else { 0.0 };
                    row[t] = F64x4([
                        band_entry(prev[0], next[0], c, t),
                        band_entry(prev[1], next[1], c, t),
                        band_entry(prev[2], next[2], c, t),
                        idle,
                    ]);
                }
            }
        }
        for i in 0..BEAMS {
            let blk0 = Self::element_block(vals, ne, i, 0);
            for a in 0..3 {
                for b in 0..3 {
                    self.s[border_g(a) * ns + border_g(b)] += blk0[6 * a + b];
                }
            }
        }
    }

    /// In-place banded Cholesky of the three beams (one lane each), with the reciprocals of the
    /// diagonal, without a test per row; whether every pivot `d` was usable (positive and
    /// finite). That holds exactly when `L[j][j] = sqrt(d)` and `1 / L[j][j]` are finite in every
    /// row, i.e. when the sum over the rows of `(L[j][j] + 1 / L[j][j]) 0` is zero (not NaN; the
    /// sum of the two is below 1e162).
    #[inline(always)]
    fn cholesky_fast(&mut self) -> bool {
        let n = 3 * self.lay.ne;
        let mut nan_if_bad = F64x4::splat(0.0);
        for j in HB..n + HB {
            cholesky_row(&mut self.band, &mut self.dinv, j);
            nan_if_bad += (self.band[j][HB] + self.dinv[j]) * 0.0;
        }
        // all four lanes (the idle one is the identity, always usable): testing only the beams'
        // would let the compiler drop the idle lane and regroup the rows' arithmetic badly
        nan_if_bad.0.iter().all(|&x| x == 0.0)
    }

    /// The bands and their Cholesky again, testing every row, to name the first failing pivot
    /// (rare: the caller then falls back to the sparse LU).
    #[cold]
    #[inline(never)]
    fn name_failing_pivot(&mut self, vals: &[f64]) -> Result<(), PivotError> {
        self.fill_band(vals);
        self.cholesky()
    }

    /// [`Bordered::cholesky_fast`], testing every row: `Err` names the first beam (lowest row,
    /// then lowest beam) whose pivot is not positive and finite.
    #[inline(always)]
    fn cholesky(&mut self) -> Result<(), PivotError> {
        let n = 3 * self.lay.ne;
        for j in HB..n + HB {
            let d = cholesky_row(&mut self.band, &mut self.dinv, j);
            if !beam_pivots_ok(d) {
                let i = (0..BEAMS).find(|&i| !pivot_ok(d.0[i])).unwrap_or(BEAMS);
                return Err(PivotError::BeamBlock {
                    beam: i + 1,
                    row: j - HB,
                    pivot: d.0[i],
                });
            }
        }
        Ok(())
    }

    /// `E_i` (G columns from element 0, multiplier columns from the constraint rows; couplings
    /// of the multipliers with G, xi and psi go to the border), then `W_i = L_i^{-1} E_i` and
    /// `S -= W_i^T W_i` (its multiplier block from the upper triangle, accumulated row by row).
    #[inline(always)]
    fn border_columns(&mut self, vals: &[f64], win: &[[usize; 3]; 3]) {
        let ns = self.ns;
        let l = self.lay;
        let (ne, n) = (l.ne, 3 * l.ne);
        // first row touched by a window: node min(lo + ww, ne), tip-first; the earliest beam's
        let first = |i: usize| {
            (0..3)
                .map(|p| 3 * (ne - (win[i][p] + l.ww).min(ne)))
                .min()
                .unwrap_or(0)
                .min(n - 3)
        };
        let from = (0..BEAMS).map(first).min().unwrap_or(0);
        self.w_from = from;
        let w = &mut self.w[..n + HB];
        // rows from - HB..n zero (the pad before `from` keeps the loops below fixed-length)
        w[from..].fill([F64x4::splat(0.0); ROWS]);
        for i in 0..BEAMS {
            for r in 0..ROWS {
                let p = [0, 0, 1, 1, 2, 2, 0][r];
                let lo = win[i][p];
                let base = l.off_con + (ROWS * i + r) * 2 * l.ncol;
                let nu = border_nu(i, r);
                for wn in 0..=l.ww {
                    let k = lo + wn;
                    for c in 0..3 {
                        let v = vals[base + 3 * wn + c];
                        if k == 0 {
                            self.s[border_g(c) * ns + nu] += v;
                            self.s[nu * ns + border_g(c)] += v;
                        } else {
                            w[3 * (ne - k) + c + HB][r].0[i] = v;
                        }
                    }
                }
                for (col, v) in [
                    (border_xi(i, p), vals[base + l.ncol - 2]),
                    (border_psi(i), vals[base + l.ncol - 1]),
                ] {
                    self.s[col * ns + nu] += v;
                    self.s[nu * ns + col] += v;
                }
            }
        }
        // W = L^{-1} E, multiplier columns: rows from..n, and the upper triangle of W^T W
        forward_rows(&self.band, &self.dinv, w, from + HB);
        let acc = gram_upper(&w[from + HB..]);
        for i in 0..BEAMS {
            // G columns: E_G lives in the rows of node 1 (the last three), from element 0
            let blk0 = Self::element_block(vals, ne, i, 0);
            let mut wg = [[0.0; 3]; 3];
            for c in 0..3 {
                let j = n - 3 + c + HB;
                for g in 0..3 {
                    let mut v = blk0[6 * (3 + c) + g];
                    for m in 0..c {
                        v -= self.band[j][HB - (c - m)].0[i] * wg[m][g];
                    }
                    wg[c][g] = v * self.dinv[j].0[i];
                }
            }
            self.wg[i] = wg;
            // S -= W^T W
            for a in 0..ROWS {
                for b in 0..ROWS {
                    self.s[border_nu(i, a) * ns + border_nu(i, b)] -= acc[tri(a, b)].0[i];
                }
            }
            for g in 0..3 {
                for h in 0..3 {
                    let v: f64 = (0..3).map(|c| wg[c][g] * wg[c][h]).sum();
                    self.s[border_g(g) * ns + border_g(h)] -= v;
                }
                for a in 0..ROWS {
                    let v: f64 = (0..3).map(|c| wg[c][g] * self.w[n - 3 + c + HB][a].0[i]).sum();
                    self.s[border_g(g) * ns + border_nu(i, a)] -= v;
                    self.s[border_nu(i, a) * ns + border_g(g)] -= v;
                }
            }
        }
    }

    /// LU with partial pivoting of the Schur complement, in place (`P S = L U`, unit `L` below
    /// the diagonal). Only the rows with a non-zero entry in the pivot column are updated (the
    /// sleeve blocks stay uncoupled until G, last), densely over the pivot row (an update by a
    /// zero entry of the pivot row changes nothing).
    #[inline(always)]
    fn lu_schur(&mut self) -> Result<(), PivotError> {
        let ns = self.ns;
        let s = &mut self.s[..ns * ns];
        for k in 0..ns {
            // pivot: the first largest |s[r][k]|, r >= k; and the rows r > k to update
            let (mut p, mut big) = (k, s[k * ns + k].abs());
            let (mut rows, mut nr) = ([0usize; NS_MAX], 0);
            for r in k + 1..ns {
                let v = s[r * ns + k];
                if v != 0.0 {
                    rows[nr] = r;
                    nr += 1;
                    if v.abs() > big {
                        (p, big) = (r, v.abs());
                    }
                }
            }
            self.perm[k] = p;
            if p != k {
                let (above, from_p) = s.split_at_mut(p * ns);
                above[k * ns..(k + 1) * ns].swap_with_slice(&mut from_p[..ns]);
            }
            let d = s[k * ns + k];
            if d == 0.0 || !d.is_finite() {
                return Err(PivotError::Schur { index: k, pivot: d });
            }
            let (upper, lower) = s.split_at_mut((k + 1) * ns);
            let pivot_row = &upper[k * ns + k + 1..];
            for &r in &rows[..nr] {
                let row = &mut lower[(r - k - 1) * ns..(r - k) * ns];
                // (row p now holds the old row k, which may be zero in column k)
                if row[k] != 0.0 {
                    let f = row[k] / d;
                    row[k] = f;
                    for (x, u) in row[k + 1..].iter_mut().zip(pivot_row) {
                        *x -= f * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solve `A x = rhs` in place (global ordering of the star) with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let this = self;
        flexstar_numerics::dispatch_avx2!(fn(this: &mut Bordered, rhs: &mut [f64]) -> () { this.solve_inline(rhs) })
    }

    /// [`Bordered::solve`], inlined into its AVX2 and baseline copies: with `y = L^{-1} b` (beam
    /// part), `S x_s = b_s - sum_i W_i^T y_i`, then `x_i = L_i^{-T} (y_i - W_i x_s)`.
    #[inline(always)]
    fn solve_inline(&mut self, rhs: &mut [f64]) {
        let n = 3 * self.lay.ne;
        let ns = self.ns;
        let mut xs = [0.0; NS_MAX];
        for (b, x) in xs.iter_mut().enumerate().take(ns) {
            *x = rhs[self.global[b]];
        }
        let dofs = self.beam_dofs();
        let y = &mut self.y[..n + 2 * HB];
        // forward: y_i = L_i^{-1} b_i, xs -= W_i^T y_i
        beam_rows(&mut y[HB..HB + n], &mut rhs[dofs.clone()], |yj, b| {
            *yj = [beam_lanes(0.0, |i| *b[i])]
        });
        forward_rows(&self.band, &self.dinv, &mut y[..n + HB], HB);
        let rows = self.w_from + HB..n + HB;
        let mut acc = [F64x4::splat(0.0); ROWS];
        for (wj, yj) in self.w[rows.clone()].iter().zip(&y[rows.clone()]) {
            for a in 0..ROWS {
                acc[a] += wj[a] * yj[0];
            }
        }
        let acc = keep_lanes(acc);
        for i in 0..BEAMS {
            for a in 0..ROWS {
                xs[border_nu(i, a)] -= acc[a].0[i];
            }
            for g in 0..3 {
                xs[border_g(g)] -= (0..3)
                    .map(|c| self.wg[i][c][g] * y[HB + n - 3 + c][0].0[i])
                    .sum::<f64>();
            }
        }
        // border: S xs = rhs_s - sum W^T y
        border_solve(&self.s[..ns * ns], &self.perm[..ns], &mut xs[..ns]);
        // back: x_i = L_i^{-T} (y_i - W_i xs)
        let xb: [F64x4; ROWS] = std::array::from_fn(|a| beam_lanes(0.0, |i| xs[border_nu(i, a)]));
        for (wj, yj) in self.w[rows.clone()].iter().zip(&mut y[rows]) {
            let mut v = F64x4::splat(0.0);
            for a in 0..ROWS {
                v += wj[a] * xb[a];
            }
            yj[0] -= v;
        }
        for i in 0..BEAMS {
            for c in 0..3 {
                y[HB + n - 3 + c][0].0[i] -= (0..3).map(|g| self.wg[i][c][g] * xs[border_g(g)]).sum::<f64>();
            }
        }
        backward_rows(&self.band, &self.dinv, y);
        beam_rows(&mut y[HB..HB + n], &mut rhs[dofs], |yj, b| {
            for (i, x) in b.into_iter().enumerate() {
                *x = yj[0].0[i];
            }
        });
        for (b, x) in xs.iter().enumerate().take(ns) {
            rhs[self.global[b]] = *x;
        }
    }
}

/// `xs <- S^{-1} xs` with the LU factors of the border in place in `s` (row permutation `perm`,
/// unit lower and upper triangle).
#[inline(always)]
fn border_solve(s: &[f64], perm: &[usize], xs: &mut [f64]) {
    let ns = xs.len();
    for (k, &p) in perm.iter().enumerate() {
        xs.swap(k, p);
    }
    for (k, row) in s.chunks_exact(ns).enumerate() {
        let (done, rest) = xs.split_at_mut(k);
        rest[0] = row[..k].iter().zip(&*done).fold(rest[0], |v, (l, x)| v - l * x);
    }
    for (k, row) in s.chunks_exact(ns).enumerate().rev() {
        let (todo, done) = xs.split_at_mut(k + 1);
        let v = row[k + 1..].iter().zip(&*done).fold(todo[k], |v, (u, x)| v - u * x);
        todo[k] = v / row[k];
    }
}

/// Visits every beam row j (tip-first, `y[j]`, lanes) with its three entries in `dofs` (the
/// global DOFs of the beams' nodes 1..=ne, beam after beam, G-first: row `3 (ne - m) + c` of
/// beam i is DOF c of its node m).
#[inline(always)]
fn beam_rows(y: &mut [VecRow], dofs: &mut [f64], mut f: impl FnMut(&mut VecRow, [&mut f64; BEAMS])) {
    let n = y.len();
    let (d0, rest) = dofs.split_at_mut(n);
    let (d1, d2) = rest.split_at_mut(n);
    let nodes = d0
        .rchunks_exact_mut(3)
        .zip(d1.rchunks_exact_mut(3))
        .zip(d2.rchunks_exact_mut(3));
    for (yn, ((n0, n1), n2)) in y.chunks_exact_mut(3).zip(nodes) {
        for (c, yj) in yn.iter_mut().enumerate() {
            // the three slices are disjoint: one entry of each
            let [a, b, e] = [&mut n0[c], &mut n1[c], &mut n2[c]];
            f(yj, [a, b, e]);
        }
    }
}

#[cfg(test)]
mod tests {
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
