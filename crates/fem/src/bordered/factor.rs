//! Factorisation of the bordered matrix: the beam bands and their Cholesky, the multiplier
//! columns `W_i`, and the LU of the Schur complement.

use super::*;

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
pub(super) fn cholesky_row<T: Real>(band: &mut [[T; HB + 1]], dinv: &mut [T], j: usize) -> T {
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
pub(super) fn pivot_ok(d: f64) -> bool {
    d > 0.0 && d < f64::INFINITY
}

/// Whether the pivots of all three beams are usable (lane by lane, without branches).
#[inline(always)]
pub(super) fn beam_pivots_ok(d: F64x4) -> bool {
    (0..BEAMS).fold(true, |ok, i| ok & pivot_ok(d.0[i]))
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

impl Bordered {
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
        // the tangent rows' compliance of the interior field (Eq. S9, `Star::interior_compliance`
        // of `crate::star::sleeve`), within each sleeve's block
        for i in 0..3 {
            let row = border_nu(i, ROWS - 1);
            for (k, &r) in NU_COLUMNS.iter().enumerate() {
                self.s[row * ns + border_nu(i, r)] += vals[l.off_nu + NU_SLOTS * i + k];
            }
        }
        if let Some(off) = l.off_fr {
            self.friction_border(off, vals);
        }
        self.lu_schur()
    }

    /// With friction: the sleeve centres' rows against their multipliers (`crate::star::friction`),
    /// added to the symmetric entries `border_columns` wrote.
    #[cold]
    fn friction_border(&mut self, off: usize, vals: &[f64]) {
        let ns = self.ns;
        for i in 0..3 {
            let row = border_xi(i, 0);
            for r in 0..ROWS {
                self.s[row * ns + border_nu(i, r)] += vals[off + ROWS * i + r];
            }
        }
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
    pub(super) fn fill_band(&mut self, vals: &[f64]) {
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
    pub(super) fn cholesky_fast(&mut self) -> bool {
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
    pub(super) fn cholesky(&mut self) -> Result<(), PivotError> {
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
            let wg = self.g_columns(vals, i);
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

    /// G columns of `W_i = L_i^{-1} E_i`: `E_G` lives in the rows of node 1 (the last three),
    /// from element 0, so only the last three rows of `L_i` take part.
    #[inline(always)]
    fn g_columns(&self, vals: &[f64], i: usize) -> [[f64; 3]; 3] {
        let (ne, n) = (self.lay.ne, 3 * self.lay.ne);
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
        wg
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
}
