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

/// atan2(y, x), the angle of finite (x, y) in [−π, π], to within 3·10⁻⁷ radians
/// (`tests`): libm's `atan2f` is a call of some hundred instructions, which
/// every lookup of an environment map made twice. Range reduction to
/// |t| ≤ tan(π/8) and a polynomial in t² (the coefficients of Cephes'
/// `atanf`).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (a, b) = if steep { (ay, ax) } else { (ax, ay) };
    // t in [0, 1]: the tangent of the angle from the nearer axis.
    let t = if a == 0.0 { 0.0 } else { b / a };
    let (base, t) = if t > 0.414_213_57 {
        (FRAC_PI_4, (t - 1.0) / (t + 1.0))
    } else {
        (0.0, t)
    };
    let z = t * t;
    let p = (((0.080_537_445 * z - 0.138_776_86) * z + 0.199_777_1) * z - 0.333_329_5) * z * t + t;
    let mut angle = base + p;
    if steep {
        angle = FRAC_PI_2 - angle;
    }
    if x.is_sign_negative() {
        angle = PI - angle;
    }
    angle.copysign(y)
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

    #[test]
    fn atan2_is_within_three_tenths_of_a_microradian_of_the_library() {
        let mut worst = 0.0f64;
        let n = 2000;
        for i in 0..=n {
            // Every direction of the circle, and the axes' signed zeros.
            let phi = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * i as f64 / n as f64;
            for r in [1.0f64, 1e-3, 37.0] {
                let (y, x) = ((r * phi.sin()) as f32, (r * phi.cos()) as f32);
                let exact = f64::from(y).atan2(f64::from(x));
                worst = worst.max((f64::from(atan2(y, x)) - exact).abs());
            }
        }
        assert!(worst < 3e-7, "worst error {worst}");
        for (y, x) in [
            (0.0f32, 1.0f32),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
        ] {
            assert_eq!(atan2(y, x), y.atan2(x), "atan2({y}, {x})");
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
