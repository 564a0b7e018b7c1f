//! The SIMD vectors that packet tests run on: four lanes everywhere (glam's `Vec4`: SSE2 on
//! every x86-64 CPU), eight where the CPU has AVX, chosen when the scene is built
//! ([`Width::of_host`]). The build targets baseline x86-64, so the eight-lane code is compiled
//! for AVX inside [`in_avx`] and entered only with the proof ([`Avx`]) that the CPU has it; the
//! few AVX2 integer operations (a walk's sorting of a node's children, [`sorted_entries`]) the
//! same way, inside [`in_avx2`]. This is the crate's one module with `unsafe` code: the
//! intrinsics, those entries and the cache prefetch hint ([`prefetch`]).
//!
//! Both widths do the same IEEE operations (no fused multiply-adds; `min`, `max` and the
//! comparisons treat NaN as SSE does), so a packet test finds the same hits, to the bit, at
//! either width.

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use glam::{BVec4A, Vec4};

/// How many lanes a packet has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// Four (SSE2, or glam's scalar fallback off x86-64).
    Four,
    /// Eight, with the proof that this CPU has AVX (and whether AVX2).
    #[cfg(target_arch = "x86_64")]
    Eight(Avx),
}

impl Width {
    /// The widest this CPU runs: eight lanes with AVX, with AVX2's operations where it has them.
    pub fn of_host() -> Width {
        Width::on_host().pop().unwrap_or(Width::Four)
    }

    /// Every width this CPU runs, narrowest first; eight lanes twice where the CPU has AVX2,
    /// without its operations and with them.
    pub fn on_host() -> Vec<Width> {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx) = Avx::detect() {
            let mut widths = vec![Width::Four, Width::Eight(avx.without_avx2())];
            if avx.avx2().is_some() {
                widths.push(Width::Eight(avx));
            }
            return widths;
        }
        vec![Width::Four]
    }
}

/// Proof that the CPU has AVX, carrying AVX2's where it has that too: made only by
/// [`Avx::detect`].
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx {
    avx2: Option<Avx2>,
}

/// Proof that the CPU has AVX2 (and so AVX): made only by [`Avx::detect`].
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2(());

#[cfg(target_arch = "x86_64")]
impl Avx {
    /// The proof, if the CPU reports AVX.
    pub fn detect() -> Option<Avx> {
        std::arch::is_x86_feature_detected!("avx").then(|| Avx {
            avx2: std::arch::is_x86_feature_detected!("avx2").then_some(Avx2(())),
        })
    }

    /// AVX2's proof, if the CPU reported it.
    pub fn avx2(self) -> Option<Avx2> {
        self.avx2
    }

    /// This proof without AVX2's: the code for CPUs with AVX alone, to compare the two.
    pub fn without_avx2(self) -> Avx {
        Avx { avx2: None }
    }
}

/// Calls `f` from a function compiled for AVX, so that the eight-lane arithmetic inlined into
/// it runs as AVX instructions. `f` should be `#[inline(always)]` down to its lanes, the
/// closure itself included: one left out of line runs outside the AVX code, each lane operation
/// a call (a profile-guided build left a walk the profile never ran out of line: +10% of a
/// scene's instructions, 1.7× its time).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[inline(always)]
pub(crate) fn in_avx<R>(_proof: Avx, f: impl FnOnce() -> R) -> R {
    #[target_feature(enable = "avx")]
    unsafe fn run<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    // SAFETY: `Avx` exists only where the CPU reported AVX.
    unsafe { run(f) }
}

/// [`in_avx`] for AVX2: runs `f` from a function compiled for AVX2 (and so AVX).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[inline(always)]
pub(crate) fn in_avx2<R>(_proof: Avx2, f: impl FnOnce() -> R) -> R {
    #[target_feature(enable = "avx2")]
    unsafe fn run<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    // SAFETY: `Avx2` exists only where the CPU reported AVX2.
    unsafe { run(f) }
}

/// Asks the cache for the line holding `*p`, so a read soon after does not wait on memory. A
/// hint only: it reads nothing the program sees and changes no result; any address is allowed.
#[allow(unsafe_code)]
#[inline(always)]
pub(crate) fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64; a prefetch never faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Lane-wise `f32` arithmetic, comparisons to masks, and selection.
pub(crate) trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// A lane-wise truth value.
    type Mask: Copy
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + BitXor<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// Lanes per vector.
    const N: usize;
    /// Every lane `v`.
    fn splat(v: f32) -> Self;
    /// The first [`Lanes::N`] values of `v`.
    fn from_slice(v: &[f32]) -> Self;
    /// Lane `i` `f(i)`, put together in registers: lanes written one by one to memory and
    /// loaded as a vector would wait for the narrow stores to retire.
    fn from_fn(f: impl Fn(usize) -> f32) -> Self;
    /// The lanes into the first [`Lanes::N`] places of `out`.
    fn write_to(self, out: &mut [f32]);
    fn abs(self) -> Self;
    fn sqrt(self) -> Self;
    /// `self`'s magnitude with `sign`'s sign.
    fn copysign(self, sign: Self) -> Self;
    /// SSE's `minps`: `other` where either is NaN.
    fn min(self, other: Self) -> Self;
    /// SSE's `maxps`: `other` where either is NaN.
    fn max(self, other: Self) -> Self;
    /// Ordered comparisons: false where either is NaN.
    fn lt(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// Lanes that are neither infinite nor NaN.
    fn is_finite(self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Bit `i` set where lane `i` of `mask` holds.
    fn bitmask(mask: Self::Mask) -> u32;
}

impl Lanes for Vec4 {
    type Mask = BVec4A;
    const N: usize = 4;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        Vec4::splat(v)
    }
    #[inline(always)]
    fn from_slice(v: &[f32]) -> Self {
        Vec4::from_slice(v)
    }
    #[inline(always)]
    fn from_fn(f: impl Fn(usize) -> f32) -> Self {
        Vec4::new(f(0), f(1), f(2), f(3))
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f32]) {
        self.write_to_slice(out)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec4::from_array(self.to_array().map(f32::sqrt))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        Vec4::copysign(self, sign)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Vec4::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Vec4::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> BVec4A {
        self.cmplt(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> BVec4A {
        self.cmpgt(other)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> BVec4A {
        self.cmpge(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> BVec4A {
        self.cmple(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> BVec4A {
        self.cmpeq(other)
    }
    #[inline(always)]
    fn is_finite(self) -> BVec4A {
        self.is_finite_mask()
    }
    #[inline(always)]
    fn select(mask: BVec4A, if_true: Self, if_false: Self) -> Self {
        Vec4::select(mask, if_true, if_false)
    }
    #[inline(always)]
    fn bitmask(mask: BVec4A) -> u32 {
        mask.bitmask()
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::{sorted_entries, F32x8, M32x8};

/// Eight lanes in an AVX register. Every function here runs AVX instructions: they may only be
/// called inside [`in_avx`] (which needs the proof that the CPU has AVX), where they are inlined.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

    use super::Lanes;

    /// Eight `f32` lanes.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F32x8(__m256);

    // Two `Vec4`s are eight consecutive `f32`s, which `F32x8::from_pair` reads as one.
    const _: () = assert!(std::mem::size_of::<[glam::Vec4; 2]>() == 8 * std::mem::size_of::<f32>());

    /// Eight lane-wise truth values (all bits set or clear).
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct M32x8(__m256);

    /// Runs one AVX intrinsic.
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: called only inside `in_avx`, which is entered only where the CPU reported
            // AVX (see the module's documentation).
            unsafe { $e }
        };
    }

    macro_rules! binary {
        ($trait:ident, $method:ident, $ty:ident, $intrinsic:ident) => {
            impl $trait for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $method(self, other: $ty) -> $ty {
                    $ty(avx!($intrinsic(self.0, other.0)))
                }
            }
        };
    }

    impl F32x8 {
        /// The lanes of `pair[0]`, then those of `pair[1]`, in one load.
        #[inline(always)]
        pub(crate) fn from_pair(pair: &[glam::Vec4; 2]) -> F32x8 {
            // SAFETY (besides AVX, as for every function here): the pointer covers the 32 bytes
            // of `pair` (asserted above), read without an alignment requirement.
            F32x8(avx!(_mm256_loadu_ps(pair.as_ptr().cast::<f32>())))
        }

        /// The lanes of `low`, then those of `high`.
        #[inline(always)]
        pub(crate) fn from_halves(low: glam::Vec4, high: glam::Vec4) -> F32x8 {
            F32x8(avx!(_mm256_set_m128(high.into(), low.into())))
        }

        /// The lanes as an array.
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 8] {
            let mut out = [0.0; 8];
            self.write_to(&mut out);
            out
        }
    }

    // A traversal stack's entry (child reference, entry distance) is two 32-bit words in this
    // order, so `sorted_entries` writes eight as two registers.
    const _: () = assert!(
        std::mem::size_of::<(u32, f32)>() == 8
            && std::mem::offset_of!((u32, f32), 0) == 0
            && std::mem::offset_of!((u32, f32), 1) == 4
    );

    /// The entries (child, entry distance) of a node's `hit` lanes into the first places of
    /// `out`, the one to visit first last: farthest first with `NEAR_LAST`, else nearest first;
    /// returns how many. Branch-free: the keys (the distance's bits, the slot in their low
    /// three; non-negative floats order as their bits; missed lanes sort last) go through a
    /// bitonic sorting network of six compare-exchange stages, then pick their children. Runs
    /// AVX2 instructions: called only inside [`in_avx2`](super::in_avx2).
    #[inline(always)]
    pub(crate) fn sorted_entries<const NEAR_LAST: bool>(
        t_near: F32x8,
        hit: M32x8,
        children: &[u32; 8],
        out: &mut [(u32, f32); 8],
    ) -> usize {
        // SAFETY: called only inside `in_avx2`, entered only where the CPU reported AVX2; the
        // two stores cover the 64 bytes of `out` (its layout asserted above), unaligned.
        unsafe {
            let low = _mm256_set1_epi32(7);
            let slots = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            let missed = _mm256_xor_si256(_mm256_castps_si256(hit.0), _mm256_set1_epi32(-1));
            let mut k = _mm256_or_si256(
                _mm256_or_si256(_mm256_andnot_si256(low, _mm256_castps_si256(t_near.0)), slots),
                missed,
            );
            if !NEAR_LAST {
                // Nearest first: missed lanes sort last as the largest key.
                k = _mm256_and_si256(k, _mm256_set1_epi32(i32::MAX));
            }
            // Each stage pairs lane i with a partner; the lower lane keeps the larger key with
            // `NEAR_LAST`, else the smaller.
            macro_rules! stage {
                ($partner:expr, $upper_lanes:literal) => {{
                    let p = $partner;
                    let (big, small) = (_mm256_max_epi32(k, p), _mm256_min_epi32(k, p));
                    k = if NEAR_LAST {
                        _mm256_blend_epi32::<$upper_lanes>(big, small)
                    } else {
                        _mm256_blend_epi32::<$upper_lanes>(small, big)
                    };
                }};
            }
            stage!(_mm256_shuffle_epi32::<0xB1>(k), 0xAA); // i ^ 1
            stage!(_mm256_shuffle_epi32::<0x1B>(k), 0xCC); // i ^ 3
            stage!(_mm256_shuffle_epi32::<0xB1>(k), 0xAA); // i ^ 1
            stage!(_mm256_shuffle_epi32::<0x1B>(_mm256_permute2x128_si256::<1>(k, k)), 0xF0); // i ^ 7
            stage!(_mm256_shuffle_epi32::<0x4E>(k), 0xCC); // i ^ 2
            stage!(_mm256_shuffle_epi32::<0xB1>(k), 0xAA); // i ^ 1
            let c = _mm256_permutevar8x32_epi32(_mm256_loadu_si256(children.as_ptr().cast()), _mm256_and_si256(k, low));
            let t = _mm256_andnot_si256(low, k);
            let (lo, hi) = (_mm256_unpacklo_epi32(c, t), _mm256_unpackhi_epi32(c, t));
            let dst = out.as_mut_ptr().cast::<__m256i>();
            _mm256_storeu_si256(dst, _mm256_permute2x128_si256::<0x20>(lo, hi));
            _mm256_storeu_si256(dst.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
            _mm256_movemask_ps(hit.0).count_ones() as usize
        }
    }

    binary!(Add, add, F32x8, _mm256_add_ps);
    binary!(Sub, sub, F32x8, _mm256_sub_ps);
    binary!(Mul, mul, F32x8, _mm256_mul_ps);
    binary!(Div, div, F32x8, _mm256_div_ps);
    binary!(BitAnd, bitand, M32x8, _mm256_and_ps);
    binary!(BitOr, bitor, M32x8, _mm256_or_ps);
    binary!(BitXor, bitxor, M32x8, _mm256_xor_ps);

    impl Neg for F32x8 {
        type Output = F32x8;
        #[inline(always)]
        fn neg(self) -> F32x8 {
            F32x8(avx!(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
        }
    }

    impl Not for M32x8 {
        type Output = M32x8;
        #[inline(always)]
        fn not(self) -> M32x8 {
            M32x8(avx!(_mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))))
        }
    }

    impl Lanes for F32x8 {
        type Mask = M32x8;
        const N: usize = 8;
        #[inline(always)]
        fn splat(v: f32) -> Self {
            F32x8(avx!(_mm256_set1_ps(v)))
        }
        #[inline(always)]
        fn from_slice(v: &[f32]) -> Self {
            assert!(v.len() >= 8, "eight lanes");
            F32x8(avx!(_mm256_loadu_ps(v.as_ptr())))
        }
        #[inline(always)]
        fn from_fn(f: impl Fn(usize) -> f32) -> Self {
            F32x8(avx!(_mm256_setr_ps(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7))))
        }
        #[inline(always)]
        fn write_to(self, out: &mut [f32]) {
            assert!(out.len() >= 8, "eight lanes");
            avx!(_mm256_storeu_ps(out.as_mut_ptr(), self.0))
        }
        #[inline(always)]
        fn abs(self) -> Self {
            F32x8(avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            F32x8(avx!(_mm256_sqrt_ps(self.0)))
        }
        #[inline(always)]
        fn copysign(self, sign: Self) -> Self {
            let mask = avx!(_mm256_set1_ps(-0.0));
            F32x8(avx!(_mm256_or_ps(
                _mm256_and_ps(sign.0, mask),
                _mm256_andnot_ps(mask, self.0)
            )))
        }
        #[inline(always)]
        fn min(self, other: Self) -> Self {
            F32x8(avx!(_mm256_min_ps(self.0, other.0)))
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            F32x8(avx!(_mm256_max_ps(self.0, other.0)))
        }
        #[inline(always)]
        fn lt(self, other: Self) -> M32x8 {
            M32x8(avx!(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn gt(self, other: Self) -> M32x8 {
            M32x8(avx!(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn ge(self, other: Self) -> M32x8 {
            M32x8(avx!(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn le(self, other: Self) -> M32x8 {
            M32x8(avx!(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn eq(self, other: Self) -> M32x8 {
            M32x8(avx!(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn is_finite(self) -> M32x8 {
            self.abs().lt(F32x8::splat(f32::INFINITY))
        }
        #[inline(always)]
        fn select(mask: M32x8, if_true: Self, if_false: Self) -> Self {
            F32x8(avx!(_mm256_blendv_ps(if_false.0, if_true.0, mask.0)))
        }
        #[inline(always)]
        fn bitmask(mask: M32x8) -> u32 {
            avx!(_mm256_movemask_ps(mask.0)) as u32
        }
    }
}
