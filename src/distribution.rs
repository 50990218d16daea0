//! Piecewise-constant distributions: choosing among weighted items (lights),
//! and drawing points in proportion to a tabulated function (an environment
//! map's brightness), with the density of what was drawn.
//!
//! The tables hold `f32` cumulative sums. The chance of an item is the width
//! of its step in that table, not its exact share of the weights: with
//! millions of items the two differ, and densities must describe what is
//! actually drawn.

/// A distribution over `n` items (or `n` equal bins of [0, 1)) in proportion
/// to non-negative weights.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Distribution1D {
    /// Cumulative weights, normalised to end at exactly 1.
    cdf: Vec<f32>,
}

impl Distribution1D {
    /// The distribution in proportion to `weights`; `None` when they are
    /// empty, or do not add up to a positive finite total (an item of
    /// negative or NaN weight makes the total meaningless and is refused
    /// the same way).
    pub fn new(weights: &[f64]) -> Option<Self> {
        if weights.iter().any(|w| !(*w >= 0.0)) {
            return None;
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut running = 0.0;
        let mut cdf: Vec<f32> = weights
            .iter()
            .map(|w| {
                running += w;
                (running / total) as f32
            })
            .collect();
        // Every u in [0, 1) chooses an item.
        *cdf.last_mut().expect("not empty") = 1.0;
        Some(Distribution1D { cdf })
    }

    /// The number of items.
    pub fn len(&self) -> usize {
        self.cdf.len()
    }

    /// Whether there are no items (only for the default value).
    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// The probability of drawing item `i` (0 outside the items).
    #[inline]
    pub fn chance(&self, i: usize) -> f32 {
        match self.cdf.get(i) {
            Some(&c) => c - if i == 0 { 0.0 } else { self.cdf[i - 1] },
            None => 0.0,
        }
    }

    /// The item drawn by `u` in [0, 1): item `i` for u in its step
    /// [cdf(i − 1), cdf(i)), so never one of no chance.
    #[inline]
    pub fn sample(&self, u: f32) -> usize {
        self.cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1)
    }

    /// A point of [0, 1) drawn by `u` in [0, 1) with density proportional
    /// to the weights of the `n` equal bins; the bin it falls in.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, usize) {
        let i = self.sample(u);
        let below = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let within = ((u - below) / (self.cdf[i] - below)).clamp(0.0, ONE_BELOW);
        let n = self.cdf.len() as f32;
        (((i as f32 + within) / n).min(ONE_BELOW), i)
    }

    /// The density of point `x` of [0, 1) as [`sample_continuous`] draws
    /// it.
    ///
    /// [`sample_continuous`]: Distribution1D::sample_continuous
    #[inline]
    pub fn density(&self, x: f32) -> f32 {
        self.chance(self.bin(x)) * self.cdf.len() as f32
    }

    /// The bin of point `x` of [0, 1] (the last bin for 1).
    #[inline]
    pub fn bin(&self, x: f32) -> usize {
        ((x * self.cdf.len() as f32) as usize).min(self.cdf.len() - 1)
    }
}

/// The largest `f32` below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// A distribution over the unit square [0, 1)² in proportion to a table of
/// `width × height` non-negative weights, constant over each cell: a row
/// (along v) is drawn by its total, then a column within it.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    /// The distribution of rows.
    rows: Distribution1D,
    /// The distribution within each row (`None` for a row of no weight,
    /// which is never drawn).
    columns: Vec<Option<Distribution1D>>,
}

impl Distribution2D {
    /// The distribution of `weights`, row by row (`weights[y * width + x]`);
    /// `None` when the total weight is not positive and finite.
    pub fn new(weights: &[f64], width: usize) -> Option<Self> {
        if width == 0 || weights.is_empty() || !weights.len().is_multiple_of(width) {
            return None;
        }
        let columns: Vec<Option<Distribution1D>> =
            weights.chunks(width).map(Distribution1D::new).collect();
        let row_totals: Vec<f64> = weights
            .chunks(width)
            .zip(&columns)
            .map(|(row, d)| if d.is_some() { row.iter().sum() } else { 0.0 })
            .collect();
        Some(Distribution2D {
            rows: Distribution1D::new(&row_totals)?,
            columns,
        })
    }

    /// A point `[x, y]` of the unit square drawn by `u` in [0, 1)², and its
    /// density.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 2], f32) {
        let (y, row) = self.rows.sample_continuous(u[1]);
        let columns = self.columns[row].as_ref().expect("rows of weight");
        let (x, column) = columns.sample_continuous(u[0]);
        // As `density` computes it, to the bit.
        let density = (self.rows.chance(row) * self.rows.len() as f32)
            * (columns.chance(column) * columns.len() as f32);
        ([x, y], density)
    }

    /// The density of point `[x, y]` of the unit square as
    /// [`Distribution2D::sample`] draws it.
    #[inline]
    pub fn density(&self, [x, y]: [f32; 2]) -> f32 {
        let row = self.rows.bin(y);
        match &self.columns[row] {
            Some(columns) => self.rows.density(y) * columns.density(x),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::testing::{chi_square, chi_square_bound};

    #[test]
    fn refuses_weights_of_no_total() {
        assert!(Distribution1D::new(&[]).is_none());
        assert!(Distribution1D::new(&[0.0, 0.0]).is_none());
        assert!(Distribution1D::new(&[1.0, f64::NAN]).is_none());
        assert!(Distribution1D::new(&[1.0, -0.5]).is_none());
        assert!(Distribution1D::new(&[f64::INFINITY]).is_none());
        assert!(Distribution2D::new(&[0.0; 6], 3).is_none());
        assert!(Distribution2D::new(&[1.0; 5], 3).is_none());
    }

    #[test]
    fn chances_follow_the_weights_and_add_up_to_one() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 4.0]).unwrap();
        let chances: Vec<f32> = (0..4).map(|i| d.chance(i)).collect();
        assert_eq!(chances, [0.125, 0.0, 0.375, 0.5]);
        assert_eq!(d.chance(4), 0.0);
        // Every u chooses an item of weight, the one whose step holds it.
        assert_eq!(d.sample(0.0), 0);
        assert_eq!(d.sample(0.124), 0);
        assert_eq!(d.sample(0.125), 2);
        assert_eq!(d.sample(0.5), 3);
        assert_eq!(d.sample(ONE_BELOW), 3);
    }

    /// Points drawn from a 2-D table fall into a finer grid of cells as
    /// often as the density the table reports, integrated over each cell,
    /// says (χ² test with a fixed seed), and the reported density of every
    /// sample is the table's density at that point.
    #[test]
    fn two_d_samples_follow_their_density() {
        let (w, h) = (7, 5);
        let weights: Vec<f64> = (0..w * h)
            .map(|i| match i % 4 {
                0 => 0.0,
                k => k as f64 * (1.0 + (i / w) as f64),
            })
            .collect();
        let d = Distribution2D::new(&weights, w).unwrap();
        let (gw, gh) = (3 * w, 2 * h);
        let mut counts = vec![0u64; gw * gh];
        let mut rng = Rng::new(11);
        let n = 400_000;
        for _ in 0..n {
            let (p, density) = d.sample([rng.next_f32(), rng.next_f32()]);
            assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]));
            assert_eq!(density, d.density(p), "{p:?}");
            let (gx, gy) = ((p[0] * gw as f32) as usize, (p[1] * gh as f32) as usize);
            counts[gy * gw + gx] += 1;
        }
        // Each grid cell lies inside one table cell, so its expected share is
        // the density there times its area.
        let expected: Vec<f64> = (0..gw * gh)
            .map(|c| {
                let centre = [
                    ((c % gw) as f32 + 0.5) / gw as f32,
                    ((c / gw) as f32 + 0.5) / gh as f32,
                ];
                f64::from(d.density(centre)) * n as f64 / (gw * gh) as f64
            })
            .collect();
        let total: f64 = expected.iter().sum();
        assert!(
            (total / n as f64 - 1.0).abs() < 1e-5,
            "density integrates to 1"
        );
        let (chi2, dof) = chi_square(&counts, &expected);
        assert!(
            chi2 < chi_square_bound(dof),
            "χ² {chi2} with {dof} degrees of freedom"
        );
        // No sample in a cell of no weight.
        for (c, &e) in counts.iter().zip(&expected) {
            assert!(e > 0.0 || *c == 0);
        }
    }

    /// The continuous draw is exact at the ends of the steps: u at the
    /// start of a step gives the start of its bin.
    #[test]
    fn continuous_draw_maps_steps_to_bins() {
        let d = Distribution1D::new(&[1.0, 1.0, 2.0]).unwrap();
        assert_eq!(d.sample_continuous(0.0), (0.0, 0));
        assert_eq!(d.sample_continuous(0.25), (1.0 / 3.0, 1));
        assert_eq!(d.sample_continuous(0.5), (2.0 / 3.0, 2));
        let (x, bin) = d.sample_continuous(ONE_BELOW);
        assert!(x < 1.0 && bin == 2);
        assert_eq!(d.density(0.9), 1.5);
        assert_eq!(d.density(0.1), 0.75);
    }
}
