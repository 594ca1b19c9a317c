//! One number or four: the scalar type of kernels that are written once and run either on one
//! `f64` or on four independent `f64` lanes at a time ([`F64x4`]).
//!
//! A kernel generic over [`Real`] and inlined into a function compiled for AVX2
//! (`#[target_feature(enable = "avx2")]`, chosen at run time) gets every lane operation as one
//! 256-bit instruction; compiled for baseline x86-64 it gets two 128-bit ones, on other
//! processors what their compiler makes of four-element arrays. Every lane operation is the
//! correctly rounded IEEE operation of its scalar counterpart (no fused multiply-add, no
//! reassociation), so a kernel gives bit for bit the same numbers on `f64` and on each lane of
//! `F64x4`: the lanes change the speed, never the result (unit tests below, and the FEM's element
//! batch test).

use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Arithmetic of a kernel's numbers: `f64`, or [`F64x4`] (lane-wise). The `f64` right-hand
/// sides let kernels write constants as `x * 2.0`.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Result of a lane-wise comparison.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Not<Output = Self::Mask>;
    /// Lanes per value.
    const LANES: usize;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// Lane `k` set to `f(k)`, `k = 0..LANES`.
    fn from_lanes(f: impl FnMut(usize) -> f64) -> Self;
    /// Lane `k` (`k < LANES`).
    fn lane(self, k: usize) -> f64;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `|self|` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    fn gt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    /// `a` where `mask`, `b` elsewhere.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// Whether the mask holds in every lane.
    fn all(mask: Self::Mask) -> bool;
    /// `f` applied to every lane (for rare paths that need a library function).
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// `f(self, other)` lane by lane.
    fn map2(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self;
    /// `table[i]` in each lane, `i` the lane's value truncated towards zero and clamped to the
    /// table (lane values must be finite and non-negative to mean anything).
    fn lookup<const N: usize>(self, table: &[f64; N]) -> Self;
}

impl Real for f64 {
    type Mask = bool;
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn from_lanes(mut f: impl FnMut(usize) -> f64) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _k: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        f(self)
    }
    #[inline(always)]
    fn map2(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        f(self, other)
    }
    #[inline(always)]
    fn lookup<const N: usize>(self, table: &[f64; N]) -> Self {
        table[(self as usize).min(N - 1)]
    }
}

/// Four `f64` lanes, aligned for one 256-bit load.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; 4]);

/// Lane-wise comparison result of [`F64x4`]: every bit of a lane set (true) or clear (false),
/// the form of the processor's vector comparisons, so that comparisons, selections and their
/// combinations stay in vector registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct Mask4(pub [u64; 4]);

impl Mask4 {
    /// The lane mask of `b`.
    #[inline(always)]
    fn bit(b: bool) -> u64 {
        (b as u64).wrapping_neg()
    }

    /// Whether lane `k` is set.
    #[inline(always)]
    pub fn test(self, k: usize) -> bool {
        self.0[k] != 0
    }
}

impl F64x4 {
    /// Lane `k` of `f(k)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        F64x4([f(0), f(1), f(2), f(3)])
    }
}

macro_rules! lane_binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, o: F64x4) -> F64x4 {
                let (a, b) = (self.0, o.0);
                F64x4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
        impl $trait<f64> for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, o: f64) -> F64x4 {
                let a = self.0;
                F64x4([a[0] $op o, a[1] $op o, a[2] $op o, a[3] $op o])
            }
        }
    };
}
lane_binary!(Add, add, +);
lane_binary!(Sub, sub, -);
lane_binary!(Mul, mul, *);
lane_binary!(Div, div, /);

macro_rules! lane_assign {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            #[inline(always)]
            fn $method(&mut self, o: F64x4) {
                *self = *self $op o;
            }
        }
    };
}
lane_assign!(AddAssign, add_assign, +);
lane_assign!(SubAssign, sub_assign, -);
lane_assign!(MulAssign, mul_assign, *);

impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        let a = self.0;
        F64x4([-a[0], -a[1], -a[2], -a[3]])
    }
}

macro_rules! mask_binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Mask4 {
            type Output = Mask4;
            #[inline(always)]
            fn $method(self, o: Mask4) -> Mask4 {
                let (a, b) = (self.0, o.0);
                Mask4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
    };
}
mask_binary!(BitAnd, bitand, &);
mask_binary!(BitOr, bitor, |);

impl Not for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn not(self) -> Mask4 {
        let m = self.0;
        Mask4([!m[0], !m[1], !m[2], !m[3]])
    }
}

impl Real for F64x4 {
    type Mask = Mask4;
    const LANES: usize = 4;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F64x4([x; 4])
    }
    #[inline(always)]
    fn from_lanes(f: impl FnMut(usize) -> f64) -> Self {
        F64x4::from_fn(f)
    }
    #[inline(always)]
    fn lane(self, k: usize) -> f64 {
        self.0[k]
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let a = self.0;
        F64x4([a[0].sqrt(), a[1].sqrt(), a[2].sqrt(), a[3].sqrt()])
    }
    #[inline(always)]
    fn abs(self) -> Self {
        let a = self.0;
        F64x4([a[0].abs(), a[1].abs(), a[2].abs(), a[3].abs()])
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        F64x4::from_fn(|k| self.0[k].copysign(sign.0[k]))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Mask4 {
        let (a, b) = (self.0, other.0);
        let bit = Mask4::bit;
        Mask4([bit(a[0] > b[0]), bit(a[1] > b[1]), bit(a[2] > b[2]), bit(a[3] > b[3])])
    }
    #[inline(always)]
    fn le(self, other: Self) -> Mask4 {
        let (a, b) = (self.0, other.0);
        let bit = Mask4::bit;
        Mask4([
            bit(a[0] <= b[0]),
            bit(a[1] <= b[1]),
            bit(a[2] <= b[2]),
            bit(a[3] <= b[3]),
        ])
    }
    #[inline(always)]
    fn lt(self, other: Self) -> Mask4 {
        let (a, b) = (self.0, other.0);
        let bit = Mask4::bit;
        Mask4([bit(a[0] < b[0]), bit(a[1] < b[1]), bit(a[2] < b[2]), bit(a[3] < b[3])])
    }
    #[inline(always)]
    fn select(mask: Mask4, a: Self, b: Self) -> Self {
        // bitwise blend: a where the lane's bits are set, b where they are clear
        let pick = |k: usize| f64::from_bits((a.0[k].to_bits() & mask.0[k]) | (b.0[k].to_bits() & !mask.0[k]));
        F64x4([pick(0), pick(1), pick(2), pick(3)])
    }
    #[inline(always)]
    fn all(mask: Mask4) -> bool {
        mask.0[0] & mask.0[1] & mask.0[2] & mask.0[3] == u64::MAX
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let a = self.0;
        F64x4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }
    #[inline(always)]
    fn map2(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        F64x4::from_fn(|k| f(self.0[k], other.0[k]))
    }
    #[inline(always)]
    fn lookup<const N: usize>(self, table: &[f64; N]) -> Self {
        let a = self.0;
        let at = |x: f64| table[(x as usize).min(N - 1)];
        F64x4([at(a[0]), at(a[1]), at(a[2]), at(a[3])])
    }
}

/// Set by [`force_baseline`].
static BASELINE_ONLY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Make every [`dispatch_avx2!`] body run its baseline copy (`true`), or choose by the processor
/// again (`false`): the copy that processors without AVX2 (and other architectures) run, for
/// tests that compare the two and for debugging. Process-wide.
pub fn force_baseline(on: bool) {
    BASELINE_ONLY.store(on, std::sync::atomic::Ordering::Relaxed);
}

/// Whether the AVX2 copies run: the processor has the 256-bit lane instructions (AVX2, detected
/// once at run time) and [`force_baseline`] is off; false off x86-64. Kernels call their
/// `#[target_feature(enable = "avx2")]` copy when it holds.
#[inline]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !BASELINE_ONLY.load(std::sync::atomic::Ordering::Relaxed) && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// [`has_avx2`] and the processor also has FMA (detected once at run time): the choice of the
/// fused kernels of [`crate::vector`], so that [`force_baseline`] covers them too.
#[inline]
pub fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        has_avx2() && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Which copy of a [`dispatch_avx2!`] body runs (`avx2`: the AVX2 one), called by the macro: it
/// counts them in this crate's own unit tests, so that they can check which copy ran, and is an
/// empty function in every other build.
#[doc(hidden)]
#[inline(always)]
pub fn note_copy(avx2: bool) {
    #[cfg(test)]
    COPIES_RUN.with(|c| {
        let (a, b) = c.get();
        c.set(if avx2 { (a + 1, b) } else { (a, b + 1) });
    });
    #[cfg(not(test))]
    let _ = avx2;
}

#[cfg(test)]
thread_local! {
    /// Dispatched bodies run on this thread: (AVX2 copies, baseline copies).
    static COPIES_RUN: std::cell::Cell<(usize, usize)> = const { std::cell::Cell::new((0, 0)) };
}

/// Run a function body compiled twice, for AVX2 and for the baseline of the build, choosing at
/// run time ([`has_avx2`]). Two forms:
/// - a function item, `dispatch_avx2! { /// docs\n pub fn name(a: &mut [f64], x: f64) -> f64 { body } }`,
///   which defines `name` with both copies of its body inside;
/// - an expression, `dispatch_avx2!(fn(a: &mut [f64], x: f64) -> f64 { body })`, which defines
///   both copies with the arguments given and calls one with the variables of the same names.
///
/// The body's callees are compiled for AVX2 only where they are inlined into it
/// (`#[inline(always)]`). The two copies compute the same operations (no fused multiply-add is
/// enabled, the compiler does not reassociate), so their results are identical; only their
/// instructions differ.
#[macro_export]
macro_rules! dispatch_avx2 {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty $body:block) => {
        $(#[$meta])*
        #[allow(clippy::too_many_arguments)]
        $vis fn $name($($arg: $ty),*) -> $ret {
            $crate::dispatch_avx2!(fn($($arg: $ty),*) -> $ret $body)
        }
    };
    (fn($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty $body:block) => {{
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        #[allow(clippy::too_many_arguments)]
        fn with_avx2($($arg: $ty),*) -> $ret $body
        #[allow(clippy::too_many_arguments)]
        #[inline(always)]
        fn portable($($arg: $ty),*) -> $ret $body
        #[cfg(target_arch = "x86_64")]
        let out = if $crate::lanes::has_avx2() {
            $crate::lanes::note_copy(true);
            // SAFETY: the processor has AVX2 (detected at run time just above).
            unsafe { with_avx2($($arg),*) }
        } else {
            $crate::lanes::note_copy(false);
            portable($($arg),*)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let out = {
            $crate::lanes::note_copy(false);
            portable($($arg),*)
        };
        out
    }};
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A kernel with every operation of the trait, generic over the scalar type.
    #[inline(always)]
    fn kernel<T: Real>(x: T, y: T) -> T {
        let r = (x * y + 1.5) / (x.abs() + 0.25) - (y * y + 2.0).sqrt() * 3.0;
        let big = r.gt(T::splat(0.0)) & !x.lt(T::splat(-1.0));
        let mut s = T::select(big, r, -r).copysign(y);
        s += T::splat(0.5);
        s -= x;
        s *= y / 7.0;
        let table = [0.0, 1.0, 4.0, 9.0];
        let s = s + (x.abs() * 2.0).lookup(&table) + if T::all(x.le(T::splat(100.0))) { 0.0 } else { 1.0 };
        s.map2(x, f64::hypot)
    }

    #[test]
    fn both_copies_of_a_dispatched_body_agree() {
        let xs: Vec<f64> = (0..37).map(|k| (k as f64 * 0.61).sin() * 1e3).collect();
        let scaled = |xs: &[f64], c: f64| -> Vec<f64> {
            let mut buf = xs.to_vec();
            let out = &mut buf[..];
            let sum = crate::dispatch_avx2!(fn(out: &mut [f64], c: f64) -> f64 {
                let mut sum = 0.0;
                for x in out.iter_mut() {
                    *x = *x * c + 1.0 / c;
                    sum += *x;
                }
                sum
            });
            buf.push(sum);
            buf
        };
        let mut want: Vec<f64> = xs.iter().map(|x| x * 3.3 + 1.0 / 3.3).collect();
        want.push(want.iter().fold(0.0, |s, x| s + x));
        let copies = || COPIES_RUN.with(|c| c.get());
        // the processor's copy: AVX2 where the processor has it (the counters say which ran)
        force_baseline(false);
        let (a0, b0) = copies();
        let chosen = scaled(&xs, 3.3);
        let (a1, b1) = copies();
        let avx2 = has_avx2();
        assert_eq!((a1 - a0, b1 - b0), if avx2 { (1, 0) } else { (0, 1) });
        // the baseline copy, forced (process-wide; no other test here dispatches)
        force_baseline(true);
        assert!(!has_avx2());
        let baseline = scaled(&xs, 3.3);
        force_baseline(false);
        let (a2, b2) = copies();
        assert_eq!((a2 - a1, b2 - b1), (0, 1), "force_baseline must run the baseline copy");
        if !avx2 {
            eprintln!("no AVX2 on this processor: the baseline copy ran both times");
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&chosen), bits(&want));
        assert_eq!(bits(&baseline), bits(&want));
    }

    #[test]
    fn lanes_give_the_scalar_results_bit_for_bit() {
        let xs = [0.3, -1.7, 2.9, -0.0];
        let ys = [-0.8, 1.1, -2.2, 5.0];
        let lanes = kernel(F64x4(xs), F64x4(ys));
        for k in 0..4 {
            let s = kernel(xs[k], ys[k]);
            assert_eq!(lanes.0[k].to_bits(), s.to_bits(), "lane {k}: {} vs {s}", lanes.0[k]);
        }
        // and the scalar kernel is the plain arithmetic it spells (a few spot values)
        assert_eq!((2.0f64).lookup(&[5.0, 6.0, 7.0]), 7.0);
        assert_eq!((9.5f64).lookup(&[5.0, 6.0, 7.0]), 7.0, "clamped to the table");
        assert_eq!(
            F64x4([1.0, -2.0, 3.0, -4.0]).map(|v| v * 10.0),
            F64x4([10.0, -20.0, 30.0, -40.0])
        );
        assert!(F64x4::all(F64x4::splat(1.0).gt(F64x4::splat(0.0))));
        assert!(!F64x4::all(F64x4([1.0, 1.0, -1.0, 1.0]).gt(F64x4::splat(0.0))));
    }
}
