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
//! factorisation: O(ne) for the bands, O(ne x 8 columns) for `W_i`, about 3 x 11^3/3 for `S`; no
//! allocation after construction. The three beams' factorisations and substitutions advance row by
//! row together (their dependency chains overlap in the processor).
//!
//! The layout of the matrix values (element blocks, sleeve diagonals, constraint rows in window
//! columns) is the slot layout of `crate::star`, described by [`Layout`]. A non-positive Cholesky
//! pivot or a singular Schur complement is reported as an error; the caller then falls back to
//! the general sparse LU.

/// Half bandwidth of a beam block: node DOFs couple with the next node's 3 DOFs.
const HB: usize = 5;
/// Stored columns of `W_i`: the 7 multipliers of sleeve i and one zero pad (8 = two 4-wide SIMD
/// lanes). The 3 G columns of `W_i` are non-zero only in the last three rows (`wg`).
const WC: usize = 8;
/// Border unknowns per sleeve: 7 multipliers, 3 contact coordinates, 1 rotation.
const SLEEVE_BORDER: usize = 11;
/// Border size of the inverse problem: G and three sleeves.
const NS_STAR: usize = 3 + 3 * SLEEVE_BORDER;
/// Border size of the direct problem: also the three slider coordinates `s_i`.
const NS_MAX: usize = NS_STAR + 3;
/// Values per slider in the slider slot group: the diagonal, then `(row r, s_i)` and
/// `(s_i, row r)` for the 6 position rows r of sleeve i.
pub(crate) const SLIDER_SLOTS: usize = 13;
/// Constraint rows per sleeve.
const ROWS: usize = 7;

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

/// The factorisation and its workspaces.
pub(crate) struct Bordered {
    lay: Layout,
    /// Lower band of `L_i`, one row of `HB + 1` values per beam row (entry `(j, k)` at
    /// `[j + HB][HB - (j - k)]`, diagonal last), with `HB` zero rows before and after so that
    /// every row has the same fixed-length loops; per beam.
    band: [Vec<[f64; HB + 1]>; 3],
    /// Reciprocals of the diagonal of `L_i` (same padding, zero in the pad rows), per beam.
    dinv: [Vec<f64>; 3],
    /// Multiplier columns of `W_i`, one row of `WC` values per beam row (row j at `j + HB`,
    /// the padding of the band), per beam.
    w: [Vec<[f64; WC]>; 3],
    /// G columns of `W_i` in its last three rows, `[row][G DOF]`, per beam.
    wg: [[[f64; 3]; 3]; 3],
    /// First non-zero row of the multiplier columns of `W_i` (beam-local, tip-first ordering).
    first: [usize; 3],
    /// Schur complement, LU factors in place (row-major) and row permutation.
    s: Vec<f64>,
    perm: [usize; NS_MAX],
    /// Border size: 36, or 39 with the slider coordinates of the direct problem.
    ns: usize,
    /// Global unknown of every border index.
    global: [usize; NS_MAX],
    /// Work vectors of the beams (same padding as the band: row j at `j + HB`).
    y: [Vec<f64>; 3],
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

/// Row j (padded storage) of a banded Cholesky factorisation in place (the pad rows are zero, so
/// every row runs the same fixed loops); returns the pivot, left unfactorised when it is not
/// positive.
#[inline(always)]
fn cholesky_row(band: &mut [[f64; HB + 1]], dinv: &mut [f64], j: usize) -> f64 {
    let mut row = band[j];
    // entry t of the row is column k = j - HB + t; row k holds (k, m) at HB - (k - m)
    for t in 0..HB {
        let rk = &band[j - HB + t];
        let mut v = row[t];
        for u in 0..t {
            v -= row[u] * rk[HB - t + u];
        }
        row[t] = v * dinv[j - HB + t];
    }
    let mut d = row[HB];
    for u in 0..HB {
        d -= row[u] * row[u];
    }
    if d > 0.0 && d.is_finite() {
        row[HB] = d.sqrt();
        dinv[j] = 1.0 / row[HB];
        band[j] = row;
    }
    d
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
        Bordered {
            lay,
            band: std::array::from_fn(|_| vec![[0.0; HB + 1]; n + 2 * HB]),
            dinv: std::array::from_fn(|_| vec![0.0; n + 2 * HB]),
            w: std::array::from_fn(|_| vec![[0.0; WC]; n + HB]),
            wg: [[[0.0; 3]; 3]; 3],
            first: [0; 3],
            s: vec![0.0; ns * ns],
            perm: [0; NS_MAX],
            ns,
            global,
            y: std::array::from_fn(|_| vec![0.0; n + 2 * HB]),
        }
    }

    /// Global DOF of beam-local row j (tip-first) of beam i: node k = ne - j / 3.
    #[inline]
    fn global_row(&self, i: usize, j: usize) -> usize {
        let ne = self.lay.ne;
        3 * (i * ne + ne - j / 3) + j % 3
    }

    /// Factorise the matrix whose values are `vals` (star slot layout) with the windows `win`
    /// (first element of the window of each contact point, [sleeve][point]). `Err` names the
    /// failing pivot.
    pub fn factor(&mut self, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), String> {
        let this = self;
        flexstar_numerics::dispatch_avx2!(fn(this: &mut Bordered, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), String> {
            this.factor_inline(vals, win)
        })
    }

    /// [`Bordered::factor`], inlined into its AVX2 and baseline copies.
    #[inline(always)]
    fn factor_inline(&mut self, vals: &[f64], win: &[[usize; 3]; 3]) -> Result<(), String> {
        let ns = self.ns;
        self.s.iter_mut().for_each(|x| *x = 0.0);
        for i in 0..3 {
            self.fill_beam(i, vals);
        }
        self.cholesky()?;
        for i in 0..3 {
            self.border_columns(i, vals, win);
        }
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

    /// Band of beam i from its element blocks; the G-G part of element 0 goes to the border.
    #[inline(always)]
    fn fill_beam(&mut self, i: usize, vals: &[f64]) {
        let ns = self.ns;
        let ne = self.lay.ne;
        let band = &mut self.band[i];
        band.iter_mut().for_each(|r| *r = [0.0; HB + 1]);
        for k in 0..ne {
            let blk: &[f64; 36] = vals[36 * (i * ne + k)..36 * (i * ne + k) + 36]
                .try_into()
                .expect("36 values per element");
            // rows of node k + 1 (then node k) start at 3 (ne - k - 1), stored HB further
            let base = 3 * (ne - k - 1) + HB;
            let rows: &mut [[f64; HB + 1]; 6] = (&mut band[base..base + 6]).try_into().expect("6 rows");
            // node k + 1 (element DOFs 3..6): rows 0..3
            for r in 0..3 {
                for c in 0..=r {
                    rows[r][HB - (r - c)] += blk[6 * (3 + r) + 3 + c];
                }
            }
            // node k (DOFs 0..3): rows 3..6, unless it is G (k = 0: the border's)
            if k > 0 {
                for r in 0..3 {
                    for c in 0..3 {
                        rows[3 + r][HB - (3 + r - c)] += blk[6 * r + 3 + c];
                    }
                    for c in 0..=r {
                        rows[3 + r][HB - (r - c)] += blk[6 * r + c];
                    }
                }
            }
        }
        let blk0 = &vals[36 * i * ne..36 * i * ne + 36];
        for a in 0..3 {
            for b in 0..3 {
                self.s[border_g(a) * ns + border_g(b)] += blk0[6 * a + b];
            }
        }
    }

    /// In-place banded Cholesky of the three beams, with the reciprocals of the diagonal. The
    /// three independent factorisations advance row by row together, so that the processor
    /// overlaps their dependency chains (each row waits on the previous one: divisions and a
    /// square root).
    #[inline(always)]
    fn cholesky(&mut self) -> Result<(), String> {
        let n = 3 * self.lay.ne;
        let [b0, b1, b2] = &mut self.band;
        let [d0, d1, d2] = &mut self.dinv;
        for j in HB..n + HB {
            let p = [
                cholesky_row(b0, d0, j),
                cholesky_row(b1, d1, j),
                cholesky_row(b2, d2, j),
            ];
            if let Some(i) = p.iter().position(|d| !(*d > 0.0 && d.is_finite())) {
                return Err(format!(
                    "beam {} block not positive definite at row {} (pivot {:e})",
                    i + 1,
                    j - HB,
                    p[i]
                ));
            }
        }
        Ok(())
    }

    /// `E_i` (G columns from element 0, multiplier columns from the constraint rows; couplings
    /// of the multipliers with G, xi and psi go to the border), then `W_i = L_i^{-1} E_i` and
    /// `S -= W_i^T W_i`.
    #[inline(always)]
    fn border_columns(&mut self, i: usize, vals: &[f64], win: &[[usize; 3]; 3]) {
        let ns = self.ns;
        let l = self.lay;
        let (ne, n) = (l.ne, 3 * l.ne);
        // first row touched by a window: node min(lo + ww, ne), tip-first
        let first = (0..3)
            .map(|p| 3 * (ne - (win[i][p] + l.ww).min(ne)))
            .min()
            .unwrap_or(0)
            .min(n - 3);
        self.first[i] = first;
        let w = &mut self.w[i];
        // rows first - HB..n zero (the pad before `first` keeps the loops below fixed-length)
        w[first..].iter_mut().for_each(|x| *x = [0.0; WC]);
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
                        w[3 * (ne - k) + c + HB][r] = v;
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
        // W = L^{-1} E, multiplier columns: rows first..n, and their part of W^T W
        let (band, dinv) = (&self.band[i], &self.dinv[i]);
        let mut acc = [[0.0; WC]; ROWS];
        for j in first + HB..n + HB {
            let mut row = w[j];
            let lj = &band[j];
            for t in 0..HB {
                let f = lj[t];
                let wm = &w[j - HB + t];
                for a in 0..WC {
                    row[a] -= f * wm[a];
                }
            }
            let d = dinv[j];
            for a in 0..WC {
                row[a] *= d;
            }
            w[j] = row;
            for a in 0..ROWS {
                for b in 0..WC {
                    acc[a][b] += row[a] * row[b];
                }
            }
        }
        // G columns: E_G lives in the rows of node 1 (the last three), from element 0
        let blk0 = &vals[36 * i * ne..36 * i * ne + 36];
        let mut wg = [[0.0; 3]; 3];
        for c in 0..3 {
            let j = n - 3 + c;
            for g in 0..3 {
                let mut v = blk0[6 * (3 + c) + g];
                for m in 0..c {
                    v -= band[j + HB][HB - (c - m)] * wg[m][g];
                }
                wg[c][g] = v * dinv[j + HB];
            }
        }
        self.wg[i] = wg;
        // S -= W^T W
        for a in 0..ROWS {
            for b in 0..ROWS {
                self.s[border_nu(i, a) * ns + border_nu(i, b)] -= acc[a][b];
            }
        }
        for g in 0..3 {
            for h in 0..3 {
                let v: f64 = (0..3).map(|c| wg[c][g] * wg[c][h]).sum();
                self.s[border_g(g) * ns + border_g(h)] -= v;
            }
            for a in 0..ROWS {
                let v: f64 = (0..3).map(|c| wg[c][g] * w[n - 3 + c + HB][a]).sum();
                self.s[border_g(g) * ns + border_nu(i, a)] -= v;
                self.s[border_nu(i, a) * ns + border_g(g)] -= v;
            }
        }
    }

    /// LU with partial pivoting of the Schur complement, in place; the updates skip the zero
    /// entries of the pivot row (the sleeve blocks stay uncoupled until G, last).
    #[inline(always)]
    fn lu_schur(&mut self) -> Result<(), String> {
        let ns = self.ns;
        let s = &mut self.s;
        for k in 0..ns {
            let mut p = k;
            for r in k + 1..ns {
                if s[r * ns + k].abs() > s[p * ns + k].abs() {
                    p = r;
                }
            }
            self.perm[k] = p;
            if p != k {
                for c in 0..ns {
                    s.swap(k * ns + c, p * ns + c);
                }
            }
            let d = s[k * ns + k];
            if d == 0.0 || !d.is_finite() {
                return Err(format!("border Schur complement singular at pivot {k} ({d:e})"));
            }
            let mut cols = [0usize; NS_MAX];
            let mut nc = 0;
            for c in k + 1..ns {
                if s[k * ns + c] != 0.0 {
                    cols[nc] = c;
                    nc += 1;
                }
            }
            for r in k + 1..ns {
                let f = s[r * ns + k] / d;
                s[r * ns + k] = f;
                if f != 0.0 {
                    for &c in &cols[..nc] {
                        s[r * ns + c] -= f * s[k * ns + c];
                    }
                }
            }
        }
        Ok(())
    }

    /// `y_i <- L_i^{-1} y_i` for the three beams, advancing together (independent dependency
    /// chains the processor overlaps). The pad entries are zero; the last `HB` unknowns of each
    /// beam stay in registers (no reload of a value just stored), the newest one subtracted
    /// last (shortest dependency chain).
    #[inline(always)]
    fn forward(&mut self) {
        let n = 3 * self.lay.ne;
        let [y0, y1, y2] = &mut self.y;
        let ys: [&mut [f64]; 3] = [y0, y1, y2];
        let mut win = [[0.0; HB]; 3];
        for j in HB..n + HB {
            for i in 0..3 {
                let row = &self.band[i][j];
                let w = &mut win[i];
                let v = ys[i][j] - row[0] * w[0] - row[1] * w[1] - row[2] * w[2] - row[3] * w[3] - row[4] * w[4];
                *w = [w[1], w[2], w[3], w[4], v * self.dinv[i][j]];
            }
            for i in 0..3 {
                ys[i][j] = win[i][HB - 1];
            }
        }
    }

    /// `y_i <- L_i^{-T} y_i` for the three beams, together as in [`Bordered::forward`].
    #[inline(always)]
    fn backward(&mut self) {
        let n = 3 * self.lay.ne;
        let [y0, y1, y2] = &mut self.y;
        let ys: [&mut [f64]; 3] = [y0, y1, y2];
        // win[i][t] = y_i[j + HB - t] (t = 0 the farthest, HB - 1 the newest)
        let mut win = [[0.0; HB]; 3];
        for j in (HB..n + HB).rev() {
            for i in 0..3 {
                let b = &self.band[i];
                let w = &mut win[i];
                let v = ys[i][j]
                    - b[j + 5][0] * w[0]
                    - b[j + 4][1] * w[1]
                    - b[j + 3][2] * w[2]
                    - b[j + 2][3] * w[3]
                    - b[j + 1][4] * w[4];
                *w = [w[1], w[2], w[3], w[4], v * self.dinv[i][j]];
            }
            for i in 0..3 {
                ys[i][j] = win[i][HB - 1];
            }
        }
    }

    /// Solve `A x = rhs` in place (global ordering of the star) with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let this = self;
        flexstar_numerics::dispatch_avx2!(fn(this: &mut Bordered, rhs: &mut [f64]) -> () { this.solve_inline(rhs) })
    }

    /// [`Bordered::solve`], inlined into its AVX2 and baseline copies.
    #[inline(always)]
    fn solve_inline(&mut self, rhs: &mut [f64]) {
        let n = 3 * self.lay.ne;
        let ns = self.ns;
        let mut xs = [0.0; NS_MAX];
        for (b, x) in xs.iter_mut().enumerate().take(ns) {
            *x = rhs[self.global[b]];
        }
        // forward: y_i = L_i^{-1} b_i, xs -= W_i^T y_i
        for i in 0..3 {
            for j in 0..n {
                self.y[i][j + HB] = rhs[self.global_row(i, j)];
            }
        }
        self.forward();
        for i in 0..3 {
            let y = &self.y[i];
            let w = &self.w[i];
            let mut acc = [0.0; WC];
            for j in self.first[i] + HB..n + HB {
                let wj = &w[j];
                for a in 0..WC {
                    acc[a] += wj[a] * y[j];
                }
            }
            for a in 0..ROWS {
                xs[border_nu(i, a)] -= acc[a];
            }
            for g in 0..3 {
                xs[border_g(g)] -= (0..3).map(|c| self.wg[i][c][g] * y[HB + n - 3 + c]).sum::<f64>();
            }
        }
        // border: S xs = rhs_s - sum W^T y
        for k in 0..ns {
            xs.swap(k, self.perm[k]);
        }
        for k in 0..ns {
            let mut v = xs[k];
            for c in 0..k {
                v -= self.s[k * ns + c] * xs[c];
            }
            xs[k] = v;
        }
        for k in (0..ns).rev() {
            let mut v = xs[k];
            for c in k + 1..ns {
                v -= self.s[k * ns + c] * xs[c];
            }
            xs[k] = v / self.s[k * ns + k];
        }
        // back: x_i = L_i^{-T} (y_i - W_i xs)
        for i in 0..3 {
            let y = &mut self.y[i];
            let w = &self.w[i];
            let xb: [f64; WC] = std::array::from_fn(|a| if a < ROWS { xs[border_nu(i, a)] } else { 0.0 });
            for j in self.first[i] + HB..n + HB {
                let wj = &w[j];
                let mut v = 0.0;
                for a in 0..WC {
                    v += wj[a] * xb[a];
                }
                y[j] -= v;
            }
            for c in 0..3 {
                y[HB + n - 3 + c] -= (0..3).map(|g| self.wg[i][c][g] * xs[border_g(g)]).sum::<f64>();
            }
        }
        self.backward();
        for i in 0..3 {
            for j in 0..n {
                rhs[self.global_row(i, j)] = self.y[i][j + HB];
            }
        }
        for (b, x) in xs.iter().enumerate().take(ns) {
            rhs[self.global[b]] = *x;
        }
    }
}
