//! Dot product of two slices, the inner kernel of the AMM's per-step Gram data and solves.
//!
//! The build targets baseline x86-64 (SSE2), so the compiler's own code multiplies two numbers
//! at a time and never fuses the multiply with the add. Where the processor has AVX2 and FMA
//! (every x86-64 processor since about 2013-2015), detected at run time, four lanes are fused per
//! instruction; elsewhere (older x86-64, other architectures) the portable loop runs. The two
//! round differently (the fused one rounds once per product-sum), so results agree to a few ulps
//! of the sum of |products|, not bit for bit, across processors; on one processor they are
//! reproducible.
//!
//! The choice is [`crate::lanes::has_avx2_fma`], so [`crate::lanes::force_baseline`] selects the
//! portable loop here too. The kernels are not bodies of `dispatch_avx2!`: that macro compiles
//! one portable body twice and lets the compiler vectorise it for AVX2, which never fuses a
//! multiply with an add (no FMA target feature, and Rust does not contract `a * b + c`); the
//! fused sums need the explicit FMA intrinsics below.

/// `sum_k a[k] b[k]` over the shorter length.
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    #[cfg(target_arch = "x86_64")]
    {
        if crate::lanes::has_avx2_fma() {
            // SAFETY: the processor has AVX2 and FMA (has_avx2_fma, just above), and a, b have length n.
            return unsafe { dot_avx2_fma(a, b) };
        }
    }
    dot_portable(a, b)
}

/// `[a . b[0], ..., a . b[K-1]]` in one pass over `a` (over the shortest length): the products of
/// one vector with several others, each read once, the sums in independent registers.
#[inline]
pub fn dots<const K: usize>(a: &[f64], b: [&[f64]; K]) -> [f64; K] {
    let n = b.iter().fold(a.len(), |n, v| n.min(v.len()));
    let a = &a[..n];
    let b = b.map(|v| &v[..n]);
    #[cfg(target_arch = "x86_64")]
    {
        if crate::lanes::has_avx2_fma() {
            // SAFETY: the processor has AVX2 and FMA (has_avx2_fma, just above); every slice has length n.
            return unsafe { dots_avx2_fma(a, b) };
        }
    }
    b.map(|v| dot_portable(a, v))
}

/// Four independent accumulators (the add latency chain broken; SSE2 vectorises it in pairs).
fn dot_portable(a: &[f64], b: &[f64]) -> f64 {
    let (ca, ra) = a.as_chunks::<4>();
    let (cb, rb) = b.as_chunks::<4>();
    let mut acc = [0.0f64; 4];
    for (x, y) in ca.iter().zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Two 4-lane fused accumulators over blocks of 8, then the tail.
///
/// # Safety
/// The processor must support AVX2 and FMA; `a` and `b` must have the same length.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn dot_avx2_fma(a: &[f64], b: &[f64]) -> f64 {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_setzero_pd, _mm256_storeu_pd};
    let n = a.len().min(b.len());
    let (pa, pb) = (a.as_ptr(), b.as_ptr());
    let (mut acc0, mut acc1) = (_mm256_setzero_pd(), _mm256_setzero_pd());
    let mut i = 0;
    // SAFETY (loads): every index read is below n, the length of both slices.
    while i + 8 <= n {
        acc0 = _mm256_fmadd_pd(_mm256_loadu_pd(pa.add(i)), _mm256_loadu_pd(pb.add(i)), acc0);
        acc1 = _mm256_fmadd_pd(_mm256_loadu_pd(pa.add(i + 4)), _mm256_loadu_pd(pb.add(i + 4)), acc1);
        i += 8;
    }
    if i + 4 <= n {
        acc0 = _mm256_fmadd_pd(_mm256_loadu_pd(pa.add(i)), _mm256_loadu_pd(pb.add(i)), acc0);
        i += 4;
    }
    let mut lanes = [0.0f64; 4];
    _mm256_storeu_pd(lanes.as_mut_ptr(), _mm256_add_pd(acc0, acc1));
    let mut s = (lanes[0] + lanes[2]) + (lanes[1] + lanes[3]);
    for k in i..n {
        s += a[k] * b[k];
    }
    s
}

/// One 4-lane fused accumulator per product, blocks of 4, then the tail.
///
/// # Safety
/// The processor must support AVX2 and FMA; every slice of `b` must be as long as `a`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn dots_avx2_fma<const K: usize>(a: &[f64], b: [&[f64]; K]) -> [f64; K] {
    use std::arch::x86_64::{__m256d, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_setzero_pd, _mm256_storeu_pd};
    let n = a.len();
    let mut acc: [__m256d; K] = [_mm256_setzero_pd(); K];
    let mut i = 0;
    // SAFETY (loads): every index read is below n, the length of every slice.
    while i + 4 <= n {
        let x = _mm256_loadu_pd(a.as_ptr().add(i));
        for (acc, v) in acc.iter_mut().zip(&b) {
            *acc = _mm256_fmadd_pd(x, _mm256_loadu_pd(v.as_ptr().add(i)), *acc);
        }
        i += 4;
    }
    let mut out = [0.0f64; K];
    for ((o, acc), v) in out.iter_mut().zip(&acc).zip(&b) {
        let mut lanes = [0.0f64; 4];
        _mm256_storeu_pd(lanes.as_mut_ptr(), *acc);
        let mut s = (lanes[0] + lanes[2]) + (lanes[1] + lanes[3]);
        for k in i..n {
            s += a[k] * v[k];
        }
        *o = s;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact sum of products of small integers (every partial sum exact in f64).
    fn exact(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    #[test]
    fn integer_data_give_the_exact_sum_at_every_length() {
        // small integers: every product and partial sum is exact, so any summation order must
        // give the exact value; covers the 8-blocks, the 4-block and every tail length
        for n in 0..40 {
            let a: Vec<f64> = (0..n).map(|k| ((k * 7) % 11) as f64 - 5.0).collect();
            let b: Vec<f64> = (0..n).map(|k| ((k * 5) % 13) as f64 - 6.0).collect();
            assert_eq!(dot(&a, &b), exact(&a, &b), "n = {n}");
            assert_eq!(dot_portable(&a, &b), exact(&a, &b), "n = {n}");
        }
    }

    #[test]
    fn real_data_agree_with_a_compensated_sum() {
        // Neumaier-compensated reference: the kernels' error is a few ulps of sum |a b|
        let n = 53;
        let a: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin() / (1.0 + k as f64)).collect();
        let b: Vec<f64> = (0..n).map(|k| (k as f64 * 1.3).cos() * (k as f64).sqrt()).collect();
        let (mut s, mut c) = (0.0f64, 0.0f64);
        for (x, y) in a.iter().zip(&b) {
            let p = x * y;
            let t = s + p;
            c += if s.abs() >= p.abs() { (s - t) + p } else { (p - t) + s };
            s = t;
        }
        let reference = s + c;
        let scale: f64 = a.iter().zip(&b).map(|(x, y)| (x * y).abs()).sum();
        for v in [dot(&a, &b), dot_portable(&a, &b)] {
            assert!(
                (v - reference).abs() <= 8.0 * f64::EPSILON * scale,
                "{v} vs {reference}"
            );
        }
        // the shorter length is used
        assert_eq!(dot(&a[..10], &b), dot(&a[..10], &b[..10]));
    }

    #[test]
    fn several_products_at_once_are_the_single_ones() {
        // integer data (exact in any order) at every length, and the shortest length rule
        for n in 0..30 {
            let v = |m: usize, r: usize| (0..n).map(|k| ((k * m) % r) as f64 - 3.0).collect::<Vec<f64>>();
            let (a, b, c, d) = (v(7, 11), v(5, 13), v(3, 7), v(2, 5));
            let got = dots(&a, [&b, &c, &d]);
            assert_eq!(got, [exact(&a, &b), exact(&a, &c), exact(&a, &d)], "n = {n}");
        }
        let (a, b) = (vec![1.0; 9], vec![2.0; 6]);
        // every product over the shortest slice (6)
        assert_eq!(dots(&a, [&a, &b]), [6.0, 12.0]);
    }
}
