//! The sleeve kernel of the full model ([`super::recurrence::elastic_triplets`] with the bending
//! sums) for the three beams at once, one beam per lane of the processor's 256-bit registers
//! (AVX), on a mode set shared by the three beams (`docs/amm.md` 2.1, "Cost of a step").
//!
//! Every lane does the scalar kernel's multiplications, additions and subtractions in the same
//! order, each rounded once as there (no fused multiply-add), so the values are the scalar
//! kernel's bit for bit (unit test); a mode whose root offset needs the direct evaluation (the
//! first one or two) is evaluated per beam by the scalar code.

use super::recurrence::{ModeTrig, Triplet, TripletOut, TAYLOR_DELTA};

/// Whether [`elastic_triplets_x3`] can run here: the processor has AVX2, hence the AVX
/// instructions used (`flexstar_numerics::lanes::has_avx2`: detected once at run time, off under
/// `flexstar_numerics::lanes::force_baseline`).
pub(super) fn available() -> bool {
    flexstar_numerics::lanes::has_avx2()
}

/// [`super::recurrence::elastic_triplets`] with the bending sums (`BENT`) for three beams on the
/// same `tri`: beam i's trigonometric state `trig[i]`, outputs `out[i]`, effective coordinates
/// `alpha_eff[i]`, sums added to `bend[i]`. `s`, `sd`: the value and slope scales [1/sqrt(m),
/// 1/m^1.5].
///
/// # Safety
/// The processor must support AVX ([`available`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub(super) unsafe fn elastic_triplets_x3(
    tri: &Triplet,
    trig: [ModeTrig<'_>; 3],
    mut out: [TripletOut<'_>; 3],
    alpha_eff: [&[f64]; 3],
    (s, sd): (f64, f64),
    bend: &mut [[f64; 3]; 3],
) {
    use std::arch::x86_64::*;
    let n = out[0].mid.len();
    let lanes = |v: [f64; 3]| _mm256_setr_pd(v[0], v[1], v[2], v[2]);
    let store = |v: __m256d| {
        let mut a = [0.0; 4];
        _mm256_storeu_pd(a.as_mut_ptr(), v);
        a
    };
    let (mul, add, sub) = (_mm256_mul_pd, _mm256_add_pd, _mm256_sub_pd);
    // the lanes' state: nominal values, rotation, decay factors, xi
    let mut sn = lanes(trig.each_ref().map(|t| t.nominal[0]));
    let mut cs = lanes(trig.each_ref().map(|t| t.nominal[1]));
    let mut e1 = lanes(trig.each_ref().map(|t| t.nominal[2]));
    let mut e2 = lanes(trig.each_ref().map(|t| t.nominal[3]));
    let (rs, rc) = (
        lanes(trig.each_ref().map(|t| t.rot.0)),
        lanes(trig.each_ref().map(|t| t.rot.1)),
    );
    let (q0, q1) = (
        lanes(trig.each_ref().map(|t| t.q.0)),
        lanes(trig.each_ref().map(|t| t.q.1)),
    );
    let xi_s = trig.each_ref().map(|t| t.xi);
    let xi = lanes(xi_s);
    let one_minus_xi = sub(_mm256_set1_pd(1.0), xi);
    let tiny = _mm256_set1_pd(1e-290);
    let (vs, vsd) = (_mm256_set1_pd(s), _mm256_set1_pd(sd));
    let (mut sl, mut sr, mut cv) = (_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd());
    let one = _mm256_set1_pd(1.0);
    for k in 0..n {
        let (b, d) = (tri.bl[k], tri.delta[k]);
        // ModeTrig::advance, lane by lane
        let next_sn = add(mul(sn, rc), mul(cs, rs));
        let next_cs = sub(mul(cs, rc), mul(sn, rs));
        let next_e1 = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(e1, tiny), mul(e1, q0));
        let next_e2 = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(e2, tiny), mul(e2, q1));
        let (tsn, tcs, te1, te2) = if d == 0.0 {
            (sn, cs, e1, e2)
        } else if d.abs() <= TAYLOR_DELTA {
            let vd = _mm256_set1_pd(d);
            let x = mul(vd, xi);
            let x2 = mul(x, x);
            let sx = mul(x, sub(one, mul(x2, _mm256_set1_pd(1.0 / 6.0))));
            let cx = sub(
                one,
                mul(x2, sub(_mm256_set1_pd(0.5), mul(x2, _mm256_set1_pd(1.0 / 24.0)))),
            );
            (
                add(mul(sn, cx), mul(cs, sx)),
                sub(mul(cs, cx), mul(sn, sx)),
                mul(e1, exp_neg_small(x)),
                mul(e2, exp_neg_small(mul(vd, one_minus_xi))),
            )
        } else {
            let direct = xi_s.map(|x| {
                let (sn, cs) = (b * x).sin_cos();
                [sn, cs, (-b * x).exp(), (-b * (1.0 - x)).exp()]
            });
            let at = |j: usize| lanes(direct.map(|v| v[j]));
            (at(0), at(1), at(2), at(3))
        };
        (sn, cs, e1, e2) = (next_sn, next_cs, next_e1, next_e2);
        // the kernel of elastic_triplets
        let vb = _mm256_set1_pd(b);
        let [c0, c1, c2, c3] = tri.c[k].map(|v| _mm256_set1_pd(v));
        let [f0, f1, f2, f3] = tri.f[k].map(|v| _mm256_set1_pd(v));
        let p = add(mul(c0, tcs), mul(c1, tsn));
        let q = sub(mul(c1, tcs), mul(c0, tsn));
        let (g1, g2) = (mul(c2, te1), mul(c3, te2));
        let v_mid = mul(add(add(p, g1), g2), vs);
        let v_slope = mul(mul(vb, add(sub(q, g1), g2)), vsd);
        let (pc, qs) = (mul(p, f0), mul(q, f1));
        let v_right = mul(add(add(add(pc, qs), mul(g1, f2)), mul(g2, f3)), vs);
        let v_left = mul(add(add(sub(pc, qs), mul(g1, f3)), mul(g2, f2)), vs);
        let (qc, ps) = (mul(q, f0), mul(p, f1));
        let ba = mul(vb, lanes(alpha_eff.map(|a| a[k])));
        sr = add(sr, mul(ba, add(sub(sub(qc, ps), mul(g1, f2)), mul(g2, f3))));
        sl = add(sl, mul(ba, add(sub(add(qc, ps), mul(g1, f3)), mul(g2, f2))));
        cv = add(cv, mul(mul(vb, ba), sub(add(g1, g2), p)));
        let [m, sp, r, l] = [v_mid, v_slope, v_right, v_left].map(store);
        for (i, o) in out.iter_mut().enumerate() {
            (o.left[k], o.mid[k], o.right[k], o.slope[k]) = (l[i], m[i], r[i], sp[i]);
        }
    }
    let [sl, sr, cv] = [sl, sr, cv].map(store);
    for i in 0..3 {
        bend[i][0] += sl[i];
        bend[i][1] += sr[i];
        bend[i][2] += cv[i];
    }
}

/// `exp(-x)` for `|x| <= TAYLOR_DELTA` per lane, as [`super::recurrence::exp_neg_small`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn exp_neg_small(x: std::arch::x86_64::__m256d) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    let (mul, sub) = (_mm256_mul_pd, _mm256_sub_pd);
    let c = _mm256_set1_pd;
    // 1 - x (1 - x (0.5 - x (1/6 - x / 24)))
    let inner = sub(c(1.0 / 6.0), mul(x, c(1.0 / 24.0)));
    let inner = sub(c(0.5), mul(x, inner));
    let inner = sub(c(1.0), mul(x, inner));
    sub(c(1.0), mul(x, inner))
}

#[cfg(test)]
mod tests {
    use crate::modes::{ModeSet, SleeveBending};
    use flexstar_model::{ModeFamily, RobotParams};

    #[test]
    fn three_beams_in_lanes_give_the_scalar_kernel_bit_for_bit() {
        // against ModeSet::triplet_at beam by beam (the scalar kernel, itself checked against
        // direct evaluation in modes::tests), on the enriched set whose first modes take the
        // direct and Taylor paths of the recurrence, sleeves near both ends and mid-beam
        if !super::available() {
            eprintln!("no AVX on this processor: the lanes are not used, nothing to compare");
            return;
        }
        let p = RobotParams::paper();
        let hp = 0.5 * p.lp;
        for n in [53, 25] {
            let set = ModeSet::new(ModeFamily::Enriched, n, &p).unwrap();
            let tri = set.triplet(hp);
            let na = set.analytic_len();
            let taylor = super::TAYLOR_DELTA;
            assert!(tri.delta.iter().any(|d| d.abs() > taylor), "a mode on the direct path");
            assert!(
                tri.delta.iter().any(|d| *d != 0.0 && d.abs() <= taylor),
                "a mode on the Taylor path"
            );
            let alpha: Vec<Vec<f64>> = (0..3)
                .map(|i| {
                    (0..n)
                        .map(|m| 1e-3 * ((m * 7 + i * 3) as f64).sin() / (1.0 + m as f64))
                        .collect()
                })
                .collect();
            for x in [[hp, 0.5 * p.l, p.l - hp], [0.21, 0.2101, 0.3], [0.07, 0.43, 0.25]] {
                let zero = || [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
                let mut scalar = [zero(), zero(), zero()];
                let mut lanes = [zero(), zero(), zero()];
                let mut bent_s: [SleeveBending; 3] = std::array::from_fn(|_| SleeveBending::new(na));
                let mut bent_l = bent_s.clone();
                for i in 0..3 {
                    let [l, m, r, d] = &mut scalar[i];
                    set.triplet_at(&tri, x[i], l, m, r, d, Some((&alpha[i], &mut bent_s[i])));
                }
                let out = lanes
                    .each_mut()
                    .map(|[l, m, r, d]| [&mut l[..], &mut m[..], &mut r[..], &mut d[..]]);
                let [b0, b1, b2] = bent_l.each_mut();
                set.triplets_at3(&tri, x, out, [(&alpha[0], b0), (&alpha[1], b1), (&alpha[2], b2)]);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                for i in 0..3 {
                    for k in 0..4 {
                        assert_eq!(
                            bits(&lanes[i][k]),
                            bits(&scalar[i][k]),
                            "N {n}, x {x:?}, beam {i}, output {k}"
                        );
                    }
                    let b = |s: &SleeveBending| [s.slope_left, s.slope_right, s.curvature].map(f64::to_bits);
                    assert_eq!(b(&bent_l[i]), b(&bent_s[i]), "N {n}, x {x:?}, beam {i}: bending");
                }
                assert!(scalar[0][1].iter().any(|v| v.abs() > 0.1), "values were computed");
            }
        }
    }
}
