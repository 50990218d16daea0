//! lumen's own denoiser, in every build: an edge-avoiding à-trous wavelet
//! filter (Dammertz et al. 2010, "Edge-Avoiding À-Trous Wavelet Transform
//! for fast Global Illumination Filtering") with the edge-stopping
//! functions of SVGF's spatial filter (Schied et al. 2017): guided by the
//! shading normals and by the noise the variance buffer measures.
//!
//! The image is first divided by its albedo, channel by channel (at least
//! [`MIN_ALBEDO`]), so that the filter smooths the light falling on the
//! surfaces and not their texture, which is multiplied back at the end. Then [`PASSES`] passes
//! each average a 5 × 5 pattern of pixels spaced 2^pass apart (the B3
//! spline's weights), every neighbour weighed by
//! - how alike its shading normal is to the pixel's (their cosine to the
//!   power [`NORMAL_POWER`]; no neighbour across a silhouette against the
//!   sky, whose normal is zero);
//! - how far its luminance lies from the pixel's, in the noise's standard
//!   deviations: exp(−|ℓp − ℓq| / ([`SIGMA_LUMINANCE`] √(σp² + σq²))). A
//!   difference the noise explains is smoothed; an edge the samples
//!   resolved is not. The weight is the same both ways: with σp alone, a
//!   bright noisy pixel took its dark neighbours in but they kept it out,
//!   and the Cornell box lost 1.1 % of its light at 16 samples;
//! - how far its albedo lies from the pixel's ([`SIGMA_ALBEDO`]).
//!
//! Each pass also carries the variance of what it averaged forward
//! (Σ w² σ² / (Σ w)²), so that later, wider passes stop at smaller
//! differences. Between pixels whose samples all agreed (no variance), a
//! difference of luminance stops the filter. Without a variance buffer (or
//! with one that is 0 everywhere, which says nothing: one sample a pixel)
//! the spread of the luminance over each pixel's 3 × 3 neighbourhood
//! stands in for its noise.
//!
//! It is a fraction of OIDN's quality (docs/denoising.md, "The built-in
//! filter"), and a fraction of its time; each pixel's result depends only
//! on the inputs, so it is the same bits on any number of threads.

use super::Inputs;
use crate::math::{Color, Vec3};
use rayon::prelude::*;

/// Passes of the filter; the last one's taps are 2^(PASSES − 1) pixels
/// apart, and together they reach 2 (2^PASSES − 1) pixels from each pixel.
pub const PASSES: u32 = 5;

/// The cosine between two normals is raised to this power (SVGF's 128):
/// a neighbour whose normal is 10° away weighs a seventh.
pub const NORMAL_POWER: u32 = 128;
// [`normal_weight`] raises to it by squaring.
const _: () = assert!(NORMAL_POWER.is_power_of_two());

/// How many standard deviations of the noise of a difference of two
/// pixels' luminances, √(σp² + σq²), the difference is scaled by before it
/// stops the filter. SVGF's σ_l is 4 (of σp alone); 1.4 measured better
/// here (docs/denoising.md, "The built-in filter"): SVGF estimates the
/// noise of a sample or a few, these renders know that of many.
pub const SIGMA_LUMINANCE: f32 = 1.4;

/// The difference of albedo (summed over the channels) at which a
/// neighbour's weight falls to 1/e: the albedo keeps the light of one
/// material from running into another's where the normals agree.
pub const SIGMA_ALBEDO: f32 = 0.1;

/// The B3 spline's weights of the taps 0, ±1 and ±2 steps away.
const KERNEL: [f32; 3] = [3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

/// The image is divided by its albedo channel by channel, but never by
/// less than this: dividing a glossy coat's white reflection on a blue
/// base by the base's red (a few hundredths) made it a red firefly the
/// filter then spread.
const MIN_ALBEDO: f32 = 0.1;

/// The image of `inputs` filtered (before highlights and the blend, which
/// [`super::denoise`] does for every denoiser).
pub fn filter(inputs: &Inputs) -> Vec<Color> {
    let (width, n) = (inputs.width, inputs.width * inputs.height);
    // A file's albedo may hold anything: what is not finite counts as 0
    // (a NaN weight would spread through every later pass).
    let albedos: Vec<Color> = match inputs.albedo {
        Some(albedo) => albedo.iter().map(|&a| finite(a).max(Color::ZERO)).collect(),
        None => vec![Color::ONE; n],
    };
    let factors: Vec<Color> = albedos
        .iter()
        .map(|&a| a.max(Color::splat(MIN_ALBEDO)))
        .collect();
    let normals: Vec<Vec3> = match inputs.normal {
        // `normalize_or_zero` makes a vector that is not finite zero.
        Some(normal) => normal.iter().map(|v| v.normalize_or_zero()).collect(),
        None => vec![Vec3::ZERO; n],
    };
    let light: Vec<Color> = inputs
        .color
        .iter()
        .zip(&factors)
        .map(|(&c, &f)| finite(c / f))
        .collect();
    let variance: Vec<f32> = match inputs.variance {
        Some(v) if v.iter().any(|&v| channel_mean(v) > 0.0) => v
            .iter()
            .zip(&factors)
            .map(|(&v, &f)| channel_mean(finite(v / (f * f))).max(0.0))
            .collect(),
        // Without a measured variance, the spread of each pixel's
        // neighbourhood stands in for its noise.
        _ => local_variance(&light, width),
    };
    let mut image = Image { light, variance };
    for pass in 0..PASSES {
        image = image.pass(&normals, &albedos, width, 1 << pass);
    }
    image
        .light
        .iter()
        .zip(&factors)
        .map(|(&l, &f)| l * f)
        .collect()
}

/// The light and its variance, as a pass of the filter leaves them.
struct Image {
    /// The image divided by its albedo.
    light: Vec<Color>,
    /// The variance of each pixel's luminance: the mean of its channels'
    /// variances (the channels of a path's samples vary together).
    variance: Vec<f32>,
}

impl Image {
    /// One pass of the filter, its taps `step` pixels apart.
    fn pass(&self, normals: &[Vec3], albedos: &[Color], width: usize, step: usize) -> Image {
        let height = self.light.len() / width;
        // The variance each pixel's luminance is compared by: its own
        // averaged with its neighbours' (a 3 × 3 Gaussian), steadier than
        // one pixel's estimate.
        let smoothed: Vec<f32> = blur3(&self.variance, width)
            .iter()
            .map(|&v| v.max(0.0))
            .collect();
        let rows: Vec<(Vec<Color>, Vec<f32>)> = (0..height)
            .into_par_iter()
            .map(|y| {
                (0..width)
                    .map(|x| self.pixel(normals, albedos, &smoothed, (width, height), (x, y), step))
                    .unzip()
            })
            .collect();
        let mut next = Image {
            light: Vec::with_capacity(self.light.len()),
            variance: Vec::with_capacity(self.light.len()),
        };
        for (light, variance) in rows {
            next.light.extend(light);
            next.variance.extend(variance);
        }
        next
    }

    /// Pixel (`x`, `y`) after the pass: its weighted mean and variance.
    /// `smoothed` holds the variances its luminance is compared by.
    fn pixel(
        &self,
        normals: &[Vec3],
        albedos: &[Color],
        smoothed: &[f32],
        (width, height): (usize, usize),
        (x, y): (usize, usize),
        step: usize,
    ) -> (Color, f32) {
        let p = y * width + x;
        let (lp, np, vp) = (luma(self.light[p]), normals[p], smoothed[p]);
        let ap = albedos[p];
        let mut sum = Color::ZERO;
        let mut weights = 0.0f32;
        let mut variance = 0.0f32;
        for dy in -2isize..=2 {
            let qy = y as isize + dy * step as isize;
            if qy < 0 || qy >= height as isize {
                continue;
            }
            for dx in -2isize..=2 {
                let qx = x as isize + dx * step as isize;
                if qx < 0 || qx >= width as isize {
                    continue;
                }
                let q = qy as usize * width + qx as usize;
                let spline = KERNEL[dx.unsigned_abs()] * KERNEL[dy.unsigned_abs()];
                let w = if q == p {
                    spline
                } else {
                    let normal = normal_weight(np, normals[q]);
                    if normal == 0.0 {
                        continue;
                    }
                    // The luminance's and the albedo's terms, in one
                    // exponential.
                    let difference = (lp - luma(self.light[q])).abs();
                    let luminance = if difference == 0.0 {
                        0.0
                    } else if vp + smoothed[q] > 0.0 {
                        difference / (SIGMA_LUMINANCE * (vp + smoothed[q]).sqrt())
                    } else {
                        continue;
                    };
                    let albedo = (ap - albedos[q]).abs().element_sum() / SIGMA_ALBEDO;
                    spline * normal * (-(luminance + albedo)).exp()
                };
                sum += self.light[q] * w;
                weights += w;
                variance += w * w * self.variance[q];
            }
        }
        // The pixel's own tap weighs at least 9/64, so `weights` > 0.
        (sum / weights, variance / (weights * weights))
    }
}

/// How much a neighbour of normal `q` counts for a pixel of normal `p`
/// (both unit or zero): their cosine to the [`NORMAL_POWER`]; 1 between
/// two zeros (the sky), 0 between a zero and a surface.
fn normal_weight(p: Vec3, q: Vec3) -> f32 {
    let (p_sky, q_sky) = (p == Vec3::ZERO, q == Vec3::ZERO);
    if p_sky || q_sky {
        return if p_sky == q_sky { 1.0 } else { 0.0 };
    }
    let mut w = p.dot(q).max(0.0);
    let mut power = 1;
    while power < NORMAL_POWER {
        w *= w;
        power *= 2;
    }
    w
}

/// The mean of the channels: the luminance the filter compares (its
/// noise is measured per channel, and the channels' noise is alike).
fn luma(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// The mean of the channels, 0 if it is not finite.
fn channel_mean(c: Color) -> f32 {
    let m = luma(c);
    if m.is_finite() {
        m
    } else {
        0.0
    }
}

/// `c` with every channel that is not finite made 0.
fn finite(c: Color) -> Color {
    let v = |v: f32| if v.is_finite() { v } else { 0.0 };
    Color::new(v(c.x), v(c.y), v(c.z))
}

/// `values` (an image `width` wide) blurred by the 3 × 3 Gaussian
/// (¼, ½, ¼ each way), the edge pixels repeated beyond the image.
fn blur3(values: &[f32], width: usize) -> Vec<f32> {
    let height = values.len() / width;
    let at = |x: isize, y: isize| {
        let x = x.clamp(0, width as isize - 1) as usize;
        let y = y.clamp(0, height as isize - 1) as usize;
        values[y * width + x]
    };
    (0..values.len())
        .map(|i| {
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            let row = |y| 0.25 * at(x - 1, y) + 0.5 * at(x, y) + 0.25 * at(x + 1, y);
            0.25 * row(y - 1) + 0.5 * row(y) + 0.25 * row(y + 1)
        })
        .collect()
}

/// The variance of the luminance over the 3 × 3 pixels around each pixel:
/// what stands in for the noise when the image has no variance buffer.
fn local_variance(light: &[Color], width: usize) -> Vec<f32> {
    let height = light.len() / width;
    (0..light.len())
        .map(|i| {
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            let mut sum = 0.0f32;
            let mut squares = 0.0f32;
            for (dx, dy) in (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))) {
                let qx = (x + dx).clamp(0, width as isize - 1) as usize;
                let qy = (y + dy).clamp(0, height as isize - 1) as usize;
                let l = luma(light[qy * width + qx]);
                sum += l;
                squares += l * l;
            }
            let mean = sum / 9.0;
            (squares / 9.0 - mean * mean).max(0.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::denoise::{Denoiser, Options};
    use crate::rng::Rng;

    const W: usize = 64;

    /// A W × W image of `truth` with noise of standard deviation `sigma` a
    /// pixel (uniform, fixed seed), and its variance buffer.
    fn noisy(truth: &[Color], sigma: f32, seed: u64) -> (Vec<Color>, Vec<Color>) {
        let mut rng = Rng::new(seed);
        let color = truth
            .iter()
            .map(|&t| t + Color::splat((rng.next_f32() - 0.5) * sigma * 12f32.sqrt()))
            .collect();
        (color, vec![Color::splat(sigma * sigma); truth.len()])
    }

    fn inputs<'a>(
        color: &'a [Color],
        albedo: &'a [Vec3],
        normal: &'a [Vec3],
        variance: Option<&'a [Color]>,
    ) -> Inputs<'a> {
        Inputs {
            width: W,
            height: color.len() / W,
            color,
            albedo: Some(albedo),
            normal: Some(normal),
            variance,
            options: Options {
                denoiser: Denoiser::Atrous,
                ..Options::default()
            },
        }
    }

    fn mse(a: &[Color], b: &[Color]) -> f64 {
        let squares = a
            .iter()
            .zip(b)
            .map(|(a, b)| f64::from((*a - *b).length_squared()));
        squares.sum::<f64>() / a.len() as f64
    }

    fn mean(a: &[Color]) -> f64 {
        a.iter().map(|c| f64::from(luma(*c))).sum::<f64>() / a.len() as f64
    }

    /// A checkerboard of 8-pixel squares of albedo 0.2 and 0.7 under light
    /// of 1: the texture is the signal, and it must survive.
    fn checkerboard() -> Vec<Vec3> {
        (0..W * W)
            .map(|i| match ((i % W) / 8 + (i / W) / 8) % 2 {
                0 => Vec3::splat(0.2),
                _ => Vec3::splat(0.7),
            })
            .collect()
    }

    #[test]
    fn a_noisy_textured_wall_comes_out_closer_to_the_truth_with_its_mean_kept() {
        let albedo = checkerboard();
        let normal = vec![Vec3::Z; W * W];
        let sigma = 0.1;
        let (color, variance) = noisy(&albedo, sigma, 7);
        let out = filter(&inputs(&color, &albedo, &normal, Some(&variance)));
        let (before, after) = (mse(&color, &albedo), mse(&out, &albedo));
        assert!(after < before / 10.0, "MSE {before} -> {after}");
        // The noise's own mean over N pixels has a standard deviation of
        // σ/√N (0.0016, 0.35 % of the mean); the filter's weighted means
        // may not stray three of them from the samples'.
        let bound = 3.0 * f64::from(sigma) / (W as f64);
        let (noisy_mean, got) = (mean(&color), mean(&out));
        assert!(
            (got - noisy_mean).abs() < bound,
            "mean {got} against {noisy_mean}"
        );
    }

    #[test]
    fn light_does_not_cross_a_crease_or_a_silhouette() {
        // Left: a wall facing the camera at 0.4; middle: one facing sideways
        // at 0.6; right: the sky (no normal) at 0.5; all of albedo 1. The
        // differences are within the noise's reach, so only the normals
        // keep the regions apart.
        let region = |i: usize| (i % W) * 3 / W;
        let truth: Vec<Color> = (0..W * W)
            .map(|i| Color::splat([0.4, 0.6, 0.5][region(i)]))
            .collect();
        let normal: Vec<Vec3> = (0..W * W)
            .map(|i| [Vec3::Z, Vec3::X, Vec3::ZERO][region(i)])
            .collect();
        let albedo = vec![Vec3::ONE; W * W];
        let (color, variance) = noisy(&truth, 0.1, 11);
        let out = filter(&inputs(&color, &albedo, &normal, Some(&variance)));
        let column = |x: usize| (0..W).map(|y| out[y * W + x].x).sum::<f32>() / W as f32;
        // Beside each edge (columns 21 | 22 and 42 | 43), the column's mean
        // is its region's: the noise left in a filtered column's mean is
        // well below 0.02, and light crossing the edge would move it by
        // half the step, 0.05.
        for (x, t) in [(21, 0.4), (22, 0.6), (42, 0.6), (43, 0.5)] {
            assert!((column(x) - t).abs() < 0.02, "column {x}: {}", column(x));
        }
        // Without the normals, the same edges are crossed.
        let flat = vec![Vec3::Z; W * W];
        let blurred = filter(&inputs(&color, &albedo, &flat, Some(&variance)));
        let crossed = (0..W).map(|y| blurred[y * W + 21].x).sum::<f32>() / W as f32;
        assert!(crossed > 0.42, "column 21 without normals: {crossed}");
    }

    #[test]
    fn an_albedo_or_normal_that_is_not_a_number_stays_where_it_is() {
        let mut albedo = checkerboard();
        let mut normal = vec![Vec3::Z; W * W];
        albedo[W * 32 + 32] = Vec3::NAN;
        albedo[W * 10 + 10] = Vec3::INFINITY;
        normal[W * 50 + 50] = Vec3::NAN;
        let (color, variance) = noisy(&checkerboard(), 0.1, 13);
        let out = filter(&inputs(&color, &albedo, &normal, Some(&variance)));
        assert!(out.iter().all(|c| c.is_finite()));
        let clean = checkerboard();
        assert!(mse(&out, &clean) < mse(&color, &clean) / 5.0);
    }

    #[test]
    fn where_every_sample_agreed_the_pixels_stay() {
        // Detail without noise (a variance of 0) is not smoothed, though
        // its luminance differences are small.
        let albedo = vec![Vec3::ONE; W * W];
        let normal = vec![Vec3::Z; W * W];
        let color: Vec<Color> = (0..W * W)
            .map(|i| Color::splat(0.5 + 0.01 * ((i * 7919) % 13) as f32))
            .collect();
        let variance = vec![Color::ZERO; W * W];
        // A variance buffer of zeros says nothing, and the neighbourhood's
        // spread stands in for it; give one pixel a little noise so the
        // buffer is taken as measured.
        let mut measured = variance.clone();
        measured[0] = Color::splat(1e-6);
        let out = filter(&inputs(&color, &albedo, &normal, Some(&measured)));
        let changed = out
            .iter()
            .zip(&color)
            .skip(2 * W)
            .filter(|(o, c)| (**o - **c).abs().max_element() > 1e-6);
        assert_eq!(changed.count(), 0);
    }

    #[test]
    fn the_same_bits_on_any_number_of_threads() {
        let albedo = checkerboard();
        let normal = vec![Vec3::Z; W * W];
        let (color, variance) = noisy(&albedo, 0.1, 3);
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let out = pool.install(|| filter(&inputs(&color, &albedo, &normal, Some(&variance))));
            out.iter()
                .flat_map(|c| c.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(run(1), run(3));
    }

    #[test]
    fn without_a_variance_buffer_the_neighbourhood_measures_the_noise() {
        let albedo = checkerboard();
        let normal = vec![Vec3::Z; W * W];
        let (color, _) = noisy(&albedo, 0.1, 5);
        let out = filter(&inputs(&color, &albedo, &normal, None));
        let (before, after) = (mse(&color, &albedo), mse(&out, &albedo));
        assert!(after < before / 3.0, "MSE {before} -> {after}");
    }

    #[test]
    fn a_normals_weight_is_its_cosine_to_the_128th_and_zero_across_the_sky() {
        let tilted = Vec3::new(0.1f32.sin(), 0.0, 0.1f32.cos());
        let w = normal_weight(Vec3::Z, tilted);
        assert!((w - 0.1f32.cos().powi(128)).abs() < 1e-4, "{w}");
        assert_eq!(normal_weight(Vec3::ZERO, Vec3::ZERO), 1.0);
        assert_eq!(normal_weight(Vec3::Z, Vec3::ZERO), 0.0);
        assert_eq!(normal_weight(Vec3::Z, -Vec3::Z), 0.0);
    }
}
