//! Disks and cylinders: a unit shape in its own space, placed in the world
//! by an affine transform (so a disk may be stretched into an ellipse, a
//! cylinder turned, scaled and sheared), as Mitsuba and pbrt describe them.
//!
//! In its own space the disk is x² + y² ≤ 1 in the plane z = 0, its outside
//! towards +z, with texture coordinates (u, v) = (r, φ/2π); the cylinder is
//! x² + y² = 1 for 0 ≤ z ≤ 1, open at both ends, its outside away from the
//! axis, with (u, v) = (φ/2π, z). φ runs from +x towards +y.
//!
//! A ray is taken into the shape's space without normalising its direction,
//! so that the distance t along it is the world distance, and met there in
//! `f64`: these shapes are rare enough that a lane at a time, in double
//! precision, costs nothing a scene notices, and the quadratic of a
//! cylinder then keeps its digits for rays leaving the surface.

use crate::geometry::bvh_build::Aabb;
use crate::geometry::transform::Transform;
use crate::math::{Point3, Vec3};
use crate::ray::Ray;
use glam::DVec3;
use std::f64::consts::TAU;

/// Which unit shape a [`Quadric`] places.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum QuadricForm {
    /// The unit disk in z = 0, facing +z.
    Disk,
    /// The unit cylinder about the z axis from z = 0 to z = 1, open ends.
    Cylinder,
}

/// A unit disk or cylinder placed by an affine transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Which shape.
    pub form: QuadricForm,
    /// World to object: the rows of a 3 × 4 matrix.
    to_object: [[f32; 4]; 3],
    /// Object to world: the rows of a 3 × 4 matrix.
    to_world: [[f32; 4]; 3],
    /// The world box.
    bounds: Aabb,
    /// Whether its outside is turned in ([`Quadric::facing_in`]).
    inward: bool,
}

/// What a hit on a quadric gives its record, in the world.
#[derive(Clone, Copy, Debug)]
pub struct QuadricHit {
    /// The point, on the surface.
    pub point: Point3,
    /// The unit outward normal.
    pub outward: Vec3,
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// ∂p/∂u.
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
    /// The size of the coordinates the point was computed from (the
    /// translation and the lengths of the axes): its rounding is relative
    /// to this.
    pub extent: f32,
}

impl Quadric {
    /// The unit `form` placed by `transform`.
    pub fn new(form: QuadricForm, transform: &Transform) -> Quadric {
        let rows = |m: glam::DMat4| {
            let r = m.transpose().to_cols_array_2d();
            [0, 1, 2].map(|i| r[i].map(|x| x as f32))
        };
        let z = match form {
            QuadricForm::Disk => 0.0,
            QuadricForm::Cylinder => 1.0,
        };
        let unit = Aabb {
            min: Vec3::new(-1.0, -1.0, 0.0),
            max: Vec3::new(1.0, 1.0, z),
        };
        let mut bounds = transform.bounds(&unit);
        // The surface traced is that of the rounded inverse: a few more
        // roundings of the box's size.
        let margin = bounds.min.abs().max(bounds.max.abs()) * (8.0 * f32::EPSILON);
        bounds.min -= margin;
        bounds.max += margin;
        Quadric {
            form,
            to_object: rows(transform.to_object_matrix()),
            to_world: rows(transform.to_world_matrix()),
            bounds,
            inward: false,
        }
    }

    /// The same surface with its outside turned in if `inward`: a
    /// cylinder facing its axis, a disk facing the other way.
    pub fn facing_in(self, inward: bool) -> Quadric {
        Quadric { inward, ..self }
    }

    /// The world box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The world point of object point `p`.
    fn world_point(&self, p: DVec3) -> DVec3 {
        apply(&self.to_world, p, 1.0)
    }

    /// The world vector of object vector `v`.
    fn world_vector(&self, v: DVec3) -> Vec3 {
        Vec3::from(apply(&self.to_world, v, 0.0).as_vec3())
    }

    /// The ray's origin and direction in the object's space (the direction
    /// not normalised: distances along it are the world's).
    #[inline]
    fn object_ray(&self, ray: &Ray) -> (DVec3, DVec3) {
        let origin = ray.origin().as_dvec3();
        let direction = ray.direction.as_dvec3();
        (
            apply(&self.to_object, origin, 1.0),
            apply(&self.to_object, direction, 0.0),
        )
    }

    /// The distance to the nearest hit of `ray` beyond `t_min`, if any
    /// (rounded to `f32`, and beyond `t_min` once rounded).
    pub fn hit(&self, ray: &Ray, t_min: f32) -> Option<f32> {
        let (o, d) = self.object_ray(ray);
        let beyond = |t: f64| {
            let t32 = t as f32;
            (t32 > t_min && t32.is_finite()).then_some(t32)
        };
        match self.form {
            QuadricForm::Disk => {
                if d.z == 0.0 {
                    return None;
                }
                let t = -o.z / d.z;
                let (x, y) = (o.x + t * d.x, o.y + t * d.y);
                if x * x + y * y <= 1.0 {
                    beyond(t)
                } else {
                    None
                }
            }
            QuadricForm::Cylinder => {
                let a = d.x * d.x + d.y * d.y;
                if a == 0.0 {
                    return None;
                }
                let b = o.x * d.x + o.y * d.y;
                let c = o.x * o.x + o.y * o.y - 1.0;
                let discriminant = b * b - a * c;
                if !(discriminant >= 0.0) {
                    return None;
                }
                // The root that does not cancel first, then the other
                // from their product c/a.
                let q = -(b + discriminant.sqrt().copysign(b));
                let t0 = q / a;
                let t1 = if q != 0.0 { c / q } else { t0 };
                let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
                [near, far].into_iter().find_map(|t| {
                    let z = o.z + t * d.z;
                    if (0.0..=1.0).contains(&z) {
                        beyond(t)
                    } else {
                        None
                    }
                })
            }
        }
    }

    /// The surface at distance `t` along `ray` (a hit [`Quadric::hit`]
    /// found): the point moved onto the shape, its outward normal, texture
    /// coordinates and derivatives.
    pub fn surface(&self, ray: &Ray, t: f32) -> QuadricHit {
        let (o, d) = self.object_ray(ray);
        let p = o + f64::from(t) * d;
        let (r, phi) = polar(p);
        self.at(match self.form {
            QuadricForm::Disk => [r.min(1.0), phi / TAU],
            QuadricForm::Cylinder => [phi / TAU, p.z.clamp(0.0, 1.0)],
        })
    }

    /// The surface at texture coordinates `uv` (the disk's (r, φ/2π), the
    /// cylinder's (φ/2π, z)).
    pub fn at(&self, uv: [f64; 2]) -> QuadricHit {
        let (point, normal, dpdu, dpdv) = self.local(uv);
        QuadricHit {
            point: Vec3::from(self.world_point(point).as_vec3()),
            outward: self.outward(normal),
            uv: uv.map(|x| x as f32),
            dpdu: self.world_vector(dpdu),
            dpdv: self.world_vector(dpdv),
            extent: self.extent(),
        }
    }

    /// The point, normal and derivatives at `uv` in the shape's own space.
    fn local(&self, [u, v]: [f64; 2]) -> (DVec3, DVec3, DVec3, DVec3) {
        match self.form {
            QuadricForm::Disk => {
                let (sin, cos) = (v * TAU).sin_cos();
                let radial = DVec3::new(cos, sin, 0.0);
                let around = DVec3::new(-sin, cos, 0.0) * (TAU * u);
                (radial * u, DVec3::Z, radial, around)
            }
            QuadricForm::Cylinder => {
                let (sin, cos) = (u * TAU).sin_cos();
                let radial = DVec3::new(cos, sin, 0.0);
                let around = DVec3::new(-sin, cos, 0.0) * TAU;
                (radial + DVec3::new(0.0, 0.0, v), radial, around, DVec3::Z)
            }
        }
    }

    /// The world unit normal of object normal `n`: the inverse transpose,
    /// which keeps the outside outside under a mirroring transform, turned
    /// in if the shape is.
    fn outward(&self, n: DVec3) -> Vec3 {
        let row = |j: usize| {
            let r = self.to_object[j].map(f64::from);
            DVec3::new(r[0], r[1], r[2])
        };
        let w = row(0) * n.x + row(1) * n.y + row(2) * n.z;
        let w = if self.inward { -w } else { w };
        Vec3::from(w.normalize().as_vec3())
    }

    /// The translation's largest coordinate plus the lengths of the three
    /// axes: the size of what a point's world coordinates are summed from.
    pub fn extent(&self) -> f32 {
        let [x, y, z, origin] = self.axes();
        origin.abs().max_element() + x.length() + y.length() + z.length()
    }

    /// The world axes of the object's x, y and z, and its origin.
    pub fn axes(&self) -> [Vec3; 4] {
        let m = &self.to_world;
        [0, 1, 2, 3].map(|j| Vec3::new(m[0][j], m[1][j], m[2][j]))
    }

    /// The surface area: π|x × y| for the disk (an ellipse), 2π r |z| for
    /// a cylinder whose x and y axes are perpendicular, of one length r,
    /// and perpendicular to its z axis (see [`Quadric::round`]).
    pub fn area(&self) -> f32 {
        let [x, y, z, _] = self.axes().map(|a| a.as_dvec3());
        let area = match self.form {
            QuadricForm::Disk => std::f64::consts::PI * x.cross(y).length(),
            QuadricForm::Cylinder => TAU * x.length() * z.length(),
        };
        area as f32
    }

    /// Whether a uniform (u, v) is uniform over the area: always for the
    /// disk (as (r², φ/2π)), for a cylinder whose cross-sections are
    /// circles perpendicular to its axis (x and y axes perpendicular, of
    /// one length, and perpendicular to z, to 10⁻⁵).
    pub fn round(&self) -> bool {
        let [x, y, z, _] = self.axes().map(|a| a.as_dvec3());
        match self.form {
            QuadricForm::Disk => true,
            QuadricForm::Cylinder => {
                let (lx, ly, lz) = (x.length(), y.length(), z.length());
                let tolerance = 1e-5;
                (lx - ly).abs() <= tolerance * lx
                    && x.dot(y).abs() <= tolerance * lx * ly
                    && x.dot(z).abs() <= tolerance * lx * lz
                    && y.dot(z).abs() <= tolerance * ly * lz
            }
        }
    }

    /// A point uniform over the area for `uv` uniform in the unit square
    /// (for a cylinder, when [`Quadric::round`]): the point, its outward
    /// normal and its texture coordinates (a light sample needs no
    /// derivatives).
    pub fn sample(&self, [s, t]: [f32; 2]) -> (Point3, Vec3, [f32; 2]) {
        let (s, t) = (f64::from(s), f64::from(t));
        let uv = match self.form {
            QuadricForm::Disk => [s.sqrt(), t],
            QuadricForm::Cylinder => [s, t],
        };
        let (point, normal, ..) = self.local(uv);
        (
            Vec3::from(self.world_point(point).as_vec3()),
            self.outward(normal),
            uv.map(|x| x as f32),
        )
    }
}

/// The placement of the unit disk that makes the disk of `radius` about
/// `center` facing unit `normal`, its φ measured from the first axis of
/// [`crate::math::frame`] of the normal: a 4 × 4 matrix row by row (as
/// `TransformStep::Matrix` takes it).
pub fn disk_placement(center: [f64; 3], normal: DVec3, radius: f64) -> [[f64; 4]; 4] {
    let [s, t, n] = crate::math::frame(normal);
    columns([s * radius, t * radius, n * radius, DVec3::from(center)])
}

/// The placement of the unit cylinder that makes the cylinder of `radius`
/// from `p0` to `p1`, turned about its axis as Mitsuba and pbrt turn it
/// (by [`crate::math::frame`] of the axis), row by row; `None` when `p0`
/// is `p1`.
pub fn cylinder_placement(p0: [f64; 3], p1: [f64; 3], radius: f64) -> Option<[[f64; 4]; 4]> {
    let (p0, axis) = (DVec3::from(p0), DVec3::from(p1) - DVec3::from(p0));
    if !(axis.length() > 0.0) {
        return None;
    }
    let [s, t, _] = crate::math::frame(axis.normalize());
    Some(columns([s * radius, t * radius, axis, p0]))
}

/// The affine matrix, row by row, whose columns are the axes `x`, `y`,
/// `z` and the origin `o`.
fn columns([x, y, z, o]: [DVec3; 4]) -> [[f64; 4]; 4] {
    [
        [x.x, y.x, z.x, o.x],
        [x.y, y.y, z.y, o.y],
        [x.z, y.z, z.z, o.z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// Row-major 3 × 4 matrix `m` times (p, w).
#[inline]
fn apply(m: &[[f32; 4]; 3], p: DVec3, w: f64) -> DVec3 {
    let row = |r: &[f32; 4]| {
        f64::from(r[0]) * p.x + f64::from(r[1]) * p.y + f64::from(r[2]) * p.z + f64::from(r[3]) * w
    };
    DVec3::new(row(&m[0]), row(&m[1]), row(&m[2]))
}

/// The distance from the z axis and the angle φ ∈ [0, 2π) from +x
/// towards +y of `p`.
fn polar(p: DVec3) -> (f64, f64) {
    let phi = p.y.atan2(p.x);
    let phi = if phi < 0.0 { phi + TAU } else { phi };
    // 2π itself rounds back into range as u = φ/2π = 1 only.
    (p.x.hypot(p.y), phi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::transform::TransformStep;
    use crate::rng::Rng;

    fn placed(form: QuadricForm, steps: &[TransformStep]) -> Quadric {
        Quadric::new(form, &Transform::from_steps(steps).unwrap())
    }

    fn turned() -> Vec<TransformStep> {
        vec![
            TransformStep::Scale([1.5, 0.5, 2.0]),
            TransformStep::Rotate {
                axis: [1.0, 2.0, 3.0],
                degrees: 40.0,
            },
            TransformStep::Translate([0.5, -1.0, 2.0]),
        ]
    }

    #[test]
    fn a_disk_is_met_where_the_ray_crosses_its_plane_inside_the_circle() {
        let disk = placed(QuadricForm::Disk, &[TransformStep::Scale([2.0, 2.0, 2.0])]);
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 3.0), -Vec3::Z);
        assert_eq!(disk.hit(&down(0.0, 0.0), 0.0), Some(3.0));
        assert_eq!(disk.hit(&down(1.9, 0.0), 0.0), Some(3.0));
        assert_eq!(disk.hit(&down(1.5, 1.5), 0.0), None);
        // Not behind the ray, nor along its plane.
        assert_eq!(disk.hit(&down(0.0, 0.0), 3.0), None);
        let along = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        assert_eq!(disk.hit(&along, 0.0), None);
        let s = disk.surface(&down(1.0, 1.0), 3.0);
        assert!((s.point - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        assert!((s.outward - Vec3::Z).length() < 1e-6);
        let r = 2f32.sqrt() / 2.0;
        assert!((s.uv[0] - r).abs() < 1e-6 && (s.uv[1] - 0.125).abs() < 1e-6);
    }

    #[test]
    fn a_cylinder_is_met_from_outside_and_from_inside_between_its_ends() {
        let tube = placed(
            QuadricForm::Cylinder,
            &[TransformStep::Scale([2.0, 2.0, 4.0])],
        );
        let across = |z: f32| Ray::new(Vec3::new(-5.0, 0.0, z), Vec3::X);
        assert_eq!(tube.hit(&across(1.0), 0.0), Some(3.0));
        // From inside (beyond the near wall), the far wall.
        assert_eq!(tube.hit(&across(1.0), 3.5), Some(7.0));
        // Past its ends, and along its axis, nothing.
        assert_eq!(tube.hit(&across(4.5), 0.0), None);
        assert_eq!(tube.hit(&across(-0.5), 0.0), None);
        let axis = Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z);
        assert_eq!(tube.hit(&axis, 0.0), None);
        // Into an open end, the inside wall.
        let slanted = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.6, 0.0, -0.8));
        let t = tube.hit(&slanted, 0.0).unwrap();
        let s = tube.surface(&slanted, t);
        assert!((s.point - Vec3::new(2.0, 0.0, 5.0 - 8.0 / 3.0)).length() < 1e-5);
        assert!((s.outward - Vec3::X).length() < 1e-6, "{}", s.outward);
        assert!(s.uv[0].abs() < 1e-6 && (s.uv[1] - (5.0 - 8.0 / 3.0) / 4.0).abs() < 1e-6);
    }

    /// Every hit found lies on the placed shape, within its rounding, and
    /// no nearer point of the ray does: sampled along the ray against the
    /// implicit function in the object's space.
    #[test]
    fn hits_lie_on_the_placed_shape_and_none_is_missed_before_them() {
        let mut rng = Rng::new(17);
        for form in [QuadricForm::Disk, QuadricForm::Cylinder] {
            let q = placed(form, &turned());
            let mut hits = 0;
            for _ in 0..2000 {
                let origin = Vec3::new(
                    rng.next_f32() * 8.0 - 4.0,
                    rng.next_f32() * 8.0 - 5.0,
                    rng.next_f32() * 8.0 - 2.0,
                );
                let target = q.sample([rng.next_f32(), rng.next_f32()]).0
                    + 0.3 * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                let ray = Ray::new(origin, (target - origin).normalize());
                let inside = |t: f32| {
                    let (o, d) = q.object_ray(&ray);
                    let p = o + f64::from(t) * d;
                    match form {
                        QuadricForm::Disk => (p.z > 0.0, p.x * p.x + p.y * p.y <= 1.0),
                        QuadricForm::Cylinder => {
                            (p.x * p.x + p.y * p.y > 1.0, (0.0..=1.0).contains(&p.z))
                        }
                    }
                };
                let end = q.hit(&ray, 0.0).unwrap_or(20.0);
                if end < 20.0 {
                    hits += 1;
                    let s = q.surface(&ray, end);
                    assert!((s.point - ray.at(end)).length() < 1e-4 * s.extent);
                }
                // No crossing of the surface before `end`.
                let steps = 400;
                let mut before = inside(1e-4);
                for k in 1..steps {
                    let t = 1e-4 + (end - 2e-4) * k as f32 / steps as f32;
                    let now = inside(t);
                    assert!(
                        !(now.0 != before.0 && now.1 && before.1),
                        "{form:?}: crossed at {t} before the hit at {end}"
                    );
                    before = now;
                }
            }
            assert!(hits > 500, "{form:?}: only {hits} hits");
        }
    }

    #[test]
    fn samples_are_uniform_by_area_and_the_area_is_the_shapes() {
        let mut rng = Rng::new(3);
        // A disk stretched into an ellipse of semi-axes 3 and 1: its
        // area, and the share of samples beyond |x| > 1.5.
        let ellipse = placed(QuadricForm::Disk, &[TransformStep::Scale([3.0, 1.0, 1.0])]);
        assert!((ellipse.area() - 3.0 * std::f32::consts::PI).abs() < 1e-5);
        let n = 200_000;
        let far = (0..n)
            .filter(|_| ellipse.sample([rng.next_f32(), rng.next_f32()]).0.x.abs() > 1.5)
            .count() as f64
            / n as f64;
        // The caps |x| > a/2 of a circle: 1 − (2/π)(asin(1/2) + (1/2)√(3/4)).
        let expected = 1.0 - 2.0 / std::f64::consts::PI * (0.5f64.asin() + 0.5 * 0.75f64.sqrt());
        let sigma = (expected * (1.0 - expected) / n as f64).sqrt();
        assert!((far - expected).abs() < 4.0 * sigma, "{far} vs {expected}");
        // A turned round cylinder of radius 2, height 3.
        let steps = [
            TransformStep::Scale([2.0, 2.0, 3.0]),
            TransformStep::Rotate {
                axis: [1.0, 1.0, 0.0],
                degrees: 30.0,
            },
        ];
        let tube = placed(QuadricForm::Cylinder, &steps);
        assert!(tube.round());
        assert!((tube.area() - 12.0 * std::f32::consts::PI).abs() < 1e-4);
        assert!(!placed(QuadricForm::Cylinder, &turned()).round());
    }

    #[test]
    fn derivatives_follow_the_texture_coordinates() {
        for form in [QuadricForm::Disk, QuadricForm::Cylinder] {
            let q = placed(form, &turned());
            let (u, v, h) = (0.6, 0.3, 1e-3);
            let s = q.at([u, v]);
            let du = (q.at([u + h, v]).point - q.at([u - h, v]).point) / (2.0 * h as f32);
            let dv = (q.at([u, v + h]).point - q.at([u, v - h]).point) / (2.0 * h as f32);
            assert!((du - s.dpdu).length() < 2e-2 * s.dpdu.length(), "{form:?}");
            assert!((dv - s.dpdv).length() < 2e-2 * s.dpdv.length(), "{form:?}");
            // The normal is perpendicular to both.
            assert!(s.outward.dot(s.dpdu).abs() < 1e-5 * s.dpdu.length());
            assert!(s.outward.dot(s.dpdv).abs() < 1e-5 * s.dpdv.length());
        }
    }
}
