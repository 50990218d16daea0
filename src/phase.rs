//! Phase functions: how a particle of a participating medium scatters the
//! light that meets it over the sphere of directions, the medium's
//! counterpart of a surface's BSDF.
//!
//! A phase function is a density over directions (it integrates to 1, the
//! albedo saying how much is scattered at all), so sampling it exactly
//! leaves the path's throughput unchanged. Both kinds here depend only on
//! the angle θ between the direction light travelled in and the direction
//! it leaves in:
//!
//! - isotropic: every direction alike, 1/4π;
//! - Henyey–Greenstein, of asymmetry g in (−1, 1) (the mean cosine of the
//!   scattering angle: g > 0 scatters forward, as in fog and clouds, g < 0
//!   back): p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}), the
//!   convention of pbrt-v4 and Mitsuba 3 (their `g` means the same).

use crate::math::Vec3;
use crate::medium::ISOTROPIC_PDF;
use crate::sampling;

/// The largest |g| accepted: beyond it the lobe is narrower than `f32`
/// directions resolve.
pub const MAX_ASYMMETRY: f32 = 0.999;

/// Below this |g| Henyey–Greenstein's inversion divides by nearly 0; the
/// lobe is then isotropic to within 10⁻³.
const NEARLY_ISOTROPIC: f32 = 1e-3;

/// How a medium's particles scatter.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Phase {
    /// Every direction alike.
    #[default]
    Isotropic,
    /// Henyey–Greenstein of asymmetry `g` (|g| ≤ [`MAX_ASYMMETRY`]).
    HenyeyGreenstein {
        /// The mean cosine of the scattering angle.
        g: f32,
    },
}

impl Phase {
    /// The phase function of asymmetry `g`: isotropic at 0.
    pub fn with_asymmetry(g: f32) -> Phase {
        debug_assert!(g.abs() <= MAX_ASYMMETRY, "{g}");
        if g == 0.0 {
            Phase::Isotropic
        } else {
            Phase::HenyeyGreenstein { g }
        }
    }

    /// The density (per unit solid angle) of scattering light that
    /// travelled along unit `travel` into unit direction `wi`; as the
    /// phase function is sampled exactly, also the value by which light
    /// from `wi` is scattered back along `−travel`.
    #[inline]
    pub fn pdf(&self, travel: Vec3, wi: Vec3) -> f32 {
        match *self {
            Phase::Isotropic => ISOTROPIC_PDF,
            Phase::HenyeyGreenstein { g } => henyey_greenstein(travel.dot(wi), g),
        }
    }

    /// A direction drawn from the phase function for light that travelled
    /// along unit `travel`, from `u` uniform in [0, 1)², and its density.
    #[inline]
    pub fn sample(&self, travel: Vec3, u: [f32; 2]) -> (Vec3, f32) {
        match *self {
            Phase::Isotropic => (sampling::unit_vector(u), ISOTROPIC_PDF),
            Phase::HenyeyGreenstein { g } => {
                let cos = henyey_greenstein_cos(u[0], g);
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let (s, c) = sampling::sin_cos_turns(u[1]);
                let (tangent, bitangent) = travel.any_orthonormal_pair();
                let wi = (tangent * (sin * c) + bitangent * (sin * s) + travel * cos).normalize();
                (wi, henyey_greenstein(travel.dot(wi), g))
            }
        }
    }
}

/// Henyey–Greenstein's density at scattering-angle cosine `cos`.
#[inline]
fn henyey_greenstein(cos: f32, g: f32) -> f32 {
    let denominator = 1.0 + g * g - 2.0 * g * cos;
    ISOTROPIC_PDF * (1.0 - g * g) / (denominator * denominator.max(0.0).sqrt())
}

/// The scattering-angle cosine that Henyey–Greenstein's distribution
/// function reaches at `u`: its inverse, in closed form.
#[inline]
fn henyey_greenstein_cos(u: f32, g: f32) -> f32 {
    if g.abs() < NEARLY_ISOTROPIC {
        return 1.0 - 2.0 * u;
    }
    // The distribution of cos θ, inverted: from −1 at u = 0 to 1 at u = 1.
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampler::Sampler;
    use crate::testing::{chi_square, chi_square_bound};
    use std::f64::consts::PI;

    const ASYMMETRIES: [f32; 7] = [0.0, 0.0005, 0.3, -0.5, 0.8, -0.9, 0.99];

    fn travel() -> Vec3 {
        Vec3::new(0.3, -0.5, 0.8).normalize()
    }

    /// The density integrates to 1 over the sphere, and the mean cosine of
    /// the scattering angle is g (numerically, in cos θ, finely enough for
    /// the narrowest lobe tested).
    #[test]
    fn phase_functions_integrate_to_one_with_mean_cosine_g() {
        let n = 2_000_000;
        for g in ASYMMETRIES {
            let phase = Phase::with_asymmetry(g);
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let cos = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let sin = (1.0 - cos * cos).sqrt();
                let wi = Vec3::new(sin as f32, 0.0, cos as f32);
                let p = phase.pdf(Vec3::Z, wi) as f64 * 2.0 * PI * 2.0 / n as f64;
                total += p;
                mean += p * cos;
            }
            assert!((total - 1.0).abs() < 2e-3, "g = {g}: integral {total}");
            assert!(
                (mean - g as f64).abs() < 2e-3,
                "g = {g}: mean cosine {mean}"
            );
        }
    }

    /// Directions drawn follow the density by Pearson's χ² over cells of
    /// the scattering angle's cosine and of the azimuth around the
    /// direction of travel, the cells' expectations integrated from `pdf`
    /// (Simpson's rule in cos θ); and each sample's reported density is
    /// `pdf`'s.
    #[test]
    fn sampled_directions_follow_the_density() {
        let (cos_cells, phi_cells, n) = (64usize, 8usize, 400_000usize);
        let axis = travel();
        let (tangent, bitangent) = axis.any_orthonormal_pair();
        for g in ASYMMETRIES {
            let phase = Phase::with_asymmetry(g);
            let mut rng = Rng::new(5);
            let mut counts = vec![0u64; cos_cells * phi_cells];
            for _ in 0..n {
                let (wi, p) = phase.sample(axis, rng.get_2d(crate::sampler::Dim::Bsdf));
                assert!((wi.length() - 1.0).abs() < 1e-5);
                let want = phase.pdf(axis, wi);
                assert!(
                    (p - want).abs() <= 1e-4 * want,
                    "g = {g}: {p} against {want}"
                );
                let cos = wi.dot(axis).clamp(-1.0, 1.0);
                let phi = wi.dot(bitangent).atan2(wi.dot(tangent)) as f64;
                let i = (((cos as f64 + 1.0) / 2.0 * cos_cells as f64) as usize).min(cos_cells - 1);
                let j = (((phi / (2.0 * PI)).rem_euclid(1.0) * phi_cells as f64) as usize)
                    .min(phi_cells - 1);
                counts[i * phi_cells + j] += 1;
            }
            let density = |cos: f64| {
                let sin = (1.0 - cos * cos).max(0.0).sqrt() as f32;
                phase.pdf(Vec3::Z, Vec3::new(sin, 0.0, cos as f32)) as f64
            };
            let mut expected = Vec::with_capacity(counts.len());
            for i in 0..cos_cells {
                let (a, b) = (
                    -1.0 + 2.0 * i as f64 / cos_cells as f64,
                    -1.0 + 2.0 * (i + 1) as f64 / cos_cells as f64,
                );
                let integral = adaptive_simpson(&density, a, b, 1e-9, 30);
                let cell = integral * 2.0 * PI / phi_cells as f64;
                expected.extend(std::iter::repeat_n(cell * n as f64, phi_cells));
            }
            let (chi2, dof) = chi_square(&counts, &expected);
            assert!(
                chi2 < chi_square_bound(dof),
                "g = {g}: χ² = {chi2} for {dof} degrees of freedom"
            );
        }
    }

    /// ∫ f over [a, b] to within about `tolerance`, by Simpson's rule
    /// halved where it disagrees with itself (the lobes near g = 1 are
    /// thousands of times narrower than a cell).
    fn adaptive_simpson(
        f: &impl Fn(f64) -> f64,
        a: f64,
        b: f64,
        tolerance: f64,
        depth: u32,
    ) -> f64 {
        let simpson = |a: f64, b: f64| (b - a) / 6.0 * (f(a) + 4.0 * f((a + b) / 2.0) + f(b));
        let m = (a + b) / 2.0;
        let (whole, halves) = (simpson(a, b), simpson(a, m) + simpson(m, b));
        if depth == 0 || (halves - whole).abs() <= 15.0 * tolerance {
            halves + (halves - whole) / 15.0
        } else {
            adaptive_simpson(f, a, m, tolerance / 2.0, depth - 1)
                + adaptive_simpson(f, m, b, tolerance / 2.0, depth - 1)
        }
    }

    /// Positive g sends light on, negative g back: the density along the
    /// direction of travel exceeds the density against it accordingly.
    #[test]
    fn the_sign_of_g_says_forward_or_back() {
        let forward = |g: f32| Phase::with_asymmetry(g).pdf(travel(), travel());
        let back = |g: f32| Phase::with_asymmetry(g).pdf(travel(), -travel());
        assert!(forward(0.7) > 10.0 * back(0.7));
        assert!(back(-0.7) > 10.0 * forward(-0.7));
        assert_eq!(forward(0.0), back(0.0));
    }
}
