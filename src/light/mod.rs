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

use crate::material::Emissive;
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
    /// What it emits, and to which sides.
    pub emission: Emissive,
}

impl Light {
    /// Its power, up to a constant factor: what [`Lights`] chooses by.
    fn power(&self) -> f64 {
        let sides = if self.emission.two_sided { 2.0 } else { 1.0 };
        f64::from(luminance(self.emission.radiance))
            * f64::from(self.shape.area())
            * std::f64::consts::PI
            * sides
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
        let (target, outward) = match light.shape {
            Shape::Sphere { center, radius } if !inside(center, radius, point) => {
                sample_cap(center, radius, point, uv)
            }
            shape => sample_area(&shape, uv),
        };
        let to = target - point;
        let distance = to.length();
        let direction = to / distance;
        let pdf = self.chance[i] * solid_angle_density(&light.shape, point, target, outward);
        if !(pdf > 0.0 && pdf.is_finite() && distance > 0.0 && distance.is_finite()) {
            return None;
        }
        Some(LightSample {
            point: target,
            direction,
            distance,
            radiance: light.emission.towards(outward.dot(direction) < 0.0),
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
        chance * solid_angle_density(&light.shape, from, point, outward)
    }
}

/// Whether `point` is inside the sphere (or on it).
#[inline]
fn inside(center: Point3, radius: f32, point: Point3) -> bool {
    (center - point).length_squared() <= radius * radius
}

/// The density per unit solid angle, seen from `from`, of the point `point`
/// (outward normal `outward`) of a light of `shape` as the sampling chooses
/// it: uniform over the cone of a sphere seen from outside, else uniform
/// over the area, whose density 1/A becomes d² / (|cos θ| A) per unit
/// solid angle.
#[inline]
fn solid_angle_density(shape: &Shape, from: Point3, point: Point3, outward: Vec3) -> f32 {
    match *shape {
        Shape::Sphere { center, radius } if !inside(center, radius, from) => {
            1.0 / cap_solid_angle(radius * radius / (center - from).length_squared())
        }
        _ => {
            let to = point - from;
            let d2 = to.length_squared();
            d2 * d2.sqrt() / (outward.dot(to).abs() * shape.area())
        }
    }
}

/// The solid angle of a sphere seen from outside, given sin²θ = r²/d² of
/// its half-angle θ: 2π(1 − cos θ), computed without cancellation.
fn cap_solid_angle(sin2: f32) -> f32 {
    // 1 − cos θ = sin²θ / (1 + cos θ).
    let cos = (1.0 - sin2).max(0.0).sqrt();
    2.0 * PI * sin2 / (1.0 + cos)
}

/// A uniform point on the area of `shape`, and its outward unit normal.
fn sample_area(shape: &Shape, [s, t]: [f32; 2]) -> (Point3, Vec3) {
    match *shape {
        Shape::Sphere { center, radius } => {
            let outward = sampling::unit_vector([s, t]);
            (center + radius * outward, outward)
        }
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
    }
}

/// The point of the sphere seen from `point` (outside it) along a direction
/// uniform over the cone it covers, and its outward normal.
fn sample_cap(center: Point3, radius: f32, point: Point3, uv: [f32; 2]) -> (Point3, Vec3) {
    let oc = center - point;
    let dc2 = oc.length_squared();
    let r2 = radius * radius;
    let one_minus_cos_max = cap_solid_angle(r2 / dc2) / (2.0 * PI);
    let direction = sampling::in_cone(uv, oc / dc2.sqrt(), one_minus_cos_max);
    // The nearer intersection with the sphere; grazing directions round to
    // the tangent point.
    let along = direction.dot(oc);
    let off_axis2 = (oc - along * direction).length_squared();
    let distance = along - (r2 - off_axis2).max(0.0).sqrt();
    let target = point + distance * direction;
    (target, (target - center).normalize())
}

#[cfg(test)]
mod tests;
