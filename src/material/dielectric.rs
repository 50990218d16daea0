//! The dielectric material: clear glass, water, diamond.

use super::param::{Invalid, Textures};
use super::{Kind, Material};
use crate::bsdf::dielectric::SmoothDielectric;
use crate::geometry::HitRecord;

material_desc! {
    /// A clear refracting material.
    pub struct DielectricDesc {
        /// Index of refraction, > 0.
        pub ior: f64,
        /// Never reflect partially (no Schlick term).
        #[serde(default)]
        pub refract_only: bool,
    }
}

impl DielectricDesc {
    /// Glass of index of refraction `ior`.
    pub fn new(ior: f64) -> Self {
        DielectricDesc {
            ior,
            ..Default::default()
        }
    }

    pub(super) fn compile(&self, field: &str, _: &mut dyn Textures) -> Result<Material, Invalid> {
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
        Ok(Material::new(Kind::Dielectric(Dielectric {
            ior: ior as f32,
            refract_only: self.refract_only,
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
}

impl Dielectric {
    /// The lobe at `hit`: η/η′ by the side the ray arrives from.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord) -> SmoothDielectric {
        SmoothDielectric {
            eta_ratio: if hit.front_face {
                1.0 / self.ior
            } else {
                self.ior
            },
            refract_only: self.refract_only,
        }
    }
}
