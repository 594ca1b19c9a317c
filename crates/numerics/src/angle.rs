//! Angles: the one wrap to (-pi, pi] and a fast `atan2`, lane by lane ([`crate::lanes::Real`]:
//! one `f64` or four lanes). The FEM's co-rotational element needs one `atan2` and two wraps per
//! element and Newton iteration; its output needs the wrap too.

use crate::lanes::Real;

/// Wrap an angle [rad] to (-pi, pi], lane by lane (the library's remainder only off the common
/// path); an angle already in (-pi, pi] is returned unchanged, bit for bit. The one wrap of
/// flexstar: the FEM's local end rotations (`flexstar_fem::element`, Crisfield's `th1`, `th2`) and
/// its output angles.
#[inline(always)]
pub fn wrap<T: Real>(a: T) -> T {
    use std::f64::consts::PI;
    if T::all(a.gt(T::splat(-PI)) & a.le(T::splat(PI))) {
        a
    } else {
        a.map(wrap_scalar)
    }
}

/// Wrap an angle to (-pi, pi].
fn wrap_scalar(a: f64) -> f64 {
    use std::f64::consts::PI;
    if a > -PI && a <= PI {
        return a;
    }
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

/// `tan(i pi / 32)`, i = 0..=8 (reduction points of [`atan2`]).
const ATAN_TAN: [f64; 9] = [
    0.0,
    0.09849140335716425,
    0.198912367379658,
    0.3033466836073424,
    0.41421356237309503,
    0.5345111359507916,
    0.6681786379192989,
    0.8206787908286602,
    0.9999999999999999,
];
/// `atan` of the doubles in [`ATAN_TAN`].
const ATAN_VAL: [f64; 9] = [
    0.0,
    0.09817477042468103,
    0.19634954084936207,
    0.2945243112740431,
    std::f64::consts::FRAC_PI_8,
    0.4908738521234052,
    0.5890486225480862,
    0.6872233929727672,
    std::f64::consts::FRAC_PI_4,
];

/// `atan2(y, x)` [rad] in (-pi, pi], within 3 eps of the C library's (unit test), about three
/// times faster (the element states need one per element and Newton iteration): octant
/// reduction to `r = min / max` in [0, 1], then `atan r = atan c + atan((r - c) / (1 + r c))`
/// with the nearest `c = tan(i pi / 32)` (`c = 0` near 0, where the reduction is exact),
/// `|t| < 0.07`, and the Taylor series of `atan t` to `t^17` (truncation below `1e-19`). Zero or
/// non-finite arguments go to the library.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    atan2_lanes(y, x)
}

/// [`atan2`] lane by lane, without branches on the common path (lanes with zero or non-finite
/// arguments go to the library).
#[inline(always)]
pub fn atan2_lanes<T: Real>(y: T, x: T) -> T {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let regular = ax.le(T::splat(f64::MAX)) & ay.le(T::splat(f64::MAX)) & (ax.gt(T::splat(0.0)) | ay.gt(T::splat(0.0)));
    if !T::all(regular) {
        return y.map2(x, f64::atan2);
    }
    let swap = ay.gt(ax);
    let r = T::select(swap, ax, ay) / T::select(swap, ay, ax);
    let i = r * 8.0 + 0.5;
    let (c, ac) = (i.lookup(&ATAN_TAN), i.lookup(&ATAN_VAL));
    let t = (r - c) / (r * c + 1.0);
    let u = t * t;
    // Estrin's scheme (short dependency chain) for sum_k (-1)^(k+1) u^k / (2k + 3), k = 0..7
    let (u2, u4) = (u * u, u * u * (u * u));
    let p = (u * (1.0 / 5.0) + (-1.0 / 3.0))
        + u2 * (u * (1.0 / 9.0) + (-1.0 / 7.0))
        + u4 * ((u * (1.0 / 13.0) + (-1.0 / 11.0)) + u2 * (u * (1.0 / 17.0) + (-1.0 / 15.0)));
    let a = ac + (t + t * u * p);
    let a = T::select(swap, T::splat(FRAC_PI_2) - a, a);
    let a = T::select(x.lt(T::splat(0.0)), T::splat(PI) - a, a);
    // a >= 0 here: the sign is y's
    a.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_range_and_identity() {
        use std::f64::consts::PI;
        // in range: unchanged, bit for bit; the ends: pi stays, -pi becomes pi
        for a in [0.0, -0.0, 1e-300, 0.1, -3.0, PI, -PI + 1e-15] {
            assert_eq!(wrap(a).to_bits(), a.to_bits(), "{a}");
        }
        assert_eq!(wrap(-PI), PI);
        for (a, want) in [
            (3.0 * PI, PI),
            (2.5 * PI, 0.5 * PI),
            (-2.5 * PI, -0.5 * PI),
            (7.0, 7.0 - 2.0 * PI),
        ] {
            let w = wrap(a);
            assert!(
                w > -PI && w <= PI && (w - want).abs() < 1e-14,
                "wrap({a}) = {w}, want {want}"
            );
        }
    }

    #[test]
    fn fast_atan2_matches_the_library() {
        // every octant and reduction interval, the axes, tiny and huge ratios, signed zeros
        let mut worst: f64 = 0.0;
        let mut k = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            // xorshift: deterministic pseudo-random angles and radii
            k ^= k << 13;
            k ^= k >> 7;
            k ^= k << 17;
            (k >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut cases: Vec<(f64, f64)> = (0..200_000)
            .map(|_| {
                let (a, r) = (
                    2.0 * std::f64::consts::PI * (next() - 0.5),
                    10f64.powf(6.0 * next() - 3.0),
                );
                (r * a.sin(), r * a.cos())
            })
            .collect();
        for v in [0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, 0.3, -0.3] {
            for w in [0.0, -0.0, 1.0, -1.0, 1e-300, 1e300, -2.5] {
                cases.push((v, w));
            }
        }
        for (y, x) in cases {
            let (a, b) = (atan2(y, x), y.atan2(x));
            assert_eq!(a.is_sign_negative(), b.is_sign_negative(), "sign at ({y}, {x})");
            let rel = (a - b).abs() / b.abs().max(f64::MIN_POSITIVE);
            worst = worst.max(rel);
            assert!(rel <= 3.0 * f64::EPSILON, "atan2({y}, {x}): {a} vs {b}");
        }
        assert!(worst > 0.0, "expected round-off differences somewhere");
    }
}
