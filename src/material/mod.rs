//! Materials: how a surface turns an incoming ray into a scattered one, and
//! the light it gives off.
//!
//! A closed set of materials dispatched with `match`, so the path loop makes no
//! virtual calls. Each states what the integrator needs:
//!
//! - [`Material::scatter`] samples a direction and the value it carries
//!   (f · |cos θ| / pdf, the *attenuation*), or absorbs the ray;
//! - [`Material::eval`] and [`Material::pdf`] give f · |cos θ| and the
//!   density of that sampling for any direction, where the material has a
//!   density the integrator can weigh against a light's
//!   ([`Material::has_density`]: the Lambertian diffuse);
//! - [`Material::is_delta`] tells the mirrors and glass apart, which scatter
//!   along single directions that a light sample never hits;
//! - [`Material::emitted`] gives the light a surface sends back.
//!
//! Fuzzy metal and the notes' other diffuse bounce models (cube, sphere
//! volume, hemisphere, absorption) have no density written down: they are
//! sampled only, as in the book, and the integrator treats them as it treats
//! a delta (no light sampling there, full weight to what the bounce finds).

pub mod dielectric;
pub mod diffuse;
pub mod emissive;
pub mod metal;

pub use dielectric::{reflectance, refract, Dielectric};
pub use diffuse::{Attenuation, BounceModel, Diffuse};
pub use emissive::Emissive;
pub use metal::{reflect, Metal};

use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::sampler::Sampler;

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Diffuse (matte) surface.
    Diffuse(Diffuse),
    /// Mirror-like metal, optionally fuzzy.
    Metal(Metal),
    /// Clear refracting material such as glass or water.
    Dielectric(Dielectric),
    /// A light-emitting surface, which scatters nothing.
    Emissive(Emissive),
}

/// The outcome of a ray meeting a surface that does not absorb it.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    /// Factor by which the scattered ray's colour is multiplied.
    pub attenuation: Color,
    /// Unit direction of the scattered ray.
    pub direction: Vec3,
}

impl Material {
    /// Scatters a ray arriving along unit `direction` at `hit`; `None` means
    /// the ray is absorbed.
    #[inline(always)]
    pub fn scatter(
        &self,
        direction: Vec3,
        hit: &HitRecord,
        sampler: &mut impl Sampler,
    ) -> Option<Scatter> {
        match self {
            Material::Diffuse(m) => m.scatter(hit, sampler),
            Material::Metal(m) => m.scatter(direction, hit, sampler),
            Material::Dielectric(m) => m.scatter(direction, hit, sampler),
            Material::Emissive(_) => None,
        }
    }

    /// Whether [`eval`](Self::eval) and [`pdf`](Self::pdf) describe how the
    /// material scatters, so that a light can be sampled from it and
    /// weighed against its own sampling: the Lambertian diffuse.
    #[inline(always)]
    pub fn has_density(&self) -> bool {
        matches!(self, Material::Diffuse(d) if d.is_lambertian())
    }

    /// Whether it scatters along single directions (a mirror, glass): no
    /// light sample can find them.
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Material::Metal(m) => m.fuzz == 0.0,
            Material::Dielectric(_) => true,
            Material::Diffuse(_) | Material::Emissive(_) => false,
        }
    }

    /// f(wo, wi) · |cos θi|: the radiance scattered towards −`wo` (the
    /// arriving ray's unit direction is `wo`) per unit radiance arriving
    /// from unit direction `wi`, per unit solid angle. Zero for materials
    /// without a density ([`has_density`](Self::has_density)).
    #[inline(always)]
    pub fn eval(&self, hit: &HitRecord, wo: Vec3, wi: Vec3) -> Color {
        self.eval_and_pdf(hit, wo, wi).0
    }

    /// [`eval`](Self::eval) and [`pdf`](Self::pdf) together, the density
    /// worked out once.
    #[inline(always)]
    pub fn eval_and_pdf(&self, hit: &HitRecord, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let pdf = self.pdf(hit, wo, wi);
        match self {
            Material::Diffuse(d) if d.is_lambertian() => (d.albedo * pdf, pdf),
            _ => (Color::ZERO, pdf),
        }
    }

    /// The density per unit solid angle with which
    /// [`scatter`](Self::scatter) leaves along unit `wi` (for a ray that
    /// arrived along `wo`). Zero for materials without a density.
    #[inline(always)]
    pub fn pdf(&self, hit: &HitRecord, _wo: Vec3, wi: Vec3) -> f32 {
        match self {
            // Only the side the path came from, by the true surface.
            Material::Diffuse(d) if d.is_lambertian() && hit.normal.dot(wi) > 0.0 => {
                diffuse::lambertian_pdf(hit, wi)
            }
            _ => 0.0,
        }
    }

    /// The radiance the surface at `hit` sends back along the ray that hit
    /// it.
    #[inline(always)]
    pub fn emitted(&self, hit: &HitRecord) -> Color {
        match self {
            Material::Emissive(e) => e.emitted(hit),
            _ => Color::ZERO,
        }
    }

    /// The material with its colour replaced by `c` (a texture's value):
    /// the albedo of a diffuse or metal surface (kept within [0, 1], so that
    /// no surface reflects more than it receives), the radiance of an
    /// emissive one. Glass has no colour.
    #[inline]
    pub fn with_color(self, c: Color) -> Material {
        match self {
            Material::Diffuse(m) => Material::Diffuse(Diffuse {
                albedo: c.clamp(Color::ZERO, Color::ONE),
                ..m
            }),
            Material::Metal(m) => Material::Metal(Metal {
                albedo: c.clamp(Color::ZERO, Color::ONE),
                ..m
            }),
            Material::Emissive(m) => Material::Emissive(Emissive { radiance: c, ..m }),
            Material::Dielectric(_) => self,
        }
    }

    /// What the material emits, if it gives off any light.
    pub fn light(&self) -> Option<Emissive> {
        match *self {
            Material::Emissive(m) if m.radiance != Color::ZERO => Some(m),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Point3;
    use crate::rng::Rng;
    use crate::testing::{chi_square, chi_square_bound};
    use std::f32::consts::PI;

    /// A hit at the origin with geometric normal `normal` and shading
    /// normal `shading` (equal: a flat surface).
    fn hit(normal: Vec3, shading: Vec3) -> HitRecord {
        HitRecord {
            point: Point3::ZERO,
            normal: normal.normalize(),
            shading_normal: shading.normalize(),
            uv: [0.0; 2],
            t: 1.0,
            front_face: true,
            material: 0,
            object: 0,
            error: 0.0,
        }
    }

    /// The sphere of directions in cells of equal solid angle: bands of z
    /// by sectors of azimuth.
    const BANDS: usize = 16;
    const SECTORS: usize = 32;

    fn cell(d: Vec3) -> usize {
        let band = (((d.z + 1.0) * 0.5 * BANDS as f32) as usize).min(BANDS - 1);
        let azimuth = d.y.atan2(d.x).rem_euclid(2.0 * PI) / (2.0 * PI);
        let sector = ((azimuth * SECTORS as f32) as usize).min(SECTORS - 1);
        band * SECTORS + sector
    }

    /// ∫ f(ω) dω over each cell, by the midpoint rule on a 12 × 12 grid of
    /// equal-area pieces of it (z and azimuth are uniform in solid angle).
    fn integrate_cells(f: impl Fn(Vec3) -> f64) -> Vec<f64> {
        let sub = 12;
        let piece = 4.0 * std::f64::consts::PI / (BANDS * SECTORS * sub * sub) as f64;
        let mut cells = vec![0.0; BANDS * SECTORS];
        for (c, total) in cells.iter_mut().enumerate() {
            let (band, sector) = (c / SECTORS, c % SECTORS);
            for i in 0..sub {
                for j in 0..sub {
                    let z =
                        -1.0 + 2.0 * (band as f64 + (i as f64 + 0.5) / sub as f64) / BANDS as f64;
                    let phi = 2.0
                        * std::f64::consts::PI
                        * (sector as f64 + (j as f64 + 0.5) / sub as f64)
                        / SECTORS as f64;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    *total += f(d) * piece;
                }
            }
        }
        cells
    }

    /// The Lambertian's directions fall into each cell as often as its
    /// `pdf` integrated over the cell says (χ², fixed seed), every sampled
    /// direction has a positive density, `eval / pdf` is the attenuation the
    /// sample carries, and `pdf` integrates to 1 and `eval` to the albedo,
    /// on a flat surface and on a smoothly shaded one (whose directions
    /// below the true surface are mirrored above it).
    #[test]
    fn lambertian_samples_follow_pdf_and_eval_matches() {
        let albedo = Color::new(0.8, 0.5, 0.2);
        let material = Material::Diffuse(Diffuse::lambertian(albedo));
        assert!(material.has_density() && !material.is_delta());
        let wo = -Vec3::Z;
        for (what, record) in [
            (
                "flat",
                hit(Vec3::new(0.2, -0.1, 1.0), Vec3::new(0.2, -0.1, 1.0)),
            ),
            ("smooth", hit(Vec3::Z, Vec3::new(0.6, 0.0, 0.8))),
        ] {
            let n = 400_000u64;
            let mut counts = vec![0u64; BANDS * SECTORS];
            let mut rng = Rng::new(23);
            for _ in 0..n {
                let s = material
                    .scatter(wo, &record, &mut rng)
                    .expect("never absorbs");
                let pdf = material.pdf(&record, wo, s.direction);
                assert!(pdf > 0.0, "{what}: sampled where pdf is 0: {}", s.direction);
                let ratio = material.eval(&record, wo, s.direction) / pdf;
                assert!((ratio - s.attenuation).abs().max_element() < 1e-6, "{what}");
                counts[cell(s.direction)] += 1;
            }
            let pdf = |d: Vec3| f64::from(material.pdf(&record, wo, d));
            let cells = integrate_cells(pdf);
            let total: f64 = cells.iter().sum();
            assert!((total - 1.0).abs() < 2e-3, "{what}: ∫pdf = {total}");
            let reflected = integrate_cells(|d| f64::from(material.eval(&record, wo, d).x));
            let sum: f64 = reflected.iter().sum();
            assert!((sum - 0.8).abs() < 2e-3, "{what}: ∫eval = {sum}");
            let expected: Vec<f64> = cells.iter().map(|p| p * n as f64).collect();
            let (chi2, dof) = chi_square(&counts, &expected);
            assert!(
                chi2 < chi_square_bound(dof),
                "{what}: χ² {chi2} with {dof} degrees of freedom"
            );
        }
    }

    /// Materials without a density report none: the mirror and glass are
    /// deltas, fuzzy metal and the notes' other bounce models are sampled
    /// only, and an emitter scatters nothing but emits.
    #[test]
    fn materials_without_a_density_report_none() {
        let record = hit(Vec3::Z, Vec3::Z);
        let (wo, wi) = (-Vec3::Z, Vec3::new(0.3, 0.0, 1.0).normalize());
        let mirror = Material::Metal(Metal {
            albedo: Color::ONE,
            fuzz: 0.0,
        });
        let fuzzy = Material::Metal(Metal {
            albedo: Color::ONE,
            fuzz: 0.3,
        });
        let glass = Material::Dielectric(Dielectric {
            ior: 1.5,
            refract_only: false,
        });
        let cube = Material::Diffuse(Diffuse {
            bounce: BounceModel::Cube,
            ..Diffuse::lambertian(Color::ONE)
        });
        let absorb = Material::Diffuse(Diffuse {
            attenuation: Attenuation::Absorb,
            ..Diffuse::lambertian(Color::ONE)
        });
        let lamp = Material::Emissive(Emissive {
            radiance: Color::splat(3.0),
            two_sided: false,
        });
        for (m, delta) in [
            (mirror, true),
            (glass, true),
            (fuzzy, false),
            (cube, false),
            (absorb, false),
            (lamp, false),
        ] {
            assert!(!m.has_density(), "{m:?}");
            assert_eq!(m.is_delta(), delta, "{m:?}");
            assert_eq!(m.pdf(&record, wo, wi), 0.0, "{m:?}");
            assert_eq!(m.eval(&record, wo, wi), Color::ZERO, "{m:?}");
        }
        assert_eq!(lamp.emitted(&record), Color::splat(3.0));
        assert_eq!(mirror.emitted(&record), Color::ZERO);
    }
}
