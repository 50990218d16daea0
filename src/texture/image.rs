//! Images read from files: OpenEXR and Radiance HDR as linear RGB, PNG
//! and JPEG as the file stores them (8 or 16 bits a channel, with alpha),
//! decoded from sRGB, or read as linear data, at each lookup.

use crate::math::{floor_i64, wrap_index, Color};
use std::path::Path;

/// An image, row by row from the top: 8- and 16-bit images as they are
/// stored (RGBA, sRGB-encoded or linear data as the use says, decoded at
/// each lookup), floating-point ones as linear RGB.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    texels: Texels,
}

/// An image's texels as stored.
#[derive(Clone, Debug, PartialEq)]
enum Texels {
    /// 8 bits a channel, RGBA (grey and grey-alpha images expanded).
    Rgba8(Vec<[u8; 4]>),
    /// 16 bits a channel, RGBA.
    Rgba16(Vec<[u16; 4]>),
    /// Linear floating-point RGB (OpenEXR, Radiance HDR), opaque.
    Rgb32F(Vec<Color>),
}

/// Why an image file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be read or decoded.
    #[error("cannot read image {path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A texel is negative, infinite or NaN.
    #[error("image {path}: texel ({x}, {y}) is {value:?}; texels must be finite and not negative")]
    BadTexel {
        /// The file.
        path: String,
        /// Its column.
        x: usize,
        /// Its row from the top.
        y: usize,
        /// The texel.
        value: [f32; 3],
    },
}

/// Most texels read from an image file: 2^28, a 16384 × 16384 image (1 GiB
/// as 8-bit RGBA, 3 GiB as floating-point RGB).
pub const MAX_TEXELS: u64 = 1 << 28;

/// Bytes a texel of a decoded image of `color` takes as lumen keeps it.
fn kept_bytes(color: ::image::ColorType) -> u64 {
    use ::image::ColorType as C;
    match color {
        C::L8 | C::La8 | C::Rgb8 | C::Rgba8 => 4,
        C::L16 | C::La16 | C::Rgb16 | C::Rgba16 => 8,
        _ => 12,
    }
}

/// The bytes a texel of an 8-bit colour type takes, if it is one lumen
/// spreads to RGBA itself ([`decode_rgba8`]).
fn rgba8_source_bytes(color: ::image::ColorType) -> Option<usize> {
    use ::image::ColorType as C;
    Some(match color {
        C::L8 => 1,
        C::La8 => 2,
        C::Rgb8 => 3,
        C::Rgba8 => 4,
        _ => return None,
    })
}

/// An empty array with room for `n` texels, in huge pages where the
/// system has them (see [`crate::memory::huge_vec`]).
fn texel_room<T>(n: usize) -> Result<Vec<T>, String> {
    crate::memory::huge_vec(n).ok_or_else(|| format!("its {n} texels do not fit in memory"))
}

/// The texels of an 8-bit image of `channels` bytes a texel, decoded
/// straight into the RGBA array that keeps them and spread out in place:
/// a texture is allocated and written once, where decoding to `image`'s
/// buffer, converting it and collecting it took three of its size (a
/// 2048 × 2048 texture is 16 MB, and fresh pages cost a fault each).
fn decode_rgba8(
    decoder: impl ::image::ImageDecoder,
    channels: usize,
) -> Result<Vec<[u8; 4]>, String> {
    let (w, h) = ::image::ImageDecoder::dimensions(&decoder);
    let n = w as usize * h as usize;
    let mut texels: Vec<[u8; 4]> = texel_room(n)?;
    texels.resize(n, [0; 4]);
    let bytes = texels.as_flattened_mut();
    decoder
        .read_image(&mut bytes[..n * channels])
        .map_err(|e| e.to_string())?;
    // Grey goes to all three colour channels, as `image`'s conversions do.
    match channels {
        1 => spread::<1>(bytes, n, |s| [s[0], s[0], s[0], u8::MAX]),
        2 => spread::<2>(bytes, n, |s| [s[0], s[0], s[0], s[1]]),
        3 => spread::<3>(bytes, n, |s| [s[0], s[1], s[2], u8::MAX]),
        _ => {}
    }
    Ok(texels)
}

/// Spreads the `n` texels of `C` bytes packed at the start of `bytes` to
/// four bytes each (`rgba` of a texel's bytes), in place: from the end
/// back, a block at a time, each block's texels written where no texel
/// still to be read lies, so that the copy of a block is a plain loop over
/// two disjoint slices. The blocks shrink by a factor `C / 4`, so there
/// are few of them; the last few texels go one at a time.
fn spread<const C: usize>(bytes: &mut [u8], n: usize, rgba: impl Fn(&[u8]) -> [u8; 4]) {
    let mut end = n;
    while end > 0 {
        // Texels `start..end` go to bytes from `4 · start` on, past the
        // last source byte they read, `C · end`.
        let start = (C * end).div_ceil(4);
        if start >= end {
            for i in (0..end).rev() {
                let texel = rgba(&bytes[C * i..C * i + C]);
                bytes[4 * i..4 * i + 4].copy_from_slice(&texel);
            }
            return;
        }
        let (sources, targets) = bytes.split_at_mut(4 * start);
        let sources = sources[C * start..C * end].chunks_exact(C);
        let targets = targets[..4 * (end - start)].chunks_exact_mut(4);
        for (target, source) in targets.zip(sources) {
            target.copy_from_slice(&rgba(source));
        }
        end = start;
    }
}

/// The file extensions [`Image::read`] accepts.
pub const IMAGE_EXTENSIONS: &[&str] = &["exr", "hdr", "png", "jpg", "jpeg", "bmp"];

impl Image {
    /// A floating-point image of `width × height` linear texels, row by
    /// row from the top.
    ///
    /// # Panics
    /// If `texels` does not hold `width × height` texels or the image is
    /// empty.
    pub fn new(width: usize, height: usize, texels: Vec<Color>) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        Image {
            width,
            height,
            texels: Texels::Rgb32F(texels),
        }
    }

    /// An 8-bit RGBA image of `width × height` texels, row by row from the
    /// top.
    ///
    /// # Panics
    /// If `texels` does not hold `width × height` texels or the image is
    /// empty.
    pub fn from_rgba8(width: usize, height: usize, texels: Vec<[u8; 4]>) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        Image {
            width,
            height,
            texels: Texels::Rgba8(texels),
        }
    }

    /// The width and height an image file declares in its header (the
    /// texels are not decoded); an error says why it cannot be read or that
    /// it is empty.
    pub fn dimensions(path: &Path) -> Result<(u32, u32), String> {
        let bytes =
            crate::input::read(path, crate::input::MAX_IMAGE_BYTES).map_err(|e| e.to_string())?;
        let (w, h) = ::image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?
            .into_dimensions()
            .map_err(|e| e.to_string())?;
        if w == 0 || h == 0 {
            return Err("the image is empty".into());
        }
        Ok((w, h))
    }

    /// Reads an image file (`.exr`, `.hdr`, `.png`, `.jpg`/`.jpeg`, `.bmp`,
    /// by its content); see [`Image::decode`].
    pub fn read(path: &Path) -> Result<Image, ImageError> {
        let bytes = crate::input::read(path, crate::input::MAX_IMAGE_BYTES).map_err(|e| {
            ImageError::Read {
                path: path.display().to_string(),
                message: e.to_string(),
            }
        })?;
        Image::decode(&bytes, &path.display().to_string())
    }

    /// Decodes the bytes of an image file named `shown` (for messages).
    /// Floating-point images are kept as linear RGB (texels must be finite
    /// and not negative); 8- and 16-bit ones as they are stored, with their
    /// alpha (opaque where the file has none).
    pub fn decode(bytes: &[u8], shown: &str) -> Result<Image, ImageError> {
        use ::image::DynamicImage as D;
        let shown = shown.to_string();
        let fail = |message: String| ImageError::Read {
            path: shown.clone(),
            message,
        };
        let mut decoder = ::image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| fail(e.to_string()))?
            .into_decoder()
            .map_err(|e| fail(e.to_string()))?;
        // What the image will take is known from its header: a file of a few
        // hundred kilobytes can declare gigabytes of texels, so they are
        // counted and checked before any is decoded.
        let (w, h) = ::image::ImageDecoder::dimensions(&decoder);
        let texels = u64::from(w) * u64::from(h);
        if texels > MAX_TEXELS {
            return Err(fail(format!(
                "it declares {w}x{h} texels, more than the {MAX_TEXELS} (16384x16384) lumen reads from an image"
            )));
        }
        let color = ::image::ImageDecoder::color_type(&decoder);
        let kept = texels * kept_bytes(color);
        // 8-bit texels are decoded into the array that keeps them; others
        // into `image`'s buffer, then converted and collected.
        let source_bytes = rgba8_source_bytes(color);
        let peak = match source_bytes {
            Some(_) => kept,
            None => ::image::ImageDecoder::total_bytes(&decoder).saturating_add(2 * kept),
        };
        crate::memory::check(peak, "decoding it").map_err(|e| fail(e.to_string()))?;
        let mut limits = ::image::Limits::no_limits();
        limits.max_alloc = Some(peak);
        ::image::ImageDecoder::set_limits(&mut decoder, limits).map_err(|e| fail(e.to_string()))?;
        if w == 0 || h == 0 {
            return Err(fail("the image is empty".into()));
        }
        if let Some(channels) = source_bytes {
            return Ok(Image {
                width: w as usize,
                height: h as usize,
                texels: Texels::Rgba8(decode_rgba8(decoder, channels).map_err(fail)?),
            });
        }
        let decoded = D::from_decoder(decoder).map_err(|e| fail(e.to_string()))?;
        let (width, height) = (decoded.width() as usize, decoded.height() as usize);
        let texels = match decoded {
            D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
                Texels::Rgba8(decoded.into_rgba8().pixels().map(|p| p.0).collect())
            }
            D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
                let mut texels = texel_room(width * height).map_err(fail)?;
                texels.extend(decoded.into_rgba16().pixels().map(|p| p.0));
                Texels::Rgba16(texels)
            }
            _ => {
                let rgb = decoded.into_rgb32f();
                let mut texels = texel_room(width * height).map_err(fail)?;
                for (i, p) in rgb.pixels().enumerate() {
                    let value = p.0;
                    if value.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                        return Err(ImageError::BadTexel {
                            path: shown,
                            x: i % width,
                            y: i / width,
                            value,
                        });
                    }
                    texels.push(Color::from_array(value));
                }
                Texels::Rgb32F(texels)
            }
        };
        Ok(Image {
            width,
            height,
            texels,
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Whether the file stored floating-point (linear) values.
    pub fn is_float(&self) -> bool {
        matches!(self.texels, Texels::Rgb32F(_))
    }

    /// Whether some texel is not opaque.
    pub fn has_alpha(&self) -> bool {
        match &self.texels {
            Texels::Rgba8(t) => t.iter().any(|p| p[3] != u8::MAX),
            Texels::Rgba16(t) => t.iter().any(|p| p[3] != u16::MAX),
            Texels::Rgb32F(_) => false,
        }
    }

    /// Why the image cannot be a tangent-space normal map, if it cannot:
    /// such a map's normals point out of the surface (blue, z, above one
    /// half, but for rounding); an object-space map or a colour image has
    /// many that do not.
    pub fn normal_map_problem(&self) -> Option<String> {
        let n = self.width * self.height;
        // At most 65,536 texels looked at, spread over the image: the
        // fraction is then known to within a few tenths of a percent, and
        // the look takes a fraction of a millisecond. An odd step, so that
        // on an image a power of two wide the texels looked at do not
        // fall in a few columns.
        let step = match n.div_ceil(65_536) {
            0 | 1 => 1,
            step => step | 1,
        };
        let (mut looked, mut inward) = (0usize, 0usize);
        for i in (0..n).step_by(step) {
            let [_, _, b, _] = self.texel_rgba(i % self.width, i / self.width, false);
            looked += 1;
            inward += usize::from(b < 0.45);
        }
        let fraction = inward as f64 / looked as f64;
        (fraction > 0.05).then(|| {
            format!(
                "is not a tangent-space normal map: {:.0}% of its texels point into the \
                 surface (blue below one half); object-space normal maps are not supported",
                100.0 * fraction
            )
        })
    }

    /// Bytes held by the texels.
    pub fn heap_bytes(&self) -> usize {
        let n = self.width * self.height;
        n * match &self.texels {
            Texels::Rgba8(_) => 4,
            Texels::Rgba16(_) => 8,
            Texels::Rgb32F(_) => 12,
        }
    }

    /// The linear colour of the texel in column `x`, row `y` (from the
    /// top): integer images decoded from sRGB.
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Color {
        let i = y * self.width + x;
        match &self.texels {
            Texels::Rgba8(t) => {
                let lut = srgb8();
                let [r, g, b, _] = t[i];
                Color::new(lut[r as usize], lut[g as usize], lut[b as usize])
            }
            Texels::Rgba16(t) => {
                let [r, g, b, _] = t[i];
                Color::new(r.into(), g.into(), b.into()).map(|c| srgb_to_linear(c / 65535.0))
            }
            Texels::Rgb32F(t) => t[i],
        }
    }

    /// The texel in column `x`, row `y` as RGBA: integer images' colour
    /// channels decoded from sRGB when `srgb`, else scaled to [0, 1] (data
    /// such as roughness and normals); alpha always linear.
    #[inline]
    pub fn texel_rgba(&self, x: usize, y: usize, srgb: bool) -> [f32; 4] {
        let i = y * self.width + x;
        match &self.texels {
            Texels::Rgba8(t) => {
                let [r, g, b, a] = t[i];
                let alpha = f32::from(a) / 255.0;
                if srgb {
                    let lut = srgb8();
                    [lut[r as usize], lut[g as usize], lut[b as usize], alpha]
                } else {
                    [r, g, b, a].map(|c| f32::from(c) / 255.0)
                }
            }
            Texels::Rgba16(t) => {
                let [r, g, b, a] = t[i].map(|c| f32::from(c) / 65535.0);
                if srgb {
                    [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a]
                } else {
                    [r, g, b, a]
                }
            }
            Texels::Rgb32F(t) => {
                let c = t[i];
                [c.x, c.y, c.z, 1.0]
            }
        }
    }

    /// The colour at `(u, v)` of [0, 1]² (u rightwards, v downwards),
    /// interpolated bilinearly between the four nearest texel centres;
    /// wrapping around in u, clamped to the edge rows in v (an environment
    /// map's poles).
    #[inline]
    pub fn bilinear_wrap_u(&self, u: f32, v: f32) -> Color {
        self.bilinear(u, v, |y, h| y.clamp(0, h - 1))
    }

    /// As [`Image::bilinear_wrap_u`], but repeating in v too (a texture on
    /// a surface whose (u, v) run past [0, 1]).
    #[inline]
    pub fn bilinear_repeat(&self, u: f32, v: f32) -> Color {
        self.bilinear(u, v, wrap_index)
    }

    /// Bilinear interpolation, wrapping in u, with `row(y, height)` placing
    /// row index `y` (possibly outside the image) within it.
    #[inline]
    fn bilinear(&self, u: f32, v: f32, row: impl Fn(i64, i64) -> i64) -> Color {
        let x = u * self.width as f32 - 0.5;
        let y = v * self.height as f32 - 0.5;
        let (x0, y0) = (floor_i64(x), floor_i64(y));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let (w, h) = (self.width as i64, self.height as i64);
        let (xa, xb) = (wrap_index(x0, w), wrap_index(x0 + 1, w));
        let (ya, yb) = (row(y0, h), row(y0 + 1, h));
        let at = |x: i64, y: i64| self.texel(x as usize, y as usize);
        let top = at(xa, ya).lerp(at(xb, ya), fx);
        let bottom = at(xa, yb).lerp(at(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

/// The linear value of each 8-bit sRGB code, as `srgb_to_linear` of the
/// code over 255 (the same bits as decoding the whole image to floats).
fn srgb8() -> &'static [f32; 256] {
    static LUT: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    LUT.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

/// The sRGB transfer function, inverted: an encoded value in [0, 1] to
/// linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_lookup_interpolates_between_texel_centres_and_wraps_in_u() {
        let image = Image::new(
            2,
            2,
            vec![
                Color::new(0.0, 0.0, 0.0),
                Color::new(1.0, 0.0, 0.0),
                Color::new(0.0, 2.0, 0.0),
                Color::new(1.0, 2.0, 0.0),
            ],
        );
        // Texel centres give the texels.
        assert_eq!(image.bilinear_wrap_u(0.25, 0.25), Color::ZERO);
        assert_eq!(image.bilinear_wrap_u(0.75, 0.75), Color::new(1.0, 2.0, 0.0));
        // Halfway between centres, in u and in v.
        assert_eq!(image.bilinear_wrap_u(0.5, 0.25), Color::new(0.5, 0.0, 0.0));
        assert_eq!(image.bilinear_wrap_u(0.25, 0.5), Color::new(0.0, 1.0, 0.0));
        // Across the seam u = 0 ≡ 1, the two columns blend again; v is
        // clamped at the edges.
        assert_eq!(image.bilinear_wrap_u(0.0, 0.0), Color::new(0.5, 0.0, 0.0));
        assert_eq!(image.bilinear_wrap_u(1.0, 1.0), Color::new(0.5, 2.0, 0.0));
    }

    #[test]
    fn srgb_decoding_matches_the_standard() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
    }

    /// Spreading in place gives, for every count of texels (so every
    /// arrangement of blocks, down to the last texels taken one by one),
    /// what spreading into a second array gives.
    #[test]
    fn texels_spread_in_place_as_into_another_array() {
        fn check<const C: usize>(rgba: impl Fn(&[u8]) -> [u8; 4] + Copy) {
            for n in 0..300 {
                let mut bytes: Vec<u8> = (0..4 * n).map(|i| (i * 37 % 251) as u8).collect();
                let want: Vec<u8> = bytes[..C * n].chunks_exact(C).flat_map(rgba).collect();
                spread::<C>(&mut bytes, n, rgba);
                assert_eq!(bytes, want, "{C} bytes a texel, {n} texels");
            }
        }
        check::<1>(|s| [s[0], s[0], s[0], 255]);
        check::<2>(|s| [s[0], s[0], s[0], s[1]]);
        check::<3>(|s| [s[0], s[1], s[2], 255]);
    }

    /// Every 8-bit colour type, in each format that holds it, decodes to
    /// the texels `image`'s own conversion to RGBA gives.
    #[test]
    fn eight_bit_images_decode_to_what_images_conversion_gives() {
        use ::image::{ColorType as C, DynamicImage, ImageFormat as F};
        let (w, h) = (37u32, 11u32);
        let value = |i: u32, k: u32| ((i * 7 + k * 91 + i / 5 * 13) % 256) as u8;
        let bytes = |channels: u32| -> Vec<u8> {
            (0..w * h * channels)
                .map(|j| value(j / channels, j % channels))
                .collect()
        };
        let images = [
            (
                C::L8,
                DynamicImage::ImageLuma8(::image::ImageBuffer::from_raw(w, h, bytes(1)).unwrap()),
            ),
            (
                C::La8,
                DynamicImage::ImageLumaA8(::image::ImageBuffer::from_raw(w, h, bytes(2)).unwrap()),
            ),
            (
                C::Rgb8,
                DynamicImage::ImageRgb8(::image::ImageBuffer::from_raw(w, h, bytes(3)).unwrap()),
            ),
            (
                C::Rgba8,
                DynamicImage::ImageRgba8(::image::ImageBuffer::from_raw(w, h, bytes(4)).unwrap()),
            ),
        ];
        let mut checked = 0;
        for (color, image) in &images {
            for format in [F::Png, F::Jpeg, F::Bmp] {
                let mut file = std::io::Cursor::new(Vec::new());
                if image.write_to(&mut file, format).is_err() {
                    continue; // a type the format cannot hold
                }
                let file = file.into_inner();
                let reference = ::image::load_from_memory(&file).unwrap();
                let want: Vec<[u8; 4]> = reference.to_rgba8().pixels().map(|p| p.0).collect();
                let got = Image::decode(&file, "t").unwrap();
                assert_eq!((got.width(), got.height()), (w as usize, h as usize));
                let Texels::Rgba8(got) = &got.texels else {
                    panic!("{color:?} as {format:?}: not 8-bit RGBA");
                };
                assert_eq!(got, &want, "{color:?} as {format:?}");
                checked += 1;
            }
        }
        // PNG holds all four; JPEG and BMP some.
        assert!(checked >= 6, "{checked}");
    }
}

#[cfg(test)]
mod bomb_tests {
    use super::*;

    /// A PNG chunk: length, type, data, CRC.
    fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        let mut crc = crc32fast::Hasher::new();
        crc.update(kind);
        crc.update(data);
        c.extend_from_slice(&crc.finalize().to_be_bytes());
        c
    }

    /// A PNG of a few dozen bytes declaring a `w × h` greyscale image.
    fn png_declaring(w: u32, h: u32) -> Vec<u8> {
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = w.to_be_bytes().to_vec();
        ihdr.extend_from_slice(&h.to_be_bytes());
        ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
        png.extend(chunk(b"IHDR", &ihdr));
        // An empty zlib stream: the texels the header promises are missing.
        png.extend(chunk(
            b"IDAT",
            &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
        ));
        png.extend(chunk(b"IEND", &[]));
        png
    }

    #[test]
    fn images_declaring_too_many_texels_are_refused_from_their_header() {
        let e = Image::decode(&png_declaring(23000, 23000), "bomb.png").unwrap_err();
        let e = e.to_string();
        assert!(
            e.contains("bomb.png") && e.contains("23000x23000 texels"),
            "{e}"
        );
        let hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n";
        let e = Image::decode(hdr, "sky.hdr").unwrap_err().to_string();
        assert!(e.contains("30000x30000 texels"), "{e}");
        // At the limit the header passes, and the missing texels are what
        // is refused.
        let e = Image::decode(&png_declaring(16384, 16384), "big.png").unwrap_err();
        assert!(!e.to_string().contains("texels, more than"), "{e}");
    }
}
