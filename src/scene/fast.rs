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

use super::desc::{
    BackgroundDesc, BoundaryDesc, CameraDesc, ColorDesc, MaterialDesc, ObjectDesc, RenderDesc,
    ScaleDesc, SceneDesc, TextureDesc, TransformDesc, MAX_SEED,
};
use super::file::Format;
use super::plain_toml;
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
/// the precise reader allows, and without `null` (which serde takes for an
/// absent optional field, and the precise reader refuses).
fn json(text: &str) -> Option<SceneDesc> {
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    for b in text.bytes() {
        if in_string {
            match b {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => in_string = false,
                _ => {}
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                depth += 1;
                if depth > super::source::MAX_DEPTH {
                    return None;
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            // Outside strings, only `null` has an `n`.
            b'n' => return None,
            _ => {}
        }
    }
    serde_json::from_str(text).ok()
}

/// Objects read by one call of the `toml` crate: a few hundred, so that
/// the document it builds stays small and the batches spread over cores.
const BATCH: usize = 256;

/// Batches read at a time: bounds the memory of documents in flight.
const BATCHES_IN_FLIGHT: usize = 64;

/// The `[[objects]]` tables of a batch.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Batch {
    objects: Vec<ObjectDesc>,
}

fn toml(text: &str) -> Option<SceneDesc> {
    let split = split_toml(text)?;
    let mut desc: SceneDesc = ::toml::from_str(&split.rest).ok()?;
    if split.objects.is_empty() {
        return Some(desc);
    }
    // `objects` written outside `[[objects]]` tables as well: the whole
    // document says whether that is allowed.
    if !desc.objects.is_empty() {
        return None;
    }
    let batches = batches(&split.objects);
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

/// A TOML text cut in two: the `[[objects]]` tables (each with its
/// sub-tables), and everything else.
struct Split {
    /// Everything but the objects, in file order: a TOML document of its
    /// own, since no other table's meaning depends on the objects.
    rest: String,
    /// The byte range of each `[[objects]]` table.
    objects: Vec<Range<usize>>,
}

/// What the scanner is inside of at a given point of the text.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Inside {
    Code,
    /// `"""…"""`
    MultiLineString,
    /// `'''…'''`
    MultiLineLiteral,
}

/// What a table header starts.
enum Header {
    /// `[[objects]]`: the next object.
    Object,
    /// `[objects.x]` or `[[objects.x]]`: part of the current object.
    ObjectPart,
    /// Any other table.
    Other,
}

/// The sections of `text`, or `None` when it is written in a way the cut
/// might get wrong (then the whole document is read at once).
fn split_toml(text: &str) -> Option<Split> {
    let mut split = Split {
        rest: String::new(),
        objects: Vec::new(),
    };
    let (mut inside, mut depth) = (Inside::Code, 0usize);
    // The section being read: where it starts, and whether it is an object.
    let (mut start, mut in_object, mut seen_header) = (0usize, false, false);
    let mut pos = 0;
    while pos < text.len() {
        let end = text[pos..].find('\n').map_or(text.len(), |i| pos + i + 1);
        let line = &text[pos..end];
        if inside == Inside::Code && depth == 0 {
            let t = line.trim_start_matches([' ', '\t']);
            if t.starts_with('[') {
                let header = header(t)?;
                if !matches!(header, Header::ObjectPart) {
                    close(&mut split, text, start..pos, in_object);
                    start = pos;
                    in_object = matches!(header, Header::Object);
                } else if !in_object {
                    return None;
                }
                seen_header = true;
                pos = end;
                continue;
            }
            // A top-level key `objects` (`objects = […]`, `objects.x = …`).
            if !seen_header && top_level_objects(t) {
                return None;
            }
        }
        (inside, depth) = scan_line(line, inside, depth)?;
        pos = end;
    }
    if inside != Inside::Code || depth != 0 {
        return None;
    }
    close(&mut split, text, start..text.len(), in_object);
    Some(split)
}

fn close(split: &mut Split, text: &str, section: Range<usize>, object: bool) {
    if object {
        split.objects.push(section);
    } else {
        split.rest.push_str(&text[section]);
    }
}

fn top_level_objects(line: &str) -> bool {
    ["objects", "\"objects\"", "'objects'"].iter().any(|k| {
        line.strip_prefix(k)
            .is_some_and(|after| after.is_empty() || after.starts_with([' ', '\t', '=', '.']))
    })
}

/// What the header at the start of `line` opens; `None` for a quoted name
/// that mentions objects (left to the whole-document reader).
fn header(line: &str) -> Option<Header> {
    let array = line.starts_with("[[");
    let inner = if array { &line[2..] } else { &line[1..] };
    let name = inner.split(']').next().unwrap_or("");
    if name.contains(['"', '\'']) {
        return (!name.contains("objects")).then_some(Header::Other);
    }
    let name = name.trim();
    let first = name.split('.').next().unwrap_or("").trim();
    if first != "objects" {
        return Some(Header::Other);
    }
    match (name == "objects", array) {
        (true, true) => Some(Header::Object),
        // `[objects]`: an error, or a table the cut cannot place.
        (true, false) => None,
        (false, _) => Some(Header::ObjectPart),
    }
}

/// Where `line` leaves the scanner: inside a multi-line string or not, and
/// how deep in brackets. `None` for anything unexpected (a string left open
/// at the end of its line, a closing bracket too many).
fn scan_line(line: &str, mut inside: Inside, mut depth: usize) -> Option<(Inside, usize)> {
    let b = line.as_bytes();
    let at = |i: usize, s: &[u8]| b.get(i..i + s.len()) == Some(s);
    let mut i = 0;
    while i < b.len() {
        match inside {
            Inside::MultiLineString => {
                if b[i] == b'\\' {
                    i += 2;
                    continue;
                }
                if at(i, b"\"\"\"") {
                    i += 3;
                    // Up to two quotes may end the content before the delimiter.
                    while i < b.len() && b[i] == b'"' {
                        i += 1;
                    }
                    inside = Inside::Code;
                    continue;
                }
                i += 1;
            }
            Inside::MultiLineLiteral => {
                if at(i, b"'''") {
                    i += 3;
                    while i < b.len() && b[i] == b'\'' {
                        i += 1;
                    }
                    inside = Inside::Code;
                    continue;
                }
                i += 1;
            }
            Inside::Code => match b[i] {
                b'#' => break,
                b'"' if at(i, b"\"\"\"") => {
                    inside = Inside::MultiLineString;
                    i += 3;
                }
                b'\'' if at(i, b"'''") => {
                    inside = Inside::MultiLineLiteral;
                    i += 3;
                }
                b'"' => {
                    i += 1;
                    loop {
                        match b.get(i)? {
                            b'\\' => i += 2,
                            b'"' => break,
                            b'\n' => return None,
                            _ => i += 1,
                        }
                    }
                    i += 1;
                }
                b'\'' => {
                    i += 1 + line[i + 1..].find(['\'', '\n'])?;
                    if b[i] != b'\'' {
                        return None;
                    }
                    i += 1;
                }
                b'[' | b'{' => {
                    depth += 1;
                    i += 1;
                }
                b']' | b'}' => {
                    depth = depth.checked_sub(1)?;
                    i += 1;
                }
                _ => i += 1,
            },
        }
    }
    Some((inside, depth))
}

/// Runs of consecutive tables among `tables`, up to [`BATCH`] long, as
/// ranges of indices into it.
fn batches(tables: &[Range<usize>]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        match out.last_mut() {
            Some(run) if tables[i - 1].end == t.start && run.len() < BATCH => run.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

/// What the precise reader checks beyond the types serde knows: counts of
/// at least 1, seeds of at most [`MAX_SEED`], finite numbers (TOML has
/// `nan` and `inf`).
fn within_limits(d: &SceneDesc) -> bool {
    render(&d.render)
        && camera(&d.camera)
        && background(&d.background)
        && d.textures.values().all(texture)
        && d.materials.values().all(material)
        && d.objects.iter().all(object)
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
        && finite(&[r.aspect_ratio, r.gamma, r.epsilon])
        && r.noise_target.is_none_or(f64::is_finite)
}

fn camera(c: &CameraDesc) -> bool {
    finite(&c.lookfrom)
        && finite(&c.lookat)
        && finite(&c.vup)
        && finite(&c.shutter)
        && finite(&[c.vfov, c.defocus_angle])
        && c.focus_dist.is_none_or(f64::is_finite)
}

fn background(b: &BackgroundDesc) -> bool {
    match b {
        BackgroundDesc::Gradient { bottom, top } => finite(bottom) && finite(top),
        BackgroundDesc::Solid { color } => finite(color),
        BackgroundDesc::Image {
            rotation,
            intensity,
            ..
        } => finite(&[*rotation, *intensity]),
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
        TextureDesc::Image { .. } => true,
        TextureDesc::Noise { scale, seed, .. } => finite(&[*scale]) && *seed <= MAX_SEED,
    }
}

fn material(m: &MaterialDesc) -> bool {
    match m {
        MaterialDesc::Diffuse { albedo, .. } => color(albedo),
        MaterialDesc::Metal { albedo, fuzz } => color(albedo) && finite(&[*fuzz]),
        MaterialDesc::Dielectric { ior, .. } => finite(&[*ior]),
        MaterialDesc::Emissive { radiance, .. } => color(radiance),
    }
}

fn object(o: &ObjectDesc) -> bool {
    let shape = match o {
        ObjectDesc::Sphere { center, radius, .. } => finite(center) && finite(&[*radius]),
        ObjectDesc::Quad { corner, u, v, .. } => finite(corner) && finite(u) && finite(v),
        ObjectDesc::Box { min, max, .. } => finite(min) && finite(max),
        ObjectDesc::Mesh { .. } => true,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parts(text: &str) -> (String, Vec<&str>) {
        let s = split_toml(text).unwrap();
        (s.rest, s.objects.iter().map(|r| &text[r.clone()]).collect())
    }

    #[test]
    fn objects_are_cut_from_the_rest() {
        let text = "a = 1\n[render]\nwidth = 8\n[[objects]]\ntype = \"x\"\n\
                    [objects.boundary]\nr = 1\n[[ objects ]] # next\nm = \"[[objects]]\"\n\
                    [materials.a]\nt = '''\n[[objects]]\n'''\n";
        let (rest, objects) = parts(text);
        assert_eq!(
            objects,
            [
                "[[objects]]\ntype = \"x\"\n[objects.boundary]\nr = 1\n",
                "[[ objects ]] # next\nm = \"[[objects]]\"\n"
            ]
        );
        assert_eq!(
            rest,
            "a = 1\n[render]\nwidth = 8\n[materials.a]\nt = '''\n[[objects]]\n'''\n"
        );
        // A matrix written over several lines has rows that start with `[`.
        let text = "[[objects]]\nm = [\n [1, 2],\n [3, 4], # ]\n]\n[[objects]]\n";
        assert_eq!(parts(text).1.len(), 2);
    }

    #[test]
    fn unusual_layouts_are_left_to_the_whole_document() {
        for text in [
            "objects = []\n[[objects]]\n",
            "[objects]\n",
            "[objects.x]\n",
            "[render]\n[objects.x]\n",
            "[\"objects\"]\n",
            "a = \"open\n",
            "a = ]\n",
            "a = \"\"\"\n",
        ] {
            assert!(split_toml(text).is_none(), "{text:?}");
        }
    }

    #[test]
    fn batches_hold_consecutive_objects() {
        let ranges: Vec<Range<usize>> = (0..600).map(|i| i..i + 1).collect();
        let b = batches(&ranges);
        assert_eq!(b, [0..BATCH, BATCH..2 * BATCH, 2 * BATCH..600]);
        assert_eq!(batches(&[0..1, 2..3]), [0..1, 1..2]);
    }
}
