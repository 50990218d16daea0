//! The notes' diffuse lobe: the four ways of bouncing and the two ways of
//! attenuating that the notes compare.

use super::metal::reflect;
use super::{Bsdf, BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};
use crate::sampler::{Dim, Sampler};
use crate::sampling;

/// How a diffuse bounce chooses its direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BounceModel {
    /// Towards a random point on the surface of the cube [-1, 1]³ centred at p + N.
    /// Cube corners bias the directions, and some point into the surface.
    Cube,
    /// Towards a random point inside the unit sphere tangent at p (centre p + N).
    /// Biased towards the normal: pdf ∝ cos³θ.
    SphereVolume,
    /// Towards a random point on the surface of that sphere: true Lambertian
    /// scattering, pdf = cosθ/π.
    Lambertian,
    /// A uniform direction in the hemisphere around N: pdf = 1/(2π).
    Hemisphere,
}

/// How a diffuse surface removes light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Attenuation {
    /// Every ray scatters and its colour is multiplied by the albedo.
    Scale,
    /// A ray survives with probability p = the albedo's largest component and
    /// is otherwise absorbed; survivors are multiplied by albedo / p, which is
    /// 1 (unattenuated) for a grey albedo. Same expected value as `Scale`.
    Absorb,
}

/// The notes' diffuse lobe at one point: its albedo there, and how it
/// bounces and attenuates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BookDiffuse {
    /// Fraction of light reflected per channel.
    pub albedo: Color,
    /// How bounce directions are chosen.
    pub bounce: BounceModel,
    /// How the albedo is applied.
    pub attenuation: Attenuation,
}

impl BookDiffuse {
    /// A Lambertian surface that scales by its albedo.
    pub fn lambertian(albedo: Color) -> Self {
        Self {
            albedo,
            bounce: BounceModel::Lambertian,
            attenuation: Attenuation::Scale,
        }
    }

    /// Whether it scatters exactly as a Lambertian surface does (cosine
    /// distributed bounces, the albedo applied to every one): the one
    /// diffuse form whose density the integrator can weigh against a
    /// light's. The other bounce models and absorption are sampled only.
    #[inline(always)]
    pub fn is_lambertian(&self) -> bool {
        self.bounce == BounceModel::Lambertian && self.attenuation == Attenuation::Scale
    }

    /// Scatters at the point of `bsdf`; `None` when the ray is absorbed.
    #[inline(always)]
    pub fn sample(&self, bsdf: &Bsdf, sampler: &mut impl Sampler) -> Option<BsdfSample> {
        let attenuation = match self.attenuation {
            Attenuation::Scale => self.albedo,
            Attenuation::Absorb => {
                let p = self.albedo.max_element();
                if !(p > 0.0) || sampler.get_1d(Dim::BsdfChoice) >= p {
                    return None;
                }
                self.albedo / p
            }
        };
        let wi = bsdf.reflected_above(bounce_direction(self.bounce, bsdf.frame.n, sampler))?;
        let pdf = if self.is_lambertian() {
            self.pdf(bsdf, wi)
        } else {
            0.0
        };
        Some(BsdfSample {
            value: attenuation,
            wi,
            pdf,
            flags: LobeFlags::REFLECTION | LobeFlags::DIFFUSE,
        })
    }

    /// f·|cos θ| and the density of the Lambertian's bounce towards unit
    /// `wi`; zero for the sampled-only forms.
    #[inline(always)]
    pub fn eval_and_pdf(&self, bsdf: &Bsdf, wi: Vec3) -> (Color, f32) {
        if !self.is_lambertian() {
            return (Color::ZERO, 0.0);
        }
        let pdf = self.pdf(bsdf, wi);
        (self.albedo * pdf, pdf)
    }

    /// The density of a Lambertian bounce towards `wi`: only the side the
    /// path came from, by the true surface.
    #[inline(always)]
    fn pdf(&self, bsdf: &Bsdf, wi: Vec3) -> f32 {
        if bsdf.ng.dot(wi) > 0.0 {
            lambertian_pdf(bsdf, wi)
        } else {
            0.0
        }
    }
}

/// The density per unit solid angle with which a Lambertian bounce at the
/// point of `bsdf` leaves along unit `w`: cosine-distributed about the
/// shading normal, and on a smoothly shaded surface also the directions
/// that fell below the true surface and were mirrored above it, where
/// they are (see [`Bsdf::reflected_above`]).
#[inline]
pub fn lambertian_pdf(bsdf: &Bsdf, w: Vec3) -> f32 {
    let n = bsdf.frame.n;
    let mut cos = n.dot(w).max(0.0);
    if bsdf.mirrors_below() {
        cos += n.dot(reflect(w, bsdf.ng)).max(0.0);
    }
    cos * std::f32::consts::FRAC_1_PI
}

/// A unit bounce direction around unit `normal` following `model`.
#[inline(always)]
pub fn bounce_direction(model: BounceModel, normal: Vec3, sampler: &mut impl Sampler) -> Vec3 {
    let d = match model {
        BounceModel::Cube => normal + sampling::on_cube_surface(sampler),
        BounceModel::SphereVolume => normal + sampling::in_unit_sphere(sampler),
        BounceModel::Lambertian => {
            normal + sampling::unit_vector_around(sampler.get_2d(Dim::Bsdf), normal)
        }
        BounceModel::Hemisphere => sampling::on_hemisphere(sampler.get_2d(Dim::Bsdf), normal),
    };
    // A sample opposite the normal cancels it. For N + u with unit u, the exact
    // cosθ of the result is |d|/2, while f32 cancellation tilts a short d by
    // up to ~1e-7/|d| radians: below |d|² = 1e-6 rounding could tip the
    // direction under the surface (or to NaN at zero), so take the normal.
    // The fallback is hit with probability 2.5e-7 (|d|² is uniform on [0, 4]);
    // it is normalised because the hit normal is unit only to within ~1e-4.
    let len2 = d.length_squared();
    if len2 < 1e-6 {
        normal.normalize()
    } else {
        d / len2.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::dielectric::SmoothDielectric;
    use crate::bsdf::metal::FuzzyMetal;
    use crate::bsdf::{Frame, Lobe};
    use crate::rng::Rng;
    use crate::testing::{chi_square, chi_square_bound};
    use std::f32::consts::PI;

    /// `lobe` on a surface of geometric normal `normal` and shading normal
    /// `shading` (equal: a flat surface).
    fn on(lobe: Lobe, normal: Vec3, shading: Vec3) -> Bsdf {
        Bsdf::new(
            Frame::from_normal(shading.normalize()),
            normal.normalize(),
            lobe,
        )
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
        let lobe = Lobe::Diffuse(BookDiffuse::lambertian(albedo));
        let wo = Vec3::Z;
        for (what, bsdf) in [
            (
                "flat",
                on(lobe, Vec3::new(0.2, -0.1, 1.0), Vec3::new(0.2, -0.1, 1.0)),
            ),
            ("smooth", on(lobe, Vec3::Z, Vec3::new(0.6, 0.0, 0.8))),
        ] {
            assert!(bsdf.has_density(), "{what}");
            let n = 400_000u64;
            let mut counts = vec![0u64; BANDS * SECTORS];
            let mut rng = Rng::new(23);
            for _ in 0..n {
                let s = bsdf.sample(wo, &mut rng).expect("never absorbs");
                let pdf = bsdf.pdf(wo, s.wi);
                assert!(pdf > 0.0, "{what}: sampled where pdf is 0: {}", s.wi);
                assert_eq!(pdf, s.pdf, "{what}");
                let ratio = bsdf.eval(wo, s.wi) / pdf;
                assert!((ratio - s.value).abs().max_element() < 1e-6, "{what}");
                counts[cell(s.wi)] += 1;
            }
            let pdf = |d: Vec3| f64::from(bsdf.pdf(wo, d));
            let cells = integrate_cells(pdf);
            let total: f64 = cells.iter().sum();
            assert!((total - 1.0).abs() < 2e-3, "{what}: ∫pdf = {total}");
            let reflected = integrate_cells(|d| f64::from(bsdf.eval(wo, d).x));
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

    /// On a surface whose bumps shadow (Mitsuba's normal and bump maps),
    /// what a Lambertian about a tilted normal would send below the true
    /// surface is lost, not mirrored: for a tilt θ the cosine lobe loses
    /// (1 − cos θ)/2 of its samples, never returns a direction below, and
    /// its pdf integrates to the rest.
    #[test]
    fn a_surface_whose_bumps_shadow_loses_what_falls_below() {
        use crate::bsdf::Terminator;
        let lobe = Lobe::Diffuse(BookDiffuse::lambertian(Color::splat(0.8)));
        let theta = 0.8f32;
        let tilted = Vec3::new(theta.sin(), 0.0, theta.cos());
        let bsdf = on(lobe, Vec3::Z, tilted).with_terminator(Terminator::new(Vec3::Z, tilted));
        assert!(!bsdf.mirrors_below());
        let n = 200_000u32;
        let mut rng = Rng::new(29);
        let mut lost = 0u32;
        for _ in 0..n {
            match bsdf.sample(Vec3::Z, &mut rng) {
                Some(s) => assert!(s.wi.z > 0.0, "below the surface: {}", s.wi),
                None => lost += 1,
            }
        }
        let p = f64::from(1.0 - theta.cos()) / 2.0;
        let sigma = (p * (1.0 - p) / f64::from(n)).sqrt();
        let measured = f64::from(lost) / f64::from(n);
        assert!(
            (measured - p).abs() < 4.0 * sigma,
            "lost {measured}, expected {p}"
        );
        let total: f64 = integrate_cells(|d| f64::from(bsdf.pdf(Vec3::Z, d)))
            .iter()
            .sum();
        assert!((total - (1.0 - p)).abs() < 2e-3, "∫pdf = {total}");
    }

    /// The notes' lobes other than the Lambertian report no density: the
    /// mirror and glass are deltas, fuzzy metal and the other bounce models
    /// are sampled only.
    #[test]
    fn the_notes_other_lobes_report_no_density() {
        let (wo, wi) = (Vec3::Z, Vec3::new(0.3, 0.0, 1.0).normalize());
        let mirror = Lobe::Metal(FuzzyMetal {
            albedo: Color::ONE,
            fuzz: 0.0,
        });
        let fuzzy = Lobe::Metal(FuzzyMetal {
            albedo: Color::ONE,
            fuzz: 0.3,
        });
        let glass = Lobe::Dielectric(SmoothDielectric {
            eta_ratio: 1.0 / 1.5,
            refract_only: false,
        });
        let cube = Lobe::Diffuse(BookDiffuse {
            bounce: BounceModel::Cube,
            ..BookDiffuse::lambertian(Color::ONE)
        });
        let absorb = Lobe::Diffuse(BookDiffuse {
            attenuation: Attenuation::Absorb,
            ..BookDiffuse::lambertian(Color::ONE)
        });
        let mut rng = Rng::new(3);
        for (lobe, delta) in [
            (mirror, true),
            (glass, true),
            (fuzzy, false),
            (cube, false),
            (absorb, false),
        ] {
            let bsdf = on(lobe, Vec3::Z, Vec3::Z);
            assert!(!bsdf.has_density(), "{lobe:?}");
            assert_eq!(bsdf.pdf(wo, wi), 0.0, "{lobe:?}");
            assert_eq!(bsdf.eval(wo, wi), Color::ZERO, "{lobe:?}");
            let s = bsdf.sample(wo, &mut rng).expect("scatters");
            assert_eq!(s.flags.is_specular(), delta, "{lobe:?}");
        }
    }
}
