//! Participating media: fog and smoke of constant density inside a convex
//! boundary (a sphere or a box, placed by a transform), scattering light
//! equally in every direction, as the constant media of *The Next Week*.
//!
//! A ray crossing a medium of density σ travels a distance d before it meets
//! a particle with probability density σ e^{−σd}: [`Medium::sample_distance`]
//! draws d by inverting that law, and a ray that gets through untouched
//! does so with probability e^{−σℓ} over a length ℓ inside
//! ([`Medium::transmittance`]), which is what a shadow ray carries. The
//! boundary is not a surface: it neither reflects nor blocks; a medium that
//! should sit behind glass is given the glass as a separate object.

use crate::geometry::transform::Transform;
use crate::math::{Color, Point3};
use crate::ray::Ray;
use std::f32::consts::PI;

/// The convex region a medium fills, in its own space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Boundary {
    /// A ball.
    Sphere {
        /// Its centre.
        center: Point3,
        /// Its radius (> 0).
        radius: f32,
    },
    /// An axis-aligned box.
    Box {
        /// The lowest corner.
        min: Point3,
        /// The highest corner.
        max: Point3,
    },
}

impl Boundary {
    /// The parameters `(t0, t1)` between which the line `origin + t·direction`
    /// (any direction length) is inside, if it ever is.
    pub(crate) fn span(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (o, d) = (ray.origin(), ray.direction);
        match *self {
            Boundary::Sphere { center, radius } => {
                let f = o - center;
                let a = d.length_squared();
                let h = f.dot(d);
                // The squared distance from the centre to the line, computed
                // from the perpendicular part (stable for large spheres).
                let perpendicular = f - (h / a) * d;
                let discriminant = a * (radius * radius - perpendicular.length_squared());
                if !(discriminant > 0.0) {
                    return None;
                }
                let root = discriminant.sqrt();
                Some(((-h - root) / a, (-h + root) / a))
            }
            Boundary::Box { min, max } => {
                let inverse = d.recip();
                let (a, b) = ((min - o) * inverse, (max - o) * inverse);
                let (near, far) = (a.min(b), a.max(b));
                let (t0, t1) = (near.max_element(), far.min_element());
                (t0 <= t1).then_some((t0, t1))
            }
        }
    }
}

/// A homogeneous medium with an isotropic phase function.
#[derive(Clone, Debug)]
pub struct Medium {
    boundary: Boundary,
    /// Boundary space to world.
    transform: Transform,
    /// Density σ: the chance per unit length of meeting a particle.
    density: f32,
    /// The fraction of light a particle scatters (the rest it absorbs).
    pub albedo: Color,
}

/// The density per unit solid angle of the isotropic phase function: every
/// direction alike, 1/4π.
pub const ISOTROPIC_PDF: f32 = 1.0 / (4.0 * PI);

impl Medium {
    /// A medium of `density` (> 0) and `albedo` filling `boundary` placed by
    /// `transform`.
    pub fn new(boundary: Boundary, transform: Transform, density: f32, albedo: Color) -> Self {
        Medium {
            boundary,
            transform,
            density,
            albedo,
        }
    }

    /// The world distances `(start, end)` along the unit-direction `ray`
    /// that lie inside the medium and within `[0, t_max]`, if any length
    /// does.
    #[inline]
    pub fn span(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        let (object, scale) = self.transform.to_object_ray(ray);
        let (t0, t1) = self.boundary.span(&object)?;
        let (start, end) = ((t0 / scale).max(0.0), (t1 / scale).min(t_max));
        (start < end).then_some((start, end))
    }

    /// Where along `ray`, before `t_max`, it meets a particle, for a
    /// uniform number `u` in [0, 1): the distance drawn from the
    /// exponential law past the entry point, if that falls inside.
    #[inline]
    pub fn sample_distance(&self, ray: &Ray, t_max: f32, u: f32) -> Option<f32> {
        self.distance_within(self.span(ray, t_max)?, u)
    }

    /// [`sample_distance`](Self::sample_distance) for a ray whose
    /// [`span`](Self::span) is already known.
    #[inline]
    pub fn distance_within(&self, (start, end): (f32, f32), u: f32) -> Option<f32> {
        let t = start - (1.0 - u).ln() / self.density;
        (t < end).then_some(t)
    }

    /// The fraction of light that crosses the medium along `ray` between 0
    /// and `t_max` without meeting a particle: e^{−σℓ}.
    #[inline]
    pub fn transmittance(&self, ray: &Ray, t_max: f32) -> f32 {
        self.span(ray, t_max)
            .map_or(1.0, |(start, end)| (-self.density * (end - start)).exp())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::transform::TransformStep;
    use crate::math::Vec3;
    use crate::rng::Rng;

    fn unit_ball() -> Medium {
        let ball = Boundary::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        Medium::new(ball, Transform::IDENTITY, 2.0, Color::ONE)
    }

    #[test]
    fn spans_are_the_chords_inside_clipped_to_the_ray() {
        let ball = unit_ball();
        let through = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
        let (a, b) = ball.span(&through, f32::INFINITY).unwrap();
        assert!((a - 2.0).abs() < 1e-6 && (b - 4.0).abs() < 1e-6);
        // From inside: from 0; stopped by a surface at 0.5.
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(ball.span(&inside, 0.5), Some((0.0, 0.5)));
        assert!(ball
            .span(&Ray::new(Vec3::new(0.0, 2.0, -3.0), Vec3::Z), 9.0)
            .is_none());
        // Behind the ray.
        assert!(ball
            .span(&Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::Z), 9.0)
            .is_none());
        // A box turned 45° about y and moved: its diagonal is √2 wide.
        let steps = [
            TransformStep::Rotate {
                axis: [0.0, 1.0, 0.0],
                degrees: 45.0,
            },
            TransformStep::Translate([5.0, 0.0, 0.0]),
        ];
        let cube = Boundary::Box {
            min: Vec3::splat(-0.5),
            max: Vec3::splat(0.5),
        };
        let turned = Medium::new(
            cube,
            Transform::from_steps(&steps).unwrap(),
            1.0,
            Color::ONE,
        );
        let ray = Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::X);
        let (a, b) = turned.span(&ray, f32::INFINITY).unwrap();
        let half = 0.5 * std::f32::consts::SQRT_2;
        assert!((a - (5.0 - half)).abs() < 1e-5 && (b - (5.0 + half)).abs() < 1e-5);
    }

    /// The fraction of drawn distances that fall inside is the chance of
    /// meeting a particle, 1 − e^{−σℓ}, within 4 standard errors, and the
    /// distances inside follow the truncated exponential law (their mean).
    #[test]
    fn distances_follow_the_exponential_law() {
        let ball = unit_ball();
        let ray = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
        let n = 200_000;
        let mut rng = Rng::new(11);
        let mut hits = 0u32;
        let mut sum = 0.0f64;
        for _ in 0..n {
            if let Some(t) = ball.sample_distance(&ray, f32::INFINITY, rng.next_f32()) {
                hits += 1;
                sum += f64::from(t - 2.0);
            }
        }
        let (sigma, length) = (2.0f64, 2.0f64);
        let p = 1.0 - (-sigma * length).exp();
        let fraction = f64::from(hits) / f64::from(n);
        let se = (p * (1.0 - p) / f64::from(n)).sqrt();
        assert!((fraction - p).abs() < 4.0 * se, "{fraction} vs {p}");
        assert!(
            (f64::from(ball.transmittance(&ray, f32::INFINITY)) - (1.0 - p)).abs() < 1e-6,
            "transmittance"
        );
        // Mean of an exponential truncated to [0, ℓ].
        let e = (-sigma * length).exp();
        let mean = 1.0 / sigma - length * e / (1.0 - e);
        let second = 2.0 / (sigma * sigma); // bounds the variance
        let got = sum / f64::from(hits);
        assert!(
            (got - mean).abs() < 4.0 * (second / f64::from(hits)).sqrt(),
            "{got} vs {mean}"
        );
    }
}
