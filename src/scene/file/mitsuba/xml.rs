//! The XML layer of a Mitsuba scene: files read and parsed (no document
//! type definitions, so no entity can expand), `<include>`s spliced in,
//! `<default>`s and `-D` values substituted for `$name` in every
//! attribute, `<path>`s gathered; the result is a tree of plain elements,
//! each with the file, line and column it was written at.

use super::{located, plain, Failure, Options};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// How deep `<include>`s may nest (Mitsuba's limit).
const MAX_INCLUDE_DEPTH: usize = 15;

/// The most elements a scene may have, all files together: far beyond
/// any real scene's, a bound on the memory a hostile file can take.
const MAX_ELEMENTS: usize = 10_000_000;

/// Where an element was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct At {
    /// The file, an index into [`Files`].
    pub file: u32,
    /// 1-based line and column.
    pub line: u32,
    /// 1-based column.
    pub col: u32,
}

/// The files a scene was read from, for messages.
#[derive(Clone, Debug, Default)]
pub struct Files {
    /// Each file's name as messages show it, and its text (shared, so
    /// that a file is parsed without a copy while includes are added).
    pub files: Vec<(String, std::sync::Arc<str>)>,
}

/// An element: its tag, attributes (after substitution), children, and
/// where it was written.
#[derive(Clone, Debug)]
pub struct Element {
    /// The tag name.
    pub tag: String,
    /// The attributes, in order.
    pub attrs: Vec<(String, String)>,
    /// The child elements, in order.
    pub children: Vec<Element>,
    /// Where it was written.
    pub at: At,
}

impl Element {
    /// The value of attribute `name`.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// A whole scene's elements (the children of its `<scene>`, includes
/// spliced in) and the folders its files are looked for in.
pub struct Document {
    /// The elements, in order.
    pub elements: Vec<Element>,
    /// Folders named by `<path>`, latest first, then the scene's own.
    pub search: Vec<PathBuf>,
    /// The files read.
    pub files: Files,
}

struct Loader<'o> {
    options: &'o Options,
    /// The scene file's folder: includes stay within it unless allowed.
    root: PathBuf,
    params: HashMap<String, String>,
    /// Parameters given on the command line that some attribute used.
    used: std::collections::HashSet<String>,
    files: Files,
    search: Vec<PathBuf>,
    /// The files being read, outermost first (for cycles).
    stack: Vec<PathBuf>,
    count: usize,
}

/// Reads the scene file at `path` with its includes.
pub fn load(path: &Path, options: &Options) -> Result<Document, Failure> {
    let root = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut loader = Loader {
        options,
        root: canonical(&root).unwrap_or_else(|| root.clone()),
        params: options.defines.iter().cloned().collect(),
        used: Default::default(),
        files: Files::default(),
        search: Vec::new(),
        stack: Vec::new(),
        count: 0,
    };
    let elements = loader.file(path, None)?;
    for (name, _) in &options.defines {
        if !loader.used.contains(name) {
            return Err(plain(
                path.display().to_string(),
                format!("-D {name}=…: the scene has no parameter `${name}` (no attribute uses it)"),
            ));
        }
    }
    let mut search = loader.search;
    search.reverse();
    search.push(root);
    Ok(Document {
        elements,
        search,
        files: loader.files,
    })
}

fn canonical(p: &Path) -> Option<PathBuf> {
    std::fs::canonicalize(if p.as_os_str().is_empty() {
        Path::new(".")
    } else {
        p
    })
    .ok()
}

impl Loader<'_> {
    /// The elements of the file at `path`, included at `from` (none for
    /// the scene file itself).
    fn file(&mut self, path: &Path, from: Option<(At, &str)>) -> Result<Vec<Element>, Failure> {
        let name = path.display().to_string();
        let fail_at = |loader: &Loader, message: String| match from {
            Some((at, _)) => loader.failure(at, message),
            None => plain(name.clone(), message),
        };
        let meta = std::fs::metadata(path).map_err(|e| {
            fail_at(
                self,
                match e.kind() {
                    std::io::ErrorKind::NotFound => format!("{name}: no such file"),
                    _ => format!("{name}: cannot read it: {e}"),
                },
            )
        })?;
        if !meta.is_file() {
            return Err(fail_at(self, format!("{name}: is not a regular file")));
        }
        let canon = canonical(path).unwrap_or_else(|| path.to_path_buf());
        if let Some((_, _)) = from {
            if self.stack.contains(&canon) {
                return Err(fail_at(
                    self,
                    format!(
                        "{name}: includes itself (through {} files)",
                        self.stack.len()
                    ),
                ));
            }
            if self.stack.len() > MAX_INCLUDE_DEPTH {
                return Err(fail_at(
                    self,
                    format!("includes nest more than {MAX_INCLUDE_DEPTH} deep"),
                ));
            }
            if !self.options.allow_outside && !canon.starts_with(&self.root) {
                return Err(fail_at(
                    self,
                    format!(
                        "{name}: lies outside the scene's folder ({}); --allow-outside reads it",
                        self.root.display()
                    ),
                ));
            }
        }
        let bytes = crate::input::read(path, crate::input::MAX_SCENE_BYTES)
            .map_err(|e| fail_at(self, format!("{name}: {e}")))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| fail_at(self, format!("{name}: is not UTF-8 text")))?;
        let index = self.files.files.len() as u32;
        self.files.files.push((name.clone(), text.into()));
        self.stack.push(canon);
        let result = self.document(index, path);
        self.stack.pop();
        result
    }

    fn failure(&self, at: At, message: String) -> Failure {
        located(&self.files, at, message)
    }

    /// The elements of file number `index` (read from `path`).
    fn document(&mut self, index: u32, path: &Path) -> Result<Vec<Element>, Failure> {
        let text = std::sync::Arc::clone(&self.files.files[index as usize].1);
        let options = roxmltree::ParsingOptions {
            allow_dtd: false,
            nodes_limit: (MAX_ELEMENTS - self.count.min(MAX_ELEMENTS)) as u32,
            ..Default::default()
        };
        let doc = roxmltree::Document::parse_with_options(&text, options).map_err(|e| {
            let p = e.pos();
            let mut at = At {
                file: index,
                line: p.row,
                col: p.col,
            };
            if let (roxmltree::Error::DtdDetected, Some(offset)) = (&e, text.find("<!DOCTYPE")) {
                let (line, col) = super::super::source::line_col(&text, offset);
                at.line = line as u32;
                at.col = col as u32;
            }
            let message = match e {
                roxmltree::Error::DtdDetected => {
                    "a document type definition (<!DOCTYPE …>) is not read: its entities could \
                     expand without bound"
                        .to_string()
                }
                e => format!("malformed XML: {e}"),
            };
            self.failure(at, message)
        })?;
        let root = doc.root_element();
        let at = |n: roxmltree::Node| {
            let p = doc.text_pos_at(n.range().start);
            At {
                file: index,
                line: p.row,
                col: p.col,
            }
        };
        if root.tag_name().name() != "scene" {
            return Err(self.failure(
                at(root),
                format!(
                    "the root element is <{}>; a Mitsuba scene's is <scene version=\"…\">",
                    root.tag_name().name()
                ),
            ));
        }
        if root.attribute("version").is_none() {
            return Err(self.failure(
                at(root),
                "<scene> needs a version attribute (version=\"3.0.0\")".into(),
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let mut out = Vec::new();
        for child in root.children().filter(|n| n.is_element()) {
            match child.tag_name().name() {
                "default" => {
                    let e = self.element(child, &at, false)?;
                    let (Some(name), Some(value)) = (e.attr("name"), e.attr("value")) else {
                        return Err(self.failure(
                            e.at,
                            "<default> needs `name` and `value` attributes".into(),
                        ));
                    };
                    self.params
                        .entry(name.to_string())
                        .or_insert_with(|| value.to_string());
                }
                "include" => {
                    let e = self.element(child, &at, false)?;
                    let Some(file) = e.attr("filename") else {
                        return Err(
                            self.failure(e.at, "<include> needs a `filename` attribute".into())
                        );
                    };
                    // Beside the including file, else where Mitsuba looks:
                    // the scene's folder and the `<path>`s so far.
                    let beside = dir.join(file);
                    let included = std::iter::once(beside.clone())
                        .chain(std::iter::once(self.root.join(file)))
                        .chain(self.search.iter().rev().map(|d| d.join(file)))
                        .find(|p| p.is_file())
                        .unwrap_or(beside);
                    let elements = self.file(&included, Some((e.at, file)))?;
                    out.extend(elements);
                }
                "path" => {
                    let e = self.element(child, &at, false)?;
                    let Some(value) = e.attr("value") else {
                        return Err(self.failure(e.at, "<path> needs a `value` attribute".into()));
                    };
                    self.search.push(dir.join(value));
                }
                _ => out.push(self.element(child, &at, true)?),
            }
        }
        Ok(out)
    }

    /// `node` as an element, its attributes substituted, with its children
    /// when `deep`.
    fn element(
        &mut self,
        node: roxmltree::Node,
        at: &dyn Fn(roxmltree::Node) -> At,
        deep: bool,
    ) -> Result<Element, Failure> {
        self.count += 1;
        let here = at(node);
        if self.count > MAX_ELEMENTS {
            return Err(self.failure(
                here,
                format!("the scene has more than {MAX_ELEMENTS} elements"),
            ));
        }
        let mut attrs = Vec::new();
        for a in node.attributes() {
            let value = self.substitute(a.value(), here)?;
            attrs.push((a.name().to_string(), value));
        }
        let mut children = Vec::new();
        if deep {
            for c in node.children().filter(|n| n.is_element()) {
                children.push(self.element(c, at, true)?);
            }
        }
        Ok(Element {
            tag: node.tag_name().name().to_string(),
            attrs,
            children,
            at: here,
        })
    }

    /// `value` with every `$name` replaced by its parameter (the longest
    /// name that matches first), `\$` by `$`.
    fn substitute(&mut self, value: &str, at: At) -> Result<String, Failure> {
        if !value.contains('$') {
            return Ok(value.to_string());
        }
        let mut names: Vec<&String> = self.params.keys().collect();
        names.sort_by_key(|n| std::cmp::Reverse(n.len()));
        let mut out = String::with_capacity(value.len());
        let mut rest = value;
        let mut used = Vec::new();
        while let Some(i) = rest.find('$') {
            if rest[..i].ends_with('\\') {
                out.push_str(&rest[..i - 1]);
                out.push('$');
                rest = &rest[i + 1..];
                continue;
            }
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let Some(name) = names.iter().find(|n| after.starts_with(n.as_str())) else {
                let word: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let mut known: Vec<&str> = self.params.keys().map(String::as_str).collect();
                known.sort();
                return Err(self.failure(
                    at,
                    format!(
                        "undefined parameter `${word}`: give it a <default name=\"{word}\" \
                         value=\"…\"/> or -D {word}=…{}",
                        if known.is_empty() {
                            String::new()
                        } else {
                            format!(" (the scene's parameters: {})", known.join(", "))
                        }
                    ),
                ));
            };
            out.push_str(&self.params[name.as_str()]);
            used.push(name.to_string());
            rest = &after[name.len()..];
        }
        out.push_str(rest);
        self.used.extend(used);
        Ok(out)
    }
}
