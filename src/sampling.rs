//! Random points and directions: the building blocks of antialiasing, diffuse
//! bounces, fuzzy metal and defocus blur.
//!
//! Directions are made from uniform numbers by a warp where one exists
//! ([`unit_vector`]); the notes' rejection methods draw from a sampler until
//! a point is accepted, as the notes do.

use crate::math::Vec3;
use crate::sampler::{Dim, Sampler};
use std::f32::consts::FRAC_PI_2;

/// `u` in [0, 1) mapped to [-1, 1).
#[inline(always)]
fn signed(u: f32) -> f32 {
    -1.0 + 2.0 * u
}

/// A uniformly distributed point inside the unit sphere (rejection sampling
/// from the cube [-1, 1)³, as in the notes), drawn for a bounce.
#[inline]
pub fn in_unit_sphere(sampler: &mut impl Sampler) -> Vec3 {
    loop {
        let [x, y] = sampler.get_2d(Dim::Bsdf);
        let z = sampler.get_1d(Dim::BsdfExtra);
        let p = Vec3::new(signed(x), signed(y), signed(z));
        if p.length_squared() < 1.0 {
            return p;
        }
    }
}

/// A uniformly distributed direction (a point on the surface of the unit
/// sphere) from `u` uniform in [0, 1)².
///
/// Built from a uniform height `z` and azimuth `φ` (Archimedes' hat-box
/// theorem), which needs no rejection loop.
#[inline]
pub fn unit_vector(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u[1]);
    Vec3::new(r * c, r * s, z)
}

/// `(sin 2πu, cos 2πu)` for `u` in [0, 1], to within 10⁻⁷.
///
/// Inline polynomials instead of the C library's `sincosf`: the call was one
/// of the larger costs of a diffuse bounce, and it forces the render loop to
/// save and restore every vector register around it.
#[inline(always)]
pub(crate) fn sin_cos_turns(u: f32) -> (f32, f32) {
    // The nearest quarter turn q, and the rest as an angle in [−π/4, π/4].
    let x = 4.0 * u;
    // Rounded by truncation (x ≥ 0): `round` is a library call on the
    // baseline x86-64 instruction set.
    let q = (x + 0.5) as u32;
    let a = (x - q as f32) * FRAC_PI_2;
    let a2 = a * a;
    // Taylor series to the a⁹ and a⁸ terms: the first term left out is below
    // (π/4)¹⁰/10! ≈ 2.5·10⁻⁸.
    let sin =
        a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 / 362_880.0))));
    let cos = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 / 40_320.0)));
    // Turn by q quarter turns: an odd q swaps sine and cosine, q = 2 or 3
    // negates both. The swap compiles to a branch, mispredicted about half
    // the time (q is random); a select on the bits instead measured no
    // faster.
    let (sin, cos) = if q & 1 == 1 { (cos, -sin) } else { (sin, cos) };
    let negate = (q & 2) << 30;
    (
        f32::from_bits(sin.to_bits() ^ negate),
        f32::from_bits(cos.to_bits() ^ negate),
    )
}

/// A uniformly distributed direction, as [`unit_vector`] but with its height
/// measured along unit `axis` instead of z.
///
/// The distribution is the same; what changes is which `u` gives which
/// direction. For a Lambertian bounce `axis + v`, the cosine of the bounce
/// then depends on `u[0]` alone (cos²θ = 1 − `u[0]`) and its azimuth on `u[1]`
/// alone, so the compact cells of a low-discrepancy sampler stay compact on
/// the hemisphere, wherever the surface faces: 6% less variance per sample on
/// the sphere field and on the bunny with the Sobol sampler.
#[inline]
pub fn unit_vector_around(u: [f32; 2], axis: Vec3) -> Vec3 {
    let v = unit_vector(u);
    let (tangent, bitangent) = axis.any_orthonormal_pair();
    tangent * v.x + bitangent * v.y + axis * v.z
}

/// A direction uniformly distributed over the cone of directions within
/// angle θmax of unit `axis`, given 1 − cos θmax (at most 2, the whole
/// sphere), from `u` uniform in [0, 1)²: 1 − cos θ uniform in
/// [0, 1 − cos θmax], the azimuth uniform. sin θ is taken from 1 − cos θ
/// directly, so that cones too narrow for cos θ to differ from 1 in `f32`
/// still spread their directions.
#[inline]
pub fn in_cone(u: [f32; 2], axis: Vec3, one_minus_cos_max: f32) -> Vec3 {
    let one_minus_cos = u[0] * one_minus_cos_max;
    let cos = 1.0 - one_minus_cos;
    let sin = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u[1]);
    let (tangent, bitangent) = axis.any_orthonormal_pair();
    (tangent * (sin * c) + bitangent * (sin * s) + axis * cos).normalize()
}

/// A direction of the hemisphere around +z distributed as cos θ/π, from `u`
/// uniform in [0, 1)²: cos²θ = 1 − `u[0]`, the azimuth `u[1]` turns (the
/// projection of a uniform point of the unit disk, Malley's method).
#[inline]
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let sin2 = u[0];
    let r = sin2.sqrt();
    let (s, c) = sin_cos_turns(u[1]);
    Vec3::new(r * c, r * s, (1.0 - sin2).max(0.0).sqrt())
}

/// A uniformly distributed direction in the hemisphere around `normal`,
/// from `u` uniform in [0, 1)².
#[inline]
pub fn on_hemisphere(u: [f32; 2], normal: Vec3) -> Vec3 {
    let v = unit_vector(u);
    if v.dot(normal) >= 0.0 {
        v
    } else {
        -v
    }
}

/// A uniformly distributed point on the surface of the cube `[-1, 1]³`.
///
/// All six faces have the same area, so a face is chosen uniformly and a point
/// uniformly within it; drawn for a bounce.
#[inline]
pub fn on_cube_surface(sampler: &mut impl Sampler) -> Vec3 {
    let face = sampler.get_below(Dim::BsdfExtra, 6) as usize;
    let [a, b] = sampler.get_2d(Dim::Bsdf).map(signed);
    let sign = if face < 3 { 1.0 } else { -1.0 };
    match face % 3 {
        0 => Vec3::new(sign, a, b),
        1 => Vec3::new(a, sign, b),
        _ => Vec3::new(a, b, sign),
    }
}

/// A uniformly distributed point in the unit disk of the `z = 0` plane
/// (rejection sampling from the square, as in the notes), drawn for `dim`.
#[inline]
pub fn in_unit_disk(sampler: &mut impl Sampler, dim: Dim) -> Vec3 {
    loop {
        let [x, y] = sampler.get_2d(dim);
        let p = Vec3::new(signed(x), signed(y), 0.0);
        if p.length_squared() < 1.0 {
            return p;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_vector_around_measures_the_height_along_its_axis() {
        let mut rng = crate::rng::Rng::new(7);
        for _ in 0..10_000 {
            let u = rng.next_2d();
            // Around z it is the plain warp.
            assert_eq!(unit_vector_around(u, Vec3::Z), unit_vector(u));
            let axis = unit_vector(rng.next_2d());
            let v = unit_vector_around(u, axis);
            assert!((v.length() - 1.0).abs() < 1e-5, "{v} not unit");
            let height = 1.0 - 2.0 * u[0];
            assert!(
                (v.dot(axis) - height).abs() < 1e-5,
                "height {} not {height}",
                v.dot(axis)
            );
        }
    }

    #[test]
    fn cone_directions_keep_within_the_cone_at_their_drawn_angle() {
        let mut rng = crate::rng::Rng::new(9);
        for max in [2.0f32, 0.3, 1e-3, 1e-9] {
            for _ in 0..10_000 {
                let (u, axis) = (rng.next_2d(), unit_vector(rng.next_2d()));
                let v = in_cone(u, axis, max);
                assert!((v.length() - 1.0).abs() < 1e-5, "{v} not unit");
                let expected = 1.0 - u[0] * max;
                assert!(
                    (v.dot(axis) - expected).abs() < 2e-6,
                    "cos {} not {expected}",
                    v.dot(axis)
                );
                assert!(v.dot(axis) >= 1.0 - max - 2e-6);
            }
        }
    }

    /// Directions drawn uniformly over a cone (the whole sphere for the
    /// isotropic phase function and a sphere light seen from inside, a cap
    /// for a sphere light seen from outside) fall equally often into cells
    /// of equal solid angle: bands of 1 − cos θ about the axis by sectors
    /// of azimuth (χ², fixed seed, p ≈ 10⁻⁴).
    #[test]
    fn cone_and_sphere_directions_are_uniform_by_solid_angle() {
        use crate::testing::{chi_square, chi_square_bound};
        let (bands, sectors) = (16usize, 24usize);
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (tangent, bitangent) = axis.any_orthonormal_pair();
        type Warp<'a> = &'a dyn Fn([f32; 2]) -> Vec3;
        let draws: [(&str, f32, Warp); 4] = [
            ("unit_vector", 2.0, &|u| unit_vector_around(u, axis)),
            ("cone, whole sphere", 2.0, &|u| in_cone(u, axis, 2.0)),
            ("cone, wide cap", 0.7, &|u| in_cone(u, axis, 0.7)),
            ("cone, narrow cap", 1e-3, &|u| in_cone(u, axis, 1e-3)),
        ];
        for (what, max, draw) in draws {
            let n = 240_000u64;
            let mut counts = vec![0u64; bands * sectors];
            let mut rng = crate::rng::Rng::new(31);
            for _ in 0..n {
                let d = draw(rng.next_2d());
                let height = f64::from(1.0 - d.dot(axis)) / f64::from(max);
                let band = ((height * bands as f64) as usize).min(bands - 1);
                let azimuth = f64::from(d.dot(bitangent).atan2(d.dot(tangent)));
                let turn = azimuth.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
                let sector = ((turn * sectors as f64) as usize).min(sectors - 1);
                counts[band * sectors + sector] += 1;
            }
            let expected = vec![n as f64 / (bands * sectors) as f64; bands * sectors];
            let (chi2, dof) = chi_square(&counts, &expected);
            assert!(chi2 < chi_square_bound(dof), "{what}: χ² {chi2}, {dof} dof");
        }
    }

    #[test]
    fn inline_sine_and_cosine_match_the_library_to_1e_7() {
        let steps = 1 << 20;
        for i in 0..=steps {
            let u = i as f32 / steps as f32;
            let (s, c) = sin_cos_turns(u);
            let (es, ec) = (std::f64::consts::TAU * f64::from(u)).sin_cos();
            let error = (f64::from(s) - es).abs().max((f64::from(c) - ec).abs());
            assert!(error < 1e-7, "u = {u}: ({s}, {c}) instead of ({es}, {ec})");
        }
    }
}
