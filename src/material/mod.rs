//! Materials: what a surface is made of, as parameters (each a constant or
//! a texture), and the [`Bsdf`] it has where a ray hits it.
//!
//! A [`Material`] is one [`Kind`] of scattering (a closed set, dispatched
//! with `match`, so the path loop makes no virtual calls) and, for any
//! kind, the light it gives off ([`Emission`]). At a hit,
//! [`Material::bsdf`] looks its textures up and gives the lobe there in
//! the hit's shading frame; [`Material::emitted`] the light it sends back
//! along the ray.

pub mod dielectric;
pub mod diffuse;
pub mod emissive;
pub mod metal;

pub use crate::bsdf::dielectric::{reflectance, refract};
pub use crate::bsdf::diffuse::{Attenuation, BounceModel};
pub use crate::bsdf::metal::reflect;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use emissive::{Emission, Emissive};
pub use metal::Metal;

use crate::bsdf::{Bsdf, Frame, Lobe};
use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;

/// A colour parameter: one colour, or a texture's colour where a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorParam {
    /// The colour.
    Const(Color),
    /// Texture number n of the scene's table.
    Texture(u32),
}

impl ColorParam {
    /// The colour at `hit`, textures looked up in `textures`.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        match *self {
            ColorParam::Const(c) => c,
            ColorParam::Texture(t) => textures[t as usize].value(textures, hit.uv, hit.point),
        }
    }

    /// An albedo: the colour at `hit`, a texture's kept within [0, 1] so
    /// that no surface reflects more than it receives (a constant one is
    /// checked when the scene is compiled).
    #[inline(always)]
    pub fn albedo_at(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        match *self {
            ColorParam::Const(c) => c,
            ColorParam::Texture(_) => self.at(hit, textures).clamp(Color::ZERO, Color::ONE),
        }
    }

    /// The texture it looks up, if any.
    pub fn texture(&self) -> Option<u32> {
        match *self {
            ColorParam::Const(_) => None,
            ColorParam::Texture(t) => Some(t),
        }
    }
}

/// How a material scatters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Reflects and transmits nothing: a path that meets it ends there (the
    /// notes' lights).
    Black,
    /// Diffuse (matte) surface.
    Diffuse(Diffuse),
    /// Mirror-like metal, optionally fuzzy.
    Metal(Metal),
    /// Clear refracting material such as glass or water.
    Dielectric(Dielectric),
}

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// How it scatters.
    pub kind: Kind,
    /// The light it gives off, if any.
    pub emission: Option<Emission>,
}

impl Material {
    /// A material of `kind` that gives off no light.
    pub const fn new(kind: Kind) -> Material {
        Material {
            kind,
            emission: None,
        }
    }

    /// A light that scatters nothing (the notes' emissive material).
    pub const fn emitter(emission: Emission) -> Material {
        Material {
            kind: Kind::Black,
            emission: Some(emission),
        }
    }

    /// The scattering at `hit` (textures looked up in `textures`), or
    /// `None` where it scatters nothing.
    #[inline(always)]
    pub fn bsdf(&self, hit: &HitRecord, textures: &[Texture]) -> Option<Bsdf> {
        // The notes' lobes scatter about the normal alone.
        let notes = |lobe| {
            Some(Bsdf::new(
                Frame::normal_only(hit.shading_normal),
                hit.normal,
                lobe,
            ))
        };
        match &self.kind {
            Kind::Black => None,
            Kind::Diffuse(d) => notes(Lobe::Diffuse(d.at(hit, textures))),
            Kind::Metal(m) => notes(Lobe::Metal(m.at(hit, textures))),
            Kind::Dielectric(d) => notes(Lobe::Dielectric(d.at(hit))),
        }
    }

    /// The radiance the surface at `hit` sends back along the ray that hit
    /// it.
    #[inline(always)]
    pub fn emitted(&self, hit: &HitRecord, textures: &[Texture]) -> Color {
        match &self.emission {
            Some(e) => e.emitted(hit, textures),
            None => Color::ZERO,
        }
    }

    /// Whether it scatters nothing (a path that meets it ends there).
    #[inline(always)]
    pub fn is_black(&self) -> bool {
        matches!(self.kind, Kind::Black)
    }

    /// Whether it gives off light anywhere: a constant radiance above zero,
    /// or a texture.
    pub fn emits(&self) -> bool {
        self.emission.is_some_and(|e| match e.radiance {
            ColorParam::Const(c) => c != Color::ZERO,
            ColorParam::Texture(_) => true,
        })
    }

    /// Whether any of its parameters is a texture looked up by the
    /// surface's (u, v) (directly or through a texture it refers to).
    pub fn uses_uv(&self, textures: &[Texture]) -> bool {
        self.textures()
            .any(|t| textures[t as usize].uses_uv(textures))
    }

    /// The textures its parameters look up.
    pub fn textures(&self) -> impl Iterator<Item = u32> {
        let colour = match &self.kind {
            Kind::Diffuse(d) => d.albedo.texture(),
            Kind::Metal(m) => m.albedo.texture(),
            Kind::Black | Kind::Dielectric(_) => None,
        };
        colour
            .into_iter()
            .chain(self.emission.and_then(|e| e.radiance.texture()))
    }
}
