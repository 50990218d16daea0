//! The plastic material: a diffuse base under a clear dielectric coat,
//! smooth or rough (see [`crate::bsdf::plastic`] for the model).

use super::param::{self, ColorDesc, ColorParam, ColorRange, Invalid, Textures};
use super::roughness::Roughness;
use super::{Kind, Material};
use crate::bsdf::coat::CoatTable;
use crate::bsdf::plastic::Plastic as PlasticLobe;
use crate::geometry::HitRecord;
use crate::texture::Texture;

material_desc! {
    microfacets;
    /// A coated diffuse surface: paint, plastic, varnished wood.
    pub struct PlasticDesc {
        /// The base's albedo, each channel in [0, 1], or a texture; 0.5
        /// grey when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub albedo: Option<ColorDesc>,
        /// The coat's index of refraction, > 0; 1.5 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub ior: Option<f64>,
        /// Colour the light between base and coat at every bounce
        /// (ρ / (1 − ρ Ri): true, the default) or once (ρ / (1 − Ri):
        /// Mitsuba's `nonlinear = false`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub nonlinear: Option<bool>,
    }
}

/// The coat's index when none is given.
const DEFAULT_IOR: f64 = 1.5;

/// The largest index a coat may have: where the tables of a rough coat
/// end, and the fits of a smooth coat's internal reflection still hold.
const MAX_IOR: f64 = crate::bsdf::albedo::ETA_MAX as f64;

impl PlasticDesc {
    /// Plastic of albedo `albedo` under a coat of roughness `roughness`.
    pub fn new(albedo: impl Into<ColorDesc>, roughness: f64) -> Self {
        PlasticDesc {
            albedo: Some(albedo.into()),
            roughness: Some(roughness.into()),
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let albedo = match &self.albedo {
            Some(a) => textures.color(&format!("{field}.albedo"), a, ColorRange::Unit)?,
            None => ColorParam::Const(crate::math::Color::splat(0.5)),
        };
        let ior = param::number(
            &format!("{field}.ior"),
            self.ior.unwrap_or(DEFAULT_IOR),
            param::Range::Index(MAX_IOR),
        )?;
        let roughness = self.microfacets(field, 0.0, textures)?;
        let coat = roughness
            .constant()
            .filter(|d| d.alpha_x == d.alpha_y)
            .map(|d| CoatTable::of(&d, ior));
        Ok(Material::new(Kind::Plastic(Box::new(Plastic {
            albedo,
            ior,
            roughness,
            coat,
            multiscatter: self.multiscatter,
            nonlinear: self.nonlinear.unwrap_or(true),
        }))))
    }
}

/// A coated diffuse surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The base's albedo.
    pub albedo: ColorParam,
    /// The coat's index of refraction.
    pub ior: f32,
    /// The coat's microfacets.
    pub roughness: Roughness,
    /// A rough coat's own table, when its roughness is one isotropic
    /// number.
    pub coat: Option<&'static CoatTable>,
    /// Return the energy the coat's single scattering loses.
    pub multiscatter: bool,
    /// Colour the light between base and coat at every bounce.
    pub nonlinear: bool,
}

impl Plastic {
    /// The lobe at `hit` (the same from either side: the base is opaque).
    #[inline]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> PlasticLobe {
        PlasticLobe {
            albedo: self.albedo.albedo_at(hit, textures),
            eta: self.ior,
            roughness: self.roughness.at(hit, textures),
            coat: self.coat,
            multiscatter: self.multiscatter,
            nonlinear: self.nonlinear,
        }
    }

    /// The textures it looks up.
    pub fn textures(&self) -> Vec<u32> {
        self.albedo
            .texture()
            .into_iter()
            .chain(self.roughness.textures())
            .collect()
    }
}
