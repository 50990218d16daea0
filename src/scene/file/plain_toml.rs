//! The quickest way through `[[objects]]` tables written plainly, as
//! programs and most people write them: one `key = value` a line, values
//! on one line. Such a table is the same data as a JSON object, so it is
//! rewritten as one and read by `serde_json`, many times faster than the
//! `toml` crate, which builds a document of every key and value first.
//!
//! Only the part of TOML whose meaning JSON shares is rewritten: bare keys,
//! strings without escapes, decimal numbers, booleans, one-line arrays and
//! inline tables. Anything else (a dotted key, an escape, `1_000`, `inf`, a
//! date, a sub-table, an array over several lines, a comment inside a
//! value, a repeated key) makes [`objects_as_json`] give up, and the
//! `toml` crate reads the tables instead.

/// Appends the `[[objects]]` table `table` (header line included) to `out`
/// as a JSON object; `None`, with `out` in an unspecified state, when the
/// table is not written plainly.
pub(super) fn objects_as_json(table: &str, out: &mut String) -> Option<()> {
    let mut lines = table.lines();
    let header = lines.next()?.trim();
    let after = header.strip_prefix("[[objects]]")?.trim_start();
    if !(after.is_empty() || after.starts_with('#')) {
        return None;
    }
    out.push('{');
    let mut keys: Vec<&str> = Vec::new();
    for line in lines {
        let line = line.trim_matches([' ', '\t', '\r']);
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut c = Cursor { s: line, i: 0 };
        c.entry(&mut keys, out, 0)?;
        c.ws();
        if !(c.done() || c.peek() == Some(b'#')) {
            return None;
        }
    }
    out.push('}');
    Some(())
}

/// Deepest nesting of arrays and inline tables rewritten (a matrix is 2).
const MAX_NESTING: usize = 8;

struct Cursor<'a> {
    s: &'a str,
    i: usize,
}

impl<'a> Cursor<'a> {
    fn peek(&self) -> Option<u8> {
        self.s.as_bytes().get(self.i).copied()
    }

    fn done(&self) -> bool {
        self.i >= self.s.len()
    }

    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.i += 1;
        }
    }

    fn expect(&mut self, b: u8) -> Option<()> {
        self.ws();
        (self.peek()? == b).then(|| self.i += 1)
    }

    /// A bare key: letters, digits, `_` and `-`, also valid in a JSON string.
    /// One `key = value` entry of a table whose keys so far are `keys`,
    /// written as a JSON member (after a comma unless it is the first).
    fn entry(&mut self, keys: &mut Vec<&'a str>, out: &mut String, depth: usize) -> Option<()> {
        let key = self.key()?;
        // A repeated key is an error in TOML; serde would say so too, but
        // not for every type: refused here, the `toml` crate words it.
        if keys.contains(&key) {
            return None;
        }
        if !keys.is_empty() {
            out.push(',');
        }
        keys.push(key);
        self.expect(b'=')?;
        out.push('"');
        out.push_str(key);
        out.push_str("\":");
        self.value(out, depth)
    }

    fn key(&mut self) -> Option<&'a str> {
        self.ws();
        let start = self.i;
        while matches!(
            self.peek(),
            Some(b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'_' | b'-')
        ) {
            self.i += 1;
        }
        (self.i > start).then(|| &self.s[start..self.i])
    }

    fn value(&mut self, out: &mut String, depth: usize) -> Option<()> {
        if depth > MAX_NESTING {
            return None;
        }
        self.ws();
        match self.peek()? {
            b'"' => self.string(b'"', out),
            b'\'' => self.string(b'\'', out),
            b'[' => {
                self.i += 1;
                out.push('[');
                let mut first = true;
                loop {
                    self.ws();
                    if self.peek()? == b']' {
                        self.i += 1;
                        break;
                    }
                    if !first {
                        out.push(',');
                    }
                    first = false;
                    self.value(out, depth + 1)?;
                    self.ws();
                    match self.peek()? {
                        // TOML allows a comma after the last element.
                        b',' => self.i += 1,
                        b']' => {}
                        _ => return None,
                    }
                }
                out.push(']');
                Some(())
            }
            b'{' => {
                self.i += 1;
                out.push('{');
                self.ws();
                if self.peek()? == b'}' {
                    self.i += 1;
                    out.push('}');
                    return Some(());
                }
                let mut keys: Vec<&str> = Vec::new();
                loop {
                    self.entry(&mut keys, out, depth + 1)?;
                    self.ws();
                    match self.peek()? {
                        // No comma after the last entry of an inline table.
                        b',' => self.i += 1,
                        b'}' => {
                            self.i += 1;
                            break;
                        }
                        _ => return None,
                    }
                }
                out.push('}');
                Some(())
            }
            b't' | b'f' => {
                let word = ["true", "false"]
                    .into_iter()
                    .find(|w| self.s[self.i..].starts_with(w))?;
                self.i += word.len();
                out.push_str(word);
                self.ends_value()
            }
            _ => self.number(out),
        }
    }

    /// After a bare value: a delimiter must follow (`truex` is no boolean).
    fn ends_value(&self) -> Option<()> {
        match self.peek() {
            None | Some(b' ' | b'\t' | b',' | b']' | b'}' | b'#') => Some(()),
            _ => None,
        }
    }

    /// A string without escapes or control characters: the same text in
    /// both languages (a literal string is re-quoted).
    fn string(&mut self, quote: u8, out: &mut String) -> Option<()> {
        let start = self.i + 1;
        let len = self.s[start..].find(quote as char)?;
        let body = &self.s[start..start + len];
        if body
            .bytes()
            .any(|b| b == b'\\' || b == b'"' || b < 0x20 || b == 0x7f)
        {
            return None;
        }
        // `"""` or `'''` opens a multi-line string.
        if len == 0 && self.s.as_bytes().get(start + 1) == Some(&quote) {
            return None;
        }
        self.i = start + len + 1;
        out.push('"');
        out.push_str(body);
        out.push('"');
        Some(())
    }

    /// A decimal number as TOML and JSON both write it:
    /// `-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?`, an integer within
    /// the 64-bit range TOML allows.
    fn number(&mut self, out: &mut String) -> Option<()> {
        let b = self.s.as_bytes();
        let start = self.i;
        let mut i = start;
        let digits = |i: &mut usize| {
            let from = *i;
            while b.get(*i).is_some_and(u8::is_ascii_digit) {
                *i += 1;
            }
            *i - from
        };
        if b.get(i) == Some(&b'-') {
            i += 1;
        }
        let int_start = i;
        let n = digits(&mut i);
        if n == 0 || (n > 1 && b[int_start] == b'0') {
            return None;
        }
        let mut integer = true;
        if b.get(i) == Some(&b'.') {
            i += 1;
            if digits(&mut i) == 0 {
                return None;
            }
            integer = false;
        }
        if matches!(b.get(i), Some(b'e' | b'E')) {
            i += 1;
            if matches!(b.get(i), Some(b'+' | b'-')) {
                i += 1;
            }
            if digits(&mut i) == 0 {
                return None;
            }
            integer = false;
        }
        let token = &self.s[start..i];
        // TOML's `-0` is the integer 0; serde_json reads it as the float
        // -0.0, which would be written back with its sign.
        if integer && (token == "-0" || token.parse::<i64>().is_err()) {
            return None;
        }
        self.i = i;
        out.push_str(token);
        self.ends_value()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn json(table: &str) -> Option<String> {
        let mut out = String::new();
        objects_as_json(table, &mut out).map(|()| out)
    }

    #[test]
    fn plain_tables_become_json_objects() {
        assert_eq!(
            json("[[objects]] # a ball\ntype = \"sphere\"  # kind\n\n  center = [0, -1.5e3, 2.25,]\nm = 'x y'\nt = [{ scale = 2 }, {a={}}]\nb = false\n")
                .as_deref(),
            Some(r#"{"type":"sphere","center":[0,-1.5e3,2.25],"m":"x y","t":[{"scale":2},{"a":{}}],"b":false}"#)
        );
        assert_eq!(json("[[objects]]\n").as_deref(), Some("{}"));
    }

    #[test]
    fn anything_else_is_left_to_the_toml_crate() {
        for table in [
            "[[objects]]\na.b = 1\n",
            "[[objects]]\n\"a\" = 1\n",
            "[[objects]]\na = 1\na = 2\n",
            "[[objects]]\na = \"x\\ty\"\n",
            "[[objects]]\na = \"\"\"x\"\"\"\n",
            "[[objects]]\na = 1_000\n",
            "[[objects]]\na = +1\n",
            "[[objects]]\na = 01\n",
            "[[objects]]\na = -0\n",
            "[[objects]]\na = 1.\n",
            "[[objects]]\na = .5\n",
            "[[objects]]\na = 1e\n",
            "[[objects]]\na = inf\n",
            "[[objects]]\na = nan\n",
            "[[objects]]\na = 0x10\n",
            "[[objects]]\na = 9223372036854775808\n",
            "[[objects]]\na = 1979-05-27\n",
            "[[objects]]\na = [\n1]\n",
            "[[objects]]\na = { b = 1, }\n",
            "[[objects]]\na = { b = 1, b = 2 }\n",
            "[[objects]]\na = truex\n",
            "[[objects]]\na = 1 2\n",
            "[[objects]]\n[objects.b]\n",
            "[[objects]]\na = [[[[[[[[[[1]]]]]]]]]]\n",
            "[[objects.x]]\n",
            "[[objects]] x\n",
        ] {
            assert_eq!(json(table), None, "{table:?}");
        }
    }
}
