//! The text of a scene file read into a tree of values that remember where
//! they were written, so that every later complaint can name a line and column.
//!
//! TOML is parsed by `toml_edit`, which keeps spans. JSON is checked and
//! unescaped by `serde_json` (whose syntax errors carry line and column), and
//! a small scanner walks the already-validated text to record where each
//! value sits, since `serde_json` keeps no positions.

use std::ops::Range;

/// A value of a scene file and where it was written (byte range).
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Bytes of the source this value spans (for a TOML table: its header).
    pub span: Range<usize>,
    /// The value.
    pub value: Value,
}

/// A key of a table, its position, and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// The key.
    pub key: String,
    /// Where the key was written.
    pub key_span: Range<usize>,
    /// Its value.
    pub node: Node,
}

/// The kinds of value a scene file can hold.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A table (TOML table or inline table, JSON object), in file order.
    Table(Vec<Entry>),
    /// An array.
    Array(Vec<Node>),
    /// A string.
    String(String),
    /// An integer (wide enough for every `u64` and `i64`).
    Integer(i128),
    /// A floating-point number (may be non-finite: TOML has `nan` and `inf`).
    Float(f64),
    /// A boolean.
    Bool(bool),
    /// Anything else the format allows but scenes never use (a TOML date,
    /// JSON `null`), by the name used in messages.
    Other(&'static str),
}

impl Value {
    /// How the value is called in "expected …, got …" messages.
    pub fn describe(&self) -> String {
        match self {
            Value::Table(_) => "a table".into(),
            Value::Array(a) => format!("an array of {} values", a.len()),
            Value::String(s) => format!("the string {s:?}"),
            Value::Integer(i) => format!("the integer {i}"),
            Value::Float(f) => format!("the number {f}"),
            Value::Bool(b) => format!("the boolean {b}"),
            Value::Other(what) => (*what).into(),
        }
    }
}

/// A syntax error: what the parser said and where.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntaxError {
    /// Byte offset, when the parser knows it.
    pub offset: Option<usize>,
    /// 1-based line and column, when the parser knows them.
    pub line_col: Option<(usize, usize)>,
    /// The parser's message.
    pub message: String,
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

/// Parses TOML text into a [`Node`] tree.
pub fn parse_toml(text: &str) -> Result<Node, SyntaxError> {
    let doc = toml_edit::ImDocument::parse(text).map_err(|e| {
        let offset = e.span().map(|s| s.start);
        SyntaxError {
            offset,
            line_col: offset.map(|o| line_col(text, o)),
            message: e.message().trim().to_string(),
        }
    })?;
    Ok(toml_table(doc.as_table(), 0..0))
}

fn toml_item(item: &toml_edit::Item, fallback: Range<usize>) -> Node {
    use toml_edit::Item;
    match item {
        Item::Value(v) => toml_value(v, fallback),
        Item::Table(t) => toml_table(t, fallback),
        Item::ArrayOfTables(a) => {
            let items: Vec<Node> = a.iter().map(|t| toml_table(t, fallback.clone())).collect();
            let span = a
                .span()
                .or_else(|| items.first().map(|n| n.span.clone()))
                .unwrap_or(fallback);
            Node {
                span,
                value: Value::Array(items),
            }
        }
        Item::None => Node {
            span: fallback,
            value: Value::Other("nothing"),
        },
    }
}

/// A table's span is its header; implicit tables (`materials` in
/// `[materials.glass]`) and dotted keys have none, so they borrow the span of
/// their key, passed in as `fallback`.
fn toml_table(table: &toml_edit::Table, fallback: Range<usize>) -> Node {
    Node {
        value: Value::Table(toml_entries(table, &fallback)),
        span: table.span().unwrap_or(fallback),
    }
}

/// The entries of a table or inline table; a key without a span of its own
/// borrows its value's, else `fallback`.
fn toml_entries(table: &dyn toml_edit::TableLike, fallback: &Range<usize>) -> Vec<Entry> {
    table
        .iter()
        .map(|(key, item)| {
            let key_span = table
                .key(key)
                .and_then(|k| k.span())
                .or_else(|| item.span())
                .unwrap_or_else(|| fallback.clone());
            Entry {
                key: key.to_string(),
                key_span: key_span.clone(),
                node: toml_item(item, key_span),
            }
        })
        .collect()
}

fn toml_value(value: &toml_edit::Value, fallback: Range<usize>) -> Node {
    use toml_edit::Value as V;
    let span = value.span().unwrap_or_else(|| fallback.clone());
    let value = match value {
        V::String(s) => Value::String(s.value().clone()),
        V::Integer(i) => Value::Integer(i128::from(*i.value())),
        V::Float(f) => Value::Float(*f.value()),
        V::Boolean(b) => Value::Bool(*b.value()),
        V::Datetime(_) => Value::Other("a date-time"),
        V::Array(a) => Value::Array(a.iter().map(|v| toml_value(v, span.clone())).collect()),
        V::InlineTable(t) => Value::Table(toml_entries(t, &span)),
    };
    Node { span, value }
}

/// Parses JSON text into a [`Node`] tree.
pub fn parse_json(text: &str) -> Result<Node, SyntaxError> {
    // The nesting depth is bounded first (`too_deep`: serde_json skipping
    // with `IgnoredAny` does not bound it, and the scanner below recurses
    // once per level), then serde_json validates the syntax, so the scanner
    // only ever sees well-formed JSON. (`IgnoredAny` accepts numbers too
    // large for f64, which the decoder then refuses with the field's path.)
    if let Some(offset) = too_deep(text) {
        return Err(SyntaxError {
            offset: Some(offset),
            line_col: Some(line_col(text, offset)),
            message: format!("arrays and objects nested more than {MAX_DEPTH} deep"),
        });
    }
    if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(text) {
        let full = e.to_string();
        let message = full
            .rfind(" at line ")
            .map_or(full.as_str(), |i| &full[..i])
            .to_string();
        let line_col = (e.line() > 0).then(|| (e.line(), e.column().max(1)));
        return Err(SyntaxError {
            offset: None,
            line_col,
            message,
        });
    }
    let mut scanner = Scanner { text, pos: 0 };
    scanner.skip_ws();
    let node = scanner.value();
    node.ok_or_else(|| SyntaxError {
        offset: Some(scanner.pos),
        line_col: Some(line_col(text, scanner.pos)),
        message: "unexpected JSON syntax".into(),
    })
}

/// The offset of the first bracket nested deeper than [`MAX_DEPTH`], if any.
fn too_deep(text: &str) -> Option<usize> {
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    for (i, b) in text.bytes().enumerate() {
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
                if depth > MAX_DEPTH {
                    return Some(i);
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

/// Walks valid JSON recording byte spans. Returns `None` rather than panic on
/// anything unexpected. Its recursion is bounded by [`too_deep`], checked
/// first: one level per array or object.
struct Scanner<'a> {
    text: &'a str,
    pos: usize,
}

/// Deepest nesting of JSON arrays and objects accepted: far more than any
/// scene needs, far less than would overflow the stack.
pub(super) const MAX_DEPTH: usize = 64;

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.pos += 1;
        }
    }

    /// Skips whitespace, then `byte` if it comes next.
    fn eat(&mut self, byte: u8) -> bool {
        self.skip_ws();
        let next = self.peek() == Some(byte);
        self.pos += usize::from(next);
        next
    }

    /// After an item of a list closed by `close`: past a comma, `false`;
    /// past `close`, `true`; anything else, `None`.
    fn comma_or(&mut self, close: u8) -> Option<bool> {
        self.skip_ws();
        let next = self.peek()?;
        if next != b',' && next != close {
            return None;
        }
        self.pos += 1;
        Some(next == close)
    }

    fn value(&mut self) -> Option<Node> {
        self.skip_ws();
        let start = self.pos;
        let value = match self.peek()? {
            b'{' => {
                self.pos += 1;
                let mut entries = Vec::new();
                if !self.eat(b'}') {
                    loop {
                        self.skip_ws();
                        let key_start = self.pos;
                        let key = self.string()?;
                        let key_span = key_start..self.pos;
                        self.eat(b':').then_some(())?;
                        let node = self.value()?;
                        entries.push(Entry {
                            key,
                            key_span,
                            node,
                        });
                        if self.comma_or(b'}')? {
                            break;
                        }
                    }
                }
                Value::Table(entries)
            }
            b'[' => {
                self.pos += 1;
                let mut items = Vec::new();
                if !self.eat(b']') {
                    loop {
                        items.push(self.value()?);
                        if self.comma_or(b']')? {
                            break;
                        }
                    }
                }
                Value::Array(items)
            }
            b'"' => Value::String(self.string()?),
            b't' => self.word("true", Value::Bool(true))?,
            b'f' => self.word("false", Value::Bool(false))?,
            b'n' => self.word("null", Value::Other("null"))?,
            _ => self.number()?,
        };
        Some(Node {
            span: start..self.pos,
            value,
        })
    }

    fn word(&mut self, word: &str, value: Value) -> Option<Value> {
        self.text.get(self.pos..)?.starts_with(word).then(|| {
            self.pos += word.len();
            value
        })
    }

    fn string(&mut self) -> Option<String> {
        let start = self.pos;
        if self.peek()? != b'"' {
            return None;
        }
        self.pos += 1;
        loop {
            match self.peek()? {
                b'\\' => self.pos += 2,
                b'"' => break,
                _ => self.pos += 1,
            }
        }
        self.pos += 1;
        serde_json::from_str(self.text.get(start..self.pos)?).ok()
    }

    fn number(&mut self) -> Option<Value> {
        let start = self.pos;
        while matches!(
            self.peek(),
            Some(b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9')
        ) {
            self.pos += 1;
        }
        let token = self.text.get(start..self.pos)?;
        if token.is_empty() {
            return None;
        }
        if let Ok(i) = token.parse::<i128>() {
            return Some(Value::Integer(i));
        }
        // Rust parses numbers too large for f64 as infinity, which the
        // decoder then refuses as non-finite.
        token.parse::<f64>().ok().map(Value::Float)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(node: &Node) -> &[Entry] {
        match &node.value {
            Value::Table(t) => t,
            other => panic!("not a table: {other:?}"),
        }
    }

    #[test]
    fn line_col_counts_characters() {
        let text = "ab\nçd\n";
        assert_eq!(line_col(text, 0), (1, 1));
        assert_eq!(line_col(text, 3), (2, 1));
        assert_eq!(line_col(text, 5), (2, 2), "ç is one column");
        assert_eq!(line_col(text, 100), (3, 1));
    }

    /// The tree without positions, to compare TOML and JSON readings.
    fn strip(n: &Node) -> Node {
        let value = match &n.value {
            Value::Table(t) => Value::Table(
                t.iter()
                    .map(|e| Entry {
                        key: e.key.clone(),
                        key_span: 0..0,
                        node: strip(&e.node),
                    })
                    .collect(),
            ),
            Value::Array(a) => Value::Array(a.iter().map(strip).collect()),
            v => v.clone(),
        };
        Node { span: 0..0, value }
    }

    #[test]
    fn toml_and_json_give_the_same_tree() {
        let t = parse_toml("a = 1\n[b]\nc = [1.5, \"x\", {d = true}]\n").unwrap();
        let j = parse_json("{\"a\": 1, \"b\": {\"c\": [1.5, \"x\", {\"d\": true}]}}").unwrap();
        assert_eq!(strip(&t), strip(&j));
    }

    #[test]
    fn spans_point_at_the_values() {
        let text = "[render]\nwidth = 64\n";
        let root = parse_toml(text).unwrap();
        let render = &table(&root)[0];
        let width = &table(&render.node)[0];
        assert_eq!(&text[width.key_span.clone()], "width");
        assert_eq!(&text[width.node.span.clone()], "64");
        let json = "{ \"w\" : [ 1 , \"a\\\"b\" ] }";
        let root = parse_json(json).unwrap();
        let w = &table(&root)[0];
        assert_eq!(&json[w.key_span.clone()], "\"w\"");
        let Value::Array(items) = &w.node.value else {
            panic!()
        };
        assert_eq!(&json[items[1].span.clone()], "\"a\\\"b\"");
        assert_eq!(items[1].value, Value::String("a\"b".into()));
    }

    #[test]
    fn syntax_errors_have_positions() {
        let e = parse_toml("a = 1\nb = = 2\n").unwrap_err();
        assert_eq!(e.line_col.map(|p| p.0), Some(2));
        let e = parse_json("{\n \"a\": }").unwrap_err();
        assert_eq!(e.line_col.map(|p| p.0), Some(2));
        assert!(!e.message.contains("at line"), "{}", e.message);
    }

    #[test]
    fn json_nesting_is_limited_to_max_depth_arrays_and_objects() {
        let nest = |depth: usize, inner: &str| {
            format!("{}{inner}{}", "[".repeat(depth), "]".repeat(depth))
        };
        for inner in ["", "1", "\"x\"", "{}", "true"] {
            let depth = MAX_DEPTH - usize::from(inner == "{}");
            assert!(
                parse_json(&nest(depth, inner)).is_ok(),
                "{depth} around {inner:?}"
            );
            let e = parse_json(&nest(depth + 1, inner)).unwrap_err();
            assert!(
                e.message.contains("nested more than 64 deep"),
                "{}",
                e.message
            );
            assert_eq!(e.offset, Some(MAX_DEPTH), "the first bracket too deep");
        }
    }

    #[test]
    fn huge_json_numbers_become_infinite() {
        let root = parse_json("{\"r\": 1e999}").unwrap();
        assert_eq!(table(&root)[0].node.value, Value::Float(f64::INFINITY));
    }
}
