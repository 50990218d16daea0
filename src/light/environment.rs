//! The environment: the light arriving from infinitely far away along every
//! direction a ray escapes by. A gradient, one colour, or an image
//! (equirectangular, or pbrt's equal-area octahedral square); each can be
//! sampled as a light, with a density in proportion to its brightness.

use super::luminance;
use crate::distribution::Distribution2D;
use crate::math::{atan2, lerp, Color, Vec3};
use crate::sampling::sin_cos_turns;
use crate::texture::Image;
use std::f32::consts::PI;
use std::sync::Arc;

/// What rays that escape the scene see, and the light it sheds.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// Blend from `bottom` to `top` by the unit direction's y.
    Gradient {
        /// Colour straight down.
        bottom: Color,
        /// Colour straight up.
        top: Color,
    },
    /// One colour everywhere.
    Solid(Color),
    /// An image wrapped around the sky.
    Map(Arc<EnvironmentMap>),
}

/// A direction drawn towards the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentSample {
    /// Unit direction towards the sky.
    pub direction: Vec3,
    /// The radiance arriving from it.
    pub radiance: Color,
    /// Its density per unit solid angle.
    pub pdf: f32,
}

impl Environment {
    /// The radiance arriving along unit `direction` (the colour seen looking
    /// that way).
    #[inline]
    pub fn color(&self, direction: Vec3) -> Color {
        match self {
            Environment::Gradient { bottom, top } => lerp(*bottom, *top, 0.5 * (direction.y + 1.0)),
            Environment::Solid(c) => *c,
            Environment::Map(map) => map.color(direction),
        }
    }

    /// A direction drawn from `u` in [0, 1)² with density in proportion to
    /// the brightness seen along it (luminance for a gradient and one
    /// colour; for an image, the brightest texel near it, times the area
    /// its texel covers); `None` where the draw is degenerate (a pole of an
    /// image).
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Option<EnvironmentSample> {
        let (direction, pdf) = match self {
            Environment::Gradient { bottom, top } => sample_gradient(*bottom, *top, u),
            Environment::Solid(_) => sample_gradient(Color::ONE, Color::ONE, u),
            Environment::Map(map) => map.sample(u)?,
        };
        Some(EnvironmentSample {
            direction,
            radiance: self.color(direction),
            pdf,
        })
    }

    /// The density per unit solid angle with which [`Environment::sample`]
    /// draws unit `direction`.
    #[inline]
    pub fn pdf(&self, direction: Vec3) -> f32 {
        match self {
            Environment::Gradient { bottom, top } => gradient_pdf(*bottom, *top, direction),
            Environment::Solid(_) => 1.0 / (4.0 * PI),
            Environment::Map(map) => map.pdf(direction),
        }
    }

    /// The luminance of the environment integrated over the sphere of
    /// directions (∫ Y(ω) dω).
    pub fn integral(&self) -> f64 {
        match self {
            Environment::Gradient { bottom, top } => {
                // The mean of a linear blend is the mean of its ends.
                2.0 * std::f64::consts::PI * f64::from(luminance(*bottom) + luminance(*top))
            }
            Environment::Solid(c) => 4.0 * std::f64::consts::PI * f64::from(luminance(*c)),
            Environment::Map(map) => map.integral,
        }
    }
}

/// A direction with density in proportion to the luminance of a blend from
/// `bottom` to `top` by y: y = 2t − 1 with t drawn from the mixture of
/// densities 2(1 − t) and 2t, weighted by the luminances of the two ends;
/// the azimuth uniform.
fn sample_gradient(bottom: Color, top: Color, u: [f32; 2]) -> (Vec3, f32) {
    let (a, b) = (luminance(bottom), luminance(top));
    let share_bottom = if a + b > 0.0 { a / (a + b) } else { 0.5 };
    let t = if u[0] < share_bottom {
        1.0 - (u[0] / share_bottom).sqrt()
    } else {
        ((u[0] - share_bottom) / (1.0 - share_bottom))
            .min(1.0)
            .sqrt()
    };
    let y = (2.0 * t - 1.0).clamp(-1.0, 1.0);
    let r = (1.0 - y * y).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u[1]);
    let direction = Vec3::new(r * c, y, r * s);
    (direction, gradient_pdf(bottom, top, direction))
}

/// The density of [`sample_gradient`]: that of t, 2((1 − t)a + t b)/(a + b),
/// over the 4π of the sphere (y = 2t − 1 is uniform on it when t is).
fn gradient_pdf(bottom: Color, top: Color, direction: Vec3) -> f32 {
    let (a, b) = (luminance(bottom), luminance(top));
    let t = (0.5 * (direction.y + 1.0)).clamp(0.0, 1.0);
    let density_t = if a + b > 0.0 {
        2.0 * ((1.0 - t) * a + t * b) / (a + b)
    } else {
        1.0
    };
    density_t / (4.0 * PI)
}

/// An equirectangular image of the sky: u = 0.5 + φ/2π across, the azimuth
/// φ = atan2(x, −z) turning from −z towards +x (so the image's centre lies
/// along −z, where the default camera looks, with +x to its right, and its
/// left and right edges meet along +z), and v = θ/π down, θ measured from
/// +y (the top row is straight up). The image is turned by
/// `rotation` about +y and scaled by `intensity`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    image: Image,
    intensity: f32,
    /// sin and cos of the rotation about +y.
    rotation: (f32, f32),
    distribution: Distribution2D,
    integral: f64,
    /// Whether the first and last rows lie at the poles (see
    /// [`EnvironmentMap::with_rows_at_poles`]).
    rows_at_poles: bool,
    /// A square map in the equal-area octahedral layout (see
    /// [`EnvironmentMap::equal_area`]), rather than equirectangular.
    equal_area: bool,
    /// The map's x, y and z axes in the world, when they are not the
    /// world's (an equal-area map's [`frame`](EnvironmentMap::equal_area),
    /// an equirectangular map's [`with_frame`](EnvironmentMap::with_frame)).
    frame: Option<[Vec3; 3]>,
}

/// The point of the unit square of the equal-area octahedral layout
/// (Clarberg 2008) that unit `d` maps to: +z at the centre, −z at the
/// corners, +x at the middle of the right edge, +y at the middle of the
/// bottom edge (v grows down the image).
pub fn equal_area_square(d: Vec3) -> [f32; 2] {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * (2.0 / PI);
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    let u = u.copysign(d.x);
    let v = v.copysign(d.y);
    [
        (0.5 * (u + 1.0)).clamp(0.0, 1.0),
        (0.5 * (v + 1.0)).clamp(0.0, 1.0),
    ]
}

/// The unit direction of point `[u, v]` of the unit square in the
/// equal-area octahedral layout (the inverse of [`equal_area_square`]).
pub fn equal_area_sphere([u, v]: [f32; 2]) -> Vec3 {
    let (u, v) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * (PI / 4.0);
    let z = (1.0 - r * r).copysign(signed);
    let (sin, cos) = phi.sin_cos();
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(cos.copysign(u) * s, sin.copysign(v) * s, z)
}

impl EnvironmentMap {
    /// The map with its first row straight up and its last straight down,
    /// the rows between spread evenly (Mitsuba's `envmap`), rather than
    /// each row at its middle, half a row from the poles at the ends.
    /// Only the look-up changes: the density of directions drawn still
    /// follows the rows as they are, which leaves the image unbiased (it
    /// weighs each texel by its brightest neighbour) and barely changes
    /// its noise.
    pub fn with_rows_at_poles(mut self) -> Self {
        self.rows_at_poles = true;
        self
    }

    /// The environment of `image`, turned by `rotation_degrees` about +y
    /// (counter-clockwise seen from above) and scaled by `intensity` (≥ 0);
    /// `None` when the image is black everywhere or the intensity is 0.
    pub fn new(image: Image, rotation_degrees: f32, intensity: f32) -> Option<Self> {
        if !(intensity > 0.0) {
            return None;
        }
        let (w, h) = (image.width(), image.height());
        // A texel's weight: the brightest of it and its eight neighbours
        // (the bilinear lookup within the texel's area draws on them, so
        // nothing visible goes unsampled), times the sine of its row's
        // polar angle (rows near the poles cover less of the sphere).
        let mut weights = vec![0.0f64; w * h];
        let mut integral = 0.0f64;
        for y in 0..h {
            let sin = (std::f64::consts::PI * (y as f64 + 0.5) / h as f64).sin();
            for x in 0..w {
                let mut brightest = 0.0f32;
                for dy in [-1i64, 0, 1] {
                    let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                    for dx in [-1i64, 0, 1] {
                        let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                        brightest = brightest.max(luminance(image.texel(xx, yy)));
                    }
                }
                weights[y * w + x] = f64::from(brightest) * sin;
                integral += f64::from(luminance(image.texel(x, y))) * sin;
            }
        }
        // Each texel covers (2π/w)(π/h) sin θ of the sphere.
        let texel_area = 2.0 * std::f64::consts::PI * std::f64::consts::PI / (w * h) as f64;
        let integral = integral * texel_area * f64::from(intensity);
        let distribution = Distribution2D::new(&weights, w)?;
        let (sin, cos) = rotation_degrees.to_radians().sin_cos();
        Some(EnvironmentMap {
            image,
            intensity,
            rotation: (sin, cos),
            distribution,
            integral,
            rows_at_poles: false,
            equal_area: false,
            frame: None,
        })
    }

    /// The environment of a square `image` in the equal-area octahedral
    /// layout (pbrt's): every texel covers the same solid angle, 4π / its
    /// number, and is looked up as it is (nearest, as pbrt does). `frame`
    /// is the map's x, y and z axes in the world (orthonormal); the image's
    /// centre looks along z. `Err` when the image is not square; `None`
    /// when it is black everywhere or the intensity is 0.
    pub fn equal_area(
        image: Image,
        frame: [Vec3; 3],
        intensity: f32,
    ) -> Result<Option<Self>, String> {
        let (w, h) = (image.width(), image.height());
        if w != h {
            return Err(format!(
                "an equal-area environment map is square; this image is {w} × {h}"
            ));
        }
        if !(intensity > 0.0) {
            return Ok(None);
        }
        let weights: Vec<f64> = (0..w * h)
            .map(|i| f64::from(luminance(image.texel(i % w, i / w))))
            .collect();
        let total: f64 = weights.iter().sum();
        let integral = total * 4.0 * std::f64::consts::PI / (w * h) as f64 * f64::from(intensity);
        let Some(distribution) = Distribution2D::new(&weights, w) else {
            return Ok(None);
        };
        Ok(Some(EnvironmentMap {
            image,
            intensity,
            rotation: (0.0, 1.0),
            distribution,
            integral,
            rows_at_poles: false,
            equal_area: true,
            frame: Some(frame),
        }))
    }

    /// The equirectangular map with its x, y and z axes `frame` in the
    /// world (orthonormal), turned by its rotation within that frame: a map
    /// whose top is not up (a scene whose up is +z).
    pub fn with_frame(mut self, frame: [Vec3; 3]) -> Self {
        self.frame = Some(frame);
        self
    }

    /// World direction `d` in the map's frame.
    #[inline]
    fn local(&self, d: Vec3) -> Vec3 {
        match self.frame {
            Some([x, y, z]) => Vec3::new(x.dot(d), y.dot(d), z.dot(d)),
            None => d,
        }
    }

    /// The world direction of direction `d` in the map's frame.
    #[inline]
    fn world(&self, d: Vec3) -> Vec3 {
        match self.frame {
            Some([x, y, z]) => x * d.x + y * d.y + z * d.z,
            None => d,
        }
    }

    /// The image's (u, v) seen along unit world `direction`.
    #[inline]
    fn uv(&self, direction: Vec3) -> [f32; 2] {
        let direction = self.local(direction);
        if self.equal_area {
            return equal_area_square(direction);
        }
        // Into the image's frame: turned back by the rotation.
        let (s, c) = self.rotation;
        let x = c * direction.x - s * direction.z;
        let z = s * direction.x + c * direction.z;
        let u = 0.5 + atan2(x, -z) * (0.5 / PI);
        // θ from its sine and cosine: acos(y) loses the digits near the
        // poles.
        let v = atan2((x * x + z * z).sqrt(), direction.y) / PI;
        [u.rem_euclid(1.0), v.clamp(0.0, 1.0)]
    }

    /// The world direction of the image's point `[u, v]`, and sin θ there.
    #[inline]
    fn direction(&self, [u, v]: [f32; 2]) -> (Vec3, f32) {
        let (sin_theta, cos_theta) = (PI * v).sin_cos();
        // φ = 2π(u − 0.5): half a turn from 2πu.
        let (s_u, c_u) = sin_cos_turns(u);
        let (sin_phi, cos_phi) = (-s_u, -c_u);
        let (x, z) = (sin_theta * sin_phi, -sin_theta * cos_phi);
        let (s, c) = self.rotation;
        let turned = Vec3::new(c * x + s * z, cos_theta, -s * x + c * z);
        (self.world(turned), sin_theta)
    }

    fn color(&self, direction: Vec3) -> Color {
        let [u, mut v] = self.uv(direction);
        if self.equal_area {
            let (w, h) = (self.image.width(), self.image.height());
            let x = ((u * w as f32) as usize).min(w - 1);
            let y = ((v * h as f32) as usize).min(h - 1);
            return self.intensity * self.image.texel(x, y);
        }
        if self.rows_at_poles {
            // Row r at v = r / (h − 1), looked up where the centred rows
            // have it: at (r + ½) / h.
            let h = self.image.height() as f32;
            v = (v * (h - 1.0) + 0.5) / h;
        }
        self.intensity * self.image.bilinear_wrap_u(u, v)
    }

    fn sample(&self, u: [f32; 2]) -> Option<(Vec3, f32)> {
        let (uv, density) = self.distribution.sample(u);
        if self.equal_area {
            // The layout keeps areas: the square covers the sphere at 4π.
            let world = self.world(equal_area_sphere(uv)).normalize();
            return Some((world, density / (4.0 * PI)));
        }
        let (direction, sin_theta) = self.direction(uv);
        if !(sin_theta > 0.0) {
            return None;
        }
        // (u, v) covers the sphere at 2π² sin θ per unit area.
        Some((direction, density / (2.0 * PI * PI * sin_theta)))
    }

    fn pdf(&self, direction: Vec3) -> f32 {
        if self.equal_area {
            return self.distribution.density(self.uv(direction)) / (4.0 * PI);
        }
        let d = self.local(direction);
        let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        self.distribution.density(self.uv(direction)) / (2.0 * PI * PI * sin_theta)
    }
}

#[cfg(test)]
mod tests;
