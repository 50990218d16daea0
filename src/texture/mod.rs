//! Textures: colours that vary over a surface, looked up where a ray hits
//! it. A closed set, as in *Ray Tracing: The Next Week*: one colour, a 3-D
//! checker, an image wrapped by the surface's (u, v), and Perlin noise
//! (smooth, turbulent, marble). Images are also what environment maps are
//! made of.

pub mod image;
pub mod map;
pub mod noise;

pub use image::{Image, ImageError};
pub use map::{Channels, Filter, ImageMap, UvTransform, Wrap};
pub use noise::Perlin;

use crate::math::{Color, Point3};
use std::sync::Arc;

/// Where a texture is looked up: the surface's two sets of texture
/// coordinates and the point in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoords {
    /// The first texture coordinates (v up the image).
    pub uv: [f32; 2],
    /// The second set (a mesh's `TEXCOORD_1`; the first elsewhere).
    pub uv1: [f32; 2],
    /// The point.
    pub point: Point3,
}

impl TexCoords {
    /// Coordinates `uv` (both sets) at `point`.
    #[inline(always)]
    pub fn new(uv: [f32; 2], point: Point3) -> TexCoords {
        TexCoords { uv, uv1: uv, point }
    }
}

/// Octaves summed by turbulence, as in the book.
const OCTAVES: u32 = 7;

/// A texture. Textures that refer to others (the checker's two squares) do
/// so by index into the scene's table of textures.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// One colour everywhere.
    Solid(Color),
    /// Alternating cubes of side `1 / inverse_scale` in space (not on the
    /// surface): texture `even` where ⌊x/s⌋ + ⌊y/s⌋ + ⌊z/s⌋ is even, `odd`
    /// elsewhere.
    Checker {
        /// 1 / the side of a cube.
        inverse_scale: f32,
        /// The texture of the even cubes.
        even: u32,
        /// The texture of the odd cubes.
        odd: u32,
    },
    /// Squares by the surface's (u, v): texture `even` where ⌊s⌋ + ⌊t⌋ is
    /// even, (s, t) = scale · (u, v) + offset, `odd` elsewhere.
    UvChecker {
        /// Factors on u and v.
        scale: [f32; 2],
        /// Added after scaling.
        offset: [f32; 2],
        /// The texture of the even squares.
        even: u32,
        /// The texture of the odd squares.
        odd: u32,
    },
    /// An image, by the surface's (u, v): u rightwards, v upwards (the
    /// image's bottom row at v = 0), wrapped and filtered as the map says
    /// (by default repeating outside [0, 1]² and blended bilinearly).
    Map(Arc<ImageMap>),
    /// Another texture of the table times a colour.
    Scaled {
        /// The texture scaled.
        texture: u32,
        /// The factor.
        factor: Color,
    },
    /// Two textures of the table blended: (1 − a)·first + a·second, a the
    /// (scalar) texture `amount`.
    Mix {
        /// What amount 0 shows.
        first: u32,
        /// What amount 1 shows.
        second: u32,
        /// How much of `second`.
        amount: u32,
    },
    /// One minus another texture of the table (a gloss map read as a
    /// roughness).
    Inverted {
        /// The texture inverted.
        texture: u32,
    },
    /// Perlin noise, grey, over the point in space scaled by `scale`.
    Noise {
        /// The noise function.
        perlin: Arc<Perlin>,
        /// Frequency: the point is multiplied by it.
        scale: f32,
        /// How the noise becomes a colour.
        pattern: NoisePattern,
    },
}

/// How [`Texture::Noise`] turns noise into a grey level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NoisePattern {
    /// ½(1 + noise(s·p)): soft blotches.
    Smooth,
    /// turbulence(s·p): a sum of seven octaves, folded to be positive.
    Turbulence,
    /// ½(1 + sin(s·z + 10 turbulence(s·p))): veined marble along z.
    Marble,
}

impl Texture {
    /// The colour at `at`; textures that refer to others find them in
    /// `table`. A scalar texture (one channel of an image) gives its value
    /// in all three channels.
    pub fn value(&self, table: &[Texture], at: &TexCoords) -> Color {
        let p = at.point;
        match self {
            Texture::Solid(c) => *c,
            Texture::Checker {
                inverse_scale,
                even,
                odd,
            } => {
                let cell = (*inverse_scale * p).floor();
                let sum = cell.x as i64 + cell.y as i64 + cell.z as i64;
                let which = if sum.rem_euclid(2) == 0 { even } else { odd };
                table[*which as usize].value(table, at)
            }
            Texture::UvChecker {
                scale,
                offset,
                even,
                odd,
            } => {
                let s = (scale[0] * at.uv[0] + offset[0]).floor() as i64;
                let t = (scale[1] * at.uv[1] + offset[1]).floor() as i64;
                let which = if (s + t).rem_euclid(2) == 0 {
                    even
                } else {
                    odd
                };
                table[*which as usize].value(table, at)
            }
            Texture::Map(map) => {
                let [r, g, b, a] = map.rgba(at);
                match map.channels {
                    Channels::Rgb => Color::new(r, g, b),
                    Channels::One(c) => Color::splat([r, g, b, a][c as usize]),
                }
            }
            Texture::Scaled { texture, factor } => {
                table[*texture as usize].value(table, at) * *factor
            }
            Texture::Inverted { texture } => Color::ONE - table[*texture as usize].value(table, at),
            Texture::Mix {
                first,
                second,
                amount,
            } => {
                let a = table[*amount as usize].value(table, at).x;
                let first = table[*first as usize].value(table, at);
                first + (table[*second as usize].value(table, at) - first) * a
            }
            Texture::Noise {
                perlin,
                scale,
                pattern,
            } => Color::splat(match pattern {
                NoisePattern::Smooth => 0.5 * (1.0 + perlin.noise(*scale * p)),
                NoisePattern::Turbulence => perlin.turbulence(*scale * p, OCTAVES),
                NoisePattern::Marble => {
                    let s = *scale * p;
                    0.5 * (1.0 + (s.z + 10.0 * perlin.turbulence(s, OCTAVES)).sin())
                }
            }),
        }
    }

    /// Whether the texture depends on the surface's (u, v) (directly or
    /// through a texture it refers to).
    pub fn uses_uv(&self, table: &[Texture]) -> bool {
        // Each texture looked at once, without recursion: a checker whose
        // squares are one texture, nested, would be visited 2^depth times
        // by following both references of each.
        let mut seen = std::collections::HashSet::new();
        let mut todo = vec![self];
        while let Some(t) = todo.pop() {
            let refs = match t {
                Texture::Map(_) | Texture::UvChecker { .. } => return true,
                Texture::Checker { even, odd, .. } => [Some(*even), Some(*odd), None],
                Texture::Mix {
                    first,
                    second,
                    amount,
                } => [Some(*first), Some(*second), Some(*amount)],
                Texture::Scaled { texture, .. } | Texture::Inverted { texture } => {
                    [Some(*texture), None, None]
                }
                Texture::Solid(_) | Texture::Noise { .. } => [None, None, None],
            };
            for r in refs.into_iter().flatten() {
                if seen.insert(r) {
                    todo.push(&table[r as usize]);
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn a_checker_alternates_cubes_in_space() {
        let table = [
            Texture::Solid(Color::X),
            Texture::Solid(Color::Y),
            Texture::Checker {
                inverse_scale: 2.0,
                even: 0,
                odd: 1,
            },
        ];
        let at = |x: f32, y: f32, z: f32| {
            table[2].value(&table, &TexCoords::new([0.0, 0.0], Vec3::new(x, y, z)))
        };
        // Cubes of side 0.5: (0.1, 0.1, 0.1) is in cube (0, 0, 0), even.
        assert_eq!(at(0.1, 0.1, 0.1), Color::X);
        assert_eq!(at(0.6, 0.1, 0.1), Color::Y);
        assert_eq!(at(0.6, 0.6, 0.1), Color::X);
        // Negative coordinates floor downwards: cube (−1, 0, 0), odd.
        assert_eq!(at(-0.1, 0.1, 0.1), Color::Y);
        assert_eq!(at(-0.1, -0.1, 0.1), Color::X);
        assert!(!table[2].uses_uv(&table));
    }

    #[test]
    fn a_checkerboard_alternates_squares_of_u_and_v() {
        let table = [
            Texture::Solid(Color::X),
            Texture::Solid(Color::Y),
            Texture::UvChecker {
                scale: [4.0, 2.0],
                offset: [0.5, 0.0],
                even: 0,
                odd: 1,
            },
        ];
        let at = |u: f32, v: f32| table[2].value(&table, &TexCoords::new([u, v], Vec3::ZERO));
        // s = 4u + ½, t = 2v: (0.05, 0.1) is in square (0, 0), even.
        assert_eq!(at(0.05, 0.1), Color::X);
        assert_eq!(at(0.2, 0.1), Color::Y);
        assert_eq!(at(0.2, 0.6), Color::X);
        // Below zero, squares floor downwards.
        assert_eq!(at(-0.2, 0.1), Color::Y);
        assert!(table[2].uses_uv(&table));
    }

    #[test]
    fn an_image_is_looked_up_with_v_upwards_and_repeats() {
        // Bottom row red, top row blue.
        let image = Image::new(1, 2, vec![Color::Z, Color::X]);
        let t = Texture::Map(Arc::new(ImageMap::color(Arc::new(image))));
        let at = |u: f32, v: f32| t.value(&[], &TexCoords::new([u, v], Vec3::ZERO));
        assert_eq!(at(0.5, 0.25), Color::X);
        assert_eq!(at(0.5, 0.75), Color::Z);
        assert_eq!(at(3.5, 1.25), Color::X);
        assert!(t.uses_uv(&[]));
    }

    #[test]
    fn noise_patterns_are_grey_and_in_range() {
        let perlin = Arc::new(Perlin::new(0));
        for pattern in [
            NoisePattern::Smooth,
            NoisePattern::Turbulence,
            NoisePattern::Marble,
        ] {
            let t = Texture::Noise {
                perlin: perlin.clone(),
                scale: 4.0,
                pattern,
            };
            for i in 0..500 {
                let p = Vec3::new(i as f32 * 0.37, (i % 7) as f32 * 0.9, i as f32 * -0.11);
                let c = t.value(&[], &TexCoords::new([0.0, 0.0], p));
                assert!(c.x == c.y && c.y == c.z, "{pattern:?}: grey");
                assert!((0.0..=2.0).contains(&c.x), "{pattern:?}: {c:?}");
            }
        }
    }
}
