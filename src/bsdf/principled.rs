//! The glTF 2.0 metallic-roughness material (the specification's Appendix
//! B) with the layers of its KHR material extensions, as one lobe:
//!
//! - a metal, `metallic` of it, reflecting by Schlick's Fresnel from the
//!   base colour off GGX microfacets;
//! - a dielectric, the rest, of reflectance F = f0 + (f90 − f0)(1 − |V·H|)⁵
//!   (f0 from `ior`, `specular` and `specular_color`:
//!   KHR_materials_specular, KHR_materials_ior), over a base that diffuses
//!   the base colour or, `transmission` of it, lets it through
//!   (KHR_materials_transmission): straight through a thin wall, blurred by
//!   the microfacets, or refracted into a volume (KHR_materials_volume);
//!   the base weighted by 1 − max(F);
//! - sheen on top (KHR_materials_sheen: the Charlie distribution, the
//!   layers below scaled by 1 − max(sheen colour)·E(μ));
//! - a clear coat on top of all (KHR_materials_clearcoat: f0 = 0.04, its
//!   own roughness and normal, weighted by its Fresnel at the view).
//!
//! The microfacet terms use the height-correlated Smith shadowing the
//! appendix gives (also for the transmission, which the extension's
//! informative text writes separable). The coat's weight depends on the
//! view alone, as the extension defines it, so a coated surface is not
//! exactly reciprocal. Sampling chooses a layer in proportion to an
//! estimate of its reflectance at the view and then a direction by the
//! layer's own distribution (visible normals, or the cosine); every sample
//! is evaluated as the whole mixture.

use super::microfacet::Microfacet;
use super::{albedo, fresnel, sheen};
use super::{BsdfSample, Frame, LobeFlags};
use crate::math::{Color, Vec3};
use crate::sampling::cosine_hemisphere;
use std::f32::consts::FRAC_1_PI;

/// The coat's reflectance at normal incidence (index 1.5).
const COAT_F0: f32 = 0.04;

/// How near 1 an index counts as no interface at all.
const NO_INTERFACE: f32 = 1e-3;

/// The least probability of sampling a layer that scatters at all, so
/// that every direction it reaches has a density.
const MIN_WEIGHT: f32 = 0.02;

/// The principled material at one point, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// The base colour, each channel in [0, 1].
    pub base_color: Color,
    /// How much of it is metal, in [0, 1].
    pub metallic: f32,
    /// The microfacets of the base's specular reflection.
    pub specular: Microfacet,
    /// The dielectric's reflectance at normal incidence.
    pub f0: Color,
    /// Its reflectance at grazing incidence (`specular`).
    pub f90: f32,
    /// The fraction of the dielectric's base that transmits, in [0, 1].
    pub transmission: f32,
    /// The index below the surface over the index above (a volume's
    /// refraction).
    pub eta: f32,
    /// Whether the transmission goes straight through (a thin wall), not
    /// refracted into a volume.
    pub thin: bool,
    /// The clear coat's weight, in [0, 1] (0: none).
    pub clearcoat: f32,
    /// Its microfacets.
    pub coat: Microfacet,
    /// Its normal, in the local frame (+z unless it has a normal map of
    /// its own while the base has one).
    pub coat_normal: Vec3,
    /// The sheen's colour (black: none).
    pub sheen_color: Color,
    /// Its roughness, in [[`sheen::MIN_ROUGHNESS`], 1].
    pub sheen_roughness: f32,
    /// Return the energy the specular microfacets' single scattering loses.
    pub multiscatter: bool,
}

/// A number per layer, from one view: its estimated reflectance, or the
/// probability of sampling it.
#[derive(Clone, Copy, Debug)]
struct Weights {
    coat: f32,
    specular: f32,
    cosine: f32,
    transmission: f32,
}

fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

fn fifth(cos: f32) -> f32 {
    let m = (1.0 - cos.abs()).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

impl Principled {
    /// What kind of scattering it does.
    pub fn flags(&self) -> LobeFlags {
        let mut f = LobeFlags::REFLECTION | LobeFlags::GLOSSY;
        if self.metallic < 1.0 {
            f = f | LobeFlags::DIFFUSE;
            if self.transmission > 0.0 {
                f = f | LobeFlags::TRANSMISSION;
                if self.no_interface() {
                    f = f | LobeFlags::SPECULAR;
                }
            }
        }
        f
    }

    /// The dielectric's reflectance at cosine `cos` between the view and
    /// a microfacet: Schlick's, of the angle outside a volume seen from
    /// within (total internal reflection reflecting everything).
    #[inline]
    fn dielectric_fresnel(&self, cos: f32) -> Color {
        let mut c = cos.abs();
        if !self.thin && self.eta < 1.0 {
            let sin2_t = (1.0 - c * c) / (self.eta * self.eta);
            if sin2_t >= 1.0 {
                return Color::ONE;
            }
            c = (1.0 - sin2_t).sqrt();
        }
        fresnel::schlick(c, self.f0, Color::splat(self.f90))
    }

    /// The coat's weight seen along `wo`: clearcoat × its Fresnel.
    #[inline]
    fn coat_weight(&self, wo: Vec3) -> f32 {
        if self.clearcoat <= 0.0 {
            return 0.0;
        }
        let c = wo.dot(self.coat_normal);
        self.clearcoat * (COAT_F0 + (1.0 - COAT_F0) * fifth(c))
    }

    /// The factor on the layers under the sheen seen at cosine `mu`.
    #[inline]
    fn sheen_scale(&self, mu: f32) -> f32 {
        let s = self.sheen_color.max_element();
        if s <= 0.0 {
            return 1.0;
        }
        (1.0 - s * sheen::albedo(self.sheen_roughness, mu.abs())).max(0.0)
    }

    /// Each layer's reflectance seen along `wo`, estimated from its Fresnel
    /// factor at the view cosine `mu`: what [`Principled::weights`] samples
    /// the layers in proportion to, and [`Principled::near_mirror_share`]
    /// weighs.
    #[inline]
    fn reflectances(&self, wo: Vec3, mu: f32) -> Weights {
        let coat = self.coat_weight(wo);
        let under = 1.0 - coat;
        let scale = self.sheen_scale(mu);
        let metal = mean(self.base_color + (Color::ONE - self.base_color) * fifth(mu));
        let fd = self.dielectric_fresnel(mu).max_element();
        let m = self.metallic;
        let through = under * scale * (1.0 - m) * (1.0 - fd) * mean(self.base_color);
        let sheen = self.sheen_color.max_element();
        let sheen_w = if sheen > 0.0 {
            under * sheen * sheen::albedo(self.sheen_roughness, mu)
        } else {
            0.0
        };
        Weights {
            coat,
            specular: under * scale * (m * metal + (1.0 - m) * fd),
            cosine: through * (1.0 - self.transmission) + sheen_w,
            // Refracted through the specular microfacets.
            transmission: through * self.transmission,
        }
    }

    fn weights(&self, wo: Vec3) -> Weights {
        let r = self.reflectances(wo, wo.z);
        let m = self.metallic;
        let base = mean(self.base_color);
        let sheen = self.sheen_color.max_element();
        let floor = |w: f32, present: bool| if present { w.max(MIN_WEIGHT) } else { 0.0 };
        let w = Weights {
            coat: floor(r.coat, self.clearcoat > 0.0),
            specular: floor(
                r.specular,
                m > 0.0 || self.f0.max_element() > 0.0 || self.f90 > 0.0,
            ),
            cosine: floor(
                r.cosine,
                (m < 1.0 && self.transmission < 1.0 && base > 0.0) || sheen > 0.0,
            ),
            transmission: floor(
                r.transmission,
                m < 1.0 && self.transmission > 0.0 && base > 0.0,
            ),
        };
        let sum = w.coat + w.specular + w.cosine + w.transmission;
        if !(sum > 0.0) {
            return Weights {
                coat: 0.0,
                specular: 0.0,
                cosine: 0.0,
                transmission: 0.0,
            };
        }
        Weights {
            coat: w.coat / sum,
            specular: w.specular / sum,
            cosine: w.cosine / sum,
            transmission: w.transmission / sum,
        }
    }

    /// The share of what it reflects and transmits along `wo` that goes by
    /// layers whose microfacets are near mirrors (see
    /// [`Lobe::feature_albedo_seen`](super::Lobe::feature_albedo_seen)),
    /// each layer's estimated as [`Principled::weights`] estimates it.
    pub fn near_mirror_share(&self, wo: Vec3) -> f32 {
        let r = self.reflectances(wo, wo.z.abs());
        let mut mirror = 0.0;
        if self.coat.is_near_mirror() {
            mirror += r.coat;
        }
        if self.specular.is_near_mirror() {
            mirror += r.specular + r.transmission;
        }
        let total = r.coat + r.specular + r.cosine + r.transmission;
        if total > 0.0 {
            mirror / total
        } else {
            0.0
        }
    }

    /// The frame of the coat's normal, when it is not the shading normal.
    #[inline]
    fn coat_frame(&self) -> Option<Frame> {
        (self.coat_normal != Vec3::Z).then(|| Frame::from_normal(self.coat_normal))
    }

    /// A direction for light leaving along `wo`, from `uc` (the layer) and
    /// `u`, uniform in [0, 1).
    #[inline]
    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let w = self.weights(wo);
        let d = &self.specular;
        let (wi, flags) = if uc < w.coat {
            let frame = self.coat_frame();
            let co = frame.map_or(wo, |f| f.to_local(wo));
            if !(co.z > 0.0) {
                return None;
            }
            let ci = fresnel::reflect(co, self.coat.sample_wm(co, u));
            // Below the coat's own horizon the coat's density is zero.
            if !(ci.z > 0.0) {
                return None;
            }
            (frame.map_or(ci, |f| f.to_world(ci)), LobeFlags::GLOSSY)
        } else if uc < w.coat + w.specular {
            (fresnel::reflect(wo, d.sample_wm(wo, u)), LobeFlags::GLOSSY)
        } else if uc < w.coat + w.specular + w.cosine {
            (cosine_hemisphere(u), LobeFlags::DIFFUSE)
        } else if w.transmission > 0.0 {
            if self.no_interface() {
                return Some(self.straight_through(wo, &w));
            }
            let wm = d.sample_wm(wo, u);
            let wi = if self.thin {
                let r = fresnel::reflect(wo, wm);
                Vec3::new(r.x, r.y, -r.z)
            } else {
                fresnel::refract(wo, wm, self.eta)?.0
            };
            (wi, LobeFlags::GLOSSY | LobeFlags::TRANSMISSION)
        } else {
            return None;
        };
        let transmitted = flags.is_transmission();
        if wi.z == 0.0 || (wi.z < 0.0) != transmitted {
            return None;
        }
        let side = if transmitted {
            LobeFlags::TRANSMISSION
        } else {
            LobeFlags::REFLECTION
        };
        BsdfSample::evaluated(self.eval_and_pdf(wo, wi), wi, flags | side)
    }

    /// f(wo, wi)·|cos θi| and the density of `wi`.
    #[inline]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return (Color::ZERO, 0.0);
        }
        let w = self.weights(wo);
        let coat = self.coat_weight(wo);
        let under = 1.0 - coat;
        if wi.z > 0.0 {
            let (layers, pdf) = self.reflect(wo, wi, &w);
            let (coat_f_cos, coat_pdf) = self.coat_reflect(wo, wi);
            (
                layers * (under * wi.z) + Color::splat(coat * coat_f_cos),
                pdf + w.coat * coat_pdf,
            )
        } else {
            let (f, pdf) = self.transmit(wo, wi, &w);
            (f * under, pdf)
        }
    }

    /// The layers under the coat reflecting (f, without the cosine) and
    /// their density.
    #[inline]
    fn reflect(&self, wo: Vec3, wi: Vec3, w: &Weights) -> (Color, f32) {
        let d = &self.specular;
        let diffuse =
            self.base_color * ((1.0 - self.metallic) * (1.0 - self.transmission) * FRAC_1_PI);
        let mut pdf = w.cosine * wi.z * FRAC_1_PI;
        let wm = (wo + wi).normalize_or_zero();
        let mut f = if wm != Vec3::ZERO && wo.dot(wm) > 0.0 && wi.dot(wm) > 0.0 {
            let voh = wo.dot(wm);
            let spec = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z);
            let fw = fifth(voh);
            let mut metal = (self.base_color + (Color::ONE - self.base_color) * fw) * spec;
            let fd = self.dielectric_fresnel(voh);
            let mut glossy = fd * spec;
            if self.multiscatter {
                metal *= albedo::conductor_compensation(d, wo, self.base_color);
                glossy *= albedo::conductor_compensation(d, wo, self.f0);
            }
            pdf += w.specular * d.pdf(wo, wm) / (4.0 * voh);
            metal * self.metallic
                + glossy * (1.0 - self.metallic)
                + diffuse * (1.0 - fd.max_element())
        } else {
            diffuse
        };
        let s = self.sheen_color.max_element();
        if s > 0.0 {
            let scale = self.sheen_scale(wo.z).min(self.sheen_scale(wi.z));
            f = f * scale + self.sheen_color * sheen::brdf(self.sheen_roughness, wo, wi);
        }
        (f, pdf)
    }

    /// The coat's reflection (f·cos θi of a white coat, the cosine to the
    /// coat's normal) and the density of sampling it.
    #[inline]
    fn coat_reflect(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        if self.clearcoat <= 0.0 {
            return (0.0, 0.0);
        }
        let frame = self.coat_frame();
        let (co, ci) = match frame {
            Some(f) => (f.to_local(wo), f.to_local(wi)),
            None => (wo, wi),
        };
        if !(co.z > 0.0 && ci.z > 0.0) {
            return (0.0, 0.0);
        }
        let wm = (co + ci).normalize_or_zero();
        if wm == Vec3::ZERO || co.dot(wm) <= 0.0 {
            return (0.0, 0.0);
        }
        // The cosine is the coat's own (ci.z), not the base's: a coat
        // whose normal is tilted from the base's reflects its Fresnel
        // weight, whatever the tilt.
        let c = &self.coat;
        let f_cos = c.d(wm) * c.g(co, ci) / (4.0 * co.z);
        (f_cos, c.pdf(co, wm) / (4.0 * co.dot(wm)))
    }

    /// Whether the surface bounds a volume of the same index as outside
    /// (glTF's "air", index 1): no microfacet refracts there, and light
    /// goes straight on whatever the roughness.
    #[inline]
    fn no_interface(&self) -> bool {
        !self.thin && (self.eta - 1.0).abs() < NO_INTERFACE
    }

    /// The transmitted sample of a surface with [`Self::no_interface`]: a
    /// delta along −`wo`, weighed as the rest of the transmission is.
    #[inline]
    fn straight_through(&self, wo: Vec3, w: &Weights) -> BsdfSample {
        let tint = self.base_color * ((1.0 - self.metallic) * self.transmission);
        let t = 1.0 - self.dielectric_fresnel(wo.z).max_element();
        let under = 1.0 - self.coat_weight(wo);
        BsdfSample {
            value: tint * (t * under * self.sheen_scale(wo.z) / w.transmission),
            wi: -wo,
            pdf: w.transmission,
            flags: LobeFlags::TRANSMISSION | LobeFlags::SPECULAR,
        }
    }

    /// The transmission (f·|cos θi|) and its density.
    #[inline]
    fn transmit(&self, wo: Vec3, wi: Vec3, w: &Weights) -> (Color, f32) {
        // A delta where there is no interface: nothing to evaluate.
        if w.transmission <= 0.0 || self.no_interface() {
            return (Color::ZERO, 0.0);
        }
        let d = &self.specular;
        let tint = self.base_color * ((1.0 - self.metallic) * self.transmission);
        let scale = self.sheen_scale(wo.z).min(self.sheen_scale(wi.z));
        if self.thin {
            // Straight through: the reflection's microfacets, mirrored
            // through the surface.
            let wr = Vec3::new(wi.x, wi.y, -wi.z);
            let wm = (wo + wr).normalize_or_zero();
            if wm == Vec3::ZERO || wo.dot(wm) <= 0.0 || wr.dot(wm) <= 0.0 {
                return (Color::ZERO, 0.0);
            }
            let voh = wo.dot(wm);
            let t = 1.0 - self.dielectric_fresnel(voh).max_element();
            let f_cos = d.d(wm) * d.g(wo, wr) / (4.0 * wo.z);
            let pdf = w.transmission * d.pdf(wo, wm) / (4.0 * voh);
            return (tint * (t * f_cos * scale), pdf);
        }
        // Refracted (Walter et al. 2007), radiance divided by η² going in.
        let etap = self.eta;
        let wm = (wi * etap + wo).normalize_or_zero();
        if wm == Vec3::ZERO {
            return (Color::ZERO, 0.0);
        }
        let wm = if wm.z < 0.0 { -wm } else { wm };
        let (dot_o, dot_i) = (wo.dot(wm), wi.dot(wm));
        if dot_o <= 0.0 || dot_i >= 0.0 {
            return (Color::ZERO, 0.0);
        }
        let t = 1.0 - self.dielectric_fresnel(dot_o).max_element();
        let denom = (dot_i + dot_o / etap).powi(2);
        let f_cos = d.d(wm) * d.g(wo, wi) * (dot_i * dot_o / (wo.z * denom)).abs() / (etap * etap);
        let pdf = w.transmission * d.pdf(wo, wm) * dot_i.abs() / denom;
        (tint * (t * f_cos * scale), pdf)
    }
}
