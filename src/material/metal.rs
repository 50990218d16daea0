//! The metal material of the notes: a mirror tinted by an albedo and
//! blurred by fuzz.

use super::param::{self, ColorDesc, ColorParam, ColorRange, Invalid, Range, Textures};
use super::{Kind, Material};
use crate::bsdf::metal::FuzzyMetal;
use crate::geometry::HitRecord;
use crate::texture::Texture;

material_desc! {
    /// A reflective metal of the notes.
    pub struct MetalDesc {
        /// Reflection colour, each channel in [0, 1], or a texture giving
        /// it.
        pub albedo: ColorDesc,
        /// Blur of the reflection, in [0, 1].
        #[serde(default)]
        pub fuzz: f64,
    }
}

impl MetalDesc {
    /// A metal of colour `albedo` blurred by `fuzz`.
    pub fn new(albedo: impl Into<ColorDesc>, fuzz: f64) -> Self {
        MetalDesc {
            albedo: albedo.into(),
            fuzz,
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let fuzz = param::number(&format!("{field}.fuzz"), self.fuzz, Range::Unit)?;
        Ok(Material::new(Kind::Metal(Metal {
            albedo: textures.color(&format!("{field}.albedo"), &self.albedo, ColorRange::Unit)?,
            fuzz,
        })))
    }
}

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
