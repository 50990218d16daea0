//! Spheres: the one shape of the notes.
//!
//! A point P lies on the sphere of centre C and radius R when
//! (P − C)·(P − C) = R². Substituting the ray p(t) = A + tB gives the quadratic
//! (B·B)t² + 2B·(A − C)t + (A − C)·(A − C) − R² = 0, solved here in its
//! "half-b" form.

use crate::math::{Interval, Point3, Vec3};
use crate::ray::Ray;

/// A sphere given by its centre and (positive) radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre C.
    pub center: Point3,
    /// Radius R > 0.
    pub radius: f32,
}

impl Sphere {
    /// Creates a sphere.
    pub fn new(center: Point3, radius: f32) -> Self {
        Self { center, radius }
    }

    /// The nearest root of the ray–sphere quadratic inside `interval`, if any.
    ///
    /// The ray's direction must have unit length (every ray the camera and the
    /// materials make has), so that a = B·B = 1 drops out of the formulas and
    /// the roots are t = −h ∓ √d, with no division at all.
    ///
    /// In `f32` the textbook discriminant h² − c loses every significant digit
    /// when a small ray grazes a large sphere (the radius-1000 ground of the
    /// cover scene shows rings). Following Haines et al., *Ray Tracing Gems*
    /// ch. 7, the discriminant is computed as R² − |l|², where l is the part of
    /// A − C perpendicular to the ray. The roots −h ∓ √d cancel only when a
    /// root is close to 0 compared with h, that is for the surface a ray is
    /// leaving. On a large sphere that error (≈ 2⁻²⁴R/cos θ) can exceed any
    /// small epsilon, so the renderer starts rays leaving a surface a
    /// rounding bound off it ([`HitRecord::spawn_origin`]), where the root is
    /// clearly negative.
    ///
    /// [`HitRecord::spawn_origin`]: crate::geometry::HitRecord::spawn_origin
    #[inline]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<f32> {
        debug_assert!(
            (ray.direction.length_squared() - 1.0).abs() < 1e-4,
            "ray direction {} is not unit length",
            ray.direction
        );
        let f = ray.origin - self.center;
        let half_b = f.dot(ray.direction);
        let l = f - half_b * ray.direction;
        let discriminant = self.radius * self.radius - l.length_squared();
        if discriminant < 0.0 {
            return None;
        }
        let sqrt_d = discriminant.sqrt();
        let (near, far) = (-half_b - sqrt_d, -half_b + sqrt_d);
        if interval.surrounds(near) {
            Some(near)
        } else if interval.surrounds(far) {
            Some(far)
        } else {
            None
        }
    }

    /// The outward unit normal at a point on the surface.
    #[inline]
    pub fn outward_normal(&self, point: Point3) -> Vec3 {
        (point - self.center) / self.radius
    }

    /// The axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (Point3, Point3) {
        let r = Vec3::splat(self.radius);
        (self.center - r, self.center + r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: Interval = Interval::new(0.0, f32::INFINITY);

    fn unit_at_origin() -> Sphere {
        Sphere::new(Vec3::ZERO, 1.0)
    }

    #[test]
    fn ray_through_centre_hits_the_near_side() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert_eq!(unit_at_origin().hit(&ray, ALL), Some(4.0));
    }

    #[test]
    fn ray_that_misses_has_no_root() {
        let ray = Ray::new(Vec3::new(0.0, 2.0, -5.0), Vec3::Z);
        assert_eq!(unit_at_origin().hit(&ray, ALL), None);
    }

    #[test]
    fn tangent_ray_has_one_double_root() {
        let ray = Ray::new(Vec3::new(0.0, 1.0, -5.0), Vec3::Z);
        let t = unit_at_origin()
            .hit(&ray, ALL)
            .expect("tangent ray touches");
        assert!((t - 5.0).abs() < 1e-3, "t = {t}");
    }

    #[test]
    fn ray_from_inside_hits_the_far_side() {
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(unit_at_origin().hit(&ray, ALL), Some(1.0));
    }

    #[test]
    fn interval_excludes_roots_outside_it() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let s = unit_at_origin();
        // Near root 4 excluded, far root 6 accepted.
        assert_eq!(s.hit(&ray, Interval::new(4.5, 100.0)), Some(6.0));
        // Both roots excluded.
        assert_eq!(s.hit(&ray, Interval::new(0.0, 3.9)), None);
        assert_eq!(s.hit(&ray, Interval::new(6.5, 100.0)), None);
    }

    #[test]
    fn sphere_behind_the_ray_is_not_hit() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert_eq!(unit_at_origin().hit(&ray, ALL), None);
    }

    #[test]
    fn grazing_rays_on_a_huge_sphere_are_accurate_in_f32() {
        // The cover scene's ground: radius 1000 centred 1000 below the origin.
        let ground = Sphere::new(Vec3::new(0.0, -1000.0, 0.0), 1000.0);
        let origin = Vec3::new(13.0, 2.0, 3.0);
        for k in 1..200 {
            let target = Vec3::new(-5.0 + 0.05 * k as f32, 0.0, -20.0);
            let dir = (target - origin).normalize();
            let t = ground
                .hit(&Ray::new(origin, dir), ALL)
                .expect("looks at ground");
            let p = origin + t * dir;
            let err = ((p - ground.center).length() - ground.radius).abs();
            assert!(err < 2e-3, "hit point off the surface by {err}");
        }
    }

    #[test]
    fn normal_points_outward_with_unit_length() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let n = s.outward_normal(Vec3::new(1.0, 4.0, 3.0));
        assert_eq!(n, Vec3::Y);
    }
}
