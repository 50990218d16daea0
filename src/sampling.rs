//! Random points and directions: the building blocks of antialiasing, diffuse
//! bounces, fuzzy metal and defocus blur.

use crate::math::Vec3;
use crate::rng::Rng;
use std::f32::consts::TAU;

/// A uniformly distributed point inside the unit sphere (rejection sampling).
#[inline]
pub fn in_unit_sphere(rng: &mut Rng) -> Vec3 {
    loop {
        let p = Vec3::new(
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
        );
        if p.length_squared() < 1.0 {
            return p;
        }
    }
}

/// A uniformly distributed direction: a point on the surface of the unit sphere.
///
/// Built from a uniform height `z` and azimuth `φ` (Archimedes' hat-box
/// theorem), which needs no rejection loop.
#[inline]
pub fn unit_vector(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (TAU * rng.next_f32()).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// A uniformly distributed direction in the hemisphere around `normal`.
#[inline]
pub fn on_hemisphere(rng: &mut Rng, normal: Vec3) -> Vec3 {
    let v = unit_vector(rng);
    if v.dot(normal) >= 0.0 {
        v
    } else {
        -v
    }
}

/// A uniformly distributed point on the surface of the cube `[-1, 1]³`.
///
/// All six faces have the same area, so a face is chosen uniformly and a point
/// uniformly within it.
#[inline]
pub fn on_cube_surface(rng: &mut Rng) -> Vec3 {
    let face = (rng.next_u32() % 6) as usize;
    let a = rng.range_f32(-1.0, 1.0);
    let b = rng.range_f32(-1.0, 1.0);
    let sign = if face < 3 { 1.0 } else { -1.0 };
    match face % 3 {
        0 => Vec3::new(sign, a, b),
        1 => Vec3::new(a, sign, b),
        _ => Vec3::new(a, b, sign),
    }
}

/// A uniformly distributed point in the unit disk of the `z = 0` plane.
#[inline]
pub fn in_unit_disk(rng: &mut Rng) -> Vec3 {
    loop {
        let p = Vec3::new(rng.range_f32(-1.0, 1.0), rng.range_f32(-1.0, 1.0), 0.0);
        if p.length_squared() < 1.0 {
            return p;
        }
    }
}
