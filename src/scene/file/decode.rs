//! From a [`Node`] tree to a [`SceneDesc`], field by field, so that every
//! complaint names the field's path (`objects[3].material`), what was expected
//! and what was found, and, for a misspelling, the closest known name.
//!
//! Written by hand rather than derived with serde: serde's internally tagged
//! enums lose positions and say only "unknown variant". Ranges that are about
//! meaning rather than form (radius > 0, fuzz in [0, 1], …) are checked once,
//! by [`Scene::from_desc`](super::Scene::from_desc), for files and library
//! users alike.

use super::hint;
use super::node_de::NodeDe;
use super::source::{Entry, Node, Value};
use crate::light::LightSelection;
use crate::material::KindInfo;
use crate::scene::desc::{
    BackgroundDesc, BoundaryDesc, CameraDesc, ChannelDesc, ColorDesc, EncodingDesc,
    EnvironmentLayoutDesc, FilterDesc, GltfCamera, IntegratorDesc, LightDesc, MaterialDesc,
    MediumDesc, NoisePatternDesc, ObjectDesc, PixelFilterDesc, RenderDesc, SamplingDesc,
    ScalarDesc, ScaleDesc, SceneDesc, ShadingDesc, TextureDesc, TransformDesc, Triple, WrapDesc,
    MAX_SEED,
};
use std::collections::BTreeMap;
use std::ops::Range;

/// A value of the file that does not fit the scene format.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodeError {
    /// Path of the field, e.g. `objects[3].material`; empty for the whole file.
    pub path: String,
    /// Where in the file.
    pub span: Range<usize>,
    /// What is wrong: expected versus got.
    pub message: String,
    /// A suggestion, when one helps.
    pub hint: Option<String>,
}

type Result<T> = std::result::Result<T, DecodeError>;

fn error(path: &str, span: &Range<usize>, message: String) -> DecodeError {
    DecodeError {
        path: path.to_string(),
        span: span.clone(),
        message,
        hint: None,
    }
}

fn child(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// `names` in backquotes for a message, the closest to `near` first when
/// there are many (see [`hint::listing`]).
fn quoted(near: &str, names: &[&str]) -> String {
    hint::listing(near, names.iter().copied(), |n| format!("`{n}`"))
}

/// A table of the file with its known fields checked.
struct Table<'a> {
    path: &'a str,
    span: &'a Range<usize>,
    entries: &'a [Entry],
}

impl<'a> Table<'a> {
    /// `node` as a table whose keys are all among `known`. `what` names the
    /// table in messages ("a sphere"); `elsewhere` lists fields that belong to
    /// sibling kinds, so that `fuzz` on a diffuse material says where it goes.
    fn new(
        node: &'a Node,
        path: &'a str,
        what: &str,
        known: &[&str],
        elsewhere: &[(&str, &str)],
    ) -> Result<Self> {
        let Value::Table(entries) = &node.value else {
            return Err(error(
                path,
                &node.span,
                format!("expected {what} (a table), got {}", node.value.describe()),
            ));
        };
        for (i, e) in entries.iter().enumerate() {
            // TOML refuses repeated keys itself; JSON parsers usually keep the last.
            if entries[..i].iter().any(|earlier| earlier.key == e.key) {
                return Err(error(
                    &child(path, &e.key),
                    &e.key_span,
                    format!("field `{}` is given twice in {what}", e.key),
                ));
            }
            if known.contains(&e.key.as_str()) {
                continue;
            }
            let mut err = error(
                &child(path, &e.key),
                &e.key_span,
                format!("unknown field `{}` in {what}", e.key),
            );
            err.hint = Some(
                if let Some((_, owner)) = elsewhere.iter().find(|(k, _)| *k == e.key) {
                    format!(
                        "`{}` belongs to {owner}; {what} has {}",
                        e.key,
                        quoted(&e.key, known)
                    )
                } else if let Some(close) = hint::closest(&e.key, known.iter().copied()) {
                    format!("did you mean `{close}`?")
                } else {
                    format!("{what} has {}", quoted(&e.key, known))
                },
            );
            return Err(err);
        }
        Ok(Table {
            path,
            span: &node.span,
            entries,
        })
    }

    fn get(&self, key: &str) -> Option<&'a Node> {
        self.entries.iter().find(|e| e.key == key).map(|e| &e.node)
    }

    fn required(&self, key: &str, what: &str) -> Result<&'a Node> {
        self.get(key).ok_or_else(|| {
            error(
                &child(self.path, key),
                self.span,
                format!("missing field `{key}`: {what} needs it"),
            )
        })
    }

    fn path(&self, key: &str) -> String {
        child(self.path, key)
    }

    /// Required field `key`, read by `read` (`float`, `triple`, ...).
    fn require<T>(
        &self,
        key: &str,
        what: &str,
        read: impl Fn(&'a Node, &str) -> Result<T>,
    ) -> Result<T> {
        read(self.required(key, what)?, &self.path(key))
    }

    /// Optional field `key`, read by `read`; `None` when it is absent.
    fn optional<T>(
        &self,
        key: &str,
        read: impl Fn(&'a Node, &str) -> Result<T>,
    ) -> Result<Option<T>> {
        self.get(key).map(|n| read(n, &self.path(key))).transpose()
    }
}

fn float(node: &Node, path: &str) -> Result<f64> {
    let v = match node.value {
        Value::Float(f) => f,
        Value::Integer(i) => i as f64,
        ref other => {
            return Err(error(
                path,
                &node.span,
                format!("expected a number, got {}", other.describe()),
            ))
        }
    };
    if !v.is_finite() {
        return Err(error(
            path,
            &node.span,
            format!("expected a finite number, got {v}"),
        ));
    }
    Ok(v)
}

fn integer(node: &Node, path: &str, min: u64, max: u64) -> Result<u64> {
    match node.value {
        Value::Integer(i) if i < i128::from(min) => Err(error(
            path,
            &node.span,
            format!("must be at least {min}, got {i}"),
        )),
        Value::Integer(i) if i > i128::from(max) => Err(error(
            path,
            &node.span,
            format!("must be at most {max}, got {i}"),
        )),
        Value::Integer(i) => Ok(i as u64),
        ref other => Err(error(
            path,
            &node.span,
            format!("expected a whole number, got {}", other.describe()),
        )),
    }
}

/// A seed: 0 to [`MAX_SEED`] in both formats, so that a JSON scene can
/// always be exported to TOML (whose integers are signed 64-bit).
fn seed(node: &Node, path: &str) -> Result<u64> {
    match node.value {
        Value::Integer(i) if i > i128::from(MAX_SEED) => Err(error(
            path,
            &node.span,
            crate::scene::desc::seed_too_large(i),
        )),
        _ => integer(node, path, 0, MAX_SEED),
    }
}

fn u32_field(node: &Node, path: &str, min: u32) -> Result<u32> {
    integer(node, path, u64::from(min), u64::from(u32::MAX)).map(|v| v as u32)
}

fn triple(node: &Node, path: &str) -> Result<Triple> {
    numbers(node, path, "an array of 3 numbers [x, y, z]")
}

/// An array whose every item `item` reads.
fn list<T>(node: &Node, path: &str, item: impl Fn(&Node, &str) -> Result<T>) -> Result<Vec<T>> {
    let Value::Array(items) = &node.value else {
        return Err(error(
            path,
            &node.span,
            format!("expected an array, got {}", node.value.describe()),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, n)| item(n, &format!("{path}[{i}]")))
        .collect()
}

/// A triangle's three vertex indices.
fn index_triple(node: &Node, path: &str) -> Result<[u32; 3]> {
    counts(node, path, "an array of 3 vertex indices [a, b, c]")
}

/// An array of exactly `N` whole numbers from 0; `expected` says which in
/// messages.
fn counts<const N: usize>(node: &Node, path: &str, expected: &str) -> Result<[u32; N]> {
    match &node.value {
        Value::Array(items) if items.len() == N => {
            let mut t = [0; N];
            for (i, item) in items.iter().enumerate() {
                t[i] = u32_field(item, &format!("{path}[{i}]"), 0)?;
            }
            Ok(t)
        }
        other => Err(error(
            path,
            &node.span,
            format!("expected {expected}, got {}", other.describe()),
        )),
    }
}

/// A shutter interval.
fn pair(node: &Node, path: &str) -> Result<[f64; 2]> {
    numbers(node, path, "an array of 2 numbers [open, close]")
}

/// An array of exactly `N` numbers; `expected` says which in messages.
fn numbers<const N: usize>(node: &Node, path: &str, expected: &str) -> Result<[f64; N]> {
    let got = match &node.value {
        Value::Array(items) if items.len() == N => {
            let mut t = [0.0; N];
            for (i, item) in items.iter().enumerate() {
                t[i] = float(item, &format!("{path}[{i}]"))?;
            }
            return Ok(t);
        }
        other => other.describe(),
    };
    Err(error(
        path,
        &node.span,
        format!("expected {expected}, got {got}"),
    ))
}

/// A colour as a triple, or the name of a texture.
fn color_or_texture(node: &Node, path: &str) -> Result<ColorDesc> {
    match &node.value {
        Value::String(name) => Ok(ColorDesc::Texture(name.clone())),
        Value::Array(_) => Ok(ColorDesc::Rgb(triple(node, path)?)),
        other => Err(error(
            path,
            &node.span,
            format!(
                "expected an array of 3 numbers [r, g, b] or the name of a texture, got {}",
                other.describe()
            ),
        )),
    }
}

/// A number, or the name of a (scalar) texture.
fn number_or_texture(node: &Node, path: &str) -> Result<ScalarDesc> {
    match &node.value {
        Value::String(name) => Ok(ScalarDesc::Texture(name.clone())),
        Value::Float(_) | Value::Integer(_) => Ok(ScalarDesc::Value(float(node, path)?)),
        other => Err(error(
            path,
            &node.span,
            format!(
                "expected a number or the name of a texture, got {}",
                other.describe()
            ),
        )),
    }
}

fn string<'a>(node: &'a Node, path: &str) -> Result<&'a str> {
    match &node.value {
        Value::String(s) => Ok(s),
        other => Err(error(
            path,
            &node.span,
            format!("expected a string, got {}", other.describe()),
        )),
    }
}

fn boolean(node: &Node, path: &str) -> Result<bool> {
    match node.value {
        Value::Bool(b) => Ok(b),
        ref other => Err(error(
            path,
            &node.span,
            format!("expected true or false, got {}", other.describe()),
        )),
    }
}

/// One of a fixed set of names, e.g. a material `type`.
fn keyword<T: Copy>(node: &Node, path: &str, options: &[(&str, T)]) -> Result<T> {
    let name = string(node, path)?;
    if let Some((_, v)) = options.iter().find(|(n, _)| *n == name) {
        return Ok(*v);
    }
    let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
    let mut err = error(
        path,
        &node.span,
        format!(
            "unknown value {name:?}, expected one of {}",
            hint::listing(name, names.iter().copied(), |n| format!("{n:?}"))
        ),
    );
    err.hint = hint::closest(name, names.iter().copied()).map(|c| format!("did you mean {c:?}?"));
    Err(err)
}

/// Decodes a whole scene file.
pub fn scene(root: &Node) -> Result<SceneDesc> {
    let t = Table::new(
        root,
        "",
        "a scene file",
        &[
            "caption",
            "render",
            "camera",
            "background",
            "textures",
            "materials",
            "objects",
            "lights",
            "media",
        ],
        &[],
    )?;
    Ok(SceneDesc {
        caption: t
            .optional("caption", string)?
            .unwrap_or_default()
            .to_string(),
        render: t.optional("render", |n, _| render(n))?.unwrap_or_default(),
        camera: t.optional("camera", |n, _| camera(n))?.unwrap_or_default(),
        background: t
            .optional("background", |n, _| background(n))?
            .unwrap_or_default(),
        textures: t
            .optional("textures", |n, _| named(n, "textures", "texture", texture))?
            .unwrap_or_default(),
        materials: t
            .optional("materials", |n, _| {
                named(n, "materials", "material", material)
            })?
            .unwrap_or_default(),
        objects: t
            .optional("objects", |n, _| objects(n))?
            .unwrap_or_default(),
        lights: t.optional("lights", |n, _| lights(n))?.unwrap_or_default(),
        media: t
            .optional("media", |n, _| named(n, "media", "medium", medium))?
            .unwrap_or_default(),
    })
}

/// A medium of `[media]`, its fields as [`MediumDesc`] declares them.
fn medium(node: &Node, path: &str) -> Result<MediumDesc> {
    <MediumDesc as serde::Deserialize>::deserialize(NodeDe::new(node, path.to_string(), "a medium"))
        .map_err(|e| e.into_decode(path, &node.span, "a medium"))
}

/// The `[[lights]]` tables: each kind's fields as the kind declares them
/// (see [`crate::light::LightDesc`]).
fn lights(n: &Node) -> Result<Vec<LightDesc>> {
    let Value::Array(items) = &n.value else {
        return Err(error(
            "lights",
            &n.span,
            format!(
                "expected an array of lights ([[lights]] tables), got {}",
                n.value.describe()
            ),
        ));
    };
    let kinds = crate::light::source::kinds();
    items
        .iter()
        .enumerate()
        .map(|(i, node)| {
            let path = format!("lights[{i}]");
            let k = kind_of(node, &path, "a light", &kinds, "lights")?;
            LightDesc::deserialize_kind(
                k.name,
                NodeDe {
                    node,
                    path: path.clone(),
                    what: k.what,
                    skip: Some("type"),
                },
            )
            .map_err(|e| e.into_decode(&path, &node.span, k.what))
        })
        .collect()
}

/// A table of named entries (`[materials.NAME]`, `[textures.NAME]`) of the
/// top-level table `section`, each decoded by `entry`.
fn named<T>(
    n: &Node,
    section: &str,
    noun: &str,
    entry: impl Fn(&Node, &str) -> Result<T>,
) -> Result<BTreeMap<String, T>> {
    let Value::Table(entries) = &n.value else {
        return Err(error(
            section,
            &n.span,
            format!(
                "expected a table of named {section}, got {}",
                n.value.describe()
            ),
        ));
    };
    let mut out = BTreeMap::new();
    for e in entries {
        let path = child(section, &e.key);
        if out.contains_key(&e.key) {
            return Err(error(
                &path,
                &e.key_span,
                format!("{noun} `{}` is defined twice", e.key),
            ));
        }
        out.insert(e.key.clone(), entry(&e.node, &path)?);
    }
    Ok(out)
}

fn objects(n: &Node) -> Result<Vec<ObjectDesc>> {
    let Value::Array(items) = &n.value else {
        return Err(error(
            "objects",
            &n.span,
            format!(
                "expected an array of objects ([[objects]] tables), got {}",
                n.value.describe()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| object(item, &format!("objects[{i}]")))
        .collect()
}

const SAMPLERS: &[(&str, SamplingDesc)] = &[
    ("sobol", SamplingDesc::Sobol),
    ("zsobol", SamplingDesc::ZSobol),
    ("independent", SamplingDesc::Independent),
    ("stratified", SamplingDesc::Stratified),
    ("center", SamplingDesc::Center),
    ("random", SamplingDesc::Independent),
];

const INTEGRATORS: &[(&str, IntegratorDesc)] = &[
    ("path", IntegratorDesc::Path),
    ("bsdf", IntegratorDesc::Bsdf),
];

const LIGHT_SELECTIONS: &[(&str, LightSelection)] = &[
    ("power", LightSelection::Power),
    ("uniform", LightSelection::Uniform),
    ("objects", LightSelection::Objects),
];

const SHADINGS: &[(&str, ShadingDesc)] = &[
    ("path", ShadingDesc::Path),
    ("hit", ShadingDesc::Hit),
    ("normals-unit", ShadingDesc::NormalsUnit),
    ("normals-raw", ShadingDesc::NormalsRaw),
    ("normals-brightened", ShadingDesc::NormalsBrightened),
];

fn render(node: &Node) -> Result<RenderDesc> {
    let t = Table::new(
        node,
        "render",
        "the render table",
        &[
            "width",
            "height",
            "aspect_ratio",
            "samples_per_pixel",
            "max_depth",
            "seed",
            "sampler",
            "sampling",
            "integrator",
            "light_selection",
            "sample_background",
            "noise_target",
            "gamma",
            "epsilon",
            "shading",
            "pixel_filter",
            "filter_stddev",
            "crop",
            "aovs",
            "denoise",
            "denoiser",
            "denoise_quality",
            "denoise_prefilter",
        ],
        &[],
    )?;
    let d = RenderDesc::default();
    let positive = |n: &Node, p: &str| u32_field(n, p, 1);
    Ok(RenderDesc {
        width: t.optional("width", positive)?.unwrap_or(d.width),
        height: t.optional("height", positive)?,
        aspect_ratio: t.optional("aspect_ratio", float)?.unwrap_or(d.aspect_ratio),
        crop: t.optional("crop", |n, p| {
            counts(n, p, "an array of 4 pixel counts [x, y, width, height]")
        })?,
        samples_per_pixel: t
            .optional("samples_per_pixel", positive)?
            .unwrap_or(d.samples_per_pixel),
        max_depth: t.optional("max_depth", positive)?.unwrap_or(d.max_depth),
        seed: t.optional("seed", seed)?.unwrap_or(d.seed),
        sampler: sampler(&t)?.unwrap_or(d.sampler),
        integrator: t
            .optional("integrator", |n, p| keyword(n, p, INTEGRATORS))?
            .unwrap_or(d.integrator),
        light_selection: t
            .optional("light_selection", |n, p| keyword(n, p, LIGHT_SELECTIONS))?
            .unwrap_or(d.light_selection),
        sample_background: t.optional("sample_background", boolean)?,
        noise_target: t.optional("noise_target", float)?,
        gamma: t.optional("gamma", float)?.unwrap_or(d.gamma),
        epsilon: t.optional("epsilon", float)?,
        shading: t
            .optional("shading", |n, p| keyword(n, p, SHADINGS))?
            .unwrap_or(d.shading),
        pixel_filter: t
            .optional("pixel_filter", |n, p| keyword(n, p, PIXEL_FILTERS))?
            .unwrap_or(d.pixel_filter),
        filter_stddev: t.optional("filter_stddev", float)?,
        aovs: t.optional("aovs", aovs)?.unwrap_or_default(),
        denoise: t.optional("denoise", boolean)?.unwrap_or(false),
        denoiser: t.optional("denoiser", |n, p| {
            keyword(n, p, &crate::denoise::Denoiser::NAMES)
        })?,
        denoise_quality: t.optional("denoise_quality", |n, p| {
            keyword(n, p, &crate::denoise::Quality::NAMES)
        })?,
        denoise_prefilter: t.optional("denoise_prefilter", |n, p| {
            keyword(n, p, &crate::denoise::Prefilter::NAMES)
        })?,
    })
}

/// The feature buffers of `render.aovs`: an array of their names, each
/// once, kept in [`Aov::ALL`](crate::aov::Aov::ALL)'s order.
fn aovs(node: &Node, path: &str) -> Result<Vec<crate::aov::Aov>> {
    use crate::aov::Aov;
    let Value::Array(items) = &node.value else {
        return Err(error(
            path,
            &node.span,
            format!(
                "expected an array of AOV names, got {}",
                node.value.describe()
            ),
        ));
    };
    let options = Aov::ALL.map(|a| (a.name(), a));
    let mut list = items
        .iter()
        .enumerate()
        .map(|(i, item)| keyword(item, &format!("{path}[{i}]"), &options))
        .collect::<Result<Vec<_>>>()?;
    list.sort();
    list.dedup();
    Ok(list)
}

const PIXEL_FILTERS: &[(&str, PixelFilterDesc)] = &[
    ("box", PixelFilterDesc::Box),
    ("gaussian", PixelFilterDesc::Gaussian),
];

/// The render's sampler: `sampler`, or `sampling` as older scene files
/// name it, not both.
fn sampler(t: &Table) -> Result<Option<SamplingDesc>> {
    let read = |n: &Node, p: &str| keyword(n, p, SAMPLERS);
    match (t.get("sampler"), t.get("sampling")) {
        (Some(_), Some(old)) => Err(error(
            &t.path("sampling"),
            &old.span,
            "give `sampler` or its older name `sampling`, not both".to_string(),
        )),
        (None, Some(_)) => t.optional("sampling", read),
        _ => t.optional("sampler", read),
    }
}

fn camera(node: &Node) -> Result<CameraDesc> {
    let t = Table::new(
        node,
        "camera",
        "the camera table",
        &[
            "vfov",
            "lookfrom",
            "lookat",
            "vup",
            "defocus_angle",
            "focus_dist",
            "shutter",
            "gltf",
            "mirror",
            "near_clip",
            "far_clip",
            "medium",
            "ortho_height",
        ],
        &[],
    )?;
    let d = CameraDesc::default();
    Ok(CameraDesc {
        vfov: t.optional("vfov", float)?.unwrap_or(d.vfov),
        lookfrom: t.optional("lookfrom", triple)?.unwrap_or(d.lookfrom),
        lookat: t.optional("lookat", triple)?.unwrap_or(d.lookat),
        vup: t.optional("vup", triple)?.unwrap_or(d.vup),
        defocus_angle: t
            .optional("defocus_angle", float)?
            .unwrap_or(d.defocus_angle),
        focus_dist: t.optional("focus_dist", float)?,
        shutter: t.optional("shutter", pair)?.unwrap_or(d.shutter),
        gltf: t.optional("gltf", gltf_camera)?,
        mirror: t.optional("mirror", boolean)?.unwrap_or(false),
        near_clip: t.optional("near_clip", float)?.unwrap_or(d.near_clip),
        far_clip: t.optional("far_clip", float)?,
        medium: t.optional("medium", string)?.map(str::to_string),
        ortho_height: t.optional("ortho_height", float)?,
    })
}

/// A glTF camera by number or name.
fn gltf_camera(node: &Node, path: &str) -> Result<GltfCamera> {
    match &node.value {
        Value::String(name) => Ok(GltfCamera::Name(name.clone())),
        _ => integer(node, path, 0, u64::from(u32::MAX)).map(|n| GltfCamera::Index(n as u32)),
    }
}

/// One kind of a table tagged by `type`: its name, what it is called in
/// messages, its fields, and the fields of its sibling kinds with their owners.
struct Kind<K> {
    name: &'static str,
    kind: K,
    what: &'static str,
    fields: &'static [&'static str],
    elsewhere: &'static [(&'static str, &'static str)],
}

/// `node` as a table whose `type` names one of `kinds`. The type is checked
/// first, against the union of all kinds' fields, so that a wrong type is
/// reported as such and not as a field that does not belong.
fn tagged<'a, K: Copy>(
    node: &'a Node,
    path: &'a str,
    what: &str,
    kinds: &[Kind<K>],
) -> Result<(K, &'static str, Table<'a>)> {
    let mut all: Vec<&str> = Vec::new();
    for f in kinds.iter().flat_map(|k| k.fields) {
        if !all.contains(f) {
            all.push(f);
        }
    }
    let any = Table::new(node, path, what, &all, &[])?;
    let names: Vec<(&str, usize)> = kinds.iter().enumerate().map(|(i, k)| (k.name, i)).collect();
    let k = &kinds[keyword(any.required("type", what)?, &any.path("type"), &names)?];
    let t = Table::new(node, path, k.what, k.fields, k.elsewhere)?;
    Ok((k.kind, k.what, t))
}

#[derive(Clone, Copy)]
enum BackgroundKind {
    Gradient,
    Solid,
    Image,
}

const BACKGROUNDS: &[Kind<BackgroundKind>] = &[
    Kind {
        name: "gradient",
        kind: BackgroundKind::Gradient,
        what: "a gradient background",
        fields: &["type", "bottom", "top"],
        elsewhere: &[
            ("color", "a solid background"),
            ("file", "an image background"),
        ],
    },
    Kind {
        name: "solid",
        kind: BackgroundKind::Solid,
        what: "a solid background",
        fields: &["type", "color"],
        elsewhere: &[
            ("bottom", "a gradient background"),
            ("top", "a gradient background"),
            ("file", "an image background"),
        ],
    },
    Kind {
        name: "image",
        kind: BackgroundKind::Image,
        what: "an image background",
        fields: &[
            "type",
            "file",
            "rotation",
            "intensity",
            "rows_at_poles",
            "layout",
            "frame",
        ],
        elsewhere: &[
            ("color", "a solid background"),
            ("bottom", "a gradient background"),
            ("top", "a gradient background"),
        ],
    },
];

fn background(node: &Node) -> Result<BackgroundDesc> {
    let (kind, what, t) = tagged(node, "background", "a background", BACKGROUNDS)?;
    Ok(match kind {
        BackgroundKind::Gradient => BackgroundDesc::Gradient {
            bottom: t.require("bottom", what, triple)?,
            top: t.require("top", what, triple)?,
        },
        BackgroundKind::Solid => BackgroundDesc::Solid {
            color: t.require("color", what, triple)?,
        },
        BackgroundKind::Image => BackgroundDesc::Image {
            file: t.require("file", what, string)?.to_string(),
            rotation: t.optional("rotation", float)?.unwrap_or(0.0),
            intensity: t.optional("intensity", float)?.unwrap_or(1.0),
            rows_at_poles: t.optional("rows_at_poles", boolean)?.unwrap_or(false),
            layout: t
                .optional("layout", |n, p| {
                    keyword(
                        n,
                        p,
                        &[
                            ("equirectangular", EnvironmentLayoutDesc::Equirectangular),
                            ("equal-area", EnvironmentLayoutDesc::EqualArea),
                        ],
                    )
                })?
                .unwrap_or_default(),
            frame: t.optional("frame", |n, p| {
                let axes = list(n, p, triple)?;
                <[Triple; 3]>::try_from(axes).map_err(|a| {
                    error(
                        p,
                        &n.span,
                        format!("expected 3 axes [x, y, z], got {}", a.len()),
                    )
                })
            })?,
        },
    })
}

/// A material: its `type` read first, then the kind's fields as the kind
/// declares them (see [`crate::material::MaterialDesc`]); a field that
/// belongs to other kinds says which.
fn material(node: &Node, path: &str) -> Result<MaterialDesc> {
    let kinds = crate::material::kinds();
    let k = kind_of(node, path, "a material", &kinds, "materials")?;
    MaterialDesc::deserialize_kind(
        k.name,
        NodeDe {
            node,
            path: path.to_string(),
            what: k.what,
            skip: Some("type"),
        },
    )
    .map_err(|e| e.into_decode(path, &node.span, k.what))
}

/// The kind of `node` among `kinds` by its `type`, its fields checked
/// against the kind's: `what` names the table in messages ("a material"),
/// `plural` the kinds in hints ("materials").
fn kind_of<'k>(
    node: &Node,
    path: &str,
    what: &str,
    kinds: &'k [KindInfo],
    plural: &str,
) -> Result<&'k KindInfo> {
    let mut all: Vec<&str> = Vec::new();
    for f in kinds.iter().flat_map(|k| k.fields.iter().copied()) {
        if !all.contains(&f) {
            all.push(f);
        }
    }
    let any = Table::new(node, path, what, &all, &[])?;
    let names: Vec<(&str, usize)> = kinds.iter().enumerate().map(|(i, k)| (k.name, i)).collect();
    let k = &kinds[keyword(any.required("type", what)?, &any.path("type"), &names)?];
    // The fields of the other kinds, each with the kinds it belongs to.
    let owners: Vec<(&str, String)> = all
        .iter()
        .filter(|f| !k.fields.contains(f))
        .map(|&f| {
            let with: Vec<&str> = kinds
                .iter()
                .filter(|o| o.fields.contains(&f))
                .map(|o| o.name)
                .collect();
            (f, format!("{} {plural}", and_list(&with)))
        })
        .collect();
    let elsewhere: Vec<(&str, &str)> = owners.iter().map(|(f, o)| (*f, o.as_str())).collect();
    Table::new(node, path, k.what, &k.fields, &elsewhere)?;
    Ok(k)
}

/// "a", "a and b", "a, b and c".
fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

#[derive(Clone, Copy)]
enum TextureKind {
    Checker,
    Checkerboard,
    Scale,
    Mix,
    Image,
    Noise,
}

const TEXTURES: &[Kind<TextureKind>] = &[
    Kind {
        name: "scale",
        kind: TextureKind::Scale,
        what: "a scale texture",
        fields: &["type", "texture", "factor"],
        elsewhere: &[("scale", "checker textures"), ("file", "image textures")],
    },
    Kind {
        name: "mix",
        kind: TextureKind::Mix,
        what: "a mix texture",
        fields: &["type", "first", "second", "amount"],
        elsewhere: &[
            ("even", "checker textures"),
            ("odd", "checker textures"),
            ("texture", "scale textures"),
            ("file", "image textures"),
        ],
    },
    Kind {
        name: "checkerboard",
        kind: TextureKind::Checkerboard,
        what: "a checkerboard texture",
        fields: &["type", "even", "odd", "uv_scale", "uv_offset"],
        elsewhere: &[
            ("scale", "checker textures (squares in space)"),
            ("file", "image textures"),
        ],
    },
    Kind {
        name: "checker",
        kind: TextureKind::Checker,
        what: "a checker texture",
        fields: &["type", "scale", "even", "odd"],
        elsewhere: &[
            ("file", "image textures"),
            ("channel", "image textures"),
            ("encoding", "image textures"),
            ("wrap", "image textures"),
            ("filter", "image textures"),
            ("uv_set", "image textures"),
            ("uv_offset", "image textures"),
            ("uv_rotation", "image textures"),
            ("uv_scale", "image textures"),
            ("pattern", "noise textures"),
            ("seed", "noise textures"),
        ],
    },
    Kind {
        name: "image",
        kind: TextureKind::Image,
        what: "an image texture",
        fields: &[
            "type",
            "file",
            "channel",
            "encoding",
            "wrap",
            "filter",
            "uv_set",
            "uv_offset",
            "uv_rotation",
            "uv_scale",
        ],
        elsewhere: &[
            ("scale", "checker and noise textures"),
            ("even", "checker textures"),
            ("odd", "checker textures"),
            ("pattern", "noise textures"),
            ("seed", "noise textures"),
        ],
    },
    Kind {
        name: "noise",
        kind: TextureKind::Noise,
        what: "a noise texture",
        fields: &["type", "scale", "pattern", "seed"],
        elsewhere: &[
            ("file", "image textures"),
            ("channel", "image textures"),
            ("encoding", "image textures"),
            ("wrap", "image textures"),
            ("filter", "image textures"),
            ("uv_set", "image textures"),
            ("uv_offset", "image textures"),
            ("uv_rotation", "image textures"),
            ("uv_scale", "image textures"),
            ("even", "checker textures"),
            ("odd", "checker textures"),
        ],
    },
];

const CHANNELS: &[(&str, ChannelDesc)] = &[
    ("r", ChannelDesc::R),
    ("g", ChannelDesc::G),
    ("b", ChannelDesc::B),
    ("a", ChannelDesc::A),
];

const ENCODINGS: &[(&str, EncodingDesc)] = &[
    ("srgb", EncodingDesc::Srgb),
    ("linear", EncodingDesc::Linear),
];

const WRAPS: &[(&str, WrapDesc)] = &[
    ("repeat", WrapDesc::Repeat),
    ("clamp", WrapDesc::Clamp),
    ("mirror", WrapDesc::Mirror),
];

const FILTERS: &[(&str, FilterDesc)] = &[
    ("bilinear", FilterDesc::Bilinear),
    ("nearest", FilterDesc::Nearest),
];

/// A set of texture coordinates: 0 or 1.
fn uv_set(node: &Node, path: &str) -> Result<u32> {
    integer(node, path, 0, 1).map(|n| n as u32)
}

const NOISE_PATTERNS: &[(&str, NoisePatternDesc)] = &[
    ("smooth", NoisePatternDesc::Smooth),
    ("turbulence", NoisePatternDesc::Turbulence),
    ("marble", NoisePatternDesc::Marble),
];

fn texture(node: &Node, path: &str) -> Result<TextureDesc> {
    let (kind, what, t) = tagged(node, path, "a texture", TEXTURES)?;
    Ok(match kind {
        TextureKind::Checker => TextureDesc::Checker {
            scale: t.require("scale", what, float)?,
            even: t.require("even", what, color_or_texture)?,
            odd: t.require("odd", what, color_or_texture)?,
        },
        TextureKind::Scale => TextureDesc::Scale {
            texture: t.require("texture", what, color_or_texture)?,
            factor: t.require("factor", what, triple)?,
        },
        TextureKind::Mix => TextureDesc::Mix {
            first: t.require("first", what, color_or_texture)?,
            second: t.require("second", what, color_or_texture)?,
            amount: t.require("amount", what, number_or_texture)?,
        },
        TextureKind::Checkerboard => TextureDesc::Checkerboard {
            even: t.require("even", what, color_or_texture)?,
            odd: t.require("odd", what, color_or_texture)?,
            uv_scale: t.optional("uv_scale", |n, p| {
                numbers(n, p, "an array of 2 numbers [u, v]")
            })?,
            uv_offset: t.optional("uv_offset", |n, p| {
                numbers(n, p, "an array of 2 numbers [u, v]")
            })?,
        },
        TextureKind::Image => TextureDesc::Image {
            file: t.require("file", what, string)?.to_string(),
            channel: t.optional("channel", |n, p| keyword(n, p, CHANNELS))?,
            encoding: t.optional("encoding", |n, p| keyword(n, p, ENCODINGS))?,
            wrap: t.optional("wrap", |n, p| keyword(n, p, WRAPS))?,
            filter: t.optional("filter", |n, p| keyword(n, p, FILTERS))?,
            uv_set: t.optional("uv_set", uv_set)?,
            uv_offset: t.optional("uv_offset", pair)?,
            uv_rotation: t.optional("uv_rotation", float)?,
            uv_scale: t.optional("uv_scale", pair)?,
        },
        TextureKind::Noise => TextureDesc::Noise {
            scale: t.optional("scale", float)?.unwrap_or(1.0),
            pattern: t
                .optional("pattern", |n, p| keyword(n, p, NOISE_PATTERNS))?
                .unwrap_or_default(),
            seed: t.optional("seed", seed)?.unwrap_or(0),
        },
    })
}

#[derive(Clone, Copy)]
enum ObjectKind {
    Sphere,
    Quad,
    Disk,
    Cylinder,
    Box,
    Mesh,
    Triangles,
    Medium,
}

const OBJECTS: &[Kind<ObjectKind>] = &[
    Kind {
        name: "sphere",
        kind: ObjectKind::Sphere,
        what: "a sphere",
        fields: &[
            "type",
            "center",
            "radius",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("corner", "quads"),
            ("u", "quads"),
            ("v", "quads"),
            ("min", "boxes"),
            ("max", "boxes"),
            ("file", "meshes"),
            ("smooth", "meshes"),
        ],
    },
    Kind {
        name: "quad",
        kind: ObjectKind::Quad,
        what: "a quad",
        fields: &[
            "type",
            "corner",
            "u",
            "v",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("center", "spheres"),
            ("radius", "spheres"),
            ("min", "boxes"),
            ("max", "boxes"),
            ("file", "meshes"),
            ("smooth", "meshes"),
        ],
    },
    Kind {
        name: "disk",
        kind: ObjectKind::Disk,
        what: "a disk",
        fields: &[
            "type",
            "center",
            "normal",
            "radius",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("corner", "quads"),
            ("p0", "cylinders"),
            ("p1", "cylinders"),
            ("min", "boxes"),
            ("max", "boxes"),
            ("file", "meshes"),
        ],
    },
    Kind {
        name: "cylinder",
        kind: ObjectKind::Cylinder,
        what: "a cylinder",
        fields: &[
            "type",
            "p0",
            "p1",
            "radius",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("center", "spheres and disks"),
            ("normal", "disks"),
            ("corner", "quads"),
            ("min", "boxes"),
            ("max", "boxes"),
            ("file", "meshes"),
        ],
    },
    Kind {
        name: "box",
        kind: ObjectKind::Box,
        what: "a box",
        fields: &[
            "type",
            "min",
            "max",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("center", "spheres"),
            ("radius", "spheres"),
            ("corner", "quads"),
            ("u", "quads"),
            ("v", "quads"),
            ("file", "meshes"),
            ("smooth", "meshes"),
        ],
    },
    Kind {
        name: "mesh",
        kind: ObjectKind::Mesh,
        what: "a mesh",
        fields: &[
            "type",
            "file",
            "material",
            "smooth",
            "allow_outside",
            "part",
            "flip_v",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("center", "spheres"),
            ("radius", "spheres"),
            ("corner", "quads"),
            ("u", "quads"),
            ("v", "quads"),
            ("min", "boxes"),
            ("max", "boxes"),
        ],
    },
    Kind {
        name: "triangles",
        kind: ObjectKind::Triangles,
        what: "a triangle mesh",
        fields: &[
            "type",
            "positions",
            "indices",
            "normals",
            "uvs",
            "material",
            "flip_normals",
            "transform",
        ],
        elsewhere: &[
            ("file", "meshes"),
            ("smooth", "meshes"),
            ("center", "spheres"),
            ("corner", "quads"),
        ],
    },
    Kind {
        name: "medium",
        kind: ObjectKind::Medium,
        what: "a medium",
        fields: &["type", "boundary", "density", "albedo", "transform"],
        elsewhere: &[
            ("center", "spheres (a medium's sphere goes in `boundary`)"),
            ("radius", "spheres (a medium's sphere goes in `boundary`)"),
            ("min", "boxes (a medium's box goes in `boundary`)"),
            ("max", "boxes (a medium's box goes in `boundary`)"),
            ("material", "surfaces (a medium has `albedo`)"),
        ],
    },
];

const BOUNDARIES: &[Kind<bool>] = &[
    Kind {
        name: "sphere",
        kind: true,
        what: "a sphere boundary",
        fields: &["type", "center", "radius"],
        elsewhere: &[("min", "boxes"), ("max", "boxes")],
    },
    Kind {
        name: "box",
        kind: false,
        what: "a box boundary",
        fields: &["type", "min", "max"],
        elsewhere: &[("center", "spheres"), ("radius", "spheres")],
    },
];

/// A medium's boundary: a sphere or a box.
fn boundary(node: &Node, path: &str) -> Result<BoundaryDesc> {
    let (sphere, what, t) = tagged(node, path, "a boundary", BOUNDARIES)?;
    Ok(if sphere {
        BoundaryDesc::Sphere {
            center: t.require("center", what, triple)?,
            radius: t.require("radius", what, float)?,
        }
    } else {
        BoundaryDesc::Box {
            min: t.require("min", what, triple)?,
            max: t.require("max", what, triple)?,
        }
    })
}

fn object(node: &Node, path: &str) -> Result<ObjectDesc> {
    let (kind, what, t) = tagged(node, path, "an object", OBJECTS)?;
    let material = || -> Result<String> { Ok(t.require("material", what, string)?.to_string()) };
    let transform = t.optional("transform", transforms)?.unwrap_or_default();
    let flip_normals = t.optional("flip_normals", boolean)?.unwrap_or(false);
    Ok(match kind {
        ObjectKind::Sphere => ObjectDesc::Sphere {
            center: t.require("center", what, triple)?,
            radius: t.require("radius", what, float)?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Quad => ObjectDesc::Quad {
            corner: t.require("corner", what, triple)?,
            u: t.require("u", what, triple)?,
            v: t.require("v", what, triple)?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Disk => ObjectDesc::Disk {
            center: t.require("center", what, triple)?,
            normal: t.require("normal", what, triple)?,
            radius: t.require("radius", what, float)?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Cylinder => ObjectDesc::Cylinder {
            p0: t.require("p0", what, triple)?,
            p1: t.require("p1", what, triple)?,
            radius: t.require("radius", what, float)?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Box => ObjectDesc::Box {
            min: t.require("min", what, triple)?,
            max: t.require("max", what, triple)?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Mesh => ObjectDesc::Mesh {
            file: t.require("file", what, string)?.to_string(),
            material: t.optional("material", string)?.map(str::to_string),
            smooth: t.optional("smooth", boolean)?.unwrap_or(true),
            allow_outside: t.optional("allow_outside", boolean)?.unwrap_or(false),
            part: t
                .optional("part", |n, p| integer(n, p, 0, u64::from(u32::MAX)))?
                .map(|n| n as u32),
            flip_v: t.optional("flip_v", boolean)?.unwrap_or(false),
            flip_normals,
            transform,
        },
        ObjectKind::Triangles => ObjectDesc::Triangles {
            positions: t.require("positions", what, |n, p| list(n, p, triple))?,
            indices: t.require("indices", what, |n, p| list(n, p, index_triple))?,
            normals: t.optional("normals", |n, p| list(n, p, triple))?,
            uvs: t.optional("uvs", |n, p| {
                list(n, p, |n, p| numbers(n, p, "an array of 2 numbers [u, v]"))
            })?,
            material: material()?,
            flip_normals,
            transform,
        },
        ObjectKind::Medium => ObjectDesc::Medium {
            boundary: t.require("boundary", what, boundary)?,
            density: t.require("density", what, float)?,
            albedo: t.require("albedo", what, triple)?,
            transform,
        },
    })
}

const TRANSFORM_STEPS: &[&str] = &["translate", "rotate", "scale", "matrix", "motion"];

/// A `transform` list: tables of one step each.
fn transforms(node: &Node, path: &str) -> Result<Vec<TransformDesc>> {
    let Value::Array(items) = &node.value else {
        return Err(error(
            path,
            &node.span,
            format!(
                "expected a list of steps such as [{{ translate = [0, 1, 0] }}, {{ scale = 2 }}], got {}",
                node.value.describe()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| transform_step(item, &format!("{path}[{i}]")))
        .collect()
}

fn transform_step(node: &Node, path: &str) -> Result<TransformDesc> {
    let t = Table::new(node, path, "a transform step", TRANSFORM_STEPS, &[])?;
    let [entry] = t.entries else {
        return Err(error(
            path,
            &node.span,
            format!(
                "a transform step has exactly one of {}, got {}",
                quoted("", TRANSFORM_STEPS),
                t.entries.len()
            ),
        ));
    };
    let p = t.path(&entry.key);
    let n = &entry.node;
    Ok(match entry.key.as_str() {
        "translate" => TransformDesc::Translate(triple(n, &p)?),
        "rotate" => {
            let r = Table::new(n, &p, "a rotation", &["axis", "degrees"], &[])?;
            TransformDesc::Rotate {
                axis: r.require("axis", "a rotation", triple)?,
                degrees: r.require("degrees", "a rotation", float)?,
            }
        }
        "scale" => TransformDesc::Scale(match &n.value {
            Value::Array(_) => ScaleDesc::PerAxis(triple(n, &p)?),
            Value::Float(_) | Value::Integer(_) => ScaleDesc::Uniform(float(n, &p)?),
            other => {
                return Err(error(
                    &p,
                    &n.span,
                    format!(
                        "expected a number or an array of 3 numbers [x, y, z], got {}",
                        other.describe()
                    ),
                ))
            }
        }),
        "motion" => TransformDesc::Motion(triple(n, &p)?),
        _ => TransformDesc::Matrix(matrix(n, &p)?),
    })
}

/// Four rows of four numbers.
fn matrix(node: &Node, path: &str) -> Result<[[f64; 4]; 4]> {
    let bad = |got: String| {
        error(
            path,
            &node.span,
            format!("expected 4 rows of 4 numbers [[a, b, c, d], …], got {got}"),
        )
    };
    let Value::Array(rows) = &node.value else {
        return Err(bad(node.value.describe()));
    };
    if rows.len() != 4 {
        return Err(bad(format!("{} rows", rows.len())));
    }
    let mut m = [[0.0; 4]; 4];
    for (i, row) in rows.iter().enumerate() {
        let row_path = format!("{path}[{i}]");
        match &row.value {
            Value::Array(items) if items.len() == 4 => {
                for (j, item) in items.iter().enumerate() {
                    m[i][j] = float(item, &format!("{row_path}[{j}]"))?;
                }
            }
            other => {
                return Err(error(
                    &row_path,
                    &row.span,
                    format!("expected a row of 4 numbers, got {}", other.describe()),
                ))
            }
        }
    }
    Ok(m)
}
