//! Rays: the vector function p(t) = A + tB.

use crate::math::{Point3, Vec3};

/// A half-line from `origin` along `direction`.
///
/// Rays made by the camera and the materials have unit-length directions, so
/// `t` measures distance, and the sphere tests rely on it (B·B = 1 saves two
/// divisions per sphere): rays given to `Sphere::hit`, `Bvh::hit` or
/// `Scene::hit` must have unit-length directions.
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
