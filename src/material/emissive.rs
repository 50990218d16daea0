//! Emission: the light a surface gives off, such as a lamp's shade, a
//! window or the light quad of a Cornell box. Any material may emit.

use super::param::{ColorDesc, ColorParam, ColorRange, Invalid, Textures};
use super::Material;
use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;

material_desc! {
    /// A light: emits `radiance` and scatters nothing.
    pub struct EmissiveDesc {
        /// Emitted radiance per channel, ≥ 0 (may exceed 1), or a texture
        /// giving it.
        pub radiance: ColorDesc,
    }
}

impl EmissiveDesc {
    /// A one-sided light of radiance `radiance`.
    pub fn new(radiance: impl Into<ColorDesc>) -> Self {
        EmissiveDesc {
            radiance: radiance.into(),
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        Ok(Material::emitter(Emission {
            radiance: textures.color(
                &format!("{field}.radiance"),
                &self.radiance,
                ColorRange::NonNegative,
            )?,
            two_sided: self.two_sided,
        }))
    }
}

/// The light a material gives off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Radiance emitted per channel (≥ 0; may exceed 1), or a texture of it.
    pub radiance: ColorParam,
    /// Emit from both sides; otherwise only from the side the surface's
    /// outward normal points to (a sphere's outside, the side of a quad
    /// its u × v points to, the counter-clockwise side of a triangle).
    pub two_sided: bool,
}

impl Emission {
    /// The radiance leaving the surface at `hit` towards the ray that hit
    /// it.
    #[inline(always)]
    pub fn emitted(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        if hit.front_face || self.two_sided {
            self.radiance.at(hit, textures)
        } else {
            Color::ZERO
        }
    }

    /// The emission's constant part as a light sees it: its radiance when
    /// it has no texture (else zero: the texture gives it), and its sides.
    pub fn constant(&self) -> Emissive {
        Emissive {
            radiance: match self.radiance {
                ColorParam::Const(c) => c,
                ColorParam::Texture(_) => Color::ZERO,
            },
            two_sided: self.two_sided,
        }
    }
}

/// A constant emission, as a light carries it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emissive {
    /// Radiance emitted per channel (≥ 0; may exceed 1).
    pub radiance: Color,
    /// Emit from both sides; otherwise only from the outward side.
    pub two_sided: bool,
}

impl Emissive {
    /// The radiance leaving the surface towards a side of it: the side its
    /// outward normal points to when `front`, else the other.
    #[inline(always)]
    pub fn towards(&self, front: bool) -> Color {
        if front || self.two_sided {
            self.radiance
        } else {
            Color::ZERO
        }
    }
}
