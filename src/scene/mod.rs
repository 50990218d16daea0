//! Scenes: the description people write, the built-in scenes of the notes, and
//! the compiled form the renderer traces.

pub mod builtin;
mod compile;
pub mod desc;
pub mod file;
mod world;

pub use file::{export, hint, source};

pub use desc::SceneDesc;

use crate::camera::{Camera, CameraError};
use crate::geometry::bvh::Hit;
use crate::geometry::bvh_bundle::LANES;
use crate::geometry::{HitRecord, RayBundle, Sphere};
pub use crate::light::LightSelection;
use crate::light::{Environment, Lights};
use crate::material::Material;
use crate::math::{Color, Interval};
use crate::medium::Medium;
use crate::ray::Ray;
use crate::sampler::{Dim, Sampler};
use crate::texture::Texture;
use crate::volume::Volume;
use desc::{IntegratorDesc, SamplingDesc, ShadingDesc};
use thiserror::Error;
pub use world::PlacedShapes;
use world::{LightIds, World};

/// Largest magnitude of an object's coordinates and radius: the sphere test
/// squares lengths of this order in `f32` (whose maximum is about 3.4e38).
pub const MAX_COORDINATE: f64 = 1e18;

/// Largest accepted image, in pixels (e.g. 8192×8192). The film needs 52
/// bytes a pixel (104 with adaptive sampling) and a pass in flight keeps a
/// copy, so this caps the film's memory near 7.0 GB (14 GB adaptive):
/// larger images are refused, not attempted.
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
                CameraError::FocusDistance(_) | CameraError::Unresolved { .. } => {
                    "camera.focus_dist".into()
                }
                CameraError::DefocusAngle(_) => "camera.defocus_angle".into(),
                CameraError::EmptyImage(..) => "render".into(),
                CameraError::Overflow => "camera".into(),
                CameraError::NotFinite(name) => format!("camera.{name}"),
                CameraError::Shutter(..) => "camera.shutter".into(),
                CameraError::Crop(..) => "render.crop".into(),
                CameraError::NearClip(_) => "camera.near_clip".into(),
                CameraError::FarClip(..) => "camera.far_clip".into(),
                CameraError::OrthoHeight(_) | CameraError::OrthographicUnresolved { .. } => {
                    "camera.ortho_height".into()
                }
                CameraError::OrthographicLens(_) => "camera.defocus_angle".into(),
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
/// How paths gather light (see [`desc::IntegratorDesc`]).
pub type Integrator = IntegratorDesc;

/// Render settings after validation.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Image width in pixels (of the crop window, when cropped).
    pub width: u32,
    /// Image height in pixels (of the crop window, when cropped).
    pub height: u32,
    /// Where the image lies in the full image, when cropped: `[x, y]` of
    /// its top left pixel and the full image's width and height (as
    /// [`crate::camera::CameraSettings::crop`]).
    pub crop: Option<[u32; 4]>,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Maximum ray segments per path.
    pub max_depth: u32,
    /// Seed of the render.
    pub seed: u64,
    /// Where the render's random numbers come from.
    pub sampler: Sampling,
    /// How paths gather light.
    pub integrator: Integrator,
    /// How the `path` integrator chooses the light it samples.
    pub light_selection: LightSelection,
    /// Adaptive sampling: pixels stop once their estimated relative error
    /// is at most this (see [`crate::adaptive`]); `None` samples every pixel
    /// fully.
    pub noise_target: Option<f32>,
    /// Display gamma.
    pub gamma: f32,
    /// Feature buffers written beside the image (see [`crate::aov`]).
    pub aovs: Vec<crate::aov::Aov>,
    /// The sums of features the film keeps for them.
    pub layers: crate::aov::Layers,
    /// Whether the finished image is denoised (see [`crate::denoise`]).
    pub denoise: bool,
    /// The denoiser's settings the scene chooses (`render.denoiser`,
    /// `denoise_quality`, `denoise_prefilter`).
    pub denoise_choices: crate::denoise::Choices,
    /// Shadow-acne epsilon: how far along a ray leaving a surface that
    /// surface is not met again (0 when the scene gives none); see
    /// [`Scene::intersect_leaving`].
    pub epsilon: f32,
    /// Whether rays leave surfaces offset by the hit's rounding error (all
    /// but the notes' epsilon 0).
    pub offset: bool,
    /// What camera rays show.
    pub shading: Shading,
    /// The pixel filter, and a Gaussian's standard deviation.
    pub pixel_filter: (desc::PixelFilterDesc, Option<f64>),
}

/// A scene compiled for rendering: validated, with a BVH over its objects.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Render settings.
    pub settings: Settings,
    /// The camera, sized for the image.
    pub camera: Camera,
    /// What rays that escape the scene see: the environment.
    pub background: Environment,
    /// Material table indexed by [`HitRecord::material`].
    pub materials: Vec<Material>,
    /// The textures materials refer to.
    pub textures: Vec<Texture>,
    /// The spheres placed directly in the world, in description order.
    pub spheres: Vec<Sphere>,
    /// The mesh files the scene reads, with a hash of their content: part
    /// of the scene's identity (a checkpoint refuses a changed mesh).
    pub sources: Vec<MeshSource>,
    /// Counts of what the scene holds.
    pub stats: SceneStats,
    /// The emissive surfaces and the environment, to be sampled by
    /// next-event estimation.
    pub lights: Lights,
    light_ids: LightIds,
    /// The fog and smoke of the scene.
    pub media: Vec<Medium>,
    /// The media that fill what surfaces enclose, which materials name
    /// (see [`crate::volume`]).
    pub volumes: Vec<Volume>,
    /// The medium the camera stands in, by index in `volumes`.
    pub camera_medium: Option<u32>,
    /// Whether paths keep track of the medium they travel in, and cross
    /// interfaces and thin glass without a bounce: in scenes with
    /// `volumes` or interface materials.
    pub volumetric: bool,
    /// What each mesh file loaded holds, and what of it lumen does not
    /// render.
    pub reports: Vec<FileReport>,
    /// Whether some material is not all there (has an opacity), so that
    /// rays must look past the hits they find.
    cutouts: bool,
    world: World,
}

/// The most surfaces with an opacity a ray passes through before it
/// stops at the next, whatever that one's opacity (a bound on the work
/// of a ray through foliage).
const MAX_CUTOUTS: u32 = 64;

/// The most times a ray looks past the surface it leaves, met again closer
/// than the epsilon, before it falls back on ignoring every hit that close
/// (a sphere is met at most twice; more is rounding gone astray).
const MAX_REHITS: u32 = 4;

/// The smallest distance beyond a hit at `t` that is surely past it: a
/// little more than the rounding of its distance (an instance's hit is
/// found again in its own space, and its distance rounded twice).
#[inline]
fn beyond(t: f32) -> f32 {
    t + t.abs() * 4.0 * f32::EPSILON + f32::MIN_POSITIVE
}

/// A number in [0, 1) made from the ray and the distance of a hit on it:
/// whether a partly present surface stops the ray is decided by it, the
/// same for the same ray whatever the thread or the order of the work.
#[inline]
fn cutout_random(ray: &Ray, t: f32) -> f32 {
    let (o, d) = (ray.origin(), ray.direction);
    crate::rng::unit_hash([o.x, o.y, o.z, d.x, d.y, d.z, t])
}

/// A mesh file a scene reads.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct MeshSource {
    /// The file, as the scene names it.
    pub file: String,
    /// CRC-32 of its bytes.
    pub crc: u32,
    /// Its length in bytes.
    pub len: u64,
}

/// What a mesh file loaded for a scene holds.
#[derive(Clone, Debug, PartialEq)]
pub struct FileReport {
    /// The file, as the scene names it.
    pub file: String,
    /// Triangles in it (a mesh placed several times counts once).
    pub triangles: usize,
    /// Its materials.
    pub materials: usize,
    /// The images its materials map, and the bytes their texels take.
    pub images: usize,
    /// Bytes of the images' texels.
    pub image_bytes: usize,
    /// What the file holds that lumen does not render.
    pub warnings: Vec<String>,
}

impl FileReport {
    /// The report of `model`, read from `file`.
    pub fn of(file: &str, model: &crate::mesh::Model) -> FileReport {
        let mut images: Vec<&std::sync::Arc<crate::texture::Image>> = Vec::new();
        for map in model.materials.iter().flat_map(|m| m.maps()) {
            if !images.iter().any(|i| std::sync::Arc::ptr_eq(i, &map.image)) {
                images.push(&map.image);
            }
        }
        let image_bytes = images.iter().map(|i| i.heap_bytes()).sum();
        FileReport {
            file: file.to_string(),
            triangles: model.triangle_count(),
            materials: model.materials.len(),
            images: images.len(),
            image_bytes,
            warnings: model.warnings.clone(),
        }
    }
}

impl std::fmt::Display for FileReport {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
        write!(
            f,
            "{}: {}, {}, {} ({:.1} MB)",
            self.file,
            plural(self.triangles, "triangle"),
            plural(self.materials, "material"),
            plural(self.images, "texture image"),
            self.image_bytes as f64 / 1e6
        )
    }
}

/// Counts of what a compiled scene holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneStats {
    /// Triangles stored (a mesh placed several times counts once).
    pub triangles: u64,
    /// Triangles as placed (every instance counted).
    pub placed_triangles: u64,
    /// Instances of shared meshes (and of other transformed shapes).
    pub instances: u64,
    /// Zero-area triangles skipped while loading meshes.
    pub skipped_degenerate: u64,
    /// Bytes held by meshes, their trees and the scene's tree.
    pub geometry_bytes: u64,
}

impl Scene {
    /// The nearest hit of `ray` within `interval`; the ray's direction must
    /// have unit length.
    #[inline(always)]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let hit = self.intersect(ray, interval)?;
        Some(self.record(ray, hit))
    }

    /// The scene's shapes as placed in the world, numbered as the tree's
    /// items (see [`PlacedShapes`]), or `None` when some are placed by
    /// instances.
    pub fn placed_shapes(&self) -> Option<PlacedShapes> {
        self.world.placed_shapes()
    }

    /// Which primitive `ray` hits first within `interval`, and where along
    /// the ray, without working out the surface there ([`Scene::record`]
    /// does); the ray's direction must have unit length.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        if self.cutouts {
            return self.intersect_solid(ray, interval);
        }
        self.world.bvh.hit(ray, interval)
    }

    /// [`Scene::intersect`] where surfaces may be partly there: a hit where
    /// the surface is not is passed through.
    #[inline(never)]
    fn intersect_solid(&self, ray: &Ray, mut interval: Interval) -> Option<Hit> {
        for _ in 0..MAX_CUTOUTS {
            let hit = self.world.bvh.hit(ray, interval)?;
            if self.stops(ray, hit) {
                return Some(hit);
            }
            interval.min = beyond(hit.t);
        }
        self.world.bvh.hit(ray, interval)
    }

    /// Whether `hit` is the surface `from`, which the ray leaves, met again
    /// closer than the epsilon: the hit the epsilon is there to ignore.
    #[inline(always)]
    fn rehit(&self, hit: &Hit, from: Option<&Hit>) -> bool {
        hit.t <= self.settings.epsilon
            && from.is_some_and(|f| f.index == hit.index && f.sub == hit.sub)
    }

    /// The nearest hit of `ray` before `t_max` that counts, for a ray
    /// leaving the surface of hit `from` (`None`: a ray from the camera or
    /// from a particle of a medium). Every surface counts from distance 0
    /// except the one the ray leaves, which counts only beyond the
    /// epsilon: an epsilon applied to every surface would also pass over a
    /// wall meeting the one left at a corner, closer than it, and let the
    /// ray out of a closed room. The ray's direction must have unit length.
    #[inline(always)]
    pub fn intersect_leaving(&self, ray: &Ray, from: Option<&Hit>, t_max: f32) -> Option<Hit> {
        let mut hit = self.intersect(ray, Interval::new(0.0, t_max));
        self.keep_counted(ray, &mut hit, from, t_max);
        hit
    }

    /// Makes `hit`, the nearest hit of `ray` from distance 0 to `t_max` (as
    /// [`Scene::hit_bundle`] finds it), the hit that counts for a ray
    /// leaving the surface of hit `from`: it stays as it is, or when it is
    /// that surface met again closer than the epsilon, becomes the nearest
    /// beyond it that counts (see [`Scene::intersect_leaving`]). In place,
    /// so that a hit just stored whole is not rebuilt field by field and
    /// read back whole, which stalls the processor.
    #[inline(always)]
    pub fn keep_counted(&self, ray: &Ray, hit: &mut Option<Hit>, from: Option<&Hit>, t_max: f32) {
        if let Some(h) = *hit {
            if self.rehit(&h, from) {
                *hit = self.intersect_past(ray, h, from, t_max);
            }
        }
    }

    /// [`Scene::intersect_leaving`] after it met the surface left at
    /// `hit`: the nearest hit that counts beyond it (rays leave surfaces
    /// offset by their rounding, so that this is rare).
    #[cold]
    #[inline(never)]
    pub(crate) fn intersect_past(
        &self,
        ray: &Ray,
        mut hit: Hit,
        from: Option<&Hit>,
        t_max: f32,
    ) -> Option<Hit> {
        for _ in 0..MAX_REHITS {
            hit = self.intersect(ray, Interval::new(beyond(hit.t), t_max))?;
            if !self.rehit(&hit, from) {
                return Some(hit);
            }
        }
        self.intersect(ray, Interval::new(self.settings.epsilon, t_max))
    }

    /// Whether `ray`, leaving the surface of hit `from` (see
    /// [`Scene::intersect_leaving`]), hits anything that counts before
    /// `t_max`: a shadow ray's question.
    #[inline(always)]
    pub fn occluded_leaving(&self, ray: &Ray, from: Option<&Hit>, t_max: f32) -> bool {
        let interval = Interval::new(0.0, t_max);
        let any = if self.cutouts {
            self.intersect_solid(ray, interval)
        } else {
            self.world.bvh.any_hit(ray, interval)
        };
        match any {
            None => false,
            // Found first, not nearest: something else may lie before it.
            Some(hit) if self.rehit(&hit, from) => {
                self.intersect_leaving(ray, from, t_max).is_some()
            }
            Some(_) => true,
        }
    }

    /// Whether the surface `ray` meets at `hit` is there.
    #[inline]
    fn stops(&self, ray: &Ray, hit: Hit) -> bool {
        let record = self.record(ray, hit);
        let Some(opacity) = self.material(&record).opacity else {
            return true;
        };
        opacity.stops(&record, &self.textures, cutout_random(ray, hit.t))
    }

    /// The surface where `ray` meets `hit` (found by [`Scene::intersect`] or
    /// [`Scene::hit_bundle`] for this ray): point, normals, material, ….
    #[inline(always)]
    pub fn record(&self, ray: &Ray, hit: Hit) -> HitRecord {
        self.world.record(ray, hit)
    }

    /// The index in [`Scene::lights`] of the light `hit` met, if it is one
    /// that can be sampled.
    #[inline]
    pub fn light_of(&self, hit: &Hit) -> Option<usize> {
        self.light_ids.of(hit)
    }

    /// The material of the surface at `record`.
    #[inline(always)]
    pub fn material(&self, record: &HitRecord) -> &Material {
        &self.materials[record.material as usize]
    }

    /// Whether `ray` hits anything within `interval` (a shadow ray's
    /// question: any hit, not the nearest).
    #[inline(always)]
    pub fn occluded(&self, ray: &Ray, interval: Interval) -> bool {
        if self.cutouts {
            return self.intersect_solid(ray, interval).is_some();
        }
        self.world.bvh.occluded(ray, interval)
    }

    /// Where `ray`, before distance `t_max`, first meets a particle of one
    /// of the scene's media, and which medium: each medium draws the
    /// distance a ray gets into it, and the nearest event counts (the first
    /// of several independent exponential laws follows their sum's).
    #[inline]
    pub fn medium_event(
        &self,
        ray: &Ray,
        t_max: f32,
        sampler: &mut impl Sampler,
    ) -> Option<(f32, usize)> {
        let mut nearest: Option<(f32, usize)> = None;
        for (i, medium) in self.media.iter().enumerate() {
            let limit = nearest.map_or(t_max, |(t, _)| t);
            let Some(span) = medium.span(ray, limit) else {
                continue;
            };
            let u = sampler.get_1d(Dim::Medium);
            if let Some(t) = medium.distance_within(span, u) {
                nearest = Some((t, i));
            }
        }
        nearest
    }

    /// The fraction of light that crosses the scene's media along `ray`
    /// from 0 to `t_max` (1 where there are none).
    #[inline]
    pub fn transmittance(&self, ray: &Ray, t_max: f32) -> f32 {
        self.media
            .iter()
            .map(|m| m.transmittance(ray, t_max))
            .product()
    }

    /// The share of light, per channel, that gets along `ray` (leaving the
    /// surface of hit `from`, see [`Scene::intersect_leaving`]) to
    /// distance `t_max`, starting in `medium`: through the media it
    /// travels in, and straight through the interfaces and thin glass it
    /// crosses (see [`Material::straight_through`]), entering the medium
    /// beyond each; 0 where any other surface stands in the way. A shadow
    /// ray's question in a scene with [`volumes`](Scene::volumes); an
    /// unbiased estimate where a medium's density varies.
    pub fn transmittance_along(
        &self,
        ray: &Ray,
        from: Option<&Hit>,
        t_max: f32,
        mut medium: Option<u32>,
        sampler: &mut impl Sampler,
    ) -> Color {
        let (mut ray, mut from, mut left) = (*ray, from.copied(), t_max);
        let mut share = Color::ONE;
        for _ in 0..MAX_CUTOUTS {
            let hit = self.intersect_leaving(&ray, from.as_ref(), left);
            if let Some(m) = medium {
                let reach = hit.map_or(left, |h| h.t);
                share *= self.volumes[m as usize].transmittance(&ray, reach, sampler);
            }
            let Some(hit) = hit else {
                return share;
            };
            let record = self.record(&ray, hit);
            let material = self.material(&record);
            share *= material.straight_through(&record, -ray.direction, &self.textures);
            if share == Color::ZERO {
                return share;
            }
            medium = material.medium_beyond(&record, ray.direction, medium);
            left -= hit.t;
            ray = Ray::timed(
                record.spawn_origin(ray.direction),
                ray.direction,
                ray.time(),
            );
            from = Some(hit);
        }
        Color::ZERO
    }

    /// The nearest hit within `interval` of each ray `rays[lanes[k]]` (1 to
    /// [`LANES`] of them), as [`Scene::intersect`] would find it for each
    /// ray alone, in the order of `lanes`; `reference` is a ray close to all
    /// of them (see [`RayBundle`]). Entries beyond `lanes.len()` are `None`.
    /// The surfaces are left to [`Scene::record`], for the paths that need them.
    #[inline(always)]
    pub fn hit_bundle(
        &self,
        rays: &[Ray],
        lanes: &[u8],
        reference: &Ray,
        interval: Interval,
    ) -> [Option<Hit>; LANES] {
        self.world
            .bvh
            .hit_bundle(&RayBundle::gather(rays, lanes), reference, interval)
    }

    /// Whether rays are worth tracing as bundles ([`Scene::hit_bundle`]):
    /// in scenes of spheres only (see [`Bvh::spheres_only`](crate::geometry::Bvh::spheres_only)).
    #[inline(always)]
    pub fn bundles_pay_off(&self) -> bool {
        self.world.bvh.spheres_only() && !self.cutouts
    }

    /// Whether a pixel's camera rays are worth tracing as bundles
    /// ([`Scene::hit_bundle`]): in every scene without cut-outs (whose
    /// any-hit test goes ray by ray). They start together and go nearly the
    /// same way, so a bundle visits the nodes one ray would, and its rays
    /// nearly always meet every box's planes in the same order and share
    /// their triangle axes, which spares the tests their choices per lane:
    /// on the bunny the camera rays cost 0.85× what they cost one by one.
    /// Bounces part ways at once, and only spheres' bundles gain from them.
    #[inline(always)]
    pub fn camera_bundles_pay_off(&self) -> bool {
        !self.cutouts
    }

    /// The radius of the sphere a hit record's `object` names, if it is a
    /// sphere placed directly in the world.
    pub fn sphere_radius(&self, object: u32) -> Option<f32> {
        self.spheres.get(object as usize).map(|s| s.radius)
    }

    /// Number of nodes in the acceleration structure.
    pub fn bvh_nodes(&self) -> usize {
        self.world.bvh.node_count()
    }

    /// Bytes of memory held by the acceleration structure (the scene's tree
    /// and the trees of its instanced meshes).
    pub fn bvh_memory_bytes(&self) -> usize {
        self.world.bvh_memory_bytes()
    }
}

fn unknown_material_message(name: &str, known: &[String]) -> String {
    if known.is_empty() {
        format!("no material named \"{name}\": the scene defines no materials")
    } else {
        format!(
            "no material named \"{name}\"; defined materials: {}",
            hint::listing(name, known.iter().map(String::as_str), str::to_string)
        )
    }
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
    /// The sampler.
    pub sampler: Option<Sampling>,
    /// The integrator.
    pub integrator: Option<Integrator>,
    /// How lights are chosen.
    pub light_selection: Option<LightSelection>,
    /// The noise target of adaptive sampling.
    pub noise_target: Option<f64>,
    /// Feature buffers written beside the image, in place of the scene's.
    pub aovs: Option<Vec<crate::aov::Aov>>,
    /// Denoise the finished image, whatever the scene says.
    pub denoise: bool,
    /// Lets every mesh object's files lie outside its folder, as
    /// `allow_outside = true` on each would.
    pub allow_outside: bool,
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
        if let Some(s) = self.sampler {
            r.sampler = s;
        }
        if let Some(i) = self.integrator {
            r.integrator = i;
        }
        if let Some(l) = self.light_selection {
            r.light_selection = l;
        }
        if let Some(t) = self.noise_target {
            r.noise_target = Some(t);
        }
        if let Some(aovs) = &self.aovs {
            r.aovs.clone_from(aovs);
        }
        if self.denoise {
            r.denoise = true;
        }
        if self.allow_outside {
            for object in &mut desc.objects {
                if let desc::ObjectDesc::Mesh { allow_outside, .. } = object {
                    *allow_outside = true;
                }
            }
        }
    }
}
