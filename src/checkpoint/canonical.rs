//! Canonical JSON, written as it goes: the text of
//! `serde_json::to_value(v)?.to_string()` (compact, every object's keys in
//! sorted order, numbers as a `serde_json::Value` holds them), byte for
//! byte, without first building the `Value` of the whole thing.
//!
//! A `Value` costs about 700 bytes for each object of a scene description
//! (a map node and a heap string per field), 700 MB for a field of a million
//! spheres; this writer holds the text and, while an object is written, the
//! text of its fields, to put them in order.

use serde::ser::{self, Serialize};
use serde_json::{Error, Value};
use std::borrow::Cow;

/// The canonical JSON text of `value`, leaving out the fields at the key
/// paths `omit` (`&["render", "gamma"]` is the `gamma` field of the top
/// object's `render` object). Fails where `serde_json::to_value` would
/// (a map key that is not a string, a number or a boolean).
pub(crate) fn sorted_json<T: Serialize + ?Sized>(
    value: &T,
    omit: &[&[&str]],
) -> Result<String, Error> {
    let mut w = Writer {
        out: Vec::new(),
        path: Vec::new(),
        omit,
    };
    value.serialize(&mut w)?;
    let mut out = w.out;
    out.shrink_to_fit();
    Ok(String::from_utf8(out).expect("serde_json writes UTF-8"))
}

/// One step of the path to the value being written: an object's key, or
/// `None` for an array's element.
type Step = Option<Cow<'static, str>>;

struct Writer<'o> {
    /// The text of the value being written (an object's field is written
    /// into a buffer of its own, swapped in).
    out: Vec<u8>,
    /// Where the value being written is.
    path: Vec<Step>,
    omit: &'o [&'o [&'o str]],
}

impl Writer<'_> {
    /// Appends a value as `serde_json` writes it.
    fn json<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        serde_json::to_writer(&mut self.out, value)
    }

    /// Whether the value at the current path is left out.
    fn omitted(&self) -> bool {
        self.omit.iter().any(|o| {
            o.len() == self.path.len()
                && o.iter()
                    .zip(&self.path)
                    .all(|(a, b)| b.as_deref() == Some(*a))
        })
    }

    /// Writes `{"variant":` around what follows, as `to_value` nests an
    /// enum's data under its variant's name.
    fn open_variant(&mut self, variant: &'static str) -> Result<(), Error> {
        self.out.push(b'{');
        self.json(variant)?;
        self.out.push(b':');
        self.path.push(Some(Cow::Borrowed(variant)));
        Ok(())
    }

    fn close_variant(&mut self) {
        self.path.pop();
        self.out.push(b'}');
    }
}

/// A map key as `serde_json::to_value` turns it into a string: the value of
/// a one-entry map made by serde_json itself.
fn key_text<T: Serialize + ?Sized>(key: &T) -> Result<String, Error> {
    struct OneKey<'a, T: ?Sized>(&'a T);
    impl<T: Serialize + ?Sized> Serialize for OneKey<'_, T> {
        fn serialize<S: ser::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            use ser::SerializeMap;
            let mut map = s.serialize_map(Some(1))?;
            map.serialize_entry(self.0, &())?;
            map.end()
        }
    }
    match serde_json::to_value(OneKey(key))? {
        Value::Object(map) => Ok(map.into_iter().next().map(|(k, _)| k).unwrap_or_default()),
        _ => Err(ser::Error::custom("a map serialised as something else")),
    }
}

impl<'a, 'o> ser::Serializer for &'a mut Writer<'o> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = Array<'a, 'o>;
    type SerializeTuple = Array<'a, 'o>;
    type SerializeTupleStruct = Array<'a, 'o>;
    type SerializeTupleVariant = Array<'a, 'o>;
    type SerializeMap = Object<'a, 'o>;
    type SerializeStruct = Object<'a, 'o>;
    type SerializeStructVariant = Object<'a, 'o>;

    fn serialize_bool(self, v: bool) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_i8(self, v: i8) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_i16(self, v: i16) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_i32(self, v: i32) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_i64(self, v: i64) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_i128(self, v: i128) -> Result<(), Error> {
        // Through a `Value`, which holds only what fits 64 bits.
        self.json(&serde_json::to_value(v)?)
    }
    fn serialize_u8(self, v: u8) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_u16(self, v: u16) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_u32(self, v: u32) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_u64(self, v: u64) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_u128(self, v: u128) -> Result<(), Error> {
        self.json(&serde_json::to_value(v)?)
    }
    fn serialize_f32(self, v: f32) -> Result<(), Error> {
        // A `Value` holds an f32 as the f64 it widens to, and prints that.
        self.json(&Value::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), Error> {
        self.json(&Value::from(v))
    }
    fn serialize_char(self, v: char) -> Result<(), Error> {
        self.json(&v)
    }
    fn serialize_str(self, v: &str) -> Result<(), Error> {
        self.json(v)
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Error> {
        // An array of numbers, as in a `Value`.
        self.json(&v.to_vec())
    }
    fn serialize_none(self) -> Result<(), Error> {
        self.json(&())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Error> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Error> {
        self.json(&())
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Error> {
        self.json(&())
    }
    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<(), Error> {
        self.json(variant)
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.open_variant(variant)?;
        value.serialize(&mut *self)?;
        self.close_variant();
        Ok(())
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Array<'a, 'o>, Error> {
        Array::new(self, None)
    }
    fn serialize_tuple(self, _: usize) -> Result<Array<'a, 'o>, Error> {
        Array::new(self, None)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Array<'a, 'o>, Error> {
        Array::new(self, None)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Array<'a, 'o>, Error> {
        Array::new(self, Some(variant))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Object<'a, 'o>, Error> {
        Ok(Object::new(self, None))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Object<'a, 'o>, Error> {
        Ok(Object::new(self, None))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Object<'a, 'o>, Error> {
        self.path.push(Some(Cow::Borrowed(variant)));
        Ok(Object::new(self, Some(variant)))
    }
}

/// An array being written: its elements go straight to the text.
pub(crate) struct Array<'a, 'o> {
    w: &'a mut Writer<'o>,
    first: bool,
    /// Inside `{"variant":…}`.
    variant: bool,
}

impl<'a, 'o> Array<'a, 'o> {
    fn new(w: &'a mut Writer<'o>, variant: Option<&'static str>) -> Result<Self, Error> {
        if let Some(v) = variant {
            w.open_variant(v)?;
        }
        w.out.push(b'[');
        Ok(Self {
            w,
            first: true,
            variant: variant.is_some(),
        })
    }

    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        if !std::mem::replace(&mut self.first, false) {
            self.w.out.push(b',');
        }
        self.w.path.push(None);
        value.serialize(&mut *self.w)?;
        self.w.path.pop();
        Ok(())
    }

    fn finish(self) -> Result<(), Error> {
        self.w.out.push(b']');
        if self.variant {
            self.w.close_variant();
        }
        Ok(())
    }
}

impl ser::SerializeSeq for Array<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

impl ser::SerializeTuple for Array<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

impl ser::SerializeTupleStruct for Array<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

impl ser::SerializeTupleVariant for Array<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

/// An object being written: each field's text is kept with its key until
/// the end, when they are written in the order of their keys.
pub(crate) struct Object<'a, 'o> {
    w: &'a mut Writer<'o>,
    fields: Vec<(Cow<'static, str>, Vec<u8>)>,
    /// The key given by `serialize_key`, awaiting its value.
    key: Option<Cow<'static, str>>,
    /// Inside `{"variant":…}` (its step is on the path).
    variant: Option<&'static str>,
}

impl<'a, 'o> Object<'a, 'o> {
    fn new(w: &'a mut Writer<'o>, variant: Option<&'static str>) -> Self {
        Self {
            w,
            fields: Vec::new(),
            key: None,
            variant,
        }
    }

    fn field<T: Serialize + ?Sized>(
        &mut self,
        key: Cow<'static, str>,
        value: &T,
    ) -> Result<(), Error> {
        self.w.path.push(Some(key));
        if !self.w.omitted() {
            let outer = std::mem::take(&mut self.w.out);
            let written = value.serialize(&mut *self.w);
            let text = std::mem::replace(&mut self.w.out, outer);
            written?;
            let key = self.w.path.pop().flatten().expect("the key pushed above");
            self.fields.push((key, text));
        } else {
            self.w.path.pop();
        }
        Ok(())
    }

    fn finish(mut self) -> Result<(), Error> {
        // As a `BTreeMap` has them: in order, with the last value of a key
        // given twice (reversed, a stable sort puts it first of its key).
        let mut fields = std::mem::take(&mut self.fields);
        fields.reverse();
        fields.sort_by(|a, b| a.0.cmp(&b.0));
        fields.dedup_by(|later, kept| later.0 == kept.0);
        let mut head = Vec::new();
        if let Some(v) = self.variant {
            // Its step is on the path already (pushed when the variant
            // began); `close_variant` pops it.
            head.push(b'{');
            serde_json::to_writer(&mut head, v)?;
            head.push(b':');
        }
        head.push(b'{');
        // The largest field's text becomes the whole text, written around
        // it, when nothing precedes this object: the text of a million
        // objects is not copied once more.
        let largest = (0..fields.len()).max_by_key(|&i| fields[i].1.len());
        let whole = self.w.out.is_empty() && largest.is_some();
        let mut text = std::mem::take(&mut head);
        let mut body = None;
        for (i, (key, value)) in fields.into_iter().enumerate() {
            if i > 0 {
                text.push(b',');
            }
            serde_json::to_writer(&mut text, key.as_ref())?;
            text.push(b':');
            if whole && Some(i) == largest {
                body = Some((text, value));
                text = Vec::new();
            } else {
                text.extend_from_slice(&value);
            }
        }
        text.push(b'}');
        if self.variant.is_some() {
            text.push(b'}');
            self.w.path.pop();
        }
        match body {
            Some((before, mut value)) => {
                value.reserve(before.len() + text.len());
                value.splice(0..0, before);
                value.extend_from_slice(&text);
                self.w.out = value;
            }
            None => self.w.out.extend_from_slice(&text),
        }
        Ok(())
    }
}

impl ser::SerializeMap for Object<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Error> {
        self.key = Some(Cow::Owned(key_text(key)?));
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        let key = self
            .key
            .take()
            .ok_or_else(|| <Error as ser::Error>::custom("a map value without its key"))?;
        self.field(key, value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

impl ser::SerializeStruct for Object<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.field(Cow::Borrowed(key), value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

impl ser::SerializeStructVariant for Object<'_, '_> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.field(Cow::Borrowed(key), value)
    }
    fn end(self) -> Result<(), Error> {
        self.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;
    use std::collections::{BTreeMap, HashMap};

    /// The text this writer must reproduce: `to_value`, the omitted paths
    /// removed from the `Value`, then printed.
    fn through_value<T: Serialize>(value: &T, omit: &[&[&str]]) -> String {
        let mut v = serde_json::to_value(value).unwrap();
        for path in omit {
            let (last, parents) = path.split_last().unwrap();
            let parent = parents.iter().try_fold(&mut v, |v, k| v.get_mut(*k));
            if let Some(Value::Object(map)) = parent {
                map.remove(*last);
            }
        }
        v.to_string()
    }

    #[derive(Serialize)]
    enum Kind {
        Unit,
        Newtype(f32),
        Tuple(u8, String),
        Struct { zeta: bool, alpha: Option<i64> },
    }

    #[derive(Serialize)]
    #[serde(tag = "type")]
    enum Tagged {
        Ball { radius: f64, centre: [f64; 3] },
    }

    #[derive(Serialize)]
    struct Unit;

    #[derive(Serialize)]
    struct Inner {
        gamma: f64,
        keep: u32,
    }

    #[derive(Serialize)]
    struct Every {
        z_last: u8,
        text: String,
        escaped: &'static str,
        floats: Vec<f32>,
        doubles: [f64; 5],
        ints: (i8, i16, i32, i64, u16, u64, i128, u128),
        character: char,
        bytes: serde_bytes_like::Bytes,
        nothing: Option<u8>,
        unit: (),
        unit_struct: Unit,
        kinds: Vec<Kind>,
        tagged: Tagged,
        by_number: BTreeMap<i32, &'static str>,
        by_bool: HashMap<bool, u8>,
        by_char: BTreeMap<char, u8>,
        empty_map: BTreeMap<String, u8>,
        empty_list: Vec<u8>,
        render: Inner,
        nested: Vec<Inner>,
        #[serde(flatten)]
        flat: BTreeMap<String, Vec<u8>>,
    }

    mod serde_bytes_like {
        pub struct Bytes(pub Vec<u8>);
        impl serde::Serialize for Bytes {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_bytes(&self.0)
            }
        }
    }

    fn every() -> Every {
        Every {
            z_last: 7,
            text: "plain".into(),
            escaped: "quote \" backslash \\ tab \t newline \n bell \u{7} é 😀",
            floats: vec![0.1, -0.0, 1e-40, f32::MAX, f32::NAN, f32::INFINITY, 3.0],
            doubles: [0.1, 1e300, -2.5e-320, f64::NEG_INFINITY, 12.0],
            ints: (-8, -16, -32, i64::MIN, 16, u64::MAX, -5, 7),
            character: 'ß',
            bytes: serde_bytes_like::Bytes(vec![0, 255, 10]),
            nothing: None,
            unit: (),
            unit_struct: Unit,
            kinds: vec![
                Kind::Unit,
                Kind::Newtype(0.3),
                Kind::Tuple(1, "t".into()),
                Kind::Struct {
                    zeta: true,
                    alpha: Some(-1),
                },
            ],
            tagged: Tagged::Ball {
                radius: 0.5,
                centre: [1.0, 2.0, 3.0],
            },
            by_number: BTreeMap::from([(10, "ten"), (-2, "minus two"), (9, "nine")]),
            by_bool: HashMap::from([(true, 1), (false, 0)]),
            by_char: BTreeMap::from([('b', 2), ('a', 1)]),
            empty_map: BTreeMap::new(),
            empty_list: Vec::new(),
            render: Inner {
                gamma: 2.2,
                keep: 1,
            },
            nested: vec![Inner {
                gamma: 1.0,
                keep: 2,
            }],
            // Sorts between the struct's own fields; "text" is given twice,
            // and the last value is the one kept.
            flat: BTreeMap::from([("m_flat".into(), vec![1]), ("text".into(), vec![2])]),
        }
    }

    #[test]
    fn the_text_is_that_of_a_serde_json_value() {
        let value = every();
        for omit in [
            &[][..],
            &[&["render", "gamma"][..], &["z_last"]][..],
            &[&["kinds"][..], &["nested", "gamma"], &["tagged", "radius"]][..],
        ] {
            assert_eq!(
                sorted_json(&value, omit).unwrap(),
                through_value(&value, omit)
            );
        }
        // Keys that are not strings, numbers or booleans are refused, as
        // by `to_value`.
        let by_pair = BTreeMap::from([((1, 2), 3)]);
        assert!(serde_json::to_value(&by_pair).is_err());
        assert!(sorted_json(&by_pair, &[]).is_err());
    }

    #[test]
    fn every_builtin_scene_and_example_file_gives_the_same_text() {
        use crate::scene::{builtin::BUILTINS, file::SceneFile};
        let omit: &[&[&str]] = &[&["caption"], &["render", "gamma"]];
        for b in BUILTINS {
            let desc = b.desc();
            assert_eq!(
                sorted_json(&desc, omit).unwrap(),
                through_value(&desc, omit),
                "{}",
                b.name
            );
        }
        let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
        let mut read = 0;
        for entry in std::fs::read_dir(examples).unwrap() {
            let path = entry.unwrap().path();
            let Ok(file) = SceneFile::read(&path) else {
                continue;
            };
            assert_eq!(
                sorted_json(&file.desc, omit).unwrap(),
                through_value(&file.desc, omit),
                "{}",
                path.display()
            );
            read += 1;
        }
        assert!(read > 20, "only {read} example scenes read");
    }
}
