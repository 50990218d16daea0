//! The principled material: glTF 2.0's metallic-roughness material and
//! its KHR extensions (specular, ior, transmission, volume, clear coat,
//! sheen, emissive strength), every parameter a value or a texture. The
//! lobe is [`crate::bsdf::principled`]; glTF files are read into it
//! ([`crate::mesh`]), and scene files describe it with the same names.

use super::param::{
    self, ColorDesc, ColorParam, ColorRange, Invalid, Range, ScalarDesc, ScalarParam, Textures,
    Triple,
};
use super::roughness::Roughness;
use super::{Kind, Material, Shape};
use crate::bsdf::microfacet::{Microfacet, Model, SMOOTH_ALPHA};
use crate::bsdf::principled::Principled as PrincipledLobe;
use crate::bsdf::{sheen, Frame};
use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::texture::Texture;

material_desc! {
    microfacets;
    /// The glTF metallic-roughness material with its layers.
    pub struct PrincipledDesc {
        /// The base colour, each channel in [0, 1], or a texture; 0.8 grey
        /// when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub base_color: Option<ColorDesc>,
        /// How much of it is metal, in [0, 1]; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub metallic: Option<ScalarDesc>,
        /// The dielectric's index of refraction (`KHR_materials_ior`),
        /// ≥ 1; 1.5 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub ior: Option<f64>,
        /// The strength of the dielectric's specular reflection
        /// (`KHR_materials_specular`), in [0, 1]; 1 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub specular: Option<ScalarDesc>,
        /// The colour of its reflectance at normal incidence, ≥ 0; white
        /// when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub specular_color: Option<ColorDesc>,
        /// The fraction of the dielectric's base that lets light through
        /// (`KHR_materials_transmission`), in [0, 1]; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub transmission: Option<ScalarDesc>,
        /// The thickness of the volume behind the surface
        /// (`KHR_materials_volume`), ≥ 0: 0 (the default) is a thin wall
        /// light goes straight through; more refracts into a volume.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub thickness: Option<ScalarDesc>,
        /// The colour white light becomes after `attenuation_distance`
        /// inside the volume, each channel in (0, 1].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub attenuation_color: Option<Triple>,
        /// The distance over which it becomes that colour, > 0; none: no
        /// absorption.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub attenuation_distance: Option<f64>,
        /// The clear coat's strength (`KHR_materials_clearcoat`), in
        /// [0, 1]; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub clearcoat: Option<ScalarDesc>,
        /// The coat's roughness in [0, 1]; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub clearcoat_roughness: Option<ScalarDesc>,
        /// A normal map for the coat alone; none: the coat follows the
        /// surface, not the base's normal map.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub clearcoat_normal_map: Option<String>,
        /// How far the coat's normal map tilts the normal, as
        /// `normal_scale` does for the base's; 1 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub clearcoat_normal_scale: Option<f64>,
        /// The sheen's colour (`KHR_materials_sheen`), each channel in
        /// [0, 1]; black (no sheen) when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub sheen_color: Option<ColorDesc>,
        /// The sheen's roughness in [0, 1]; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub sheen_roughness: Option<ScalarDesc>,
    }
}

/// The smallest α of the specular layers: glTF allows roughness 0, which
/// as a delta would have no density to weigh light samples against.
const MIN_ALPHA: f32 = 2.0 * SMOOTH_ALPHA;

impl PrincipledDesc {
    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let at = |name: &str| format!("{field}.{name}");
        let mut scalar = |name: &str, s: &Option<ScalarDesc>, default: f64, range: Range| match s {
            Some(s) => textures.scalar(&at(name), s, range),
            None => Ok(ScalarParam::Const(default as f32)),
        };
        let metallic = scalar("metallic", &self.metallic, 0.0, Range::Unit)?;
        let specular = scalar("specular", &self.specular, 1.0, Range::Unit)?;
        let transmission = scalar("transmission", &self.transmission, 0.0, Range::Unit)?;
        let thickness = scalar("thickness", &self.thickness, 0.0, Range::NonNegative)?;
        let clearcoat = scalar("clearcoat", &self.clearcoat, 0.0, Range::Unit)?;
        let clearcoat_roughness = scalar(
            "clearcoat_roughness",
            &self.clearcoat_roughness,
            0.0,
            Range::Unit,
        )?;
        let sheen_roughness = scalar("sheen_roughness", &self.sheen_roughness, 0.0, Range::Unit)?;
        let mut color = |name: &str, c: &Option<ColorDesc>, default: f32, range| match c {
            Some(c) => textures.color(&at(name), c, range),
            None => Ok(ColorParam::Const(Color::splat(default))),
        };
        let base_color = color("base_color", &self.base_color, 0.8, ColorRange::Unit)?;
        let specular_color = color(
            "specular_color",
            &self.specular_color,
            1.0,
            ColorRange::NonNegative,
        )?;
        let sheen_color = color("sheen_color", &self.sheen_color, 0.0, ColorRange::Unit)?;
        let ior = param::number(
            &at("ior"),
            self.ior.unwrap_or(1.5),
            Range::Index(param::MAX_LAYER_IOR),
        )?;
        let roughness = self.microfacets(field, 0.5, textures)?;
        let absorption = self.absorption(field)?;
        let coat_normal = match (&self.clearcoat_normal_map, self.clearcoat_normal_scale) {
            (Some(name), scale) => Some((
                textures.normal_map(&at("clearcoat_normal_map"), name)?,
                match scale {
                    Some(v) => param::number(&at("clearcoat_normal_scale"), v, Range::NonNegative)?,
                    None => 1.0,
                },
            )),
            (None, Some(_)) => {
                return Err(Invalid::scales_missing(
                    at("clearcoat_normal_scale"),
                    "clearcoat_normal_map",
                ))
            }
            (None, None) => None,
        };
        Ok(Material::new(Kind::Principled(Box::new(Principled {
            base_color,
            vertex_color: false,
            metallic,
            roughness,
            ior,
            specular,
            specular_color,
            transmission,
            thickness,
            absorption,
            clearcoat,
            clearcoat_roughness,
            coat_normal,
            sheen_color,
            sheen_roughness,
            multiscatter: self.multiscatter,
        }))))
    }

    /// σ of the volume's absorption from `attenuation_color` and
    /// `attenuation_distance` (Beer–Lambert: c = e^(−σd)).
    fn absorption(&self, field: &str) -> Result<Option<Color>, Invalid> {
        match (self.attenuation_color, self.attenuation_distance) {
            (None, None) => Ok(None),
            (c, d) => {
                let c = c.unwrap_or([1.0; 3]);
                if c.iter().any(|x| !(*x > 0.0 && *x <= 1.0)) {
                    return Err(Invalid::new(
                        format!("{field}.attenuation_color"),
                        format!("each channel must be in (0, 1], got {c:?}"),
                    ));
                }
                let Some(d) = d else {
                    return Err(Invalid::new(
                        format!("{field}.attenuation_color"),
                        "needs `attenuation_distance`, the distance over which light takes that colour",
                    ));
                };
                let d =
                    param::number(&format!("{field}.attenuation_distance"), d, Range::Positive)?;
                let sigma = Color::new(c[0] as f32, c[1] as f32, c[2] as f32).map(|x| -x.ln() / d);
                Ok((sigma != Color::ZERO).then_some(sigma))
            }
        }
    }
}

/// The principled material, compiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// The base colour.
    pub base_color: ColorParam,
    /// Whether the base colour is multiplied by the mesh's vertex colour
    /// (glTF `COLOR_0`).
    pub vertex_color: bool,
    /// How much is metal.
    pub metallic: ScalarParam,
    /// The specular microfacets.
    pub roughness: Roughness,
    /// The dielectric's index.
    pub ior: f32,
    /// The dielectric's specular strength.
    pub specular: ScalarParam,
    /// Its colour at normal incidence.
    pub specular_color: ColorParam,
    /// The fraction of the base transmitting.
    pub transmission: ScalarParam,
    /// The volume's thickness (0: a thin wall).
    pub thickness: ScalarParam,
    /// The volume's absorption coefficient per unit length, if any.
    pub absorption: Option<Color>,
    /// The clear coat's strength.
    pub clearcoat: ScalarParam,
    /// Its roughness.
    pub clearcoat_roughness: ScalarParam,
    /// Its own normal map, if any, and the map's scale.
    pub coat_normal: Option<(u32, f32)>,
    /// The sheen's colour.
    pub sheen_color: ColorParam,
    /// The sheen's roughness.
    pub sheen_roughness: ScalarParam,
    /// Return the energy single scattering loses.
    pub multiscatter: bool,
}

impl Principled {
    /// The lobe at `hit` in shading frame `frame` (the base's normal map
    /// applied).
    #[inline]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture], frame: &Frame) -> PrincipledLobe {
        let mut base_color = self.base_color.albedo_at(hit, textures);
        if self.vertex_color {
            base_color *= Vec3::from_vec4(hit.color).clamp(Color::ZERO, Color::ONE);
        }
        let specular = self
            .roughness
            .at(hit, textures)
            .map_or(Microfacet::new(MIN_ALPHA, MIN_ALPHA, Model::Ggx), |d| {
                Microfacet::new(d.alpha_x.max(MIN_ALPHA), d.alpha_y.max(MIN_ALPHA), d.model)
            });
        let unit = |p: &ScalarParam| p.at(hit, textures).clamp(0.0, 1.0);
        let strength = unit(&self.specular);
        let r = (self.ior - 1.0) / (self.ior + 1.0);
        let f0 = (Color::splat(r * r) * self.specular_color.at(hit, textures).max(Color::ZERO))
            .min(Color::ONE)
            * strength;
        let thin = self.thickness.at(hit, textures) <= 0.0;
        let clearcoat = unit(&self.clearcoat);
        let coat_roughness = unit(&self.clearcoat_roughness);
        let coat_alpha = (coat_roughness * coat_roughness).max(MIN_ALPHA);
        let coat_normal = if clearcoat > 0.0 {
            self.coat_normal_at(hit, textures, frame)
        } else {
            Vec3::Z
        };
        PrincipledLobe {
            base_color,
            metallic: unit(&self.metallic),
            specular,
            f0,
            f90: strength,
            transmission: unit(&self.transmission),
            eta: if hit.front_face {
                self.ior
            } else {
                1.0 / self.ior
            },
            thin,
            clearcoat,
            coat: Microfacet::new(coat_alpha, coat_alpha, Model::Ggx),
            coat_normal,
            sheen_color: self.sheen_color.albedo_at(hit, textures),
            sheen_roughness: unit(&self.sheen_roughness).max(sheen::MIN_ROUGHNESS),
            multiscatter: self.multiscatter,
        }
    }

    /// The coat's normal in the local frame: its own map, or else the
    /// surface's normal before the base's map tilted it.
    #[inline]
    fn coat_normal_at(&self, hit: &HitRecord, textures: &[Texture], frame: &Frame) -> Vec3 {
        let n = match self.coat_normal {
            Some((texture, scale)) => Shape::Normal { texture, scale }.normal(hit, textures),
            None => hit.shading_normal,
        };
        let local = frame.to_local(n).normalize_or_zero();
        if local.z > 1e-4 {
            local
        } else {
            Vec3::Z
        }
    }

    /// The textures it looks up.
    pub fn textures(&self) -> Vec<u32> {
        let scalars = [
            self.metallic,
            self.specular,
            self.transmission,
            self.thickness,
            self.clearcoat,
            self.clearcoat_roughness,
            self.sheen_roughness,
        ];
        let colors = [self.base_color, self.specular_color, self.sheen_color];
        scalars
            .iter()
            .filter_map(ScalarParam::texture)
            .chain(colors.iter().filter_map(ColorParam::texture))
            .chain(self.roughness.textures())
            .chain(self.coat_normal.map(|(texture, _)| texture))
            .collect()
    }
}
