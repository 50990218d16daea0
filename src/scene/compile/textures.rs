//! Compiling the textures of a description: each named texture once, in
//! the order materials (and other textures) ask for them, with references
//! between textures followed and cycles refused; image files read once and
//! recorded as sources of the scene.

use crate::hint;
use crate::math::Color;
use crate::scene::desc::{
    ChannelDesc, ColorDesc, EncodingDesc, FilterDesc, NoisePatternDesc, ScalarDesc, TextureDesc,
    WrapDesc,
};
use crate::scene::{invalid, MeshSource, SceneError};
use crate::texture::{
    Channels, Filter, Image, ImageMap, NoisePattern, Perlin, Texture, UvTransform, Wrap,
};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

/// A colour parameter as compiled: a colour, or a texture of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum ColorRef {
    /// The colour itself.
    Rgb(Color),
    /// Texture number n of the table.
    Texture(u32),
}

/// Most textures a chain of references may pass through (a checker of
/// checkers of …): compiling a texture and looking it up at a hit follow
/// the chain by recursion, whose depth an input must not set.
pub const MAX_TEXTURE_DEPTH: usize = 64;

/// The names of the textures `desc` refers to.
fn references(desc: &TextureDesc) -> impl Iterator<Item = &str> {
    let (even, odd) = match desc {
        TextureDesc::Checker { even, odd, .. } | TextureDesc::Checkerboard { even, odd, .. } => {
            (Some(even), Some(odd))
        }
        TextureDesc::Mix { first, second, .. } => (Some(first), Some(second)),
        TextureDesc::Scale { texture, .. } => (Some(texture), None),
        _ => (None, None),
    };
    let amount = match desc {
        TextureDesc::Mix {
            amount: ScalarDesc::Texture(name),
            ..
        } => Some(name.as_str()),
        _ => None,
    };
    [even, odd]
        .into_iter()
        .flatten()
        .filter_map(|c| match c {
            ColorDesc::Texture(name) => Some(name.as_str()),
            ColorDesc::Rgb(_) => None,
        })
        .chain(amount)
}

/// Checks every texture, whether a material uses it or not: none refers to
/// itself, directly or through others (the chain named), and no chain is
/// more than [`MAX_TEXTURE_DEPTH`] textures long. Walked without recursion,
/// each texture once, so that neither a long chain nor a long cycle can
/// overflow the stack or take quadratic time.
fn check_references(descs: &BTreeMap<String, TextureDesc>) -> Result<(), SceneError> {
    // Each texture's depth once known: the longest chain it starts.
    let mut depth: HashMap<&str, usize> = HashMap::with_capacity(descs.len());
    let mut on_path: HashMap<&str, usize> = HashMap::new();
    for start in descs.keys() {
        if depth.contains_key(start.as_str()) {
            continue;
        }
        // The path being walked: each texture with the references it has
        // left to visit.
        let mut path: Vec<(&str, Vec<&str>)> = Vec::new();
        let children = |name: &str| -> Vec<&str> {
            descs
                .get(name)
                .map(|d| references(d).filter(|r| descs.contains_key(*r)).collect())
                .unwrap_or_default()
        };
        on_path.insert(start, 0);
        path.push((start, children(start)));
        while let Some((name, left)) = path.last_mut() {
            let name = *name;
            match left.pop() {
                Some(next) if depth.contains_key(next) => {}
                Some(next) => {
                    if let Some(&at) = on_path.get(next) {
                        let mut chain: Vec<&str> = path[at..].iter().map(|(n, _)| *n).collect();
                        chain.push(next);
                        return Err(invalid(
                            format!("textures.{next}"),
                            format!("refers to itself: {}", shown_chain(&chain)),
                        ));
                    }
                    on_path.insert(next, path.len());
                    path.push((next, children(next)));
                }
                None => {
                    let d = 1 + children(name).iter().map(|c| depth[c]).max().unwrap_or(0);
                    if d > MAX_TEXTURE_DEPTH {
                        return Err(invalid(
                            format!("textures.{name}"),
                            format!(
                                "starts a chain of {d} textures referring to each other, \
                                 more than the {MAX_TEXTURE_DEPTH} lumen follows"
                            ),
                        ));
                    }
                    depth.insert(name, d);
                    on_path.remove(name);
                    path.pop();
                }
            }
        }
    }
    Ok(())
}

/// A chain of texture names as `a → b → a`; a long one by its ends and how
/// many lie between.
fn shown_chain(chain: &[&str]) -> String {
    const ENDS: usize = 4;
    if chain.len() <= 2 * ENDS + 1 {
        return chain.join(" → ");
    }
    format!(
        "{} → … ({} more) … → {}",
        chain[..ENDS].join(" → "),
        chain.len() - 2 * ENDS,
        chain[chain.len() - ENDS..].join(" → ")
    )
}

/// The textures compiled so far.
pub(crate) struct TextureTable<'a> {
    descs: &'a BTreeMap<String, TextureDesc>,
    base: &'a Path,
    /// The compiled textures; materials refer to them by index.
    pub(crate) textures: Vec<Texture>,
    index: HashMap<&'a str, u32>,
    /// The images read, by file name.
    images: HashMap<String, Arc<Image>>,
}

impl<'a> TextureTable<'a> {
    /// An empty table for the textures `descs`, whose files are relative to
    /// `base`, once the references between them are checked (see
    /// [`check_references`]).
    pub(crate) fn new(
        descs: &'a BTreeMap<String, TextureDesc>,
        base: &'a Path,
    ) -> Result<Self, SceneError> {
        check_references(descs)?;
        Ok(TextureTable {
            descs,
            base,
            textures: Vec::new(),
            index: HashMap::new(),
            images: HashMap::new(),
        })
    }

    /// Adds `texture` to the table; its index.
    pub(crate) fn push(&mut self, texture: Texture) -> u32 {
        self.textures.push(texture);
        self.textures.len() as u32 - 1
    }

    /// The colour parameter `field` given by `c`; `check` validates a
    /// colour given outright. Image files read are added to `sources`.
    pub(crate) fn color(
        &mut self,
        field: &str,
        c: &ColorDesc,
        check: fn(&str, [f64; 3]) -> Result<Color, SceneError>,
        sources: &mut Vec<MeshSource>,
    ) -> Result<ColorRef, SceneError> {
        match c {
            ColorDesc::Rgb(rgb) => Ok(ColorRef::Rgb(check(field, *rgb)?)),
            ColorDesc::Texture(name) => Ok(ColorRef::Texture(self.named(field, name, sources)?)),
        }
    }

    /// The texture of the colour parameter `field` of a texture: a colour
    /// given outright becomes a texture of that one colour.
    fn texture_of(
        &mut self,
        field: &str,
        c: &'a ColorDesc,
        sources: &mut Vec<MeshSource>,
    ) -> Result<u32, SceneError> {
        match c {
            ColorDesc::Rgb(rgb) => {
                let colour = super::color(field, *rgb)?;
                self.textures.push(Texture::Solid(colour));
                Ok(self.textures.len() as u32 - 1)
            }
            ColorDesc::Texture(name) => self.named(field, name, sources),
        }
    }

    /// The index of the texture `name`, compiled on first use (and its
    /// references with it: `check_references` has refused cycles and chains
    /// longer than [`MAX_TEXTURE_DEPTH`], so this recursion is bounded).
    fn named(
        &mut self,
        field: &str,
        name: &str,
        sources: &mut Vec<MeshSource>,
    ) -> Result<u32, SceneError> {
        if let Some(&i) = self.index.get(name) {
            return Ok(i);
        }
        let descs = self.descs;
        let Some((key, desc)) = descs.get_key_value(name) else {
            let listed = if descs.is_empty() {
                "the scene defines no textures".to_string()
            } else {
                let known = descs.keys().map(String::as_str);
                format!("defined: {}", hint::listing(name, known, str::to_string))
            };
            return Err(invalid(
                field,
                format!("no texture named \"{name}\" ({listed})"),
            ));
        };
        let here = format!("textures.{name}");
        let texture = match desc {
            TextureDesc::Checker { scale, even, odd } => Texture::Checker {
                inverse_scale: 1.0 / positive(&format!("{here}.scale"), *scale)?,
                even: self.texture_of(&format!("{here}.even"), even, sources)?,
                odd: self.texture_of(&format!("{here}.odd"), odd, sources)?,
            },
            TextureDesc::Scale { texture, factor } => Texture::Scaled {
                factor: super::color(&format!("{here}.factor"), *factor)?,
                texture: self.texture_of(&format!("{here}.texture"), texture, sources)?,
            },
            TextureDesc::Mix {
                first,
                second,
                amount,
            } => {
                let at = format!("{here}.amount");
                let amount = match amount {
                    ScalarDesc::Value(v) => {
                        if !(0.0..=1.0).contains(v) {
                            return Err(invalid(at, format!("must be within [0, 1], got {v}")));
                        }
                        self.push(Texture::Solid(Color::splat(*v as f32)))
                    }
                    ScalarDesc::Texture(name) => {
                        let t = self.named(&at, name, sources)?;
                        if self.kind(t) == TextureKind::Color {
                            return Err(invalid(
                                at,
                                format!(
                                    "texture \"{name}\" is a colour; the amount is a number: \
                                     give the image texture a `channel`"
                                ),
                            ));
                        }
                        t
                    }
                };
                Texture::Mix {
                    first: self.texture_of(&format!("{here}.first"), first, sources)?,
                    second: self.texture_of(&format!("{here}.second"), second, sources)?,
                    amount,
                }
            }
            TextureDesc::Checkerboard {
                even,
                odd,
                uv_scale,
                uv_offset,
            } => {
                let pair = |field: &str, v: Option<[f64; 2]>, default: f64| {
                    let v = v.unwrap_or([default; 2]);
                    super::finite(format!("{here}.{field}"), &v)?;
                    Ok::<_, SceneError>(v.map(|x| x as f32))
                };
                Texture::UvChecker {
                    scale: pair("uv_scale", *uv_scale, 1.0)?,
                    offset: pair("uv_offset", *uv_offset, 0.0)?,
                    even: self.texture_of(&format!("{here}.even"), even, sources)?,
                    odd: self.texture_of(&format!("{here}.odd"), odd, sources)?,
                }
            }
            TextureDesc::Image {
                file,
                channel,
                encoding,
                wrap,
                filter,
                uv_set,
                uv_offset,
                uv_rotation,
                uv_scale,
            } => {
                let image = self.image(&format!("{here}.file"), file, sources)?;
                let channels = match channel {
                    None => Channels::Rgb,
                    Some(ChannelDesc::R) => Channels::One(0),
                    Some(ChannelDesc::G) => Channels::One(1),
                    Some(ChannelDesc::B) => Channels::One(2),
                    Some(ChannelDesc::A) => Channels::One(3),
                };
                let srgb = match encoding {
                    Some(EncodingDesc::Srgb) => true,
                    Some(EncodingDesc::Linear) => false,
                    None => channel.is_none(),
                };
                let wrap = match wrap.unwrap_or(WrapDesc::Repeat) {
                    WrapDesc::Repeat => Wrap::Repeat,
                    WrapDesc::Clamp => Wrap::Clamp,
                    WrapDesc::Mirror => Wrap::Mirror,
                };
                let number = |name: &str, v: &[f64]| {
                    super::finite(format!("{here}.{name}"), v)
                        .map(|_| v.iter().map(|x| *x as f32).collect::<Vec<f32>>())
                };
                let offset = number("uv_offset", &uv_offset.unwrap_or([0.0; 2]))?;
                let scale = number("uv_scale", &uv_scale.unwrap_or([1.0; 2]))?;
                let rotation = number("uv_rotation", &[uv_rotation.unwrap_or(0.0)])?[0];
                Texture::Map(Arc::new(ImageMap {
                    image,
                    srgb,
                    channels,
                    wrap: [wrap; 2],
                    filter: match filter.unwrap_or(FilterDesc::Bilinear) {
                        FilterDesc::Bilinear => Filter::Bilinear,
                        FilterDesc::Nearest => Filter::Nearest,
                    },
                    transform: UvTransform::offset_rotation_scale(
                        [offset[0], offset[1]],
                        rotation.to_radians(),
                        [scale[0], scale[1]],
                    ),
                    uv_set: uv_set.unwrap_or(0) as u8,
                }))
            }
            TextureDesc::Noise {
                scale,
                pattern,
                seed,
            } => Texture::Noise {
                perlin: Arc::new(Perlin::new(super::check_seed(
                    &format!("{here}.seed"),
                    *seed,
                )?)),
                scale: positive(&format!("{here}.scale"), *scale)?,
                pattern: match pattern {
                    NoisePatternDesc::Smooth => NoisePattern::Smooth,
                    NoisePatternDesc::Turbulence => NoisePattern::Turbulence,
                    NoisePatternDesc::Marble => NoisePattern::Marble,
                },
            },
        };
        self.textures.push(texture);
        let i = self.textures.len() as u32 - 1;
        self.index.insert(key, i);
        Ok(i)
    }
}

impl TextureTable<'_> {
    /// The image file `file` of field `field`, read once however many
    /// textures name it.
    fn image(
        &mut self,
        field: &str,
        file: &str,
        sources: &mut Vec<MeshSource>,
    ) -> Result<Arc<Image>, SceneError> {
        if let Some(image) = self.images.get(file) {
            return Ok(image.clone());
        }
        let image = Arc::new(read_image(field, self.base, file, sources)?);
        self.images.insert(file.to_string(), image.clone());
        Ok(image)
    }

    /// Whether texture `t` gives a colour, a scalar (one channel of an
    /// image), or either (grey noise, one colour).
    pub(crate) fn kind(&self, t: u32) -> TextureKind {
        self.kind_among(t, &mut HashMap::new())
    }

    /// [`kind`](Self::kind), each texture decided once: checkers nested
    /// many times over one texture are as many lookups, not 2ⁿ.
    fn kind_among(&self, t: u32, known: &mut HashMap<u32, TextureKind>) -> TextureKind {
        // Scaled textures are what they scale (a chain: no recursion).
        let mut t = t;
        while let Texture::Scaled { texture, .. } | Texture::Inverted { texture } =
            &self.textures[t as usize]
        {
            t = *texture;
        }
        if let Some(k) = known.get(&t) {
            return *k;
        }
        let kind = match &self.textures[t as usize] {
            Texture::Map(map) => match map.channels {
                Channels::Rgb => TextureKind::Color,
                Channels::One(_) => TextureKind::Scalar,
            },
            Texture::Scaled { .. } | Texture::Inverted { .. } => unreachable!("followed above"),
            // A checker (or a mix) of greys is grey: its squares decide
            // (chains of them are at most MAX_TEXTURE_DEPTH long).
            Texture::Checker { even, odd, .. }
            | Texture::UvChecker { even, odd, .. }
            | Texture::Mix {
                first: even,
                second: odd,
                ..
            } => match (self.kind_among(*even, known), self.kind_among(*odd, known)) {
                (TextureKind::Color, _) | (_, TextureKind::Color) => TextureKind::Color,
                (TextureKind::Scalar, _) | (_, TextureKind::Scalar) => TextureKind::Scalar,
                _ => TextureKind::Either,
            },
            Texture::Solid(c) if !(c.x == c.y && c.y == c.z) => TextureKind::Color,
            Texture::Solid(_) | Texture::Noise { .. } => TextureKind::Either,
        };
        known.insert(t, kind);
        kind
    }
}

/// What a texture gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TextureKind {
    /// A colour.
    Color,
    /// A scalar.
    Scalar,
    /// A grey that is either.
    Either,
}

/// A scale of field `field`: finite and above 0 in `f32`.
fn positive(field: &str, value: f64) -> Result<f32, SceneError> {
    super::finite(field, &[value])?;
    if !(value as f32 > 0.0) {
        return Err(invalid(
            field,
            format!("must be greater than 0, got {value}"),
        ));
    }
    Ok(value as f32)
}

/// How a scene names an image built into lumen, as `lumen:earth.png`.
pub const EMBEDDED_PREFIX: &str = "lumen:";

/// The images built into lumen (for the built-in scenes, which must render
/// anywhere without files): name and file bytes.
const EMBEDDED: &[(&str, &[u8])] = &[
    ("earth.png", include_bytes!("../../../assets/earth.png")),
    ("sky.hdr", include_bytes!("../../../assets/sky.hdr")),
];

/// The bytes of the built-in image `name`.
fn embedded(name: &str) -> Option<&'static [u8]> {
    EMBEDDED.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
}

/// Reads the image `file` (relative to `base`, or built in when it starts
/// with [`EMBEDDED_PREFIX`]) of field `field`, and records it in `sources`.
pub(crate) fn read_image(
    field: &str,
    base: &Path,
    file: &str,
    sources: &mut Vec<MeshSource>,
) -> Result<Image, SceneError> {
    let path = base.join(file);
    let fail = |message: String| invalid(field, message);
    let bytes = match file.strip_prefix(EMBEDDED_PREFIX) {
        Some(name) => embedded(name)
            .ok_or_else(|| {
                let known = EMBEDDED.iter().map(|(n, _)| *n);
                let show = |n: &str| format!("{EMBEDDED_PREFIX}{n}");
                fail(format!(
                    "{file}: lumen has no such image (it has {})",
                    hint::listing(name, known, show)
                ))
            })?
            .to_vec(),
        None => crate::input::read(&path, crate::input::MAX_IMAGE_BYTES)
            .map_err(|e| fail(format!("{}: {e}", path.display())))?,
    };
    let image =
        Image::decode(&bytes, &path.display().to_string()).map_err(|e| fail(e.to_string()))?;
    if !sources.iter().any(|s| s.file == file) {
        sources.push(MeshSource {
            file: file.to_string(),
            crc: crc32fast::hash(&bytes),
            len: bytes.len() as u64,
        });
    }
    Ok(image)
}
