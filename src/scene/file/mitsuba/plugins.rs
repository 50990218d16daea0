//! Mitsuba's plugins as lumen's description: the sensor as the camera
//! and the render settings, shapes as objects, BSDFs as materials,
//! textures, emitters as lights and the background. One function a
//! plugin tag; each reads its parameters through [`Props`], refusing any
//! it does not know.

use super::props::{describe, Colour, Props};
use super::spectrum::Use;
use super::transform::{self, Mat4, IDENTITY};
use super::xml::{Document, Element};
use super::{located, Failure, Imported, Options};
use crate::hint;
use crate::light::source::{
    DirectionalLightDesc, PointLightDesc, ProjectorLightDesc, SpotLightDesc,
};
use crate::material::dielectric::FresnelDesc;
use crate::material::roughness::DistributionDesc;
use crate::material::{
    ConductorDesc, DielectricDesc, DiffuseDesc, EmissiveDesc, MaterialDesc, MixDesc, PlasticDesc,
    PrincipledDesc,
};
use crate::scene::desc::{
    BackgroundDesc, CameraDesc, ColorDesc, EncodingDesc, FilterDesc, LightDesc, ObjectDesc,
    PixelFilterDesc, RoughnessDesc, SamplingDesc, ScalarDesc, SceneDesc, TextureDesc,
    TransformDesc, Triple, WrapDesc,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

mod media;

/// The plugins lumen reads, by tag, for messages.
const SHAPES: &[&str] = &[
    "obj",
    "ply",
    "serialized",
    "sphere",
    "rectangle",
    "cube",
    "shapegroup",
    "instance",
];
const BSDFS: &[&str] = &[
    "diffuse",
    "dielectric",
    "roughdielectric",
    "thindielectric",
    "conductor",
    "roughconductor",
    "plastic",
    "roughplastic",
    "principled",
    "twosided",
    "mask",
    "bumpmap",
    "normalmap",
    "null",
    "blendbsdf",
];
const EMITTERS: &[&str] = &[
    "area",
    "constant",
    "envmap",
    "point",
    "spot",
    "directional",
    "projector",
];
const INTEGRATORS: &[&str] = &[
    "path",
    "direct",
    "volpath",
    "volpathmis",
    "ptracer",
    "moment",
];
const TEXTURES: &[&str] = &["bitmap", "checkerboard"];

/// The parameters of a rough BSDF's microfacets.
const MICROFACET_PARAMS: [&str; 5] = [
    "distribution",
    "alpha",
    "alpha_u",
    "alpha_v",
    "sample_visible",
];

/// Mitsuba's `max_depth = -1` (no limit), as lumen's largest practical
/// depth: Russian roulette ends paths long before.
const UNLIMITED_DEPTH: u32 = 1024;

/// A scene being converted.
pub struct Convert<'d> {
    doc: &'d Document,
    options: &'d Options,
    /// The scene file's folder: the description's files are relative to it.
    dir: PathBuf,
    ids: HashMap<&'d str, &'d Element>,
    desc: SceneDesc,
    warnings: Vec<String>,
    /// Each BSDF element's material, by its address.
    materials: HashMap<*const Element, String>,
    /// Each texture element's texture (and as which channel), by address.
    textures: HashMap<(*const Element, bool), String>,
    /// Names handed out so far, to make new ones unique.
    counter: usize,
    /// Where the background came from, when an emitter gave one.
    background: Option<&'d Element>,
    /// Each medium element's medium, by its address.
    media: HashMap<*const Element, String>,
    /// Each material with media on its sides (material, interior,
    /// exterior), by the names it was made from.
    bounded: crate::scene::file::import::MediaCopies,
}

impl<'d> Convert<'d> {
    /// A conversion of `doc`, whose scene file lies in `dir`.
    pub fn new(doc: &'d Document, options: &'d Options, dir: PathBuf) -> Result<Self, Failure> {
        let mut cx = Convert {
            doc,
            options,
            dir,
            ids: HashMap::new(),
            desc: SceneDesc::default(),
            warnings: Vec::new(),
            materials: HashMap::new(),
            textures: HashMap::new(),
            counter: 0,
            background: None,
            media: HashMap::new(),
            bounded: Default::default(),
        };
        fn gather<'d>(
            e: &'d Element,
            ids: &mut HashMap<&'d str, &'d Element>,
            doc: &Document,
        ) -> Result<(), Failure> {
            if e.tag != "ref" {
                if let Some(id) = e.attr("id") {
                    if let Some(first) = ids.insert(id, e) {
                        let f = &doc.files.files[first.at.file as usize].0;
                        return Err(located(
                            &doc.files,
                            e.at,
                            format!(
                                "id `{id}` is given twice (first at {f}:{}:{})",
                                first.at.line, first.at.col
                            ),
                        ));
                    }
                }
            }
            for c in &e.children {
                gather(c, ids, doc)?;
            }
            Ok(())
        }
        for e in &doc.elements {
            gather(e, &mut cx.ids, doc)?;
        }
        // Mitsuba's defaults, where lumen's differ.
        cx.desc.background = BackgroundDesc::Solid { color: [0.0; 3] };
        cx.desc.render.gamma = 2.2;
        cx.desc.render.width = 768;
        cx.desc.render.height = Some(576);
        cx.desc.render.sampler = SamplingDesc::Independent;
        cx.desc.render.samples_per_pixel = 4;
        cx.desc.render.max_depth = UNLIMITED_DEPTH;
        // Mitsuba 3 chooses among its emitters uniformly.
        cx.desc.render.light_selection = crate::light::LightSelection::Objects;
        Ok(cx)
    }

    /// The description and the warnings.
    pub fn finish(self) -> Imported {
        Imported {
            desc: self.desc,
            warnings: self.warnings,
        }
    }

    /// A failure at element `e`.
    pub fn fail(&self, e: &Element, message: String) -> Failure {
        located(&self.doc.files, e.at, message)
    }

    /// A failure at element `e`, with a hint.
    pub fn fail_hint(&self, e: &Element, message: String, hint: Option<String>) -> Failure {
        let mut f = self.fail(e, message);
        f.0.hint = hint;
        f
    }

    /// The element a `<ref id>` names.
    pub fn resolve(&self, r: &Element) -> Result<&'d Element, Failure> {
        let Some(id) = r.attr("id") else {
            return Err(self.fail(r, "<ref> needs an `id`".into()));
        };
        self.ids.get(id).copied().ok_or_else(|| {
            let mut known: Vec<&str> = self.ids.keys().copied().collect();
            known.sort();
            self.fail_hint(
                r,
                format!("no element has id `{id}`"),
                hint::closest(id, known.iter().copied()).map(|k| format!("did you mean `{k}`?")),
            )
        })
    }

    /// What lumen lacks, at `e`: refused, or with `--approximate` a
    /// warning that `instead` is done.
    fn lacks(&mut self, e: &Element, what: &str, instead: &str) -> Result<(), Failure> {
        if self.options.approximate {
            let f = &self.doc.files.files[e.at.file as usize].0;
            self.warnings.push(format!(
                "{f}:{}:{}: {what}; {instead} instead (--approximate)",
                e.at.line, e.at.col
            ));
            Ok(())
        } else {
            Err(self.fail_hint(
                e,
                what.to_string(),
                Some(format!("--approximate renders {instead} instead")),
            ))
        }
    }

    /// A plugin `type` lumen does not read.
    fn unknown_type(&self, e: &Element, kind: &str, known: &[&str]) -> Failure {
        let t = e.attr("type").unwrap_or("");
        self.fail_hint(
            e,
            format!(
                "{kind} type `{t}` is not supported; lumen reads {}",
                known.join(", ")
            ),
            hint::closest(t, known.iter().copied()).map(|k| format!("did you mean `{k}`?")),
        )
    }

    fn type_of<'e>(&self, e: &'e Element) -> Result<&'e str, Failure> {
        e.attr("type")
            .ok_or_else(|| self.fail(e, format!("<{}> needs a `type`", e.tag)))
    }

    /// A fresh name starting with `stem`.
    fn name(&mut self, stem: &str) -> String {
        self.counter += 1;
        format!("{stem}-{}", self.counter)
    }

    /// The file `name` (from `e`), looked for in the `<path>` folders
    /// and the scene's: its path relative to the scene file's folder.
    fn file(&self, name: &str, e: &Element) -> Result<String, Failure> {
        let given = Path::new(name);
        let candidates: Vec<PathBuf> = if given.is_absolute() {
            vec![given.to_path_buf()]
        } else {
            self.doc.search.iter().map(|d| d.join(given)).collect()
        };
        for c in &candidates {
            if c.is_file() {
                let relative = c.strip_prefix(&self.dir).unwrap_or(c);
                return Ok(relative.to_string_lossy().into_owned());
            }
        }
        Err(self.fail(
            e,
            format!(
                "file `{name}` not found (looked in {})",
                candidates
                    .iter()
                    .map(|c| c.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ))
    }

    /// The whole scene.
    pub fn scene(&mut self) -> Result<(), Failure> {
        let doc = self.doc;
        let mut sensor = None;
        let mut integrator = None;
        for e in &doc.elements {
            match e.tag.as_str() {
                "sensor" => {
                    if sensor.is_some() {
                        self.lacks(e, "a second <sensor>", "the first sensor")?;
                    } else {
                        sensor = Some(e);
                    }
                }
                "integrator" => {
                    if integrator.replace(e).is_some() {
                        return Err(self.fail(e, "a scene has one <integrator>".into()));
                    }
                }
                "shape" => {
                    // A group is placed by its instances.
                    if e.attr("type") != Some("shapegroup") {
                        self.shape(e, &IDENTITY)?;
                    }
                }
                "emitter" => self.emitter(e)?,
                // Definitions, converted where they are referred to.
                "bsdf" | "texture" => {
                    if e.attr("id").is_none() {
                        return Err(self.fail(
                            e,
                            format!(
                                "a <{}> outside a shape needs an `id` to be referred to",
                                e.tag
                            ),
                        ));
                    }
                }
                "medium" => {
                    if e.attr("id").is_none() {
                        return Err(self.fail(
                            e,
                            "a <medium> outside a shape needs an `id` to be referred to".into(),
                        ));
                    }
                }
                other => {
                    let known = [
                        "sensor",
                        "integrator",
                        "shape",
                        "emitter",
                        "bsdf",
                        "texture",
                        "medium",
                        "default",
                        "include",
                        "path",
                    ];
                    return Err(self.fail_hint(
                        e,
                        format!("<{other}> is not an element of a Mitsuba scene; the scene's elements: {}", known.join(", ")),
                        hint::closest(other, known.iter().copied()).map(|k| format!("did you mean <{k}>?")),
                    ));
                }
            }
        }
        if let Some(i) = integrator {
            self.integrator(i)?;
        }
        if let Some(s) = sensor {
            self.sensor(s)?;
        }
        Ok(())
    }

    // ----------------------------------------------------------------
    // Integrator, sensor, film, sampler

    fn integrator(&mut self, e: &Element) -> Result<(), Failure> {
        let p = Props::of(e, self)?;
        match self.type_of(e)? {
            "moment" => {
                let inner = p.objects("integrator");
                p.finish(&[], self)?;
                match inner[..] {
                    [one] => self.integrator(one),
                    _ => {
                        Err(self.fail(e, "a moment integrator wraps exactly one integrator".into()))
                    }
                }
            }
            // The particle tracer's image is the path tracer's: lumen
            // renders it by path tracing.
            t @ ("path" | "direct" | "volpath" | "volpathmis" | "ptracer") => {
                let depth = p.integer("max_depth", self)?;
                let _rr = p.integer("rr_depth", self)?; // Roulette changes the noise only.
                if p.boolean("hide_emitters", self)? == Some(true) {
                    self.lacks(e, "hide_emitters", "the emitters shown")?;
                }
                let mut known = vec!["max_depth", "rr_depth", "hide_emitters"];
                if t == "ptracer" {
                    // How the particles are split into passes: not the image.
                    let _ = p.integer("samples_per_pass", self)?;
                    known.push("samples_per_pass");
                }
                if t == "direct" {
                    for n in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                        if let Some(v) = p.integer(n, self)? {
                            if v != 1 {
                                self.lacks(e, &format!("{n} = {v}"), "one sample of each")?;
                            }
                        }
                    }
                    known.extend(["emitter_samples", "bsdf_samples", "shading_samples"]);
                }
                p.finish(&known, self)?;
                // The direct integrator is the path integrator's first
                // bounce: light sampled and met, weighted by MIS.
                let depth = if t == "direct" { Some(2) } else { depth };
                self.desc.render.max_depth = match depth {
                    None | Some(-1) => UNLIMITED_DEPTH,
                    Some(d) if d >= 1 => u32::try_from(d)
                        .unwrap_or(UNLIMITED_DEPTH)
                        .min(UNLIMITED_DEPTH),
                    Some(0) => {
                        return Err(self.fail(
                            e,
                            "max_depth 0 renders nothing: lumen needs at least 1".into(),
                        ))
                    }
                    Some(d) => {
                        return Err(
                            self.fail(e, format!("max_depth must be -1 or at least 1, got {d}"))
                        )
                    }
                };
                Ok(())
            }
            _ => Err(self.unknown_type(e, "integrator", INTEGRATORS)),
        }
    }

    fn sensor(&mut self, e: &'d Element) -> Result<(), Failure> {
        let t = self.type_of(e)?;
        const SENSORS: &[&str] = &["perspective", "thinlens", "orthographic"];
        if !SENSORS.contains(&t) {
            return Err(self.unknown_type(e, "sensor", SENSORS));
        }
        let orthographic = t == "orthographic";
        let p = Props::of(e, self)?;
        let mut known = vec!["to_world", "near_clip", "far_clip", "srf"];
        if !orthographic {
            known.extend([
                "fov",
                "fov_axis",
                "focal_length",
                "principal_point_offset_x",
                "principal_point_offset_y",
            ]);
        }
        if t != "thinlens" {
            // Every Mitsuba camera has one; a pinhole is in focus
            // everywhere.
            let _ = p.float("focus_distance", self)?;
            known.push("focus_distance");
        }
        // The film first: the field of view depends on its shape.
        let films = p.objects("film");
        let samplers = p.objects("sampler");
        let (width, height) = match films[..] {
            [] => (768, 576),
            [f] => self.film(f)?,
            _ => return Err(self.fail(e, "a sensor has one <film>".into())),
        };
        match samplers[..] {
            [] => {}
            [s] => self.sampler(s)?,
            _ => return Err(self.fail(e, "a sensor has one <sampler>".into())),
        }
        let to_world = p.transform("to_world", self)?.unwrap_or(IDENTITY);
        let aspect = f64::from(width) / f64::from(height);
        let vfov = if orthographic {
            None
        } else {
            Some(self.vertical_fov(e, &p, aspect)?)
        };
        // Mitsuba's camera rays start on the near plane (10⁻² by default).
        let near_clip = p.float("near_clip", self)?.unwrap_or(1e-2);
        let far_clip = p.float("far_clip", self)?.unwrap_or(1e4);
        if !(near_clip >= 0.0) {
            return Err(self.fail(
                e,
                format!("near_clip must not be negative, got {near_clip}"),
            ));
        }
        for n in ["principal_point_offset_x", "principal_point_offset_y"] {
            if !orthographic && p.float(n, self)?.is_some_and(|v| v != 0.0) {
                self.lacks(e, &format!("{n} (a shifted lens)"), "a centred lens")?;
            }
        }
        if p.has("srf") {
            let _ = p.colour("srf", Use::Unbounded, self)?;
            self.lacks(
                e,
                "a sensor response function (srf)",
                "the RGB film's response",
            )?;
        }
        let origin = transform::point(&to_world, [0.0; 3]);
        let forward = transform::vector(&to_world, [0.0, 0.0, 1.0]);
        let up = transform::vector(&to_world, [0.0, 1.0, 0.0]);
        let lengths = [forward, up, transform::vector(&to_world, [1.0, 0.0, 0.0])]
            .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt());
        let [depth_scale, y_scale, x_scale] = lengths;
        let (near_clip, far_clip, ortho_height) = if orthographic {
            // The sensor's plane is [−1, 1] × [−1/aspect, 1/aspect] of its
            // frame, at near_clip along its z: the frame's scale sizes it
            // (and the near distance), and it must keep pixels square.
            if !(depth_scale > 0.0) {
                return Err(self.fail(
                    e,
                    "the sensor's to_world flattens its view direction to nothing".into(),
                ));
            }
            if !(x_scale > 0.0 && (y_scale / x_scale - 1.0).abs() <= 1e-3) {
                return Err(self.fail(
                    e,
                    format!(
                        "the sensor's to_world scales x by {x_scale} and y by {y_scale}: an \
                         orthographic view must scale both alike"
                    ),
                ));
            }
            let near = near_clip * depth_scale;
            (
                near,
                near + far_clip - near_clip,
                Some(2.0 * y_scale / aspect),
            )
        } else {
            if lengths.iter().any(|l| (l - 1.0).abs() > 1e-3) {
                return Err(self.fail(
                    e,
                    "the sensor's to_world scales: a camera's transform may only turn and move it"
                        .into(),
                ));
            }
            (near_clip, far_clip, None)
        };
        let unit = |v: [f64; 3], l: f64| v.map(|c| c / l);
        let (forward, up) = (unit(forward, depth_scale), unit(up, y_scale));
        let mut camera = CameraDesc {
            vfov: vfov.map_or(CameraDesc::default().vfov, f64::to_degrees),
            ortho_height,
            lookfrom: origin,
            lookat: [
                origin[0] + forward[0],
                origin[1] + forward[1],
                origin[2] + forward[2],
            ],
            vup: up,
            // Mitsuba's image runs along −x of the sensor's frame: a frame
            // that mirrors mirrors the image.
            mirror: transform::det3(&to_world) < 0.0,
            ..CameraDesc::default()
        };
        if t == "thinlens" {
            known.extend(["aperture_radius", "focus_distance"]);
            let radius = p.float("aperture_radius", self)?.ok_or_else(|| {
                self.fail(e, "a thinlens sensor needs an `aperture_radius`".into())
            })?;
            // Mitsuba focuses at the far clipping plane by default.
            let focus = p.float("focus_distance", self)?.unwrap_or(far_clip);
            if !(radius >= 0.0 && focus > 0.0) {
                return Err(self.fail(
                    e,
                    "aperture_radius must be ≥ 0 and focus_distance > 0".into(),
                ));
            }
            camera.defocus_angle = (2.0 * (radius / focus).atan()).to_degrees();
            camera.focus_dist = Some(focus);
        }
        // Mitsuba takes a medium nested in the sensor, whatever its name,
        // as the one the camera stands in.
        camera.medium = match p.objects("medium")[..] {
            [] => None,
            [m] => Some(self.medium(m)?),
            _ => return Err(self.fail(e, "a sensor stands in one <medium>".into())),
        };
        p.finish(&known, self)?;
        camera.near_clip = near_clip;
        camera.far_clip = Some(far_clip);
        self.desc.camera = camera;
        self.desc.render.width = width;
        self.desc.render.height = Some(height);
        Ok(())
    }

    /// The width over the height of the image of texture `name` (1 for a
    /// texture that is no image), from the image file's header.
    fn image_aspect(&self, name: &str, e: &Element) -> Result<f64, Failure> {
        let Some(TextureDesc::Image { file, .. }) = self.desc.textures.get(name) else {
            return Ok(1.0);
        };
        match crate::texture::image::Image::dimensions(&self.dir.join(file)) {
            Ok((w, h)) => Ok(f64::from(w) / f64::from(h)),
            Err(err) => Err(self.fail(e, format!("image `{file}`: {err}"))),
        }
    }

    /// A perspective sensor's vertical field of view in radians, from its
    /// `fov` and `fov_axis` or its `focal_length`.
    fn vertical_fov(&self, e: &Element, p: &Props, aspect: f64) -> Result<f64, Failure> {
        let fov = p.float("fov", self)?;
        let focal = p.string("focal_length", self)?;
        let x_fov = match (fov, focal) {
            (Some(_), Some(_)) => {
                return Err(self.fail(e, "give `fov` or `focal_length`, not both".into()))
            }
            (Some(fov), None) => {
                let axis = p
                    .string("fov_axis", self)?
                    .unwrap_or("x")
                    .to_ascii_lowercase();
                let half = (fov.to_radians() / 2.0).tan();
                let x = match axis.as_str() {
                    "x" => fov.to_radians(),
                    "y" => 2.0 * (half * aspect).atan(),
                    "diagonal" => {
                        2.0 * ((2.0 * half) / (1.0 + 1.0 / (aspect * aspect)).sqrt() / 2.0).atan()
                    }
                    "smaller" if aspect > 1.0 => 2.0 * (half * aspect).atan(),
                    "smaller" => fov.to_radians(),
                    "larger" if aspect > 1.0 => fov.to_radians(),
                    "larger" => 2.0 * (half * aspect).atan(),
                    other => {
                        return Err(self.fail(
                            e,
                            format!(
                                "fov_axis `{other}`: expected x, y, diagonal, smaller or larger"
                            ),
                        ))
                    }
                };
                x
            }
            (None, focal) => {
                let f = focal.unwrap_or("50mm");
                let mm: f64 = f.trim_end_matches("mm").parse().map_err(|_| {
                    self.fail(
                        e,
                        format!("focal_length `{f}`: expected millimetres, as \"50mm\""),
                    )
                })?;
                // A 35 mm film's diagonal.
                let diagonal = 2.0 * ((36f64.hypot(24.0)) / (2.0 * mm)).atan();
                let half = (diagonal / 2.0).tan();
                2.0 * (2.0 * half / (1.0 + 1.0 / (aspect * aspect)).sqrt() / 2.0).atan()
            }
        };
        if !(x_fov > 0.0 && x_fov < std::f64::consts::PI) {
            return Err(self.fail(
                e,
                "the field of view must lie between 0 and 180 degrees".into(),
            ));
        }
        Ok(2.0 * ((x_fov / 2.0).tan() / aspect).atan())
    }

    fn film(&mut self, e: &Element) -> Result<(u32, u32), Failure> {
        if self.type_of(e)? != "hdrfilm" {
            return Err(self.unknown_type(e, "film", &["hdrfilm"]));
        }
        let p = Props::of(e, self)?;
        let size = |p: &Props, n: &str, d: i64, cx: &Self| -> Result<u32, Failure> {
            let v = p.integer(n, cx)?.unwrap_or(d);
            u32::try_from(v)
                .ok()
                .filter(|v| (1..=1 << 20).contains(v))
                .ok_or_else(|| cx.fail(e, format!("{n} must be from 1 to 1048576, got {v}")))
        };
        let width = size(&p, "width", 768, self)?;
        let height = size(&p, "height", 576, self)?;
        let mut crop = [0, 0, width, height];
        let mut cropped = false;
        for (i, n) in [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ]
        .iter()
        .enumerate()
        {
            if let Some(v) = p.integer(n, self)? {
                crop[i] = u32::try_from(v)
                    .map_err(|_| self.fail(e, format!("{n} must not be negative, got {v}")))?;
                cropped = true;
            }
        }
        if cropped {
            // The window's size defaults to the image's, as Mitsuba's.
            self.desc.render.crop = Some(crop);
        }
        for n in ["pixel_format", "component_format", "file_format"] {
            let _ = p.string(n, self)?; // lumen's output follows -o.
        }
        let _ = p.boolean("sample_border", self)?;
        let _ = p.boolean("banner", self)?;
        let _ = p.boolean("high_quality_edges", self)?;
        let filters = p.objects("rfilter");
        let (filter, stddev) = match filters[..] {
            // Mitsuba's default.
            [] => (PixelFilterDesc::Gaussian, None),
            [f] => {
                let fp = Props::of(f, self)?;
                match self.type_of(f)? {
                    "box" => {
                        fp.finish(&[], self)?;
                        (PixelFilterDesc::Box, None)
                    }
                    "gaussian" => {
                        let s = fp.float("stddev", self)?;
                        fp.finish(&["stddev"], self)?;
                        (PixelFilterDesc::Gaussian, s)
                    }
                    _ => return Err(self.unknown_type(f, "rfilter", &["box", "gaussian"])),
                }
            }
            _ => return Err(self.fail(e, "a film has one <rfilter>".into())),
        };
        self.desc.render.pixel_filter = filter;
        self.desc.render.filter_stddev = stddev;
        p.finish(
            &[
                "width",
                "height",
                "crop_offset_x",
                "crop_offset_y",
                "crop_width",
                "crop_height",
                "pixel_format",
                "component_format",
                "file_format",
                "sample_border",
                "banner",
                "high_quality_edges",
            ],
            self,
        )?;
        Ok((width, height))
    }

    fn sampler(&mut self, e: &Element) -> Result<(), Failure> {
        let t = self.type_of(e)?;
        let kind = match t {
            "independent" => SamplingDesc::Independent,
            "stratified" | "multijitter" => SamplingDesc::Stratified,
            "ldsampler" | "orthogonal" => SamplingDesc::ZSobol,
            _ => {
                return Err(self.unknown_type(
                    e,
                    "sampler",
                    &[
                        "independent",
                        "stratified",
                        "multijitter",
                        "ldsampler",
                        "orthogonal",
                    ],
                ))
            }
        };
        let p = Props::of(e, self)?;
        if let Some(n) = p.integer("sample_count", self)? {
            self.desc.render.samples_per_pixel = u32::try_from(n)
                .ok()
                .filter(|n| *n >= 1)
                .ok_or_else(|| self.fail(e, format!("sample_count must be at least 1, got {n}")))?;
        }
        if let Some(s) = p.integer("seed", self)? {
            self.desc.render.seed = u64::try_from(s)
                .map_err(|_| self.fail(e, format!("seed must not be negative, got {s}")))?;
        }
        let _ = p.boolean("jitter", self)?;
        let _ = p.integer("strength", self)?;
        let _ = p.integer("dimension", self)?;
        p.finish(
            &["sample_count", "seed", "jitter", "strength", "dimension"],
            self,
        )?;
        self.desc.render.sampler = kind;
        Ok(())
    }

    // ----------------------------------------------------------------
    // Emitters

    fn emitter(&mut self, e: &'d Element) -> Result<(), Failure> {
        let t = self.type_of(e)?;
        let p = Props::of(e, self)?;
        let colour = |cx: &Self, p: &Props, n: &str| -> Result<[f64; 3], Failure> {
            match p.colour(n, Use::Emission, cx)? {
                None => Ok([1.0; 3]),
                Some(Colour::Rgb(c)) => Ok(c),
                Some(Colour::Texture(t)) => Err(cx.fail(
                    t,
                    format!("a textured `{n}` of this emitter is not supported"),
                )),
            }
        };
        match t {
            "constant" | "envmap" => {
                if let Some(first) = self.background {
                    return Err(self.fail(
                        e,
                        format!(
                            "a second environment emitter (the first is at line {}): lumen has one background",
                            first.at.line
                        ),
                    ));
                }
                self.background = Some(e);
                if t == "constant" {
                    let c = colour(self, &p, "radiance")?;
                    p.finish(&["radiance"], self)?;
                    self.desc.background = BackgroundDesc::Solid { color: c };
                } else {
                    let (name, at) = p
                        .string_at("filename", self)?
                        .ok_or_else(|| self.fail(e, "an envmap needs a `filename`".into()))?;
                    let file = self.file(name, at)?;
                    let scale = p.float("scale", self)?.unwrap_or(1.0);
                    let m = p.transform("to_world", self)?.unwrap_or(IDENTITY);
                    let (rotation, frame) = self.envmap_orientation(e, &m)?;
                    let _ = p.boolean("mis_compensation", self)?;
                    p.finish(&["filename", "scale", "to_world", "mis_compensation"], self)?;
                    self.desc.background = BackgroundDesc::Image {
                        file,
                        rotation,
                        intensity: scale,
                        rows_at_poles: true,
                        layout: Default::default(),
                        frame,
                    };
                }
                // Mitsuba samples its environment as a light.
                self.desc.render.sample_background = Some(true);
                Ok(())
            }
            "point" => {
                let intensity = colour(self, &p, "intensity")?;
                let position = match (p.point("position", self)?, p.transform("to_world", self)?) {
                    (Some(_), Some(_)) => {
                        return Err(self.fail(e, "give `position` or `to_world`, not both".into()))
                    }
                    (Some(x), None) => x,
                    (None, Some(m)) => transform::point(&m, [0.0; 3]),
                    (None, None) => [0.0; 3],
                };
                p.finish(&["position", "to_world", "intensity"], self)?;
                self.desc.lights.push(LightDesc::Point(PointLightDesc {
                    position,
                    intensity,
                }));
                Ok(())
            }
            "spot" => {
                let intensity = colour(self, &p, "intensity")?;
                let m = p.transform("to_world", self)?.unwrap_or(IDENTITY);
                let cutoff = p.float("cutoff_angle", self)?;
                let beam = p.float("beam_width", self)?;
                let texture = match p.colour("texture", Use::Reflectance, self)? {
                    None => None,
                    Some(Colour::Texture(t)) => Some(self.texture(t, false)?),
                    Some(Colour::Rgb(_)) => {
                        return Err(self.fail(e, "a spot light's `texture` is an image".into()))
                    }
                };
                p.finish(
                    &[
                        "to_world",
                        "intensity",
                        "cutoff_angle",
                        "beam_width",
                        "texture",
                    ],
                    self,
                )?;
                self.desc.lights.push(LightDesc::Spot(SpotLightDesc {
                    position: transform::point(&m, [0.0; 3]),
                    direction: Some(transform::vector(&m, [0.0, 0.0, 1.0])),
                    target: None,
                    intensity,
                    cutoff_angle: cutoff,
                    beam_width: beam,
                    // Mitsuba's image has its top towards the light's -y
                    // and its u along +x: lumen's, seen up = -y.
                    up: texture
                        .is_some()
                        .then(|| transform::vector(&m, [0.0, -1.0, 0.0])),
                    texture,
                    falloff: None,
                }));
                Ok(())
            }
            "projector" => {
                let m = p.transform("to_world", self)?.unwrap_or(IDENTITY);
                let scale = p.float("scale", self)?.unwrap_or(1.0);
                let (colour, texture) = match p.colour("irradiance", Use::Emission, self)? {
                    None => return Err(self.fail(e, "a projector needs an `irradiance`".into())),
                    Some(Colour::Rgb(c)) => (c, None),
                    Some(Colour::Texture(t)) => ([1.0; 3], Some(self.texture(t, false)?)),
                };
                // Mitsuba frames the image as its perspective camera
                // frames the film: the field of view's axis refers to
                // the image's shape (a colour's is a single texel's).
                let aspect = match &texture {
                    Some(name) => self.image_aspect(name, e)?,
                    None => 1.0,
                };
                let vfov = self.vertical_fov(e, &p, aspect)?;
                let fov = 2.0 * ((vfov / 2.0).tan() * aspect).atan();
                p.finish(
                    &[
                        "to_world",
                        "scale",
                        "irradiance",
                        "fov",
                        "fov_axis",
                        "focal_length",
                    ],
                    self,
                )?;
                let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
                    .map(|v| transform::vector(&m, v));
                let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                let turns = (0..3).all(|i| {
                    (0..3).all(|j| {
                        (dot(axes[i], axes[j]) - f64::from(u8::from(i == j))).abs() <= 1e-3
                    })
                });
                if !turns || transform::det3(&m) < 0.0 {
                    return Err(self.fail(
                        e,
                        "a projector's to_world may only turn and move it (no scale, shear or \
                         mirror)"
                            .into(),
                    ));
                }
                // Mitsuba's irradiance of 1 lights the plane at unit
                // distance with π; its image's top lies towards the frame's
                // +y and its u runs along −x, which is lumen's right for
                // that up.
                let irradiance = colour.map(|c| std::f64::consts::PI * scale * c);
                self.desc
                    .lights
                    .push(LightDesc::Projector(ProjectorLightDesc {
                        position: transform::point(&m, [0.0; 3]),
                        direction: Some(axes[2]),
                        target: None,
                        up: Some(axes[1]),
                        fov: fov.to_degrees(),
                        irradiance: Some(irradiance),
                        intensity: None,
                        texture,
                        aspect: None,
                    }));
                Ok(())
            }
            "directional" => {
                let irradiance = colour(self, &p, "irradiance")?;
                let direction = match (p.point("direction", self)?, p.transform("to_world", self)?)
                {
                    (Some(_), Some(_)) => {
                        return Err(self.fail(e, "give `direction` or `to_world`, not both".into()))
                    }
                    (Some(d), None) => d,
                    (None, Some(m)) => transform::vector(&m, [0.0, 0.0, 1.0]),
                    (None, None) => [0.0, 0.0, 1.0],
                };
                p.finish(&["direction", "to_world", "irradiance"], self)?;
                self.desc
                    .lights
                    .push(LightDesc::Directional(DirectionalLightDesc {
                        direction,
                        irradiance,
                        angular_radius: None,
                    }));
                Ok(())
            }
            "area" => Err(self.fail(
                e,
                "an area emitter belongs inside the <shape> that emits".into(),
            )),
            _ => Err(self.unknown_type(e, "emitter", EMITTERS)),
        }
    }

    /// An environment map's orientation from its `to_world` `m`: a turn
    /// about +y in degrees (lumen's `rotation`, Mitsuba's half-turn apart
    /// added), and the map's axes in the world when it turns otherwise
    /// (lumen's `frame`). Its translation does not matter (the map is at
    /// infinity); a scale, shear or mirror is refused.
    fn envmap_orientation(
        &self,
        e: &Element,
        m: &Mat4,
    ) -> Result<(f64, Option<[Triple; 3]>), Failure> {
        let axes =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|v| transform::vector(m, v));
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let rotation = (0..3).all(|i| {
            (0..3).all(|j| (dot(axes[i], axes[j]) - f64::from(u8::from(i == j))).abs() < 1e-4)
        }) && crate::scene::file::matrix::det3(m) > 0.0;
        if !rotation {
            return Err(self.fail(
                e,
                "an environment map's to_world must turn it (no scale, shear or mirror)".into(),
            ));
        }
        let [x, y, _] = axes;
        let about_y = y[0].abs() < 1e-6 && (y[1] - 1.0).abs() < 1e-6 && y[2].abs() < 1e-6;
        // Mitsuba's image centre looks along +z, lumen's along -z: half a
        // turn apart.
        if about_y {
            // Counter-clockwise seen from above (+y) turns +x towards -z.
            let turn = -x[2].atan2(x[0]).to_degrees();
            return Ok(((180.0 + turn).rem_euclid(360.0), None));
        }
        Ok((180.0, Some(axes)))
    }

    // ----------------------------------------------------------------
    // Shapes

    fn shape(&mut self, e: &'d Element, outer: &Mat4) -> Result<(), Failure> {
        let t = self.type_of(e)?;
        if t == "instance" {
            return self.instance(e, outer);
        }
        let p = Props::of(e, self)?;
        let local = p.transform("to_world", self)?.unwrap_or(IDENTITY);
        let m = transform::mul(outer, &local);
        if transform::det3(&m) == 0.0 {
            return Err(self.fail(
                e,
                "the shape's to_world is singular: it flattens the shape".into(),
            ));
        }
        let mut known = vec![
            "to_world",
            "bsdf",
            "emitter",
            "flip_normals",
            "interior",
            "exterior",
            "id",
        ];
        let flip = p.boolean("flip_normals", self)? == Some(true);
        // A mesh's outside is the side its winding gives in the shape's own
        // to_world (which a mirror turns, in Mitsuba), where lumen's
        // meshes keep it under a mirror; an instance's transform keeps it
        // in both.
        let winding_turned = flip != (transform::det3(&local) < 0.0);
        let mut material = self.shape_material(e, &p)?;
        let interior = p.peek("interior").map(|m| self.medium(m)).transpose()?;
        let exterior = p.peek("exterior").map(|m| self.medium(m)).transpose()?;
        if interior.is_some() || exterior.is_some() {
            p.take("interior");
            p.take("exterior");
            let null = p.objects("bsdf").first().and_then(|b| b.attr("type")) == Some("null")
                && p.objects("emitter").is_empty();
            material = self.with_media(material, interior, exterior, null);
        }
        let matrix = |m: &Mat4| -> Vec<TransformDesc> {
            if *m == IDENTITY {
                Vec::new()
            } else {
                vec![TransformDesc::Matrix(*m)]
            }
        };
        let object = match t {
            "obj" | "ply" | "serialized" => {
                known.extend(["filename", "face_normals"]);
                let (name, at) = p
                    .string_at("filename", self)?
                    .ok_or_else(|| self.fail(e, format!("a {t} shape needs a `filename`")))?;
                let file = self.file(name, at)?;
                let flat = p.boolean("face_normals", self)?.unwrap_or(false);
                let part = if t == "serialized" {
                    // Serialized texture coordinates are read as written.
                    known.push("shape_index");
                    match p.integer("shape_index", self)?.unwrap_or(0) {
                        i @ 0..=0xFFFF_FFFF => Some(i as u32),
                        i => return Err(self.fail(e, format!("shape_index must be ≥ 0, got {i}"))),
                    }
                } else {
                    // Mitsuba's v runs down the image, lumen's up: Mitsuba
                    // turns an OBJ's over (OBJ's v runs up, as lumen's), and
                    // takes a PLY's as written (v down), which lumen turns
                    // over (`flip_v`).
                    known.push("flip_tex_coords");
                    let flip = p.boolean("flip_tex_coords", self)?;
                    if flip.is_some_and(|f| f != (t == "obj")) {
                        self.lacks(
                            e,
                            "flip_tex_coords other than the format's default",
                            "the default",
                        )?;
                    }
                    None
                };
                ObjectDesc::Mesh {
                    flip_normals: winding_turned,
                    file,
                    material: Some(material),
                    smooth: !flat,
                    allow_outside: false,
                    part,
                    flip_v: t == "ply",
                    transform: matrix(&m),
                }
            }
            "sphere" => {
                known.extend(["center", "radius"]);
                let center = p.point("center", self)?.unwrap_or([0.0; 3]);
                let radius = p.float("radius", self)?.unwrap_or(1.0);
                // Turned so that its (u, v) are Mitsuba's.
                let turn = crate::scene::file::matrix::z_up_sphere(center);
                ObjectDesc::Sphere {
                    flip_normals: flip,
                    center,
                    radius,
                    material,
                    transform: matrix(&crate::scene::file::matrix::mul(&m, &turn)),
                }
            }
            "rectangle" => {
                let desc = &self.desc.materials[&material];
                let emits =
                    matches!(desc, MaterialDesc::Emissive(_)) || desc.surface().emission.is_some();
                if emits {
                    // A light stays a quad, which light sampling sees by
                    // its solid angle, turned over in y so that its (α, β)
                    // are Mitsuba's (u, v) with v up the image (a mirror
                    // keeps a quad's side).
                    let mirror = crate::scene::file::matrix::scaling([1.0, -1.0, 1.0]);
                    ObjectDesc::Quad {
                        flip_normals: flip,
                        corner: [-1.0, -1.0, 0.0],
                        u: [2.0, 0.0, 0.0],
                        v: [0.0, 2.0, 0.0],
                        material,
                        transform: matrix(&crate::scene::file::matrix::mul(&m, &mirror)),
                    }
                } else {
                    // Two triangles, so that the texture coordinates are
                    // Mitsuba's: (0, 0) at (−1, −1), v down the image
                    // (lumen's runs up it: 1 − v). Mitsuba's normal is
                    // to_world's image of +z, which a mirror keeps on its
                    // side, as lumen's winding does.
                    ObjectDesc::Triangles {
                        flip_normals: flip,
                        positions: vec![
                            [-1.0, -1.0, 0.0],
                            [1.0, -1.0, 0.0],
                            [1.0, 1.0, 0.0],
                            [-1.0, 1.0, 0.0],
                        ],
                        indices: vec![[0, 1, 2], [0, 2, 3]],
                        normals: None,
                        uvs: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
                        material,
                        transform: matrix(&m),
                    }
                }
            }
            // Mitsuba's cube is a mesh.
            "cube" => ObjectDesc::Box {
                flip_normals: winding_turned,
                min: [-1.0; 3],
                max: [1.0; 3],
                material,
                transform: matrix(&m),
            },
            "disk" => {
                // Mitsuba's v runs down the image, lumen's up: the disk
                // turned over in y (v = φ/2π becomes 1 − φ/2π), which
                // keeps its side.
                let m = crate::scene::file::matrix::mul(
                    &m,
                    &crate::scene::file::matrix::scaling([1.0, -1.0, 1.0]),
                );
                ObjectDesc::Disk {
                    flip_normals: flip,
                    center: [0.0; 3],
                    normal: [0.0, 0.0, 1.0],
                    radius: 1.0,
                    material,
                    transform: matrix(&m),
                }
            }
            "cylinder" => {
                known.extend(["p0", "p1", "radius"]);
                let p0 = p.point("p0", self)?.unwrap_or([0.0; 3]);
                let p1 = p.point("p1", self)?.unwrap_or([0.0, 0.0, 1.0]);
                let radius = p.float("radius", self)?.unwrap_or(1.0);
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(self.fail(
                        e,
                        format!("a cylinder's radius must be above 0, got {radius}"),
                    ));
                }
                let Some(unit) = crate::geometry::quadric::cylinder_placement(p0, p1, radius)
                else {
                    return Err(self.fail(e, "a cylinder's p0 and p1 must differ".into()));
                };
                // Mitsuba's v (along the axis) runs down the image, lumen's
                // up: z becomes 1 − z.
                use crate::scene::file::matrix::{mul, scaling, translation};
                let along = mul(&translation([0.0, 0.0, 1.0]), &scaling([1.0, 1.0, -1.0]));
                ObjectDesc::Cylinder {
                    flip_normals: flip,
                    p0: [0.0; 3],
                    p1: [0.0, 0.0, 1.0],
                    radius: 1.0,
                    material,
                    transform: matrix(&mul(&m, &mul(&unit, &along))),
                }
            }
            "shapegroup" => {
                return Err(self.fail(
                    e,
                    "a shapegroup is placed by <shape type=\"instance\">".into(),
                ))
            }
            _ => return Err(self.unknown_type(e, "shape", SHAPES)),
        };
        p.finish(&known, self)?;
        self.desc.objects.push(object);
        Ok(())
    }

    fn instance(&mut self, e: &'d Element, outer: &Mat4) -> Result<(), Failure> {
        let p = Props::of(e, self)?;
        let m = transform::mul(outer, &p.transform("to_world", self)?.unwrap_or(IDENTITY));
        let groups = p.objects("shape");
        p.finish(&["to_world"], self)?;
        let [group] = groups[..] else {
            return Err(self.fail(e, "an instance places exactly one shapegroup".into()));
        };
        if group.attr("type") != Some("shapegroup") {
            return Err(self.fail(e, "an instance places a <shape type=\"shapegroup\">".into()));
        }
        for s in &group.children {
            match s.tag.as_str() {
                "shape" => self.shape(s, &m)?,
                "ref" => {
                    let r = self.resolve(s)?;
                    self.shape(r, &m)?
                }
                _ => return Err(self.fail(s, "a shapegroup holds shapes only".into())),
            }
        }
        Ok(())
    }

    /// The material of shape `e`: its BSDF's (a grey one-sided diffuse
    /// by default, Mitsuba's), with its area emitter's light.
    fn shape_material(&mut self, e: &'d Element, p: &Props<'d>) -> Result<String, Failure> {
        let bsdfs = p.objects("bsdf");
        let emitters = p.objects("emitter");
        if bsdfs.len() > 1 || emitters.len() > 1 {
            return Err(self.fail(e, "a shape has at most one <bsdf> and one <emitter>".into()));
        }
        let radiance = match emitters.first() {
            None => None,
            Some(em) => {
                if self.type_of(em)? != "area" {
                    return Err(self.fail(em, "a shape's emitter is an area emitter".into()));
                }
                let ep = Props::of(em, self)?;
                let c = match ep.colour("radiance", Use::Emission, self)? {
                    None => ColorDesc::Rgb([1.0; 3]),
                    Some(Colour::Rgb(c)) => ColorDesc::Rgb(c),
                    Some(Colour::Texture(t)) => ColorDesc::Texture(self.texture(t, false)?),
                };
                ep.finish(&["radiance"], self)?;
                Some(c)
            }
        };
        let Some(radiance) = radiance else {
            return match bsdfs.first() {
                Some(b) => self.bsdf(b),
                None => self.default_material(),
            };
        };
        // The emitter's light on (a copy of) the BSDF's material; a light
        // without a BSDF scatters nothing, as Mitsuba's black diffuse.
        let mut desc = match bsdfs.first() {
            Some(b) => {
                let name = self.bsdf(b)?;
                self.desc.materials[&name].clone()
            }
            None => MaterialDesc::Emissive(EmissiveDesc::new(radiance.clone())),
        };
        if !matches!(desc, MaterialDesc::Emissive(_)) {
            *desc.surface_mut().emission = Some(radiance);
        }
        let name = self.name("light");
        self.desc.materials.insert(name.clone(), desc);
        Ok(name)
    }

    fn default_material(&mut self) -> Result<String, Failure> {
        const NAME: &str = "mitsuba-default";
        if !self.desc.materials.contains_key(NAME) {
            let mut d = DiffuseDesc::new([0.5; 3]);
            d.one_sided = true;
            self.desc
                .materials
                .insert(NAME.into(), MaterialDesc::Diffuse(d));
        }
        Ok(NAME.into())
    }

    // ----------------------------------------------------------------
    // BSDFs

    /// The material of BSDF element `e` (converted once).
    fn bsdf(&mut self, e: &'d Element) -> Result<String, Failure> {
        let key = e as *const Element;
        if let Some(name) = self.materials.get(&key) {
            return Ok(name.clone());
        }
        let desc = self.bsdf_desc(e)?;
        let name = match e.attr("id") {
            Some(id) if !self.desc.materials.contains_key(id) => id.to_string(),
            _ => self.name("bsdf"),
        };
        self.desc.materials.insert(name.clone(), desc);
        self.materials.insert(key, name.clone());
        Ok(name)
    }

    /// A child BSDF of wrapper `e`.
    fn nested(&mut self, e: &'d Element, p: &Props<'d>) -> Result<MaterialDesc, Failure> {
        match p.objects("bsdf")[..] {
            [] => Err(self.fail(e, format!("{} wraps a <bsdf>", describe(e)))),
            [first, ref rest @ ..] => {
                if !rest.is_empty() {
                    self.lacks(e, &format!("{} with two BSDFs", describe(e)), "the first")?;
                }
                self.bsdf_desc(first)
            }
        }
    }

    fn bsdf_desc(&mut self, e: &'d Element) -> Result<MaterialDesc, Failure> {
        let t = self.type_of(e)?;
        let p = Props::of(e, self)?;
        let desc = match t {
            "diffuse" => {
                let albedo = self
                    .colour(&p, "reflectance", Use::Reflectance)?
                    .unwrap_or(ColorDesc::Rgb([0.5; 3]));
                p.finish(&["reflectance"], self)?;
                let mut d = DiffuseDesc::new([0.5; 3]);
                d.albedo = albedo;
                d.one_sided = true;
                MaterialDesc::Diffuse(d)
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                let ior = self.ior_ratio(e, &p, 1.5046)?;
                self.unit_factor(e, &p, "specular_reflectance")?;
                self.unit_factor(e, &p, "specular_transmittance")?;
                let mut known = vec![
                    "int_ior",
                    "ext_ior",
                    "specular_reflectance",
                    "specular_transmittance",
                ];
                let mut d = DielectricDesc::new(ior);
                d.thin = t == "thindielectric";
                if t == "roughdielectric" {
                    known.extend(MICROFACET_PARAMS);
                    let (alpha, distribution) = self.microfacets(e, &p)?;
                    d.alpha = Some(alpha);
                    d.distribution = Some(distribution);
                } else {
                    d.fresnel = Some(FresnelDesc::Exact);
                }
                p.finish(&known, self)?;
                MaterialDesc::Dielectric(d)
            }
            "conductor" | "roughconductor" => {
                let mut d = ConductorDesc::default();
                let material = p.string("material", self)?;
                let eta = self.unbounded(&p, "eta")?;
                let k = self.unbounded(&p, "k")?;
                match (material, eta, k) {
                    (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                        return Err(
                            self.fail(e, "give `material` or `eta` and `k`, not both".into())
                        )
                    }
                    (Some("none") | None, None, None) => {
                        // Mitsuba's default: a perfect mirror.
                        d.eta = Some(ColorDesc::Rgb([0.0; 3]));
                        d.k = Some(ColorDesc::Rgb([1.0; 3]));
                    }
                    (Some(name), None, None) => {
                        if crate::material::metals::find(name).is_none() {
                            return Err(
                                self.fail(e, format!("unknown conductor material `{name}`"))
                            );
                        }
                        d.metal = Some(name.to_string());
                    }
                    (None, eta, k) => {
                        d.eta = Some(eta.unwrap_or(ColorDesc::Rgb([0.0; 3])));
                        d.k = Some(k.unwrap_or(ColorDesc::Rgb([1.0; 3])));
                    }
                }
                self.unit_factor(e, &p, "specular_reflectance")?;
                let mut known = vec!["material", "eta", "k", "specular_reflectance"];
                if t == "roughconductor" {
                    known.extend(MICROFACET_PARAMS);
                    let (alpha, distribution) = self.microfacets(e, &p)?;
                    d.alpha = Some(alpha);
                    d.distribution = Some(distribution);
                }
                p.finish(&known, self)?;
                d.one_sided = true;
                MaterialDesc::Conductor(d)
            }
            "plastic" | "roughplastic" => {
                let albedo = self
                    .colour(&p, "diffuse_reflectance", Use::Reflectance)?
                    .unwrap_or(ColorDesc::Rgb([0.5; 3]));
                let ior = self.ior_ratio(e, &p, 1.49)?;
                self.unit_factor(e, &p, "specular_reflectance")?;
                let nonlinear = p.boolean("nonlinear", self)?.unwrap_or(false);
                let mut known = vec![
                    "diffuse_reflectance",
                    "specular_reflectance",
                    "int_ior",
                    "ext_ior",
                    "nonlinear",
                ];
                let mut d = PlasticDesc {
                    albedo: Some(albedo),
                    ior: Some(ior),
                    nonlinear: Some(nonlinear),
                    ..PlasticDesc::default()
                };
                if t == "roughplastic" {
                    known.extend(["distribution", "alpha", "sample_visible"]);
                    let (alpha, distribution) = self.microfacets(e, &p)?;
                    d.alpha = Some(alpha);
                    d.distribution = Some(distribution);
                }
                p.finish(&known, self)?;
                d.one_sided = true;
                MaterialDesc::Plastic(d)
            }
            "principled" => self.principled(e, &p)?,
            "twosided" => {
                let mut d = self.nested(e, &p)?;
                p.finish(&[], self)?;
                self.two_sided(&mut d);
                d
            }
            "mask" => {
                let opacity = match p.scalar("opacity", self)? {
                    None => ScalarDesc::Value(0.5),
                    Some(Colour::Rgb(c)) => {
                        ScalarDesc::Value(((c[0] + c[1] + c[2]) / 3.0).clamp(0.0, 1.0))
                    }
                    Some(Colour::Texture(t)) => ScalarDesc::Texture(self.texture(t, true)?),
                };
                let mut d = self.nested(e, &p)?;
                p.finish(&["opacity"], self)?;
                *d.surface_mut().opacity = Some(opacity);
                d
            }
            "normalmap" if self.identity_normals(&p) => {
                // A constant normal of (0, 0, 1) tilts nothing: the nested
                // BSDF as it is.
                let _ = p.objects("texture");
                let _ = p.boolean("flip_invalid_normals", self)?;
                let _ = p.boolean("use_shadowing_function", self)?;
                let d = self.nested(e, &p)?;
                p.finish(
                    &[
                        "normalmap",
                        "flip_invalid_normals",
                        "use_shadowing_function",
                    ],
                    self,
                )?;
                d
            }
            "bumpmap" | "normalmap" => {
                let map = if t == "normalmap" {
                    match p.colour("normalmap", Use::Unbounded, self)? {
                        Some(Colour::Texture(tex)) => self.texture(tex, false)?,
                        _ => {
                            return Err(
                                self.fail(e, "a normalmap needs a `normalmap` texture".into())
                            )
                        }
                    }
                } else {
                    let textures = p.objects("texture");
                    let [tex] = textures[..] else {
                        return Err(
                            self.fail(e, "a bumpmap needs one <texture> (the height)".into())
                        );
                    };
                    self.texture(tex, true)?
                };
                let scale = if t == "bumpmap" {
                    p.float("scale", self)?
                } else {
                    None
                };
                if p.boolean("flip_invalid_normals", self)? == Some(false) {
                    self.lacks(e, "flip_invalid_normals = false", "flipped normals")?;
                }
                let shadowing = p.boolean("use_shadowing_function", self)?.unwrap_or(true);
                let mut d = self.nested(e, &p)?;
                p.finish(
                    &[
                        "normalmap",
                        "scale",
                        "flip_invalid_normals",
                        "use_shadowing_function",
                    ],
                    self,
                )?;
                let s = d.surface_mut();
                *s.bump_shadowing = shadowing;
                if t == "normalmap" {
                    *s.normal_map = Some(map);
                } else {
                    *s.bump_map = Some(map);
                    *s.bump_scale = scale;
                }
                d
            }
            "null" => {
                p.finish(&[], self)?;
                let mut d = DiffuseDesc::new([0.0; 3]);
                d.opacity = Some(ScalarDesc::Value(0.0));
                MaterialDesc::Diffuse(d)
            }
            "blendbsdf" => {
                let weight = match p.scalar("weight", self)? {
                    None => ScalarDesc::Value(0.5),
                    Some(Colour::Rgb(c)) => ScalarDesc::Value(mean(c).clamp(0.0, 1.0)),
                    Some(Colour::Texture(t)) => ScalarDesc::Texture(self.texture(t, true)?),
                };
                let [first, second] = p.objects("bsdf")[..] else {
                    return Err(self.fail(e, "a blendbsdf blends two <bsdf>s".into()));
                };
                let (first, second) = (self.bsdf(first)?, self.bsdf(second)?);
                p.finish(&["weight"], self)?;
                // Each BSDF keeps its own sides: the blend adds none.
                MaterialDesc::Mix(MixDesc::new(&first, &second, weight))
            }
            _ => return Err(self.unknown_type(e, "bsdf", BSDFS)),
        };
        Ok(desc)
    }

    /// Makes `d` scatter on both sides, as Mitsuba's `twosided` does: a
    /// blend's BSDFs too (copies of them, as another shape may use them
    /// one-sided).
    fn two_sided(&mut self, d: &mut MaterialDesc) {
        *d.surface_mut().one_sided = false;
        if let MaterialDesc::Mix(mix) = d {
            for name in &mut mix.materials {
                let mut part = self.desc.materials[name.as_str()].clone();
                self.two_sided(&mut part);
                *name = self.name("twosided");
                self.desc.materials.insert(name.clone(), part);
            }
        }
    }

    /// Whether a normal map's `normalmap` is a `rawconstant` texture of
    /// the untilted normal, (0.5, 0.5, 1) (taking the parameter if so).
    fn identity_normals(&self, p: &Props<'d>) -> bool {
        let Some(tex) = p.peek("normalmap") else {
            return false;
        };
        if tex.tag != "texture" || tex.attr("type") != Some("rawconstant") {
            return false;
        }
        let Ok(inner) = Props::of(tex, self) else {
            return false;
        };
        let value = inner.point("value", self).ok().flatten();
        let identity = value == Some([0.5, 0.5, 1.0]) && inner.finish(&["value"], self).is_ok();
        if identity {
            p.take("normalmap");
        }
        identity
    }

    /// Mitsuba's Disney-style `principled` as lumen's glTF principled, as
    /// near as the two models come.
    fn principled(&mut self, e: &'d Element, p: &Props<'d>) -> Result<MaterialDesc, Failure> {
        let mut d = PrincipledDesc {
            base_color: Some(
                self.colour(p, "base_color", Use::Reflectance)?
                    .unwrap_or(ColorDesc::Rgb([0.5; 3])),
            ),
            ..PrincipledDesc::default()
        };
        d.roughness = Some(match self.scalar(p, "roughness")? {
            Some(ScalarDesc::Value(v)) => RoughnessDesc::Value(v),
            Some(ScalarDesc::Texture(t)) => RoughnessDesc::Texture(t),
            None => RoughnessDesc::Value(0.5),
        });
        d.metallic = self.scalar(p, "metallic")?;
        d.transmission = self.scalar(p, "spec_trans")?;
        d.clearcoat = self.scalar(p, "clearcoat")?;
        if let Some(g) = self.scalar(p, "clearcoat_gloss")? {
            d.clearcoat_roughness = Some(match g {
                ScalarDesc::Value(g) => ScalarDesc::Value(0.1 * (1.0 - g) + 0.001 * g),
                t => t,
            });
        }
        match (p.float("specular", self)?, p.float("eta", self)?) {
            (Some(_), Some(_)) => {
                return Err(self.fail(e, "give `specular` or `eta`, not both".into()))
            }
            (Some(s), None) => d.ior = Some(2.0 / (1.0 - (0.08 * s).sqrt()) - 1.0),
            (None, Some(eta)) => d.ior = Some(eta),
            (None, None) => {}
        }
        for n in [
            "anisotropic",
            "spec_tint",
            "sheen",
            "sheen_tint",
            "flatness",
        ] {
            if let Some(v) = self.scalar(p, n)? {
                if v != ScalarDesc::Value(0.0) {
                    self.lacks(e, &format!("principled `{n}`"), "none")?;
                }
            }
        }
        for n in [
            "main_specular_sampling_rate",
            "clearcoat_sampling_rate",
            "diffuse_reflectance_sampling_rate",
        ] {
            let _ = p.float(n, self)?;
        }
        p.finish(
            &[
                "base_color",
                "roughness",
                "metallic",
                "spec_trans",
                "clearcoat",
                "clearcoat_gloss",
                "specular",
                "eta",
                "anisotropic",
                "spec_tint",
                "sheen",
                "sheen_tint",
                "flatness",
                "main_specular_sampling_rate",
                "clearcoat_sampling_rate",
                "diffuse_reflectance_sampling_rate",
            ],
            self,
        )?;
        Ok(MaterialDesc::Principled(d))
    }

    /// `int_ior` over `ext_ior` (numbers or names; `int_default` and
    /// air when absent).
    fn ior_ratio(&self, e: &Element, p: &Props, int_default: f64) -> Result<f64, Failure> {
        let ior = |n: &str, default: f64| -> Result<f64, Failure> {
            if !p.has(n) {
                return Ok(default);
            }
            if let Ok(Some(v)) = p.float(n, self) {
                return Ok(v);
            }
            let name = p.string(n, self)?.unwrap_or("");
            crate::material::metals::find_ior(name)
                .map(f64::from)
                .ok_or_else(|| {
                    let names: Vec<&str> = crate::material::metals::IORS
                        .iter()
                        .map(|(n, _)| *n)
                        .collect();
                    self.fail_hint(
                        e,
                        format!(
                            "unknown index of refraction `{name}`; the named ones: {}",
                            names.join(", ")
                        ),
                        hint::closest(name, names.iter().copied())
                            .map(|k| format!("did you mean `{k}`?")),
                    )
                })
        };
        let int = ior("int_ior", int_default)?;
        let ext = ior("ext_ior", 1.000277)?;
        if !(int > 0.0 && ext > 0.0) {
            return Err(self.fail(
                e,
                format!("indices of refraction must be above 0, got {int} and {ext}"),
            ));
        }
        Ok(int / ext)
    }

    /// A factor lumen does not have, which must be 1.
    fn unit_factor(&mut self, e: &Element, p: &Props, n: &str) -> Result<(), Failure> {
        if !p.has(n) {
            return Ok(());
        }
        match p.colour(n, Use::Reflectance, self)? {
            Some(Colour::Rgb(c)) if c == [1.0; 3] => Ok(()),
            _ => self.lacks(e, &format!("`{n}` other than 1"), "1"),
        }
    }

    /// A colour not bounded by 1, or a texture (a conductor's `eta`,
    /// `k`).
    fn unbounded(&mut self, p: &Props<'d>, n: &str) -> Result<Option<ColorDesc>, Failure> {
        Ok(match p.colour(n, Use::Unbounded, self)? {
            None => None,
            Some(Colour::Rgb(c)) => Some(ColorDesc::Rgb(c)),
            Some(Colour::Texture(t)) => Some(ColorDesc::Texture(self.texture(t, false)?)),
        })
    }

    /// The microfacets of a rough BSDF: α (one, a pair or a texture) and
    /// the distribution (Mitsuba's default Beckmann, α 0.1).
    fn microfacets(
        &mut self,
        e: &Element,
        p: &Props<'d>,
    ) -> Result<(RoughnessDesc, DistributionDesc), Failure> {
        let distribution = match p.string("distribution", self)?.unwrap_or("beckmann") {
            "beckmann" => DistributionDesc::Beckmann,
            "ggx" => DistributionDesc::Ggx,
            other => {
                return Err(self.fail(
                    e,
                    format!("distribution `{other}`: expected beckmann or ggx"),
                ))
            }
        };
        let _ = p.boolean("sample_visible", self)?; // sampling only
        let alpha =
            |cx: &mut Self, n: &str| -> Result<Option<ScalarDesc>, Failure> { cx.scalar(p, n) };
        let a = alpha(self, "alpha")?;
        let (u, v) = (alpha(self, "alpha_u")?, alpha(self, "alpha_v")?);
        let roughness = match (a, u, v) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                return Err(self.fail(
                    e,
                    "give `alpha` or `alpha_u` and `alpha_v`, not both".into(),
                ))
            }
            (Some(ScalarDesc::Value(a)), None, None) => RoughnessDesc::Value(a),
            (Some(ScalarDesc::Texture(t)), None, None) => RoughnessDesc::Texture(t),
            (None, Some(ScalarDesc::Value(u)), Some(ScalarDesc::Value(v))) => {
                RoughnessDesc::Pair([u, v])
            }
            (None, Some(u), Some(v)) => RoughnessDesc::Each([u, v]),
            (None, None, None) => RoughnessDesc::Value(0.1),
            _ => return Err(self.fail(e, "give both `alpha_u` and `alpha_v`".into())),
        };
        // Mitsuba keeps α at least 1e-4.
        let roughness = match roughness {
            RoughnessDesc::Value(a) => RoughnessDesc::Value(a.max(1e-4)),
            RoughnessDesc::Pair([u, v]) => RoughnessDesc::Pair([u.max(1e-4), v.max(1e-4)]),
            RoughnessDesc::Each(each) => RoughnessDesc::Each(each.map(|a| match a {
                ScalarDesc::Value(a) => ScalarDesc::Value(a.max(1e-4)),
                t => t,
            })),
            t => t,
        };
        Ok((roughness, distribution))
    }

    // ----------------------------------------------------------------
    // Textures and colours

    /// A colour parameter: a colour or a texture's name.
    fn colour(&mut self, p: &Props<'d>, n: &str, use_: Use) -> Result<Option<ColorDesc>, Failure> {
        Ok(match p.colour(n, use_, self)? {
            None => None,
            Some(Colour::Rgb(c)) => Some(ColorDesc::Rgb(c)),
            Some(Colour::Texture(t)) => Some(ColorDesc::Texture(self.texture(t, false)?)),
        })
    }

    /// A scalar parameter: a number (a colour's mean) or a texture's name.
    fn scalar(&mut self, p: &Props<'d>, n: &str) -> Result<Option<ScalarDesc>, Failure> {
        Ok(match p.scalar(n, self)? {
            None => None,
            Some(Colour::Rgb(c)) => Some(ScalarDesc::Value(mean(c))),
            Some(Colour::Texture(t)) => Some(ScalarDesc::Texture(self.texture(t, true)?)),
        })
    }

    /// The texture of element `e`, as a colour or (`scalar`) its first
    /// channel.
    fn texture(&mut self, e: &'d Element, scalar: bool) -> Result<String, Failure> {
        let key = (e as *const Element, scalar);
        if let Some(name) = self.textures.get(&key) {
            return Ok(name.clone());
        }
        let t = self.type_of(e)?;
        if t == "checkerboard" {
            return self.checkerboard(e, scalar, key);
        }
        if t != "bitmap" {
            return Err(self.unknown_type(e, "texture", TEXTURES));
        }
        let p = Props::of(e, self)?;
        let (name, at) = p
            .string_at("filename", self)?
            .ok_or_else(|| self.fail(e, "a bitmap needs a `filename`".into()))?;
        let file = self.file(name, at)?;
        let raw = p.boolean("raw", self)?.unwrap_or(false);
        let filter = match p.string("filter_type", self)?.unwrap_or("bilinear") {
            "bilinear" => FilterDesc::Bilinear,
            "nearest" => FilterDesc::Nearest,
            other => {
                return Err(self.fail(
                    e,
                    format!("filter_type `{other}`: expected bilinear or nearest"),
                ))
            }
        };
        let wrap = match p.string("wrap_mode", self)?.unwrap_or("repeat") {
            "repeat" => WrapDesc::Repeat,
            "mirror" => WrapDesc::Mirror,
            "clamp" => WrapDesc::Clamp,
            other => {
                return Err(self.fail(
                    e,
                    format!("wrap_mode `{other}`: expected repeat, mirror or clamp"),
                ))
            }
        };
        let (mut uv_scale, mut uv_offset) = (None, None);
        if let Some(m) = p.transform("to_uv", self)? {
            let affine = m[0][1] == 0.0 && m[1][0] == 0.0;
            if !affine {
                self.lacks(e, "a to_uv that turns or shears", "its scale and offset")?;
            }
            uv_scale = Some([m[0][0], m[1][1]]);
            uv_offset = Some([m[0][3], m[1][3]]);
        }
        let _ = p.string("format", self)?;
        p.finish(
            &[
                "filename",
                "raw",
                "filter_type",
                "wrap_mode",
                "to_uv",
                "format",
            ],
            self,
        )?;
        let desc = TextureDesc::Image {
            file,
            channel: scalar.then_some(crate::scene::desc::ChannelDesc::R),
            encoding: Some(if raw {
                EncodingDesc::Linear
            } else {
                EncodingDesc::Srgb
            }),
            wrap: Some(wrap),
            filter: Some(filter),
            uv_set: None,
            uv_offset,
            uv_rotation: None,
            uv_scale,
        };
        let name = match e.attr("id") {
            Some(id) if !scalar && !self.desc.textures.contains_key(id) => id.to_string(),
            _ => self.name("texture"),
        };
        self.desc.textures.insert(name.clone(), desc);
        self.textures.insert(key, name.clone());
        Ok(name)
    }
}

impl<'d> Convert<'d> {
    /// A `checkerboard`: `color0` where ⌊2U⌋ + ⌊2V⌋ is even, (U, V) =
    /// `to_uv` · (u, v) in Mitsuba's coordinates, whose v runs down the
    /// image where lumen's runs up.
    fn checkerboard(
        &mut self,
        e: &'d Element,
        scalar: bool,
        key: (*const Element, bool),
    ) -> Result<String, Failure> {
        let p = Props::of(e, self)?;
        // For a number (a roughness, a weight) its squares are numbers
        // too: a grey checkerboard, read from any of its channels.
        let square = |cx: &mut Self, n: &str, default: f64| -> Result<ColorDesc, Failure> {
            Ok(if scalar {
                match cx.scalar(&p, n)? {
                    None => ColorDesc::Rgb([default; 3]),
                    Some(ScalarDesc::Value(v)) => ColorDesc::Rgb([v; 3]),
                    Some(ScalarDesc::Texture(t)) => ColorDesc::Texture(t),
                }
            } else {
                cx.colour(&p, n, Use::Reflectance)?
                    .unwrap_or(ColorDesc::Rgb([default; 3]))
            })
        };
        let mut color0 = square(self, "color0", 0.4)?;
        let mut color1 = square(self, "color1", 0.2)?;
        if scalar {
            // Mitsuba 3 (3.9) looks a checkerboard up as a number with its
            // squares the other way round from the colour lookup: its
            // `eval_1` gives color0 where `eval` gives color1.
            std::mem::swap(&mut color0, &mut color1);
        }
        let [a, b, c, d] = match p.transform("to_uv", self)? {
            None => [1.0, 1.0, 0.0, 0.0],
            Some(m) => {
                if m[0][1] != 0.0 || m[1][0] != 0.0 {
                    self.lacks(e, "a to_uv that turns or shears", "its scale and offset")?;
                }
                [m[0][0], m[1][1], m[0][3], m[1][3]]
            }
        };
        p.finish(&["color0", "color1", "to_uv"], self)?;
        let desc = TextureDesc::Checkerboard {
            even: color0,
            odd: color1,
            uv_scale: Some([2.0 * a, -2.0 * b]),
            uv_offset: Some([2.0 * c, 2.0 * (b + d)]),
        };
        let name = self.name("checkerboard");
        self.desc.textures.insert(name.clone(), desc);
        self.textures.insert(key, name.clone());
        Ok(name)
    }
}

/// A colour's mean (the colour itself when it is grey).
fn mean(c: [f64; 3]) -> f64 {
    if c[0] == c[1] && c[1] == c[2] {
        c[0]
    } else {
        (c[0] + c[1] + c[2]) / 3.0
    }
}
