//! The diffuse material: a matte surface of the notes, bouncing by one of
//! four models and attenuating in one of two ways.

use super::param::{ColorDesc, ColorParam, ColorRange, Invalid, Textures};
use super::{Kind, Material};
use crate::bsdf::diffuse::{Attenuation, BookDiffuse, BounceModel};
use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;
use serde::{Deserialize, Serialize};

material_desc! {
    /// A matte surface.
    pub struct DiffuseDesc {
        /// Reflected fraction per channel, each in [0, 1], or a texture
        /// giving it.
        pub albedo: ColorDesc,
        /// Bounce direction model.
        #[serde(default)]
        pub bounce: BounceDesc,
        /// How the albedo is applied.
        #[serde(default)]
        pub attenuation: AttenuationDesc,
    }
}

/// Diffuse bounce model (see [`BounceModel`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BounceDesc {
    /// Random point on the surface of a cube around p + N.
    Cube,
    /// Random point inside the unit sphere at p + N.
    SphereVolume,
    /// Random point on the surface of the unit sphere at p + N.
    #[default]
    Lambertian,
    /// Uniform direction in the hemisphere around N.
    Hemisphere,
}

/// Diffuse attenuation form (see [`Attenuation`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AttenuationDesc {
    /// Multiply the colour by the albedo.
    #[default]
    Scale,
    /// Absorb rays with probability 1 − p, p = the albedo's largest
    /// component; survivors are multiplied by albedo / p.
    Absorb,
}

impl DiffuseDesc {
    /// A Lambertian surface of albedo `albedo` (a colour or a texture).
    pub fn new(albedo: impl Into<ColorDesc>) -> Self {
        DiffuseDesc {
            albedo: albedo.into(),
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        Ok(Material::new(Kind::Diffuse(Diffuse {
            albedo: textures.color(&format!("{field}.albedo"), &self.albedo, ColorRange::Unit)?,
            bounce: match self.bounce {
                BounceDesc::Cube => BounceModel::Cube,
                BounceDesc::SphereVolume => BounceModel::SphereVolume,
                BounceDesc::Lambertian => BounceModel::Lambertian,
                BounceDesc::Hemisphere => BounceModel::Hemisphere,
            },
            attenuation: match self.attenuation {
                AttenuationDesc::Scale => Attenuation::Scale,
                AttenuationDesc::Absorb => Attenuation::Absorb,
            },
        })))
    }
}

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
