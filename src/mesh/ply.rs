//! Stanford PLY, ASCII or binary of either byte order.
//!
//! The `vertex` element gives the positions (`x`, `y`, `z`), and the normals
//! (`nx`, `ny`, `nz`) and texture coordinates (`u`/`v`, `s`/`t` or
//! `texture_u`/`texture_v`) when the header gives every vertex them. Each
//! `face`'s `vertex_indices` (or `vertex_index`) list is a polygon, fanned
//! into triangles from its first vertex. Other elements and properties
//! (colours, edges, scanner data) are read past. PLY has no materials: its
//! triangles take the scene's material, or the default grey.
//!
//! The header is read and checked in full before any of the data: an
//! element may hold at most [`MAX_RECORDS`] records, and all of them
//! together must fit in the bytes after the header at their least size
//! (binary: the sum of their properties' sizes, a list counting its length
//! alone; ASCII: two bytes a value, a digit and a space or line end), so
//! that no count in a header makes the reader allocate more than the file
//! can fill, or loop without reading. The vertex element must have `x`,
//! `y` and `z` numbers, the face element a `vertex_indices` list of
//! integers. In ASCII, each record is one line holding exactly its values.
//!
//! The reader takes the file's bytes and writes the mesh's arrays directly,
//! each reserved once at its size (with `try_reserve`: too large a mesh is
//! an error, not an abort): the file and the mesh are all it holds.

use super::{fan, MeshError, Model, TriangleMesh, NO_MATERIAL};
use glam::Mat4;
use std::collections::HashSet;
use std::path::Path;

/// The most records a PLY element may declare: vertex indices are 32-bit.
pub const MAX_RECORDS: u64 = u32::MAX as u64;

/// A scalar type of the format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    /// The type named `name` in a header (both spellings of the format).
    fn of(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }
}

/// A property's type: a number, or a list of numbers after its length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Type {
    Scalar(Scalar),
    List { length: Scalar, item: Scalar },
}

impl Type {
    /// The fewest bytes a binary value of this type takes.
    fn least_bytes(self) -> u64 {
        match self {
            Type::Scalar(s) => s.size() as u64,
            Type::List { length, .. } => length.size() as u64,
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    ty: Type,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// Its `element` line in the header.
    line: usize,
}

impl Element {
    /// The property named `name`, the last if several are.
    fn find(&self, name: &str) -> Option<(usize, &Property)> {
        self.properties
            .iter()
            .enumerate()
            .rev()
            .find(|(_, p)| p.name == name)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug)]
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Where the data starts, just after the `end_header` line.
    data_start: usize,
    /// The number of the data's first line.
    data_line: usize,
}

/// An error at a line (or none) of the file.
type Located = (Option<usize>, String);

/// Whether `s` is a name as the format writes them.
fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Reads and checks the header at the start of `bytes`.
fn read_header(bytes: &[u8]) -> Result<Header, Located> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    // The names given so far, of elements and of the last one's properties
    // (sets: a header of a million lines is checked in linear time).
    let mut element_names: HashSet<String> = HashSet::new();
    let mut property_names: HashSet<String> = HashSet::new();
    let mut at = 0;
    let mut line = 0;
    loop {
        line += 1;
        let Some(len) = bytes[at..].iter().position(|&b| b == b'\n') else {
            let why = if line == 1 {
                "not a PLY file: no `ply` line"
            } else {
                "malformed PLY header: it has no `end_header` line"
            };
            return Err((None, why.into()));
        };
        let raw = &bytes[at..at + len];
        at += len + 1;
        let here = |why: String| (Some(line), format!("malformed PLY header: {why}"));
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let words: Vec<&[u8]> = raw
            .split(|&b| b == b' ' || b == b'\t')
            .filter(|w| !w.is_empty())
            .collect();
        if line == 1 {
            if words.len() != 1 || words[0] != b"ply" {
                return Err((
                    Some(1),
                    "not a PLY file: the first line is not `ply`".into(),
                ));
            }
            continue;
        }
        let keyword = words.first().copied().unwrap_or(b"");
        if keyword == b"comment" || keyword == b"obj_info" {
            continue;
        }
        // Anything else is ASCII words.
        let Ok(words) = words
            .iter()
            .map(|w| std::str::from_utf8(w))
            .collect::<Result<Vec<&str>, _>>()
        else {
            return Err(here("a line that is not text".into()));
        };
        match words.as_slice() {
            [] => return Err(here("an empty line".into())),
            ["end_header"] => break,
            ["format", name, version] => {
                let this = match *name {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    other => return Err(here(format!("unknown format `{other}`"))),
                };
                let numeric = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
                if !version
                    .split_once('.')
                    .is_some_and(|(a, b)| numeric(a) && numeric(b))
                {
                    return Err(here(format!("`{version}` is not a version (1.0)")));
                }
                if encoding.is_some_and(|e| e != this) {
                    return Err(here("a second `format` line, another format".into()));
                }
                encoding = Some(this);
            }
            ["element", name, count] => {
                if !is_name(name) {
                    return Err(here(format!("`{name}` is not an element name")));
                }
                if !element_names.insert(name.to_string()) {
                    return Err(here(format!("element `{name}` is declared twice")));
                }
                property_names.clear();
                if !count.bytes().all(|b| b.is_ascii_digit()) {
                    return Err(here(format!(
                        "element `{name}`: `{count}` is not a count of records"
                    )));
                }
                let count = match count.parse::<u64>() {
                    Ok(n) if n <= MAX_RECORDS => n,
                    _ => {
                        return Err(here(format!(
                            "element `{name}` declares {count} records; at most {MAX_RECORDS} are supported"
                        )))
                    }
                };
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                    line,
                });
            }
            ["property", rest @ ..] => {
                let (ty, name) = match rest {
                    [ty, name] => match Scalar::of(ty) {
                        Some(s) => (Type::Scalar(s), name),
                        None => return Err(here(format!("unknown property type `{ty}`"))),
                    },
                    ["list", length, item, name] => match (Scalar::of(length), Scalar::of(item)) {
                        (Some(length), Some(item)) => (Type::List { length, item }, name),
                        _ => {
                            return Err(here(format!(
                                "unknown list type `{length} {item}`"
                            )))
                        }
                    },
                    _ => return Err(here("a `property` line is `property TYPE NAME` or `property list LENGTH_TYPE ITEM_TYPE NAME`".into())),
                };
                if !is_name(name) {
                    return Err(here(format!("`{name}` is not a property name")));
                }
                let Some(element) = elements.last_mut() else {
                    return Err(here(format!("property `{name}` before any element")));
                };
                if !property_names.insert(name.to_string()) {
                    return Err(here(format!(
                        "element `{}` has two properties `{name}`",
                        element.name
                    )));
                }
                if let Type::List { length, .. } = ty {
                    if !length.is_integer() {
                        return Err(here(format!(
                            "list `{name}`: its length is a {}; it must be an integer type",
                            length.name()
                        )));
                    }
                }
                element.properties.push(Property {
                    name: name.to_string(),
                    ty,
                });
            }
            [keyword, ..] => return Err(here(format!("unknown or malformed `{keyword}` line"))),
        }
    }
    let Some(encoding) = encoding else {
        return Err((None, "malformed PLY header: it has no `format` line".into()));
    };
    Ok(Header {
        encoding,
        elements,
        data_start: at,
        data_line: line + 1,
    })
}

/// Checks what the header promises against the file: every element fits
/// in the bytes after the header at its least size, the vertex element has
/// its position and the face element its indices.
fn check_header(header: &Header, data_bytes: usize) -> Result<(), Located> {
    for e in &header.elements {
        let at = |why: String| (Some(e.line), why);
        if e.count > 0 && e.properties.is_empty() {
            return Err(at(format!(
                "element `{}` declares {} records but no properties",
                e.name, e.count
            )));
        }
        let scalar = |name: &str| -> Result<bool, Located> {
            match e.find(name) {
                None => Ok(false),
                Some((_, p)) => match p.ty {
                    Type::Scalar(_) => Ok(true),
                    Type::List { .. } => Err(at(format!(
                        "property `{name}` of element `{}` is a list; it must be a number",
                        e.name
                    ))),
                },
            }
        };
        if e.name == "vertex" {
            for axis in ["x", "y", "z"] {
                if !scalar(axis)? {
                    return Err(at(format!("element `vertex` has no `{axis}` property")));
                }
            }
            for name in ["nx", "ny", "nz"]
                .into_iter()
                .chain(UV_NAMES.iter().flatten().copied())
            {
                scalar(name)?;
            }
        }
        if e.name == "face" && e.count > 0 {
            match face_indices(e) {
                None => return Err(at("element `face` has no `vertex_indices` list".to_string())),
                Some((_, p)) => match p.ty {
                    Type::List { item, .. } if item.is_integer() => {}
                    Type::List { item, .. } => {
                        return Err(at(format!(
                            "`{}` of element `face` is a list of {}; vertex indices are integers",
                            p.name,
                            item.name()
                        )))
                    }
                    Type::Scalar(_) => {
                        return Err(at(format!(
                            "`{}` of element `face` is a number; it must be a list",
                            p.name
                        )))
                    }
                },
            }
        }
    }
    let mut left = data_bytes as u64;
    for e in &header.elements {
        let least: u64 = match header.encoding {
            // A value is at least a digit and a space or a line end.
            Encoding::Ascii => 2 * e.properties.len() as u64,
            _ => e.properties.iter().map(|p| p.ty.least_bytes()).sum(),
        };
        let need = e.count.saturating_mul(least);
        if need > left {
            return Err((
                Some(e.line),
                format!(
                    "element `{}` declares {} records of at least {least} bytes, {need} in all, \
                     but the file has only {left} bytes left for them",
                    e.name, e.count
                ),
            ));
        }
        left -= need;
    }
    Ok(())
}

/// The names of the texture coordinates: u, then v.
const UV_NAMES: [[&str; 4]; 2] = [
    ["u", "s", "texture_u", "texture_s"],
    ["v", "t", "texture_v", "texture_t"],
];

/// The face element's index list: `vertex_indices`, or `vertex_index`
/// (the later in the header if both are there).
fn face_indices(e: &Element) -> Option<(usize, &Property)> {
    [e.find("vertex_indices"), e.find("vertex_index")]
        .into_iter()
        .flatten()
        .max_by_key(|(i, _)| *i)
}

/// What went wrong reading a record.
enum Fault {
    /// The data ended.
    End,
    /// A value that is not one of its type, in words (`` `x` is not a
    /// float ``).
    Bad(String),
    /// An ASCII record's line ended before its last value.
    Missing,
    /// An ASCII record's line goes on after its last value.
    Extra,
    /// What is wrong with a face, in words after "face N".
    Face(String),
}

/// The data of a file, read a value at a time: ASCII or binary.
trait Data {
    /// Starts a record (ASCII: its line).
    fn begin(&mut self) -> Result<(), Fault>;
    /// A number of type `s`, as an `f32` (integers converted, doubles
    /// rounded).
    fn number(&mut self, s: Scalar) -> Result<f32, Fault>;
    /// An integer of integer type `s`.
    fn integer(&mut self, s: Scalar) -> Result<i64, Fault>;
    /// Reads past a value of type `ty`.
    fn skip(&mut self, ty: Type) -> Result<(), Fault>;
    /// Ends a record.
    fn end(&mut self) -> Result<(), Fault>;
    /// The line being read (ASCII), for errors.
    fn line(&self) -> Option<usize>;
    /// Whether `n` more values of type `item` can fit in what is left (of
    /// the file; of the line, in ASCII), or the fault if they cannot.
    fn fits(&self, n: u64, item: Scalar) -> Result<(), Fault>;
}

/// Binary data, little endian or (`BIG`) big endian.
struct Binary<'a, const BIG: bool> {
    bytes: &'a [u8],
    at: usize,
}

impl<const BIG: bool> Binary<'_, BIG> {
    #[inline(always)]
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fault> {
        let b = self
            .bytes
            .get(self.at..self.at + N)
            .ok_or(Fault::End)?
            .try_into()
            .expect("N bytes");
        self.at += N;
        Ok(b)
    }
}

macro_rules! read_binary {
    ($self:ident, $t:ty) => {{
        let b = $self.take::<{ std::mem::size_of::<$t>() }>()?;
        if BIG {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }
    }};
}

impl<const BIG: bool> Data for Binary<'_, BIG> {
    fn begin(&mut self) -> Result<(), Fault> {
        Ok(())
    }

    #[inline(always)]
    fn number(&mut self, s: Scalar) -> Result<f32, Fault> {
        Ok(match s {
            Scalar::I8 => f32::from(read_binary!(self, i8)),
            Scalar::U8 => f32::from(read_binary!(self, u8)),
            Scalar::I16 => f32::from(read_binary!(self, i16)),
            Scalar::U16 => f32::from(read_binary!(self, u16)),
            Scalar::I32 => read_binary!(self, i32) as f32,
            Scalar::U32 => read_binary!(self, u32) as f32,
            Scalar::F32 => read_binary!(self, f32),
            Scalar::F64 => read_binary!(self, f64) as f32,
        })
    }

    #[inline(always)]
    fn integer(&mut self, s: Scalar) -> Result<i64, Fault> {
        Ok(match s {
            Scalar::I8 => i64::from(read_binary!(self, i8)),
            Scalar::U8 => i64::from(read_binary!(self, u8)),
            Scalar::I16 => i64::from(read_binary!(self, i16)),
            Scalar::U16 => i64::from(read_binary!(self, u16)),
            Scalar::I32 => i64::from(read_binary!(self, i32)),
            Scalar::U32 => i64::from(read_binary!(self, u32)),
            Scalar::F32 | Scalar::F64 => unreachable!("the header has integer types here"),
        })
    }

    fn skip(&mut self, ty: Type) -> Result<(), Fault> {
        let n = match ty {
            Type::Scalar(s) => s.size(),
            Type::List { length, item } => {
                let n = self.integer(length)?;
                usize::try_from(n)
                    .ok()
                    .and_then(|n| n.checked_mul(item.size()))
                    .ok_or_else(|| Fault::Bad(format!("a list of {n} values")))?
            }
        };
        if self.bytes.len() - self.at < n {
            return Err(Fault::End);
        }
        self.at += n;
        Ok(())
    }

    fn end(&mut self) -> Result<(), Fault> {
        Ok(())
    }

    fn line(&self) -> Option<usize> {
        None
    }

    fn fits(&self, n: u64, item: Scalar) -> Result<(), Fault> {
        n.checked_mul(item.size() as u64)
            .is_some_and(|b| b <= (self.bytes.len() - self.at) as u64)
            .then_some(())
            .ok_or(Fault::End)
    }
}

/// ASCII data: a record a line, values separated by spaces or tabs.
struct Ascii<'a> {
    bytes: &'a [u8],
    /// The start of the next line.
    next: usize,
    /// The number of the next line.
    next_line: usize,
    /// What is left of the record's line.
    rest: &'a [u8],
}

impl<'a> Ascii<'a> {
    fn token(&mut self) -> Result<&'a str, Fault> {
        let start = self
            .rest
            .iter()
            .position(|&b| b != b' ' && b != b'\t')
            .ok_or(Fault::Missing)?;
        let rest = &self.rest[start..];
        let len = rest
            .iter()
            .position(|&b| b == b' ' || b == b'\t')
            .unwrap_or(rest.len());
        self.rest = &rest[len..];
        std::str::from_utf8(&rest[..len]).map_err(|_| {
            let token = String::from_utf8_lossy(&rest[..len]);
            Fault::Bad(format!("`{token}` is not a number"))
        })
    }

    /// The next value parsed as `T`, of the format's type `s`; refused
    /// unless it is written as a number (sign, digits, point, exponent: not
    /// `nan` or `inf`).
    fn parse<T: std::str::FromStr>(&mut self, s: Scalar) -> Result<T, Fault> {
        let token = self.token()?;
        let numeric = token
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'));
        match token.parse() {
            Ok(v) if numeric => Ok(v),
            _ => Err(Fault::Bad(format!("`{token}` is not a {}", s.name()))),
        }
    }
}

impl Data for Ascii<'_> {
    fn begin(&mut self) -> Result<(), Fault> {
        if self.next >= self.bytes.len() {
            return Err(Fault::End);
        }
        let tail = &self.bytes[self.next..];
        let len = tail.iter().position(|&b| b == b'\n').unwrap_or(tail.len());
        let line = &tail[..len];
        self.rest = line.strip_suffix(b"\r").unwrap_or(line);
        self.next += len + 1;
        self.next_line += 1;
        Ok(())
    }

    fn number(&mut self, s: Scalar) -> Result<f32, Fault> {
        // As each type's value, then converted as binary values are.
        Ok(match s {
            Scalar::I8 => f32::from(self.parse::<i8>(s)?),
            Scalar::U8 => f32::from(self.parse::<u8>(s)?),
            Scalar::I16 => f32::from(self.parse::<i16>(s)?),
            Scalar::U16 => f32::from(self.parse::<u16>(s)?),
            Scalar::I32 => self.parse::<i32>(s)? as f32,
            Scalar::U32 => self.parse::<u32>(s)? as f32,
            Scalar::F32 => self.parse::<f32>(s)?,
            Scalar::F64 => self.parse::<f64>(s)? as f32,
        })
    }

    fn integer(&mut self, s: Scalar) -> Result<i64, Fault> {
        Ok(match s {
            Scalar::I8 => i64::from(self.parse::<i8>(s)?),
            Scalar::U8 => i64::from(self.parse::<u8>(s)?),
            Scalar::I16 => i64::from(self.parse::<i16>(s)?),
            Scalar::U16 => i64::from(self.parse::<u16>(s)?),
            Scalar::I32 => i64::from(self.parse::<i32>(s)?),
            Scalar::U32 => i64::from(self.parse::<u32>(s)?),
            Scalar::F32 | Scalar::F64 => unreachable!("the header has integer types here"),
        })
    }

    fn skip(&mut self, ty: Type) -> Result<(), Fault> {
        match ty {
            Type::Scalar(s) => {
                self.number(s)?;
            }
            Type::List { length, item } => {
                let n = self.integer(length)?;
                if n < 0 {
                    return Err(Fault::Bad(format!("a list of {n} values")));
                }
                for _ in 0..n {
                    self.number(item)?;
                }
            }
        }
        Ok(())
    }

    fn end(&mut self) -> Result<(), Fault> {
        match self.token() {
            Err(Fault::Missing) => Ok(()),
            _ => Err(Fault::Extra),
        }
    }

    fn line(&self) -> Option<usize> {
        Some(self.next_line - 1)
    }

    fn fits(&self, n: u64, _: Scalar) -> Result<(), Fault> {
        // Each value takes two bytes of its line at least (the last, one).
        n.checked_mul(2)
            .is_some_and(|b| b <= self.rest.len() as u64 + 1)
            .then_some(())
            .ok_or(Fault::Missing)
    }
}

/// What to do with a vertex property.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Slot {
    Position(usize),
    Normal(usize),
    Uv(usize),
    Skip,
}

/// Reads record `index` of `element`: its start, each property by
/// `value` (given the property's number and type), its end.
fn record<D: Data>(
    data: &mut D,
    element: &Element,
    index: u64,
    mut value: impl FnMut(&mut D, usize, Type) -> Result<(), Fault>,
) -> Result<(), Located> {
    let mut k = 0;
    let mut read = |data: &mut D| {
        data.begin()?;
        while k < element.properties.len() {
            value(data, k, element.properties[k].ty)?;
            k += 1;
        }
        data.end()
    };
    read(data).map_err(|fault| {
        let what = format!("{} {index}", element.name);
        let property = element.properties.get(k).map(|p| &p.name);
        let why = match (fault, property) {
            (Fault::Face(why), _) => format!("{what}{why}"),
            (Fault::End, _) => format!(
                "malformed PLY: unexpected end of file at {what} of {}",
                element.count
            ),
            (Fault::Bad(why), Some(p)) => format!("malformed PLY: {what}: {why} (property `{p}`)"),
            (Fault::Missing, Some(p)) => {
                format!("malformed PLY: {what} has too few values: none for property `{p}`")
            }
            (Fault::Extra, _) => {
                format!("malformed PLY: {what} has more values than the header gives it")
            }
            (Fault::Bad(why), None) => format!("malformed PLY: {what}: {why}"),
            (Fault::Missing, None) => format!("malformed PLY: {what} has too few values"),
        };
        (data.line(), why)
    })
}

/// Room for `additional` more items in `v`, or an error saying what for.
fn reserve<T>(v: &mut Vec<T>, additional: usize, what: &str) -> Result<(), Located> {
    v.try_reserve_exact(additional)
        .map_err(|_| (None, format!("not enough memory for {additional} {what}")))
}

/// Reads every element of `header` from `data` into a mesh whose
/// triangles are not yet checked for area (a file may give its faces
/// before its vertices).
fn read<D: Data>(header: &Header, data: &mut D) -> Result<TriangleMesh, Located> {
    let mut mesh = TriangleMesh::default();
    let vertex_count = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .map_or(0, |e| e.count);
    for element in &header.elements {
        match element.name.as_str() {
            "vertex" => vertices(data, element, &mut mesh)?,
            "face" => faces(data, element, vertex_count, &mut mesh.triangles)?,
            _ => {
                for i in 0..element.count {
                    record(data, element, i, |data, _, ty| data.skip(ty))?;
                }
            }
        }
    }
    Ok(mesh)
}

fn vertices<D: Data>(
    data: &mut D,
    element: &Element,
    mesh: &mut TriangleMesh,
) -> Result<(), Located> {
    let slot_of = |name: &str| match name {
        "x" => Slot::Position(0),
        "y" => Slot::Position(1),
        "z" => Slot::Position(2),
        "nx" => Slot::Normal(0),
        "ny" => Slot::Normal(1),
        "nz" => Slot::Normal(2),
        n if UV_NAMES[0].contains(&n) => Slot::Uv(0),
        n if UV_NAMES[1].contains(&n) => Slot::Uv(1),
        _ => Slot::Skip,
    };
    let slots: Vec<Slot> = element
        .properties
        .iter()
        .map(|p| slot_of(&p.name))
        .collect();
    let has = |all: &[Slot]| all.iter().all(|s| slots.contains(s));
    let normals = has(&[Slot::Normal(0), Slot::Normal(1), Slot::Normal(2)]);
    let uvs = has(&[Slot::Uv(0), Slot::Uv(1)]);
    let count = element.count as usize;
    reserve(&mut mesh.positions, count, "vertices")?;
    if normals {
        let mut v = Vec::new();
        reserve(&mut v, count, "vertex normals")?;
        mesh.normals = Some(v);
    }
    if uvs {
        let mut v = Vec::new();
        reserve(&mut v, count, "texture coordinates")?;
        mesh.uvs = Some(v);
    }
    for i in 0..element.count {
        let (mut position, mut normal, mut uv) = ([0f32; 3], [0f32; 3], [0f32; 2]);
        record(data, element, i, |data, k, ty| {
            match (slots[k], ty) {
                (Slot::Position(a), Type::Scalar(s)) => position[a] = data.number(s)?,
                (Slot::Normal(a), Type::Scalar(s)) => normal[a] = data.number(s)?,
                (Slot::Uv(a), Type::Scalar(s)) => uv[a] = data.number(s)?,
                (_, ty) => data.skip(ty)?,
            }
            Ok(())
        })?;
        if !position.iter().all(|c| c.is_finite()) {
            return Err((
                data.line(),
                format!("vertex {i}: position {position:?} is not finite (NaN or infinite)"),
            ));
        }
        mesh.positions.push(position);
        if let Some(n) = &mut mesh.normals {
            n.push(normal);
        }
        if let Some(t) = &mut mesh.uvs {
            t.push(uv);
        }
    }
    Ok(())
}

fn faces<D: Data>(
    data: &mut D,
    element: &Element,
    vertex_count: u64,
    triangles: &mut Vec<[u32; 3]>,
) -> Result<(), Located> {
    let indices = face_indices(element).map(|(k, _)| k);
    // Usually a triangle a face; polygons make more as they come.
    reserve(triangles, element.count as usize, "triangles")?;
    let mut polygon: Vec<u32> = Vec::new();
    for f in 0..element.count {
        record(data, element, f, |data, k, ty| match ty {
            Type::List { length, item } if Some(k) == indices => {
                read_polygon(data, length, item, vertex_count, &mut polygon)
            }
            ty => data.skip(ty),
        })?;
        let n = polygon.len();
        let at = |why: String| (data.line(), format!("face {f}{why}"));
        if n < 3 {
            return Err(at(format!(" has {n} vertices; a face needs at least 3")));
        }
        if triangles.len() as u64 + (n as u64 - 2) > MAX_RECORDS {
            return Err(at(format!(": more than {MAX_RECORDS} triangles in all")));
        }
        if triangles.capacity() - triangles.len() < n - 2 {
            let more = (n - 2).max(triangles.len() / 2);
            reserve(triangles, more, "triangles")?;
        }
        triangles.extend(fan(&polygon));
    }
    Ok(())
}

/// Reads a face's index list, of `length` and `item` types, into
/// `polygon`, each index checked against `vertex_count`.
fn read_polygon<D: Data>(
    data: &mut D,
    length: Scalar,
    item: Scalar,
    vertex_count: u64,
    polygon: &mut Vec<u32>,
) -> Result<(), Fault> {
    let n = data.integer(length)?;
    let n = u64::try_from(n).map_err(|_| Fault::Face(format!(" has {n} vertices")))?;
    data.fits(n, item)?;
    polygon.clear();
    polygon
        .try_reserve(n as usize)
        .map_err(|_| Fault::Face(format!(" has {n} vertices, more than memory holds")))?;
    for _ in 0..n {
        let i = data.integer(item)?;
        if i < 0 {
            return Err(Fault::Face(format!(" has a negative index ({i})")));
        }
        if i as u64 >= vertex_count {
            return Err(Fault::Face(format!(
                ": vertex index {i} out of range (the file has {vertex_count} vertices)"
            )));
        }
        polygon.push(i as u32);
    }
    Ok(())
}

/// Reads a PLY file's `bytes` (named `path` in errors).
pub(super) fn load(path: &Path, bytes: Vec<u8>) -> Result<Model, MeshError> {
    let located = |(line, why): Located| MeshError::new(path, line, why);
    let header = read_header(&bytes).map_err(located)?;
    check_header(&header, bytes.len() - header.data_start).map_err(located)?;
    if !header.elements.iter().any(|e| e.name == "vertex") {
        return Err(MeshError::new(path, None, "no `vertex` element"));
    }
    let data = &bytes[header.data_start..];
    let mesh = match header.encoding {
        Encoding::Ascii => read(
            &header,
            &mut Ascii {
                bytes: data,
                next: 0,
                next_line: header.data_line,
                rest: &[],
            },
        ),
        Encoding::BinaryLittleEndian => read(&header, &mut Binary::<false> { bytes: data, at: 0 }),
        Encoding::BinaryBigEndian => read(&header, &mut Binary::<true> { bytes: data, at: 0 }),
    }
    .map_err(located)?;
    // The mesh is all that is needed now.
    drop(bytes);
    let mut mesh = mesh;
    // Zero-area triangles are left out, now that every vertex is known.
    let before = mesh.triangles.len();
    let positions = &mesh.positions;
    mesh.triangles.retain(|&t| super::has_area(positions, t));
    let skipped_degenerate = before - mesh.triangles.len();
    reserve(&mut mesh.material, mesh.triangles.len(), "triangles").map_err(located)?;
    mesh.material.resize(mesh.triangles.len(), NO_MATERIAL);
    Model {
        meshes: vec![mesh],
        materials: Vec::new(),
        instances: vec![(0, Mat4::IDENTITY)],
        skipped_degenerate,
        ..Model::default()
    }
    .finish(path)
}
