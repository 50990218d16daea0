//! Scene files: reading TOML or JSON into a [`SceneDesc`], compiling it with
//! command-line overrides, writing a description back out, and turning every
//! mistake into one message with file, line, column, field path and a hint.
//!
//! ```
//! use lumen::scene::file::{Format, SceneFile};
//! use lumen::scene::Overrides;
//!
//! let text = "[render]\nwidth = 16\nsamples_per_pixel = 1\n\n\
//!             [materials.red]\ntype = \"diffuse\"\nalbedo = [0.8, 0.1, 0.1]\n\n\
//!             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = \"red\"\n";
//! let file = SceneFile::parse("demo.toml", text.to_string(), Format::Toml).unwrap();
//! let scene = file.compile(&Overrides::default()).unwrap();
//! assert_eq!((scene.settings.width, scene.settings.height), (16, 9));
//!
//! let bad = text.replace("radius = 0.5", "radus = 0.5");
//! let err = SceneFile::parse("demo.toml", bad, Format::Toml).unwrap_err();
//! assert!(err.to_string().contains("demo.toml:12:1: objects[0].radus: unknown field"));
//! assert!(err.to_string().contains("did you mean `radius`?"));
//! ```

mod decode;
pub mod export;
mod fast;
pub mod import;
pub(crate) mod matrix;
pub mod mitsuba;
pub mod pbrt;
mod tessellate;
pub use crate::hint;
mod node_de;
mod plain_toml;
pub mod source;
mod toml_cut;

use super::{Overrides, Scene, SceneDesc, SceneError};
use source::{Node, Value};

use std::fmt;
use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;
use thiserror::Error;

/// The two scene file formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// TOML (`.toml`): the format for people to write.
    Toml,
    /// JSON (`.json`): the same schema, for generated scenes.
    Json,
}

impl Format {
    /// The format a file name's extension asks for, if it is `.toml` or `.json`.
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "toml" => Some(Format::Toml),
            "json" => Some(Format::Json),
            _ => None,
        }
    }
}

/// A scene file that cannot be read or rendered; its message (`Display`) is
/// everything a person needs to find and fix the mistake.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{0}")]
pub struct SceneFileError(pub Box<Diagnostic>);

impl From<Diagnostic> for SceneFileError {
    fn from(d: Diagnostic) -> Self {
        SceneFileError(Box::new(d))
    }
}

impl std::ops::Deref for SceneFileError {
    type Target = Diagnostic;
    fn deref(&self) -> &Diagnostic {
        &self.0
    }
}

/// The parts of a [`SceneFileError`].
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// The file, as given.
    pub file: String,
    /// 1-based line and column, where known.
    pub line_col: Option<(usize, usize)>,
    /// Path of the field at fault, e.g. `objects[3].material`, where there is one.
    pub field: Option<String>,
    /// What is wrong: expected versus got.
    pub message: String,
    /// A suggestion, where one helps.
    pub hint: Option<String>,
    /// The offending line with the place underlined, where known.
    pub excerpt: Option<String>,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((line, col)) = self.line_col {
            write!(f, ":{line}:{col}")?;
        }
        write!(f, ": ")?;
        if let Some(field) = self.field.as_deref().filter(|p| !p.is_empty()) {
            write!(f, "{field}: ")?;
        }
        write!(f, "{}", self.message)?;
        if let Some(excerpt) = &self.excerpt {
            write!(f, "\n{excerpt}")?;
        }
        if let Some(hint) = &self.hint {
            write!(f, "\n  = hint: {hint}")?;
        }
        Ok(())
    }
}

impl Diagnostic {
    fn plain(file: &str, message: impl Into<String>) -> Self {
        Diagnostic {
            file: file.to_string(),
            line_col: None,
            field: None,
            message: message.into(),
            hint: None,
            excerpt: None,
        }
    }

    /// Located at `span` of `text`: its line, column and underlined excerpt.
    fn at(mut self, text: &str, span: Range<usize>) -> Self {
        let lc = source::line_col(text, span.start);
        self.line_col = Some(lc);
        self.excerpt = Some(excerpt(text, lc, Some(span)));
        self
    }
}

/// A scene description could not be written out.
#[derive(Debug, Error)]
#[error("cannot write the scene as {format:?}: {message}")]
pub struct ExportError {
    /// The format asked for.
    pub format: Format,
    /// Why.
    pub message: String,
}

/// Writes `desc` as a scene file of the given format. Reading the text back
/// gives `desc` again, and writing that gives the same text (see
/// [`export::write_scene`], which writes it to a file or a pipe as
/// it goes).
pub fn export(desc: &SceneDesc, format: Format) -> Result<String, ExportError> {
    let mut text = Vec::new();
    export::write_scene(desc, format, &mut text).map_err(|e| ExportError {
        format,
        message: e.to_string(),
    })?;
    // Both writers write UTF-8 only.
    Ok(String::from_utf8(text).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into()))
}

/// Whether `path` names a Mitsuba scene (`.xml`).
pub fn is_mitsuba(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// A parsed scene file, kept with its text so that errors found later (when
/// compiling, after overrides) can still point into it.
#[derive(Clone, Debug)]
pub struct SceneFile {
    /// The file name used in messages.
    pub name: String,
    /// The file's format.
    pub format: Format,
    /// The scene it describes, with defaults filled in.
    pub desc: SceneDesc,
    /// The directory mesh files are relative to: the file's own.
    pub dir: std::path::PathBuf,
    /// What reading a scene of another renderer's format made do with
    /// (`--approximate`), one line each.
    pub import_warnings: Vec<String>,
    source: String,
    root: OnceLock<Node>,
}

impl SceneFile {
    /// Reads and parses the file at `path`; the extension (`.toml`, `.json`,
    /// `.xml` for a Mitsuba 3 scene, `.pbrt` for a pbrt-v4 scene) gives the
    /// format.
    pub fn read(path: &Path) -> Result<SceneFile, SceneFileError> {
        Self::read_with(path, &mitsuba::Options::default())
    }

    /// [`SceneFile::read`], a Mitsuba scene read with `import`.
    pub fn read_with(path: &Path, import: &mitsuba::Options) -> Result<SceneFile, SceneFileError> {
        let name = path.display().to_string();
        if is_mitsuba(path) || pbrt::is_pbrt(path) {
            let imported = if is_mitsuba(path) {
                mitsuba::read(path, import)?
            } else {
                pbrt::read(path, import)?
            };
            return Ok(SceneFile {
                name,
                // Imported scenes are what they export as.
                format: Format::Toml,
                desc: imported.desc,
                dir: path.parent().unwrap_or(Path::new("")).to_path_buf(),
                import_warnings: imported.warnings,
                source: String::new(),
                root: OnceLock::new(),
            });
        }
        let fail = |message: String| Diagnostic::plain(&name, message);
        let meta = std::fs::metadata(path).map_err(|e| {
            fail(match e.kind() {
                std::io::ErrorKind::NotFound => "no such scene file".to_string(),
                _ => format!("cannot read the scene file: {e}"),
            })
        })?;
        if meta.is_dir() {
            return Err(fail(
                "is a directory; expected a scene file (.toml, .json, .xml or .pbrt)".into(),
            )
            .into());
        }
        let format = Format::from_extension(path).ok_or_else(|| {
            fail(
                "unknown scene file type: the name must end in .toml, .json, .xml (Mitsuba 3) or .pbrt (pbrt-v4)"
                    .into(),
            )
        })?;
        let bytes = crate::input::read(path, crate::input::MAX_SCENE_BYTES)
            .map_err(|e| fail(format!("the scene file {e}")))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let offset = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            let mut err = fail("the file is not UTF-8 text".into());
            err.line_col = Some(source::line_col(&text, offset));
            err
        })?;
        let mut file = SceneFile::parse(name, text, format)?;
        file.dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        Ok(file)
    }

    /// Parses `text` in `format`; `name` is used in messages, and mesh
    /// files are found relative to the working directory.
    ///
    /// A file without mistakes is read straight into its description; only
    /// a file with one is read again, slowly, to say exactly where and what
    /// it is (the result is the same as [`SceneFile::parse_with_positions`]).
    pub fn parse(
        name: impl Into<String>,
        mut text: String,
        format: Format,
    ) -> Result<SceneFile, SceneFileError> {
        drop_bom(&mut text);
        let desc = if is_blank(&text) {
            Some(SceneDesc::default())
        } else {
            fast::read(&text, format)
        };
        match desc {
            Some(desc) => Ok(SceneFile {
                name: name.into(),
                format,
                desc,
                dir: std::path::PathBuf::new(),
                import_warnings: Vec::new(),
                source: text,
                root: OnceLock::new(),
            }),
            None => Self::parse_with_positions(name, text, format),
        }
    }

    /// [`SceneFile::parse`] by the reader that records where every value is
    /// written, the one that words the error messages: several times
    /// slower, and several kilobytes an object, on large files.
    pub fn parse_with_positions(
        name: impl Into<String>,
        mut text: String,
        format: Format,
    ) -> Result<SceneFile, SceneFileError> {
        let name = name.into();
        drop_bom(&mut text);
        let root = tree(&text, format).map_err(|e| {
            // toml_edit splits its message over lines; keep the message on one.
            let message = e.message.lines().collect::<Vec<_>>().join("; ");
            let mut err = Diagnostic::plain(&name, format!("syntax error: {message}"));
            err.line_col = e.line_col;
            err.excerpt = e
                .line_col
                .map(|lc| excerpt(&text, lc, e.offset.map(|o| o..o + 1)));
            err
        })?;
        let desc = decode::scene(&root).map_err(|e| {
            let mut err = Diagnostic::plain(&name, e.message).at(&text, e.span);
            err.field = Some(e.path);
            err.hint = e.hint;
            err
        })?;
        Ok(SceneFile {
            name,
            format,
            desc,
            dir: std::path::PathBuf::new(),
            import_warnings: Vec::new(),
            source: text,
            root: OnceLock::from(root),
        })
    }

    /// The file's values with their positions, read when first needed (to
    /// place an error found when compiling).
    fn root(&self) -> &Node {
        self.root.get_or_init(|| {
            tree(&self.source, self.format).unwrap_or(Node {
                span: 0..0,
                value: Value::Table(Vec::new()),
            })
        })
    }

    /// Applies `overrides` and validates and compiles the scene. An error is
    /// located in the file unless the faulty value came from the overrides.
    pub fn compile(&self, overrides: &Overrides) -> Result<Scene, SceneFileError> {
        Ok(self.resolve(overrides)?.1)
    }

    /// [`SceneFile::compile`], also returning the description as overridden
    /// (what a checkpoint records).
    pub fn resolve(&self, overrides: &Overrides) -> Result<(SceneDesc, Scene), SceneFileError> {
        self.finish(self.desc.clone(), overrides)
    }

    /// [`SceneFile::resolve`], consuming the file: the description is moved
    /// rather than copied (a file may hold millions of objects), and the
    /// file's text is freed once the scene is compiled.
    pub fn into_resolved(
        mut self,
        overrides: &Overrides,
    ) -> Result<(SceneDesc, Scene), SceneFileError> {
        let desc = std::mem::take(&mut self.desc);
        self.finish(desc, overrides)
    }

    /// `desc` (this file's description) with `overrides` applied, and its
    /// scene, compiled against the file's folder.
    fn finish(
        &self,
        mut desc: SceneDesc,
        overrides: &Overrides,
    ) -> Result<(SceneDesc, Scene), SceneFileError> {
        overrides.apply(&mut desc);
        let scene =
            Scene::from_desc_in(&desc, &self.dir).map_err(|e| self.locate(&e, overrides))?;
        Ok((desc, scene))
    }

    /// `error`, found when compiling this file's scene, with the file's name,
    /// the line and column of the field at fault, and a hint where one helps.
    pub fn locate(&self, error: &SceneError, overrides: &Overrides) -> SceneFileError {
        let field = error.field();
        let mut err = Diagnostic::plain(&self.name, error.message());
        err.hint = error.hint();
        if overridden(overrides).contains(&field.as_str()) {
            err.message
                .push_str(" (with the settings given on the command line)");
        } else if let Some(span) = find(self.root(), &field) {
            err = err.at(&self.source, span);
        }
        err.field = Some(field);
        err.into()
    }
}

/// The Unicode byte-order mark.
const BOM: char = '\u{feff}';

/// A byte-order mark only says the text is UTF-8 (some Windows editors
/// write one): dropped in both formats, so that columns on the first line
/// count from its first visible character.
fn drop_bom(text: &mut String) {
    if text.starts_with(BOM) {
        text.drain(..BOM.len_utf8());
    }
}

/// The tree of `text`'s values and their positions. Nothing but whitespace
/// is the empty scene in both formats, as an empty TOML document is (JSON
/// would call it a syntax error).
pub(super) fn tree(text: &str, format: Format) -> Result<Node, source::SyntaxError> {
    if is_blank(text) {
        return Ok(Node {
            span: 0..0,
            value: Value::Table(Vec::new()),
        });
    }
    match format {
        Format::Toml => source::parse_toml(text),
        Format::Json => source::parse_json(text),
    }
}

/// Whether `text` holds nothing but the whitespace both formats allow
/// between values (space, tab, line breaks).
fn is_blank(text: &str) -> bool {
    text.bytes()
        .all(|b| matches!(b, b' ' | b'\t' | b'\n' | b'\r'))
}

/// The fields whose values `overrides` replaces.
fn overridden(o: &Overrides) -> Vec<&'static str> {
    let mut fields = Vec::new();
    if o.width.is_some() {
        fields.extend(["render", "render.width", "render.height"]);
    }
    if o.samples_per_pixel.is_some() {
        fields.push("render.samples_per_pixel");
    }
    if o.max_depth.is_some() {
        fields.push("render.max_depth");
    }
    if o.seed.is_some() {
        fields.push("render.seed");
    }
    fields
}

/// The span of the value at `path` (`objects[3].radius`), or of its nearest
/// ancestor written in the file when the value itself was left to its default.
fn find(root: &Node, path: &str) -> Option<Range<usize>> {
    let mut node = root;
    let mut rest = path;
    loop {
        rest = rest.strip_prefix('.').unwrap_or(rest);
        if rest.is_empty() {
            return Some(node.span.clone());
        }
        let next = match &node.value {
            Value::Table(entries) => entries
                .iter()
                .filter(|e| {
                    rest.strip_prefix(e.key.as_str())
                        .is_some_and(|after| after.is_empty() || after.starts_with(['.', '[']))
                })
                // Material names may contain dots: prefer the longest match.
                .max_by_key(|e| e.key.len())
                .map(|e| (&e.node, e.key.len())),
            Value::Array(items) => rest
                .strip_prefix('[')
                .and_then(|r| r.split_once(']'))
                .and_then(|(index, _)| {
                    let i: usize = index.parse().ok()?;
                    Some((items.get(i)?, index.len() + 2))
                }),
            _ => None,
        };
        match next {
            Some((child, consumed)) => {
                node = child;
                rest = &rest[consumed..];
            }
            // The TOML root has no position of its own.
            None => return (!std::ptr::eq(node, root)).then(|| node.span.clone()),
        }
    }
}

/// The line `line_col` points into, with `span` (or one character) underlined:
///
/// ```text
///    12 | radius = -1
///       |          ^^
/// ```
fn excerpt(text: &str, (line, col): (usize, usize), span: Option<Range<usize>>) -> String {
    let line_text = text.lines().nth(line.saturating_sub(1)).unwrap_or("");
    let chars: Vec<char> = line_text.chars().collect();
    let start = col.saturating_sub(1).min(chars.len());
    let width = span
        .and_then(|s| text.get(s))
        .map_or(1, |s| s.lines().next().unwrap_or("").chars().count())
        .clamp(1, (chars.len() - start).max(1));
    // Keep long lines (one-line JSON) readable: show a window around the place.
    let from = start.saturating_sub(40);
    let to = (start + width + 40).min(chars.len());
    let shown: String = chars[from..to].iter().collect();
    let lead = if from > 0 { "…" } else { "" };
    let tail = if to < chars.len() { "…" } else { "" };
    let number = line.to_string();
    let pad = " ".repeat(number.len());
    let offset = " ".repeat(start - from + lead.chars().count());
    format!(
        " {pad} |\n {number} | {lead}{shown}{tail}\n {pad} | {offset}{}",
        "^".repeat(width.min(to - start).max(1))
    )
}
