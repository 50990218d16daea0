//! Turning a scene description into a [`Scene`]: settings, camera,
//! background, materials and objects checked and compiled; meshes loaded,
//! placed once in world space or shared by instances.

use super::desc::{
    BackgroundDesc, BoundaryDesc, CameraDesc, ColorDesc, EnvironmentLayoutDesc, GltfCamera,
    MaterialDesc, ObjectDesc, PixelFilterDesc, ScalarDesc, ScaleDesc, TransformDesc, MAX_SEED,
};
use super::world::{Group, Mesh, PlacedGroup, Rounding, Shapes, Surface, World};
use super::{
    invalid, FileReport, MeshSource, Scene, SceneDesc, SceneError, SceneStats, Settings,
    MAX_COORDINATE, MAX_PIXELS,
};
use crate::camera::{Camera, CameraError, CameraSettings, Projection};
use crate::filter::PixelFilter;
use crate::geometry::bvh_build::Aabb;
use crate::geometry::quadric;
use crate::geometry::transform::{Transform, TransformStep};
use crate::geometry::{Quad, Quadric, QuadricForm, Sphere};
use crate::light::{Environment, EnvironmentMap, Lights};
use crate::material::param::{self, ColorRange, Range};
use crate::material::{ColorParam, Invalid, Material, ScalarParam, Textures};
use crate::math::{Color, Vec3};
use crate::medium::{Boundary, Medium};
use crate::mesh::{self, Model, ModelView, TriangleMesh, NO_MATERIAL};
use crate::texture::{Channels, ImageMap, Texture};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use textures::{read_image, ColorRef, TextureKind, TextureTable};

mod file_material;
mod media;
mod textures;

/// The factor of [`HitRecord::error`]: the hit point and its offset from the
/// centre are each rounded to about 2⁻²⁴ of their size (the point's
/// coordinates, the radius); 2⁻²⁰ leaves a wide margin over their sum.
/// Without `offset` (epsilon 0, the notes' demonstration of shadow acne) it
/// is 0, and rays leave from the hit point itself, as in the notes.
fn error_scale(offset: bool) -> f32 {
    if offset {
        1.0 / (1u32 << 20) as f32
    } else {
        0.0
    }
}

fn vec3(t: [f64; 3]) -> Vec3 {
    Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32)
}

/// Accepts numbers that stay finite once converted to the renderer's `f32`.
/// `field` is only formatted when a number is refused (scene files may hold
/// millions of spheres).
pub(crate) fn finite(field: impl std::fmt::Display, values: &[f64]) -> Result<(), SceneError> {
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

pub(super) fn color(field: &str, c: [f64; 3]) -> Result<Color, SceneError> {
    finite(field, &c)?;
    if c.iter().any(|&v| v < 0.0) {
        return Err(invalid(
            field,
            format!("colour components must not be negative, got {c:?}"),
        ));
    }
    Ok(vec3(c))
}

pub(super) fn albedo(field: &str, c: [f64; 3]) -> Result<Color, SceneError> {
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
    /// Validates and compiles a scene description; mesh files are found
    /// relative to the working directory.
    pub fn from_desc(desc: &SceneDesc) -> Result<Scene, SceneError> {
        Self::from_desc_in(desc, Path::new(""))
    }

    /// Validates and compiles a scene description whose mesh files are
    /// relative to `base` (the scene file's directory).
    pub fn from_desc_in(desc: &SceneDesc, base: &Path) -> Result<Scene, SceneError> {
        let settings = compile_settings(desc)?;
        // Checked before the objects are read (which may be slow); built
        // when it is known whether anything moves.
        compile_camera(&desc.camera, &settings, true)?;
        let mut materials = Vec::with_capacity(desc.materials.len());
        let mut material_index = HashMap::with_capacity(desc.materials.len());
        let mut table = TextureTable::new(&desc.textures, base)?;
        let mut sources = Vec::new();
        let mut context = MaterialTextures {
            textures: &mut table,
            sources: &mut sources,
            materials: &desc.materials,
            resolving: Vec::new(),
        };
        let enclosed = media::Media::compile(desc, base)?;
        for (name, m) in &desc.materials {
            material_index.insert(name.as_str(), materials.len() as u32);
            context.resolving = vec![name.as_str()];
            let field = format!("materials.{name}");
            let mut material = m
                .compile(&field, &mut context)
                .map_err(|e| invalid(e.field, e.message))?;
            material.media = enclosed.of_material(&field, m)?;
            materials.push(material);
        }
        let camera_medium = enclosed.of_camera(desc.camera.medium.as_deref())?;
        context.resolving.clear();
        let mut light_sources = Vec::with_capacity(desc.lights.len());
        for (i, l) in desc.lights.iter().enumerate() {
            light_sources.push(
                l.compile(&format!("lights[{i}]"), &mut context)
                    .map_err(|e| invalid(e.field, e.message))?,
            );
        }
        let textures = table.textures;
        let mut objects = Objects {
            desc,
            base,
            materials,
            material_index,
            textures,
            top: Shapes::default(),
            spheres: Vec::with_capacity(desc.objects.len()),
            groups: Vec::new(),
            instances: Vec::new(),
            media: Vec::new(),
            models: HashMap::new(),
            read_ahead: read_mesh_files(desc, base),
            placements: Vec::new(),
            sources,
            stats: SceneStats::default(),
            reports: Vec::new(),
        };
        for (i, object) in desc.objects.iter().enumerate() {
            objects.add(i, object)?;
        }
        objects.place_meshes()?;
        let gltf_camera = objects.gltf_camera()?;
        let background = compile_background(&desc.background, base, &mut objects.sources)?;
        let Objects {
            materials,
            textures,
            top,
            spheres,
            groups,
            instances,
            media,
            sources,
            mut stats,
            reports,
            models,
            ..
        } = objects;
        // What the scene did not take of the files' meshes is freed before
        // the tree is built, whose peak it would add to.
        drop(models);
        let moves = instances.iter().any(|p| p.motion != Vec3::ZERO);
        let camera = compile_camera(
            gltf_camera.as_ref().unwrap_or(&desc.camera),
            &settings,
            moves,
        )?;
        let rounding = Rounding {
            scale: error_scale(settings.offset),
            onto_spheres: desc.render.epsilon.is_none(),
        };
        let world = World::new(top, groups, &instances, rounding)
            .map_err(|e| invalid("objects", e.to_string()))?;
        stats.instances = instances.len() as u64;
        stats.geometry_bytes = world.memory_bytes() as u64;
        let (lights, light_ids) = world.lights(&materials);
        // A smooth sky is found as well by the bounces, which follow the
        // surface's cosine, as by a shadow ray drawn over the whole sphere;
        // the shadow rays would cost time for nothing (half the efficiency
        // on the bunny under the default sky). An image, with its sun, is
        // sampled.
        let sampled = desc
            .render
            .sample_background
            .unwrap_or(matches!(background, Environment::Map(_)));
        let lights = Lights::with_sources(
            lights,
            light_sources,
            textures.clone(),
            sampled.then(|| background.clone()),
            world.bounding_radius(),
            settings.light_selection,
        );
        let cutouts = materials.iter().any(|m| m.opacity.is_some());
        let volumes = enclosed.volumes;
        let volumetric = !volumes.is_empty() || materials.iter().any(Material::is_interface);
        Ok(Scene {
            volumes,
            camera_medium,
            volumetric,
            reports,
            settings,
            camera,
            background,
            cutouts,
            materials,
            textures,
            spheres,
            sources,
            stats,
            lights,
            light_ids,
            media,
            world,
        })
    }
}

/// The environment of `desc`; an image is read relative to `base`, and
/// recorded in `sources`.
fn compile_background(
    desc: &BackgroundDesc,
    base: &Path,
    sources: &mut Vec<MeshSource>,
) -> Result<Environment, SceneError> {
    Ok(match desc {
        BackgroundDesc::Gradient { bottom, top } => Environment::Gradient {
            bottom: color("background.bottom", *bottom)?,
            top: color("background.top", *top)?,
        },
        BackgroundDesc::Solid { color: c } => Environment::Solid(color("background.color", *c)?),
        BackgroundDesc::Image {
            file,
            rotation,
            intensity,
            rows_at_poles,
            layout: EnvironmentLayoutDesc::EqualArea,
            frame,
        } => {
            finite("background.intensity", &[*intensity])?;
            if *intensity < 0.0 {
                return Err(invalid(
                    "background.intensity",
                    format!("must not be negative, got {intensity}"),
                ));
            }
            if *rotation != 0.0 || *rows_at_poles {
                return Err(invalid(
                    "background.layout",
                    "an equal-area map turns by its `frame`; `rotation` and `rows_at_poles` are for equirectangular maps",
                ));
            }
            let axes = frame_axes(frame)?.unwrap_or([Vec3::X, Vec3::Y, Vec3::Z]);
            let image = read_image("background.file", base, file, sources)?;
            match EnvironmentMap::equal_area(image, axes, *intensity as f32)
                .map_err(|e| invalid("background.file", format!("{file}: {e}")))?
            {
                Some(map) => Environment::Map(Arc::new(map)),
                None => Environment::Solid(Color::ZERO),
            }
        }
        BackgroundDesc::Image {
            file,
            rotation,
            intensity,
            rows_at_poles,
            frame,
            ..
        } => {
            finite("background.rotation", &[*rotation])?;
            finite("background.intensity", &[*intensity])?;
            if *intensity < 0.0 {
                return Err(invalid(
                    "background.intensity",
                    format!("must not be negative, got {intensity}"),
                ));
            }
            let axes = frame_axes(frame)?;
            let image = read_image("background.file", base, file, sources)?;
            match EnvironmentMap::new(image, *rotation as f32, *intensity as f32) {
                Some(mut map) => {
                    if *rows_at_poles {
                        map = map.with_rows_at_poles();
                    }
                    if let Some(axes) = axes {
                        map = map.with_frame(axes);
                    }
                    Environment::Map(Arc::new(map))
                }
                // Black everywhere: it sheds no light.
                None => Environment::Solid(Color::ZERO),
            }
        }
    })
}

/// The camera of `desc`. Where nothing `moves`, every ray is traced as the
/// shutter opens: drawing a time would change nothing but the samples.
fn compile_camera(
    cam: &CameraDesc,
    settings: &Settings,
    moves: bool,
) -> Result<Camera, SceneError> {
    finite("camera.vfov", &[cam.vfov])?;
    finite("camera.lookfrom", &cam.lookfrom)?;
    finite("camera.lookat", &cam.lookat)?;
    finite("camera.vup", &cam.vup)?;
    finite("camera.defocus_angle", &[cam.defocus_angle])?;
    finite("camera.shutter", &cam.shutter)?;
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
    let filter = compile_filter(&settings.pixel_filter)?;
    Ok(Camera::new(
        &CameraSettings {
            vfov: cam.vfov as f32,
            lookfrom: vec3(cam.lookfrom),
            lookat: vec3(cam.lookat),
            vup: vec3(cam.vup),
            defocus_angle: cam.defocus_angle as f32,
            focus_dist,
            shutter: if moves {
                cam.shutter.map(|t| t as f32)
            } else {
                [cam.shutter[0] as f32; 2]
            },
            mirror: cam.mirror,
            near_clip: cam.near_clip as f32,
            far_clip: cam.far_clip.map_or(f32::INFINITY, |f| f as f32),
            crop: settings.crop,
            projection: match cam.ortho_height {
                None => Projection::Perspective,
                Some(height) => {
                    finite("camera.ortho_height", &[height])?;
                    Projection::Orthographic {
                        height: height as f32,
                    }
                }
            },
        },
        settings.width,
        settings.height,
    )?
    .with_filter(filter))
}

/// The pixel filter `[render]` asks for.
fn compile_filter(desc: &(PixelFilterDesc, Option<f64>)) -> Result<PixelFilter, SceneError> {
    match *desc {
        (PixelFilterDesc::Box, None) => Ok(PixelFilter::Box),
        (PixelFilterDesc::Box, Some(_)) => Err(invalid(
            "render.filter_stddev",
            "is a Gaussian filter's; give pixel_filter = \"gaussian\"",
        )),
        (PixelFilterDesc::Gaussian, stddev) => {
            let s = stddev.unwrap_or(0.5);
            if !(s > 0.0 && s <= 16.0) {
                return Err(invalid(
                    "render.filter_stddev",
                    format!("must be above 0 and at most 16 pixels, got {s}"),
                ));
            }
            Ok(PixelFilter::gaussian(s as f32))
        }
    }
}

/// The key of a mesh file read with `options` among the loaded models.
/// A file read with its texture coordinates turned over is another model
/// (no file's name holds a NUL).
fn model_key(path: &Path, options: mesh::LoadOptions) -> PathBuf {
    if options.flip_v {
        let mut key = path.to_path_buf().into_os_string();
        key.push("\0flip_v");
        PathBuf::from(key)
    } else {
        path.to_path_buf()
    }
}

/// The load options of a mesh object (`None` for other objects).
fn mesh_options(object: &ObjectDesc) -> Option<(&str, mesh::LoadOptions)> {
    match object {
        ObjectDesc::Mesh {
            file,
            allow_outside,
            flip_v,
            ..
        } => Some((
            file,
            mesh::LoadOptions {
                allow_outside: *allow_outside,
                flip_v: *flip_v,
            },
        )),
        _ => None,
    }
}

/// Most bytes of mesh files [`read_mesh_files`] reads at once: beyond,
/// they are read one at a time, as the objects are compiled, so that a
/// mistake in an earlier object is reported before gigabytes are read.
const READ_AHEAD_MAX_BYTES: u64 = 256 << 20;

/// How many times its size on disk a mesh file is counted as taking once
/// read (a glTF file's textures decode to some 25 times their size), for
/// [`read_mesh_files`]' bound: the memory checks of files read at once all
/// see the same free memory, so together they must fit in it with room.
const READ_AHEAD_GROWTH: u64 = 64;

/// The scene's mesh files read on all threads at once, by their key,
/// when it names more than one and they are small enough (see
/// [`READ_AHEAD_MAX_BYTES`], [`READ_AHEAD_GROWTH`]): a file's own reading
/// is only partly parallel (its textures are decoded together, its JSON
/// and meshes are not). Each is taken by [`Objects::load`] when its first
/// object is compiled, so that what goes wrong is still reported in the
/// objects' order.
fn read_mesh_files(
    desc: &SceneDesc,
    base: &Path,
) -> HashMap<PathBuf, Result<Model, mesh::MeshError>> {
    use rayon::prelude::*;
    let mut seen = std::collections::HashSet::new();
    let mut files: Vec<(PathBuf, PathBuf, mesh::LoadOptions)> = Vec::new();
    let mut bytes = 0u64;
    for (file, options) in desc.objects.iter().filter_map(mesh_options) {
        let path = model_path(base, file);
        let key = model_key(&path, options);
        if seen.insert(key.clone()) {
            bytes = bytes.saturating_add(std::fs::metadata(&path).map_or(0, |m| m.len()));
            if bytes > READ_AHEAD_MAX_BYTES {
                return HashMap::new();
            }
            files.push((key, path, options));
        }
    }
    let room = crate::memory::available().unwrap_or(u64::MAX);
    if files.len() < 2 || bytes.saturating_mul(READ_AHEAD_GROWTH) > room {
        return HashMap::new();
    }
    files
        .into_par_iter()
        .map(|(key, path, options)| (key, mesh::load_with(&path, options)))
        .collect()
}

/// A loaded mesh file, shared by every object that names it.
struct LoadedModel {
    model: Model,
    /// Scene material of each of the file's materials, once mapped.
    materials: Vec<Option<u32>>,
}

/// Most meshes a scene places (each mesh object once per node of its file
/// that holds a mesh): 2^24.
pub const MAX_INSTANCES: u64 = 1 << 24;

/// Memory a placed mesh takes while the scene is built and rendered, at
/// most: its placement, its instance and its share of the tree over the
/// instances (about 420 bytes measured, with room).
const BYTES_PER_PLACEMENT: u64 = 512;

/// How a mesh's surface is taken from its file.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
struct MeshSurface {
    /// Its vertex normals interpolated (or every triangle flat).
    smooth: bool,
    /// Its outside turned in, against the file's winding.
    flipped: bool,
}

/// Which mesh: (file, mesh of the file, how its surface is taken).
type MeshKey = (PathBuf, usize, MeshSurface);

/// One placement of one mesh of a file.
struct Placement {
    key: MeshKey,
    transform: Transform,
    /// The material that replaces the file's, if the object names one.
    material: Option<u32>,
    /// How far it moves from time 0 to time 1.
    motion: Vec3,
    /// The object that places it.
    object: usize,
}

/// The objects being compiled.
struct Objects<'a> {
    desc: &'a SceneDesc,
    base: &'a Path,
    materials: Vec<Material>,
    material_index: HashMap<&'a str, u32>,
    textures: Vec<Texture>,
    top: Shapes,
    spheres: Vec<Sphere>,
    groups: Vec<Group>,
    instances: Vec<PlacedGroup>,
    media: Vec<Medium>,
    models: HashMap<PathBuf, LoadedModel>,
    /// Mesh files read before the objects are compiled, not yet taken.
    read_ahead: HashMap<PathBuf, Result<Model, mesh::MeshError>>,
    placements: Vec<Placement>,
    sources: Vec<MeshSource>,
    stats: SceneStats,
    reports: Vec<FileReport>,
}

impl<'a> Objects<'a> {
    /// Whether material `m`'s texture uses the surface's (u, v), which
    /// spheres then work out.
    fn uses_uv(&self, m: u32) -> bool {
        self.materials[m as usize].uses_uv(&self.textures)
    }

    fn material(&self, i: usize, name: &str) -> Result<u32, SceneError> {
        self.material_index
            .get(name)
            .copied()
            .ok_or_else(|| SceneError::UnknownMaterial {
                field: format!("objects[{i}].material"),
                name: name.to_string(),
                known: self.desc.materials.keys().cloned().collect(),
            })
    }

    fn add(&mut self, i: usize, object: &'a ObjectDesc) -> Result<(), SceneError> {
        let (transform, motion) = compile_transform(i, object.transform())?;
        if motion == Vec3::ZERO
            || matches!(
                object,
                ObjectDesc::Mesh { .. } | ObjectDesc::Triangles { .. }
            )
        {
            return self.add_placed(i, object, &transform, motion);
        }
        if matches!(object, ObjectDesc::Medium { .. }) {
            return Err(invalid(
                format!("objects[{i}].transform"),
                "a medium cannot move: a `motion` step is for surfaces",
            ));
        }
        // A moving shape is traced in a tree of its own, which an instance
        // carries: its shapes are gathered apart from the scene's.
        let top = std::mem::take(&mut self.top);
        let (spheres, instances) = (self.spheres.len(), self.instances.len());
        let added = self.add_placed(i, object, &transform, motion);
        let shapes = std::mem::replace(&mut self.top, top);
        added?;
        self.spheres.truncate(spheres);
        for placed in &mut self.instances[instances..] {
            placed.motion = motion;
        }
        if !(shapes.spheres.is_empty() && shapes.quads.is_empty() && shapes.quadrics.is_empty()) {
            let group =
                Group::new(shapes).map_err(|e| invalid(format!("objects[{i}]"), e.to_string()))?;
            self.groups.push(group);
            self.instances.push(PlacedGroup {
                group: self.groups.len() as u32 - 1,
                transform: Transform::IDENTITY,
                material: None,
                motion,
            });
        }
        Ok(())
    }

    /// Adds object `i` placed by `transform`; a mesh moves by `motion`
    /// (other shapes are moved by [`add`](Self::add)).
    fn add_placed(
        &mut self,
        i: usize,
        object: &'a ObjectDesc,
        transform: &Transform,
        motion: Vec3,
    ) -> Result<(), SceneError> {
        let transform = *transform;
        match object {
            ObjectDesc::Sphere {
                center,
                radius,
                material,
                flip_normals,
                ..
            } => {
                finite(format_args!("objects[{i}].center"), center)?;
                positive(format_args!("objects[{i}].radius"), *radius)?;
                // The intersection squares the radius and distances of the
                // order of the centre's coordinates, in f32.
                let extent = center.iter().fold(*radius, |m, c| m.max(c.abs()));
                if extent > MAX_COORDINATE {
                    return Err(invalid(
                        format!("objects[{i}]"),
                        format!(
                            "centre and radius must be at most {MAX_COORDINATE:e} in size, so that their squares fit in f32"
                        ),
                    ));
                }
                let m = self.material(i, material)?;
                let sphere = Sphere::new(vec3(*center), *radius as f32);
                // A textured sphere that is turned keeps its own space, so
                // that its texture turns with it.
                let uv = self.uses_uv(m);
                let keeps_texture = |scale: f32| {
                    !uv || [Vec3::X, Vec3::Y, Vec3::Z]
                        .iter()
                        .all(|&e| (transform.vector(e) / scale - e).length() <= 1e-6)
                };
                match similarity(&transform).filter(|&scale| keeps_texture(scale)) {
                    Some(scale) => {
                        let placed =
                            Sphere::new(transform.point(sphere.center), sphere.radius * scale);
                        if !placed.center.is_finite() || !(placed.radius.is_finite()) {
                            return Err(out_of_range(i));
                        }
                        let extent = placed.center.abs().max_element().max(placed.radius);
                        placed_within(i, "the sphere", extent)?;
                        self.top
                            .spheres
                            .push(Surface::new(&placed, m, uv, *flip_normals));
                        self.spheres.push(placed);
                    }
                    None => {
                        // Stretched unevenly (an ellipsoid) or turned with
                        // its texture: traced as the sphere in its own
                        // space.
                        let (min, max) = sphere.bounds();
                        let placed = transform.bounds(&Aabb { min, max });
                        if !(placed.min.is_finite() && placed.max.is_finite()) {
                            return Err(out_of_range(i));
                        }
                        let extent = placed.min.abs().max(placed.max.abs()).max_element();
                        placed_within(i, "the sphere", extent)?;
                        let mut shapes = Shapes::default();
                        // Placed by an instance, whose material may be
                        // another: (u, v) always.
                        shapes
                            .spheres
                            .push(Surface::new(&sphere, m, true, *flip_normals));
                        let group = Group::new(shapes)
                            .map_err(|e| invalid(format!("objects[{i}]"), e.to_string()))?;
                        self.groups.push(group);
                        self.instances.push(PlacedGroup {
                            group: self.groups.len() as u32 - 1,
                            transform,
                            material: None,
                            motion: Vec3::ZERO,
                        });
                    }
                }
            }
            ObjectDesc::Quad {
                corner,
                u,
                v,
                material,
                flip_normals,
                ..
            } => {
                for (name, value) in [("corner", corner), ("u", u), ("v", v)] {
                    finite(format_args!("objects[{i}].{name}"), value)?;
                }
                let extent = (0..3)
                    .map(|k| {
                        let far = corner[k] + u[k].min(0.0) + v[k].min(0.0);
                        let near = corner[k] + u[k].max(0.0) + v[k].max(0.0);
                        far.abs().max(near.abs()).max(u[k].abs()).max(v[k].abs())
                    })
                    .fold(0.0, f64::max);
                if extent > MAX_COORDINATE {
                    return Err(invalid(
                        format!("objects[{i}]"),
                        format!(
                            "corner and edges must be at most {MAX_COORDINATE:e} in size, so that products of two coordinates fit in f32"
                        ),
                    ));
                }
                let m = self.material(i, material)?;
                let quad =
                    place_quad(i, "the quad", &transform, vec3(*corner), vec3(*u), vec3(*v))?;
                self.top.quads.push((turned(quad, *flip_normals), m));
            }
            ObjectDesc::Disk {
                center,
                normal,
                radius,
                material,
                flip_normals,
                ..
            } => {
                let field = |name: &str| format!("objects[{i}].{name}");
                finite(field("center"), center)?;
                finite(field("normal"), normal)?;
                let radius = positive(field("radius"), *radius)?;
                let n = glam::DVec3::from(*normal);
                if n == glam::DVec3::ZERO {
                    return Err(invalid(field("normal"), "must not be zero"));
                }
                let unit = quadric::disk_placement(*center, n.normalize(), radius);
                let m = self.material(i, material)?;
                let form = (QuadricForm::Disk, *flip_normals);
                self.place_quadric(i, form, unit, &transform, m)?;
            }
            ObjectDesc::Cylinder {
                p0,
                p1,
                radius,
                material,
                flip_normals,
                ..
            } => {
                let field = |name: &str| format!("objects[{i}].{name}");
                finite(field("p0"), p0)?;
                finite(field("p1"), p1)?;
                let radius = positive(field("radius"), *radius)?;
                let unit = quadric::cylinder_placement(*p0, *p1, radius).ok_or_else(|| {
                    invalid(field("p1"), "must not be p0: the cylinder has no length")
                })?;
                let m = self.material(i, material)?;
                let form = (QuadricForm::Cylinder, *flip_normals);
                self.place_quadric(i, form, unit, &transform, m)?;
            }
            ObjectDesc::Box {
                min,
                max,
                material,
                flip_normals,
                ..
            } => {
                finite(format_args!("objects[{i}].min"), min)?;
                finite(format_args!("objects[{i}].max"), max)?;
                if !(0..3).all(|k| (min[k] as f32) < (max[k] as f32)) {
                    return Err(invalid(
                        format!("objects[{i}].max"),
                        format!("must be greater than min on every axis, got min {min:?} and max {max:?}"),
                    ));
                }
                if min.iter().chain(max).any(|c| c.abs() > MAX_COORDINATE) {
                    return Err(invalid(
                        format!("objects[{i}]"),
                        format!(
                            "min and max must be at most {MAX_COORDINATE:e} in size, so that products of two coordinates fit in f32"
                        ),
                    ));
                }
                let m = self.material(i, material)?;
                for (q, u, v) in box_faces(vec3(*min), vec3(*max)) {
                    let quad = place_quad(i, "the box", &transform, q, u, v)?;
                    self.top.quads.push((turned(quad, *flip_normals), m));
                }
            }
            ObjectDesc::Medium {
                boundary,
                density,
                albedo: colour,
                ..
            } => {
                let field = |name: &str| format!("objects[{i}].{name}");
                positive(field("density"), *density)?;
                let albedo = albedo(&field("albedo"), *colour)?;
                let shape = match boundary {
                    BoundaryDesc::Sphere { center, radius } => {
                        finite(field("boundary.center"), center)?;
                        positive(field("boundary.radius"), *radius)?;
                        Boundary::Sphere {
                            center: vec3(*center),
                            radius: *radius as f32,
                        }
                    }
                    BoundaryDesc::Box { min, max } => {
                        finite(field("boundary.min"), min)?;
                        finite(field("boundary.max"), max)?;
                        if !(0..3).all(|k| (min[k] as f32) < (max[k] as f32)) {
                            return Err(invalid(
                                field("boundary.max"),
                                format!("must be greater than min on every axis, got min {min:?} and max {max:?}"),
                            ));
                        }
                        Boundary::Box {
                            min: vec3(*min),
                            max: vec3(*max),
                        }
                    }
                };
                self.media
                    .push(Medium::new(shape, transform, *density as f32, albedo));
            }
            ObjectDesc::Mesh {
                file,
                material,
                smooth,
                part,
                flip_normals,
                ..
            } => {
                let override_material = material
                    .as_deref()
                    .map(|name| self.material(i, name))
                    .transpose()?;
                let (_, options) = mesh_options(object).expect("a mesh object");
                let path = self.load(i, file, options)?;
                self.place(
                    i,
                    file,
                    (path, *part),
                    override_material,
                    MeshSurface {
                        smooth: *smooth,
                        flipped: *flip_normals,
                    },
                    &transform,
                    motion,
                )?;
            }
            ObjectDesc::Triangles {
                positions,
                indices,
                normals,
                uvs,
                material,
                flip_normals,
                ..
            } => {
                let material = self.material(i, material)?;
                let model = mesh::Model::from_arrays(
                    positions.iter().map(|p| p.map(|x| x as f32)).collect(),
                    indices,
                    normals
                        .as_ref()
                        .map(|n| n.iter().map(|p| p.map(|x| x as f32)).collect()),
                    uvs.as_ref()
                        .map(|t| t.iter().map(|t| t.map(|x| x as f32)).collect()),
                )
                .map_err(|e| invalid(format!("objects[{i}]"), e))?;
                self.stats.skipped_degenerate += model.skipped_degenerate as u64;
                // No file has this name: a path cannot hold a NUL.
                let path = PathBuf::from(format!("\0objects[{i}]"));
                self.models.insert(
                    path.clone(),
                    LoadedModel {
                        model,
                        materials: vec![None],
                    },
                );
                let label = format!("the triangles of objects[{i}]");
                let surface = MeshSurface {
                    smooth: normals.is_some(),
                    flipped: *flip_normals,
                };
                self.place(
                    i,
                    &label,
                    (path, None),
                    Some(material),
                    surface,
                    &transform,
                    motion,
                )?;
            }
        }
        Ok(())
    }

    /// Adds the unit `form` placed by `unit` (a matrix, row by row) and
    /// then by `transform`, its outside turned in if `inward`, in material
    /// `m`: for object `i`.
    fn place_quadric(
        &mut self,
        i: usize,
        (form, inward): (QuadricForm, bool),
        unit: [[f64; 4]; 4],
        transform: &Transform,
        m: u32,
    ) -> Result<(), SceneError> {
        let matrix = TransformStep::Matrix(unit);
        let what = match form {
            QuadricForm::Disk => "the disk",
            QuadricForm::Cylinder => "the cylinder",
        };
        let own = Transform::from_steps(&[matrix]).map_err(|e| {
            invalid(
                format!("objects[{i}]"),
                format!("{what} is too thin or too large: {}", e.message),
            )
        })?;
        let placed = own.then(transform).ok_or_else(|| {
            invalid(
                format!("objects[{i}].transform"),
                format!("flattens {what} or places it beyond the range of f32"),
            )
        })?;
        let quadric = Quadric::new(form, &placed).facing_in(inward);
        let b = quadric.bounds();
        if !(b.min.is_finite() && b.max.is_finite()) {
            return Err(out_of_range(i));
        }
        placed_within(i, what, b.min.abs().max(b.max.abs()).max_element())?;
        self.top.quadrics.push((quadric, m));
        Ok(())
    }

    /// Places every mesh of the loaded model at `path` (`file` names it in
    /// messages), or only its mesh `part`, by `transform`, moving by
    /// `motion`, in `material` or the model's own.
    #[allow(clippy::too_many_arguments)]
    fn place(
        &mut self,
        i: usize,
        file: &str,
        (path, part): (PathBuf, Option<u32>),
        override_material: Option<u32>,
        surface: MeshSurface,
        transform: &Transform,
        motion: Vec3,
    ) -> Result<(), SceneError> {
        let model = &self.models[&path].model;
        if let Some(part) = part.filter(|&p| p as usize >= model.meshes.len()) {
            let n = model.meshes.len();
            return Err(invalid(
                format!("objects[{i}].part"),
                format!(
                    "{file} holds {n} mesh{}, numbered from 0; there is no mesh {part}",
                    if n == 1 { "" } else { "es" }
                ),
            ));
        }
        let chosen = |mesh: usize| part.is_none_or(|p| p as usize == mesh);
        // Counted before they are taken: a file of many nodes placed
        // by many objects multiplies.
        let more = model.instances.iter().filter(|(m, _)| chosen(*m)).count() as u64;
        let total = self.placements.len() as u64 + more;
        if total > MAX_INSTANCES {
            return Err(invalid(
                format!("objects[{i}].file"),
                format!(
                    "{file}: with the objects before it, the scene places {total} meshes, \
                             more than the {MAX_INSTANCES} lumen holds"
                ),
            ));
        }
        let room = crate::memory::check(more * BYTES_PER_PLACEMENT, "")
            .is_ok()
            .then(|| self.placements.try_reserve(more as usize).ok())
            .flatten();
        if room.is_none() {
            let e = crate::memory::MemoryError {
                what: format!("placing {total} meshes"),
                bytes: total * BYTES_PER_PLACEMENT,
                available: crate::memory::available(),
            };
            return Err(invalid(
                format!("objects[{i}].file"),
                format!("{file}: {e}"),
            ));
        }
        for (mesh, node) in model.instances.iter().filter(|(m, _)| chosen(*m)) {
            let node = mat4_transform(node).ok_or_else(|| {
                invalid(
                    format!("objects[{i}].file"),
                    format!("{file}: a node's transform is singular or out of range"),
                )
            })?;
            let placed = transform.compose(&node).ok_or_else(|| {
                        invalid(
                            format!("objects[{i}].transform"),
                            "together with the file's own node transforms, the transform is singular or out of range",
                        )
                    })?;
            self.placements.push(Placement {
                key: (path.clone(), *mesh, surface),
                transform: placed,
                material: override_material,
                motion,
                object: i,
            });
        }
        Ok(())
    }

    /// Loads mesh file `file` of object `i` (once per file), returning
    /// where it was found.
    fn load(
        &mut self,
        i: usize,
        file: &str,
        options: mesh::LoadOptions,
    ) -> Result<PathBuf, SceneError> {
        let path = model_path(self.base, file);
        let key = model_key(&path, options);
        if self.models.contains_key(&key) {
            return Ok(key);
        }
        let fail = |message: String| invalid(format!("objects[{i}].file"), message);
        let read = match self.read_ahead.remove(&key) {
            Some(read) => read,
            None => mesh::load_with(&path, options),
        };
        let model = read.map_err(|e| fail(e.to_string()))?;
        self.sources.push(MeshSource {
            file: file.to_string(),
            crc: model.file_crc,
            len: model.file_len,
        });
        self.stats.skipped_degenerate += model.skipped_degenerate as u64;
        self.reports.push(FileReport::of(file, &model));
        let materials = vec![None; model.materials.len() + 1];
        self.models
            .insert(key.clone(), LoadedModel { model, materials });
        Ok(key)
    }

    /// The scene material of material `m` of the file at `path`
    /// (`NO_MATERIAL`: a default grey diffuse).
    fn file_material(&mut self, path: &Path, m: u32) -> u32 {
        let loaded = self.models.get_mut(path).expect("loaded");
        let slot = if m == NO_MATERIAL {
            loaded.model.materials.len()
        } else {
            m as usize
        };
        if let Some(index) = loaded.materials[slot] {
            return index;
        }
        let material = match loaded.model.materials.get(slot) {
            Some(m) => file_material::compile(m, &mut self.textures),
            None => file_material::no_material(),
        };
        let index = self.materials.len() as u32;
        self.materials.push(material);
        loaded.materials[slot] = Some(index);
        index
    }

    /// Places every mesh: one placed once goes into the scene's tree in
    /// world space; one placed several times is stored once with a tree of
    /// its own, and placed by instances.
    fn place_meshes(&mut self) -> Result<(), SceneError> {
        let placements = std::mem::take(&mut self.placements);
        let mut order: Vec<&MeshKey> = Vec::new();
        let mut by_key: HashMap<&MeshKey, Vec<&Placement>> = HashMap::new();
        for p in &placements {
            let list = by_key.entry(&p.key).or_default();
            if list.is_empty() {
                order.push(&p.key);
            }
            list.push(p);
        }
        // How many keys use each mesh of a file: the last to place it takes
        // the file's arrays instead of a copy (the file's meshes are not
        // needed after, and a large mesh was held twice).
        let mut uses: HashMap<(&Path, usize), usize> = HashMap::new();
        for (path, mesh_index, _) in &order {
            *uses.entry((path.as_path(), *mesh_index)).or_default() += 1;
        }
        for key in order {
            let placed = &by_key[key];
            let (path, mesh_index, surface) = key;
            let left = uses
                .get_mut(&(path.as_path(), *mesh_index))
                .expect("counted");
            *left -= 1;
            let last = *left == 0;
            // A mesh placed once and still goes into the scene's tree; a
            // moving one is carried by an instance.
            let still = placed.len() == 1 && placed[0].motion == Vec3::ZERO;
            if let (true, [only]) = (still, placed.as_slice()) {
                let mesh = self.scene_mesh(path, *mesh_index, only.material, *surface, last);
                let n = mesh.data.triangles.len() as u64;
                self.stats.triangles += n;
                self.stats.placed_triangles += n;
                self.top
                    .push_mesh(place_mesh(mesh, path, &only.transform, only.object)?);
            } else {
                // Stored once with the file's materials; an instance whose
                // object names a material uses it instead.
                let mesh = self.scene_mesh(path, *mesh_index, None, *surface, last);
                let n = mesh.data.triangles.len() as u64;
                self.stats.triangles += n;
                self.stats.placed_triangles += n * placed.len() as u64;
                let group = Group::new(Shapes::of_mesh(mesh)).map_err(|e| {
                    let first = placed.first().map_or(0, |p| p.object);
                    invalid(
                        format!("objects[{first}].file"),
                        format!("{}: {e}", path.display()),
                    )
                })?;
                // Each placement must stay within f32, as a mesh placed once
                // must: its tree's box, placed.
                for p in placed {
                    let placed_box = p.transform.bounds(&group.bvh.bounds());
                    let extent = placed_box.min.abs().max(placed_box.max.abs());
                    let extent = if extent.is_finite() {
                        extent.max_element()
                    } else {
                        f32::INFINITY
                    };
                    mesh_within(p.object, path, extent)?;
                }
                self.groups.push(group);
                let group = self.groups.len() as u32 - 1;
                self.instances.extend(placed.iter().map(|p| PlacedGroup {
                    group,
                    transform: p.transform,
                    material: p.material,
                    motion: p.motion,
                }));
            }
        }
        Ok(())
    }

    /// Mesh `mesh_index` of the file at `path` with scene materials; `last`:
    /// no other placement uses the file's mesh after this one, whose arrays
    /// it takes.
    fn scene_mesh(
        &mut self,
        path: &Path,
        mesh_index: usize,
        override_material: Option<u32>,
        surface: MeshSurface,
        last: bool,
    ) -> Mesh {
        let smooth = surface.smooth;
        let loaded = self.models.get_mut(path).expect("loaded");
        let source = &mut loaded.model.meshes[mesh_index];
        let source = if last {
            std::mem::take(source)
        } else {
            source.clone()
        };
        let file_materials = source.material;
        let mut data = TriangleMesh {
            normals: if smooth { source.normals } else { None },
            tangents: if smooth { source.tangents } else { None },
            material: Vec::new(),
            ..source
        };
        data.material = match override_material {
            Some(m) => vec![m],
            None => {
                let mapped: Vec<u32> = file_materials
                    .iter()
                    .map(|&m| self.file_material(path, m))
                    .collect();
                if mapped.windows(2).all(|w| w[0] == w[1]) {
                    mapped
                        .first()
                        .map_or_else(|| vec![self.file_material(path, NO_MATERIAL)], |&m| vec![m])
                } else {
                    mapped
                }
            }
        };
        data.material.shrink_to_fit();
        Mesh {
            data,
            flipped: surface.flipped,
        }
    }
}

impl Objects<'_> {
    /// The camera description with the place and field of view of the
    /// glTF camera it names, if it names one.
    fn gltf_camera(&self) -> Result<Option<CameraDesc>, SceneError> {
        let Some(which) = &self.desc.camera.gltf else {
            return Ok(None);
        };
        let mut all = Vec::new();
        for (i, o) in self.desc.objects.iter().enumerate() {
            let ObjectDesc::Mesh { file, .. } = o else {
                continue;
            };
            let Some(loaded) = self.models.get(&model_path(self.base, file)) else {
                continue;
            };
            let (transform, _) = compile_transform(i, o.transform())?;
            all.extend(loaded.model.cameras.iter().map(|c| (c, transform)));
        }
        let found = match which {
            GltfCamera::Index(n) => all.get(*n as usize),
            GltfCamera::Name(name) => all.iter().find(|(c, _)| c.name.as_deref() == Some(name)),
        };
        let Some((c, t)) = found else {
            let names: Vec<String> = all
                .iter()
                .enumerate()
                .map(|(k, (c, _))| match &c.name {
                    Some(n) => format!("{k} \"{n}\""),
                    None => k.to_string(),
                })
                .collect();
            let what = match which {
                GltfCamera::Index(n) => format!("no camera {n}"),
                GltfCamera::Name(n) => format!("no camera named \"{n}\""),
            };
            let have = if names.is_empty() {
                "the scene's glTF models have no cameras".to_string()
            } else {
                format!("the scene's glTF models have cameras {}", names.join(", "))
            };
            return Err(invalid("camera.gltf", format!("{what}: {have}")));
        };
        let m = c.transform;
        let point = |p: glam::Vec3| t.point(Vec3::from(m.transform_point3(p)));
        let eye = point(glam::Vec3::ZERO);
        let ahead = point(glam::Vec3::NEG_Z);
        let up = t.vector(Vec3::from(m.transform_vector3(glam::Vec3::Y)));
        let triple = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let (vfov, ortho_height) = match c.view {
            ModelView::Perspective { yfov } => (f64::from(yfov).to_degrees(), None),
            // ±ymag up its frame, which the transforms may scale, alike
            // across for square pixels.
            ModelView::Orthographic { ymag } => {
                let across = t.vector(Vec3::from(m.transform_vector3(glam::Vec3::X)));
                if (across.length() / up.length() - 1.0).abs() > 1e-3 {
                    return Err(invalid(
                        "camera.gltf",
                        format!(
                            "the orthographic camera's node scales its x by {} and its y by {}: \
                             lumen's pixels are square",
                            across.length(),
                            up.length()
                        ),
                    ));
                }
                (
                    self.desc.camera.vfov,
                    Some(2.0 * f64::from(ymag) * f64::from(up.length())),
                )
            }
        };
        Ok(Some(CameraDesc {
            lookfrom: triple(eye),
            lookat: triple(ahead),
            vup: triple(up),
            vfov,
            ortho_height,
            ..self.desc.camera.clone()
        }))
    }
}

/// Where a mesh file named `file` by a scene in `base` is, as the scene's
/// table of loaded models knows it.
fn model_path(base: &Path, file: &str) -> PathBuf {
    let path = if Path::new(file).is_absolute() {
        PathBuf::from(file)
    } else {
        base.join(file)
    };
    std::fs::canonicalize(&path).unwrap_or(path)
}

/// `value` of `field` when it is finite and above 0 once in `f32`.
/// `field` is only formatted when the value is refused (as for
/// [`finite`]).
fn positive(field: impl std::fmt::Display, value: f64) -> Result<f64, SceneError> {
    finite(&field, &[value])?;
    if !(value as f32 > 0.0) {
        return Err(invalid(
            field.to_string(),
            format!("must be greater than 0, got {value}"),
        ));
    }
    Ok(value)
}

/// The uniform scale of `transform` when it is a similarity (rotation,
/// uniform scale, translation, reflection), which maps a sphere to a sphere.
fn similarity(transform: &Transform) -> Option<f32> {
    let [x, y, z] = [Vec3::X, Vec3::Y, Vec3::Z].map(|e| transform.vector(e));
    let (a, b, c) = (x.length(), y.length(), z.length());
    let close = |p: f32, q: f32| (p - q).abs() <= 1e-5 * p.max(q);
    let orthogonal = [(x, y), (y, z), (z, x)]
        .iter()
        .all(|(p, q)| p.dot(*q).abs() <= 1e-5 * a * a);
    (close(a, b) && close(b, c) && orthogonal).then_some(a)
}

fn out_of_range(i: usize) -> SceneError {
    invalid(
        format!("objects[{i}].transform"),
        "places the object beyond the range of f32",
    )
}

/// Refuses object `i` when its transform makes `what` `extent` in size
/// (its largest coordinate or radius): the limit on what a scene writes
/// holds for what its transforms make of it too.
fn placed_within(i: usize, what: &str, extent: f32) -> Result<(), SceneError> {
    if f64::from(extent) <= MAX_COORDINATE {
        return Ok(());
    }
    Err(invalid(
        format!("objects[{i}].transform"),
        format!(
            "makes {what} {extent:.2e} in size, more than the {MAX_COORDINATE:e} an object may reach, so that products of two coordinates fit in f32"
        ),
    ))
}

/// Refuses the mesh of object `i`, read from `path`, when its vertices,
/// placed (by the object's transform and the file's own), reach `extent`
/// in size; an `extent` that is not finite is the transform's doing (a
/// file's own numbers are finite), and the transform is named.
fn mesh_within(i: usize, path: &Path, extent: f32) -> Result<(), SceneError> {
    if f64::from(extent) <= MAX_COORDINATE {
        return Ok(());
    }
    let path = path.display();
    Err(if extent.is_finite() {
        invalid(
            format!("objects[{i}]"),
            format!(
                "the vertices of {path}, as placed, reach {extent:.2e} in size, more than the {MAX_COORDINATE:e} an object may reach, so that products of two coordinates fit in f32"
            ),
        )
    } else {
        invalid(
            format!("objects[{i}].transform"),
            format!("places the vertices of {path} beyond the range of f32"),
        )
    })
}

/// The quad at `corner` with edges `u`, `v`, placed by `transform`: of
/// object `i`, `what` it is a part of (a quad, a box).
fn place_quad(
    i: usize,
    what: &str,
    transform: &Transform,
    corner: Vec3,
    u: Vec3,
    v: Vec3,
) -> Result<Quad, SceneError> {
    if Quad::parallel(u, v) {
        return Err(invalid(
            format!("objects[{i}]"),
            format!("edges u {u} and v {v} are parallel or zero: the quad has no area"),
        ));
    }
    let (q, u, v) = (
        transform.point(corner),
        transform.vector(u),
        transform.vector(v),
    );
    if !(q.is_finite() && u.is_finite() && v.is_finite()) {
        return Err(out_of_range(i));
    }
    let corners = [q, q + u, q + v, q + u + v];
    let extent = corners
        .iter()
        .fold(u.abs().max(v.abs()), |m, c| m.max(c.abs()))
        .max_element();
    placed_within(i, what, extent)?;
    let quad = Quad::new(q, u, v).ok_or_else(|| {
        if transform.is_identity() {
            invalid(
                format!("objects[{i}]"),
                format!("edges u {u} and v {v} are too small for f32 arithmetic"),
            )
        } else if Quad::parallel(u, v) {
            invalid(
                format!("objects[{i}].transform"),
                format!("turns the edges into u {u} and v {v}, so nearly parallel that the quad has no area"),
            )
        } else {
            invalid(
                format!("objects[{i}].transform"),
                format!("makes the edges u {u} and v {v} too small for f32 arithmetic"),
            )
        }
    })?;
    // A mirroring transform reverses u × v: the outside stays the outside.
    Ok(turned(quad, transform.mirrors()))
}

/// `quad`, with its outside turned in if `inward`.
fn turned(quad: Quad, inward: bool) -> Quad {
    if inward {
        quad.flipped()
    } else {
        quad
    }
}

/// The six faces (corner, u, v) of the box from `min` to `max`, each with
/// u × v pointing out of the box.
fn box_faces(min: Vec3, max: Vec3) -> [(Vec3, Vec3, Vec3); 6] {
    let d = max - min;
    let (dx, dy, dz) = (
        Vec3::new(d.x, 0.0, 0.0),
        Vec3::new(0.0, d.y, 0.0),
        Vec3::new(0.0, 0.0, d.z),
    );
    [
        (Vec3::new(min.x, min.y, max.z), dx, dy),  // front (+z)
        (Vec3::new(max.x, min.y, max.z), -dz, dy), // right (+x)
        (Vec3::new(max.x, min.y, min.z), -dx, dy), // back (−z)
        (Vec3::new(min.x, min.y, min.z), dz, dy),  // left (−x)
        (Vec3::new(min.x, max.y, max.z), dx, -dz), // top (+y)
        (Vec3::new(min.x, min.y, min.z), dx, dz),  // bottom (−y)
    ]
}

/// `mesh` moved into world space by `transform`.
fn place_mesh(
    mut mesh: Mesh,
    path: &Path,
    transform: &Transform,
    object: usize,
) -> Result<Mesh, SceneError> {
    if !transform.is_identity() {
        for p in &mut mesh.data.positions {
            *p = transform.point(Vec3::from(*p)).to_array();
        }
        // A mirror turns the winding over and keeps the outside, as for
        // every other shape and for an instanced mesh (and as glTF's
        // nodes of negative determinant do).
        let mirror = transform.mirrors();
        mesh.flipped ^= mirror;
        if let Some(normals) = &mut mesh.data.normals {
            for n in normals {
                *n = transform.normal(Vec3::from(*n)).to_array();
            }
        }
        if let Some(tangents) = &mut mesh.data.tangents {
            // A mirroring transform turns the bitangent (w · n × t) over.
            let side = if mirror { -1.0 } else { 1.0 };
            for t in tangents {
                let v = transform.vector(Vec3::new(t[0], t[1], t[2]));
                *t = [v.x, v.y, v.z, t[3] * side];
            }
        }
    }
    // NaN compares as no larger than anything: counted as infinite.
    let extent = mesh.data.positions.iter().flatten().fold(0f32, |m, c| {
        if c.is_finite() {
            m.max(c.abs())
        } else {
            f32::INFINITY
        }
    });
    mesh_within(object, path, extent)?;
    Ok(mesh)
}

/// A file's node matrix (column-major) as a transform.
fn mat4_transform(m: &glam::Mat4) -> Option<Transform> {
    let rows: [[f64; 4]; 4] =
        std::array::from_fn(|r| std::array::from_fn(|c| f64::from(m.col(c)[r])));
    Transform::from_steps(&[TransformStep::Matrix(rows)]).ok()
}

/// The transform of object `i`'s steps (its place at time 0), and how far
/// its `motion` steps move it by time 1, in the world.
fn compile_transform(i: usize, steps: &[TransformDesc]) -> Result<(Transform, Vec3), SceneError> {
    transform_at(&format!("objects[{i}].transform"), steps)
}

/// The transform (and motion) of `steps`, the field at `at` (for messages).
fn transform_at(at: &str, steps: &[TransformDesc]) -> Result<(Transform, Vec3), SceneError> {
    let placing = |steps: &[TransformDesc]| -> Vec<(usize, TransformStep)> {
        steps
            .iter()
            .enumerate()
            .filter_map(|(k, s)| {
                let step = match s {
                    TransformDesc::Translate(t) => TransformStep::Translate(*t),
                    TransformDesc::Rotate { axis, degrees } => TransformStep::Rotate {
                        axis: *axis,
                        degrees: *degrees,
                    },
                    TransformDesc::Scale(ScaleDesc::Uniform(s)) => TransformStep::Scale([*s; 3]),
                    TransformDesc::Scale(ScaleDesc::PerAxis(s)) => TransformStep::Scale(*s),
                    TransformDesc::Matrix(m) => TransformStep::Matrix(*m),
                    TransformDesc::Motion(_) => return None,
                };
                Some((k, step))
            })
            .collect()
    };
    let build = |offset: usize, steps: &[TransformDesc]| {
        let (index, steps): (Vec<usize>, Vec<TransformStep>) = placing(steps).into_iter().unzip();
        Transform::from_steps(&steps)
            .map_err(|e| invalid(format!("{at}[{}]", offset + index[e.index]), e.message))
    };
    let transform = build(0, steps)?;
    let mut motion = Vec3::ZERO;
    for (k, step) in steps.iter().enumerate() {
        if let TransformDesc::Motion(m) = step {
            let field = format!("{at}[{k}].motion");
            finite(&field, m)?;
            // Carried by the steps after it, as the object is.
            motion += build(k + 1, &steps[k + 1..])?.vector(vec3(*m));
            if !motion.is_finite() {
                return Err(invalid(field, "moves the object beyond the range of f32"));
            }
        }
    }
    Ok((transform, motion))
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
    if let Some(e) = r.epsilon {
        finite("render.epsilon", &[e])?;
        if !(e >= 0.0) {
            return Err(invalid(
                "render.epsilon",
                format!("must not be negative, got {e}"),
            ));
        }
    }
    check_seed("render.seed", r.seed)?;
    let noise_target = match r.noise_target {
        None => None,
        Some(t) if t > 0.0 && t <= 1.0 && (t as f32) > 0.0 => Some(t as f32),
        Some(t) => {
            return Err(invalid(
                "render.noise_target",
                format!("must be a relative error above 0 and at most 1, got {t}"),
            ))
        }
    };
    let (width, height, crop) = match r.crop {
        None => (r.width, height, None),
        Some([x, y, w, h]) => {
            let inside = w > 0
                && h > 0
                && x.checked_add(w).is_some_and(|e| e <= r.width)
                && y.checked_add(h).is_some_and(|e| e <= height);
            if !inside {
                return Err(invalid(
                    "render.crop",
                    format!(
                        "[x, y, width, height] must be a window of at least one pixel within \
                         the {}x{height} image, got [{x}, {y}, {w}, {h}]",
                        r.width
                    ),
                ));
            }
            (w, h, Some([x, y, r.width, height]))
        }
    };
    Ok(Settings {
        width,
        height,
        crop,
        noise_target,
        samples_per_pixel: r.samples_per_pixel,
        max_depth: r.max_depth,
        seed: r.seed,
        sampler: r.sampler,
        integrator: r.integrator,
        light_selection: r.light_selection,
        gamma: r.gamma as f32,
        aovs: r.written_aovs(),
        layers: crate::aov::Layers::for_aovs(&r.written_aovs()),
        denoise: r.denoise,
        denoise_choices: r.denoise_choices(),
        epsilon: r.epsilon.map_or(0.0, |e| e as f32),
        offset: r.epsilon != Some(0.0),
        shading: r.shading,
        pixel_filter: (r.pixel_filter, r.filter_stddev),
    })
}

/// An environment image's `frame`, checked: three unit axes at right
/// angles.
fn frame_axes(frame: &Option<[super::desc::Triple; 3]>) -> Result<Option<[Vec3; 3]>, SceneError> {
    let Some(f) = frame else {
        return Ok(None);
    };
    finite("background.frame", &f.concat())?;
    let axes = f.map(vec3);
    let orthonormal = (0..3).all(|i| {
        (0..3).all(|j| {
            let want = if i == j { 1.0 } else { 0.0 };
            (axes[i].dot(axes[j]) - want).abs() < 1e-4
        })
    });
    if !orthonormal {
        return Err(invalid(
            "background.frame",
            "must be three unit axes at right angles (a rotation)",
        ));
    }
    Ok(Some(axes))
}

/// The seed, or refuses one above [`MAX_SEED`] (given by a program or the library's
/// user: scene files are checked when read), which TOML could not write.
pub(super) fn check_seed(field: &str, seed: u64) -> Result<u64, SceneError> {
    if seed > MAX_SEED {
        return Err(invalid(field, crate::scene::desc::seed_too_large(seed)));
    }
    Ok(seed)
}

/// The scene's textures and materials as a material being compiled finds
/// them.
struct MaterialTextures<'t, 'a> {
    textures: &'t mut TextureTable<'a>,
    sources: &'t mut Vec<MeshSource>,
    materials: &'a BTreeMap<String, MaterialDesc>,
    /// The materials being compiled, outermost first (a mix's materials
    /// are compiled inside it): one that is among them mixes itself in.
    resolving: Vec<&'a str>,
}

impl Textures for MaterialTextures<'_, '_> {
    fn color(
        &mut self,
        field: &str,
        c: &ColorDesc,
        range: ColorRange,
    ) -> Result<ColorParam, Invalid> {
        let check = match range {
            ColorRange::NonNegative => color,
            ColorRange::Unit => albedo,
        };
        match self.textures.color(field, c, check, self.sources) {
            Ok(ColorRef::Rgb(c)) => Ok(ColorParam::Const(c)),
            Ok(ColorRef::Texture(t)) => {
                if self.textures.kind(t) == TextureKind::Scalar {
                    let ColorDesc::Texture(name) = c else {
                        unreachable!("a texture has a name")
                    };
                    return Err(Invalid::new(
                        field,
                        format!(
                            "texture \"{name}\" is one channel of an image (a scalar); a colour \
                             is expected here: leave out its `channel`"
                        ),
                    ));
                }
                Ok(ColorParam::Texture(t))
            }
            Err(e) => Err(Invalid::new(e.field(), e.message())),
        }
    }

    fn scalar(
        &mut self,
        field: &str,
        s: &ScalarDesc,
        range: Range,
    ) -> Result<ScalarParam, Invalid> {
        match s {
            ScalarDesc::Value(v) => Ok(ScalarParam::Const(param::number(field, *v, range)?)),
            ScalarDesc::Texture(name) => {
                let t = self.named(field, name)?;
                if self.textures.kind(t) == TextureKind::Color {
                    return Err(Invalid::new(
                        field,
                        format!(
                            "texture \"{name}\" is a colour; a scalar is expected here: \
                             give the image texture a `channel` (\"r\", \"g\", \"b\" or \"a\")"
                        ),
                    ));
                }
                Ok(ScalarParam::Texture(t))
            }
        }
    }

    fn scaled(&mut self, t: u32, factor: Color) -> u32 {
        self.textures.push(Texture::Scaled { texture: t, factor })
    }

    fn aspect(&self, t: u32) -> Option<f64> {
        match self.textures.textures.get(t as usize)? {
            Texture::Map(map) => Some(map.image.width() as f64 / map.image.height() as f64),
            Texture::Scaled { texture, .. } => self.aspect(*texture),
            _ => None,
        }
    }

    fn material(&mut self, field: &str, name: &str) -> Result<Material, Invalid> {
        let Some((name, desc)) = self.materials.get_key_value(name) else {
            return Err(Invalid::new(
                field,
                format!(
                    "no material is named \"{name}\"{}",
                    crate::hint::closest(name, self.materials.keys().map(String::as_str))
                        .map(|k| format!("; did you mean \"{k}\"?"))
                        .unwrap_or_default()
                ),
            ));
        };
        if self.resolving.contains(&name.as_str()) {
            return Err(Invalid::new(
                field,
                format!("material \"{name}\" is mixed into itself"),
            ));
        }
        self.resolving.push(name);
        let material = desc.compile(&format!("materials.{name}"), self);
        self.resolving.pop();
        material
    }

    fn normal_map(&mut self, field: &str, name: &str) -> Result<u32, Invalid> {
        let t = self.named(field, name)?;
        let map = match &self.textures.textures[t as usize] {
            Texture::Map(map) if map.channels == Channels::Rgb => map.clone(),
            _ => {
                return Err(Invalid::new(
                    field,
                    format!(
                        "texture \"{name}\" is not a normal map: a normal map is an image \
                         texture of all three channels"
                    ),
                ))
            }
        };
        if let Some(problem) = map.image.normal_map_problem() {
            return Err(Invalid::new(field, format!("texture \"{name}\" {problem}")));
        }
        if map.image.is_float() || !map.srgb {
            return Ok(t);
        }
        // The same image, read as data rather than colour.
        Ok(self.textures.push(Texture::Map(Arc::new(ImageMap {
            srgb: false,
            ..(*map).clone()
        }))))
    }
}

impl MaterialTextures<'_, '_> {
    /// The texture `name` of field `field`, compiled.
    fn named(&mut self, field: &str, name: &str) -> Result<u32, Invalid> {
        let c = ColorDesc::Texture(name.to_string());
        match self
            .textures
            .color(field, &c, albedo, self.sources)
            .map_err(|e| Invalid::new(e.field(), e.message()))?
        {
            ColorRef::Texture(t) => Ok(t),
            ColorRef::Rgb(_) => unreachable!("a name is a texture"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_faces_point_out_of_the_box() {
        let (min, max) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 5.0));
        let center = 0.5 * (min + max);
        let mut seen = Vec::new();
        for (q, u, v) in box_faces(min, max) {
            let n = u.cross(v).normalize();
            let face_center = q + 0.5 * (u + v);
            assert!(
                n.dot(face_center - center) > 0.0,
                "face at {face_center} has normal {n}"
            );
            seen.push(n);
        }
        // One face per direction ±x, ±y, ±z.
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            for sign in [1.0, -1.0] {
                assert!(seen.iter().any(|n| (*n - sign * axis).length() < 1e-6));
            }
        }
    }
}
