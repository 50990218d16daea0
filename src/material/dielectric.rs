//! The dielectric material: clear glass, water, diamond.

use super::param::{Invalid, RoughnessDesc, Textures};
use super::roughness::Roughness;
use super::{Kind, Material};
use crate::bsdf::dielectric::{ExactDielectric, SmoothDielectric};
use crate::bsdf::thin_dielectric::ThinDielectric;
use crate::bsdf::Lobe;
use crate::geometry::HitRecord;
use crate::texture::Texture;

material_desc! {
    microfacets;
    /// A clear refracting material.
    pub struct DielectricDesc {
        /// Index of refraction, > 0.
        pub ior: f64,
        /// Never reflect partially (no Schlick term).
        #[serde(default)]
        pub refract_only: bool,
        /// How a smooth surface divides light between reflection and
        /// refraction: "schlick" (the notes' approximation, the default) or
        /// "exact" (the Fresnel equations, as a rough surface always does).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub fresnel: Option<FresnelDesc>,
        /// A thin sheet (a window pane, a bubble) rather than the surface
        /// of a solid: light is mirrored or goes straight through, its
        /// bounces inside the sheet counted; smooth only.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        pub thin: bool,
    }
}

/// How a smooth dielectric reflects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FresnelDesc {
    /// Schlick's approximation.
    Schlick,
    /// The Fresnel equations.
    Exact,
}

impl DielectricDesc {
    /// Glass of index of refraction `ior`.
    pub fn new(ior: f64) -> Self {
        DielectricDesc {
            ior,
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let ior = self.ior;
        if !(ior.abs() <= f64::from(f32::MAX)) {
            return Err(Invalid::new(
                format!("{field}.ior"),
                format!(
                    "must be a finite number of magnitude at most {:e}, got {ior}",
                    f32::MAX
                ),
            ));
        }
        if !(ior as f32 > 0.0) {
            return Err(Invalid::new(
                format!("{field}.ior"),
                format!("index of refraction must be greater than 0, got {ior}"),
            ));
        }
        let roughness = self.microfacets(field, 0.0, textures)?;
        // Given as zero (or not given): the notes' glass, to the bit.
        let zero = |r: Option<&RoughnessDesc>| {
            r.is_none_or(|r| matches!(r, RoughnessDesc::Value(v) if *v == 0.0))
        };
        let rough = !(zero(self.roughness.as_ref()) && zero(self.alpha.as_ref()));
        if rough && self.refract_only {
            return Err(Invalid::new(
                format!("{field}.refract_only"),
                "is the notes' smooth glass: a rough dielectric reflects by the Fresnel equations",
            ));
        }
        if self.thin {
            let refused = if rough {
                Some(("roughness", "a thin sheet is smooth"))
            } else if self.refract_only {
                Some((
                    "refract_only",
                    "a thin sheet reflects by the Fresnel equations",
                ))
            } else if self.fresnel == Some(FresnelDesc::Schlick) {
                Some((
                    "fresnel",
                    "a thin sheet reflects by the Fresnel equations (\"exact\")",
                ))
            } else {
                None
            };
            if let Some((name, why)) = refused {
                return Err(Invalid::new(format!("{field}.{name}"), why));
            }
        }
        let exact = match self.fresnel {
            Some(FresnelDesc::Schlick) if rough => return Err(Invalid::new(
                format!("{field}.fresnel"),
                "a rough dielectric reflects by the Fresnel equations (\"exact\"), not Schlick's",
            )),
            Some(FresnelDesc::Exact) if self.refract_only => return Err(Invalid::new(
                format!("{field}.refract_only"),
                "is the notes' glass, which never reflects; the Fresnel equations (\"exact\") do",
            )),
            Some(f) => f == FresnelDesc::Exact,
            None => rough,
        };
        Ok(Material::new(Kind::Dielectric(Dielectric {
            ior: ior as f32,
            refract_only: self.refract_only,
            roughness: rough.then_some(roughness),
            exact,
            multiscatter: self.multiscatter,
            thin: self.thin,
        })))
    }
}

/// A clear refracting material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Index of refraction relative to the surrounding medium (glass ≈ 1.5).
    /// An inner sphere with 1/η models a hollow shell.
    pub ior: f32,
    /// Refract whenever Snell's law allows it and never reflect partially
    /// (no Schlick term): the notes' "only refracting" figure.
    pub refract_only: bool,
    /// The microfacets of frosted glass, reflecting and refracting by the
    /// exact Fresnel equations; `None` for a smooth one.
    pub roughness: Option<Roughness>,
    /// Reflect by the Fresnel equations (always when rough); a smooth
    /// surface without is the notes' glass, by Schlick's approximation.
    pub exact: bool,
    /// Return the energy single scattering loses.
    pub multiscatter: bool,
    /// A thin sheet: mirrored or straight through.
    pub thin: bool,
}

impl Dielectric {
    /// The lobe at `hit`: η/η′ by the side the ray arrives from.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> Lobe {
        match &self.roughness {
            None if self.thin => Lobe::ThinDielectric(ThinDielectric { eta: self.ior }),
            None if self.exact => Lobe::ExactDielectric(ExactDielectric {
                eta: crate::bsdf::fresnel::rough_eta(self.ior, hit.front_face),
                roughness: None,
                multiscatter: false,
            }),
            None => Lobe::Dielectric(SmoothDielectric {
                eta_ratio: if hit.front_face {
                    1.0 / self.ior
                } else {
                    self.ior
                },
                refract_only: self.refract_only,
            }),
            Some(r) => Lobe::ExactDielectric(ExactDielectric {
                eta: crate::bsdf::fresnel::rough_eta(self.ior, hit.front_face),
                roughness: r.at(hit, textures),
                multiscatter: self.multiscatter,
            }),
        }
    }
}
