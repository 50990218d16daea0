//! The diffuse material: a matte surface of the notes, bouncing by one of
//! four models and attenuating in one of two ways.

use super::ColorParam;
use crate::bsdf::diffuse::{Attenuation, BookDiffuse, BounceModel};
use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;

/// A diffuse (matte) surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Fraction of light reflected per channel.
    pub albedo: ColorParam,
    /// How bounce directions are chosen.
    pub bounce: BounceModel,
    /// How the albedo is applied.
    pub attenuation: Attenuation,
}

impl Diffuse {
    /// A Lambertian surface of constant albedo that scales by it.
    pub fn lambertian(albedo: Color) -> Self {
        Self {
            albedo: ColorParam::Const(albedo),
            bounce: BounceModel::Lambertian,
            attenuation: Attenuation::Scale,
        }
    }

    /// The lobe at `hit`.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> BookDiffuse {
        BookDiffuse {
            albedo: self.albedo.albedo_at(hit, textures),
            bounce: self.bounce,
            attenuation: self.attenuation,
        }
    }
}
