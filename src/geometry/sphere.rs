//! Spheres: the one shape of the notes.
//!
//! A point P lies on the sphere of centre C and radius R when
//! (P − C)·(P − C) = R². Substituting the ray p(t) = A + tB gives the quadratic
//! (B·B)t² + 2B·(A − C)t + (A − C)·(A − C) − R² = 0, solved here in its
//! "half-b" form.

use crate::lanes::{Mask, Real};
use crate::math::{Interval, Point3, Vec3};
use crate::ray::{Ray, RayLanes};

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
    /// The ray's direction must have unit length; see [`intersect`].
    #[inline]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<f32> {
        debug_assert!(
            (ray.direction.length_squared() - 1.0).abs() < 1e-4,
            "ray direction {} is not unit length",
            ray.direction
        );
        let (t, valid) = intersect(&RayLanes::splat(ray, interval.min), &self.lanes());
        (valid && t < interval.max).then_some(t)
    }

    /// The sphere as one lane of [`intersect`].
    #[inline(always)]
    pub fn lanes(&self) -> SphereLanes<f32> {
        SphereLanes {
            center: self.center.to_array(),
            radius2: self.radius * self.radius,
        }
    }

    /// The outward unit normal at a point on the surface.
    #[inline]
    pub fn outward_normal(&self, point: Point3) -> Vec3 {
        (point - self.center) / self.radius
    }

    /// The texture coordinates at the unit outward normal `n`: u = φ/2π
    /// around the y axis from −x, v = θ/π from −y, as in *The Next Week*.
    /// Hit records leave them to be computed here, when a texture asks.
    pub fn uv(n: Vec3) -> [f32; 2] {
        let theta = (-n.y).clamp(-1.0, 1.0).acos();
        let phi = (-n.z).atan2(n.x) + std::f32::consts::PI;
        [
            phi / (2.0 * std::f32::consts::PI),
            theta / std::f32::consts::PI,
        ]
    }

    /// The axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (Point3, Point3) {
        let r = Vec3::splat(self.radius);
        (self.center - r, self.center + r)
    }
}

/// Spheres in lanes: one per lane of `R`, or one repeated in every lane.
#[derive(Clone, Copy, Debug)]
pub struct SphereLanes<R> {
    /// Centre C.
    pub center: [R; 3],
    /// Radius squared; −∞ in unused lanes, which no ray hits.
    pub radius2: R,
}

/// The ray–sphere test, written once for any number of lanes: for each lane,
/// the first root of the quadratic beyond the ray's `t_min`, and whether it
/// exists. The caller compares the root with the far end of its interval.
///
/// The ray's direction must have unit length, so that a = B·B = 1 drops out
/// and the roots are t = −h ∓ √d. In `f32` the textbook discriminant h² − c
/// loses every significant digit when a small ray grazes a large sphere (the
/// radius-1000 ground of the cover shows rings). Following Haines et al.,
/// *Ray Tracing Gems* ch. 7, the discriminant is computed as R² − |l|², where
/// l is the part of A − C perpendicular to the ray. The roots −h ∓ √d cancel
/// only when a root is close to 0 compared with h, that is for the surface a
/// ray is leaving; on a large sphere that error (≈ 2⁻²⁴R/cos θ) can exceed
/// any small epsilon, so the renderer starts rays leaving a surface a
/// rounding bound off it ([`HitRecord::spawn_origin`]), where the root is
/// clearly negative.
///
/// [`HitRecord::spawn_origin`]: crate::geometry::HitRecord::spawn_origin
#[inline(always)]
pub fn intersect<R: Real>(ray: &RayLanes<R>, sphere: &SphereLanes<R>) -> (R, R::Mask) {
    intersect_with::<R, true>(ray, sphere)
}

/// [`intersect`], which leaves early when no lane's discriminant is
/// non-negative if `EARLY_OUT` is set, and otherwise finishes every lane
/// without that branch; the result is the same either way. A packet of
/// spheres against one ray misses all of them often enough for the exit to
/// pay; a bundle of rays against one sphere does not, and mispredicts it.
#[inline(always)]
pub fn intersect_with<R: Real, const EARLY_OUT: bool>(
    ray: &RayLanes<R>,
    sphere: &SphereLanes<R>,
) -> (R, R::Mask) {
    let [ox, oy, oz] = ray.origin;
    let [dx, dy, dz] = ray.direction;
    let [cx, cy, cz] = sphere.center;
    let fx = ox - cx;
    let fy = oy - cy;
    let fz = oz - cz;
    let half_b = fx * dx + fy * dy + fz * dz;
    let lx = fx - half_b * dx;
    let ly = fy - half_b * dy;
    let lz = fz - half_b * dz;
    let discriminant = sphere.radius2 - (lx * lx + ly * ly + lz * lz);
    let real = R::splat(0.0).le(discriminant);
    if EARLY_OUT && !real.any() {
        return (discriminant, real);
    }
    let sqrt_d = discriminant.sqrt();
    let near = -half_b - sqrt_d;
    let far = -half_b + sqrt_d;
    let near_ok = ray.t_min.lt(near);
    let t = R::select(near_ok, near, far);
    (t, real & (near_ok | ray.t_min.lt(far)))
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
    fn texture_coordinates_follow_the_book() {
        // (1, 0, 0) → (0.5, 0.5); (0, 1, 0) → (0.5, 1); (0, 0, 1) → (0.25, 0.5).
        let close =
            |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
        assert!(close(Sphere::uv(Vec3::X), [0.5, 0.5]));
        assert!(close(Sphere::uv(Vec3::Y), [0.5, 1.0]));
        assert!(close(Sphere::uv(Vec3::Z), [0.25, 0.5]));
        assert!(close(Sphere::uv(Vec3::new(-1.0, 0.0, 0.0)), [0.0, 0.5]));
    }

    #[test]
    fn normal_points_outward_with_unit_length() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let n = s.outward_normal(Vec3::new(1.0, 4.0, 3.0));
        assert_eq!(n, Vec3::Y);
    }
}
