//! Piecewise quintic curves of three channels through given knots (`docs/motions.md` sections
//! 1.2-1.4): the rest-to-rest segments of `kind = "via"` with `rest = true` and the clamped
//! quintic spline of `rest = false` and of `kind = "table"`.
//!
//! Each segment is a quintic in the local time `tau = (t - t_k) / h_k` written in Hermite form from
//! the values, first and second time derivatives at its two knots (section 1.3). The curve holds
//! still at the first value before the first knot and at the last after the last knot. It is
//! evaluated generically over dual numbers, so that the trajectory's s, s', s'' are exact.

use crate::geometry::Scalar;

/// Three channels (e.g. Gx, Gy, theta or s1, s2, s3) of a piecewise quintic in time [s].
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseQuintic {
    /// Knot times [s], strictly increasing, at least two.
    knots: Vec<f64>,
    /// Per segment and channel, the coefficients `c0..c5` of the quintic in tau.
    coefs: Vec<[[f64; 6]; 3]>,
}

/// Hermite coefficients of one quintic segment in tau from the values `v0, v1`, the scaled
/// first derivatives `D0 = h d0, D1 = h d1` and scaled second derivatives `A0 = h^2 a0,
/// A1 = h^2 a1` (`docs/motions.md` section 1.3).
fn hermite(v0: f64, v1: f64, d: [f64; 2], a: [f64; 2]) -> [f64; 6] {
    let delta = v1 - v0;
    let [d0, d1] = d;
    let [a0, a1] = a;
    [
        v0,
        d0,
        a0 / 2.0,
        10.0 * delta - 6.0 * d0 - 4.0 * d1 - (3.0 * a0 - a1) / 2.0,
        -15.0 * delta + 8.0 * d0 + 7.0 * d1 + (3.0 * a0 - 2.0 * a1) / 2.0,
        6.0 * delta - 3.0 * d0 - 3.0 * d1 - (a0 - a1) / 2.0,
    ]
}

/// Knot derivatives `[d, a]` (time derivatives, first and second) of one channel.
type KnotDerivs = Vec<[f64; 2]>;

impl PiecewiseQuintic {
    /// Rest-to-rest segments (section 1.2): every knot with zero first and second derivative, so
    /// each segment is `v_k + (v_k+1 - v_k)(10 tau^3 - 15 tau^4 + 6 tau^5)`. `t` must be strictly
    /// increasing with at least two entries, `values[k]` the three channels at `t[k]`.
    pub fn rest_segments(t: &[f64], values: &[[f64; 3]]) -> Self {
        let zero = vec![[0.0; 2]; t.len()];
        Self::from_knot_derivs(t, values, [&zero, &zero, &zero])
    }

    /// The clamped quintic spline (section 1.3): C4 at the interior knots, first and second
    /// derivative zero at the first and last knot. Same requirements on `t` and `values` as
    /// [`PiecewiseQuintic::rest_segments`].
    pub fn clamped_spline(t: &[f64], values: &[[f64; 3]]) -> Self {
        let derivs = [0, 1, 2].map(|c| {
            let v: Vec<f64> = values.iter().map(|row| row[c]).collect();
            clamped_knot_derivs(t, &v)
        });
        Self::from_knot_derivs(t, values, [&derivs[0], &derivs[1], &derivs[2]])
    }

    fn from_knot_derivs(t: &[f64], values: &[[f64; 3]], derivs: [&KnotDerivs; 3]) -> Self {
        let coefs = (0..t.len() - 1)
            .map(|k| {
                let h = t[k + 1] - t[k];
                [0, 1, 2].map(|c| {
                    let (l, r) = (derivs[c][k], derivs[c][k + 1]);
                    hermite(
                        values[k][c],
                        values[k + 1][c],
                        [h * l[0], h * r[0]],
                        [h * h * l[1], h * h * r[1]],
                    )
                })
            })
            .collect();
        PiecewiseQuintic {
            knots: t.to_vec(),
            coefs,
        }
    }

    /// The knot times [s].
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The three channels at time `t` [s], exact in the dual parts: constant before the first
    /// and after the last knot.
    pub fn eval<D: Scalar>(&self, t: D) -> [D; 3] {
        let n = self.knots.len();
        let (k, tau) = if t.re() <= self.knots[0] {
            (0, D::zero())
        } else if t.re() >= self.knots[n - 1] {
            (n - 2, D::one())
        } else {
            let k = (self.knots.partition_point(|&tk| tk <= t.re()) - 1).min(n - 2);
            (k, (t - self.knots[k]) / (self.knots[k + 1] - self.knots[k]))
        };
        self.coefs[k].map(|c| c.iter().rev().fold(D::zero(), |acc, &ck| acc * tau + ck))
    }
}

/// `[p''', p'''']` (derivatives in tau) at tau = 1 of a segment (left end `at_end = false`: at
/// tau = 0) with the given Hermite data.
fn high_derivs(c: [f64; 6], at_end: bool) -> [f64; 2] {
    if at_end {
        [6.0 * c[3] + 24.0 * c[4] + 60.0 * c[5], 24.0 * c[4] + 120.0 * c[5]]
    } else {
        [6.0 * c[3], 24.0 * c[4]]
    }
}

/// The jumps of s''' and s'''' (time derivatives) at interior knot k, from the derivatives
/// `x[j] = [d, a]` at knots k-1, k, k+1.
fn knot_jump(t: &[f64], v: &[f64], k: usize, x: [[f64; 2]; 3]) -> [f64; 2] {
    let (hl, hr) = (t[k] - t[k - 1], t[k + 1] - t[k]);
    let seg = |h: f64, v0: f64, v1: f64, l: [f64; 2], r: [f64; 2]| {
        hermite(v0, v1, [h * l[0], h * r[0]], [h * h * l[1], h * h * r[1]])
    };
    let left = high_derivs(seg(hl, v[k - 1], v[k], x[0], x[1]), true);
    let right = high_derivs(seg(hr, v[k], v[k + 1], x[1], x[2]), false);
    [
        left[0] / hl.powi(3) - right[0] / hr.powi(3),
        left[1] / hl.powi(4) - right[1] / hr.powi(4),
    ]
}

type Block = [[f64; 2]; 2];

fn solve2(m: Block, r: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [
        (r[0] * m[1][1] - m[0][1] * r[1]) / det,
        (m[0][0] * r[1] - m[1][0] * r[0]) / det,
    ]
}

/// The blocks `(B, C, E)` and right-hand side of the linear equations `B x_k-1 + C x_k +
/// E x_k+1 = r` of interior knot k, found from [`knot_jump`] by linearity (the jump is affine in
/// the derivatives: its columns are the jumps of unit derivatives less the constant part).
fn knot_equations(t: &[f64], v: &[f64], k: usize) -> ([Block; 3], [f64; 2]) {
    let base = knot_jump(t, v, k, [[0.0; 2]; 3]);
    let blocks = [0, 1, 2].map(|j| {
        let mut m = [[0.0; 2]; 2];
        for col in 0..2 {
            let mut x = [[0.0; 2]; 3];
            x[j][col] = 1.0;
            let r = knot_jump(t, v, k, x);
            m[0][col] = r[0] - base[0];
            m[1][col] = r[1] - base[1];
        }
        m
    });
    (blocks, [-base[0], -base[1]])
}

fn mul(a: Block, b: Block) -> Block {
    [0, 1].map(|i| [0, 1].map(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

/// Knot derivatives `[d, a]` of the clamped quintic spline of one channel: zero at both ends,
/// the interior ones from the block tridiagonal system of continuity of s''' and s'''' (section
/// 1.3), solved by block elimination in O(n).
fn clamped_knot_derivs(t: &[f64], v: &[f64]) -> KnotDerivs {
    let n = t.len();
    let mut x = vec![[0.0; 2]; n];
    if n < 3 {
        return x;
    }
    // forward sweep: C'_k = C_k - B_k C'^-1_k-1 E_k-1, r'_k likewise; stored as (C', r', E)
    let mut sweep: Vec<(Block, [f64; 2], Block)> = Vec::with_capacity(n - 2);
    for k in 1..n - 1 {
        let ([b, c, e], r) = knot_equations(t, v, k);
        let (c, r) = match sweep.last() {
            None => (c, r),
            Some(&(cp, rp, ep)) => {
                // B C'^-1 E and B C'^-1 r through the solves C' Y = E_k-1, C' y = r'_k-1
                let y_e = [0, 1].map(|col| solve2(cp, [ep[0][col], ep[1][col]]));
                let y_e: Block = [[y_e[0][0], y_e[1][0]], [y_e[0][1], y_e[1][1]]];
                let y_r = solve2(cp, rp);
                let be = mul(b, y_e);
                let c = [0, 1].map(|i| [0, 1].map(|j| c[i][j] - be[i][j]));
                let r = [0, 1].map(|i| r[i] - b[i][0] * y_r[0] - b[i][1] * y_r[1]);
                (c, r)
            }
        };
        sweep.push((c, r, e));
    }
    // back substitution: x_k = C'^-1_k (r'_k - E_k x_k+1), x_n-1 = 0
    for k in (1..n - 1).rev() {
        let (c, r, e) = sweep[k - 1];
        let next = x[k + 1];
        let rhs = [0, 1].map(|i| r[i] - e[i][0] * next[0] - e[i][1] * next[1]);
        x[k] = solve2(c, rhs);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{Dual2, Dual3};

    /// A quintic polynomial and its rest-to-rest form on [0, 1]: `10 t^3 - 15 t^4 + 6 t^5`.
    fn blend(t: f64) -> f64 {
        t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
    }

    #[test]
    fn clamped_spline_reproduces_a_rest_to_rest_quintic_sampled_unevenly() {
        // the quintic satisfies every condition of the spline, which is unique (section 1.3)
        let t: Vec<f64> = (0..=40).map(|k| (k as f64 / 40.0).powf(1.3)).collect();
        let v: Vec<[f64; 3]> = t.iter().map(|&x| [blend(x), -2.0 * blend(x), 0.5]).collect();
        let s = PiecewiseQuintic::clamped_spline(&t, &v);
        for k in 0..=997 {
            let x = k as f64 / 997.0;
            let p = s.eval(Dual2::<f64>::from_re(x).derivative());
            let d1 = 30.0 * x * x * (1.0 - x) * (1.0 - x);
            let d2 = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x);
            assert!((p[0].re - blend(x)).abs() < 1e-11, "t = {x}");
            assert!(
                (p[0].v1 - d1).abs() < 1e-9 && (p[0].v2 - d2).abs() < 1e-7,
                "t = {x}: {p:?}"
            );
            assert!((p[1].re + 2.0 * blend(x)).abs() < 1e-11 && p[2].v2.abs() < 1e-12);
        }
    }

    #[test]
    fn clamped_spline_interpolates_is_c4_inside_and_at_rest_at_the_ends() {
        let t = [0.0, 0.3, 0.45, 0.9, 1.0, 1.6];
        let v = [0.0, 0.02, -0.01, 0.03, 0.03, 0.0].map(|x| [x, 2.0 * x, -x]);
        let s = PiecewiseQuintic::clamped_spline(&t, &v);
        let jet = |x: f64| {
            let d = s.eval(Dual3::<f64>::from_re(x).derivative())[0];
            [d.re, d.v1, d.v2, d.v3]
        };
        for (k, &tk) in t.iter().enumerate() {
            assert!((jet(tk)[0] - v[k][0]).abs() < 1e-15);
        }
        // ends at rest, joined C2 to the rests outside
        for end in [0.0, 1.6] {
            let j = jet(end);
            assert!(j[1].abs() < 1e-12 && j[2].abs() < 1e-10, "{j:?}");
        }
        // interior knots: s'' and s''' continuous (left and right limits, 1e-9 s away)
        for &tk in &t[1..5] {
            let (l, r) = (jet(tk - 1e-9), jet(tk + 1e-9));
            assert!((l[2] - r[2]).abs() < 1e-5 * (1.0 + l[2].abs()), "{tk}: {l:?} {r:?}");
            assert!((l[3] - r[3]).abs() < 1e-3 * (1.0 + l[3].abs()), "{tk}: {l:?} {r:?}");
        }
    }

    #[test]
    fn rest_segments_stop_at_every_knot_and_hold_outside() {
        let t = [0.1, 0.5, 0.8];
        let v = [[0.0, 1.0, 2.0], [0.5, 1.0, 0.0], [0.5, 1.0, 0.0]];
        let s = PiecewiseQuintic::rest_segments(&t, &v);
        for x in [0.0, 0.1, 0.5, 0.65, 0.8, 1.0] {
            let p = s.eval(Dual2::<f64>::from_re(x).derivative());
            for c in p {
                if !(0.5..0.8).contains(&x) || x == 0.5 {
                    assert!(c.v1.abs() < 1e-12 && c.v2.abs() < 1e-9, "{x}: {p:?}");
                }
            }
        }
        // the dwell between the two equal knots holds still; the segment is the blend
        assert_eq!(s.eval(0.65f64), [0.5, 1.0, 0.0]);
        let p = s.eval(0.2f64);
        assert!((p[0] - 0.5 * blend(0.25)).abs() < 1e-15 && (p[2] - (2.0 - 2.0 * blend(0.25))).abs() < 1e-15);
    }
}
