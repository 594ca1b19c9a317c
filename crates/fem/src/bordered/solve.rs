//! Solution with the last factorisation: forward substitution of the beams, the border, then
//! back substitution of the beams.

use super::*;

/// `y <- L^{-T} y` on rows `HB..y.len() - HB` (padded storage, the `HB` rows after are zero):
/// `y[j] <- (y[j] - sum_{t=HB..1} L[j+t][j] y[j+t]) L[j][j]^{-1}`, the farthest row first.
#[inline(always)]
pub(super) fn backward_rows<T: Real>(band: &[[T; HB + 1]], dinv: &[T], y: &mut [[T; 1]]) {
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
