//! Materials: how a surface turns an incoming ray into a scattered one, and
//! the light it gives off.
//!
//! A closed set of materials dispatched with `match`, so the path loop makes no
//! virtual calls.

pub mod dielectric;
pub mod diffuse;
pub mod emissive;
pub mod metal;

pub use dielectric::{reflectance, refract, Dielectric};
pub use diffuse::{Attenuation, BounceModel, Diffuse};
pub use emissive::Emissive;
pub use metal::{reflect, Metal};

use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::sampler::Sampler;

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Diffuse (matte) surface.
    Diffuse(Diffuse),
    /// Mirror-like metal, optionally fuzzy.
    Metal(Metal),
    /// Clear refracting material such as glass or water.
    Dielectric(Dielectric),
    /// A light-emitting surface, which scatters nothing.
    Emissive(Emissive),
}

/// The outcome of a ray meeting a surface that does not absorb it.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    /// Factor by which the scattered ray's colour is multiplied.
    pub attenuation: Color,
    /// Unit direction of the scattered ray.
    pub direction: Vec3,
}

impl Material {
    /// Scatters a ray arriving along unit `direction` at `hit`; `None` means
    /// the ray is absorbed.
    #[inline(always)]
    pub fn scatter(
        &self,
        direction: Vec3,
        hit: &HitRecord,
        sampler: &mut impl Sampler,
    ) -> Option<Scatter> {
        match self {
            Material::Diffuse(m) => m.scatter(hit, sampler),
            Material::Metal(m) => m.scatter(direction, hit, sampler),
            Material::Dielectric(m) => m.scatter(direction, hit, sampler),
            Material::Emissive(_) => None,
        }
    }

    /// The material with its colour replaced by `c` (a texture's value):
    /// the albedo of a diffuse or metal surface (kept within [0, 1], so that
    /// no surface reflects more than it receives), the radiance of an
    /// emissive one. Glass has no colour.
    #[inline]
    pub fn with_color(self, c: Color) -> Material {
        match self {
            Material::Diffuse(m) => Material::Diffuse(Diffuse {
                albedo: c.clamp(Color::ZERO, Color::ONE),
                ..m
            }),
            Material::Metal(m) => Material::Metal(Metal {
                albedo: c.clamp(Color::ZERO, Color::ONE),
                ..m
            }),
            Material::Emissive(m) => Material::Emissive(Emissive { radiance: c, ..m }),
            Material::Dielectric(_) => self,
        }
    }

    /// What the material emits, if it gives off any light.
    pub fn light(&self) -> Option<Emissive> {
        match *self {
            Material::Emissive(m) if m.radiance != Color::ZERO => Some(m),
            _ => None,
        }
    }
}
