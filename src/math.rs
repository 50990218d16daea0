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
