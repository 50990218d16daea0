//! From a [`Node`] tree to a [`SceneDesc`], field by field, so that every
//! complaint names the field's path (`objects[3].material`), what was expected
//! and what was found, and, for a misspelling, the closest known name.
//!
//! Written by hand rather than derived with serde: serde's internally tagged
//! enums lose positions and say only "unknown variant". Ranges that are about
//! meaning rather than form (radius > 0, fuzz in [0, 1], …) are checked once,
//! by [`Scene::from_desc`](super::Scene::from_desc), for files and library
//! users alike.

use super::desc::{
    AttenuationDesc, BackgroundDesc, BounceDesc, CameraDesc, MaterialDesc, ObjectDesc, RenderDesc,
    SamplingDesc, SceneDesc, ShadingDesc, Triple,
};
use super::hint;
use super::source::{Entry, Node, Value};
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

fn quoted(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
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
                        quoted(known)
                    )
                } else if let Some(close) = hint::closest(&e.key, known.iter().copied()) {
                    format!("did you mean `{close}`?")
                } else {
                    format!("{what} has {}", quoted(known))
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

fn u32_field(node: &Node, path: &str, min: u32) -> Result<u32> {
    integer(node, path, u64::from(min), u64::from(u32::MAX)).map(|v| v as u32)
}

fn triple(node: &Node, path: &str) -> Result<Triple> {
    let got = match &node.value {
        Value::Array(items) if items.len() == 3 => {
            let mut t = [0.0; 3];
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
        format!("expected an array of 3 numbers [x, y, z], got {got}"),
    ))
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
            names
                .iter()
                .map(|n| format!("{n:?}"))
                .collect::<Vec<_>>()
                .join(", ")
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
            "materials",
            "objects",
        ],
        &[],
    )?;
    let mut desc = SceneDesc {
        caption: String::new(),
        render: RenderDesc::default(),
        camera: CameraDesc::default(),
        background: BackgroundDesc::default(),
        materials: BTreeMap::new(),
        objects: Vec::new(),
    };
    if let Some(n) = t.get("caption") {
        desc.caption = string(n, "caption")?.to_string();
    }
    if let Some(n) = t.get("render") {
        desc.render = render(n)?;
    }
    if let Some(n) = t.get("camera") {
        desc.camera = camera(n)?;
    }
    if let Some(n) = t.get("background") {
        desc.background = background(n)?;
    }
    if let Some(n) = t.get("materials") {
        let Value::Table(entries) = &n.value else {
            return Err(error(
                "materials",
                &n.span,
                format!(
                    "expected a table of named materials, got {}",
                    n.value.describe()
                ),
            ));
        };
        for e in entries {
            let path = child("materials", &e.key);
            if desc.materials.contains_key(&e.key) {
                return Err(error(
                    &path,
                    &e.key_span,
                    format!("material `{}` is defined twice", e.key),
                ));
            }
            desc.materials
                .insert(e.key.clone(), material(&e.node, &path)?);
        }
    }
    if let Some(n) = t.get("objects") {
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
        for (i, item) in items.iter().enumerate() {
            desc.objects.push(object(item, &format!("objects[{i}]"))?);
        }
    }
    Ok(desc)
}

const SAMPLINGS: &[(&str, SamplingDesc)] = &[
    ("random", SamplingDesc::Random),
    ("stratified", SamplingDesc::Stratified),
    ("center", SamplingDesc::Center),
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
            "sampling",
            "gamma",
            "epsilon",
            "shading",
        ],
        &[],
    )?;
    let mut r = RenderDesc::default();
    if let Some(n) = t.get("width") {
        r.width = u32_field(n, &t.path("width"), 1)?;
    }
    if let Some(n) = t.get("height") {
        r.height = Some(u32_field(n, &t.path("height"), 1)?);
    }
    if let Some(n) = t.get("aspect_ratio") {
        r.aspect_ratio = float(n, &t.path("aspect_ratio"))?;
    }
    if let Some(n) = t.get("samples_per_pixel") {
        r.samples_per_pixel = u32_field(n, &t.path("samples_per_pixel"), 1)?;
    }
    if let Some(n) = t.get("max_depth") {
        r.max_depth = u32_field(n, &t.path("max_depth"), 1)?;
    }
    if let Some(n) = t.get("seed") {
        r.seed = integer(n, &t.path("seed"), 0, u64::MAX)?;
    }
    if let Some(n) = t.get("sampling") {
        r.sampling = keyword(n, &t.path("sampling"), SAMPLINGS)?;
    }
    if let Some(n) = t.get("gamma") {
        r.gamma = float(n, &t.path("gamma"))?;
    }
    if let Some(n) = t.get("epsilon") {
        r.epsilon = float(n, &t.path("epsilon"))?;
    }
    if let Some(n) = t.get("shading") {
        r.shading = keyword(n, &t.path("shading"), SHADINGS)?;
    }
    Ok(r)
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
        ],
        &[],
    )?;
    let mut c = CameraDesc::default();
    if let Some(n) = t.get("vfov") {
        c.vfov = float(n, &t.path("vfov"))?;
    }
    if let Some(n) = t.get("lookfrom") {
        c.lookfrom = triple(n, &t.path("lookfrom"))?;
    }
    if let Some(n) = t.get("lookat") {
        c.lookat = triple(n, &t.path("lookat"))?;
    }
    if let Some(n) = t.get("vup") {
        c.vup = triple(n, &t.path("vup"))?;
    }
    if let Some(n) = t.get("defocus_angle") {
        c.defocus_angle = float(n, &t.path("defocus_angle"))?;
    }
    if let Some(n) = t.get("focus_dist") {
        c.focus_dist = Some(float(n, &t.path("focus_dist"))?);
    }
    Ok(c)
}

#[derive(Clone, Copy)]
enum BackgroundKind {
    Gradient,
    Solid,
}

fn background(node: &Node) -> Result<BackgroundDesc> {
    let path = "background";
    let any = Table::new(
        node,
        path,
        "a background",
        &["type", "bottom", "top", "color"],
        &[],
    )?;
    let kind = keyword(
        any.required("type", "a background")?,
        &any.path("type"),
        &[
            ("gradient", BackgroundKind::Gradient),
            ("solid", BackgroundKind::Solid),
        ],
    )?;
    Ok(match kind {
        BackgroundKind::Gradient => {
            let what = "a gradient background";
            let t = Table::new(
                node,
                path,
                what,
                &["type", "bottom", "top"],
                &[("color", "a solid background")],
            )?;
            BackgroundDesc::Gradient {
                bottom: triple(t.required("bottom", what)?, &t.path("bottom"))?,
                top: triple(t.required("top", what)?, &t.path("top"))?,
            }
        }
        BackgroundKind::Solid => {
            let what = "a solid background";
            let t = Table::new(
                node,
                path,
                what,
                &["type", "color"],
                &[
                    ("bottom", "a gradient background"),
                    ("top", "a gradient background"),
                ],
            )?;
            BackgroundDesc::Solid {
                color: triple(t.required("color", what)?, &t.path("color"))?,
            }
        }
    })
}

#[derive(Clone, Copy)]
enum MaterialKind {
    Diffuse,
    Metal,
    Dielectric,
}

const DIFFUSE_FIELDS: &[&str] = &["type", "albedo", "bounce", "attenuation"];
const METAL_FIELDS: &[&str] = &["type", "albedo", "fuzz"];
const DIELECTRIC_FIELDS: &[&str] = &["type", "ior", "refract_only"];

fn material(node: &Node, path: &str) -> Result<MaterialDesc> {
    // Check the type first, against the union of all fields, so that a wrong
    // type is reported as such and not as a field that does not belong.
    let mut all: Vec<&str> = Vec::new();
    for f in [DIFFUSE_FIELDS, METAL_FIELDS, DIELECTRIC_FIELDS].concat() {
        if !all.contains(&f) {
            all.push(f);
        }
    }
    let any = Table::new(node, path, "a material", &all, &[])?;
    let kind = keyword(
        any.required("type", "a material")?,
        &any.path("type"),
        &[
            ("diffuse", MaterialKind::Diffuse),
            ("metal", MaterialKind::Metal),
            ("dielectric", MaterialKind::Dielectric),
        ],
    )?;
    Ok(match kind {
        MaterialKind::Diffuse => {
            let what = "a diffuse material";
            let t = Table::new(
                node,
                path,
                what,
                DIFFUSE_FIELDS,
                &[
                    ("fuzz", "metal materials"),
                    ("ior", "dielectric materials"),
                    ("refract_only", "dielectric materials"),
                ],
            )?;
            MaterialDesc::Diffuse {
                albedo: triple(t.required("albedo", what)?, &t.path("albedo"))?,
                bounce: match t.get("bounce") {
                    None => BounceDesc::default(),
                    Some(n) => keyword(
                        n,
                        &t.path("bounce"),
                        &[
                            ("cube", BounceDesc::Cube),
                            ("sphere-volume", BounceDesc::SphereVolume),
                            ("lambertian", BounceDesc::Lambertian),
                            ("hemisphere", BounceDesc::Hemisphere),
                        ],
                    )?,
                },
                attenuation: match t.get("attenuation") {
                    None => AttenuationDesc::default(),
                    Some(n) => keyword(
                        n,
                        &t.path("attenuation"),
                        &[
                            ("scale", AttenuationDesc::Scale),
                            ("absorb", AttenuationDesc::Absorb),
                        ],
                    )?,
                },
            }
        }
        MaterialKind::Metal => {
            let what = "a metal material";
            let t = Table::new(
                node,
                path,
                what,
                METAL_FIELDS,
                &[
                    ("bounce", "diffuse materials"),
                    ("attenuation", "diffuse materials"),
                    ("ior", "dielectric materials"),
                    ("refract_only", "dielectric materials"),
                ],
            )?;
            MaterialDesc::Metal {
                albedo: triple(t.required("albedo", what)?, &t.path("albedo"))?,
                fuzz: match t.get("fuzz") {
                    None => 0.0,
                    Some(n) => float(n, &t.path("fuzz"))?,
                },
            }
        }
        MaterialKind::Dielectric => {
            let what = "a dielectric material";
            let t = Table::new(
                node,
                path,
                what,
                DIELECTRIC_FIELDS,
                &[
                    ("albedo", "diffuse and metal materials"),
                    ("fuzz", "metal materials"),
                    ("bounce", "diffuse materials"),
                    ("attenuation", "diffuse materials"),
                ],
            )?;
            MaterialDesc::Dielectric {
                ior: float(t.required("ior", what)?, &t.path("ior"))?,
                refract_only: match t.get("refract_only") {
                    None => false,
                    Some(n) => boolean(n, &t.path("refract_only"))?,
                },
            }
        }
    })
}

#[derive(Clone, Copy)]
enum ObjectKind {
    Sphere,
}

fn object(node: &Node, path: &str) -> Result<ObjectDesc> {
    let fields = &["type", "center", "radius", "material"];
    let any = Table::new(node, path, "an object", fields, &[])?;
    let kind = keyword(
        any.required("type", "an object")?,
        &any.path("type"),
        &[("sphere", ObjectKind::Sphere)],
    )?;
    Ok(match kind {
        ObjectKind::Sphere => {
            let what = "a sphere";
            let t = Table::new(node, path, what, fields, &[])?;
            ObjectDesc::Sphere {
                center: triple(t.required("center", what)?, &t.path("center"))?,
                radius: float(t.required("radius", what)?, &t.path("radius"))?,
                material: string(t.required("material", what)?, &t.path("material"))?.to_string(),
            }
        }
    })
}
