//! Rays: the vector function p(t) = A + tB.

use crate::math::{Point3, Vec3};

/// A half-line from `origin` along `direction`.
///
/// Rays made by the camera and the materials have unit-length directions, so
/// `t` measures distance; nothing else relies on that.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// The point A where the ray starts.
    pub origin: Point3,
    /// The direction B.
    pub direction: Vec3,
}

impl Ray {
    /// Creates the ray A + tB.
    #[inline]
    pub fn new(origin: Point3, direction: Vec3) -> Self {
        Self { origin, direction }
    }

    /// The point p(t) = A + tB.
    #[inline]
    pub fn at(&self, t: f32) -> Point3 {
        self.origin + t * self.direction
    }
}
