//! Scenes: the description people write, the built-in scenes of the notes, and
//! the compiled form the renderer traces.

pub mod builtin;
mod decode;
pub mod desc;
pub mod file;
pub mod hint;
pub mod source;

pub use desc::SceneDesc;

use crate::camera::{Camera, CameraError, CameraSettings};
use crate::geometry::bvh_bundle::LANES;
use crate::geometry::{Bvh, HitRecord, Primitive, RayBundle, Sphere};
use crate::material::{Attenuation, BounceModel, Dielectric, Diffuse, Material, Metal};
use crate::math::{lerp, Color, Interval, Point3, Vec3};
use crate::ray::Ray;
use desc::{
    AttenuationDesc, BackgroundDesc, BounceDesc, MaterialDesc, ObjectDesc, SamplingDesc,
    ShadingDesc,
};
use std::collections::HashMap;
use thiserror::Error;

/// Largest magnitude of an object's coordinates and radius: the sphere test
/// squares lengths of this order in `f32` (whose maximum is about 3.4e38).
pub const MAX_COORDINATE: f64 = 1e18;

/// Largest accepted image, in pixels (e.g. 8192×8192). The film needs 28
/// bytes a pixel and a pass in flight keeps a copy, so this caps the render's
/// memory near 3.8 GB: larger images are refused, not attempted.
pub const MAX_PIXELS: u64 = 1 << 26;

/// A scene description that cannot be rendered.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The camera cannot be built.
    #[error("camera: {0}")]
    Camera(#[from] CameraError),
    /// A field has a value outside its allowed range.
    #[error("{field}: {message}")]
    Invalid {
        /// Path of the field, e.g. `objects[3].radius`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// An object refers to a material that no entry of `materials` defines.
    #[error("{field}: {}", unknown_material_message(name, known))]
    UnknownMaterial {
        /// Path of the reference, e.g. `objects[3].material`.
        field: String,
        /// The name used.
        name: String,
        /// The names the scene defines.
        known: Vec<String>,
    },
}

impl SceneError {
    /// Path of the field at fault, e.g. `objects[3].radius` or `camera.vfov`
    /// (`render` when the image size as a whole is wrong).
    pub fn field(&self) -> String {
        match self {
            SceneError::Camera(c) => match c {
                CameraError::FieldOfView(_) => "camera.vfov".into(),
                CameraError::NoViewDirection(_) => "camera.lookat".into(),
                CameraError::UpParallelToView(_) => "camera.vup".into(),
                CameraError::FocusDistance(_) => "camera.focus_dist".into(),
                CameraError::DefocusAngle(_) => "camera.defocus_angle".into(),
                CameraError::EmptyImage(..) => "render".into(),
                CameraError::Overflow => "camera".into(),
                CameraError::NotFinite(name) => format!("camera.{name}"),
            },
            SceneError::Invalid { field, .. } | SceneError::UnknownMaterial { field, .. } => {
                field.clone()
            }
        }
    }

    /// What is wrong, without the field path.
    pub fn message(&self) -> String {
        match self {
            SceneError::Camera(c) => c.to_string(),
            SceneError::Invalid { message, .. } => message.clone(),
            SceneError::UnknownMaterial { name, known, .. } => {
                unknown_material_message(name, known)
            }
        }
    }

    /// A suggestion, where one helps: the closest defined material name to a
    /// misspelt one.
    pub fn hint(&self) -> Option<String> {
        match self {
            SceneError::UnknownMaterial { name, known, .. } => {
                hint::closest(name, known.iter().map(String::as_str))
                    .map(|c| format!("did you mean \"{c}\"?"))
            }
            _ => None,
        }
    }
}

fn invalid(field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

/// What a camera ray's colour shows (see [`desc::ShadingDesc`]).
pub type Shading = ShadingDesc;
/// Placement of samples within a pixel (see [`desc::SamplingDesc`]).
pub type Sampling = SamplingDesc;

/// What rays that escape the scene see.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    /// Blend from `bottom` to `top` by the unit direction's y.
    Gradient {
        /// Colour straight down.
        bottom: Color,
        /// Colour straight up.
        top: Color,
    },
    /// One colour everywhere.
    Solid(Color),
}

impl Background {
    /// The colour seen along unit direction `direction`.
    #[inline]
    pub fn color(&self, direction: Vec3) -> Color {
        match *self {
            Background::Gradient { bottom, top } => lerp(bottom, top, 0.5 * (direction.y + 1.0)),
            Background::Solid(c) => c,
        }
    }
}

/// Render settings after validation.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Maximum ray segments per path.
    pub max_depth: u32,
    /// Seed of the render.
    pub seed: u64,
    /// Sample placement.
    pub sampling: Sampling,
    /// Display gamma.
    pub gamma: f32,
    /// Shadow-acne epsilon: smallest accepted hit distance.
    pub epsilon: f32,
    /// What camera rays show.
    pub shading: Shading,
}

/// A scene compiled for rendering: validated, with a BVH over its objects.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Render settings.
    pub settings: Settings,
    /// The camera, sized for the image.
    pub camera: Camera,
    /// The background.
    pub background: Background,
    /// Material table indexed by [`HitRecord::material`].
    pub materials: Vec<Material>,
    /// The spheres, in description order.
    pub spheres: Vec<Sphere>,
    bvh: Bvh,
    /// See [`error_scale`].
    error_scale: f32,
    /// What shading needs of each sphere, in one place.
    surfaces: Vec<Surface>,
}

/// The factor of [`HitRecord::error`]: the hit point and its offset from the
/// centre are each rounded to about 2⁻²⁴ of their size (the point's
/// coordinates, the radius); 2⁻²⁰ leaves a wide margin over their sum. With
/// epsilon 0 (the notes' demonstration of shadow acne) it is 0, and rays
/// leave from the hit point itself, as in the notes.
fn error_scale(epsilon: f32) -> f32 {
    if epsilon > 0.0 {
        1.0 / (1u32 << 20) as f32
    } else {
        0.0
    }
}

/// The part of a sphere and its material that the record of a hit needs,
/// together in 32 bytes: one cache line per hit instead of two, and a
/// multiplication by the inverse radius instead of a division.
#[derive(Clone, Copy, Debug)]
struct Surface {
    center: Point3,
    inverse_radius: f32,
    radius: f32,
    material: u32,
}

fn vec3(t: [f64; 3]) -> Vec3 {
    Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32)
}

/// Accepts numbers that stay finite once converted to the renderer's `f32`.
/// `field` is only formatted when a number is refused (scene files may hold
/// millions of spheres).
fn finite(field: impl std::fmt::Display, values: &[f64]) -> Result<(), SceneError> {
    // `!(a <= b)` also catches NaN.
    match values.iter().find(|v| !(v.abs() <= f64::from(f32::MAX))) {
        None => Ok(()),
        Some(v) => Err(invalid(
            field.to_string(),
            format!(
                "must be a finite number of magnitude at most {:e}, got {v}",
                f32::MAX
            ),
        )),
    }
}

fn color(field: &str, c: [f64; 3]) -> Result<Color, SceneError> {
    finite(field, &c)?;
    if c.iter().any(|&v| v < 0.0) {
        return Err(invalid(
            field,
            format!("colour components must not be negative, got {c:?}"),
        ));
    }
    Ok(vec3(c))
}

fn albedo(field: &str, c: [f64; 3]) -> Result<Color, SceneError> {
    let v = color(field, c)?;
    if c.iter().any(|&x| x > 1.0) {
        return Err(invalid(
            field,
            format!("albedo components must be in [0, 1], got {c:?}"),
        ));
    }
    Ok(v)
}

impl Scene {
    /// Validates and compiles a scene description.
    pub fn from_desc(desc: &SceneDesc) -> Result<Scene, SceneError> {
        let settings = compile_settings(desc)?;
        let cam = &desc.camera;
        finite("camera.vfov", &[cam.vfov])?;
        finite("camera.lookfrom", &cam.lookfrom)?;
        finite("camera.lookat", &cam.lookat)?;
        finite("camera.vup", &cam.vup)?;
        finite("camera.defocus_angle", &[cam.defocus_angle])?;
        let lookfrom = vec3(cam.lookfrom);
        let lookat = vec3(cam.lookat);
        let focus_dist = match cam.focus_dist {
            Some(d) => {
                finite("camera.focus_dist", &[d])?;
                d as f32
            }
            None => {
                let d = glam::DVec3::from(cam.lookfrom).distance(cam.lookat.into());
                if !(d as f32).is_finite() {
                    return Err(SceneError::Camera(CameraError::Overflow));
                }
                d as f32
            }
        };
        let camera = Camera::new(
            &CameraSettings {
                vfov: cam.vfov as f32,
                lookfrom,
                lookat,
                vup: vec3(cam.vup),
                defocus_angle: cam.defocus_angle as f32,
                focus_dist,
            },
            settings.width,
            settings.height,
        )?;
        let background = match &desc.background {
            BackgroundDesc::Gradient { bottom, top } => Background::Gradient {
                bottom: color("background.bottom", *bottom)?,
                top: color("background.top", *top)?,
            },
            BackgroundDesc::Solid { color: c } => Background::Solid(color("background.color", *c)?),
        };

        let mut materials = Vec::with_capacity(desc.materials.len());
        let mut material_index = HashMap::with_capacity(desc.materials.len());
        for (name, m) in &desc.materials {
            material_index.insert(name.as_str(), materials.len() as u32);
            materials.push(compile_material(&format!("materials.{name}"), m)?);
        }

        let mut spheres = Vec::with_capacity(desc.objects.len());
        let mut surfaces = Vec::with_capacity(desc.objects.len());
        for (i, object) in desc.objects.iter().enumerate() {
            match object {
                ObjectDesc::Sphere {
                    center,
                    radius,
                    material,
                } => {
                    finite(format_args!("objects[{i}].center"), center)?;
                    finite(format_args!("objects[{i}].radius"), &[*radius])?;
                    if !(*radius as f32 > 0.0) {
                        return Err(invalid(
                            format!("objects[{i}].radius"),
                            format!("must be greater than 0, got {radius}"),
                        ));
                    }
                    // The intersection squares the radius and distances of
                    // the order of the centre's coordinates, in f32.
                    let extent = center.iter().fold(*radius, |m, c| m.max(c.abs()));
                    if extent > MAX_COORDINATE {
                        return Err(invalid(
                            format!("objects[{i}]"),
                            format!(
                                "centre and radius must be at most {MAX_COORDINATE:e} in size, so that their squares fit in f32"
                            ),
                        ));
                    }
                    let Some(&m) = material_index.get(material.as_str()) else {
                        return Err(SceneError::UnknownMaterial {
                            field: format!("objects[{i}].material"),
                            name: material.clone(),
                            known: desc.materials.keys().cloned().collect(),
                        });
                    };
                    let sphere = Sphere::new(vec3(*center), *radius as f32);
                    surfaces.push(Surface {
                        center: sphere.center,
                        inverse_radius: 1.0 / sphere.radius,
                        radius: sphere.radius,
                        material: m,
                    });
                    spheres.push(sphere);
                }
            }
        }
        let primitives: Vec<Primitive> = spheres.iter().map(|&s| Primitive::Sphere(s)).collect();
        let bvh = Bvh::new(&primitives);
        Ok(Scene {
            error_scale: error_scale(settings.epsilon),
            settings,
            camera,
            background,
            materials,
            spheres,
            bvh,
            surfaces,
        })
    }

    /// The nearest hit of `ray` within `interval`; the ray's direction must
    /// have unit length.
    #[inline(always)]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let hit = self.bvh.hit(ray, interval)?;
        Some(self.record(ray, hit))
    }

    /// The nearest hit within `interval` of each ray `rays[lanes[k]]` (1 to
    /// [`LANES`] of them), as [`Scene::hit`] would find it for each ray
    /// alone, in the order of `lanes`; `reference` is a ray close to all of
    /// them (see [`RayBundle`]). Entries beyond `lanes.len()` are `None`.
    #[inline(always)]
    pub fn hit_bundle(
        &self,
        rays: &[Ray],
        lanes: &[u8],
        reference: &Ray,
        interval: Interval,
    ) -> [Option<HitRecord>; LANES] {
        let hits = self
            .bvh
            .hit_bundle(&RayBundle::gather(rays, lanes), reference, interval);
        let mut records = [None; LANES];
        for (k, &i) in lanes.iter().enumerate() {
            records[k] = hits[k].map(|hit| self.record(&rays[usize::from(i)], hit));
        }
        records
    }

    /// The full record of a hit the BVH found.
    #[inline(always)]
    fn record(&self, ray: &Ray, hit: crate::geometry::bvh::Hit) -> HitRecord {
        let surface = &self.surfaces[hit.index as usize];
        let point = ray.at(hit.t);
        let outward = (point - surface.center) * surface.inverse_radius;
        let (normal, front_face) = crate::geometry::hit::face_normal(ray, outward);
        HitRecord {
            point,
            normal,
            t: hit.t,
            front_face,
            material: surface.material,
            object: hit.index,
            error: (point.abs().max_element() + surface.radius) * self.error_scale,
        }
    }

    /// Number of nodes in the acceleration structure.
    pub fn bvh_nodes(&self) -> usize {
        self.bvh.node_count()
    }

    /// Bytes of memory held by the acceleration structure.
    pub fn bvh_memory_bytes(&self) -> usize {
        self.bvh.memory_bytes()
    }
}

fn unknown_material_message(name: &str, known: &[String]) -> String {
    if known.is_empty() {
        format!("no material named \"{name}\": the scene defines no materials")
    } else {
        format!(
            "no material named \"{name}\"; defined materials: {}",
            known.join(", ")
        )
    }
}

fn compile_settings(desc: &SceneDesc) -> Result<Settings, SceneError> {
    let r = &desc.render;
    if r.width == 0 {
        return Err(invalid("render.width", "must be at least 1 pixel"));
    }
    let height = match r.height {
        Some(0) => return Err(invalid("render.height", "must be at least 1 pixel")),
        Some(h) => h,
        None => {
            finite("render.aspect_ratio", &[r.aspect_ratio])?;
            if !(r.aspect_ratio > 0.0) {
                return Err(invalid(
                    "render.aspect_ratio",
                    format!("must be greater than 0, got {}", r.aspect_ratio),
                ));
            }
            let h = (f64::from(r.width) / r.aspect_ratio).floor();
            if h > f64::from(u32::MAX) {
                return Err(invalid(
                    "render.aspect_ratio",
                    "gives an image taller than 4294967295 pixels",
                ));
            }
            (h as u32).max(1)
        }
    };
    let pixels = u64::from(r.width) * u64::from(height);
    if pixels > MAX_PIXELS {
        return Err(invalid(
            "render",
            format!(
                "image {}x{} has {pixels} pixels, more than the {MAX_PIXELS} lumen can hold in memory",
                r.width, height
            ),
        ));
    }
    if r.samples_per_pixel == 0 {
        return Err(invalid("render.samples_per_pixel", "must be at least 1"));
    }
    if r.max_depth == 0 {
        return Err(invalid(
            "render.max_depth",
            "must be at least 1 (the camera ray)",
        ));
    }
    finite("render.gamma", &[r.gamma])?;
    if !(r.gamma as f32 > 0.0) {
        return Err(invalid(
            "render.gamma",
            format!("must be greater than 0, got {}", r.gamma),
        ));
    }
    finite("render.epsilon", &[r.epsilon])?;
    if !(r.epsilon >= 0.0) {
        return Err(invalid(
            "render.epsilon",
            format!("must not be negative, got {}", r.epsilon),
        ));
    }
    Ok(Settings {
        width: r.width,
        height,
        samples_per_pixel: r.samples_per_pixel,
        max_depth: r.max_depth,
        seed: r.seed,
        sampling: r.sampling,
        gamma: r.gamma as f32,
        epsilon: r.epsilon as f32,
        shading: r.shading,
    })
}

fn compile_material(field: &str, m: &MaterialDesc) -> Result<Material, SceneError> {
    Ok(match m {
        MaterialDesc::Diffuse {
            albedo: a,
            bounce,
            attenuation,
        } => Material::Diffuse(Diffuse {
            albedo: albedo(&format!("{field}.albedo"), *a)?,
            bounce: match bounce {
                BounceDesc::Cube => BounceModel::Cube,
                BounceDesc::SphereVolume => BounceModel::SphereVolume,
                BounceDesc::Lambertian => BounceModel::Lambertian,
                BounceDesc::Hemisphere => BounceModel::Hemisphere,
            },
            attenuation: match attenuation {
                AttenuationDesc::Scale => Attenuation::Scale,
                AttenuationDesc::Absorb => Attenuation::Absorb,
            },
        }),
        MaterialDesc::Metal { albedo: a, fuzz } => {
            finite(format_args!("{field}.fuzz"), &[*fuzz])?;
            if !(0.0..=1.0).contains(fuzz) {
                return Err(invalid(
                    format!("{field}.fuzz"),
                    format!("must be in [0, 1], got {fuzz}"),
                ));
            }
            Material::Metal(Metal {
                albedo: albedo(&format!("{field}.albedo"), *a)?,
                fuzz: *fuzz as f32,
            })
        }
        MaterialDesc::Dielectric { ior, refract_only } => {
            finite(format_args!("{field}.ior"), &[*ior])?;
            if !(*ior as f32 > 0.0) {
                return Err(invalid(
                    format!("{field}.ior"),
                    format!("index of refraction must be greater than 0, got {ior}"),
                ));
            }
            Material::Dielectric(Dielectric {
                ior: *ior as f32,
                refract_only: *refract_only,
            })
        }
    })
}

/// Settings given on the command line that replace a scene's own.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Image width; the height follows the scene's aspect ratio.
    pub width: Option<u32>,
    /// Samples per pixel.
    pub samples_per_pixel: Option<u32>,
    /// Maximum path depth.
    pub max_depth: Option<u32>,
    /// Random seed.
    pub seed: Option<u64>,
}

impl Overrides {
    /// Replaces the description's settings by those given here.
    pub fn apply(&self, desc: &mut SceneDesc) {
        let r = &mut desc.render;
        if let Some(w) = self.width {
            // Keep an explicit height in proportion to the new width.
            if let Some(h) = r.height {
                let scaled = (u64::from(h) * u64::from(w)) / u64::from(r.width.max(1));
                r.height = Some(scaled.clamp(1, u64::from(u32::MAX)) as u32);
            }
            r.width = w;
        }
        if let Some(n) = self.samples_per_pixel {
            r.samples_per_pixel = n;
        }
        if let Some(d) = self.max_depth {
            r.max_depth = d;
        }
        if let Some(s) = self.seed {
            r.seed = s;
        }
    }
}
