//! pbrt-v4 scenes (`.pbrt`): read into a [`SceneDesc`](crate::scene::desc::SceneDesc), the description
//! every lumen scene has, so that a pbrt scene renders as it is and
//! exports to lumen's TOML unchanged.
//!
//! `lex` cuts the text into tokens; this module reads directives and their
//! parameter lists (`params`), following `Include` and `Import`; `scene`
//! keeps pbrt's graphics state and turns each directive into lumen's
//! description, with `materials` for materials and textures and `spectra`
//! for pbrt's named spectra. What lumen does not have is refused with the
//! file, line and column and the list of what it has, unless
//! [`Options::approximate`] asks for the nearest it has instead.
//! docs/pbrt.md lists the directives and what differs.

mod lex;
mod materials;
mod media;
mod params;
mod scene;
mod shapes;
mod spectra;

use super::import::{Imported, Options};
use super::{excerpt, Diagnostic, SceneFileError};
use lex::{At, Lexer, Tok};
use params::{Param, Params, Values};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The place of a problem that has none in the files.
const NOWHERE: At = At {
    file: u32::MAX,
    line: 0,
    col: 0,
};

/// How deep `Include`s may nest.
const MAX_INCLUDE_DEPTH: usize = 32;

/// What went wrong, located.
pub(super) type Failure = SceneFileError;

/// Whether `path` names a pbrt scene (`.pbrt`).
pub fn is_pbrt(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("pbrt"))
}

/// Reads the pbrt-v4 scene at `path`.
pub fn read(path: &Path, options: &Options) -> Result<Imported, Failure> {
    if let Some((name, _)) = options.defines.first() {
        return Err(Diagnostic::plain(
            &path.display().to_string(),
            format!("-D {name}=…: a pbrt scene has no parameters (-D is for Mitsuba scenes)"),
        )
        .into());
    }
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut input = Input {
        files: Vec::new(),
        open: Vec::new(),
        peeked: None,
        root: canonical(&dir).unwrap_or_else(|| dir.clone()),
        dir: dir.clone(),
        options: options.clone(),
    };
    input.open(path, None).map_err(|(_, message, _)| {
        SceneFileError::from(Diagnostic::plain(&path.display().to_string(), message))
    })?;
    let mut builder = scene::Builder::new(options.approximate);
    let read = (|| {
        while let Some((name, at)) = input.directive()? {
            builder.directive(&name, at, &mut input)?;
        }
        builder.finish(&input)
    })();
    read.map_err(|p| input.problem(p))
}

fn canonical(p: &Path) -> Option<PathBuf> {
    std::fs::canonicalize(if p.as_os_str().is_empty() {
        Path::new(".")
    } else {
        p
    })
    .ok()
}

/// A token, owned.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Token {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

impl Token {
    fn describe(&self) -> String {
        match self {
            Token::Word(w) => format!("`{w}`"),
            Token::Str(s) => format!("the string \"{s}\""),
            Token::Num(n) => format!("the number {n}"),
            Token::Open => "`[`".into(),
            Token::Close => "`]`".into(),
        }
    }
}

/// The files being read, innermost last, and what they are read from.
pub(crate) struct Input {
    /// Every file read: its name in messages and its text.
    files: Vec<(String, Arc<str>)>,
    /// The files open (the scene's, then its `Include`s): their tokens and
    /// canonical paths.
    open: Vec<(Lexer, PathBuf)>,
    peeked: Option<(Token, At)>,
    /// The scene file's folder, canonical: includes stay within it.
    root: PathBuf,
    /// The scene file's folder as given: every relative name is found
    /// from it, as pbrt finds them.
    dir: PathBuf,
    options: Options,
}

/// What is wrong: where, what, and a hint.
pub(crate) type Problem = params::Problem;

impl Input {
    /// A failure at `at`.
    fn problem(&self, (at, message, hint): Problem) -> Failure {
        let Some((name, text)) = self.files.get(at.file as usize) else {
            return Diagnostic::plain("", message).into();
        };
        let mut d = Diagnostic::plain(name, message);
        if at.line > 0 {
            let lc = (at.line as usize, at.col as usize);
            d.line_col = Some(lc);
            d.excerpt = Some(excerpt(text, lc, None));
        }
        d.hint = hint;
        d.into()
    }

    /// `file:line:col` of `at`, for warnings.
    pub fn place(&self, at: At) -> String {
        let name = self
            .files
            .get(at.file as usize)
            .map_or("", |(n, _)| n.as_str());
        format!("{name}:{}:{}", at.line, at.col)
    }

    /// The file `name` as written in the scene: its path from the scene's
    /// folder, checked to be there.
    pub fn file(&self, name: &str, at: At) -> Result<String, Problem> {
        let path = self.dir.join(name);
        if path.is_file() {
            Ok(name.to_string())
        } else {
            Err((
                at,
                format!("file `{name}` not found (looked for {})", path.display()),
                None,
            ))
        }
    }

    /// The wavelength–value pairs of spectrum file `name` (written at
    /// `at`): numbers separated by white space, `#` starting a comment,
    /// as pbrt reads them.
    fn spectrum_file(&self, name: &str, at: At) -> Result<Vec<f64>, Problem> {
        let path = self.dir.join(name);
        let fail = |message: String| (at, message, None);
        let canon = canonical(&path).unwrap_or_else(|| path.clone());
        self.within_folder(&canon, name).map_err(fail)?;
        let text = read_text(&path, name).map_err(fail)?;
        let mut numbers = Vec::new();
        for (line, content) in text.lines().enumerate() {
            let content = content.split('#').next().unwrap_or("");
            for word in content.split_whitespace() {
                let x: f64 = word
                    .parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite())
                    .ok_or_else(|| {
                        fail(format!(
                            "{name}:{}: `{word}` is not a finite number",
                            line + 1
                        ))
                    })?;
                numbers.push(x);
            }
        }
        if numbers.len() < 4 || numbers.len() % 2 != 0 {
            return Err(fail(format!(
                "{name}: a spectrum file holds pairs of a wavelength and a value, at least two; it holds {} numbers",
                numbers.len()
            )));
        }
        if numbers
            .chunks_exact(2)
            .zip(numbers.chunks_exact(2).skip(1))
            .any(|(a, b)| b[0] <= a[0])
        {
            return Err(fail(format!("{name}: its wavelengths must increase")));
        }
        Ok(numbers)
    }

    /// Refuses file `name` (canonical path `canon`) outside the scene's
    /// folder unless `--allow-outside` was given.
    fn within_folder(&self, canon: &Path, name: &str) -> Result<(), String> {
        if self.options.allow_outside || canon.starts_with(&self.root) {
            return Ok(());
        }
        Err(format!(
            "{name}: lies outside the scene's folder ({}); --allow-outside reads it",
            self.root.display()
        ))
    }

    /// Opens the file at `path` (included at `from`).
    fn open(&mut self, path: &Path, from: Option<At>) -> Result<(), Problem> {
        let name = path.display().to_string();
        let at = from.unwrap_or(NOWHERE);
        let fail = |message: String| (at, message, None);
        let meta = std::fs::metadata(path).map_err(|e| {
            fail(match e.kind() {
                std::io::ErrorKind::NotFound => format!("{name}: no such file"),
                _ => format!("{name}: cannot read it: {e}"),
            })
        })?;
        if !meta.is_file() {
            return Err(fail(format!("{name}: is not a regular file")));
        }
        let canon = canonical(path).unwrap_or_else(|| path.to_path_buf());
        if from.is_some() {
            if self.open.iter().any(|(_, p)| *p == canon) {
                return Err(fail(format!(
                    "{name}: includes itself (through {} files)",
                    self.open.len()
                )));
            }
            if self.open.len() >= MAX_INCLUDE_DEPTH {
                return Err(fail(format!(
                    "includes nest more than {MAX_INCLUDE_DEPTH} deep"
                )));
            }
            self.within_folder(&canon, &name).map_err(fail)?;
        }
        let text: Arc<str> = read_text(path, &name).map_err(fail)?.into();
        let index = self.files.len() as u32;
        self.files.push((name, Arc::clone(&text)));
        self.open.push((Lexer::new(text, index), canon));
        Ok(())
    }

    /// The next token of the innermost open file, closing files as they
    /// end; `None` at the end of the scene file.
    fn next(&mut self) -> Result<Option<(Token, At)>, Problem> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        loop {
            let Some((lexer, _)) = self.open.last_mut() else {
                return Ok(None);
            };
            match lexer.next_token() {
                Ok(Some((tok, at))) => {
                    let tok = match tok {
                        Tok::Word(w) => Token::Word(w.to_string()),
                        Tok::Str(s) => Token::Str(s.into_owned()),
                        Tok::Num(n) => Token::Num(n),
                        Tok::Open => Token::Open,
                        Tok::Close => Token::Close,
                    };
                    return Ok(Some((tok, at)));
                }
                Ok(None) => {
                    self.open.pop();
                }
                Err((at, message)) => return Err((at, message, None)),
            }
        }
    }

    fn peek(&mut self) -> Result<Option<&(Token, At)>, Problem> {
        if self.peeked.is_none() {
            self.peeked = self.next()?;
        }
        Ok(self.peeked.as_ref())
    }

    /// The next directive's name and place.
    fn directive(&mut self) -> Result<Option<(String, At)>, Problem> {
        match self.next()? {
            None => Ok(None),
            Some((Token::Word(w), at)) => Ok(Some((w, at))),
            Some((t, at)) => Err((
                at,
                format!(
                    "expected a directive (such as Shape or WorldBegin), got {}",
                    t.describe()
                ),
                None,
            )),
        }
    }

    /// Follows `Include`/`Import` of `name` written at `at`.
    pub fn include(&mut self, name: &str, at: At) -> Result<(), Problem> {
        let path = self.dir.join(name);
        self.open(&path, Some(at))
    }

    fn expected(&self, what: &str, got: Option<(Token, At)>, after: At) -> Problem {
        match got {
            Some((t, at)) => (at, format!("expected {what}, got {}", t.describe()), None),
            None => (after, format!("expected {what}, but the file ends"), None),
        }
    }

    /// A positional number of the directive at `at`.
    pub fn num(&mut self, at: At) -> Result<f64, Problem> {
        match self.next()? {
            Some((Token::Num(n), _)) => Ok(n),
            other => Err(self.expected("a number", other, at)),
        }
    }

    /// `N` positional numbers, bracketed or not.
    pub fn nums<const N: usize>(&mut self, at: At) -> Result<[f64; N], Problem> {
        let bracketed = matches!(self.peek()?, Some((Token::Open, _)));
        if bracketed {
            self.next()?;
        }
        let mut v = [0.0; N];
        for x in &mut v {
            *x = self.num(at)?;
        }
        if bracketed {
            match self.next()? {
                Some((Token::Close, _)) => {}
                other => return Err(self.expected(&format!("`]` after {N} numbers"), other, at)),
            }
        }
        Ok(v)
    }

    /// A positional string of the directive at `at`.
    pub fn string(&mut self, at: At) -> Result<(String, At), Problem> {
        match self.next()? {
            Some((Token::Str(s), sat)) => Ok((s, sat)),
            other => Err(self.expected("a quoted string", other, at)),
        }
    }

    /// A positional word (`ActiveTransform All`) of the directive at `at`.
    pub fn word(&mut self, at: At) -> Result<(String, At), Problem> {
        match self.next()? {
            Some((Token::Word(s), wat)) => Ok((s, wat)),
            other => Err(self.expected("a word", other, at)),
        }
    }

    /// Whether a quoted string comes next (a second positional string).
    pub fn string_follows(&mut self) -> Result<bool, Problem> {
        let p = self.peek()?;
        Ok(matches!(p, Some((Token::Str(s), _)) if !s.contains(char::is_whitespace)))
    }

    /// The parameter list that follows.
    pub fn params(&mut self, _at: At) -> Result<Params, Problem> {
        let mut params = Params::default();
        loop {
            let decl = match self.peek()? {
                Some((Token::Str(_), _)) => self.next()?,
                _ => return Ok(params),
            };
            let Some((Token::Str(decl), dat)) = decl else {
                unreachable!("peeked a string")
            };
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err((
                    dat,
                    format!("expected a parameter declared as \"type name\" (such as \"float radius\"), got \"{decl}\""),
                    None,
                ));
            };
            let mut values = self.values(ty, name, dat)?;
            // A spectrum named by a file of its samples (pbrt's `.spd`),
            // where no spectrum of pbrt's has that name.
            if let ("spectrum", params::Values::Strs(v)) = (ty, &values) {
                if let [file] = v.as_slice() {
                    if !spectra::is_named(file) && self.dir.join(file).is_file() {
                        values = params::Values::Nums(self.spectrum_file(file, dat)?);
                    }
                }
            }
            if params.list.iter().any(|p: &Param| p.name == name) {
                return Err((dat, format!("`{name}` is given twice"), None));
            }
            params
                .list
                .push(Param::new(ty.to_string(), name.to_string(), values, dat));
        }
    }

    /// A parameter's value or bracketed values, read as they come (a
    /// mesh's millions of numbers are not held as tokens).
    fn values(&mut self, ty: &str, name: &str, at: At) -> Result<Values, Problem> {
        let bracketed = match self.next()? {
            Some((Token::Open, _)) => true,
            Some(t @ (Token::Num(_) | Token::Str(_) | Token::Word(_), _)) => {
                self.peeked = Some(t);
                false
            }
            other => return Err(self.expected(&format!("a value for `{name}`"), other, at)),
        };
        let mut values: Option<Values> = None;
        loop {
            let (t, tat) = match self.next()? {
                Some((Token::Close, _)) if bracketed => break,
                Some(t @ (Token::Num(_) | Token::Str(_) | Token::Word(_), _)) => t,
                other => {
                    return Err(self.expected(&format!("a value of `{name}` or `]`"), other, at))
                }
            };
            let boolean = match &t {
                Token::Word(w) | Token::Str(w) if ty == "bool" && w == "true" => Some(true),
                Token::Word(w) | Token::Str(w) if ty == "bool" && w == "false" => Some(false),
                _ => None,
            };
            let values = values.get_or_insert_with(|| match (&t, boolean) {
                (_, Some(_)) => Values::Bools(Vec::new()),
                (Token::Num(_), _) => Values::Nums(Vec::new()),
                _ => Values::Strs(Vec::new()),
            });
            match (values, t, boolean) {
                (Values::Bools(v), _, Some(b)) => v.push(b),
                (Values::Nums(v), Token::Num(n), None) => v.push(n),
                (Values::Strs(v), Token::Str(s), None) if ty != "bool" => v.push(s),
                (_, t, _) if ty == "bool" => {
                    return Err((
                        tat,
                        format!("`{name}` takes true or false, got {}", t.describe()),
                        None,
                    ))
                }
                (_, t, _) => {
                    return Err((
                        tat,
                        format!("`{name}` mixes values of different kinds: {}", t.describe()),
                        None,
                    ))
                }
            }
            if !bracketed {
                break;
            }
        }
        Ok(values.unwrap_or(Values::Nums(Vec::new())))
    }
}

/// The text of the file at `path` (`name` in messages), at most a scene
/// file's size.
fn read_text(path: &Path, name: &str) -> Result<String, String> {
    let bytes = crate::input::read(path, crate::input::MAX_SCENE_BYTES)
        .map_err(|e| format!("{name}: {e}"))?;
    String::from_utf8(bytes).map_err(|_| format!("{name}: is not UTF-8 text"))
}
