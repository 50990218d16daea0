//! Images read from files, as linear RGB: OpenEXR and Radiance HDR as they
//! are stored, PNG and JPEG decoded from sRGB.

use crate::math::Color;
use std::path::Path;

/// An image of linear RGB texels, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    texels: Vec<Color>,
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

/// The file extensions [`Image::read`] accepts.
pub const IMAGE_EXTENSIONS: &[&str] = &["exr", "hdr", "png", "jpg", "jpeg"];

impl Image {
    /// An image of `width × height` texels, row by row from the top.
    ///
    /// # Panics
    /// If `texels` does not hold `width × height` texels or the image is
    /// empty.
    pub fn new(width: usize, height: usize, texels: Vec<Color>) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        Image {
            width,
            height,
            texels,
        }
    }

    /// Reads an image file (`.exr`, `.hdr`, `.png`, `.jpg`/`.jpeg`, by its
    /// content); see [`Image::decode`].
    pub fn read(path: &Path) -> Result<Image, ImageError> {
        let bytes = std::fs::read(path).map_err(|e| ImageError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Image::decode(&bytes, &path.display().to_string())
    }

    /// Decodes the bytes of an image file named `shown` (for messages).
    /// Floating-point images are taken as linear, 8- and 16-bit ones as
    /// sRGB-encoded; alpha is ignored. Texels must be finite and not
    /// negative.
    pub fn decode(bytes: &[u8], shown: &str) -> Result<Image, ImageError> {
        let shown = shown.to_string();
        let fail = |message: String| ImageError::Read {
            path: shown.clone(),
            message,
        };
        let decoded = ::image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| fail(e.to_string()))?
            .decode()
            .map_err(|e| fail(e.to_string()))?;
        let linear = matches!(
            decoded,
            ::image::DynamicImage::ImageRgb32F(_) | ::image::DynamicImage::ImageRgba32F(_)
        );
        let rgb = decoded.into_rgb32f();
        let (width, height) = (rgb.width() as usize, rgb.height() as usize);
        if width == 0 || height == 0 {
            return Err(fail("the image is empty".into()));
        }
        let mut texels = Vec::with_capacity(width * height);
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
            let c = Color::from_array(value);
            texels.push(if linear { c } else { c.map(srgb_to_linear) });
        }
        Ok(Image::new(width, height, texels))
    }

    /// The image with every texel multiplied by `c`.
    pub fn scaled(&self, c: Color) -> Image {
        Image::new(
            self.width,
            self.height,
            self.texels.iter().map(|t| *t * c).collect(),
        )
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The texel in column `x`, row `y` (from the top).
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Color {
        self.texels[y * self.width + x]
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
        self.bilinear(u, v, i64::rem_euclid)
    }

    /// Bilinear interpolation, wrapping in u, with `row(y, height)` placing
    /// row index `y` (possibly outside the image) within it.
    #[inline]
    fn bilinear(&self, u: f32, v: f32, row: impl Fn(i64, i64) -> i64) -> Color {
        let x = u * self.width as f32 - 0.5;
        let y = v * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (w, h) = (self.width as i64, self.height as i64);
        let (xa, xb) = ((x0 as i64).rem_euclid(w), (x0 as i64 + 1).rem_euclid(w));
        let (ya, yb) = (row(y0 as i64, h), row(y0 as i64 + 1, h));
        let at = |x: i64, y: i64| self.texel(x as usize, y as usize);
        let top = at(xa, ya).lerp(at(xb, ya), fx);
        let bottom = at(xa, yb).lerp(at(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

/// The sRGB transfer function, inverted: an encoded value in [0, 1] to
/// linear light.
fn srgb_to_linear(c: f32) -> f32 {
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
}
