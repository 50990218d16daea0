//! Pixel filters: how much each point near a pixel counts towards it. A
//! box counts the pixel's own square evenly; a Gaussian weighs points by
//! their distance from the pixel's centre, out to a radius of 4σ (2
//! pixels at σ = ½, Mitsuba's default), smoothing the image and its
//! aliasing.
//!
//! The filter is applied by importance sampling (as pbrt-v4 does): a
//! camera ray's position about its pixel's centre is drawn with density
//! in proportion to the filter, so every sample counts with weight 1 and
//! the pixel's mean is the filtered image, the same expected value that
//! splatting each sample into its neighbours with the filter's weight
//! (Mitsuba's way) converges to.

use std::sync::Arc;

/// The pixel filter of a render.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum PixelFilter {
    /// The pixel's square, evenly.
    #[default]
    Box,
    /// exp(−x²/2σ²) − exp(−r²/2σ²) per axis within r = 4σ of the centre.
    Gaussian(Arc<Table>),
}

/// A filter's inverse distribution along one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The filter's reach on each side of the centre, in pixels.
    radius: f32,
    /// The cumulative weight at the end of each of [`BINS`] bins of equal
    /// width over [−radius, radius], 1 at the last.
    cdf: Vec<f32>,
}

/// Bins of a tabulated filter: 4 pixels in 1,024 bins, each 1/256 of a
/// pixel wide, far finer than any image shows.
const BINS: usize = 1024;

impl PixelFilter {
    /// The Gaussian of standard deviation `stddev` pixels (> 0).
    pub fn gaussian(stddev: f32) -> PixelFilter {
        let radius = 4.0 * f64::from(stddev);
        let s2 = 2.0 * f64::from(stddev) * f64::from(stddev);
        let floor = (-radius * radius / s2).exp();
        let weight = |x: f64| ((-x * x / s2).exp() - floor).max(0.0);
        // Each bin's weight by Simpson's rule over its width.
        let width = 2.0 * radius / BINS as f64;
        let mut total = 0.0;
        let mut cdf = Vec::with_capacity(BINS);
        for i in 0..BINS {
            let a = -radius + i as f64 * width;
            total += width / 6.0 * (weight(a) + 4.0 * weight(a + width / 2.0) + weight(a + width));
            cdf.push(total);
        }
        let cdf = cdf.into_iter().map(|c| (c / total) as f32).collect();
        PixelFilter::Gaussian(Arc::new(Table {
            radius: radius as f32,
            cdf,
        }))
    }

    /// The offset from the pixel's centre, in pixels, of a sample given
    /// `d` uniform in [−½, ½) (the offset a box gives): `d` itself for a
    /// box, and for a Gaussian an offset drawn in proportion to the
    /// filter (0 for `d` = 0, the median).
    #[inline]
    pub fn offset(&self, d: f32) -> f32 {
        match self {
            PixelFilter::Box => d,
            PixelFilter::Gaussian(t) => t.offset(d + 0.5),
        }
    }
}

impl Table {
    /// The offset from the centre with cumulative weight `u`: its bin, and
    /// uniformly within it.
    #[inline]
    fn offset(&self, u: f32) -> f32 {
        let i = self.cdf.partition_point(|c| *c <= u).min(BINS - 1);
        let below = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let span = self.cdf[i] - below;
        let within = if span > 0.0 {
            ((u - below) / span).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let width = 2.0 * self.radius / BINS as f32;
        -self.radius + (i as f32 + within) * width
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter's own weight at `x`, for σ = `stddev`.
    fn weight(x: f64, stddev: f64) -> f64 {
        let r = 4.0 * stddev;
        let s2 = 2.0 * stddev * stddev;
        ((-x * x / s2).exp() - (-r * r / s2).exp()).max(0.0)
    }

    #[test]
    fn a_box_leaves_the_position_alone() {
        for d in [-0.5, 0.0, 0.25, 0.499_999] {
            assert_eq!(PixelFilter::Box.offset(d), d);
        }
    }

    #[test]
    fn gaussian_positions_follow_the_filter_by_chi_square() {
        // 200,000 stratified draws into 40 bins over [−2, 2] pixels around
        // the centre, against the filter's integral over each bin.
        let stddev = 0.5;
        let f = PixelFilter::gaussian(stddev as f32);
        let n = 200_000;
        let bins = 40;
        let mut counts = vec![0.0f64; bins];
        for i in 0..n {
            let d = (i as f32 + 0.5) / n as f32 - 0.5;
            let x = f64::from(f.offset(d));
            assert!(x.abs() <= 2.0 + 1e-6, "{x}");
            let b = (((x + 2.0) / 4.0 * bins as f64) as usize).min(bins - 1);
            counts[b] += 1.0;
        }
        let mut expected = vec![0.0f64; bins];
        let steps = 2000;
        for (b, e) in expected.iter_mut().enumerate() {
            for k in 0..steps {
                let x = -2.0 + (b as f64 + (k as f64 + 0.5) / steps as f64) * 4.0 / bins as f64;
                *e += weight(x, stddev);
            }
        }
        let total: f64 = expected.iter().sum();
        let mut chi2 = 0.0;
        for b in 0..bins {
            let e = expected[b] / total * n as f64;
            if e > 5.0 {
                chi2 += (counts[b] - e).powi(2) / e;
            } else {
                assert!(
                    counts[b] <= 5.0 * e.max(1.0),
                    "bin {b}: {} for {e}",
                    counts[b]
                );
            }
        }
        // 39 degrees of freedom; stratified draws land far below the
        // critical value 72.1 (p = 0.001) when the law is right.
        assert!(chi2 < 72.1, "chi² {chi2}");
        // A box's law is rejected by the same test.
        let uniform: f64 = expected
            .iter()
            .map(|e| {
                let e = e / total * n as f64;
                let c = n as f64 / bins as f64;
                (c - e).powi(2) / e.max(1e-9)
            })
            .sum();
        assert!(uniform > 1000.0, "{uniform}");
    }

    #[test]
    fn wider_gaussians_reach_further_and_the_ends_stay_within_the_radius() {
        let narrow = PixelFilter::gaussian(0.3);
        let wide = PixelFilter::gaussian(1.0);
        for d in [-0.5, -0.499_999_9, -0.4, 0.0, 0.4, 0.499_999_9] {
            let (a, b) = (narrow.offset(d), wide.offset(d));
            assert!(
                a.abs() <= 1.2 + 1e-6 && b.abs() <= 4.0 + 1e-6,
                "{d}: {a} {b}"
            );
            if d.abs() > 0.05 {
                assert!(b.abs() > a.abs(), "{d}: {a} {b}");
            }
        }
        // Symmetric about the centre, which the median lands on.
        let (lo, hi) = (wide.offset(-0.3), wide.offset(0.3));
        assert!((lo + hi).abs() < 1e-3, "{lo} {hi}");
        assert!(wide.offset(0.0).abs() < 1e-2);
    }
}
