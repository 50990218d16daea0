//! The quick way through a scene file that has no mistakes: serde reads it
//! straight into a [`SceneDesc`], without the tree of positioned values the
//! precise reader ([`super::source`], [`super::decode`]) builds, which costs
//! several kilobytes and several microseconds an object. Whenever this
//! reader is unsure (a value serde would take but the precise reader
//! refuses, or any error at all), it gives up and the precise reader reads
//! the file again, so that every message is the precise one.
//!
//! JSON is read by `serde_json` in one pass. TOML has no streaming reader:
//! the `toml` crate builds a document of the whole text first. So the file
//! is cut, by a scanner that knows TOML's strings, comments and brackets,
//! into the `[[objects]]` tables and the rest; the rest is read as one
//! document and the objects in batches, on every core, each batch's
//! document dropped as soon as it is read.

use super::plain_toml;
use super::toml_cut;
use super::Format;
use crate::scene::desc::{
    BackgroundDesc, BoundaryDesc, CameraDesc, ColorDesc, LightDesc, ObjectDesc, RenderDesc,
    ScalarDesc, ScaleDesc, SceneDesc, TextureDesc, TransformDesc, MAX_SEED,
};
use rayon::prelude::*;
use serde::Deserialize;
use std::ops::Range;

/// The description `text` holds, if it holds one without any mistake the
/// precise reader would report; `None` means "ask the precise reader".
pub(super) fn read(text: &str, format: Format) -> Option<SceneDesc> {
    let desc = match format {
        Format::Json => json(text)?,
        Format::Toml => toml(text)?,
    };
    within_limits(&desc).then_some(desc)
}

/// JSON that serde reads as the precise reader does: nested no deeper than
/// the precise reader allows, without `null` (which serde takes for an
/// absent optional field, and the precise reader refuses), without the
/// integer `-0`, and with a JSON object wherever the description has a
/// table (serde also takes an array there, its fields by position:
/// `{"render": [24, 8]}`).
fn json(text: &str) -> Option<SceneDesc> {
    /// What a container being scanned holds.
    enum Frame {
        /// An object; `tables` if each of its values must be an object (the
        /// `materials` and `textures` maps).
        Object { tables: bool },
        /// An array; `tables` if each element must be an object (the
        /// `objects` and `transform` lists).
        Array { tables: bool },
    }
    // Keys whose value is a table, and those whose value is a list of
    // tables or a map of them.
    const TABLE: &[&[u8]] = &[b"render", b"camera", b"background", b"boundary", b"rotate"];
    const LIST_OF_TABLES: &[&[u8]] = &[b"objects", b"transform"];
    const MAP_OF_TABLES: &[&[u8]] = &[b"materials", b"textures"];
    let bytes = text.as_bytes();
    let mut stack: Vec<Frame> = Vec::new();
    // The last string read, and the key whose value comes next.
    let (mut string, mut key): (Range<usize>, Option<Range<usize>>) = (0..0, None);
    let (mut in_string, mut escaped) = (false, false);
    for (i, &b) in bytes.iter().enumerate() {
        if in_string {
            match b {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => {
                    in_string = false;
                    string.end = i;
                }
                _ => {}
            }
            continue;
        }
        if matches!(b, b' ' | b'\t' | b'\n' | b'\r' | b',' | b']' | b'}') {
            if matches!(b, b']' | b'}') {
                stack.pop();
            }
            continue;
        }
        if b == b':' {
            // A key with an escape could spell a table's name: not read here.
            let k = &bytes[string.clone()];
            if k.contains(&b'\\') {
                return None;
            }
            key = Some(string.clone());
            continue;
        }
        // A value starts (or a key, in an object, after `{` or `,`).
        let in_object_key = matches!(stack.last(), Some(Frame::Object { .. })) && key.is_none();
        if !in_object_key {
            let named = key.take().map(|k| &bytes[k]);
            let is = |list: &[&[u8]]| named.is_some_and(|k| list.contains(&k));
            let must_be_table = match stack.last() {
                Some(Frame::Object { tables }) => *tables || is(TABLE),
                Some(Frame::Array { tables }) => *tables,
                None => true,
            };
            if must_be_table && b != b'{' {
                return None;
            }
            match b {
                b'{' => stack.push(Frame::Object {
                    tables: stack.len() == 1 && is(MAP_OF_TABLES),
                }),
                b'[' => stack.push(Frame::Array {
                    tables: is(LIST_OF_TABLES),
                }),
                _ => {}
            }
            if stack.len() > super::source::MAX_DEPTH {
                return None;
            }
        }
        match b {
            b'"' => {
                in_string = true;
                string = i + 1..i + 1;
            }
            // Outside strings, only `null` has an `n`.
            b'n' => return None,
            // The integer `-0`: serde_json reads it as the float -0.0, the
            // precise reader as 0 (the sign would show in an export).
            b'-' if bytes.get(i + 1) == Some(&b'0')
                && !matches!(bytes.get(i + 2), Some(b'.' | b'e' | b'E')) =>
            {
                return None
            }
            _ => {}
        }
    }
    serde_json::from_str(text).ok()
}

/// Batches read at a time: bounds the memory of documents in flight.
const BATCHES_IN_FLIGHT: usize = 64;

/// The `[[objects]]` tables of a batch.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Batch {
    objects: Vec<ObjectDesc>,
}

fn toml(text: &str) -> Option<SceneDesc> {
    let split = toml_cut::split(text)?;
    // Everything but the objects is small: read by the precise reader.
    let rest = super::tree(&split.rest, Format::Toml).ok()?;
    let mut desc = super::decode::scene(&rest).ok()?;
    if split.objects.is_empty() {
        return Some(desc);
    }
    // `objects` written outside `[[objects]]` tables as well: the whole
    // document says whether that is allowed.
    if !desc.objects.is_empty() {
        return None;
    }
    let batches = toml_cut::batches(&split.objects);
    desc.objects.reserve_exact(split.objects.len());
    for group in batches.chunks(BATCHES_IN_FLIGHT) {
        let read: Vec<Vec<ObjectDesc>> = group
            .par_iter()
            .map(|b| read_batch(text, &split.objects[b.clone()]))
            .collect::<Option<_>>()?;
        for objects in read {
            desc.objects.extend(objects);
        }
    }
    Some(desc)
}

/// The objects of consecutive `[[objects]]` tables of `text`: rewritten as
/// JSON when they are written plainly (see [`plain_toml`]), else read by
/// the `toml` crate.
fn read_batch(text: &str, tables: &[Range<usize>]) -> Option<Vec<ObjectDesc>> {
    let whole = &text[tables.first()?.start..tables.last()?.end];
    let mut json = String::with_capacity(whole.len() + 16);
    json.push_str("{\"objects\":[");
    let plain = tables.iter().enumerate().all(|(k, t)| {
        if k > 0 {
            json.push(',');
        }
        plain_toml::objects_as_json(&text[t.clone()], &mut json).is_some()
    });
    json.push_str("]}");
    let batch: Batch = match plain {
        true => serde_json::from_str(&json)
            .ok()
            .or_else(|| ::toml::from_str(whole).ok())?,
        false => ::toml::from_str(whole).ok()?,
    };
    (batch.objects.len() == tables.len()).then_some(batch.objects)
}

/// What the precise reader checks beyond the types serde knows: counts of
/// at least 1, seeds of at most [`MAX_SEED`], finite numbers (TOML has
/// `nan` and `inf`). Materials need no check: in TOML they are read by the
/// precise reader with the rest of the file around the objects, and JSON
/// has no numbers that are not finite.
fn within_limits(d: &SceneDesc) -> bool {
    render(&d.render)
        && camera(&d.camera)
        && background(&d.background)
        && d.textures.values().all(texture)
        && d.objects.iter().all(object)
        && d.lights.iter().all(light)
}

fn light(l: &LightDesc) -> bool {
    let optional = |v: &Option<[f64; 3]>| v.as_ref().is_none_or(|v| finite(v));
    match l {
        LightDesc::Point(p) => finite(&p.position) && finite(&p.intensity),
        LightDesc::Spot(s) => {
            finite(&s.position)
                && finite(&s.intensity)
                && optional(&s.direction)
                && optional(&s.target)
                && optional(&s.up)
                && s.cutoff_angle.is_none_or(f64::is_finite)
                && s.beam_width.is_none_or(f64::is_finite)
        }
        LightDesc::Directional(d) => {
            finite(&d.direction)
                && finite(&d.irradiance)
                && d.angular_radius.is_none_or(f64::is_finite)
        }
        LightDesc::Projector(p) => {
            finite(&p.position)
                && optional(&p.irradiance)
                && optional(&p.intensity)
                && optional(&p.direction)
                && optional(&p.target)
                && optional(&p.up)
                && p.fov.is_finite()
                && p.aspect.is_none_or(f64::is_finite)
        }
    }
}

fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

fn render(r: &RenderDesc) -> bool {
    r.width >= 1
        && r.height != Some(0)
        && r.samples_per_pixel >= 1
        && r.max_depth >= 1
        && r.seed <= MAX_SEED
        && finite(&[r.aspect_ratio, r.gamma, r.epsilon.unwrap_or(0.0)])
        && r.noise_target.is_none_or(f64::is_finite)
        && r.filter_stddev.is_none_or(f64::is_finite)
}

fn camera(c: &CameraDesc) -> bool {
    finite(&c.lookfrom)
        && finite(&c.lookat)
        && finite(&c.vup)
        && finite(&c.shutter)
        && finite(&[c.vfov, c.defocus_angle])
        && c.focus_dist.is_none_or(f64::is_finite)
        && c.ortho_height.is_none_or(f64::is_finite)
        && c.near_clip.is_finite()
        && c.far_clip.is_none_or(f64::is_finite)
}

fn background(b: &BackgroundDesc) -> bool {
    match b {
        BackgroundDesc::Gradient { bottom, top } => finite(bottom) && finite(top),
        BackgroundDesc::Solid { color } => finite(color),
        BackgroundDesc::Image {
            rotation,
            intensity,
            frame,
            ..
        } => finite(&[*rotation, *intensity]) && frame.iter().flatten().all(|a| finite(a)),
    }
}

fn color(c: &ColorDesc) -> bool {
    match c {
        ColorDesc::Rgb(rgb) => finite(rgb),
        ColorDesc::Texture(_) => true,
    }
}

fn texture(t: &TextureDesc) -> bool {
    match t {
        TextureDesc::Checker { scale, even, odd } => finite(&[*scale]) && color(even) && color(odd),
        TextureDesc::Scale { texture, factor } => color(texture) && finite(factor),
        TextureDesc::Mix {
            first,
            second,
            amount,
        } => {
            color(first)
                && color(second)
                && match amount {
                    ScalarDesc::Value(v) => finite(&[*v]),
                    ScalarDesc::Texture(_) => true,
                }
        }
        TextureDesc::Checkerboard {
            even,
            odd,
            uv_scale,
            uv_offset,
        } => color(even) && color(odd) && uv_scale.iter().chain(uv_offset).all(|v| finite(v)),
        TextureDesc::Image { .. } => true,
        TextureDesc::Noise { scale, seed, .. } => finite(&[*scale]) && *seed <= MAX_SEED,
    }
}

fn object(o: &ObjectDesc) -> bool {
    let shape = match o {
        ObjectDesc::Sphere { center, radius, .. } => finite(center) && finite(&[*radius]),
        ObjectDesc::Quad { corner, u, v, .. } => finite(corner) && finite(u) && finite(v),
        ObjectDesc::Disk {
            center,
            normal,
            radius,
            ..
        } => finite(center) && finite(normal) && finite(&[*radius]),
        ObjectDesc::Cylinder { p0, p1, radius, .. } => {
            finite(p0) && finite(p1) && finite(&[*radius])
        }
        ObjectDesc::Box { min, max, .. } => finite(min) && finite(max),
        ObjectDesc::Mesh { .. } => true,
        ObjectDesc::Triangles {
            positions,
            normals,
            uvs,
            ..
        } => {
            positions.iter().all(|p| finite(p))
                && normals.iter().flatten().all(|n| finite(n))
                && uvs.iter().flatten().all(|t| finite(t))
        }
        ObjectDesc::Medium {
            boundary,
            density,
            albedo,
            ..
        } => {
            let boundary = match boundary {
                BoundaryDesc::Sphere { center, radius } => finite(center) && finite(&[*radius]),
                BoundaryDesc::Box { min, max } => finite(min) && finite(max),
            };
            boundary && finite(&[*density]) && finite(albedo)
        }
    };
    shape && o.transform().iter().all(step)
}

fn step(s: &TransformDesc) -> bool {
    match s {
        TransformDesc::Translate(t) | TransformDesc::Motion(t) => finite(t),
        TransformDesc::Rotate { axis, degrees } => finite(axis) && finite(&[*degrees]),
        TransformDesc::Scale(ScaleDesc::Uniform(f)) => finite(&[*f]),
        TransformDesc::Scale(ScaleDesc::PerAxis(t)) => finite(t),
        TransformDesc::Matrix(m) => m.iter().all(|row| finite(row)),
    }
}
