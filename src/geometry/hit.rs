//! What a ray learns where it hits a surface.

use crate::math::{Point3, Vec3};
use crate::ray::Ray;

/// The nearest intersection of a ray with the scene.
#[derive(Clone, Copy, Debug)]
pub struct HitRecord {
    /// The hit point p(t).
    pub point: Point3,
    /// Unit surface normal, turned to face against the incoming ray.
    pub normal: Vec3,
    /// The ray parameter of the hit.
    pub t: f32,
    /// True when the ray hits the outside of the surface (it travels against
    /// the outward normal); false when it comes from inside.
    pub front_face: bool,
    /// Index of the hit object's material in the scene's material table.
    pub material: u32,
    /// Index of the hit object in the scene.
    pub object: u32,
}

/// Orients an outward normal against the ray and records which side was hit.
///
/// The sign of `direction · outward_normal` tells the side: negative means the
/// ray and the normal point in opposite directions, so the ray arrives from
/// outside.
#[inline]
pub fn face_normal(ray: &Ray, outward_normal: Vec3) -> (Vec3, bool) {
    let front_face = ray.direction.dot(outward_normal) < 0.0;
    let normal = if front_face {
        outward_normal
    } else {
        -outward_normal
    };
    (normal, front_face)
}
