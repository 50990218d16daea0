//! A serde deserializer over the positioned values of a scene file, so that
//! a kind whose fields are declared once, as a serde struct, is read with
//! the same precise messages as the hand-written decoder gives: every
//! complaint carries the field's path and where it was written.
//!
//! Numbers must be finite (TOML has `nan` and `inf`); a number wanted where
//! the file has something else says "expected a number, got …" in the
//! decoder's words, not serde's.

use super::decode::DecodeError;
use super::hint;
use super::source::{Entry, Node, Value};
use serde::de::{self, DeserializeSeed, IntoDeserializer, Visitor};
use std::fmt;
use std::ops::Range;

/// Why a value could not be read: a [`DecodeError`] once it knows where,
/// or what serde said before it is placed.
#[derive(Debug)]
pub(super) enum Error {
    /// Placed: path, span and message.
    Placed(DecodeError),
    /// A field of a struct that has no such field.
    UnknownField(String, &'static [&'static str]),
    /// A required field left out.
    MissingField(&'static str),
    /// A value of another kind than the one wanted, described by what was
    /// expected (the value itself is described once it is placed).
    Expected(String),
    /// Anything else serde says, not yet placed.
    Message(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Error::Placed(e) => write!(f, "{}: {}", e.path, e.message),
            Error::UnknownField(field, _) => write!(f, "unknown field `{field}`"),
            Error::MissingField(field) => write!(f, "missing field `{field}`"),
            Error::Expected(e) => write!(f, "expected {e}"),
            Error::Message(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {}

impl de::Error for Error {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Error::Message(msg.to_string())
    }

    fn invalid_type(_: de::Unexpected, expected: &dyn de::Expected) -> Self {
        Error::Expected(expected.to_string())
    }

    fn invalid_value(_: de::Unexpected, expected: &dyn de::Expected) -> Self {
        Error::Expected(expected.to_string())
    }

    fn invalid_length(_: usize, expected: &dyn de::Expected) -> Self {
        Error::Expected(expected.to_string())
    }

    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        Error::UnknownField(field.to_string(), expected)
    }

    fn missing_field(field: &'static str) -> Self {
        Error::MissingField(field)
    }

    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        Error::Message(format!(
            "unknown value {variant:?}, expected one of {}",
            hint::listing(variant, expected.iter().copied(), |n| format!("{n:?}"))
        ))
    }
}

impl Error {
    /// The error placed at the value `node`, written at `path`: a value of
    /// the wrong kind is described.
    fn place_at(self, path: &str, node: &Node, what: &str) -> Error {
        match self {
            Error::Expected(e) => placed(
                path,
                &node.span,
                format!("expected {e}, got {}", node.value.describe()),
            ),
            other => other.place(path, &node.span, what),
        }
    }

    /// The error placed at `path` and `span` unless it already is; `what`
    /// names the table being read ("a conductor material") for a missing
    /// field, `hint` suggests a fix for an unknown value.
    fn place(self, path: &str, span: &Range<usize>, what: &str) -> Error {
        let (message, hint) = match self {
            Error::Placed(_) => return self,
            Error::Expected(e) => (format!("expected {e}"), None),
            Error::UnknownField(field, expected) => (
                format!("unknown field `{field}` in {what}"),
                hint::closest(&field, expected.iter().copied())
                    .map(|c| format!("did you mean `{c}`?")),
            ),
            Error::MissingField(field) => {
                return placed(
                    &child(path, field),
                    span,
                    format!("missing field `{field}`: {what} needs it"),
                )
            }
            Error::Message(m) => {
                // "unknown value "x", expected one of "a", "b"": suggest the
                // closest of them.
                let hint = m
                    .strip_prefix("unknown value ")
                    .and_then(|rest| {
                        let (got, options) = rest.split_once(", expected one of ")?;
                        let got = got.trim_matches('"');
                        let options: Vec<&str> =
                            options.split(", ").map(|o| o.trim_matches('"')).collect();
                        hint::closest(got, options.iter().copied())
                    })
                    .map(|c| format!("did you mean {c:?}?"));
                (m, hint)
            }
        };
        Error::Placed(DecodeError {
            path: path.to_string(),
            span: span.clone(),
            message,
            hint,
        })
    }

    /// The placed error (a bare one at `path` and `span`).
    pub(super) fn into_decode(self, path: &str, span: &Range<usize>, what: &str) -> DecodeError {
        match self.place(path, span, what) {
            Error::Placed(e) => e,
            _ => unreachable!("placed"),
        }
    }
}

fn placed(path: &str, span: &Range<usize>, message: String) -> Error {
    Error::Placed(DecodeError {
        path: path.to_string(),
        span: span.clone(),
        message,
        hint: None,
    })
}

fn child(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// A value of the file to deserialize, at `path`; `what` names it in
/// messages; the table's entry `skip` (a kind's `type`) is left out.
pub(super) struct NodeDe<'a> {
    pub(super) node: &'a Node,
    pub(super) path: String,
    pub(super) what: &'a str,
    pub(super) skip: Option<&'a str>,
}

impl<'a> NodeDe<'a> {
    /// The value `node` at `path`.
    pub(super) fn new(node: &'a Node, path: String, what: &'a str) -> Self {
        NodeDe {
            node,
            path,
            what,
            skip: None,
        }
    }

    fn wrong(&self, expected: &str) -> Error {
        placed(
            &self.path,
            &self.node.span,
            format!("expected {expected}, got {}", self.node.value.describe()),
        )
    }

    fn number(&self) -> Result<f64, Error> {
        let v = match self.node.value {
            Value::Float(f) => f,
            Value::Integer(i) => i as f64,
            _ => return Err(self.wrong("a number")),
        };
        if !v.is_finite() {
            return Err(placed(
                &self.path,
                &self.node.span,
                format!("expected a finite number, got {v}"),
            ));
        }
        Ok(v)
    }

    fn integer(&self, min: i128, max: i128) -> Result<i128, Error> {
        match self.node.value {
            Value::Integer(i) if i < min => Err(placed(
                &self.path,
                &self.node.span,
                format!("must be at least {min}, got {i}"),
            )),
            Value::Integer(i) if i > max => Err(placed(
                &self.path,
                &self.node.span,
                format!("must be at most {max}, got {i}"),
            )),
            Value::Integer(i) => Ok(i),
            _ => Err(self.wrong("a whole number")),
        }
    }

    fn entries(&self) -> Option<&'a [Entry]> {
        match &self.node.value {
            Value::Table(entries) => Some(entries),
            _ => None,
        }
    }
}

macro_rules! integers {
    ($($method:ident $visit:ident $t:ty),*) => {$(
        fn $method<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
            let i = self.integer(i128::from(<$t>::MIN), i128::from(<$t>::MAX))?;
            visitor.$visit(i as $t)
        }
    )*};
}

impl<'de, 'a> de::Deserializer<'de> for NodeDe<'a> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match &self.node.value {
            Value::Table(_) => self.deserialize_map(visitor),
            Value::Array(_) => self.deserialize_seq(visitor),
            Value::String(s) => visitor.visit_str(s),
            Value::Integer(i) => match i64::try_from(*i) {
                Ok(i) => visitor.visit_i64(i),
                Err(_) => match u64::try_from(*i) {
                    Ok(u) => visitor.visit_u64(u),
                    Err(_) => Err(self.wrong("a number within 64 bits")),
                },
            },
            Value::Float(_) => visitor.visit_f64(self.number()?),
            Value::Bool(b) => visitor.visit_bool(*b),
            Value::Other(_) => Err(self.wrong("a value a scene file can hold")),
        }
    }

    fn deserialize_bool<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.node.value {
            Value::Bool(b) => visitor.visit_bool(b),
            _ => Err(self.wrong("true or false")),
        }
    }

    integers!(
        deserialize_i8 visit_i8 i8, deserialize_i16 visit_i16 i16, deserialize_i32 visit_i32 i32,
        deserialize_i64 visit_i64 i64, deserialize_u8 visit_u8 u8, deserialize_u16 visit_u16 u16,
        deserialize_u32 visit_u32 u32, deserialize_u64 visit_u64 u64
    );

    fn deserialize_f32<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_f64(self.number()?)
    }

    fn deserialize_f64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_f64(self.number()?)
    }

    fn deserialize_char<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_str(visitor)
    }

    fn deserialize_str<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match &self.node.value {
            Value::String(s) => visitor.visit_str(s),
            _ => Err(self.wrong("a string")),
        }
    }

    fn deserialize_string<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_str(visitor)
    }

    fn deserialize_bytes<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Error> {
        Err(self.wrong("bytes"))
    }

    fn deserialize_byte_buf<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Error> {
        Err(self.wrong("bytes"))
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_some(self)
    }

    fn deserialize_unit<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Error> {
        Err(self.wrong("nothing"))
    }

    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.deserialize_unit(visitor)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        visitor: V,
    ) -> Result<V::Value, Error> {
        visitor.visit_newtype_struct(self)
    }

    fn deserialize_seq<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match &self.node.value {
            Value::Array(items) => visitor.visit_seq(Items {
                items,
                next: 0,
                path: &self.path,
                what: self.what,
            }),
            _ => Err(self.wrong("an array")),
        }
    }

    fn deserialize_tuple<V: Visitor<'de>>(self, len: usize, visitor: V) -> Result<V::Value, Error> {
        match &self.node.value {
            Value::Array(items) if items.len() == len => self.deserialize_seq(visitor),
            _ => Err(self.wrong(&format!("an array of {len} numbers"))),
        }
    }

    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        len: usize,
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.deserialize_tuple(len, visitor)
    }

    fn deserialize_map<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        let Some(entries) = self.entries() else {
            return Err(self.wrong(&format!("{} (a table)", self.what)));
        };
        for (i, e) in entries.iter().enumerate() {
            // TOML refuses repeated keys itself; JSON parsers usually keep
            // the last.
            if entries[..i].iter().any(|earlier| earlier.key == e.key) {
                return Err(placed(
                    &child(&self.path, &e.key),
                    &e.key_span,
                    format!("field `{}` is given twice in {}", e.key, self.what),
                ));
            }
        }
        let (path, span, what) = (self.path.clone(), self.node.span.clone(), self.what);
        visitor
            .visit_map(Entries {
                entries,
                next: 0,
                path: &self.path,
                what: self.what,
                skip: self.skip,
            })
            .map_err(|e| e.place(&path, &span, what))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        _: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.deserialize_map(visitor)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _: &'static str,
        _: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        match &self.node.value {
            Value::String(s) => {
                let (path, span, what) = (self.path.clone(), self.node.span.clone(), self.what);
                visitor
                    .visit_enum(s.as_str().into_deserializer())
                    .map_err(|e: Error| e.place(&path, &span, what))
            }
            _ => Err(self.wrong("a string")),
        }
    }

    fn deserialize_identifier<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_str(visitor)
    }

    fn deserialize_ignored_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_unit()
    }
}

/// The items of an array.
struct Items<'a> {
    items: &'a [Node],
    next: usize,
    path: &'a str,
    what: &'a str,
}

impl<'de> de::SeqAccess<'de> for Items<'_> {
    type Error = Error;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Error> {
        let Some(node) = self.items.get(self.next) else {
            return Ok(None);
        };
        let path = format!("{}[{}]", self.path, self.next);
        self.next += 1;
        seed.deserialize(NodeDe::new(node, path.clone(), self.what))
            .map(Some)
            .map_err(|e| e.place_at(&path, node, self.what))
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.items.len() - self.next)
    }
}

/// The entries of a table.
struct Entries<'a> {
    entries: &'a [Entry],
    next: usize,
    path: &'a str,
    what: &'a str,
    skip: Option<&'a str>,
}

impl<'de> de::MapAccess<'de> for Entries<'_> {
    type Error = Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Error> {
        while self
            .entries
            .get(self.next)
            .is_some_and(|e| Some(e.key.as_str()) == self.skip)
        {
            self.next += 1;
        }
        let Some(e) = self.entries.get(self.next) else {
            return Ok(None);
        };
        seed.deserialize(e.key.as_str().into_deserializer())
            .map(Some)
            .map_err(|err: Error| err.place(&child(self.path, &e.key), &e.key_span, self.what))
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, Error> {
        let e = &self.entries[self.next];
        self.next += 1;
        let path = child(self.path, &e.key);
        seed.deserialize(NodeDe::new(&e.node, path.clone(), self.what))
            .map_err(|err| err.place_at(&path, &e.node, self.what))
    }
}
