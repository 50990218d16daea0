//! A rectangle sampled by the solid angle it covers: Ureña, Fajardo and
//! King, "An Area-Preserving Parametrization for Spherical Rectangles"
//! (EGSR 2013). Every direction towards the rectangle is equally likely,
//! so that the density is 1 / Ω wherever the light is seen from, where
//! sampling its area gives a density that grows as the square of the
//! distance over the cosine, and noise where a rectangle is seen close up
//! or at a slant.
//!
//! Worked in f64: the solid angle is the sum of four angles less 2π, and in
//! f32 a small one loses most of its digits.

use crate::math::{Point3, Vec3};
use glam::DVec3;
use std::f64::consts::PI;

/// Solid angles below this are sampled by area: there the two densities
/// differ little, and even f64 leaves few digits of Ω (as pbrt-v4 does).
const MIN_SOLID_ANGLE: f64 = 3e-4;

/// A rectangle as seen from a point, ready to be sampled.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphericalRectangle {
    /// The point it is seen from.
    origin: DVec3,
    /// Unit axes along the edges, and the normal towards the point's side
    /// turned away (so that `z0` < 0).
    x: DVec3,
    y: DVec3,
    z: DVec3,
    /// The rectangle in that frame: x from x0 to x1, y from y0 to y1, at
    /// height z0 < 0.
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    /// The z components of the first and third edge planes' normals.
    b0: f64,
    b1: f64,
    /// 2π less the third and fourth inner angles.
    k: f64,
    /// The solid angle Ω it covers.
    solid_angle: f64,
}

impl SphericalRectangle {
    /// The rectangle of corner `corner` and perpendicular edges `u`, `v`,
    /// seen from `from`; `None` when it covers too small a solid angle to
    /// be sampled this way, or `from` lies in its plane.
    pub(super) fn new(corner: Point3, u: Vec3, v: Vec3, from: Point3) -> Option<Self> {
        let (u, v) = (u.as_dvec3(), v.as_dvec3());
        let (width, height) = (u.length(), v.length());
        let (x, y) = (u / width, v / height);
        let mut z = x.cross(y);
        let d = corner.as_dvec3() - from.as_dvec3();
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        if !(z0 < 0.0) {
            return None;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + width, y0 + height);
        // The z components of the inward normals of the four planes
        // through the point and an edge (the edges at y0, x1, y1, x0).
        let n0 = -y0 / (z0 * z0 + y0 * y0).sqrt();
        let n1 = x1 / (z0 * z0 + x1 * x1).sqrt();
        let n2 = y1 / (z0 * z0 + y1 * y1).sqrt();
        let n3 = -x0 / (z0 * z0 + x0 * x0).sqrt();
        let angle = |a: f64, b: f64| (-a * b).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        if !(solid_angle >= MIN_SOLID_ANGLE) {
            return None;
        }
        Some(SphericalRectangle {
            origin: from.as_dvec3(),
            x,
            y,
            z,
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0,
            b1: n2,
            k,
            solid_angle,
        })
    }

    /// The solid angle it covers: the density of [`Self::sample`] is its
    /// reciprocal.
    pub(super) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// The point of the rectangle along a direction drawn uniformly over
    /// the solid angle, from `[s, t]` uniform in the unit square.
    pub(super) fn sample(&self, [s, t]: [f32; 2]) -> Point3 {
        let (s, t) = (f64::from(s), f64::from(t));
        let Self {
            x0,
            x1,
            y0,
            y1,
            z0,
            b0,
            b1,
            ..
        } = *self;
        // The azimuth: the cut at x = xu that leaves s Ω to its left.
        let au = s * self.solid_angle + self.k;
        let fu = (au.cos() * b0 - b1) / au.sin();
        let cu = ((fu * fu + b0 * b0).sqrt().recip() * fu.signum()).clamp(-1.0, 1.0);
        let xu = (-(cu * z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(x0, x1);
        // The height along that cut, uniform in the sine of its elevation.
        let d = (xu * xu + z0 * z0).sqrt();
        let h0 = y0 / (d * d + y0 * y0).sqrt();
        let h1 = y1 / (d * d + y1 * y1).sqrt();
        let hv = h0 + t * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv2).sqrt()).clamp(y0, y1)
        } else {
            y1
        };
        let p = self.origin + xu * self.x + yv * self.y + z0 * self.z;
        p.as_vec3().into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The solid angle of a rectangle by the formula of Mazonka (2012) for
    /// a polygon, through the triangles' signed solid angles (Van
    /// Oosterom and Strackee 1983): an independent check of Ω.
    fn solid_angle_of(corners: [DVec3; 4]) -> f64 {
        let triangle = |a: DVec3, b: DVec3, c: DVec3| {
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c));
            let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * numerator.atan2(denominator)
        };
        (triangle(corners[0], corners[1], corners[2])
            + triangle(corners[0], corners[2], corners[3]))
        .abs()
    }

    fn corners(corner: Point3, u: Vec3, v: Vec3, from: Point3) -> [DVec3; 4] {
        let q = corner.as_dvec3() - from.as_dvec3();
        let (u, v) = (u.as_dvec3(), v.as_dvec3());
        [q, q + u, q + u + v, q + v]
    }

    /// Rectangles seen from points near and far, in front and behind,
    /// square-on and at a slant.
    fn cases() -> Vec<(Point3, Vec3, Vec3, Point3)> {
        let (corner, u, v) = (
            Vec3::new(-1.0, 2.0, 1.5),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(-0.3, 1.5, 0.6),
        );
        // Make v perpendicular to u.
        let v = v - u * (u.dot(v) / u.dot(u));
        vec![
            (corner, u, v, Vec3::new(0.0, 0.0, 0.0)),
            (corner, u, v, Vec3::new(0.3, 2.9, 3.0)),
            (corner, u, v, Vec3::new(0.1, 2.5, 0.2)),
            (corner, u, v, Vec3::new(5.0, -3.0, 1.0)),
            (
                Vec3::new(213.0, 554.0, 227.0),
                Vec3::new(130.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 105.0),
                Vec3::new(278.0, 0.0, 278.0),
            ),
            (
                Vec3::new(213.0, 554.0, 227.0),
                Vec3::new(130.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 105.0),
                Vec3::new(0.0, 500.0, 100.0),
            ),
        ]
    }

    #[test]
    fn its_solid_angle_agrees_with_an_independent_formula() {
        for (corner, u, v, from) in cases() {
            let r = SphericalRectangle::new(corner, u, v, from).unwrap_or_else(|| {
                panic!(
                    "from {from}: {}",
                    solid_angle_of(corners(corner, u, v, from))
                )
            });
            let expected = solid_angle_of(corners(corner, u, v, from));
            // Edges perpendicular only to f32's precision.
            assert!(
                (r.solid_angle() - expected).abs() <= 1e-6 * expected,
                "{} against {expected}",
                r.solid_angle()
            );
        }
    }

    /// The sampled points, binned on a grid over the rectangle, fall in
    /// each cell in proportion to the solid angle the cell covers (found
    /// by the independent formula): Pearson's χ² below what a correct
    /// sampler exceeds with probability 10⁻⁴, 10⁶ samples a case, cells
    /// expected to hold fewer than 5 pooled.
    #[test]
    fn points_are_uniform_in_solid_angle_chi_squared() {
        let n = 16;
        let samples = 1_000_000;
        let mut rng = Rng::new(7);
        for (corner, u, v, from) in cases() {
            let r = SphericalRectangle::new(corner, u, v, from).unwrap();
            let mut counts = vec![0u64; n * n];
            for _ in 0..samples {
                let p = r.sample(rng.next_2d());
                let d = (p - corner).as_dvec3();
                let a = d.dot(u.as_dvec3()) / u.as_dvec3().length_squared();
                let b = d.dot(v.as_dvec3()) / v.as_dvec3().length_squared();
                assert!((-1e-5..=1.0 + 1e-5).contains(&a) && (-1e-5..=1.0 + 1e-5).contains(&b));
                let i = ((a * n as f64) as usize).min(n - 1);
                let j = ((b * n as f64) as usize).min(n - 1);
                counts[i * n + j] += 1;
            }
            let mut expected = Vec::with_capacity(n * n);
            for i in 0..n {
                for j in 0..n {
                    let c = corner + (i as f32 / n as f32) * u + (j as f32 / n as f32) * v;
                    let omega = solid_angle_of(corners(c, u / n as f32, v / n as f32, from));
                    expected.push(omega / r.solid_angle() * samples as f64);
                }
            }
            let (chi2, dof) = crate::testing::chi_square(&counts, &expected);
            let bound = crate::testing::chi_square_bound(dof);
            assert!(
                chi2 < bound,
                "χ² {chi2} on {dof} degrees of freedom (bound {bound}) from {from}"
            );
        }
    }

    #[test]
    fn tiny_and_edge_on_rectangles_are_left_to_area_sampling() {
        let (corner, u, v) = (Vec3::ZERO, Vec3::X, Vec3::Z);
        assert!(SphericalRectangle::new(corner, u, v, Vec3::new(0.5, 0.0, 0.5)).is_none());
        assert!(SphericalRectangle::new(corner, u, v, Vec3::new(0.5, 100.0, 0.5)).is_none());
        assert!(SphericalRectangle::new(corner, u, v, Vec3::new(0.5, 10.0, 0.5)).is_some());
    }
}
