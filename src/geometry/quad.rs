//! Quads: parallelograms given by a corner Q and two edge vectors u and v,
//! as in *Ray Tracing: The Next Week*. A box is six of them.
//!
//! The ray meets the quad's plane n·P = D (n the unit normal of u × v) at
//! t = (D − n·A)/(n·B). The hit point's coordinates in the quad's own
//! frame, P − Q = αu + βv, come from w = (u × v)/|u × v|²:
//! α = w·((P − Q) × v), β = w·(u × (P − Q)); the quad holds the points with
//! α and β in [0, 1], and (α, β) is also its texture coordinate.

use crate::lanes::{Mask, Real};
use crate::math::{Interval, Point3, Vec3};
use crate::ray::{Ray, RayLanes};

/// Rays closer to parallel with the plane than this (|n·B| for a unit
/// direction) miss: the book's threshold.
const PARALLEL: f32 = 1e-8;

/// How much a quad grows on every side as it is traced, relative to the
/// size of its coordinates (see [`Quad::grown`]).
const GROWTH: f32 = 1.0 / (1u32 << 20) as f32;

/// A parallelogram with corners Q, Q + u, Q + u + v, Q + v.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// The corner Q.
    pub corner: Point3,
    /// The first edge u.
    pub u: Vec3,
    /// The second edge v.
    pub v: Vec3,
    /// Unit normal: along u × v, or against it for a quad placed by a
    /// mirroring transform ([`Quad::flipped`]). Its side is the outside.
    pub normal: Vec3,
    /// (u × v)/|u × v|², which turns a point of the plane into (α, β).
    pub w: Vec3,
    /// D = n·Q: the plane's offset.
    pub d: f32,
    /// 1/|u × v| times |v| and |u|: how far a step of 1 in α and in β
    /// takes a point from an edge, inverted (see [`Quad::within`]).
    pub inverse_widths: [f32; 2],
}

/// Edges closer to parallel than this (the sine of their angle) make no
/// quad: their cross product, the quad's normal, is then as much rounding
/// as direction.
const PARALLEL_EDGES: f32 = 1.0 / (1u32 << 20) as f32;

impl Quad {
    /// The quad at `corner` with edges `u` and `v`, or `None` when the edges
    /// are parallel or zero (the quad has no area; see
    /// [`Quad::parallel`]) or too small for its `f32` arithmetic (|u × v|
    /// below about 1e-38).
    pub fn new(corner: Point3, u: Vec3, v: Vec3) -> Option<Quad> {
        if Quad::parallel(u, v) {
            return None;
        }
        let n = u.cross(v);
        let n2 = n.length_squared();
        // u × v in f64, where its square neither overflows nor underflows.
        let n64 = u.as_dvec3().cross(v.as_dvec3());
        let (normal, w, length) = if n2.is_normal() {
            let length = n2.sqrt();
            (n / length, n / n2, length)
        } else {
            // |u × v|² overflows (edges of 6e9) or underflows: worked out
            // in f64, where it does not.
            let length = n64.length();
            let normal = n64 / length;
            (
                Vec3::from(normal.as_vec3()),
                Vec3::from((normal / length).as_vec3()),
                length as f32,
            )
        };
        if !(w.is_finite() && length.is_finite() && w != Vec3::ZERO) {
            return None;
        }
        // Where the plane passes much nearer the origin than the corner
        // lies (a turned floor of 1e9 under a camera at the origin), the
        // terms of n·Q cancel, and in f32 what is left is their rounding
        // (to 16 times nearer, that rounding is within about 2⁻²⁰ of D).
        // There D is the distance of the true plane (of u × v in f64) from
        // the origin: the plane of the rounded normal then passes through
        // the true plane's point nearest the origin, where the rays are,
        // and strays from it only in proportion to the distance from there.
        let d = normal.dot(corner);
        let terms = (normal * corner).abs().element_sum();
        let d = if terms > 16.0 * d.abs() {
            (n64.dot(corner.as_dvec3()) / n64.length()) as f32
        } else {
            d
        };
        Some(Quad {
            corner,
            u,
            v,
            normal,
            w,
            d,
            inverse_widths: [v.length() / length, u.length() / length],
        })
    }

    /// Whether edges `u` and `v` are zero or parallel (or so nearly that
    /// their sine is below 2⁻²⁰): relative to their lengths, so that a
    /// quad is one at any size.
    pub fn parallel(u: Vec3, v: Vec3) -> bool {
        // In f64, where neither the product of the lengths nor the cross
        // product's square overflows or underflows.
        let (u, v) = (u.as_dvec3(), v.as_dvec3());
        let sine = u.cross(v).length() / (u.length() * v.length());
        !(sine > f64::from(PARALLEL_EDGES))
    }

    /// The same parallelogram with its outside on the other side: what a
    /// mirroring transform makes of it, which reverses u × v relative to
    /// the surface's true outside. Its (α, β) coordinates are unchanged.
    pub fn flipped(self) -> Quad {
        Quad {
            normal: -self.normal,
            d: -self.d,
            ..self
        }
    }

    /// The quad as it is traced: grown on every side by a bound on the
    /// rounding of its corners and edges (2⁻²⁰ of their size). Two quads
    /// placed to share an edge (two faces of a turned box) are each
    /// rounded apart, and a ray could pass between them; grown, they
    /// overlap instead. The plane is kept to the bit, so that every hit
    /// distance is the quad's own; only hits this close outside an edge
    /// are added.
    pub fn grown(&self) -> Quad {
        let (min, max) = self.bounds();
        let size = min.abs().max(max.abs()).max_element()
            + self.u.abs().max_element()
            + self.v.abs().max_element();
        // The margin in α is margin·|v|/|u × v|, and |u × v| = 1/|w|.
        let scale = size * GROWTH * self.w.length();
        let (da, db) = (scale * self.v.length(), scale * self.u.length());
        let (ka, kb) = (1.0 + 2.0 * da, 1.0 + 2.0 * db);
        let [wa, wb] = self.inverse_widths;
        Quad {
            corner: self.corner - da * self.u - db * self.v,
            u: ka * self.u,
            v: kb * self.v,
            w: self.w / (ka * kb),
            inverse_widths: [wa / ka, wb / kb],
            ..*self
        }
    }

    /// Whether its outside is against u × v (see [`Quad::flipped`]).
    pub fn is_flipped(&self) -> bool {
        self.normal.dot(self.u.cross(self.v)) < 0.0
    }

    /// The axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (Point3, Point3) {
        let corners = [
            self.corner,
            self.corner + self.u,
            self.corner + self.v,
            self.corner + self.u + self.v,
        ];
        let min = corners.iter().fold(corners[0], |m, &c| m.min(c));
        let max = corners.iter().fold(corners[0], |m, &c| m.max(c));
        (min, max)
    }

    /// The distance along unit `ray` to the quad, if it is hit strictly
    /// inside `interval`.
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<f32> {
        let (t, valid) = intersect(&RayLanes::splat(ray, interval.min), &self.lanes());
        (valid && t < interval.max).then_some(t)
    }

    /// The quad's (α, β) coordinates of a point of its plane.
    pub fn coordinates(&self, point: Point3) -> (f32, f32) {
        let p = point - self.corner;
        (self.w.dot(p.cross(self.v)), self.w.dot(self.u.cross(p)))
    }

    /// `point`, a point of the quad's plane at coordinates `(alpha,
    /// beta)`, moved into the quad (from outside too, as it is traced
    /// grown) until it is at least `margin` from every edge (onto the
    /// middle line where the quad is narrower than twice that), with its
    /// coordinates there. A hit a rounding away from an
    /// edge may lie on the plane of a wall meeting the quad there, or past
    /// it, and a ray leaving from it would not meet that wall.
    #[inline]
    pub fn within(
        &self,
        point: Point3,
        (alpha, beta): (f32, f32),
        margin: f32,
    ) -> (Point3, [f32; 2]) {
        // A point at α is α·|u × v|/|v| from the edges along v: the margin
        // is margin·|v|/|u × v| in α.
        let [wa, wb] = self.inverse_widths;
        let (ma, mb) = ((margin * wa).min(0.5), (margin * wb).min(0.5));
        // Outside too: the quad is traced grown (see `Quad::grown`).
        let inside = |x: f32, m: f32| m <= x && x <= 1.0 - m;
        if inside(alpha, ma) && inside(beta, mb) {
            return (point, [alpha, beta]);
        }
        let (a, b) = (alpha.clamp(ma, 1.0 - ma), beta.clamp(mb, 1.0 - mb));
        (point + (a - alpha) * self.u + (b - beta) * self.v, [a, b])
    }

    /// The quad as one lane of [`intersect`].
    pub fn lanes(&self) -> QuadLanes<f32> {
        QuadLanes {
            corner: self.corner.to_array(),
            u: self.u.to_array(),
            v: self.v.to_array(),
            normal: self.normal.to_array(),
            w: self.w.to_array(),
            d: self.d,
        }
    }
}

/// Quads in lanes (see [`Quad`] for the fields). Unused lanes are NaN,
/// which no ray hits.
#[derive(Clone, Copy, Debug)]
pub struct QuadLanes<R> {
    /// Corner Q.
    pub corner: [R; 3],
    /// Edge u.
    pub u: [R; 3],
    /// Edge v.
    pub v: [R; 3],
    /// Unit normal.
    pub normal: [R; 3],
    /// (u × v)/|u × v|².
    pub w: [R; 3],
    /// n·Q.
    pub d: R,
}

#[inline(always)]
fn dot<R: Real>(a: &[R; 3], b: &[R; 3]) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross<R: Real>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The ray–quad test, written once for any number of lanes: for each lane
/// the distance to the quad and whether the ray hits it beyond `t_min`. The
/// caller compares the distance with the far end of its interval.
#[inline(always)]
pub fn intersect<R: Real>(ray: &RayLanes<R>, quad: &QuadLanes<R>) -> (R, R::Mask) {
    let denom = dot(&quad.normal, &ray.direction);
    let eps = R::splat(PARALLEL);
    let crossing = eps.le(denom) | denom.le(-eps);
    let t = (quad.d - dot(&quad.normal, &ray.origin)) / denom;
    let ahead = crossing & ray.t_min.lt(t);
    if !ahead.any() {
        return (t, ahead);
    }
    let at = |k: usize| ray.origin[k] + t * ray.direction[k] - quad.corner[k];
    let p = [at(0), at(1), at(2)];
    let alpha = dot(&quad.w, &cross(&p, &quad.v));
    let beta = dot(&quad.w, &cross(&quad.u, &p));
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let inside = zero.le(alpha) & alpha.le(one) & zero.le(beta) & beta.le(one);
    (t, ahead & inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn floor() -> Quad {
        Quad::new(
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
        )
        .expect("a real quad")
    }

    #[test]
    fn hits_inside_at_the_right_distance_and_coordinates() {
        let q = floor();
        let ray = Ray::new(Vec3::new(0.5, 3.0, 0.0), -Vec3::Y);
        assert_eq!(q.hit(&ray, Interval::new(0.001, f32::INFINITY)), Some(3.0));
        assert_eq!(q.coordinates(ray.at(3.0)), (0.75, 0.5));
        // From below (the back face) too.
        let up = Ray::new(Vec3::new(0.5, -2.0, 0.0), Vec3::Y);
        assert_eq!(q.hit(&up, Interval::new(0.001, f32::INFINITY)), Some(2.0));
        let slanted_dir = Vec3::new(1.0, -1.0, 0.0).normalize();
        let slanted = Ray::new(Vec3::new(-1.0, 1.0, 0.0), slanted_dir);
        let t = q
            .hit(&slanted, Interval::new(0.0, f32::INFINITY))
            .expect("hits");
        assert!((t - 2f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn misses_outside_edges_parallel_and_interval() {
        let q = floor();
        for (x, z) in [
            (1.01, 0.0),
            (-1.01, 0.0),
            (0.0, 1.01),
            (0.0, -1.01),
            (5.0, 5.0),
        ] {
            let ray = Ray::new(Vec3::new(x, 1.0, z), -Vec3::Y);
            assert_eq!(
                q.hit(&ray, Interval::new(0.0, f32::INFINITY)),
                None,
                "({x}, {z})"
            );
        }
        // On the edge x = 1: inside (the interval is closed).
        let edge = Ray::new(Vec3::new(1.0, 1.0, 0.0), -Vec3::Y);
        assert_eq!(q.hit(&edge, Interval::new(0.0, f32::INFINITY)), Some(1.0));
        let parallel = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::X);
        assert_eq!(q.hit(&parallel, Interval::new(0.0, f32::INFINITY)), None);
        let ray = Ray::new(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y);
        assert_eq!(q.hit(&ray, Interval::new(0.0, 2.5)), None);
        assert_eq!(q.hit(&ray, Interval::new(3.0, 5.0)), None);
    }

    #[test]
    fn grown_quads_keep_their_plane_and_reach_past_their_edges() {
        let q = Quad::new(
            Vec3::new(0.3, 1.7, -2.1),
            Vec3::new(1.1, 0.4, 0.2),
            Vec3::new(-0.3, 0.9, 0.6),
        )
        .expect("a real quad");
        let g = q.grown();
        assert_eq!((g.normal, g.d), (q.normal, q.d));
        // Just outside the edge α = 1, by far less than the growth.
        let p = q.corner + (1.0 + 1e-6) * q.u + 0.5 * q.v;
        let ray = Ray::new(p + q.normal, -q.normal);
        let all = Interval::new(0.0, f32::INFINITY);
        assert_eq!(q.hit(&ray, all), None);
        assert!(g.hit(&ray, all).is_some());
        // And not much further.
        let far = q.corner + 1.001 * q.u + 0.5 * q.v;
        assert_eq!(g.hit(&Ray::new(far + q.normal, -q.normal), all), None);
    }

    #[test]
    fn points_at_an_edge_are_moved_in_by_the_margin() {
        let q = floor();
        let margin = 1e-3;
        // (α, β) = (1, 0.25): on the edge x = 1.
        let edge = Vec3::new(1.0, 0.0, -0.5);
        let (p, [a, b]) = q.within(edge, q.coordinates(edge), margin);
        assert!((1.0 - p.x - margin).abs() < 1e-6, "{p}");
        assert_eq!((p.y, p.z), (0.0, -0.5));
        assert_eq!(q.coordinates(p), (a, b));
        // Outside (a hit on the grown quad) too.
        let outside = Vec3::new(-1.0 - 1e-5, 0.0, 0.0);
        let (p, _) = q.within(outside, q.coordinates(outside), margin);
        assert!((p.x + 1.0 - margin).abs() < 1e-6, "{p}");
        // Inside the margin, nothing moves; without one, nothing inside.
        let inner = Vec3::new(0.3, 0.0, 0.2);
        assert_eq!(q.within(inner, q.coordinates(inner), margin).0, inner);
        assert_eq!(q.within(edge, q.coordinates(edge), 0.0).0, edge);
    }

    #[test]
    fn parallel_or_zero_edges_make_no_quad() {
        assert!(Quad::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X).is_none());
        assert!(Quad::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y).is_none());
        assert!(Quad::new(Vec3::ZERO, Vec3::X, Vec3::Y).is_some());
        // Nearly parallel: the cross product is rounding.
        let nearly = Vec3::new(1.0, 1e-7, 0.0);
        assert!(Quad::new(Vec3::ZERO, Vec3::X, nearly).is_none());
    }

    #[test]
    fn perpendicular_edges_make_a_quad_at_any_size() {
        // |u × v|² overflows f32 from edges of about 4e9.
        for size in [1e-3f32, 1.0, 6e9, 1e12, 1e18] {
            let q = Quad::new(
                Vec3::new(-size, 0.0, -size),
                2.0 * size * Vec3::Z,
                2.0 * size * Vec3::X,
            )
            .unwrap_or_else(|| panic!("no quad of size {size}"));
            assert_eq!(q.normal, Vec3::Y, "size {size}");
            let ray = Ray::new(Vec3::new(0.3 * size, 1.0, 0.2 * size), -Vec3::Y);
            assert_eq!(
                q.hit(&ray, Interval::new(0.0, f32::INFINITY)),
                Some(1.0),
                "size {size}"
            );
            assert_eq!(
                q.coordinates(Vec3::new(-size, 0.0, size)),
                (1.0, 0.0),
                "size {size}"
            );
        }
    }
}
