//! The mix material: two materials, one or the other at each point, the
//! second with probability `weight` (Mitsuba's `blendbsdf`, pbrt's `mix`).
//!
//! Choosing one material per hit, rather than summing both lobes, gives
//! the blend f = (1 − w)·f₀ + w·f₁ in expectation (every estimator of a
//! path is linear in the BSDF it meets), keeps a [`Bsdf`](crate::bsdf::Bsdf) one lobe, and
//! lets a mix hold any materials, mixes among them. The choice is a hash of
//! the hit point and the direction it is seen from, as pbrt-v4's: the same
//! hit seen the same way always makes the same choice, whatever thread or
//! pass renders it.

use super::param::{self, Invalid, ScalarDesc, ScalarParam, Textures};
use super::{Kind, Material, Shape};
use crate::geometry::HitRecord;
use crate::math::Vec3;
use crate::texture::Texture;

material_desc! {
    /// Two materials of the scene, one or the other at each point.
    pub struct MixDesc {
        /// The names of the two materials mixed.
        pub materials: [String; 2],
        /// The share of the second material, in [0, 1]: a number or a
        /// scalar texture; 0.5 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub weight: Option<ScalarDesc>,
    }
}

/// The most materials one mix may hold, counting those of the mixes in it:
/// each is a copy, and mixes of mixes double them at every level.
pub const MAX_PARTS: usize = 64;

impl MixDesc {
    /// The mix of materials `first` and `second`, the second with share
    /// `weight`.
    pub fn new(first: &str, second: &str, weight: impl Into<ScalarDesc>) -> Self {
        MixDesc {
            materials: [first.to_string(), second.to_string()],
            weight: Some(weight.into()),
            ..Default::default()
        }
    }

    pub(super) fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        let weight = match &self.weight {
            Some(w) => textures.scalar(&format!("{field}.weight"), w, param::Range::Unit)?,
            None => ScalarParam::Const(0.5),
        };
        let mut parts = Vec::with_capacity(2);
        for (i, name) in self.materials.iter().enumerate() {
            let at = format!("{field}.materials[{i}]");
            let m = textures.material(&at, name)?;
            let refuse = |what: &str| {
                Err(Invalid::new(
                    &at,
                    format!(
                        "`{name}` {what}, which a material in a mix cannot: give it to the mix"
                    ),
                ))
            };
            if m.emission.is_some() {
                return refuse("gives off light");
            }
            if m.opacity.is_some() {
                return refuse("is cut out (`opacity`)");
            }
            if matches!(&m.kind, Kind::Principled(p) if p.absorption.is_some()) {
                return refuse("absorbs light inside its volume");
            }
            parts.push(m);
        }
        let count: usize = parts.iter().map(Material::parts).sum();
        if count > MAX_PARTS {
            return Err(Invalid::new(
                format!("{field}.materials"),
                format!("the mix holds {count} materials (counting those of the mixes in it); at most {MAX_PARTS} are allowed"),
            ));
        }
        let [first, second]: [Material; 2] = parts.try_into().expect("two materials");
        Ok(Material::new(Kind::Mix(Box::new(Mix {
            materials: [first, second],
            weight,
        }))))
    }
}

/// Two materials, the second chosen with probability `weight`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mix {
    /// The materials (copies of the scene's).
    pub materials: [Material; 2],
    /// The probability of the second, in [0, 1].
    pub weight: ScalarParam,
}

impl Mix {
    /// The material used at `hit` seen from `wo`, never a mix (a mix
    /// chosen chooses in turn). Out of the path loop's way (cold), as few
    /// materials are mixes.
    #[cold]
    #[inline(never)]
    pub fn choose(&self, hit: &HitRecord, wo: Vec3, textures: &[Texture]) -> &Material {
        let mut mix = self;
        loop {
            let w = mix.weight.at(hit, textures);
            let second = w >= 1.0 || (w > 0.0 && unit_hash(hit.point, wo) < w);
            let m = &mix.materials[usize::from(second)];
            match &m.kind {
                Kind::Mix(inner) => mix = inner,
                _ => return m,
            }
        }
    }

    /// Gives the mix's own surface to the materials it holds (and to
    /// theirs, through mixes in it): its one-sidedness when it is
    /// one-sided, and its normal or bump map, which tilts the normal all
    /// of them are seen about; `field` names the mix for messages.
    pub(super) fn hand_down(
        &mut self,
        field: &str,
        one_sided: bool,
        shape: Option<Shape>,
        bump_shadowing: bool,
    ) -> Result<(), Invalid> {
        for (i, m) in self.materials.iter_mut().enumerate() {
            m.one_sided |= one_sided;
            if shape.is_some() && m.shape.is_some() {
                return Err(Invalid::new(
                    format!("{field}.materials[{i}]"),
                    "has a normal or bump map of its own, and so has the mix: give one of them the map",
                ));
            }
            match &mut m.kind {
                Kind::Mix(inner) => inner.hand_down(field, one_sided, shape, bump_shadowing)?,
                _ if shape.is_some() => {
                    m.shape = shape;
                    m.bump_shadowing = bump_shadowing;
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The textures its weight and its materials look up.
    pub fn textures(&self) -> Vec<u32> {
        let mut out: Vec<u32> = self.weight.texture().into_iter().collect();
        for m in &self.materials {
            out.extend(m.textures());
        }
        out
    }
}

/// A number in [0, 1) fixed by point `p` and direction `wo`.
#[inline]
fn unit_hash(p: Vec3, wo: Vec3) -> f32 {
    crate::rng::unit_hash([p.x, p.y, p.z, wo.x, wo.y, wo.z])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_is_even_over_the_unit_interval() {
        // Points along a line, as a pixel's samples land near each other:
        // a χ² of 16 bins against the uniform distribution.
        const N: usize = 64_000;
        let mut bins = [0usize; 16];
        for i in 0..N {
            let p = Vec3::new(0.1 + i as f32 * 1e-5, 0.3, -2.0);
            let u = unit_hash(p, Vec3::Z);
            assert!((0.0..1.0).contains(&u));
            bins[(u * 16.0) as usize] += 1;
        }
        let expected = N as f64 / 16.0;
        let chi2: f64 = bins
            .iter()
            .map(|&b| (b as f64 - expected).powi(2) / expected)
            .sum();
        // 15 degrees of freedom: P(χ² > 37.7) = 0.001.
        assert!(chi2 < 37.7, "χ² = {chi2}, bins {bins:?}");
    }

    #[test]
    fn the_direction_changes_the_choice() {
        let p = Vec3::new(0.25, 0.5, 0.75);
        let a = unit_hash(p, Vec3::Z);
        let b = unit_hash(p, Vec3::new(0.0, 0.6, 0.8));
        assert_ne!(a, b);
        assert_eq!(a, unit_hash(p, Vec3::Z));
    }
}
