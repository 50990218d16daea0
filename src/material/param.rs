//! A material's parameters: each a constant or a texture, as a scene file
//! gives it ([`ColorDesc`], [`ScalarDesc`], [`RoughnessDesc`]) and as a
//! compiled material holds it ([`ColorParam`], [`ScalarParam`]).

use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;
use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use std::fmt;

/// An RGB triple or a 3-D point/vector.
pub type Triple = [f64; 3];

/// A colour given outright, or by naming a texture of `textures`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ColorDesc {
    /// The colour.
    Rgb(Triple),
    /// The name of a texture.
    Texture(String),
}

impl From<Triple> for ColorDesc {
    fn from(c: Triple) -> Self {
        ColorDesc::Rgb(c)
    }
}

impl Default for ColorDesc {
    fn default() -> Self {
        ColorDesc::Rgb([0.0; 3])
    }
}

/// A number given outright, or by naming a scalar texture of `textures`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ScalarDesc {
    /// The number.
    Value(f64),
    /// The name of a texture.
    Texture(String),
}

impl From<f64> for ScalarDesc {
    fn from(v: f64) -> Self {
        ScalarDesc::Value(v)
    }
}

/// A roughness (or a microfacet α): one number, a pair `[u, v]` for a
/// surface rougher along its tangent than along its bitangent (or the
/// reverse), or the name of a scalar texture.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum RoughnessDesc {
    /// The same along both directions.
    Value(f64),
    /// Along the tangent and the bitangent.
    Pair([f64; 2]),
    /// The name of a scalar texture.
    Texture(String),
    /// Along the tangent and the bitangent, either or both a scalar
    /// texture (`[0.1, "bumps"]`).
    Each([ScalarDesc; 2]),
}

impl From<f64> for RoughnessDesc {
    fn from(v: f64) -> Self {
        RoughnessDesc::Value(v)
    }
}

/// Reads one of the parameter forms from whatever the file holds:
/// `number` and `pair`/`triple` say which forms the parameter takes.
struct ParamVisitor {
    expecting: &'static str,
    number: bool,
    length: usize,
}

/// What a [`ParamVisitor`] read.
enum Read {
    Number(f64),
    Numbers(Vec<f64>),
    Name(String),
}

impl<'de> Visitor<'de> for ParamVisitor {
    type Value = Read;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.expecting)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Read, E> {
        Ok(Read::Name(v.to_string()))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Read, E> {
        if self.number {
            Ok(Read::Number(v))
        } else {
            Err(E::invalid_type(de::Unexpected::Float(v), &self))
        }
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Read, E> {
        if self.number {
            Ok(Read::Number(v as f64))
        } else {
            Err(E::invalid_type(de::Unexpected::Signed(v), &self))
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Read, E> {
        if self.number {
            Ok(Read::Number(v as f64))
        } else {
            Err(E::invalid_type(de::Unexpected::Unsigned(v), &self))
        }
    }

    fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Read, A::Error> {
        if self.length == 0 {
            return Err(de::Error::invalid_type(de::Unexpected::Seq, &self));
        }
        let mut numbers = Vec::with_capacity(self.length);
        while let Some(x) = seq.next_element::<f64>()? {
            numbers.push(x);
            if numbers.len() > self.length {
                return Err(de::Error::invalid_length(numbers.len(), &self));
            }
        }
        if numbers.len() != self.length {
            return Err(de::Error::invalid_length(numbers.len(), &self));
        }
        Ok(Read::Numbers(numbers))
    }
}

impl<'de> Deserialize<'de> for ColorDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let read = d.deserialize_any(ParamVisitor {
            expecting: "an array of 3 numbers [r, g, b] or the name of a texture",
            number: false,
            length: 3,
        })?;
        Ok(match read {
            Read::Numbers(n) => ColorDesc::Rgb([n[0], n[1], n[2]]),
            Read::Name(s) => ColorDesc::Texture(s),
            Read::Number(_) => unreachable!("refused by the visitor"),
        })
    }
}

impl<'de> Deserialize<'de> for ScalarDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let read = d.deserialize_any(ParamVisitor {
            expecting: "a number or the name of a texture",
            number: true,
            length: 0,
        })?;
        Ok(match read {
            Read::Number(v) => ScalarDesc::Value(v),
            Read::Name(s) => ScalarDesc::Texture(s),
            Read::Numbers(_) => unreachable!("refused by the visitor"),
        })
    }
}

impl<'de> Deserialize<'de> for RoughnessDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Roughness;
        impl<'de> Visitor<'de> for Roughness {
            type Value = RoughnessDesc;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number, an array of 2 numbers or textures [u, v], or the name of a texture",
                )
            }

            fn visit_str<E: de::Error>(self, v: &str) -> Result<RoughnessDesc, E> {
                Ok(RoughnessDesc::Texture(v.to_string()))
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RoughnessDesc, E> {
                Ok(RoughnessDesc::Value(v))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RoughnessDesc, E> {
                Ok(RoughnessDesc::Value(v as f64))
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RoughnessDesc, E> {
                Ok(RoughnessDesc::Value(v as f64))
            }

            fn visit_seq<A: de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<RoughnessDesc, A::Error> {
                let mut each = Vec::with_capacity(2);
                while let Some(x) = seq.next_element::<ScalarDesc>()? {
                    each.push(x);
                    if each.len() > 2 {
                        return Err(de::Error::invalid_length(each.len(), &self));
                    }
                }
                match <[ScalarDesc; 2]>::try_from(each) {
                    Ok([ScalarDesc::Value(u), ScalarDesc::Value(v)]) => {
                        Ok(RoughnessDesc::Pair([u, v]))
                    }
                    Ok(pair) => Ok(RoughnessDesc::Each(pair)),
                    Err(each) => Err(de::Error::invalid_length(each.len(), &self)),
                }
            }
        }
        d.deserialize_any(Roughness)
    }
}

/// A colour parameter: one colour, or a texture's colour where a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorParam {
    /// The colour.
    Const(Color),
    /// Texture number n of the scene's table.
    Texture(u32),
}

impl ColorParam {
    /// The colour at `hit`, textures looked up in `textures`.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        match *self {
            ColorParam::Const(c) => c,
            ColorParam::Texture(t) => textures[t as usize].value(textures, &hit.tex_coords()),
        }
    }

    /// An albedo: the colour at `hit`, a texture's kept within [0, 1] so
    /// that no surface reflects more than it receives (a constant one is
    /// checked when the scene is compiled).
    #[inline(always)]
    pub fn albedo_at(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        match *self {
            ColorParam::Const(c) => c,
            ColorParam::Texture(_) => self.at(hit, textures).clamp(Color::ZERO, Color::ONE),
        }
    }

    /// The texture it looks up, if any.
    pub fn texture(&self) -> Option<u32> {
        match *self {
            ColorParam::Const(_) => None,
            ColorParam::Texture(t) => Some(t),
        }
    }
}

/// A scalar parameter: one number, or a scalar texture's value where a ray
/// hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScalarParam {
    /// The number.
    Const(f32),
    /// Texture number n of the scene's table (a scalar texture: its value
    /// is the same in every channel).
    Texture(u32),
}

impl ScalarParam {
    /// The value at `hit`.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> f32 {
        match *self {
            ScalarParam::Const(v) => v,
            ScalarParam::Texture(t) => textures[t as usize].value(textures, &hit.tex_coords()).x,
        }
    }

    /// The texture it looks up, if any.
    pub fn texture(&self) -> Option<u32> {
        match *self {
            ScalarParam::Const(_) => None,
            ScalarParam::Texture(t) => Some(t),
        }
    }
}

/// A parameter that cannot be compiled: the field and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    /// Path of the field, e.g. `materials.gold.roughness`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl Invalid {
    /// Field `field` is wrong: `message`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Field `field` scales `map`, which the material does not have.
    pub fn scales_missing(field: impl Into<String>, map: &str) -> Self {
        Invalid::new(
            field,
            format!("scales `{map}`, which the material does not have"),
        )
    }
}

/// What a material's parameters are checked against while they are
/// compiled: a number's range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// Any finite number.
    Any,
    /// Not negative.
    NonNegative,
    /// Greater than zero.
    Positive,
    /// Within [0, 1].
    Unit,
    /// The index of a layer over what it covers (a coat, a glTF
    /// dielectric), relative to the outside: from 1 (no interface) to the
    /// given largest. Below 1 a coat's internal reflection would be total
    /// where its model assumes none, and the layer would give more than
    /// it receives.
    Index(f64),
}

/// The largest index a glTF dielectric (`principled`) may have: far beyond any
/// real material's (diamond 2.42, germanium about 4 in the infrared) and
/// the index glTF's "ior 0" is read as, small enough that 1/η² is a normal
/// number.
pub const MAX_LAYER_IOR: f64 = 1000.0;

impl Range {
    /// `v` checked: `Ok` with it as `f32`, or why it is refused.
    pub fn check(self, v: f64) -> Result<f32, String> {
        if !(v.abs() <= f64::from(f32::MAX)) {
            return Err(format!(
                "must be a finite number of magnitude at most {:e}, got {v}",
                f32::MAX
            ));
        }
        let ok = match self {
            Range::Any => true,
            Range::NonNegative => v >= 0.0,
            Range::Positive => v as f32 > 0.0,
            Range::Unit => (0.0..=1.0).contains(&v),
            Range::Index(max) => (1.0..=max).contains(&v),
        };
        if ok {
            Ok(v as f32)
        } else {
            Err(match self {
                Range::Any => unreachable!(),
                Range::NonNegative => format!("must not be negative, got {v}"),
                Range::Positive => format!("must be greater than 0, got {v}"),
                Range::Unit => format!("must be in [0, 1], got {v}"),
                Range::Index(max) => format!(
                    "must be from 1 to {max} (the index inside over the index outside), got {v}"
                ),
            })
        }
    }
}

/// How colours given outright are checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorRange {
    /// Components not negative (a radiance).
    NonNegative,
    /// Components in [0, 1] (an albedo).
    Unit,
}

/// Where a material's textures are found while it is compiled: the scene
/// compiler resolves names to its table and checks their kind.
pub trait Textures {
    /// The colour parameter `field` given by `c`.
    fn color(
        &mut self,
        field: &str,
        c: &ColorDesc,
        range: ColorRange,
    ) -> Result<ColorParam, Invalid>;

    /// The scalar parameter `field` given by `s`.
    fn scalar(&mut self, field: &str, s: &ScalarDesc, range: Range)
        -> Result<ScalarParam, Invalid>;

    /// A texture that is texture `t` times `factor`.
    fn scaled(&mut self, t: u32, factor: Color) -> u32;

    /// The width over the height of the image texture `t` shows (through
    /// any scaling); `None` when it shows no single image.
    fn aspect(&self, t: u32) -> Option<f64>;

    /// The colour texture `name` of field `field` read as a tangent-space
    /// normal map (linear data, not sRGB-decoded colour).
    fn normal_map(&mut self, field: &str, name: &str) -> Result<u32, Invalid>;

    /// The scene's material `name`, compiled, for field `field` (a mix's
    /// materials).
    fn material(&mut self, field: &str, name: &str) -> Result<super::Material, Invalid>;
}

/// `v` checked by `range` for field `field`.
pub fn number(field: &str, v: f64, range: Range) -> Result<f32, Invalid> {
    range.check(v).map_err(|m| Invalid::new(field, m))
}

/// The fields of struct `T`, as serde knows them (for listing a kind's
/// fields without writing them out again).
pub fn fields_of<'de, T: serde::Deserialize<'de>>() -> &'static [&'static str] {
    struct Capture(Option<&'static [&'static str]>);
    struct Probe<'c>(&'c mut Capture);
    #[derive(Debug)]
    struct Stop;
    impl fmt::Display for Stop {
        fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("stop")
        }
    }
    impl std::error::Error for Stop {}
    impl de::Error for Stop {
        fn custom<M: fmt::Display>(_: M) -> Self {
            Stop
        }
    }
    impl<'de> de::Deserializer<'de> for Probe<'_> {
        type Error = Stop;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Stop> {
            Err(Stop)
        }
        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _: &'static str,
            fields: &'static [&'static str],
            _: V,
        ) -> Result<V::Value, Stop> {
            self.0 .0 = Some(fields);
            Err(Stop)
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
            bytes byte_buf option unit unit_struct newtype_struct seq tuple
            tuple_struct map enum identifier ignored_any
        }
    }
    let mut capture = Capture(None);
    let _ = T::deserialize(Probe(&mut capture));
    capture.0.unwrap_or(&[])
}
