//! Lights: the emissive surfaces of a scene, gathered so that a path can aim
//! at them (next-event estimation) instead of only meeting them by chance.
//!
//! Every emissive sphere, quad and triangle becomes a [`Light`] in world
//! space. A [`Lights`] list chooses one in proportion to its power (emitted
//! radiance × area × π, twice that for two-sided lights) and samples a point
//! on it: spheres by the solid angle of the cap seen from the shaded point,
//! quads and triangles uniformly by area. [`Lights::pdf`] gives the density,
//! per unit solid angle, with which a direction that happens to meet a light
//! would have been sampled, which multiple importance sampling needs.

use crate::math::{Color, Point3, Vec3};
use crate::sampler::{Dim, Sampler};
use crate::sampling;
use std::f32::consts::PI;

/// The shape of a light, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Point3,
        /// Radius.
        radius: f32,
    },
    /// A parallelogram: corner, edges u and v; its outward side is u × v's.
    Quad {
        /// The corner Q.
        corner: Point3,
        /// The first edge.
        u: Vec3,
        /// The second edge.
        v: Vec3,
    },
    /// A triangle; its outward side is the one from which a, b, c run
    /// counter-clockwise.
    Triangle {
        /// The corners.
        vertices: [Point3; 3],
    },
}

impl Shape {
    /// The surface area.
    pub fn area(&self) -> f32 {
        match *self {
            Shape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            Shape::Quad { u, v, .. } => u.cross(v).length(),
            Shape::Triangle {
                vertices: [a, b, c],
            } => 0.5 * (b - a).cross(c - a).length(),
        }
    }
}

/// An emissive surface that can be sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Where it is.
    pub shape: Shape,
    /// The radiance it emits.
    pub radiance: Color,
    /// Whether it emits from both sides.
    pub two_sided: bool,
}

impl Light {
    /// Its power, up to a constant factor: what [`Lights`] chooses by.
    fn power(&self) -> f64 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        f64::from(luminance(self.radiance))
            * f64::from(self.shape.area())
            * std::f64::consts::PI
            * sides
    }

    /// The radiance leaving the light at a point of outward normal
    /// `outward` towards direction `towards` (from the light).
    #[inline]
    fn emitted(&self, outward: Vec3, towards: Vec3) -> Color {
        if self.two_sided || outward.dot(towards) > 0.0 {
            self.radiance
        } else {
            Color::ZERO
        }
    }
}

/// The luminance of a linear RGB colour (Rec. 709 weights).
#[inline]
pub fn luminance(c: Color) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// A point sampled on a light, seen from a shaded point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point on the light.
    pub point: Point3,
    /// Unit direction from the shaded point to the light point.
    pub direction: Vec3,
    /// Distance to the light point.
    pub distance: f32,
    /// Radiance arriving from the light point along `-direction` (before
    /// any occlusion).
    pub radiance: Color,
    /// The density of this direction per unit solid angle, including the
    /// choice of the light.
    pub pdf: f32,
}

/// The lights of a scene, and how to choose among them.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    lights: Vec<Light>,
    /// Cumulative powers, normalised to end at 1.
    cdf: Vec<f32>,
    /// The probability of choosing each light.
    chance: Vec<f32>,
}

impl Lights {
    /// The list of `lights`, in order (a light's index is its place in
    /// `lights`). Lights of no power are never chosen; when none has any
    /// power the list is empty.
    pub fn new(lights: Vec<Light>) -> Self {
        let powers: Vec<f64> = lights.iter().map(Light::power).collect();
        let total: f64 = powers.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Lights::default();
        }
        let mut running = 0.0;
        let mut cdf: Vec<f32> = powers
            .iter()
            .map(|p| {
                running += p;
                (running / total) as f32
            })
            .collect();
        // Every u in [0, 1) chooses a light.
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        // The chance of each light is the width of its step of the f32
        // table that chooses it, not its exact share: with millions of
        // lights the two differ, and the weights must use what is sampled.
        let chance = (0..cdf.len())
            .map(|i| cdf[i] - if i == 0 { 0.0 } else { cdf[i - 1] })
            .collect();
        Lights {
            lights,
            cdf,
            chance,
        }
    }

    /// Whether there is no light to sample.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// The number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Light `i`.
    pub fn get(&self, i: usize) -> &Light {
        &self.lights[i]
    }

    /// Chooses a light in proportion to its power and samples a direction
    /// from `point` towards it; `None` when the sample carries no light (the
    /// back of a one-sided light, a degenerate direction).
    pub fn sample(&self, point: Point3, sampler: &mut impl Sampler) -> Option<LightSample> {
        let u = sampler.get_1d(Dim::LightChoice);
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.lights.len() - 1);
        let light = &self.lights[i];
        let uv = sampler.get_2d(Dim::Light);
        let (target, outward, pdf_solid_angle) = match light.shape {
            Shape::Sphere { center, radius } => sample_sphere(center, radius, point, uv)?,
            shape => {
                let (target, outward) = sample_flat(&shape, uv);
                let to = target - point;
                let d2 = to.length_squared();
                let cos = outward.dot(to).abs() / d2.sqrt();
                (target, outward, d2 / (cos * shape.area()))
            }
        };
        let to = target - point;
        let distance = to.length();
        let direction = to / distance;
        let pdf = self.chance[i] * pdf_solid_angle;
        if !(pdf > 0.0 && pdf.is_finite() && distance > 0.0 && distance.is_finite()) {
            return None;
        }
        Some(LightSample {
            point: target,
            direction,
            distance,
            radiance: light.emitted(outward, -direction),
            pdf,
        })
    }

    /// The density per unit solid angle with which [`Lights::sample`] from
    /// `from` picks the direction that meets light `i` at `point` (outward
    /// normal `outward`).
    pub fn pdf(&self, i: usize, from: Point3, point: Point3, outward: Vec3) -> f32 {
        let (Some(light), Some(&chance)) = (self.lights.get(i), self.chance.get(i)) else {
            return 0.0;
        };
        if chance == 0.0 {
            return 0.0;
        }
        let to = point - from;
        let d2 = to.length_squared();
        let solid_angle = match light.shape {
            Shape::Sphere { center, radius } => {
                let dc2 = (center - from).length_squared();
                if dc2 > radius * radius {
                    1.0 / cap_solid_angle(radius * radius / dc2)
                } else {
                    let cos = outward.dot(to).abs() / d2.sqrt();
                    d2 / (cos * light.shape.area())
                }
            }
            shape => {
                let cos = outward.dot(to).abs() / d2.sqrt();
                d2 / (cos * shape.area())
            }
        };
        chance * solid_angle
    }
}

/// The solid angle of a sphere seen from outside, given sin²θ = r²/d² of
/// its half-angle θ: 2π(1 − cos θ), computed without cancellation.
fn cap_solid_angle(sin2: f32) -> f32 {
    // 1 − cos θ = sin²θ / (1 + cos θ).
    let cos = (1.0 - sin2).max(0.0).sqrt();
    2.0 * PI * sin2 / (1.0 + cos)
}

/// A uniform point on a quad or a triangle, and its outward unit normal.
fn sample_flat(shape: &Shape, [s, t]: [f32; 2]) -> (Point3, Vec3) {
    match *shape {
        Shape::Quad { corner, u, v } => (corner + s * u + t * v, u.cross(v).normalize()),
        Shape::Triangle {
            vertices: [a, b, c],
        } => {
            // Folding the unit square onto the triangle below its diagonal.
            let (s, t) = if s + t > 1.0 {
                (1.0 - s, 1.0 - t)
            } else {
                (s, t)
            };
            (
                a + s * (b - a) + t * (c - a),
                (b - a).cross(c - a).normalize(),
            )
        }
        Shape::Sphere { .. } => unreachable!("spheres are sampled by solid angle"),
    }
}

/// A point on the sphere seen from `point`: uniform over the solid angle of
/// the visible cap from outside; uniform over the area from inside. The
/// point, its outward normal and the density per unit solid angle.
fn sample_sphere(
    center: Point3,
    radius: f32,
    point: Point3,
    uv: [f32; 2],
) -> Option<(Point3, Vec3, f32)> {
    let oc = center - point;
    let dc2 = oc.length_squared();
    let r2 = radius * radius;
    if dc2 <= r2 {
        let outward = sampling::unit_vector(uv);
        let target = center + radius * outward;
        let to = target - point;
        let d2 = to.length_squared();
        let cos = outward.dot(to).abs() / d2.sqrt();
        return Some((target, outward, d2 / (cos * 4.0 * PI * r2)));
    }
    let sin2_max = r2 / dc2;
    let solid_angle = cap_solid_angle(sin2_max);
    // A uniform direction in the cone: 1 − cos θ uniform in [0, 1 − cos θmax].
    let one_minus_cos = uv[0] * solid_angle / (2.0 * PI);
    let cos = 1.0 - one_minus_cos;
    let sin = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let axis = oc / dc2.sqrt();
    let (t, b) = axis.any_orthonormal_pair();
    let phi = 2.0 * PI * uv[1];
    let direction = (t * (sin * phi.cos()) + b * (sin * phi.sin()) + axis * cos).normalize();
    // The nearer intersection with the sphere; grazing directions round to
    // the tangent point.
    let along = direction.dot(oc);
    let off_axis2 = (oc - along * direction).length_squared();
    let distance = along - (r2 - off_axis2).max(0.0).sqrt();
    let target = point + distance * direction;
    let outward = (target - center).normalize();
    Some((target, outward, 1.0 / solid_angle))
}

#[cfg(test)]
mod tests;
