//! pbrt-v4's tokens: words (directives, `true`, `false`), quoted strings,
//! numbers and square brackets, with `#` comments to the end of a line.
//! Each token knows the file, line and column it was written at.

use std::borrow::Cow;
use std::sync::Arc;

/// Where a token was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct At {
    /// The file, an index into the reader's list of files.
    pub file: u32,
    /// 1-based line.
    pub line: u32,
    /// 1-based column, in characters.
    pub col: u32,
}

/// A token.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok<'t> {
    /// A bare word: a directive, `true` or `false`.
    Word(&'t str),
    /// A quoted string, without its quotes, escapes resolved.
    Str(Cow<'t, str>),
    /// A number.
    Num(f64),
    /// `[`.
    Open,
    /// `]`.
    Close,
}

/// The tokens of one file's text.
pub struct Lexer {
    text: Arc<str>,
    pos: usize,
    line: u32,
    /// A byte offset on the current line and its column (0-based), so
    /// that columns are counted once however long the line.
    mark: (usize, usize),
    file: u32,
}

impl Lexer {
    /// The tokens of `text`, file number `file`.
    pub fn new(text: Arc<str>, file: u32) -> Lexer {
        Lexer {
            text,
            pos: 0,
            line: 1,
            mark: (0, 0),
            file,
        }
    }

    /// Where byte `pos` of the current line is.
    fn at(text: &str, mark: &mut (usize, usize), line: u32, file: u32, pos: usize) -> At {
        let (from, col) = *mark;
        let col = col + text[from..pos].chars().count();
        *mark = (pos, col);
        At {
            file,
            line,
            col: (col + 1).min(u32::MAX as usize) as u32,
        }
    }

    /// The next token and where it is, `None` at the end of the text;
    /// `Err` names what cannot be read and where.
    pub fn next_token(&mut self) -> Result<Option<(Tok<'_>, At)>, (At, String)> {
        let bytes = self.text.as_bytes();
        // Blanks and comments.
        loop {
            match bytes.get(self.pos) {
                Some(b'\n') => {
                    self.pos += 1;
                    self.line += 1;
                    self.mark = (self.pos, 0);
                }
                Some(b' ' | b'\t' | b'\r') => self.pos += 1,
                Some(b'#') => {
                    while bytes.get(self.pos).is_some_and(|&b| b != b'\n') {
                        self.pos += 1;
                    }
                }
                _ => break,
            }
        }
        let start = self.pos;
        let Some(&first) = bytes.get(start) else {
            return Ok(None);
        };
        let at = Self::at(&self.text, &mut self.mark, self.line, self.file, start);
        match first {
            b'[' => {
                self.pos += 1;
                Ok(Some((Tok::Open, at)))
            }
            b']' => {
                self.pos += 1;
                Ok(Some((Tok::Close, at)))
            }
            b'"' => {
                let mut end = start + 1;
                let mut escaped = false;
                loop {
                    match bytes.get(end) {
                        None | Some(b'\n') => {
                            return Err((
                                at,
                                "this string is not closed on its line: a `\"` is missing".into(),
                            ))
                        }
                        Some(b'"') => break,
                        Some(b'\\') => {
                            escaped = true;
                            end += 2;
                        }
                        Some(_) => end += 1,
                    }
                }
                self.pos = end + 1;
                let raw = &self.text[start + 1..end];
                let s = if escaped {
                    Cow::Owned(unescape(raw).map_err(|m| (at, m))?)
                } else {
                    Cow::Borrowed(raw)
                };
                Ok(Some((Tok::Str(s), at)))
            }
            _ => {
                let mut end = start;
                while bytes.get(end).is_some_and(|b| {
                    !matches!(b, b' ' | b'\t' | b'\r' | b'\n' | b'[' | b']' | b'"' | b'#')
                }) {
                    end += 1;
                }
                self.pos = end;
                let word = &self.text[start..end];
                if matches!(first, b'0'..=b'9' | b'-' | b'+' | b'.') {
                    match word.parse::<f64>() {
                        Ok(n) if n.is_finite() => Ok(Some((Tok::Num(n), at))),
                        Ok(_) => Err((at, format!("`{word}` is not a finite number"))),
                        Err(_) => Err((at, format!("`{word}` is not a number"))),
                    }
                } else if first.is_ascii_alphabetic() {
                    Ok(Some((Tok::Word(word), at)))
                } else {
                    Err((at, format!("unexpected `{word}`: expected a directive, a quoted string, a number or a bracket")))
                }
            }
        }
    }
}

/// `raw` with its backslash escapes resolved.
fn unescape(raw: &str) -> Result<String, String> {
    let mut out = String::with_capacity(raw.len());
    let mut chars = raw.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        out.push(match chars.next() {
            Some('n') => '\n',
            Some('t') => '\t',
            Some('r') => '\r',
            Some('b') => '\u{8}',
            Some('f') => '\u{c}',
            Some('\\') => '\\',
            Some('\'') => '\'',
            Some('"') => '"',
            other => {
                return Err(format!(
                    "unknown escape `\\{}` in a string",
                    other.map(String::from).unwrap_or_default()
                ))
            }
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    type Tokens = Vec<(Tok<'static>, u32, u32)>;

    fn tokens(text: &str) -> Result<Tokens, (At, String)> {
        let mut lexer = Lexer::new(Arc::from(text), 0);
        let mut out = Vec::new();
        while let Some((t, at)) = lexer.next_token()? {
            let t = match t {
                Tok::Word(w) => Tok::Str(Cow::Owned(format!("word:{w}"))),
                Tok::Str(s) => Tok::Str(Cow::Owned(s.into_owned())),
                Tok::Num(n) => Tok::Num(n),
                Tok::Open => Tok::Open,
                Tok::Close => Tok::Close,
            };
            out.push((t, at.line, at.col));
        }
        Ok(out)
    }

    #[test]
    fn tokens_are_read_with_their_places() {
        let t = tokens("Shape \"sphere\" # a ball\n  \"float radius\" [ -2.5e1 ]\n\"a\\\"b\" true")
            .unwrap();
        let s = |x: &str| Tok::Str(Cow::Owned(x.to_string()));
        assert_eq!(
            t,
            vec![
                (s("word:Shape"), 1, 1),
                (s("sphere"), 1, 7),
                (s("float radius"), 2, 3),
                (Tok::Open, 2, 18),
                (Tok::Num(-25.0), 2, 20),
                (Tok::Close, 2, 27),
                (s("a\"b"), 3, 1),
                (s("word:true"), 3, 8),
            ]
        );
    }

    #[test]
    fn what_is_no_token_is_refused_where_it_is() {
        for (text, line, col, says) in [
            ("Shape \"sphere", 1, 7, "not closed"),
            ("Translate 1 2x 3", 1, 13, "`2x` is not a number"),
            ("Scale 1e999 1 1", 1, 7, "not a finite number"),
            ("\n  @", 2, 3, "unexpected `@`"),
            ("\"a\\q\"", 1, 1, "unknown escape"),
        ] {
            let (at, message) = tokens(text).unwrap_err();
            assert_eq!((at.line, at.col), (line, col), "{text}: {message}");
            assert!(message.contains(says), "{text}: {message}");
        }
    }
}
