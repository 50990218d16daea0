//! Lights: the emissive surfaces of a scene and its environment, gathered so
//! that a path can aim at them (next-event estimation) instead of only
//! meeting them by chance.
//!
//! Every emissive sphere, quad, disk, cylinder and triangle becomes a
//! [`Light`] in world space; the [`Environment`] (what escaping rays see) is
//! one more. A [`Lights`] list chooses one in proportion to its power
//! (emitted radiance × area × π, twice that for two-sided lights; see
//! [`LightSelection`]) or uniformly, and samples a point on it: spheres by
//! the solid angle of the cap seen from the shaded point, the other shapes
//! uniformly by area (rectangles close up by solid angle), the
//! environment by its brightness. [`Lights::pdf`] gives the density,
//! per unit solid angle, with which a direction that happens to meet a light
//! would have been sampled, which multiple importance sampling needs.

pub mod environment;
mod rectangle;
pub mod source;

use rectangle::SphericalRectangle;

pub use environment::{Environment, EnvironmentMap};
pub use source::{LightDesc, LightSource};

use crate::distribution::Distribution1D;
use crate::geometry::{Quadric, QuadricForm, Sphere};
use crate::material::Emissive;
use crate::math::{Color, Point3, Vec3};
use crate::sampler::{Dim, Sampler};
use crate::sampling;
use crate::texture::Texture;
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
    /// A disk, or a cylinder whose cross-sections are circles (see
    /// [`Quadric::round`]): its outward side is its own.
    Quadric(Quadric),
}

impl Shape {
    /// The surface area.
    pub fn area(&self) -> f32 {
        // The length of a cross product, in f64 where its square overflows
        // f32 (edges beyond about 4e9).
        let length = |n: Vec3, p: Vec3, q: Vec3| {
            let l = n.length();
            if l.is_finite() {
                l
            } else {
                p.as_dvec3().cross(q.as_dvec3()).length() as f32
            }
        };
        match *self {
            Shape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            Shape::Quad { u, v, .. } => length(u.cross(v), u, v),
            Shape::Triangle {
                vertices: [a, b, c],
            } => 0.5 * length((b - a).cross(c - a), b - a, c - a),
            Shape::Quadric(q) => q.area(),
        }
    }
}

/// An emissive surface that can be sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Where it is.
    pub shape: Shape,
    /// What it emits, and to which sides (the radiance is the texture's
    /// where it has one).
    pub emission: Emissive,
    /// The texture of its radiance, if it has one.
    pub texture: Option<LightTexture>,
    /// The emitting object it is part of (the triangles of a mesh, or of
    /// an instance, share one), for [`LightSelection::Objects`].
    pub object: u32,
}

/// The radiance of a light given by a texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTexture {
    /// The texture, in the table given to [`Lights::new`].
    pub texture: u32,
    /// The texture coordinates at a triangle's corners a, b, c, or at a
    /// quad's corner Q, Q + u and Q + v (unused for spheres, whose
    /// coordinates follow from the normal, and for disks and cylinders,
    /// whose own they are).
    pub uvs: [[f32; 2]; 3],
}

impl Light {
    /// Its power, up to a constant factor: what [`Lights`] chooses by.
    fn power(&self, textures: &[Texture], grid: usize) -> f64 {
        let sides = if self.emission.two_sided { 2.0 } else { 1.0 };
        f64::from(self.mean_luminance(textures, grid))
            * f64::from(self.shape.area())
            * std::f64::consts::PI
            * sides
    }

    /// The luminance of its radiance averaged over its area: a textured
    /// light's over a `n` × `n` grid of points spread evenly by area.
    fn mean_luminance(&self, textures: &[Texture], n: usize) -> f32 {
        if self.texture.is_none() {
            return luminance(self.emission.radiance);
        }
        let normal = Surface::of(&self.shape).normal;
        let mut total = 0.0;
        for i in 0..n {
            for j in 0..n {
                let uv = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                let (point, outward, st) = sample_area(&self.shape, normal, uv);
                total += luminance(self.radiance_at(textures, point, outward, st));
            }
        }
        total / (n * n) as f32
    }

    /// Its radiance at `point` of its surface (outward normal `outward`,
    /// parameters `st` as [`sample_area`] gives them), before the side.
    #[inline]
    fn radiance_at(
        &self,
        textures: &[Texture],
        point: Point3,
        outward: Vec3,
        st: [f32; 2],
    ) -> Color {
        let Some(t) = self.texture else {
            return self.emission.radiance;
        };
        let uv = match self.shape {
            Shape::Sphere { .. } => Sphere::uv(outward),
            Shape::Quadric(_) => st,
            // Affine in (s, t) from the coordinates at the corner and at the
            // ends of the two edges (a triangle's barycentrics b₁, b₂).
            Shape::Quad { .. } | Shape::Triangle { .. } => {
                let [p, q, r] = t.uvs;
                let [s, t] = st;
                [
                    p[0] + s * (q[0] - p[0]) + t * (r[0] - p[0]),
                    p[1] + s * (q[1] - p[1]) + t * (r[1] - p[1]),
                ]
            }
        };
        // Emitted light is not clamped as an albedo is, but never negative.
        textures[t.texture as usize]
            .value(textures, &crate::texture::TexCoords::new(uv, point))
            .max(Color::ZERO)
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
    /// The point on the light (for the environment, infinitely far away:
    /// the shaded point moved one unit along `direction`).
    pub point: Point3,
    /// Unit direction from the shaded point to the light point.
    pub direction: Vec3,
    /// Distance to the light point (infinite for the environment).
    pub distance: f32,
    /// Radiance arriving from the light point along `-direction` (before
    /// any occlusion).
    pub radiance: Color,
    /// The density of this direction per unit solid angle, including the
    /// choice of the light; for a delta light (`delta`), the chance of its
    /// choice alone, and `radiance` is the irradiance it brings to a
    /// surface facing it.
    pub pdf: f32,
    /// Whether the light has a single direction here (a point, a spot, a
    /// directional light without angular radius): no bounce can find it, so
    /// the sample needs no weight against the bounces.
    pub delta: bool,
}

/// How [`Lights`] chooses the light to sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightSelection {
    /// In proportion to each light's power (the environment's: its
    /// radiance over the sphere of directions, through the disc of the
    /// scene's bounding sphere).
    #[default]
    Power,
    /// Every light that emits anything equally often (each triangle of
    /// a mesh a light of its own, as in pbrt).
    Uniform,
    /// Every emitting object equally often (a whole mesh as one light,
    /// its triangles in proportion to their area), and each light that is
    /// no surface and the environment as one object each: Mitsuba's
    /// choice.
    Objects,
}

/// The lights of a scene (its emissive surfaces, and the environment when
/// it sheds light), and how to choose among them.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    lights: Vec<Light>,
    /// The normal and area of each of `lights`, worked out once rather
    /// than at every sample.
    surfaces: Vec<Surface>,
    /// The textures of textured lights.
    textures: Vec<Texture>,
    /// The lights that are no surface (point, spot, directional), chosen
    /// as light numbers `lights.len()` on.
    sources: Vec<LightSource>,
    /// Whether any of `sources` can be seen by an escaping ray (a disc of
    /// the sky).
    sources_seen: bool,
    /// The environment, chosen as light number `lights.len() +
    /// sources.len()`.
    environment: Option<Environment>,
    /// The choice of a light: `lights`, `sources`, then the environment.
    choice: Distribution1D,
}

impl Lights {
    /// The list of `lights`, in order (a light's index is its place in
    /// `lights`), whose textures are in `textures`, and the `environment`
    /// seen by rays that escape a scene whose bounding sphere has radius
    /// `scene_radius`. Lights of no power are never chosen; when nothing
    /// sheds any light the list is empty.
    pub fn new(
        lights: Vec<Light>,
        textures: Vec<Texture>,
        environment: Option<Environment>,
        scene_radius: f32,
        selection: LightSelection,
    ) -> Self {
        Self::with_sources(
            lights,
            Vec::new(),
            textures,
            environment,
            scene_radius,
            selection,
        )
    }

    /// [`Lights::new`] with light `sources` too (point, spot and
    /// directional lights), numbered after `lights`.
    pub fn with_sources(
        lights: Vec<Light>,
        sources: Vec<LightSource>,
        textures: Vec<Texture>,
        environment: Option<Environment>,
        scene_radius: f32,
        selection: LightSelection,
    ) -> Self {
        // The environment's power is its light through the disc the scene
        // presents to it (π r²), whichever way it comes.
        let disc = std::f64::consts::PI * f64::from(scene_radius.max(f32::MIN_POSITIVE)).powi(2);
        // A black environment is no light.
        let environment = environment
            .map(|e| (e.integral(), e))
            .filter(|(integral, _)| *integral > 0.0);
        // A textured light's power is estimated from a grid of its texture:
        // 16 × 16 for a few lights, fewer for many (a textured mesh of a
        // million emissive triangles), about 4 million lookups at most. An
        // estimate only steers the choice of lights: any positive power
        // leaves the image unbiased.
        let textured = lights.iter().filter(|l| l.texture.is_some()).count().max(1);
        let grid = ((4e6 / textured as f64).sqrt() as usize).clamp(2, 16);
        let mut powers: Vec<f64> = {
            use rayon::prelude::*;
            lights
                .par_iter()
                .map(|l| l.power(&textures, grid))
                .collect()
        };
        powers.extend(sources.iter().map(|s| s.power(scene_radius)));
        powers.extend(environment.as_ref().map(|(integral, _)| integral * disc));
        let environment = environment.map(|(_, e)| e);
        let surfaces: Vec<Surface> = lights.iter().map(|l| Surface::of(&l.shape)).collect();
        match selection {
            LightSelection::Power => {}
            LightSelection::Uniform => {
                for p in &mut powers {
                    *p = if *p > 0.0 { 1.0 } else { 0.0 };
                }
            }
            LightSelection::Objects => {
                // Each object's share is 1, split among its parts by area.
                let mut areas: std::collections::HashMap<u32, f64> = Default::default();
                for ((l, s), p) in lights.iter().zip(&surfaces).zip(&powers) {
                    if *p > 0.0 {
                        *areas.entry(l.object).or_default() += f64::from(s.area);
                    }
                }
                for (i, p) in powers.iter_mut().enumerate() {
                    *p = match (lights.get(i), surfaces.get(i)) {
                        _ if *p <= 0.0 => 0.0,
                        (Some(l), Some(s)) => f64::from(s.area) / areas[&l.object],
                        _ => 1.0,
                    };
                }
            }
        }
        let Some(choice) = Distribution1D::new(&powers) else {
            return Lights::default();
        };
        // Only the textures of textured lights are looked up.
        let textures = if lights.iter().any(|l| l.texture.is_some())
            || sources.iter().any(LightSource::is_textured)
        {
            textures
        } else {
            Vec::new()
        };
        Lights {
            surfaces,
            lights,
            textures,
            sources_seen: sources.iter().any(LightSource::is_visible),
            sources,
            environment,
            choice,
        }
    }

    /// Whether there is no light to sample.
    pub fn is_empty(&self) -> bool {
        self.choice.is_empty()
    }

    /// The number of lights, the environment included.
    pub fn len(&self) -> usize {
        self.choice.len()
    }

    /// The probability of choosing light `i` (the environment is light
    /// number [`Lights::len`] − 1 when there is one).
    pub fn chance(&self, i: usize) -> f32 {
        self.choice.chance(i)
    }

    /// Chooses a light (see [`LightSelection`]) and samples a direction
    /// from `point` towards it; `None` when the sample carries no light (the
    /// back of a one-sided light, a degenerate direction).
    pub fn sample(&self, point: Point3, sampler: &mut impl Sampler) -> Option<LightSample> {
        let i = self.choice.sample(sampler.get_1d(Dim::LightChoice));
        let chance = self.choice.chance(i);
        let uv = sampler.get_2d(Dim::Light);
        let Some(light) = self.lights.get(i) else {
            if let Some(source) = self.sources.get(i - self.lights.len()) {
                let mut sample = source.illuminate(point, uv, &self.textures)?;
                sample.pdf *= chance;
                return (sample.pdf > 0.0 && sample.pdf.is_finite()).then_some(sample);
            }
            let sky = self.environment.as_ref()?.sample(uv)?;
            let pdf = chance * sky.pdf;
            if !(pdf > 0.0 && pdf.is_finite()) {
                return None;
            }
            return Some(LightSample {
                point: point + sky.direction,
                direction: sky.direction,
                distance: f32::INFINITY,
                radiance: sky.radiance,
                pdf,
                delta: false,
            });
        };
        let surface = &self.surfaces[i];
        let seen = surface.seen_from(&light.shape, point);
        let (target, outward, st) = match (&seen, light.shape) {
            (Seen::Cap { center, radius }, _) => {
                let (target, outward) = sample_cap(*center, *radius, point, uv);
                (target, outward, uv)
            }
            (Seen::Rectangle(rectangle), Shape::Quad { corner, u, v }) => {
                let target = rectangle.sample(uv);
                let d = target - corner;
                let st = [d.dot(u) / u.length_squared(), d.dot(v) / v.length_squared()];
                (target, surface.normal, st)
            }
            (_, shape) => sample_area(&shape, surface.normal, uv),
        };
        let to = target - point;
        let distance = to.length();
        let direction = to / distance;
        let pdf = chance * seen.density(surface, point, target, outward);
        if !(pdf > 0.0 && pdf.is_finite() && distance > 0.0 && distance.is_finite()) {
            return None;
        }
        Some(LightSample {
            point: target,
            direction,
            distance,
            radiance: if outward.dot(direction) < 0.0 || light.emission.two_sided {
                light.radiance_at(&self.textures, target, outward, st)
            } else {
                Color::ZERO
            },
            pdf,
            delta: false,
        })
    }

    /// The density per unit solid angle with which [`Lights::sample`] from
    /// `from` picks the direction that meets light `i` at `point` (outward
    /// normal `outward`).
    pub fn pdf(&self, i: usize, from: Point3, point: Point3, outward: Vec3) -> f32 {
        let (Some(light), chance) = (self.lights.get(i), self.choice.chance(i)) else {
            return 0.0;
        };
        if chance == 0.0 {
            return 0.0;
        }
        let surface = &self.surfaces[i];
        chance
            * surface
                .seen_from(&light.shape, from)
                .density(surface, from, point, outward)
    }

    /// The density per unit solid angle with which [`Lights::sample`] picks
    /// unit `direction` towards the environment (0 when the environment is
    /// not sampled).
    #[inline]
    pub fn environment_pdf(&self, direction: Vec3) -> f32 {
        match &self.environment {
            Some(sky) => {
                self.choice.chance(self.lights.len() + self.sources.len()) * sky.pdf(direction)
            }
            None => 0.0,
        }
    }

    /// Whether an escaping ray can see any light that is no surface (a
    /// disc of the sky): if not, [`Lights::seen_along`] finds nothing.
    #[inline]
    pub fn sources_seen(&self) -> bool {
        self.sources_seen
    }

    /// The lights that are no surface an escaping ray sees along unit
    /// `direction`: each one's radiance and the density, per unit solid
    /// angle, with which [`Lights::sample`] picks that direction towards it
    /// (its choice included).
    pub fn seen_along(&self, direction: Vec3) -> impl Iterator<Item = (Color, f32)> + '_ {
        let first = self.lights.len();
        self.sources.iter().enumerate().filter_map(move |(j, s)| {
            let (radiance, pdf) = s.seen_along(direction)?;
            Some((radiance, self.choice.chance(first + j) * pdf))
        })
    }
}

/// Whether `point` is inside the sphere (or on it).
#[inline]
fn inside(center: Point3, radius: f32, point: Point3) -> bool {
    (center - point).length_squared() <= radius * radius
}

/// How a light is sampled from a point: what [`Lights::sample`] draws and
/// [`Lights::pdf`] gives the density of, decided once for both.
enum Seen {
    /// A sphere seen from outside: uniform over the cone it fills.
    Cap { center: Point3, radius: f32 },
    /// A rectangle seen close up: uniform over its solid angle.
    Rectangle(SphericalRectangle),
    /// Anything else: uniform over its area.
    Area,
}

impl Seen {
    /// The density per unit solid angle, seen from `from`, of the point
    /// `point` (outward normal `outward`) of the light whose surface is
    /// `surface`: over the area, 1/A becomes d² / (|cos θ| A).
    #[inline]
    fn density(&self, surface: &Surface, from: Point3, point: Point3, outward: Vec3) -> f32 {
        match *self {
            Seen::Cap { center, radius } => {
                1.0 / cap_solid_angle(radius * radius / (center - from).length_squared())
            }
            Seen::Rectangle(ref rectangle) => (1.0 / rectangle.solid_angle()) as f32,
            Seen::Area => {
                let to = point - from;
                let d2 = to.length_squared();
                d2 * d2.sqrt() / (outward.dot(to).abs() * surface.area)
            }
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

/// A rectangle is sampled by solid angle rather than by area from points
/// whose squared distance to its centre is below this times its area.
const SPHERICAL_WITHIN: f32 = 1.0;

/// The unit normal and the area of a light's shape, and whether it is a
/// rectangle.
#[derive(Clone, Copy, Debug)]
struct Surface {
    /// A quad's or triangle's outward unit normal (unused for spheres).
    normal: Vec3,
    area: f32,
    /// A quad whose edges are perpendicular: sampled by solid angle where
    /// it covers enough of it ([`SphericalRectangle`]).
    rectangle: bool,
}

impl Surface {
    fn of(shape: &Shape) -> Self {
        let normal = match *shape {
            Shape::Sphere { .. } => Vec3::ZERO,
            // A disk's normal is everywhere the same; a cylinder's is its
            // sample's.
            Shape::Quadric(q) => match q.form {
                QuadricForm::Disk => q.at([0.0, 0.0]).outward,
                QuadricForm::Cylinder => Vec3::ZERO,
            },
            Shape::Quad { u, v, .. } => u.cross(v).normalize(),
            Shape::Triangle {
                vertices: [a, b, c],
            } => (b - a).cross(c - a).normalize(),
        };
        let rectangle = match *shape {
            Shape::Quad { u, v, .. } => {
                u.dot(v).abs() <= 1e-6 * u.length() * v.length() && normal.is_finite()
            }
            _ => false,
        };
        Surface {
            normal,
            area: shape.area(),
            rectangle,
        }
    }

    /// How `shape` (the shape of this surface) is sampled from `from`.
    #[inline]
    fn seen_from(&self, shape: &Shape, from: Point3) -> Seen {
        match *shape {
            Shape::Sphere { center, radius } if !inside(center, radius, from) => {
                Seen::Cap { center, radius }
            }
            Shape::Quad { corner, u, v } if self.rectangle => {
                // Worth its cost only close up, where sampling the area
                // would vary as the inverse square of the distance over
                // the cosine: within its own size of its centre.
                let to = corner + 0.5 * (u + v) - from;
                if !(to.length_squared() < SPHERICAL_WITHIN * self.area) {
                    return Seen::Area;
                }
                SphericalRectangle::new(corner, u, v, from).map_or(Seen::Area, Seen::Rectangle)
            }
            _ => Seen::Area,
        }
    }
}

/// A uniform point on the area of `shape`, whose unit normal is `normal`
/// if it is flat ([`Surface::of`]), its outward unit normal, and its
/// parameters: a quad's (α, β), a triangle's barycentrics (b₁, b₂) of its
/// second and third corners, a disk's or cylinder's texture coordinates (a
/// sphere's follow from the normal).
fn sample_area(shape: &Shape, normal: Vec3, [s, t]: [f32; 2]) -> (Point3, Vec3, [f32; 2]) {
    match *shape {
        Shape::Sphere { center, radius } => {
            let outward = sampling::unit_vector([s, t]);
            (center + radius * outward, outward, [s, t])
        }
        Shape::Quad { corner, u, v } => (corner + s * u + t * v, normal, [s, t]),
        Shape::Triangle {
            vertices: [a, b, c],
        } => {
            // Folding the unit square onto the triangle below its diagonal.
            let (s, t) = if s + t > 1.0 {
                (1.0 - s, 1.0 - t)
            } else {
                (s, t)
            };
            (a + s * (b - a) + t * (c - a), normal, [s, t])
        }
        Shape::Quadric(q) => q.sample([s, t]),
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
