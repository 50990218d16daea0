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
