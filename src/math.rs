//! Basic numeric types shared by every module.
//!
//! lumen computes in `f32` with glam's 16-byte aligned [`Vec3A`](glam::Vec3A), which maps a
//! 3-vector onto one SIMD register. Points, directions and colours all use it.

pub use glam::Vec3A as Vec3;

/// A point in space (same representation as a vector).
pub type Point3 = Vec3;
/// A linear RGB colour; components are not limited to `[0, 1]` (high dynamic range).
pub type Color = Vec3;

/// An interval of ray parameters from `min` to `max`; hits are accepted
/// strictly inside it (see [`Interval::surrounds`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Smallest accepted value.
    pub min: f32,
    /// Largest accepted value.
    pub max: f32,
}

impl Interval {
    /// Creates the interval `[min, max]`.
    pub const fn new(min: f32, max: f32) -> Self {
        Self { min, max }
    }

    /// Whether `x` lies strictly inside the interval (the ends are excluded, as a
    /// hit exactly at `t_min` is the surface the ray starts from).
    #[inline]
    pub fn surrounds(&self, x: f32) -> bool {
        self.min < x && x < self.max
    }
}

/// ⌊x⌋ as an integer: `x.floor() as i64`, without the library call that
/// code built for baseline x86-64 (no SSE4.1 rounding instruction) makes of
/// `floor`, which texture lookups paid per texel. The same value for every
/// `x` (truncation is exact, and a truncated `f32` is an `f32`).
#[inline(always)]
pub fn floor_i64(x: f32) -> i64 {
    let t = x as i64;
    if (t as f32) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `i.rem_euclid(n)` (n > 0), without the division where `i` already lies
/// in `0..n`, as a texel index nearly always does.
#[inline(always)]
pub fn wrap_index(i: i64, n: i64) -> i64 {
    if (0..n).contains(&i) {
        i
    } else {
        i.rem_euclid(n)
    }
}

/// Linear interpolation between two colours: `(1 - t)·a + t·b`.
#[inline]
pub fn lerp(a: Color, b: Color, t: f32) -> Color {
    (1.0 - t) * a + t * b
}

/// Two unit vectors that make a right-handed orthonormal frame (s, t, n)
/// with unit `n`: Duff et al.'s branchless construction (2017), the one
/// Mitsuba's `coordinate_system` and pbrt-v4's `CoordinateSystem` use, so
/// that angles about an axis start where theirs do.
pub fn frame(n: glam::DVec3) -> [glam::DVec3; 3] {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let s = glam::DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let t = glam::DVec3::new(b, sign + n.y * n.y * a, -n.y);
    [s, t, n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_and_wrap_agree_with_the_library() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1.5,
            f32::EPSILON,
            -f32::EPSILON,
            16_777_216.0,
            -16_777_217.0,
            1e9,
            -1e9,
            1e30,
            -1e30,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        values.extend((-2000..2000).map(|i| i as f32 * 0.37));
        for x in values {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
            // A texture's lookup subtracts the floor as an `f32` from a
            // coordinate less a half, never −0 (−0 less its floor would
            // be −0, not +0).
            if x.abs() < 1e9 && x.to_bits() != (-0.0f32).to_bits() {
                assert_eq!(
                    (x - floor_i64(x) as f32).to_bits(),
                    (x - x.floor()).to_bits(),
                    "{x}"
                );
            }
        }
        for n in [1, 2, 3, 256] {
            for i in -600..600 {
                assert_eq!(wrap_index(i, n), i.rem_euclid(n), "{i} in {n}");
            }
        }
    }
}
