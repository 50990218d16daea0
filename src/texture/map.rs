//! An image mapped onto a surface as glTF and the other formats map one:
//! by a chosen set of texture coordinates, moved by an affine transform
//! (`KHR_texture_transform`), wrapped (repeat, clamp, mirror) and filtered
//! (nearest or bilinear) per axis, its colour decoded from sRGB or read as
//! linear data, and all four channels or one of them.

use super::image::Image;
use super::TexCoords;
use crate::math::floor_i64;
use std::sync::Arc;

/// What a coordinate outside [0, 1] reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image again (glTF `REPEAT`).
    #[default]
    Repeat,
    /// The edge texel (glTF `CLAMP_TO_EDGE`).
    Clamp,
    /// The image mirrored every other time (glTF `MIRRORED_REPEAT`).
    Mirror,
}

impl Wrap {
    /// Texel index `i` (possibly outside) placed in an image `n` texels
    /// wide.
    #[inline]
    fn place(self, i: i64, n: i64) -> usize {
        // Inside the image every mode leaves it where it is.
        if (0..n).contains(&i) {
            return i as usize;
        }
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        }) as usize
    }
}

/// How texels are blended where a lookup falls between their centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// The four nearest, weighted by distance.
    #[default]
    Bilinear,
}

/// An affine map of texture coordinates in the image's own convention
/// (u rightwards, v downwards from the top-left corner, as glTF has them):
/// (u′, v′) = (a u + b v + c, d u + e v + f).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// The rows (a, b, c) and (d, e, f).
    pub rows: [[f32; 3]; 2],
}

impl UvTransform {
    /// No change.
    pub const IDENTITY: UvTransform = UvTransform {
        rows: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    };

    /// `KHR_texture_transform`'s offset, rotation (radians,
    /// counter-clockwise as the image is seen) and scale: T · R · S.
    pub fn offset_rotation_scale(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> UvTransform {
        let (s, c) = rotation.sin_cos();
        UvTransform {
            rows: [
                [c * scale[0], s * scale[1], offset[0]],
                [-s * scale[0], c * scale[1], offset[1]],
            ],
        }
    }

    /// Whether it changes nothing.
    pub fn is_identity(&self) -> bool {
        *self == UvTransform::IDENTITY
    }

    #[inline]
    fn apply(&self, [u, v]: [f32; 2]) -> [f32; 2] {
        let [r, s] = &self.rows;
        [r[0] * u + r[1] * v + r[2], s[0] * u + s[1] * v + s[2]]
    }
}

/// The channels a map gives.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Channels {
    /// Red, green and blue: a colour.
    #[default]
    Rgb,
    /// One channel (0 red, 1 green, 2 blue, 3 alpha) in all three: a
    /// scalar.
    One(u8),
}

/// An image mapped onto surfaces.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageMap {
    /// The image, shared by every map of it.
    pub image: Arc<Image>,
    /// Decode the colour channels from sRGB (colours) or read them as they
    /// are (data: roughness, normals, masks). Floating-point images are
    /// linear either way.
    pub srgb: bool,
    /// Which channels it gives.
    pub channels: Channels,
    /// Wrapping across u and across v.
    pub wrap: [Wrap; 2],
    /// Filtering.
    pub filter: Filter,
    /// The transform of the texture coordinates.
    pub transform: UvTransform,
    /// Which set of texture coordinates (0 or 1).
    pub uv_set: u8,
}

impl ImageMap {
    /// `image` as a colour, sRGB-decoded, repeating and bilinear, by the
    /// first coordinates untransformed.
    pub fn color(image: Arc<Image>) -> ImageMap {
        ImageMap {
            image,
            srgb: true,
            channels: Channels::Rgb,
            wrap: [Wrap::Repeat; 2],
            filter: Filter::Bilinear,
            transform: UvTransform::IDENTITY,
            uv_set: 0,
        }
    }

    /// The RGBA value at `at`, every channel filtered.
    #[inline]
    pub fn rgba(&self, at: &TexCoords) -> [f32; 4] {
        let [u, v] = if self.uv_set == 0 { at.uv } else { at.uv1 };
        // lumen's v runs up the image; the transform's down.
        let [s, t] = self.transform.apply([u, 1.0 - v]);
        let image = &*self.image;
        let (w, h) = (image.width() as i64, image.height() as i64);
        let [wu, wv] = self.wrap;
        let x = s * w as f32;
        let y = t * h as f32;
        // Far beyond any image: a coordinate that lost its precision.
        if !(x.abs() < 1e9 && y.abs() < 1e9) {
            return [0.0; 4];
        }
        let at = |x: i64, y: i64| image.texel_rgba(wu.place(x, w), wv.place(y, h), self.srgb);
        match self.filter {
            Filter::Nearest => at(floor_i64(x), floor_i64(y)),
            Filter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (xa, ya) = (floor_i64(x), floor_i64(y));
                let (fx, fy) = (x - xa as f32, y - ya as f32);
                let (p, q, r, s) = (
                    at(xa, ya),
                    at(xa + 1, ya),
                    at(xa, ya + 1),
                    at(xa + 1, ya + 1),
                );
                // As `Vec3::lerp` blends: the same bits as a colour image's
                // own bilinear lookup.
                let lerp = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
                std::array::from_fn(|c| {
                    let top = lerp(p[c], q[c], fx);
                    let bottom = lerp(r[c], s[c], fx);
                    lerp(top, bottom, fy)
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn coords(u: f32, v: f32) -> TexCoords {
        TexCoords {
            uv: [u, v],
            uv1: [1.0 - u, 1.0 - v],
            point: Vec3::ZERO,
        }
    }

    /// A 2 × 1 image: red, then green at half alpha.
    fn two_texels() -> Arc<Image> {
        Arc::new(Image::from_rgba8(
            2,
            1,
            vec![[255, 0, 0, 255], [0, 255, 0, 128]],
        ))
    }

    #[test]
    fn wrap_modes_place_indices_as_gltf_defines_them() {
        let n = 3;
        let placed = |w: Wrap| (-4..7).map(|i| w.place(i, n)).collect::<Vec<_>>();
        assert_eq!(placed(Wrap::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0]);
        assert_eq!(placed(Wrap::Clamp), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2]);
        assert_eq!(placed(Wrap::Mirror), [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
    }

    #[test]
    fn nearest_reads_texels_and_alpha_and_bilinear_blends_them() {
        let map = ImageMap {
            filter: Filter::Nearest,
            srgb: false,
            ..ImageMap::color(two_texels())
        };
        assert_eq!(map.rgba(&coords(0.25, 0.5)), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(map.rgba(&coords(0.75, 0.5)), [0.0, 1.0, 0.0, 128.0 / 255.0]);
        let blend = ImageMap {
            filter: Filter::Bilinear,
            wrap: [Wrap::Clamp; 2],
            ..map.clone()
        };
        let mid = blend.rgba(&coords(0.5, 0.5));
        assert!((mid[0] - 0.5).abs() < 1e-6 && (mid[1] - 0.5).abs() < 1e-6);
        // Clamped: beyond the right edge stays green.
        assert_eq!(blend.rgba(&coords(1.7, 0.5))[1], 1.0);
    }

    #[test]
    fn srgb_decodes_colour_and_leaves_alpha() {
        let map = ImageMap {
            filter: Filter::Nearest,
            ..ImageMap::color(two_texels())
        };
        let [_, g, _, a] = map.rgba(&coords(0.75, 0.5));
        assert_eq!(g, 1.0);
        assert_eq!(a, 128.0 / 255.0);
        let grey = ImageMap {
            filter: Filter::Nearest,
            ..ImageMap::color(Arc::new(Image::from_rgba8(
                1,
                1,
                vec![[128, 128, 128, 128]],
            )))
        };
        let [r, ..] = grey.rgba(&coords(0.5, 0.5));
        assert!((r - super::super::image::srgb_to_linear(128.0 / 255.0)).abs() < 1e-7);
    }

    #[test]
    fn the_second_coordinates_and_the_transform_move_the_lookup() {
        let map = ImageMap {
            filter: Filter::Nearest,
            srgb: false,
            uv_set: 1,
            ..ImageMap::color(two_texels())
        };
        // uv1 = 1 − u: u = 0.25 reads the right texel.
        assert_eq!(map.rgba(&coords(0.25, 0.5))[1], 1.0);
        // An offset of half the image moves the left texel right.
        let moved = ImageMap {
            uv_set: 0,
            transform: UvTransform::offset_rotation_scale([0.5, 0.0], 0.0, [1.0, 1.0]),
            ..map
        };
        assert_eq!(moved.rgba(&coords(0.25, 0.5))[1], 1.0);
        // A quarter turn then a scale: (u, v) ↦ (v, −u) here.
        let t =
            UvTransform::offset_rotation_scale([0.0, 0.0], std::f32::consts::FRAC_PI_2, [1.0, 1.0]);
        let [a, b] = t.apply([0.3, 0.6]);
        assert!((a - 0.6).abs() < 1e-6 && (b + 0.3).abs() < 1e-6);
    }
}
