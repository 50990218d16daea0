//! Participating media that fill what surfaces enclose: the smoke in a
//! box, the murky water in a glass, the fog a camera stands in. A surface
//! names the medium on each of its sides (its material's `interior` and
//! `exterior`), and a path knows which medium it travels in from the last
//! surface it crossed, as Mitsuba 3 and pbrt-v4 have it.
//!
//! A medium is its extinction σt (the chance per unit length that light
//! meets a particle, per colour channel) and its single-scattering albedo
//! (the share of that light a particle scatters rather than absorbs), each
//! a constant or a voxel [`Grid`]; and its [`Phase`] function, how its
//! particles spread the light they scatter over directions.
//!
//! Along a ray, [`Volume::sample`] decides whether light met a particle
//! before the next surface, and where:
//!
//! - where σt is constant, a distance is drawn from the exponential law of
//!   one colour channel chosen at random, and the path is weighted by the
//!   ratio of the true attenuation to the average density of the three
//!   channels' laws (one-sample multiple importance sampling over the
//!   channels, so that a medium of coloured extinction is no noisier than
//!   its greyest channel allows);
//! - where σt varies, by delta tracking against a majorant μ ≥ σt: a
//!   tentative collision at rate μ is a real one (scattering, weighted by
//!   the albedo) or a null one (going on) with probabilities in proportion
//!   to σt and μ − σt, weighted per channel by the ratio of the true
//!   coefficient to the chance taken (spectral tracking, Kutz et al. 2017).
//!
//! [`Volume::transmittance`] gives a shadow ray's share of light: exactly,
//! e^{−σt·ℓ}, where σt is constant; by ratio tracking (the product of
//! 1 − σt/μ over tentative collisions, an unbiased estimate) where it
//! varies.

use crate::geometry::bvh_build::Aabb;
use crate::geometry::transform::{Transform, TransformStep};
use crate::math::{Color, Point3};
use crate::medium::Boundary;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampler::{Dim, Sampler};
use std::path::Path;

/// The most tentative collisions a ray's tracking takes before it counts
/// the ray as absorbed: a bound on the work of a ray through a dense grid
/// (a ray that gets this far carries a vanishing weight).
const MAX_COLLISIONS: u32 = 100_000;

/// A quantity of a medium at each point: one value everywhere, or a grid.
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    /// The same value everywhere.
    Constant(Color),
    /// Interpolated between the voxels of a grid (out of line: the
    /// medium's table stays small).
    Grid(Box<Grid>),
}

impl Field {
    /// The value at world point `p`.
    #[inline]
    pub fn at(&self, p: Point3) -> Color {
        match self {
            Field::Constant(c) => *c,
            Field::Grid(g) => g.at(p),
        }
    }

    /// The largest value of any channel anywhere.
    pub fn max(&self) -> f32 {
        match self {
            Field::Constant(c) => c.max_element(),
            Field::Grid(g) => g.max(),
        }
    }
}

/// Values on a regular grid of voxels filling the unit cube of its own
/// space, placed in the world by a transform, read trilinearly between
/// voxel centres and clamped to the edge voxels outside (Mitsuba's
/// `gridvolume`).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Voxels along x, y and z.
    size: [usize; 3],
    /// Channels per voxel: 1 (grey) or 3 (RGB).
    channels: usize,
    /// The values, x fastest, then y, then z, channels interleaved, each
    /// multiplied by the grid's factor.
    values: Vec<f32>,
    /// The largest value.
    max: f32,
    /// Grid space (the unit cube) to world.
    transform: Transform,
    /// The part of grid space its own voxels fill: the unit cube, or less
    /// where a border of zeros was added ([`Grid::zero_outside`]).
    own: Aabb,
}

/// The largest grid [`Grid::read`] accepts, in voxels (a 1024³ grid of
/// RGB values would take 12 GB).
pub const MAX_VOXELS: usize = 1 << 28;

impl Grid {
    /// A grid of `size` voxels of `channels` (1 or 3) values each, given x
    /// fastest, multiplied by `factor` and placed by `transform`.
    pub fn new(
        size: [usize; 3],
        channels: usize,
        mut values: Vec<f32>,
        factor: f32,
        transform: Transform,
    ) -> Result<Grid, String> {
        if !(channels == 1 || channels == 3) {
            return Err(format!("has {channels} channels per voxel, not 1 or 3"));
        }
        let voxels = size.iter().try_fold(1usize, |n, &s| n.checked_mul(s));
        if size.contains(&0) || voxels.is_none_or(|n| n > MAX_VOXELS) {
            return Err(format!(
                "has {}×{}×{} voxels: from 1 to {MAX_VOXELS} are read",
                size[0], size[1], size[2]
            ));
        }
        if values.len() != voxels.unwrap_or(0) * channels {
            return Err(format!(
                "holds {} values where its size asks for {}",
                values.len(),
                voxels.unwrap_or(0) * channels
            ));
        }
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!(
                "value {i} is {}: values must be finite and ≥ 0",
                values[i]
            ));
        }
        for v in &mut values {
            *v *= factor;
        }
        let max = values.iter().copied().fold(0.0, f32::max);
        Ok(Grid {
            size,
            channels,
            values,
            max,
            transform,
            own: Aabb {
                min: Point3::ZERO,
                max: Point3::ONE,
            },
        })
    }

    /// The grid read as 0 outside its voxels (pbrt's `uniformgrid`), so
    /// that values fall towards 0 beyond the outer centres (to half the
    /// outer voxels' at the faces), rather than stay the outer voxels'
    /// (Mitsuba's). It is the grid with a border of zero voxels around
    /// it, placed so that its own voxels stay where they were: the edge
    /// clamping then reads 0 beyond them, with no test per voxel.
    pub fn zero_outside(self) -> Result<Grid, String> {
        let [nx, ny, nz] = self.size;
        let padded = [nx + 2, ny + 2, nz + 2];
        let c = self.channels;
        let voxels = padded.iter().try_fold(1usize, |n, &s| n.checked_mul(s));
        let Some(count) = voxels.filter(|&n| n <= MAX_VOXELS) else {
            return Err(format!(
                "has {}×{}×{} voxels with its border of zeros: at most {MAX_VOXELS} are read",
                padded[0], padded[1], padded[2]
            ));
        };
        let mut values = vec![0.0; count * c];
        for z in 0..nz {
            for y in 0..ny {
                let from = (z * ny + y) * nx * c;
                let to = (((z + 1) * padded[1] + y + 1) * padded[0] + 1) * c;
                values[to..to + nx * c].copy_from_slice(&self.values[from..from + nx * c]);
            }
        }
        // Padded grid space q' to the grid's own: q = (q'·(n + 2) − 1) / n.
        let axis = |n: usize| (n as f64 + 2.0) / n as f64;
        let inner = Transform::from_steps(&[
            TransformStep::Scale([axis(nx), axis(ny), axis(nz)]),
            TransformStep::Translate([-1.0 / nx as f64, -1.0 / ny as f64, -1.0 / nz as f64]),
        ])
        .map_err(|e| e.to_string())?;
        let transform = self
            .transform
            .compose(&inner)
            .ok_or("is placed too far or too small to take a border of zeros")?;
        let border = |n: usize| 1.0 / (n as f32 + 2.0);
        let low = Point3::new(border(nx), border(ny), border(nz));
        Ok(Grid {
            size: padded,
            values,
            transform,
            own: Aabb {
                min: low,
                max: Point3::ONE - low,
            },
            ..self
        })
    }

    /// Reads a grid from a Mitsuba `.vol` file (version 3, float32 values),
    /// multiplied by `factor` and placed by `transform` (the file's own box
    /// is not used: the grid fills the unit cube that `transform` places).
    pub fn read(path: &Path, factor: f32, transform: Transform) -> Result<Grid, String> {
        let header = crate::input::read_prefix(path, 48, 48).map_err(|e| e.to_string())?;
        if &header[..3] != b"VOL" || header[3] != 3 {
            return Err("is not a .vol file of version 3 (it must begin with \"VOL\", 3)".into());
        }
        let int = |at: usize| i32::from_le_bytes(header[at..at + 4].try_into().expect("4 bytes"));
        if int(4) != 1 {
            return Err(format!(
                "stores its values with encoding {}: only 1 (float32) is read",
                int(4)
            ));
        }
        let dims = [int(8), int(12), int(16)];
        if dims.iter().any(|&d| d <= 0) {
            return Err(format!("has a size of {dims:?} voxels"));
        }
        let size = dims.map(|d| d as usize);
        let channels = int(20);
        if !(channels == 1 || channels == 3) {
            return Err(format!("has {channels} channels per voxel, not 1 or 3"));
        }
        let count = size
            .iter()
            .try_fold(channels as usize, |n, &s| n.checked_mul(s))
            .filter(|&n| n <= MAX_VOXELS * 3)
            .ok_or_else(|| format!("has {dims:?} voxels, more than {MAX_VOXELS}"))?;
        // No more than the header declares is read.
        let bytes = crate::input::read(path, 48 + count as u64 * 4).map_err(|e| e.to_string())?;
        let data = &bytes[48..];
        if data.len() != count * 4 {
            return Err(format!(
                "holds {} bytes of values where its header asks for {}",
                data.len(),
                count * 4
            ));
        }
        let values = data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
            .collect();
        Grid::new(size, channels as usize, values, factor, transform)
    }

    /// The largest value of any channel.
    pub fn max(&self) -> f32 {
        self.max
    }

    /// The world box of the grid's own voxels.
    pub fn bounds(&self) -> Aabb {
        self.transform.bounds(&self.own)
    }

    /// The value of voxel (x, y, z), clamped to the grid.
    #[inline]
    fn voxel(&self, x: isize, y: isize, z: isize) -> Color {
        let clamp = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
        let (x, y, z) = (
            clamp(x, self.size[0]),
            clamp(y, self.size[1]),
            clamp(z, self.size[2]),
        );
        let i = ((z * self.size[1] + y) * self.size[0] + x) * self.channels;
        if self.channels == 1 {
            Color::splat(self.values[i])
        } else {
            Color::new(self.values[i], self.values[i + 1], self.values[i + 2])
        }
    }

    /// The value at world point `p`: trilinear between voxel centres (voxel
    /// i's centre at (i + ½)/n in grid space).
    #[inline]
    pub fn at(&self, p: Point3) -> Color {
        let q = self.transform.inverse_point(p);
        let mut base = [0isize; 3];
        let mut frac = [0.0f32; 3];
        for a in 0..3 {
            let x = q[a] * self.size[a] as f32 - 0.5;
            let f = x.floor();
            base[a] = f as isize;
            frac[a] = x - f;
        }
        let [x, y, z] = base;
        let [fx, fy, fz] = frac;
        let lerp = |a: Color, b: Color, t: f32| a + (b - a) * t;
        let row = |y, z| lerp(self.voxel(x, y, z), self.voxel(x + 1, y, z), fx);
        let plane = |z| lerp(row(y, z), row(y + 1, z), fy);
        lerp(plane(z), plane(z + 1), fz)
    }
}

/// What becomes of light along a ray through a medium up to the next
/// surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// It met a particle at distance `t`, which scatters it; the path's
    /// throughput is multiplied by `weight` (the albedo, where the medium
    /// is grey).
    Scatter {
        /// The distance along the ray.
        t: f32,
        /// The factor on the throughput.
        weight: Color,
    },
    /// It reached the surface (or went on for ever); the throughput is
    /// multiplied by `weight` (1 where the medium is grey).
    Pass {
        /// The factor on the throughput.
        weight: Color,
    },
    /// It was absorbed: the path ends.
    Absorbed,
}

/// A participating medium (see the [module](self) documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// The extinction σt per unit length.
    sigma_t: Field,
    /// The single-scattering albedo, in [0, 1].
    albedo: Field,
    /// Where the medium is, in the world: outside this box there is
    /// nothing (a medium whose extinction is a grid fills that grid's box
    /// only, as in Mitsuba); `None`: everywhere.
    bounds: Option<Boundary>,
    /// The largest extinction of any channel anywhere: the rate of
    /// tentative collisions.
    majorant: f32,
    /// How particles scatter: isotropic unless set.
    pub phase: Phase,
}

/// The mean of a colour's channels.
#[inline]
fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

impl Volume {
    /// A medium of extinction `sigma_t` and single-scattering `albedo`;
    /// `bounds` limits it to a box.
    pub fn new(sigma_t: Field, albedo: Field, bounds: Option<Aabb>) -> Volume {
        let majorant = sigma_t.max();
        Volume {
            sigma_t,
            albedo,
            bounds: bounds.map(|b| Boundary::Box {
                min: b.min,
                max: b.max,
            }),
            majorant,
            phase: Phase::Isotropic,
        }
    }

    /// The medium with particles that scatter by `phase`.
    pub fn with_phase(self, phase: Phase) -> Volume {
        Volume { phase, ..self }
    }

    /// The part `[start, end)` of `[0, t_max)` along `ray` inside the
    /// medium's box, if any.
    #[inline]
    fn span(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        let Some(b) = &self.bounds else {
            return Some((0.0, t_max));
        };
        let (near, far) = b.span(ray)?;
        let (near, far) = (near.max(0.0), far.min(t_max));
        (near < far).then_some((near, far))
    }

    /// What becomes of light along the unit-direction `ray` up to `t_max`
    /// (the next surface, or infinity).
    pub fn sample(&self, ray: &Ray, t_max: f32, sampler: &mut impl Sampler) -> Event {
        let Some((start, end)) = self.span(ray, t_max) else {
            return Event::Pass { weight: Color::ONE };
        };
        match &self.sigma_t {
            Field::Constant(sigma_t) => self.sample_constant(ray, *sigma_t, start, end, sampler),
            Field::Grid(_) => self.delta_track(ray, start, end, sampler),
        }
    }

    /// [`sample`](Self::sample) where σt is constant, over `[start, end)`.
    fn sample_constant(
        &self,
        ray: &Ray,
        sigma_t: Color,
        start: f32,
        end: f32,
        sampler: &mut impl Sampler,
    ) -> Event {
        let channel = ((sampler.get_1d(Dim::Medium) * 3.0) as usize).min(2);
        let u = sampler.get_1d(Dim::Medium);
        let rate = sigma_t[channel];
        let d = if rate > 0.0 {
            -(1.0 - u).ln() / rate
        } else {
            f32::INFINITY
        };
        if start + d < end {
            let attenuation = (-sigma_t * d).exp();
            let pdf = mean(sigma_t * attenuation);
            let p = ray.at(start + d);
            let sigma_s = sigma_t * self.albedo.at(p);
            return if pdf > 0.0 {
                Event::Scatter {
                    t: start + d,
                    weight: sigma_s * attenuation / pdf,
                }
            } else {
                Event::Absorbed
            };
        }
        let passed = through(sigma_t, end - start);
        let chance = mean(passed);
        if chance > 0.0 {
            Event::Pass {
                weight: passed / chance,
            }
        } else {
            Event::Absorbed
        }
    }

    /// [`sample`](Self::sample) by delta tracking, over `[start, end)`.
    fn delta_track(&self, ray: &Ray, start: f32, end: f32, sampler: &mut impl Sampler) -> Event {
        let mu = self.majorant;
        if !(mu > 0.0) {
            return Event::Pass { weight: Color::ONE };
        }
        let mut t = start;
        let mut weight = Color::ONE;
        for _ in 0..MAX_COLLISIONS {
            t -= (1.0 - sampler.get_1d(Dim::Medium)).ln() / mu;
            if t >= end {
                return Event::Pass { weight };
            }
            let p = ray.at(t);
            let sigma_t = self.sigma_t.at(p);
            let sigma_n = (Color::splat(mu) - sigma_t).max(Color::ZERO);
            // The chances of a real collision (which scatters, weighted by
            // the albedo) and a null one, in proportion to what each
            // carries of the path's weight so far: for a grey medium σt/μ
            // and 1 − σt/μ, as Mitsuba's tracking has them.
            let (real, null) = (mean(sigma_t * weight), mean(sigma_n * weight));
            let total = real + null;
            if !(total > 0.0) {
                return Event::Absorbed;
            }
            if sampler.get_1d(Dim::Medium) * total < real {
                let sigma_s = sigma_t * self.albedo.at(p);
                return Event::Scatter {
                    t,
                    weight: weight * sigma_s * (total / (mu * real)),
                };
            }
            weight *= sigma_n * (total / (mu * null));
        }
        Event::Absorbed
    }

    /// The share of light that crosses the medium along the unit-direction
    /// `ray` from 0 to `t_max` without meeting a particle, per channel:
    /// exact where σt is constant, an unbiased estimate (ratio tracking)
    /// where it varies.
    pub fn transmittance(&self, ray: &Ray, t_max: f32, sampler: &mut impl Sampler) -> Color {
        let Some((start, end)) = self.span(ray, t_max) else {
            return Color::ONE;
        };
        match &self.sigma_t {
            Field::Constant(s) => through(*s, end - start),
            Field::Grid(_) => {
                let mu = self.majorant;
                let mut t = start;
                let mut share = Color::ONE;
                if !(mu > 0.0) {
                    return share;
                }
                for _ in 0..MAX_COLLISIONS {
                    t -= (1.0 - sampler.get_1d(Dim::Medium)).ln() / mu;
                    if t >= end {
                        return share;
                    }
                    let sigma_t = self.sigma_t.at(ray.at(t));
                    share *= (Color::ONE - sigma_t / mu).max(Color::ZERO);
                    if share == Color::ZERO {
                        break;
                    }
                }
                Color::ZERO
            }
        }
    }
}

/// e^{−σℓ} per channel, 1 where nothing attenuates (even over an
/// infinite length).
#[inline]
fn through(sigma: Color, length: f32) -> Color {
    let channel = |s: f32| if s > 0.0 { (-s * length).exp() } else { 1.0 };
    Color::new(channel(sigma.x), channel(sigma.y), channel(sigma.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::transform::TransformStep;
    use crate::math::Vec3;
    use crate::rng::Rng;

    fn ray() -> Ray {
        Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z)
    }

    /// Mean and standard error of `n` draws of `f`.
    fn estimate(n: usize, mut f: impl FnMut(&mut Rng) -> Color) -> (Color, Color) {
        let mut sampler = Rng::new(17);
        let (mut sum, mut sum2) = (Color::ZERO, Color::ZERO);
        for _ in 0..n {
            let v = f(&mut sampler);
            sum += v;
            sum2 += v * v;
        }
        let m = sum / n as f32;
        let var = (sum2 / n as f32 - m * m).max(Color::ZERO);
        (m, (var / n as f32).to_array().map(f32::sqrt).into())
    }

    fn assert_close(got: (Color, Color), want: Color, what: &str) {
        let (m, se) = got;
        for c in 0..3 {
            let tolerance = 4.0 * se[c] + 1e-6;
            assert!(
                (m[c] - want[c]).abs() <= tolerance,
                "{what}, channel {c}: {} against {} (± {tolerance})",
                m[c],
                want[c]
            );
        }
    }

    /// In a slab of coloured extinction, what passes carries, on average,
    /// e^{−σt·ℓ} per channel, and what scatters, the albedo times the
    /// chance of scattering: 1 − e^{−σt·ℓ} (the single-scattering
    /// integral of a slab with nothing behind it).
    #[test]
    fn constant_media_weigh_passing_and_scattering_per_channel() {
        let sigma_t = Color::new(0.2, 1.0, 3.0);
        let albedo = Color::new(0.9, 0.5, 0.25);
        let volume = Volume::new(Field::Constant(sigma_t), Field::Constant(albedo), None);
        let length = 1.5;
        let passed = estimate(400_000, |s| match volume.sample(&ray(), length, s) {
            Event::Pass { weight } => weight,
            _ => Color::ZERO,
        });
        assert_close(passed, (-sigma_t * length).exp(), "passing");
        let scattered = estimate(400_000, |s| match volume.sample(&ray(), length, s) {
            Event::Scatter { weight, t } => {
                assert!((0.0..length).contains(&t));
                weight
            }
            _ => Color::ZERO,
        });
        let want = albedo * (Color::ONE - (-sigma_t * length).exp());
        assert_close(scattered, want, "scattering");
        let exact = volume.transmittance(&ray(), length, &mut Rng::new(1));
        assert!((exact - (-sigma_t * length).exp()).abs().max_element() < 1e-6);
    }

    /// A grid medium agrees with the same density given as a constant:
    /// delta and ratio tracking estimate what the exact formulas give, and
    /// the medium ends at its grid's box.
    #[test]
    fn tracking_through_a_grid_matches_the_constant_medium() {
        let sigma = Color::new(0.5, 1.0, 2.0);
        let values: Vec<f32> = (0..8).flat_map(|_| sigma.to_array()).collect();
        // The unit cube stretched to z in [0, 2]: the ray crosses 2 of it.
        let steps = [TransformStep::Scale([1.0, 1.0, 2.0])];
        let transform = Transform::from_steps(&steps).unwrap();
        let grid = Grid::new([2, 2, 2], 3, values, 1.0, transform).unwrap();
        let bounds = Some(grid.bounds());
        let volume = Volume::new(
            Field::Grid(Box::new(grid)),
            Field::Constant(Color::splat(0.8)),
            bounds,
        );
        let along = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        let want = (-sigma * 2.0).exp();
        let ratio = estimate(100_000, |s| volume.transmittance(&along, 10.0, s));
        assert_close(ratio, want, "ratio tracking");
        let passed = estimate(200_000, |s| match volume.sample(&along, 10.0, s) {
            Event::Pass { weight } => weight,
            _ => Color::ZERO,
        });
        assert_close(passed, want, "delta tracking, passing");
        let scattered = estimate(200_000, |s| match volume.sample(&along, 10.0, s) {
            Event::Scatter { weight, t } => {
                assert!((1.0..3.0).contains(&t), "{t}");
                weight
            }
            _ => Color::ZERO,
        });
        assert_close(
            scattered,
            0.8 * (Color::ONE - want),
            "delta tracking, scattering",
        );
    }

    /// Values between voxel centres are interpolated, and clamp beyond the
    /// outer centres.
    #[test]
    fn grids_interpolate_between_voxel_centres() {
        let grid = Grid::new([2, 1, 1], 1, vec![1.0, 3.0], 2.0, Transform::IDENTITY).unwrap();
        let at = |x: f32| grid.at(Vec3::new(x, 0.5, 0.5)).x;
        assert_eq!(at(0.25), 2.0);
        assert_eq!(at(0.75), 6.0);
        assert!((at(0.5) - 4.0).abs() < 1e-6);
        assert_eq!(at(0.0), 2.0);
        assert_eq!(at(1.0), 6.0);
        assert_eq!(grid.max(), 6.0);
        assert!(Grid::new([2, 1, 1], 2, vec![0.0; 4], 1.0, Transform::IDENTITY).is_err());
        assert!(Grid::new([2, 1, 1], 1, vec![0.0], 1.0, Transform::IDENTITY).is_err());
        assert!(Grid::new([2, 1, 1], 1, vec![0.0, -1.0], 1.0, Transform::IDENTITY).is_err());
        assert!(Grid::new([0, 1, 1], 1, vec![], 1.0, Transform::IDENTITY).is_err());
    }

    /// A `.vol` file is read as written, and a broken one is refused with
    /// what is wrong.
    /// A grid read as 0 outside falls towards 0 beyond its outer centres
    /// (to half the outer value at its faces), and is its voxels' values
    /// between them.
    #[test]
    fn grids_zero_outside_fall_to_zero_at_their_faces() {
        let grid = Grid::new([2, 1, 1], 1, vec![1.0, 3.0], 1.0, Transform::IDENTITY)
            .unwrap()
            .zero_outside()
            .unwrap();
        let at = |x: f32| grid.at(Vec3::new(x, 0.5, 0.5)).x;
        for (x, want) in [
            (0.0, 0.5),
            (0.125, 0.75),
            (0.25, 1.0),
            (0.5, 2.0),
            (0.875, 2.25),
            (1.0, 1.5),
        ] {
            assert!(
                (at(x) - want).abs() < 1e-5,
                "at {x}: {} against {want}",
                at(x)
            );
        }
    }

    #[test]
    fn vol_files_are_read_and_broken_ones_refused() {
        let dir = std::env::temp_dir().join(format!("lumen-vol-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, header: &[i32], values: &[f32]| {
            let mut bytes = b"VOL\x03".to_vec();
            for h in header {
                bytes.extend(h.to_le_bytes());
            }
            bytes.extend(
                [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0]
                    .iter()
                    .flat_map(|v| v.to_le_bytes()),
            );
            bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            path
        };
        let good = write("good.vol", &[1, 2, 1, 1, 1], &[1.0, 3.0]);
        let grid = Grid::read(&good, 1.0, Transform::IDENTITY).unwrap();
        assert_eq!(grid.at(Vec3::new(0.75, 0.5, 0.5)).x, 3.0);
        let short = write("short.vol", &[1, 2, 1, 1, 1], &[1.0]);
        let e = Grid::read(&short, 1.0, Transform::IDENTITY).unwrap_err();
        assert!(e.contains("4 bytes") && e.contains("8"), "{e}");
        let long = write("long.vol", &[1, 2, 1, 1, 1], &[1.0, 3.0, 5.0]);
        let e = Grid::read(&long, 1.0, Transform::IDENTITY).unwrap_err();
        assert!(e.contains("60 bytes") && e.contains("56"), "{e}");
        let encoding = write("enc.vol", &[2, 2, 1, 1, 1], &[1.0, 3.0]);
        assert!(Grid::read(&encoding, 1.0, Transform::IDENTITY)
            .unwrap_err()
            .contains("encoding 2"));
        let huge = write("huge.vol", &[1, 1 << 20, 1 << 20, 1 << 20, 3], &[]);
        assert!(Grid::read(&huge, 1.0, Transform::IDENTITY)
            .unwrap_err()
            .contains("voxels"));
        let channels = write("ch.vol", &[1, 1, 1, 1, 6], &[0.0; 6]);
        assert!(Grid::read(&channels, 1.0, Transform::IDENTITY)
            .unwrap_err()
            .contains("6 channels"));
        std::fs::write(dir.join("tiny.vol"), b"VOL").unwrap();
        assert!(Grid::read(&dir.join("tiny.vol"), 1.0, Transform::IDENTITY).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
