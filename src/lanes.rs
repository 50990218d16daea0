//! Arithmetic written once for any number of lanes.
//!
//! Each intersection kernel of [`crate::geometry`] is one generic function
//! over [`Real`]: run on `f32` it tests one ray against one shape; run on
//! [`F8`] it tests one ray against eight shapes of a leaf, or eight rays of a
//! bundle against one shape. Every lane performs the same IEEE operations in
//! the same order, so all three give bit-identical distances.
//!
//! Eight lanes come in two forms: [`F8`], two 4-lane vectors of the
//! architecture's baseline (SSE2, NEON), and on x86-64 [`W8`], one AVX
//! register, used only inside functions compiled for AVX2. (A plain
//! `[f32; 8]` worked on by loops was vectorised badly, with gathers and
//! shuffles; see docs/performance.md.)

use glam::{BVec4A, Vec4};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A number of one or more lanes, with the operations the kernels need.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The result of a comparison, one truth value per lane.
    type Mask: Mask;
    /// Number of lanes.
    const LANES: usize;
    /// Lane `i`.
    fn lane(self, i: usize) -> f32;
    /// A copy with lane `i` replaced by `x`.
    fn with_lane(self, i: usize, x: f32) -> Self;
    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// Lane-wise square root.
    fn sqrt(self) -> Self;
    /// Lane-wise `self < other`.
    fn lt(self, other: Self) -> Self::Mask;
    /// Lane-wise `self <= other`.
    fn le(self, other: Self) -> Self::Mask;
    /// Lane-wise `self == other`.
    fn eq(self, other: Self) -> Self::Mask;
    /// Lane-wise `if mask { a } else { b }`.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
}

/// Truth values of one or more lanes.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Whether any lane is true.
    fn any(self) -> bool;
    /// Lane `i`.
    fn lane(self, i: usize) -> bool;
    /// A copy with lane `i` replaced by `b`.
    fn with_lane(self, i: usize, b: bool) -> Self;
}

impl Real for f32 {
    type Mask = bool;
    const LANES: usize = 1;
    #[inline(always)]
    fn lane(self, _: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn with_lane(self, _: usize, x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask {
            a
        } else {
            b
        }
    }
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn lane(self, _: usize) -> bool {
        self
    }
    #[inline(always)]
    fn with_lane(self, _: usize, b: bool) -> Self {
        b
    }
}

/// `[f(a[0]), f(a[1]), f(a[2])]`, always inlined. The kernels build their
/// lanes with it rather than with `array::map`, which the compiler may leave
/// as a call: the AVX instructions inside would then be calls too, since a
/// function compiled without AVX cannot inline them.
#[inline(always)]
pub fn map3<T: Copy, U>(a: &[T; 3], f: impl Fn(T) -> U) -> [U; 3] {
    [f(a[0]), f(a[1]), f(a[2])]
}

/// Number of lanes of [`F8`] and [`W8`].
pub const LANES: usize = 8;

/// Eight lanes, with what a packet's test and a bundle need beyond
/// [`Real`]: moving to and from arrays, the smallest lane, masks as bits.
pub trait Wide: Real {
    /// The lanes of `a`.
    fn from_array(a: [f32; LANES]) -> Self;
    /// The lanes as an array.
    fn to_array(self) -> [f32; LANES];
    /// The smallest lane, with `minps` semantics. The kernels only reduce
    /// lanes that are numbers or +∞, whose minimum does not depend on the
    /// order of comparisons.
    fn min_lane(self) -> f32;
    /// Bit `i` set for each true lane `i`.
    fn bits(mask: Self::Mask) -> u32;
    /// Lane `i` true where bit `i` of `bits` is set.
    fn mask_from_bits(bits: u32) -> Self::Mask;
    /// Lane-wise minimum with `minps` semantics (see [`min4`]).
    fn min_ps(self, other: Self) -> Self;
    /// Lane-wise maximum with `maxps` semantics (see [`max4`]).
    fn max_ps(self, other: Self) -> Self;
}

/// Eight `f32` lanes as two 4-lane vectors of the architecture's baseline
/// (SSE2, NEON; scalar code elsewhere): the portable eight lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F8(pub [Vec4; 2]);

/// The mask of [`F8`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct M8(pub [BVec4A; 2]);

macro_rules! halves {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8([self.0[0] $op o.0[0], self.0[1] $op o.0[1]])
            }
        }
    };
}
halves!(Add, add, +);
halves!(Sub, sub, -);
halves!(Mul, mul, *);
halves!(Div, div, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        F8([-self.0[0], -self.0[1]])
    }
}

impl Real for F8 {
    type Mask = M8;
    const LANES: usize = LANES;
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.0[i / 4][i % 4]
    }
    #[inline(always)]
    fn with_lane(mut self, i: usize, x: f32) -> Self {
        self.0[i / 4][i % 4] = x;
        self
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        F8([Vec4::splat(x); 2])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F8([sqrt4(self.0[0]), sqrt4(self.0[1])])
    }
    #[inline(always)]
    fn lt(self, o: F8) -> M8 {
        M8([self.0[0].cmplt(o.0[0]), self.0[1].cmplt(o.0[1])])
    }
    #[inline(always)]
    fn le(self, o: F8) -> M8 {
        M8([self.0[0].cmple(o.0[0]), self.0[1].cmple(o.0[1])])
    }
    #[inline(always)]
    fn eq(self, o: F8) -> M8 {
        M8([self.0[0].cmpeq(o.0[0]), self.0[1].cmpeq(o.0[1])])
    }
    #[inline(always)]
    fn select(mask: M8, a: Self, b: Self) -> Self {
        F8([
            Vec4::select(mask.0[0], a.0[0], b.0[0]),
            Vec4::select(mask.0[1], a.0[1], b.0[1]),
        ])
    }
}

impl Wide for F8 {
    #[inline(always)]
    fn from_array(a: [f32; LANES]) -> Self {
        F8([
            Vec4::new(a[0], a[1], a[2], a[3]),
            Vec4::new(a[4], a[5], a[6], a[7]),
        ])
    }
    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        let (a, b) = (self.0[0].to_array(), self.0[1].to_array());
        [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
    }
    #[inline(always)]
    fn min_lane(self) -> f32 {
        let m = min4(self.0[0], self.0[1]).to_array();
        let min = |a: f32, b: f32| if a < b { a } else { b };
        min(min(m[0], m[2]), min(m[1], m[3]))
    }
    #[inline(always)]
    fn bits(mask: M8) -> u32 {
        mask.0[0].bitmask() | mask.0[1].bitmask() << 4
    }
    #[inline(always)]
    fn mask_from_bits(bits: u32) -> M8 {
        let half = |b: u32| BVec4A::new(b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0);
        M8([half(bits), half(bits >> 4)])
    }
    #[inline(always)]
    fn min_ps(self, o: F8) -> F8 {
        F8([min4(self.0[0], o.0[0]), min4(self.0[1], o.0[1])])
    }
    #[inline(always)]
    fn max_ps(self, o: F8) -> F8 {
        F8([max4(self.0[0], o.0[0]), max4(self.0[1], o.0[1])])
    }
}

impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        M8([self.0[0] & o.0[0], self.0[1] & o.0[1]])
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        M8([self.0[0] | o.0[0], self.0[1] | o.0[1]])
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8([!self.0[0], !self.0[1]])
    }
}

impl Mask for M8 {
    #[inline(always)]
    fn any(self) -> bool {
        (self.0[0] | self.0[1]).any()
    }
    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.0[i / 4].test(i % 4)
    }
    #[inline(always)]
    fn with_lane(mut self, i: usize, b: bool) -> Self {
        self.0[i / 4].set(i % 4, b);
        self
    }
}

/// `minps` semantics on every architecture: `a` if `a < b`, else `b` (so `b`
/// when either is NaN). NEON's and the scalar fallback's `min` differ on NaN.
#[inline(always)]
pub fn min4(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        a.min(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::select(a.cmplt(b), a, b)
    }
}

/// `maxps` semantics on every architecture, as [`min4`].
#[inline(always)]
pub fn max4(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        a.max(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::select(a.cmpgt(b), a, b)
    }
}

/// Lane-wise square root (glam's `Vec4` has none).
#[inline(always)]
#[allow(unsafe_code)]
fn sqrt4(v: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE is part of the x86-64 baseline, so the instruction exists.
        Vec4::from(unsafe { std::arch::x86_64::_mm_sqrt_ps(v.into()) })
    }
    #[cfg(target_arch = "aarch64")]
    {
        // SAFETY: NEON is part of the aarch64 baseline, so the instruction exists.
        Vec4::from(unsafe { std::arch::aarch64::vsqrtq_f32(v.into()) })
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        Vec4::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt(), v.w.sqrt())
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx::{MW8, W8};

/// Eight lanes in one AVX register, for the AVX2 version of the render loop.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use super::{Mask, Real, Wide, LANES};
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    // SAFETY (every `unsafe` block of this module): a `W8` or `MW8` is only
    // made and used inside functions compiled for AVX2
    // (`#[target_feature(enable = "avx2")]`), which are only called when
    // `Isa::detect` found AVX2 on the processor, so the instructions exist.

    /// Eight `f32` lanes in one AVX register.
    #[derive(Clone, Copy, Debug)]
    pub struct W8(__m256);

    /// The mask of [`W8`]: all-ones or all-zeros lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct MW8(__m256);

    macro_rules! op {
        ($trait:ident, $f:ident, $intrinsic:ident) => {
            impl $trait for W8 {
                type Output = W8;
                #[inline(always)]
                fn $f(self, o: W8) -> W8 {
                    W8(unsafe { $intrinsic(self.0, o.0) })
                }
            }
        };
    }
    op!(Add, add, _mm256_add_ps);
    op!(Sub, sub, _mm256_sub_ps);
    op!(Mul, mul, _mm256_mul_ps);
    op!(Div, div, _mm256_div_ps);

    impl Neg for W8 {
        type Output = W8;
        #[inline(always)]
        fn neg(self) -> W8 {
            W8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    impl Real for W8 {
        type Mask = MW8;
        const LANES: usize = LANES;
        #[inline(always)]
        fn lane(self, i: usize) -> f32 {
            self.to_array()[i]
        }
        #[inline(always)]
        fn with_lane(self, i: usize, x: f32) -> Self {
            let mut a = self.to_array();
            a[i] = x;
            W8::from_array(a)
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            W8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            W8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn lt(self, o: W8) -> MW8 {
            MW8(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn le(self, o: W8) -> MW8 {
            MW8(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn eq(self, o: W8) -> MW8 {
            MW8(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn select(mask: MW8, a: Self, b: Self) -> Self {
            W8(unsafe { _mm256_blendv_ps(b.0, a.0, mask.0) })
        }
    }

    impl Wide for W8 {
        #[inline(always)]
        fn from_array(a: [f32; LANES]) -> Self {
            W8(unsafe { _mm256_loadu_ps(a.as_ptr()) })
        }
        #[inline(always)]
        fn to_array(self) -> [f32; LANES] {
            let mut a = [0.0; LANES];
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
            a
        }
        #[inline(always)]
        fn min_lane(self) -> f32 {
            unsafe {
                let t = self.0;
                let m = _mm_min_ps(_mm256_castps256_ps128(t), _mm256_extractf128_ps::<1>(t));
                let m = _mm_min_ps(m, _mm_shuffle_ps::<0b01_00_11_10>(m, m));
                let m = _mm_min_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m));
                _mm_cvtss_f32(m)
            }
        }
        #[inline(always)]
        fn bits(mask: MW8) -> u32 {
            unsafe { _mm256_movemask_ps(mask.0) as u32 }
        }
        #[inline(always)]
        fn mask_from_bits(bits: u32) -> MW8 {
            unsafe {
                let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let set = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits);
                MW8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(set, lane_bits)))
            }
        }
        #[inline(always)]
        fn min_ps(self, o: W8) -> W8 {
            W8(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn max_ps(self, o: W8) -> W8 {
            W8(unsafe { _mm256_max_ps(self.0, o.0) })
        }
    }

    macro_rules! mask_op {
        ($trait:ident, $f:ident, $intrinsic:ident) => {
            impl $trait for MW8 {
                type Output = MW8;
                #[inline(always)]
                fn $f(self, o: MW8) -> MW8 {
                    MW8(unsafe { $intrinsic(self.0, o.0) })
                }
            }
        };
    }
    mask_op!(BitAnd, bitand, _mm256_and_ps);
    mask_op!(BitOr, bitor, _mm256_or_ps);

    impl Not for MW8 {
        type Output = MW8;
        #[inline(always)]
        fn not(self) -> MW8 {
            let ones = unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(-1)) };
            MW8(unsafe { _mm256_xor_ps(self.0, ones) })
        }
    }

    impl Mask for MW8 {
        #[inline(always)]
        fn any(self) -> bool {
            unsafe { _mm256_movemask_ps(self.0) != 0 }
        }
        #[inline(always)]
        fn lane(self, i: usize) -> bool {
            W8::bits(self) >> i & 1 != 0
        }
        #[inline(always)]
        fn with_lane(self, i: usize, b: bool) -> Self {
            let bits = W8::bits(self) & !(1 << i) | u32::from(b) << i;
            W8::mask_from_bits(bits)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f32; 8] = [1.0, -2.0, 3.5, 0.0, -0.0, f32::INFINITY, 1e-30, 7.0];
    const B: [f32; 8] = [2.0, -2.0, 1.5, 0.0, 0.0, 1.0, 3e-30, -7.0];

    /// Each lane of eight computes the bits one lane computes.
    fn check<W: Wide>() {
        let (a, b) = (W::from_array(A), W::from_array(B));
        let lt = a.lt(b);
        let results = [
            (a + b).to_array(),
            (a - b).to_array(),
            (a * b).to_array(),
            (a / b).to_array(),
            (-a).to_array(),
            a.sqrt().to_array(),
            W::select(lt, a, b).to_array(),
        ];
        for i in 0..LANES {
            let (x, y) = (A[i], B[i]);
            let expected = [
                x + y,
                x - y,
                x * y,
                x / y,
                -x,
                x.sqrt(),
                f32::select(x < y, x, y),
            ];
            for (r, e) in results.iter().zip(expected) {
                // NaN payloads may differ (0/0 in a vector register is a
                // positive NaN on x86); every other result bit for bit.
                if !(r[i].is_nan() && e.is_nan()) {
                    assert_eq!(r[i].to_bits(), e.to_bits(), "lane {i}");
                }
            }
            assert_eq!(lt.lane(i), x < y);
            assert_eq!(a.le(b).lane(i), x <= y);
            assert_eq!(a.eq(b).lane(i), x == y);
            assert_eq!(a.lane(i).to_bits(), x.to_bits());
        }
        assert_eq!(W::bits(lt), 0b0100_0001);
        assert_eq!(W::bits(W::mask_from_bits(0b1010_0110)), 0b1010_0110);
        assert_eq!(
            W::bits(lt.with_lane(3, true).with_lane(0, false)),
            0b0100_1000
        );
        assert!(lt.any() && !(lt & !lt).any() && (lt | !lt).lane(5));
        assert_eq!(a.min_lane(), -2.0);
        assert_eq!(W::splat(f32::INFINITY).min_lane(), f32::INFINITY);
        assert_eq!(a.with_lane(2, 9.0).lane(2), 9.0);
    }

    #[test]
    fn portable_lanes_compute_what_one_lane_computes() {
        check::<F8>();
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn check_avx() {
        check::<W8>();
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx_lanes_compute_what_one_lane_computes() {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 was detected.
            #[allow(unsafe_code)]
            unsafe {
                check_avx()
            };
        }
    }
}
