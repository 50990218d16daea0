//! Triangles, intersected watertight.
//!
//! The test is that of Woop, Benthin and Wald, *Watertight Ray/Triangle
//! Intersection* (JCGT 2013). The ray is made the z axis of a sheared frame:
//! its axes are permuted so that z is the direction's largest component, and
//! the vertices, taken relative to the origin, are sheared so that the ray
//! becomes (0, 0, 1). In that frame the three 2-D edge functions tell on
//! which side of each edge the ray passes.
//!
//! Two things make it watertight. The projected vertices depend only on the
//! vertex and the ray, so a vertex shared by two triangles projects to the
//! same bits in both, and the edge function of a shared edge is computed from
//! the same numbers in both, with its sign exactly reversed (IEEE products
//! commute and a − b = −(b − a)). And rounding is monotonic, so a rounded
//! edge function is never of the wrong sign, only zero when it should not be;
//! zeros are recomputed in `f64`, where the products of `f32` values are
//! exact and the sign is that of the exact value.
//!
//! A ray passing exactly through an edge or a vertex has exactly-zero edge
//! functions, and the triangles around it would all claim it. A tie rule
//! decides, as rasterisers do with their top-left rule: a zero edge counts
//! as inside only when its projected direction, reversed for a back-facing
//! triangle, lies in the half-open half-plane (y > 0) ∪ (y = 0, x < 0).
//! Of two triangles sharing an edge the directions are opposite, so exactly
//! one claims the edge; around a vertex the claimed directions turn through
//! the half-plane's boundary exactly once, so exactly one triangle of the fan
//! claims the vertex.

use crate::lanes::{Mask, Real};
use crate::math::{Interval, Point3, Vec3};
use crate::ray::Ray;
use glam::DVec3;

/// A triangle given by its three vertices, counter-clockwise seen from the
/// side its geometric normal (b − a) × (c − a) points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The vertices a, b, c.
    pub vertices: [Point3; 3],
}

impl Triangle {
    /// Creates a triangle.
    pub fn new(a: Point3, b: Point3, c: Point3) -> Self {
        Triangle {
            vertices: [a, b, c],
        }
    }

    /// The axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (Point3, Point3) {
        let [a, b, c] = self.vertices;
        (a.min(b).min(c), a.max(b).max(c))
    }

    /// (b − a) × (c − a): perpendicular to the triangle, twice its area long.
    pub fn area_normal(&self) -> Vec3 {
        let [a, b, c] = self.vertices;
        (b - a).cross(c - a)
    }

    /// The distance along `ray` (unit or not) to the triangle, if it is hit
    /// strictly inside `interval`.
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<f32> {
        let axes = TriangleRay::axes_of(ray.direction);
        let r = TriangleRay::new(ray, axes, interval.min);
        let (t, valid) = intersect(&r, &self.lanes(&axes));
        (valid && t < interval.max).then_some(t)
    }

    /// The distance along `ray` (unit or not) to the triangle's plane,
    /// worked out in `f64` (see `plane_distance`); `None` when the ray
    /// runs along the plane.
    pub fn plane_distance(&self, ray: &Ray) -> Option<f32> {
        let t = plane_distance(
            ray.origin().to_array(),
            ray.direction.to_array().map(f64::from),
            self.vertices.map(|v| v.to_array()),
        )? as f32;
        t.is_finite().then_some(t)
    }

    /// The triangle as one lane of [`intersect`], in the ray's axes.
    pub fn lanes(&self, axes: &[usize; 3]) -> TriangleLanes<f32> {
        TriangleLanes {
            vertices: self.vertices.map(|v| axes.map(|k| v[k])),
        }
    }
}

/// A ray prepared for the triangle test in its own axes (kx, ky, kz), see
/// [`TriangleRay::axes_of`]: the origin permuted and the shear.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay<R> {
    /// The origin's coordinates along kx, ky, kz.
    pub origin: [R; 3],
    /// (dx/dz, dy/dz, 1/dz) in the permuted axes.
    pub shear: [R; 3],
    /// Hits at or before this distance are not counted.
    pub t_min: R,
    /// The origin's squared length: how far from the world's origin the
    /// ray's rounding is measured (see [`intersect`]).
    pub origin2: R,
}

impl TriangleRay<f32> {
    /// Prepares `ray` in its axes `axes` (from [`TriangleRay::axes_of`]).
    #[inline(always)]
    pub fn new(ray: &Ray, axes: [usize; 3], t_min: f32) -> Self {
        let d = axes.map(|k| ray.direction[k]);
        TriangleRay {
            origin: axes.map(|k| ray.origin()[k]),
            shear: [d[0] / d[2], d[1] / d[2], 1.0 / d[2]],
            t_min,
            origin2: ray.origin().length_squared(),
        }
    }

    /// The permutation (kx, ky, kz) for direction `d`: kz is the axis of the
    /// largest component (the first on a tie), kx and ky follow it cyclically.
    #[inline(always)]
    pub fn axes_of(d: Vec3) -> [usize; 3] {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        [(kz + 1) % 3, (kz + 2) % 3, kz]
    }
}

/// Triangles in lanes, each vertex's coordinates in a ray's permuted axes
/// (kx, ky, kz).
#[derive(Clone, Copy, Debug)]
pub struct TriangleLanes<R> {
    /// Vertices a, b, c.
    pub vertices: [[R; 3]; 3],
}

/// The watertight ray–triangle test, written once for any number of lanes:
/// for each lane the distance to the triangle and whether the ray hits it
/// beyond `t_min` (see the module documentation). The caller compares the
/// distance with the far end of its interval. Back faces are hit too.
#[inline(always)]
pub fn intersect<R: Real>(ray: &TriangleRay<R>, tri: &TriangleLanes<R>) -> (R, R::Mask) {
    let [sx, sy, sz] = ray.shear;
    let project = |v: &[R; 3]| {
        let x = v[0] - ray.origin[0];
        let y = v[1] - ray.origin[1];
        let z = v[2] - ray.origin[2];
        [x - sx * z, y - sy * z, sz * z]
    };
    let [a, b, c] = [
        project(&tri.vertices[0]),
        project(&tri.vertices[1]),
        project(&tri.vertices[2]),
    ];
    // Edge functions of b→c, c→a and a→b at the ray (the frame's origin).
    let u = c[0] * b[1] - c[1] * b[0];
    let v = a[0] * c[1] - a[1] * c[0];
    let w = b[0] * a[1] - b[1] * a[0];
    let zero = R::splat(0.0);
    // NaN lanes (unused lanes of a packet) are neither.
    let non_negative = zero.le(u) & zero.le(v) & zero.le(w);
    let non_positive = u.le(zero) & v.le(zero) & w.le(zero);
    let inside = non_negative | non_positive;
    if !inside.any() {
        return (zero, inside);
    }
    let on_edge = inside & (u.eq(zero) | v.eq(zero) | w.eq(zero));
    let det = u + v + w;
    let mut t = (u * a[2] + v * b[2] + w * c[2]) / det;
    let mut hit = inside & !on_edge;
    if on_edge.any() {
        for lane in 0..R::LANES {
            if on_edge.lane(lane) {
                let pick = |p: &[R; 3]| [p[0].lane(lane), p[1].lane(lane), p[2].lane(lane)];
                let exact = exact_edges(pick(&a), pick(&b), pick(&c));
                hit = hit.with_lane(lane, exact.is_some());
                t = t.with_lane(lane, exact.unwrap_or(0.0));
            }
        }
    }
    // The distance is a weighted mean of the vertices' distances along z,
    // and is off by a few roundings of the farthest: where a vertex lies
    // much farther along the ray than the hit and the ray's origin are
    // from the world's origin (a large floor seen from near it), that is
    // more than the rounding of the ray itself, the hit may even fall
    // behind the ray, and it is worked out again in f64. Sure where
    // z² ≤ REACH²·(|o|² + t²) for every vertex, and t is finite (the
    // products overflow beyond about 1e12).
    let tt = t * t;
    let bound = R::splat(REACH * REACH) * (ray.origin2 + tt);
    let near = |z: R| (z * z).le(bound);
    let sure = near(a[2]) & near(b[2]) & near(c[2]) & tt.lt(R::splat(f32::INFINITY));
    let unsure = hit & !sure;
    if unsure.any() {
        t = precise_lanes(ray, tri, unsure, t);
    }
    (t, hit & ray.t_min.lt(t))
}

/// `t` with the lanes of `unsure` replaced by their distances worked out
/// in f64 ([`precise_distance`]).
#[cold]
#[inline(never)]
fn precise_lanes<R: Real>(
    ray: &TriangleRay<R>,
    tri: &TriangleLanes<R>,
    unsure: R::Mask,
    mut t: R,
) -> R {
    for lane in 0..R::LANES {
        if unsure.lane(lane) {
            let pick = |p: &[R; 3]| [p[0].lane(lane), p[1].lane(lane), p[2].lane(lane)];
            let [p, q, r] = &tri.vertices;
            let precise = precise_distance(
                pick(&ray.origin),
                pick(&ray.shear),
                [pick(p), pick(q), pick(r)],
            );
            t = t.with_lane(lane, precise.unwrap_or(t.lane(lane)));
        }
    }
    t
}

/// How much farther along the ray than the ray's origin and the hit are
/// from the world's origin a triangle's vertices may lie before the hit's
/// distance is worked out again in `f64`: the `f32` distance is off by
/// about 8 roundings (2⁻²⁰) of the farthest vertex's, so by about 2⁻¹⁸ of
/// the ray's size, as its hit point is rounded.
const REACH: f32 = 4.0;

/// The distance along the ray to the plane of the triangle `vertices`
/// (in the ray's axes), worked out in `f64` (see [`plane_distance`]).
/// `origin` and `shear` are the prepared ray's ([`TriangleRay`]).
#[cold]
#[inline(never)]
fn precise_distance(origin: [f32; 3], shear: [f32; 3], vertices: [[f32; 3]; 3]) -> Option<f32> {
    let [sx, sy, sz] = shear.map(f64::from);
    // The direction scaled to 1 along z, whose distances are the z
    // distances: the ray's are 1/dz (`sz`) times those.
    let t = plane_distance(origin, [sx, sy, 1.0], vertices)? * sz;
    let t = t as f32;
    t.is_finite().then_some(t)
}

/// The distance from `origin` along `direction` to the plane of the
/// triangle `vertices`, in `f64`, as n·(a − o)/(n·d) with n the normal
/// (b − a) × (c − a): exact where the triangle is axis-aligned (a floor),
/// and otherwise off by about 2⁻⁵³ of the vertices' distance from the
/// origin, where the `f32` test's weighted mean of the vertices' distances
/// can keep nothing of a hit near the origin of a ray. `None` when the ray
/// runs along the plane.
pub(crate) fn plane_distance(
    origin: [f32; 3],
    direction: [f64; 3],
    vertices: [[f32; 3]; 3],
) -> Option<f64> {
    let [a, b, c] = vertices.map(|v| DVec3::from_array(v.map(f64::from)));
    let o = DVec3::from_array(origin.map(f64::from));
    let n = (b - a).cross(c - a);
    let along = n.dot(DVec3::from_array(direction));
    if along == 0.0 {
        return None;
    }
    Some(n.dot(a - o) / along)
}

/// The test of one ray whose `f32` edge functions have a zero: they are
/// recomputed exactly in `f64` and exact zeros are settled by the tie rule.
/// `a`, `b`, `c` are the projected vertices; returns the distance of a hit.
#[cold]
#[inline(never)]
fn exact_edges(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Option<f32> {
    let f = |p: [f32; 3]| p.map(f64::from);
    let (pa, pb, pc) = (f(a), f(b), f(c));
    let edge = |p: [f64; 3], q: [f64; 3]| q[0] * p[1] - q[1] * p[0];
    let (u, v, w) = (edge(pb, pc), edge(pc, pa), edge(pa, pb));
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    // The tie rule on a zero edge from p to q (see the module documentation).
    let claims = |e: f64, p: [f32; 3], q: [f32; 3]| {
        if e != 0.0 {
            return true;
        }
        let (mut dx, mut dy) = (q[0] - p[0], q[1] - p[1]);
        if det < 0.0 {
            (dx, dy) = (-dx, -dy);
        }
        dy > 0.0 || (dy == 0.0 && dx < 0.0)
    };
    if !(claims(u, b, c) && claims(v, c, a) && claims(w, a, b)) {
        return None;
    }
    Some(((u * pa[2] + v * pb[2] + w * pc[2]) / det) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_right_triangle() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)
    }

    #[test]
    fn ray_through_the_inside_hits_at_the_right_distance() {
        let t = unit_right_triangle();
        let ray = Ray::new(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z);
        assert_eq!(t.hit(&ray, Interval::new(0.0, f32::INFINITY)), Some(2.0));
        // From behind: back faces are hit too.
        let back = Ray::new(Vec3::new(0.25, 0.25, -3.0), Vec3::Z);
        assert_eq!(t.hit(&back, Interval::new(0.0, f32::INFINITY)), Some(3.0));
        // A slanted, non-unit direction: t is in units of the direction.
        let slanted = Ray::new(Vec3::new(0.0, 0.0, 4.0), Vec3::new(0.25, 0.25, -4.0));
        let got = t
            .hit(&slanted, Interval::new(0.0, f32::INFINITY))
            .expect("hits");
        assert!((got - 1.0).abs() < 1e-6, "t = {got}");
    }

    #[test]
    fn rays_beside_it_miss() {
        let t = unit_right_triangle();
        for (x, y) in [(0.6, 0.6), (-0.1, 0.5), (0.5, -0.1), (1.1, 0.0), (2.0, 2.0)] {
            let ray = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
            assert_eq!(
                t.hit(&ray, Interval::new(0.0, f32::INFINITY)),
                None,
                "at ({x}, {y})"
            );
        }
    }

    #[test]
    fn parallel_rays_and_the_interval() {
        let t = unit_right_triangle();
        // In the triangle's plane, and parallel above it.
        let inside_plane = Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X);
        assert_eq!(
            t.hit(&inside_plane, Interval::new(0.0, f32::INFINITY)),
            None
        );
        let above = Ray::new(Vec3::new(-1.0, 0.25, 1.0), Vec3::X);
        assert_eq!(t.hit(&above, Interval::new(0.0, f32::INFINITY)), None);
        // Behind the origin, or beyond t_max, or at exactly t_min.
        let ray = Ray::new(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z);
        assert_eq!(t.hit(&ray, Interval::new(0.0, 1.5)), None);
        assert_eq!(t.hit(&ray, Interval::new(2.0, 5.0)), None);
        assert_eq!(t.hit(&ray, Interval::new(2.5, 5.0)), None);
        let away = Ray::new(Vec3::new(0.25, 0.25, 2.0), Vec3::Z);
        assert_eq!(t.hit(&away, Interval::new(0.0, f32::INFINITY)), None);
    }

    #[test]
    fn a_shared_edge_belongs_to_exactly_one_of_its_triangles() {
        // Two triangles of the unit square share the diagonal a→c / c→a.
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        let first = Triangle::new(a, b, c);
        let second = Triangle::new(a, c, d);
        for k in 1..40 {
            let s = k as f32 / 40.0;
            for dir in [-Vec3::Z, Vec3::Z] {
                let ray = Ray::new(Vec3::new(s, s, -dir.z), dir);
                let hits = [first, second]
                    .iter()
                    .filter(|t| t.hit(&ray, Interval::new(0.0, f32::INFINITY)).is_some())
                    .count();
                assert_eq!(hits, 1, "diagonal point {s}, direction {dir}");
            }
        }
    }

    #[test]
    fn a_vertex_belongs_to_exactly_one_triangle_of_its_fan() {
        // Eight triangles around the origin, in both windings.
        let ring: Vec<Vec3> = (0..8)
            .map(|i| {
                let a = i as f32 * std::f32::consts::FRAC_PI_4 + 0.1;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        for flip in [false, true] {
            let fan: Vec<Triangle> = (0..8)
                .map(|i| {
                    let (p, q) = (ring[i], ring[(i + 1) % 8]);
                    if flip {
                        Triangle::new(Vec3::ZERO, q, p)
                    } else {
                        Triangle::new(Vec3::ZERO, p, q)
                    }
                })
                .collect();
            for dir in [-Vec3::Z, Vec3::Z] {
                let ray = Ray::new(-dir, dir);
                let hits = fan
                    .iter()
                    .filter(|t| t.hit(&ray, Interval::new(0.0, f32::INFINITY)).is_some())
                    .count();
                assert_eq!(hits, 1, "flip {flip}, direction {dir}");
            }
        }
    }
}
