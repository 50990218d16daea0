//! Materials: what a surface is made of, as parameters (each a constant or
//! a texture), and the [`Bsdf`] it has where a ray hits it.
//!
//! A [`Material`] is one [`Kind`] of scattering (a closed set, dispatched
//! with `match`, so the path loop makes no virtual calls) and, for any
//! kind, the light it gives off ([`Emission`]). At a hit,
//! [`Material::bsdf`] looks its textures up and gives the lobe there in
//! the hit's shading frame; [`Material::emitted`] the light it sends back
//! along the ray.

/// Declares a material kind's description: its own fields as written,
/// followed by the fields every kind has (emission, normal and bump maps,
/// opacity), so that each kind is declared once for every reader, for
/// export and for the documentation's list.
macro_rules! material_desc {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* pub $field:ident : $ty:ty, )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $ty, )*
            /// Radiance the surface gives off (added to what it reflects), or
            /// a texture of it; none when absent.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub emission: Option<$crate::material::param::ColorDesc>,
            /// Factor on `emission` (glTF's `emissiveStrength`), ≥ 0.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub emission_strength: Option<f64>,
            /// Emit from both sides; otherwise only from the side the
            /// outward normal points to.
            #[serde(default, skip_serializing_if = "std::ops::Not::not")]
            pub two_sided: bool,
        }

        impl $name {
            /// The fields every kind has.
            pub fn surface(&self) -> $crate::material::SurfaceDesc<'_> {
                $crate::material::SurfaceDesc {
                    emission: self.emission.as_ref(),
                    emission_strength: self.emission_strength,
                    two_sided: self.two_sided,
                }
            }
        }
    };
}

/// Lists the material kinds once: the description enum (tagged by `type`
/// in scene files), the table of kinds the readers check names and fields
/// against, and the compilation of each.
macro_rules! material_kinds {
    ($( $(#[$meta:meta])* $variant:ident($desc:ty) = $name:literal, $what:literal; )*) => {
        /// A material as a scene describes it (`type = "…"` and the kind's
        /// fields).
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(tag = "type", rename_all = "kebab-case")]
        pub enum MaterialDesc {
            $( $(#[$meta])* $variant($desc), )*
        }

        /// Every kind of material: its `type`, how messages call it, and
        /// its fields (`type` among them).
        pub fn kinds() -> Vec<KindInfo> {
            vec![$(KindInfo {
                name: $name,
                what: $what,
                fields: std::iter::once("type")
                    .chain(param::fields_of::<$desc>().iter().copied())
                    .collect(),
            },)*]
        }

        impl MaterialDesc {
            /// The kind's `type` name.
            pub fn type_name(&self) -> &'static str {
                match self {
                    $(MaterialDesc::$variant(_) => $name,)*
                }
            }

            /// Reads the fields of the kind called `name` (the table's
            /// `type`) from `d`.
            pub fn deserialize_kind<'de, D: serde::Deserializer<'de>>(
                name: &str,
                d: D,
            ) -> Result<MaterialDesc, D::Error> {
                use serde::Deserialize;
                match name {
                    $($name => <$desc>::deserialize(d).map(MaterialDesc::$variant),)*
                    _ => Err(serde::de::Error::unknown_variant(name, &[$($name),*])),
                }
            }

            /// The material described, compiled: `field` is its path
            /// (`materials.NAME`) for messages, `textures` resolves texture
            /// names.
            pub fn compile(
                &self,
                field: &str,
                textures: &mut dyn Textures,
            ) -> Result<Material, Invalid> {
                let (kind, surface) = match self {
                    $(MaterialDesc::$variant(d) => (d.compile(field, textures)?, d.surface()),)*
                };
                surface.compile(field, kind, textures)
            }
        }
    };
}

pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod emissive;
pub mod metal;
pub mod metals;
pub mod param;
pub mod roughness;

pub use crate::bsdf::dielectric::{reflectance, refract};
pub use crate::bsdf::diffuse::{Attenuation, BounceModel};
pub use crate::bsdf::metal::reflect;
pub use conductor::{Conductor, ConductorDesc};
pub use dielectric::{Dielectric, DielectricDesc};
pub use diffuse::{AttenuationDesc, BounceDesc, Diffuse, DiffuseDesc};
pub use emissive::{Emission, Emissive, EmissiveDesc};
pub use metal::{Metal, MetalDesc};
pub use param::{ColorDesc, ColorParam, Invalid, ScalarDesc, ScalarParam, Textures};

use crate::bsdf::{Bsdf, Frame, Lobe};
use crate::geometry::HitRecord;
use crate::math::Color;
use crate::texture::Texture;
use param::ColorRange;

material_kinds! {
    /// A matte surface.
    Diffuse(DiffuseDesc) = "diffuse", "a diffuse material";
    /// A reflective metal of the notes, blurred by fuzz.
    Metal(MetalDesc) = "metal", "a metal material";
    /// A clear refracting material.
    Dielectric(DielectricDesc) = "dielectric", "a dielectric material";
    /// A light: emits `radiance` and scatters nothing.
    Emissive(EmissiveDesc) = "emissive", "an emissive material";
    /// A metal by its complex index of refraction, smooth or rough.
    Conductor(ConductorDesc) = "conductor", "a conductor material";
}

/// A kind of material as the readers know it.
#[derive(Clone, Debug, PartialEq)]
pub struct KindInfo {
    /// Its `type`.
    pub name: &'static str,
    /// How messages call it ("a diffuse material").
    pub what: &'static str,
    /// Its fields, `type` first.
    pub fields: Vec<&'static str>,
}

/// The fields every kind of material has, borrowed from its description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceDesc<'a> {
    /// Radiance given off, if any.
    pub emission: Option<&'a ColorDesc>,
    /// Factor on the emission.
    pub emission_strength: Option<f64>,
    /// Emit from both sides.
    pub two_sided: bool,
}

impl SurfaceDesc<'_> {
    /// The material of `kind` with these fields compiled.
    fn compile(
        &self,
        field: &str,
        mut material: Material,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        if let Some(e) = self.emission {
            if material.emission.is_some() {
                return Err(Invalid::new(
                    format!("{field}.emission"),
                    "an emissive material gives off its `radiance`; `emission` is for the other kinds",
                ));
            }
            let strength = match self.emission_strength {
                Some(s) => param::number(
                    &format!("{field}.emission_strength"),
                    s,
                    param::Range::NonNegative,
                )?,
                None => 1.0,
            };
            let radiance =
                match textures.color(&format!("{field}.emission"), e, ColorRange::NonNegative)? {
                    ColorParam::Const(c) => ColorParam::Const(c * strength),
                    ColorParam::Texture(t) if strength != 1.0 => {
                        ColorParam::Texture(textures.scaled(t, Color::splat(strength)))
                    }
                    p => p,
                };
            material.emission = Some(Emission {
                radiance,
                two_sided: self.two_sided,
            });
        } else if self.emission_strength.is_some() {
            return Err(Invalid::new(
                format!("{field}.emission_strength"),
                "scales `emission`, which the material does not have",
            ));
        } else if let Some(e) = &mut material.emission {
            e.two_sided = self.two_sided;
        }
        Ok(material)
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
    /// A metal by its complex index of refraction.
    Conductor(Conductor),
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
        // The others in the frame of the surface's tangent.
        let local = |lobe| {
            let frame = Frame::from_normal_tangent(hit.shading_normal, hit.dpdu);
            Some(Bsdf::new(frame, hit.normal, lobe))
        };
        match &self.kind {
            Kind::Black => None,
            Kind::Diffuse(d) => notes(Lobe::Diffuse(d.at(hit, textures))),
            Kind::Metal(m) => notes(Lobe::Metal(m.at(hit, textures))),
            Kind::Dielectric(d) => match d.at(hit, textures) {
                lobe @ Lobe::Dielectric(_) => notes(lobe),
                lobe => local(lobe),
            },
            Kind::Conductor(c) => local(Lobe::Conductor(c.at(hit, textures))),
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
            .into_iter()
            .any(|t| textures[t as usize].uses_uv(textures))
    }

    /// The textures its parameters look up.
    pub fn textures(&self) -> Vec<u32> {
        let mut out: Vec<u32> = match &self.kind {
            Kind::Diffuse(d) => d.albedo.texture().into_iter().collect(),
            Kind::Metal(m) => m.albedo.texture().into_iter().collect(),
            Kind::Dielectric(d) => d.roughness.iter().flat_map(|r| r.textures()).collect(),
            Kind::Conductor(c) => c.roughness.textures().collect(),
            Kind::Black => Vec::new(),
        };
        out.extend(self.emission.and_then(|e| e.radiance.texture()));
        out
    }
}
