//! The conductor material: a metal by its complex index of refraction (a
//! measured one by name, or η and k given), smooth or rough.

use super::metals;
use super::param::{ColorParam, ColorRange, Invalid, Textures, Triple};
use super::roughness::Roughness;
use super::{Kind, Material};
use crate::bsdf::conductor::Conductor as ConductorLobe;
use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::scene::desc::ColorDesc;
use crate::texture::Texture;

material_desc! {
    microfacets;
    /// A metal: Fresnel reflection by a complex index of refraction, off a
    /// mirror or rough microfacets.
    pub struct ConductorDesc {
        /// A measured metal by name ("Au", "Ag", "Cu", "Al", "Cr", "Fe",
        /// "Ni", "Ti", "Pt", …; see [`metals`]), or none when `eta` and
        /// `k` are given.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub metal: Option<String>,
        /// The real part of the index of refraction per channel, ≥ 0, or
        /// the name of a colour texture giving it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub eta: Option<ColorDesc>,
        /// The imaginary part (absorption) per channel, ≥ 0, or the name
        /// of a colour texture giving it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub k: Option<ColorDesc>,
    }
}

impl ConductorDesc {
    /// The named metal `metal` of roughness `roughness`.
    pub fn named(metal: &str, roughness: f64) -> Self {
        ConductorDesc {
            metal: Some(metal.to_string()),
            roughness: Some(roughness.into()),
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let (eta, k) = match (&self.metal, &self.eta, &self.k) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                return Err(Invalid::new(
                    format!("{field}.metal"),
                    "give `metal` or `eta` and `k`, not both",
                ))
            }
            (Some(name), None, None) => {
                let m = metals::find(name).ok_or_else(|| {
                    let known: Vec<&str> = metals::names().collect();
                    let mut message = format!(
                        "unknown metal \"{name}\"; the known ones are {}",
                        known.join(", ")
                    );
                    if let Some(c) = crate::hint::closest(name, known.iter().copied()) {
                        message = format!("{message} (did you mean \"{c}\"?)");
                    }
                    Invalid::new(format!("{field}.metal"), message)
                })?;
                (
                    ColorParam::Const(Color::from_array(m.eta)),
                    ColorParam::Const(Color::from_array(m.k)),
                )
            }
            (None, Some(eta), Some(k)) => {
                let part = |name: &str, c: &ColorDesc, textures: &mut dyn Textures| match c {
                    ColorDesc::Rgb(v) => {
                        index(&format!("{field}.{name}"), *v).map(ColorParam::Const)
                    }
                    texture => {
                        textures.color(&format!("{field}.{name}"), texture, ColorRange::NonNegative)
                    }
                };
                (part("eta", eta, textures)?, part("k", k, textures)?)
            }
            (None, Some(_), None) | (None, None, Some(_)) => {
                return Err(Invalid::new(
                    format!("{field}.{}", if self.eta.is_some() { "k" } else { "eta" }),
                    "a conductor's index of refraction needs both `eta` and `k`",
                ))
            }
            (None, None, None) => {
                return Err(Invalid::new(
                    field,
                    "a conductor needs `metal` (a measured metal by name) or `eta` and `k`",
                ))
            }
        };
        let roughness = self.microfacets(field, 0.0, textures)?;
        Ok(Material::new(Kind::Conductor(Box::new(Conductor {
            eta,
            k,
            roughness,
            multiscatter: self.multiscatter,
        }))))
    }
}

/// An index of refraction given per channel: finite, not negative.
fn index(field: &str, v: Triple) -> Result<Color, Invalid> {
    if v.iter()
        .any(|x| !(x.is_finite() && *x >= 0.0 && *x <= f64::from(f32::MAX)))
    {
        return Err(Invalid::new(
            field,
            format!("must be finite and not negative, got {v:?}"),
        ));
    }
    Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
}

/// A metal surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// The real part of the index of refraction.
    pub eta: ColorParam,
    /// The imaginary part.
    pub k: ColorParam,
    /// The microfacet width.
    pub roughness: Roughness,
    /// Return the energy single scattering loses.
    pub multiscatter: bool,
}

impl Conductor {
    /// The lobe at `hit`.
    #[inline]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> ConductorLobe {
        ConductorLobe {
            // A texture may hold negative values; an index has none.
            eta: self.eta.at(hit, textures).max(Color::ZERO),
            k: self.k.at(hit, textures).max(Color::ZERO),
            tint: Color::ONE,
            roughness: self.roughness.at(hit, textures),
            multiscatter: self.multiscatter,
        }
    }
}
