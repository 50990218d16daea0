//! Rays: the vector function p(t) = A + tB.

use crate::math::{Point3, Vec3};
use glam::Vec4;

/// A half-line from its origin along its direction, traced at a moment.
///
/// Rays made by the camera and the materials have unit-length directions, so
/// `t` measures distance, and the sphere tests rely on it (B·B = 1 saves two
/// divisions per sphere): rays given to `Sphere::hit`, `Bvh::hit` or
/// `Scene::hit` must have unit-length directions.
///
/// The time shares the origin's 16 bytes (the fourth lane of a vector whose
/// first three are the origin), so a ray is 32 bytes: paths keep their rays
/// in arrays that are copied and gathered every bounce, and a ray grown to
/// 48 bytes for the time costs still scenes several percent.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// The point A where the ray starts (x, y, z) and the ray's time (w).
    origin_time: Vec4,
    /// The direction B.
    pub direction: Vec3,
}

impl Ray {
    /// Creates the ray A + tB at time 0.
    #[inline]
    pub fn new(origin: Point3, direction: Vec3) -> Self {
        Self::timed(origin, direction, 0.0)
    }

    /// Creates the ray A + tB at `time`.
    #[inline]
    pub fn timed(origin: Point3, direction: Vec3, time: f32) -> Self {
        Self {
            origin_time: origin.extend(time),
            direction,
        }
    }

    /// The point A where the ray starts.
    #[inline(always)]
    pub fn origin(&self) -> Point3 {
        Point3::from_vec4(self.origin_time)
    }

    /// The moment the ray is traced at, within the camera's shutter
    /// interval: where moving objects are (0 when nothing moves).
    #[inline(always)]
    pub fn time(&self) -> f32 {
        self.origin_time.w
    }

    /// The point p(t) = A + tB.
    #[inline]
    pub fn at(&self, t: f32) -> Point3 {
        self.origin() + t * self.direction
    }
}

/// Rays in lanes, for the intersection kernels: one ray repeated in every
/// lane (tested against several shapes at once), or one ray per lane (a
/// bundle tested against one shape). See [`crate::lanes`].
#[derive(Clone, Copy, Debug)]
pub struct RayLanes<R> {
    /// Origin A.
    pub origin: [R; 3],
    /// Direction B (unit length).
    pub direction: [R; 3],
    /// Hits at or before this distance are not counted.
    pub t_min: R,
}

impl<R: crate::lanes::Real> RayLanes<R> {
    /// One ray repeated in every lane (as one lane, for `f32`).
    #[inline(always)]
    pub fn splat(ray: &Ray, t_min: f32) -> Self {
        use crate::lanes::map3;
        RayLanes {
            origin: map3(&ray.origin().to_array(), R::splat),
            direction: map3(&ray.direction.to_array(), R::splat),
            t_min: R::splat(t_min),
        }
    }
}
