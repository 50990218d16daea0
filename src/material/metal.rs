//! The metal material of the notes: a mirror tinted by an albedo and
//! blurred by fuzz.

use super::ColorParam;
use crate::bsdf::metal::FuzzyMetal;
use crate::geometry::HitRecord;
use crate::texture::Texture;

/// A reflective metal surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
    /// Colour of the reflection.
    pub albedo: ColorParam,
    /// Radius in [0, 1] of the sphere around the tip of the reflected direction
    /// from which the actual direction is drawn; 0 is a perfect mirror.
    pub fuzz: f32,
}

impl Metal {
    /// The lobe at `hit`.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> FuzzyMetal {
        FuzzyMetal {
            albedo: self.albedo.albedo_at(hit, textures),
            fuzz: self.fuzz,
        }
    }
}
