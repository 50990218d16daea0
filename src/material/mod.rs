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
    // A rough kind: its own fields, then the microfacets' (roughness or
    // alpha, distribution, multiscatter), then every kind's.
    (
        microfacets;
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* pub $field:ident : $ty:ty, )*
        }
    ) => {
        material_desc! {
            $(#[$meta])*
            pub struct $name {
                $( $(#[$fmeta])* pub $field: $ty, )*
                /// Roughness in [0, 1] (α = roughness²), a pair `[u, v]` for
                /// a surface rougher along its tangent than its bitangent, or
                /// a scalar texture.
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub roughness: Option<$crate::material::param::RoughnessDesc>,
                /// The microfacet width α itself, instead of `roughness`.
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub alpha: Option<$crate::material::param::RoughnessDesc>,
                /// The microfacet distribution: "ggx" (the default) or
                /// "beckmann".
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub distribution: Option<$crate::material::roughness::DistributionDesc>,
                /// Return the energy single-scattering microfacets lose.
                #[serde(default, skip_serializing_if = "std::ops::Not::not")]
                pub multiscatter: bool,
            }
        }

        impl $name {
            /// The microfacets of the material at `field`: its `roughness`
            /// or `alpha`, or roughness `default` when it gives neither.
            pub(super) fn microfacets(
                &self,
                field: &str,
                default: f64,
                textures: &mut dyn $crate::material::param::Textures,
            ) -> Result<$crate::material::roughness::Roughness, $crate::material::param::Invalid> {
                let fallback = $crate::material::param::RoughnessDesc::Value(default);
                let roughness = match (&self.roughness, &self.alpha) {
                    (None, None) if default != 0.0 => Some(&fallback),
                    (r, _) => r.as_ref(),
                };
                $crate::material::roughness::Roughness::compile(
                    field,
                    roughness,
                    self.alpha.as_ref(),
                    self.distribution,
                    textures,
                )
            }
        }
    };
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
            /// A tangent-space normal map: the name of a colour texture,
            /// read as linear data (x, y, z = 2·(r, g, b) − 1).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub normal_map: Option<String>,
            /// How far the normal map tilts the normal (its x and y are
            /// multiplied by it), ≥ 0; 1 when absent.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub normal_scale: Option<f64>,
            /// A height map: the name of a scalar texture whose value lifts
            /// the surface along its normal, tilting the shading normal.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub bump_map: Option<String>,
            /// The height, in scene units, of a bump map's value 1; 1 when
            /// absent.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub bump_scale: Option<f64>,
            /// How much of the surface is there, in [0, 1]: a number or a
            /// scalar texture (cut-outs: leaves, fences). Rays pass through
            /// what is not.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub opacity: Option<$crate::material::param::ScalarDesc>,
            /// With `opacity`: the surface is there where the opacity is at
            /// least this, and nowhere else (glTF's `MASK`); without it, a
            /// ray passes through with probability 1 − opacity (`BLEND`).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha_cutoff: Option<f64>,
            /// Scatter light only on the side the outward normal points
            /// to: seen from behind, the surface is black (Mitsuba's
            /// surfaces but `twosided`'s). Otherwise both sides scatter
            /// alike.
            #[serde(default, skip_serializing_if = "std::ops::Not::not")]
            pub one_sided: bool,
            /// With a normal or bump map: darken the surface by its bumps'
            /// shadowing, mirror a tilted normal the view is below and lose
            /// the light it would reflect below the true surface (Mitsuba
            /// 3's way), rather than bend it back towards the view
            /// (Cycles').
            #[serde(default, skip_serializing_if = "std::ops::Not::not")]
            pub bump_shadowing: bool,
            /// The medium inside the surface (a name in `media`): a path
            /// that crosses it inwards travels in it. None when absent.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub interior: Option<String>,
            /// The medium outside the surface; none when absent.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub exterior: Option<String>,
        }

        impl $name {
            /// The fields every kind has.
            pub fn surface(&self) -> $crate::material::SurfaceDesc<'_> {
                $crate::material::SurfaceDesc {
                    emission: self.emission.as_ref(),
                    emission_strength: self.emission_strength,
                    two_sided: self.two_sided,
                    normal_map: self.normal_map.as_deref(),
                    normal_scale: self.normal_scale,
                    bump_map: self.bump_map.as_deref(),
                    bump_scale: self.bump_scale,
                    opacity: self.opacity.as_ref(),
                    alpha_cutoff: self.alpha_cutoff,
                    one_sided: self.one_sided,
                    bump_shadowing: self.bump_shadowing,
                    interior: self.interior.as_deref(),
                    exterior: self.exterior.as_deref(),
                }
            }

            /// The fields every kind has, to be changed.
            pub fn surface_mut(&mut self) -> $crate::material::SurfaceMut<'_> {
                $crate::material::SurfaceMut {
                    emission: &mut self.emission,
                    two_sided: &mut self.two_sided,
                    normal_map: &mut self.normal_map,
                    normal_scale: &mut self.normal_scale,
                    bump_map: &mut self.bump_map,
                    bump_scale: &mut self.bump_scale,
                    opacity: &mut self.opacity,
                    alpha_cutoff: &mut self.alpha_cutoff,
                    one_sided: &mut self.one_sided,
                    bump_shadowing: &mut self.bump_shadowing,
                    interior: &mut self.interior,
                    exterior: &mut self.exterior,
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
        // Descriptions are read once and compiled: their size does not matter.
        #[allow(clippy::large_enum_variant)]
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

            /// The fields every kind has.
            pub fn surface(&self) -> SurfaceDesc<'_> {
                match self {
                    $(MaterialDesc::$variant(d) => d.surface(),)*
                }
            }

            /// The fields every kind has, to be changed.
            pub fn surface_mut(&mut self) -> SurfaceMut<'_> {
                match self {
                    $(MaterialDesc::$variant(d) => d.surface_mut(),)*
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
pub mod interface;
pub mod metal;
pub mod metals;
pub mod mix;
pub mod param;
pub mod plastic;
pub mod principled;
pub mod roughness;

pub use crate::bsdf::dielectric::{reflectance, refract};
pub use crate::bsdf::diffuse::{Attenuation, BounceModel};
pub use crate::bsdf::metal::reflect;
pub use conductor::{Conductor, ConductorDesc};
pub use dielectric::{Dielectric, DielectricDesc};
pub use diffuse::{AttenuationDesc, BounceDesc, Diffuse, DiffuseDesc};
pub use emissive::{Emission, Emissive, EmissiveDesc};
pub use interface::InterfaceDesc;
pub use metal::{Metal, MetalDesc};
pub use mix::{Mix, MixDesc};
pub use param::{ColorDesc, ColorParam, Invalid, ScalarDesc, ScalarParam, Textures};
pub use plastic::{Plastic, PlasticDesc};
pub use principled::{Principled, PrincipledDesc};

use crate::bsdf::{Bsdf, Frame, Lobe, Terminator};
use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
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
    /// A diffuse base under a smooth or rough clear coat.
    Plastic(PlasticDesc) = "plastic", "a plastic material";
    /// The glTF metallic-roughness material and its layers.
    Principled(PrincipledDesc) = "principled", "a principled material";
    /// Two materials, one or the other at each point.
    Mix(MixDesc) = "mix", "a mix material";
    /// No surface: the boundary between two media, crossed unchanged.
    Interface(InterfaceDesc) = "interface", "an interface material";
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
    /// A normal map's texture.
    pub normal_map: Option<&'a str>,
    /// Its strength.
    pub normal_scale: Option<f64>,
    /// A bump map's texture.
    pub bump_map: Option<&'a str>,
    /// Its height.
    pub bump_scale: Option<f64>,
    /// How much of the surface is there.
    pub opacity: Option<&'a ScalarDesc>,
    /// Where it is cut off.
    pub alpha_cutoff: Option<f64>,
    /// Scatter on the outward side only.
    pub one_sided: bool,
    /// Shadow a normal or bump map's bumps.
    pub bump_shadowing: bool,
    /// The medium inside, by name.
    pub interior: Option<&'a str>,
    /// The medium outside, by name.
    pub exterior: Option<&'a str>,
}

/// The fields every kind of material has, borrowed to be changed (by a
/// reader that learns them after the kind, as Mitsuba's `twosided` and
/// `mask` wrap a BSDF).
#[derive(Debug)]
pub struct SurfaceMut<'a> {
    /// Radiance given off, if any.
    pub emission: &'a mut Option<ColorDesc>,
    /// Emit from both sides.
    pub two_sided: &'a mut bool,
    /// A normal map's texture.
    pub normal_map: &'a mut Option<String>,
    /// Its strength.
    pub normal_scale: &'a mut Option<f64>,
    /// A bump map's texture.
    pub bump_map: &'a mut Option<String>,
    /// Its height.
    pub bump_scale: &'a mut Option<f64>,
    /// How much of the surface is there.
    pub opacity: &'a mut Option<ScalarDesc>,
    /// Where it is cut off.
    pub alpha_cutoff: &'a mut Option<f64>,
    /// Scatter on the outward side only.
    pub one_sided: &'a mut bool,
    /// Shadow a normal or bump map's bumps.
    pub bump_shadowing: &'a mut bool,
    /// The medium inside.
    pub interior: &'a mut Option<String>,
    /// The medium outside.
    pub exterior: &'a mut Option<String>,
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
            return Err(Invalid::scales_missing(
                format!("{field}.emission_strength"),
                "emission",
            ));
        } else if let Some(e) = &mut material.emission {
            e.two_sided = self.two_sided;
        }
        let shape = self.shape(field, textures)?;
        material.opacity = self.opacity(field, textures)?;
        material.one_sided = self.one_sided;
        if self.bump_shadowing && shape.is_none() {
            return Err(Invalid::new(
                format!("{field}.bump_shadowing"),
                "shadows the bumps of a normal_map or bump_map, which the material does not have",
            ));
        }
        match &mut material.kind {
            Kind::Mix(mix) => mix.hand_down(field, self.one_sided, shape, self.bump_shadowing)?,
            _ => {
                material.shape = shape;
                material.bump_shadowing = self.bump_shadowing;
            }
        }
        Ok(material)
    }

    /// The normal or bump map, if any.
    fn shape(&self, field: &str, textures: &mut dyn Textures) -> Result<Option<Shape>, Invalid> {
        let factor = |name: &str, v: Option<f64>| match v {
            Some(v) => param::number(&format!("{field}.{name}"), v, param::Range::NonNegative),
            None => Ok(1.0),
        };
        match (self.normal_map, self.bump_map) {
            (Some(_), Some(_)) => Err(Invalid::new(
                format!("{field}.bump_map"),
                "give `normal_map` or `bump_map`, not both",
            )),
            (Some(name), None) => {
                if self.bump_scale.is_some() {
                    return Err(Invalid::scales_missing(
                        format!("{field}.bump_scale"),
                        "bump_map",
                    ));
                }
                let texture = textures.normal_map(&format!("{field}.normal_map"), name)?;
                Ok(Some(Shape::Normal {
                    texture,
                    scale: factor("normal_scale", self.normal_scale)?,
                }))
            }
            (None, Some(name)) => {
                if self.normal_scale.is_some() {
                    return Err(Invalid::scales_missing(
                        format!("{field}.normal_scale"),
                        "normal_map",
                    ));
                }
                let at = format!("{field}.bump_map");
                let texture = match textures.scalar(
                    &at,
                    &ScalarDesc::Texture(name.to_string()),
                    param::Range::Any,
                )? {
                    ScalarParam::Texture(t) => t,
                    ScalarParam::Const(_) => unreachable!("a name is a texture"),
                };
                let scale = match self.bump_scale {
                    Some(v) => param::number(&format!("{field}.bump_scale"), v, param::Range::Any)?,
                    None => 1.0,
                };
                Ok(Some(Shape::Bump { texture, scale }))
            }
            (None, None) => {
                for (name, v) in [
                    ("normal_scale", self.normal_scale),
                    ("bump_scale", self.bump_scale),
                ] {
                    if v.is_some() {
                        let map = name.replace("_scale", "_map");
                        return Err(Invalid::scales_missing(format!("{field}.{name}"), &map));
                    }
                }
                Ok(None)
            }
        }
    }

    /// The opacity, if any.
    fn opacity(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Option<Opacity>, Invalid> {
        let cutoff = self
            .alpha_cutoff
            .map(|c| param::number(&format!("{field}.alpha_cutoff"), c, param::Range::Unit))
            .transpose()?;
        let Some(o) = self.opacity else {
            if cutoff.is_some() {
                return Err(Invalid::new(
                    format!("{field}.alpha_cutoff"),
                    "cuts `opacity` off, which the material does not have",
                ));
            }
            return Ok(None);
        };
        let value = textures.scalar(&format!("{field}.opacity"), o, param::Range::Unit)?;
        Ok(Some(Opacity {
            value,
            cutoff,
            vertex: false,
        }))
    }
}

/// What tilts a material's shading normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A tangent-space normal map: texture (linear RGB) and how far it
    /// tilts.
    Normal {
        /// The texture.
        texture: u32,
        /// The factor on its x and y.
        scale: f32,
    },
    /// A height map: scalar texture and the height of its value 1.
    Bump {
        /// The texture.
        texture: u32,
        /// Scene units per unit of the texture.
        scale: f32,
    },
}

/// The step in texture coordinates of a bump map's differences.
const BUMP_STEP: f32 = 5e-4;

impl Shape {
    /// The shading normal at `hit` tilted by the map: unit, on the side the
    /// ray came from.
    #[inline(never)]
    pub fn normal(&self, hit: &HitRecord, textures: &[Texture]) -> Vec3 {
        // Maps are made for the outside of the surface.
        let side = if hit.front_face { 1.0 } else { -1.0 };
        let n = hit.shading_normal * side;
        let tilted = match *self {
            Shape::Normal { texture, scale } => {
                let c = textures[texture as usize].value(textures, &hit.tex_coords());
                let m = Vec3::new(
                    (2.0 * c.x - 1.0) * scale,
                    (2.0 * c.y - 1.0) * scale,
                    2.0 * c.z - 1.0,
                );
                let (t, b) = tangents(n, hit.dpdu, hit.dpdv);
                t * m.x + b * m.y + n * m.z
            }
            Shape::Bump { texture, scale } => {
                let height = |du: f32, dv: f32| {
                    let mut at = hit.tex_coords();
                    at.uv = [at.uv[0] + du, at.uv[1] + dv];
                    at.uv1 = [at.uv1[0] + du, at.uv1[1] + dv];
                    at.point += hit.dpdu * du + hit.dpdv * dv;
                    textures[texture as usize].value(textures, &at).x * scale
                };
                let h = height(0.0, 0.0);
                let dhdu = (height(BUMP_STEP, 0.0) - h) / BUMP_STEP;
                let dhdv = (height(0.0, BUMP_STEP) - h) / BUMP_STEP;
                let pu = hit.dpdu + n * dhdu;
                let pv = hit.dpdv + n * dhdv;
                let m = pu.cross(pv);
                // ∂p/∂u × ∂p/∂v may point inwards (a mirrored mapping).
                if m.dot(n) < 0.0 {
                    -m
                } else {
                    m
                }
            }
        };
        let tilted = tilted.normalize_or_zero();
        if tilted == Vec3::ZERO || !tilted.is_finite() {
            hit.shading_normal
        } else {
            tilted * side
        }
    }
}

/// Unit shading normal `n` (from a normal or bump map) bent towards the
/// geometric normal `ng` as far as needed for the mirror reflection of `wo`
/// about it to leave the surface, as Cycles does: a map tilting the normal
/// away from the view would make the surface black there.
#[inline]
fn visible(n: Vec3, wo: Vec3, ng: Vec3) -> Vec3 {
    let least = (0.9 * wo.dot(ng)).min(0.01);
    let reflects = |n: Vec3| (2.0 * wo.dot(n) * n - wo).dot(ng) >= least;
    if reflects(n) || !reflects(ng) {
        return n;
    }
    // Along the arc from `n` (fails) to `ng` (passes), by bisection.
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        if reflects(n.lerp(ng, mid).normalize()) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    n.lerp(ng, hi).normalize()
}

/// The unit tangent and bitangent about unit normal `n` from the surface's
/// derivatives: ∂p/∂u made perpendicular to `n`, and ∂p/∂v made
/// perpendicular to both (n × tangent, turned to ∂p/∂v's side, where it
/// has none).
#[inline]
fn tangents(n: Vec3, dpdu: Vec3, dpdv: Vec3) -> (Vec3, Vec3) {
    let t = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
    let t = if t == Vec3::ZERO {
        n.any_orthonormal_vector()
    } else {
        t
    };
    let b = n.cross(t);
    if b.dot(dpdv) < 0.0 {
        (t, -b)
    } else {
        (t, b)
    }
}

/// How much of a surface is there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opacity {
    /// The opacity in [0, 1].
    pub value: ScalarParam,
    /// Present where the opacity is at least this (a mask); `None`: a ray
    /// passes with probability 1 − opacity.
    pub cutoff: Option<f32>,
    /// Multiplied by the mesh's vertex alpha (glTF `COLOR_0`).
    pub vertex: bool,
}

impl Opacity {
    /// Whether the surface at `hit` stops a ray, `u` uniform in [0, 1)
    /// (used only where the opacity is partial and not cut off).
    #[inline]
    pub fn stops(&self, hit: &HitRecord, textures: &[Texture], u: f32) -> bool {
        let mut a = self.value.at(hit, textures);
        if self.vertex {
            a *= hit.color.w;
        }
        match self.cutoff {
            Some(c) => a >= c,
            None => u < a,
        }
    }
}

/// How a material scatters.
#[derive(Clone, Debug, PartialEq)]
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
    /// A metal by its complex index of refraction (out of line, as the
    /// other large kinds).
    Conductor(Box<Conductor>),
    /// A diffuse base under a clear coat.
    Plastic(Box<Plastic>),
    /// The glTF metallic-roughness material (out of line: it is large,
    /// and the table of materials every hit reads stays small).
    Principled(Box<Principled>),
    /// One of two materials at each point.
    Mix(Box<Mix>),
    /// No surface: the boundary between two media, which rays cross
    /// unchanged (see [`Material::straight_through`]).
    Interface,
}

/// The media on the two sides of a surface, by index in the scene's
/// [`volumes`](crate::scene::Scene::volumes); `None`: empty space.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumInterface {
    /// The medium inside (the side away from the outward normal).
    pub interior: Option<u32>,
    /// The medium outside.
    pub exterior: Option<u32>,
}

impl MediumInterface {
    /// The medium a path leaving the surface along `direction` enters,
    /// where the surface's outward geometric normal is `outward`.
    #[inline]
    pub fn beyond(&self, outward: Vec3, direction: Vec3) -> Option<u32> {
        if direction.dot(outward) < 0.0 {
            self.interior
        } else {
            self.exterior
        }
    }
}

/// A surface material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// How it scatters.
    pub kind: Kind,
    /// The light it gives off, if any.
    pub emission: Option<Emission>,
    /// A normal or bump map tilting its shading normal, if any.
    pub shape: Option<Shape>,
    /// How much of the surface is there, where it is not all there.
    pub opacity: Option<Opacity>,
    /// Scatters nothing seen from behind (the inward side).
    pub one_sided: bool,
    /// A normal or bump map's bumps shadow the light (see
    /// [`Terminator`]).
    pub bump_shadowing: bool,
    /// The media on its two sides, where it bounds any.
    pub media: Option<MediumInterface>,
}

impl Material {
    /// A material of `kind` that gives off no light.
    pub const fn new(kind: Kind) -> Material {
        Material {
            kind,
            emission: None,
            shape: None,
            opacity: None,
            one_sided: false,
            bump_shadowing: false,
            media: None,
        }
    }

    /// A light that scatters nothing (the notes' emissive material).
    pub const fn emitter(emission: Emission) -> Material {
        Material {
            kind: Kind::Black,
            emission: Some(emission),
            shape: None,
            opacity: None,
            one_sided: false,
            bump_shadowing: false,
            media: None,
        }
    }

    /// The scattering at `hit`, seen from unit direction `wo` (back along
    /// the ray; textures looked up in `textures`), or `None` where it
    /// scatters nothing.
    #[inline(always)]
    pub fn bsdf(&self, hit: &HitRecord, wo: Vec3, textures: &[Texture]) -> Option<Bsdf> {
        // A mix is the material it chooses (a pointer picked, no call back
        // into this function), its sides and map given to it when compiled.
        let m = match &self.kind {
            Kind::Mix(mix) => mix.choose(hit, wo, textures),
            _ => self,
        };
        m.leaf_bsdf(hit, wo, textures)
    }

    /// [`bsdf`](Self::bsdf) of a material that is not a mix.
    #[inline(always)]
    fn leaf_bsdf(&self, hit: &HitRecord, wo: Vec3, textures: &[Texture]) -> Option<Bsdf> {
        if self.one_sided && !hit.front_face {
            return None;
        }
        let (n, terminator) = match &self.shape {
            None => (hit.shading_normal, None),
            Some(shape) if self.bump_shadowing => {
                let (untilted, tilted) = (hit.shading_normal, shape.normal(hit, textures));
                // Seen from below the tilted normal, it is mirrored about
                // the untilted one.
                let tilted = if wo.dot(tilted) <= 0.0 {
                    (2.0 * tilted.dot(untilted) * untilted - tilted).normalize()
                } else {
                    tilted
                };
                (tilted, Some(Terminator::new(untilted, tilted)))
            }
            Some(shape) => (visible(shape.normal(hit, textures), wo, hit.normal), None),
        };
        let bsdf = self.lobe_at(hit, n, textures);
        match terminator {
            Some(t) => bsdf.map(|b| b.with_terminator(t)),
            None => bsdf,
        }
    }

    /// The BSDF of the material's kind at `hit` about shading normal `n`.
    #[inline(always)]
    fn lobe_at(&self, hit: &HitRecord, n: Vec3, textures: &[Texture]) -> Option<Bsdf> {
        // The notes' lobes scatter about the normal alone.
        let notes = |lobe| Some(Bsdf::new(Frame::normal_only(n), hit.normal, lobe));
        // The others in the frame of the surface's tangent.
        let local = |lobe| {
            let frame = Frame::from_normal_tangent(n, hit.dpdu);
            Some(Bsdf::new(frame, hit.normal, lobe))
        };
        match &self.kind {
            // `bsdf` gives a mix's chosen material, never the mix.
            Kind::Black | Kind::Mix(_) | Kind::Interface => None,
            Kind::Diffuse(d) => notes(Lobe::Diffuse(d.at(hit, textures))),
            Kind::Metal(m) => notes(Lobe::Metal(m.at(hit, textures))),
            Kind::Dielectric(d) => match d.at(hit, textures) {
                lobe @ Lobe::Dielectric(_) => notes(lobe),
                lobe => local(lobe),
            },
            Kind::Conductor(c) => local(Lobe::Conductor(c.at(hit, textures))),
            Kind::Plastic(p) => local(Lobe::Plastic(p.at(hit, textures))),
            Kind::Principled(p) => {
                let frame = Frame::from_normal_tangent(n, hit.dpdu);
                let lobe = p.at(hit, textures, &frame);
                Some(Bsdf::new(frame, hit.normal, Lobe::Principled(lobe)))
            }
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

    /// How much the volume it encloses absorbs per unit length (glTF's
    /// `KHR_materials_volume` attenuation), if it absorbs, for a ray that
    /// leaves the volume at `hit`. A point where the thickness is 0 is a
    /// thin wall, not the side of a volume, and absorbs nothing.
    #[inline(always)]
    pub fn absorption(&self, hit: &HitRecord, textures: &[Texture]) -> Option<Color> {
        match &self.kind {
            Kind::Principled(p) => p.absorption.filter(|_| p.thickness.at(hit, textures) > 0.0),
            _ => None,
        }
    }

    /// Whether it is no surface but the boundary of media, which paths
    /// cross unchanged.
    #[inline(always)]
    pub fn is_interface(&self) -> bool {
        matches!(self.kind, Kind::Interface)
    }

    /// The medium a path leaving this surface at `hit` along `direction`
    /// travels in: the one on that side where the material names media,
    /// else `current`, the one it was in.
    #[inline]
    pub fn medium_beyond(
        &self,
        hit: &HitRecord,
        direction: Vec3,
        current: Option<u32>,
    ) -> Option<u32> {
        match self.media {
            Some(sides) => sides.beyond(hit.outward_normal(), direction),
            None => current,
        }
    }

    /// The share of light that goes straight through the surface at `hit`
    /// (seen from `wo`, back along the ray), undeviated: all of it at an
    /// interface, what a thin sheet of glass lets through, none elsewhere.
    /// What a shadow ray carries past it in a scene with media.
    pub fn straight_through(&self, hit: &HitRecord, wo: Vec3, textures: &[Texture]) -> Color {
        match self.kind {
            Kind::Interface => return Color::ONE,
            // Only glass (or a mix holding some) can be a thin sheet: the
            // rest block without their scattering worked out.
            Kind::Dielectric(_) | Kind::Mix(_) => {}
            _ => return Color::ZERO,
        }
        match self.bsdf(hit, wo, textures).map(|b| b.lobe) {
            Some(Lobe::ThinDielectric(sheet)) => {
                Color::splat(1.0 - sheet.reflectance(wo.dot(hit.normal)))
            }
            _ => Color::ZERO,
        }
    }

    /// How many materials it is: 1, or for a mix those it holds.
    fn parts(&self) -> usize {
        match &self.kind {
            Kind::Mix(m) => m.materials.iter().map(Material::parts).sum(),
            _ => 1,
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
            Kind::Conductor(c) => (c.roughness.textures())
                .chain(c.eta.texture())
                .chain(c.k.texture())
                .collect(),
            Kind::Plastic(p) => p.textures(),
            Kind::Principled(p) => p.textures(),
            Kind::Mix(m) => m.textures(),
            Kind::Black | Kind::Interface => Vec::new(),
        };
        out.extend(self.emission.and_then(|e| e.radiance.texture()));
        out.extend(self.shape.map(|s| match s {
            Shape::Normal { texture, .. } | Shape::Bump { texture, .. } => texture,
        }));
        out.extend(self.opacity.and_then(|o| o.value.texture()));
        out
    }
}
