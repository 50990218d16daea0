//! A rough material's microfacet width, as a scene gives it: `roughness`
//! in [0, 1] with α = roughness² (the glTF and Blender convention) or
//! `alpha`, the raw α of pbrt and Mitsuba; one number, a pair `[u, v]`
//! (anisotropic along the tangent and the bitangent) or a scalar texture;
//! and the distribution, GGX or Beckmann.

use super::param::{self, Invalid, Range, RoughnessDesc, ScalarDesc, ScalarParam, Textures};
use crate::bsdf::microfacet::{Microfacet, Model};
use crate::geometry::HitRecord;
use crate::texture::Texture;
use serde::{Deserialize, Serialize};

/// The microfacet distribution of a rough material.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DistributionDesc {
    /// Trowbridge–Reitz: the default.
    #[default]
    Ggx,
    /// Beckmann.
    Beckmann,
}

/// A compiled microfacet width: α along the tangent and the bitangent,
/// each a constant or a texture, squared where it is a roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    /// Along the tangent.
    pub u: ScalarParam,
    /// Along the bitangent.
    pub v: ScalarParam,
    /// Whether the values are roughnesses (α = value²) rather than α.
    pub squared: bool,
    /// The distribution.
    pub model: Model,
}

impl Roughness {
    /// A smooth surface.
    pub const SMOOTH: Roughness = Roughness {
        u: ScalarParam::Const(0.0),
        v: ScalarParam::Const(0.0),
        squared: false,
        model: Model::Ggx,
    };

    /// The fields `roughness` and `alpha` (one or neither) and
    /// `distribution` of the material at `field`.
    pub fn compile(
        field: &str,
        roughness: Option<&RoughnessDesc>,
        alpha: Option<&RoughnessDesc>,
        distribution: Option<DistributionDesc>,
        textures: &mut dyn Textures,
    ) -> Result<Roughness, Invalid> {
        let (given, name, squared, range) = match (roughness, alpha) {
            (Some(_), Some(_)) => {
                return Err(Invalid::new(
                    format!("{field}.alpha"),
                    "give `roughness` (α = roughness²) or `alpha`, not both",
                ))
            }
            (Some(r), None) => (r, "roughness", true, Range::Unit),
            (None, Some(a)) => (a, "alpha", false, Range::NonNegative),
            (None, None) => {
                return Ok(Roughness {
                    model: model(distribution),
                    ..Roughness::SMOOTH
                })
            }
        };
        let at = format!("{field}.{name}");
        let one = |v: f64, at: &str| param::number(at, v, range).map(ScalarParam::Const);
        let (u, v) = match given {
            RoughnessDesc::Value(x) => {
                let p = one(*x, &at)?;
                (p, p)
            }
            RoughnessDesc::Pair([x, y]) => {
                (one(*x, &format!("{at}[0]"))?, one(*y, &format!("{at}[1]"))?)
            }
            RoughnessDesc::Texture(t) => {
                let p = textures.scalar(&at, &ScalarDesc::Texture(t.clone()), range)?;
                (p, p)
            }
            RoughnessDesc::Each([x, y]) => (
                textures.scalar(&format!("{at}[0]"), x, range)?,
                textures.scalar(&format!("{at}[1]"), y, range)?,
            ),
        };
        Ok(Roughness {
            u,
            v,
            squared,
            model: model(distribution),
        })
    }

    /// Whether it is smooth everywhere (constant and below the smallest α).
    pub fn is_smooth(&self) -> bool {
        match (self.u, self.v) {
            (ScalarParam::Const(u), ScalarParam::Const(v)) => {
                let (au, av) = self.alphas(u, v);
                Microfacet::is_smooth(au, av)
            }
            _ => false,
        }
    }

    /// The microfacets, when the roughness is constant and not smooth.
    pub fn constant(&self) -> Option<Microfacet> {
        match (self.u, self.v) {
            (ScalarParam::Const(u), ScalarParam::Const(v)) => {
                let (au, av) = self.alphas(u.max(0.0), v.max(0.0));
                (!Microfacet::is_smooth(au, av)).then(|| Microfacet::new(au, av, self.model))
            }
            _ => None,
        }
    }

    fn alphas(&self, u: f32, v: f32) -> (f32, f32) {
        if self.squared {
            (u * u, v * v)
        } else {
            (u, v)
        }
    }

    /// The microfacets at `hit`, or `None` where the surface is smooth.
    #[inline]
    pub fn at(&self, hit: &HitRecord, textures: &[Texture]) -> Option<Microfacet> {
        let u = self.u.at(hit, textures);
        let v = match (self.u, self.v) {
            (a, b) if a == b => u,
            _ => self.v.at(hit, textures),
        };
        let (au, av) = self.alphas(u.max(0.0), v.max(0.0));
        (!Microfacet::is_smooth(au, av)).then(|| Microfacet::new(au, av, self.model))
    }

    /// The textures it looks up.
    pub fn textures(&self) -> impl Iterator<Item = u32> {
        self.u.texture().into_iter().chain(self.v.texture())
    }
}

fn model(d: Option<DistributionDesc>) -> Model {
    match d.unwrap_or_default() {
        DistributionDesc::Ggx => Model::Ggx,
        DistributionDesc::Beckmann => Model::Beckmann,
    }
}
