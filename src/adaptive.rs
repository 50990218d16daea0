//! Adaptive sampling: no more samples for pixels that are already clean.
//!
//! Between passes, each pixel still being sampled estimates the error of its
//! mean from its two halves: the mean A of its samples of even index and the
//! mean B of those of odd index are independent estimates of the pixel, and
//! (A − B)/2 has the standard deviation of the whole mean's error. Averaged
//! over the three channels, scaled by √(π/2) (the mean of |x| for a normal x
//! is σ·√(2/π)) and divided by the pixel's brightness (its channels' mean,
//! at least [`DARK`]), it is the pixel's relative error. A pixel stops once
//! its relative error is at most the noise target, after at least
//! [`MIN_SAMPLES`] samples, and only when the mean relative error of the
//! 3×3 pixels around it is within the target too: a single estimate from
//! two halves is itself noisy, and a pixel whose halves agree by chance is
//! kept going by its neighbours (a stopped neighbour counts with the error
//! it stopped at). A firefly in either half makes the halves disagree, so a
//! pixel with one keeps sampling.
//!
//! With low-discrepancy samples the estimate is cautious: each half is less
//! evenly spread than the whole, so the error of the whole is smaller than
//! the halves say (about half on the cover's spheres), and pixels run
//! longer than strictly needed, never shorter.
//!
//! Stopped pixels never start again. The decision depends only on the film
//! after a pass and on which pixels had stopped before, so it is the same
//! whatever the thread count, and a resumed render (whose checkpoint keeps
//! the stopped pixels) takes exactly the same samples as one never stopped.

use crate::film::Film;

/// Samples every pixel takes before it may stop.
pub const MIN_SAMPLES: u32 = 16;

/// Brightness below which errors are measured against this value instead:
/// a pixel whose light is near black need not be sampled until its tiny
/// absolute error is small relative to it.
pub const DARK: f32 = 1e-3;

/// The estimated relative error of pixel `i` (row-major) of `film`, or `None`
/// when one of its halves has no sample.
pub fn relative_error(film: &Film, i: usize) -> Option<f32> {
    let (a, b) = film.halves(i)?;
    let error = (a - b).abs().element_sum() / 3.0 * 0.5 * std::f32::consts::FRAC_PI_2.sqrt();
    let brightness = (film.mean(i).element_sum() / 3.0).max(DARK);
    Some(error / brightness)
}

/// Updates `active` (one flag per pixel of `film`, row-major) after a pass
/// that left `spp_done` samples in every active pixel: the pixels within
/// `target` relative error, in a neighbourhood within it on average, stop.
/// Returns the number of pixels still active.
pub fn update(film: &Film, active: &mut [bool], target: f32, spp_done: u32) -> usize {
    let (w, h) = (film.width() as usize, film.height() as usize);
    assert_eq!(active.len(), w * h, "one flag per pixel");
    if spp_done < MIN_SAMPLES {
        return active.iter().filter(|&&a| a).count();
    }
    let errors: Vec<Option<f32>> = (0..w * h).map(|i| relative_error(film, i)).collect();
    let mut still = 0;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !active[i] {
                continue;
            }
            // The pixel's own error, and the mean over its neighbourhood
            // (itself included), both within the target.
            let (mut sum, mut n, mut known) = (0.0, 0, true);
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    match errors[ny * w + nx] {
                        Some(e) => {
                            sum += e;
                            n += 1;
                        }
                        None => known = false,
                    }
                }
            }
            let clean = known && errors[i].is_some_and(|e| e <= target) && sum / n as f32 <= target;
            if clean {
                active[i] = false;
            } else {
                still += 1;
            }
        }
    }
    still
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Color;
    use rayon::prelude::*;

    /// A film of `w`×1 pixels, each with the given sample values at indices
    /// 0, 1, 2, ….
    fn film(pixels: &[Vec<f32>]) -> Film {
        let mut film = Film::with_halves(pixels.len() as u32, 1);
        {
            let mut row = film.rows_mut().collect::<Vec<_>>().pop().unwrap();
            for (x, samples) in pixels.iter().enumerate() {
                for (i, &v) in samples.iter().enumerate() {
                    row.add(x, i as u32, Color::splat(v));
                }
            }
        }
        film
    }

    #[test]
    fn the_error_comes_from_the_two_halves() {
        // Even samples 1, odd samples 3: halves 1 and 3, mean 2, error
        // |1 − 3|/2·√(π/2) relative to 2.
        let f = film(&[vec![1.0, 3.0, 1.0, 3.0]]);
        let expected = 0.5 * std::f32::consts::FRAC_PI_2.sqrt();
        assert!((relative_error(&f, 0).unwrap() - expected).abs() < 1e-6);
        // Constant samples: no error; one sample: no estimate.
        assert_eq!(relative_error(&film(&[vec![0.5; 4]]), 0), Some(0.0));
        assert_eq!(relative_error(&film(&[vec![0.5]]), 0), None);
        // Black pixels are measured against DARK.
        let dark = film(&[vec![0.0, 2e-4, 0.0, 2e-4]]);
        let e = relative_error(&dark, 0).unwrap();
        assert!((e - 2e-4 * expected / DARK).abs() < 1e-6, "{e}");
    }

    #[test]
    fn pixels_stop_only_when_clean_after_the_minimum_and_with_clean_neighbours() {
        let n = MIN_SAMPLES as usize;
        let clean = vec![0.5; n];
        let noisy: Vec<f32> = (0..n).map(|i| (i % 2) as f32).collect();
        // Pixels 0..6: clean, clean, clean, noisy, clean, clean.
        let pixels = [&clean, &clean, &clean, &noisy, &clean, &clean].map(|p| p.to_vec());
        let f = film(&pixels);
        let mut active = vec![true; 6];
        assert_eq!(update(&f, &mut active, 0.01, MIN_SAMPLES - 1), 6);
        assert_eq!(active, vec![true; 6], "nothing stops before the minimum");
        assert_eq!(update(&f, &mut active, 0.01, MIN_SAMPLES), 3);
        // The noisy pixel keeps itself and its neighbours going.
        assert_eq!(active, [false, false, true, true, true, false]);
        // A stopped pixel never restarts, and a loose target stops all.
        assert_eq!(update(&f, &mut active, 10.0, MIN_SAMPLES), 0);
        assert_eq!(active, vec![false; 6]);
    }
}
