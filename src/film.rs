//! The film: where samples accumulate, and how the accumulated light becomes
//! displayable pixels.

use crate::aov::{Features, Layer, Layers, LAYERS};
use crate::math::{Color, Vec3};
use rayon::prelude::*;

/// The sum of some samples of a pixel, a number per channel, in 64.64 fixed
/// point: integers counting 2⁻⁶⁴.
///
/// Integer addition is associative, so a pixel's sum is the same to the bit
/// whatever order its samples are added in: by pass, by thread, or by
/// machine, each summing a share of the samples and the shares then added
/// (see `docs/distributed.md`). Each sample is exact down to 2⁻⁶⁴ ≈ 5.4e-20
/// (every `f32` from about 4.5e-13 up is kept whole; smaller values are cut
/// to a multiple of 2⁻⁶⁴), and a pixel's sum holds up to 2⁶³ ≈ 9.2e18: a
/// sample of 2⁶³ or more is dropped, like a NaN, and so is a sample that
/// would take its pixel's sum past that bound ([`RowMut::add`]), so that a
/// sum never wraps; `lumen merge` refuses parts whose sums would.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sum(pub [i128; 3]);

/// 2⁶⁴: one in 64.64 fixed point.
const ONE: f64 = 18_446_744_073_709_551_616.0;

impl Sum {
    /// Zero.
    pub const ZERO: Sum = Sum([0; 3]);

    /// The fixed-point value of a colour: `None` if a channel is NaN, infinite
    /// or of magnitude 2⁶³ or more (such a sample is dropped).
    #[inline]
    pub fn of(c: [f64; 3]) -> Option<Self> {
        let fixed = |v: f64| (v.abs() < ONE / 2.0).then_some((v * ONE) as i128);
        Some(Sum([fixed(c[0])?, fixed(c[1])?, fixed(c[2])?]))
    }

    /// [`Sum::of`] a sample's colour, from the bits of its `f32`s: shifting
    /// the significand by the exponent gives the same integers as
    /// converting through `f64` (truncated towards zero), without a
    /// float-to-`i128` conversion, which is a library call, per channel
    /// (see `docs/performance.md`).
    #[inline(always)]
    pub fn of_color(c: Color) -> Option<Self> {
        Some(Sum([fixed(c.x)?, fixed(c.y)?, fixed(c.z)?]))
    }

    /// The fixed-point value of a feature (see [`crate::aov`]) to 2⁻³²: a
    /// conversion of a few instructions a channel, where [`Sum::of_color`]
    /// keeps every bit of a colour at several times the cost. A channel
    /// beyond ±2³¹ saturates there; NaN is 0. (The albedo and normal, within
    /// ±1, take a cheaper way: [`UnitFeatures`].)
    #[inline(always)]
    pub fn of_feature(v: Vec3) -> Sum {
        // Scaling by a power of two is exact in `f32` (as through `f64`);
        // the conversion saturates, as `as` converts.
        let fixed = |x: f32| i128::from((x * TWO_32 as f32) as i64) << 32;
        Sum([fixed(v.x), fixed(v.y), fixed(v.z)])
    }

    /// The fixed-point value of a squared colour `square`, for the
    /// variance's sum of squares: below 2¹⁹ in every channel, rounded to
    /// the nearest multiple of 2⁻³² through `f64` (as [`UnitFeatures`]
    /// rounds, a few instructions a channel, where [`Sum::of_color`] takes
    /// tens); otherwise exactly, as [`Sum::of_color`] converts (`None` for
    /// NaN, infinities and 2⁶³ or more). Either way the same square always
    /// gives the same sum, so a pixel's sum of squares does not depend on
    /// how its samples were split.
    #[inline(always)]
    pub fn of_square(square: Color) -> Option<Sum> {
        /// 2¹⁹: a square below it, times 2³², is below 2⁵¹.
        const QUICK: f32 = 524_288.0;
        // NaN fails each test.
        if square.x < QUICK && square.y < QUICK && square.z < QUICK {
            let fixed = |v: f32| i128::from(round_to_integer(f64::from(v) * TWO_32)) << 32;
            Some(Sum([fixed(square.x), fixed(square.y), fixed(square.z)]))
        } else {
            Sum::of_color(square)
        }
    }

    /// This sum plus `other`, channel by channel.
    #[inline]
    pub fn plus(self, other: Sum) -> Sum {
        Sum([0, 1, 2].map(|c| self.0[c].wrapping_add(other.0[c])))
    }

    /// This sum plus `other`, channel by channel, or `None` if a channel
    /// would pass what a sum holds (±2⁶³ in value).
    #[inline(always)]
    pub fn checked_plus(self, other: Sum) -> Option<Sum> {
        let (a, fa) = self.0[0].overflowing_add(other.0[0]);
        let (b, fb) = self.0[1].overflowing_add(other.0[1]);
        let (c, fc) = self.0[2].overflowing_add(other.0[2]);
        // One branch for the three: overflow is rare, and never in a sane
        // scene.
        (!(fa | fb | fc)).then_some(Sum([a, b, c]))
    }

    /// This sum minus `other`, channel by channel.
    #[inline]
    pub fn minus(self, other: Sum) -> Sum {
        Sum([0, 1, 2].map(|c| self.0[c].wrapping_sub(other.0[c])))
    }

    /// The sum as floating-point numbers (rounded to `f64`).
    #[inline]
    pub fn to_f64(self) -> [f64; 3] {
        // Times 2⁻⁶⁴, exact as dividing by 2⁶⁴ is, and quicker; written
        // out, as `map`'s closure may be left a call a channel.
        let f = |v: i128| i128_to_f64(v) * (1.0 / ONE);
        [f(self.0[0]), f(self.0[1]), f(self.0[2])]
    }
}

/// `v as f64` (rounded to nearest, ties to even), without the library call
/// the compiler makes of it: the top 64 bits of `|v|` keep, in their last
/// bit, whether any bit below them is set, which is all the rounding to 53
/// bits needs; the shift back is by a power of two, exact.
#[inline(always)]
fn i128_to_f64(v: i128) -> f64 {
    let magnitude = v.unsigned_abs();
    let shift = 64u32.saturating_sub(magnitude.leading_zeros());
    let top = (magnitude >> shift) as u64;
    let sticky = u64::from(magnitude & ((1u128 << shift) - 1) != 0);
    let scaled = (top | sticky) as f64 * f64::from_bits(u64::from(1023 + shift) << 52);
    if v < 0 {
        -scaled
    } else {
        scaled
    }
}

/// One in the fixed point of [`UnitFeatures`]: 2³⁰.
const UNIT: f64 = 1_073_741_824.0;

/// 2³²: one in the fixed point of the depth, position and squared colour.
const TWO_32: f64 = 4_294_967_296.0;

/// `x`, of magnitude below 2⁵¹, rounded to the nearest integer (ties to
/// even) without a conversion instruction's saturation and NaN tests:
/// adding 1.5 · 2⁵² leaves the rounded value in the low bits of the
/// significand, whose bits then differ from those of 1.5 · 2⁵² by it. Four
/// lanes an instruction where the compiler vectorises it.
#[inline(always)]
fn round_to_integer(x: f64) -> i64 {
    const ROUND: f64 = 6_755_399_441_055_744.0;
    ((x + ROUND).to_bits() as i64).wrapping_sub(ROUND.to_bits() as i64)
}

/// The albedos and normals of some samples of one pixel, summed channel by
/// channel in fixed point to 2⁻³⁰ (each rounded to the nearest multiple),
/// until [`RowMut::add_unit_features`] adds them to the pixel's sums at
/// once.
///
/// Their channels lie within ±1, so each converts exactly through `f64`
/// (four channels to an instruction, no saturation to check) and a
/// pixel's sum of its samples, fewer than 2³², fits 64 bits: an addition a
/// channel and sample in place of a conversion to and an addition of 128
/// bits. The sums are integers, so how a pixel's samples are grouped
/// before they reach the film changes no bit of its features.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitFeatures([i64; 8]);

impl UnitFeatures {
    /// Adds a sample's albedo and normal. A channel beyond ±2 (no albedo
    /// or normal) or NaN counts as 0.
    #[inline(always)]
    pub fn add(&mut self, albedo: Color, normal: Vec3) {
        let v = [
            albedo.x, albedo.y, albedo.z, normal.x, normal.y, normal.z, 0.0, 0.0,
        ];
        for (sum, x) in self.0.iter_mut().zip(v) {
            let x = if x.abs() <= 2.0 { x } else { 0.0 };
            // Exact up to the rounding: 24 bits scaled by a power of two.
            *sum = sum.wrapping_add(round_to_integer(f64::from(x) * UNIT));
        }
    }
}

/// A pixel's sums of albedos (its first three channels) and normals (the
/// last three) as the film keeps them: in 2⁻³⁰, as [`UnitFeatures`]
/// gathers them, a quarter of the room and none of the conversions of
/// [`Sum`]s. A pixel holds fewer than 2³² samples (its count is a `u32`),
/// each channel within ±2 (2³¹ in 2⁻³⁰), so a channel's sum stays within
/// ±2⁶³: it never wraps. A film's files hold them as [`Sum`]s
/// ([`unit_to_sum`], [`sum_to_unit`]), as they hold every layer.
pub type UnitSums = [i64; 6];

/// Why [`Film::add_packed_layer`] refused a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PackedError {
    /// Its sum is not one its samples could have made.
    NotSamples,
    /// Added to the film's, it would pass what a sum holds.
    Overflow,
}

impl PackedError {
    /// What is wrong with the pixel, following "pixel (x, y) ".
    pub fn message(self) -> &'static str {
        match self {
            PackedError::NotSamples => "is not a sum of its samples' values",
            PackedError::Overflow => "would pass what a pixel's sum holds with the other parts'",
        }
    }
}

/// The place of `layer`'s channels in a pixel's [`UnitSums`], if they are
/// kept there.
fn unit_offset(layer: Layer) -> Option<usize> {
    match layer {
        Layer::Albedo => Some(0),
        Layer::Normal => Some(3),
        _ => None,
    }
}

/// A channel of [`UnitSums`] as the channel of a [`Sum`] (in 2⁻⁶⁴):
/// exact.
#[inline]
fn unit_to_sum(v: i64) -> i128 {
    i128::from(v) << 34
}

/// The channel of [`UnitSums`] that a channel `v` of a [`Sum`] of `count`
/// samples is, if it is one: a multiple of 2⁻³⁰, within ±2 a sample
/// (what [`UnitFeatures`] gathers).
fn sum_to_unit(v: i128, count: u32) -> Option<i64> {
    let unit = v >> 34;
    let whole = unit << 34 == v;
    (whole && unit.unsigned_abs() <= u128::from(count) << 31).then_some(unit as i64)
}

/// Makes `dst` a copy of `src`, on all threads when it already has its
/// length: a render copies its film before every pass while its threads
/// wait, and a film with feature layers is several times the image's size.
fn copy_vec<T: Copy + Send + Sync>(dst: &mut Vec<T>, src: &[T]) {
    const CHUNK: usize = 1 << 14;
    if dst.len() == src.len() {
        dst.par_chunks_mut(CHUNK)
            .zip(src.par_chunks(CHUNK))
            .for_each(|(d, s)| d.copy_from_slice(s));
    } else {
        dst.clear();
        dst.extend_from_slice(src);
    }
}

/// `v` in 64.64 fixed point, truncated towards zero; `None` if NaN,
/// infinite, or of magnitude 2⁶³ or more. Worked out from the bits: the
/// significand shifted by the exponent.
#[inline(always)]
fn fixed(v: f32) -> Option<i128> {
    let bits = v.to_bits();
    let exponent = (bits >> 23) & 0xff;
    // v = significand × 2^(exponent − 150) (exponent 1 for subnormals); an
    // exponent of 190 or more is 2⁶³ or more (255: NaN and infinities).
    if exponent >= 190 {
        return None;
    }
    let significand = (bits & 0x7f_ffff) | if exponent == 0 { 0 } else { 0x80_0000 };
    // Times 2⁶⁴: a shift by exponent − 86, from −85 to 103.
    let magnitude = if exponent >= 86 {
        i128::from(significand) << (exponent - 86)
    } else {
        i128::from(
            u64::from(significand)
                .checked_shr(86 - exponent.max(1))
                .unwrap_or(0),
        )
    };
    Some(if bits >> 31 == 1 {
        -magnitude
    } else {
        magnitude
    })
}

/// Linear accumulation of samples for every pixel.
///
/// Sums are kept in fixed point ([`Sum`]), so an image is the same to the
/// bit however its samples were split: into passes, between threads, or
/// between machines.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Sum of the finite samples of each pixel, row-major, top row first.
    sums: Vec<Sum>,
    /// Number of finite samples in each pixel.
    counts: Vec<u32>,
    /// The same for the samples of odd index only, in a film that keeps
    /// them ([`Film::with_halves`]; empty otherwise): with the whole, two
    /// independent half estimates of each pixel, whose difference measures
    /// its noise (see [`crate::adaptive`]).
    odd_sums: Vec<Sum>,
    odd_counts: Vec<u32>,
    /// The sums of the samples' features (see [`crate::aov`]), a vector a
    /// layer kept (empty for the others, and for the albedo and normal,
    /// which are in `unit_sums`), in [`Layer::ALL`]'s order; their counts
    /// are the image's.
    layer_sums: [Vec<Sum>; LAYERS],
    /// The sums of the albedos and normals, when the film keeps either
    /// (empty otherwise).
    unit_sums: Vec<UnitSums>,
    /// The layers the film keeps.
    layers: Layers,
}

/// One row of a film, to add samples to (see [`Film::rows_mut`]).
pub struct RowMut<'a> {
    /// Sums of the finite samples of each pixel.
    pub sums: &'a mut [Sum],
    /// Numbers of finite samples.
    pub counts: &'a mut [u32],
    /// Sums of the finite samples of odd index (empty in a film that does
    /// not keep them).
    pub odd_sums: &'a mut [Sum],
    /// Numbers of finite samples of odd index (empty likewise).
    pub odd_counts: &'a mut [u32],
    /// The sums of the samples' features, a slice a layer the film keeps
    /// (empty for the others, and for the albedo and normal), in
    /// [`Layer::ALL`]'s order.
    pub layer_sums: [&'a mut [Sum]; LAYERS],
    /// The sums of the albedos and normals (empty if the film keeps
    /// neither).
    pub unit_sums: &'a mut [UnitSums],
    /// Of the channels of `unit_sums`, the ones of the layers the film
    /// keeps (all bits set) and the others (none): a film that keeps the
    /// albedo alone has no sums of normals.
    pub unit_mask: UnitSums,
    /// The layers the film keeps.
    pub layers: Layers,
}

impl RowMut<'_> {
    /// Adds sample `index` of pixel `x`, of colour `c`, unless it is NaN,
    /// infinite, beyond what a [`Sum`] holds, or would take the pixel's sum
    /// past it: such a sample is left out and `false` is returned so the
    /// caller can count it.
    #[inline(always)]
    pub fn add(&mut self, x: usize, index: u32, c: Color) -> bool {
        let Some(c) = Sum::of_color(c) else {
            return false;
        };
        let Some(sum) = self.sums[x].checked_plus(c) else {
            return false;
        };
        if index % 2 == 1 && !self.odd_counts.is_empty() {
            let Some(odd) = self.odd_sums[x].checked_plus(c) else {
                return false;
            };
            self.odd_sums[x] = odd;
            self.odd_counts[x] += 1;
        }
        self.sums[x] = sum;
        self.counts[x] += 1;
        true
    }

    /// [`RowMut::add`], and the sample's `features` to the layers the film
    /// keeps when the sample is added: its albedo and normal to `unit`
    /// (for [`RowMut::add_unit_features`]), its depth and position to 2⁻³²
    /// and within ±2³¹ ([`Sum::of_feature`]), its squared colour to 2⁻³²
    /// or exactly ([`Sum::of_square`]). A
    /// squared colour beyond what a [`Sum`] holds, or one that would take
    /// its pixel's sum past it, counts as 0.
    ///
    /// A feature's sum needs no such check: a pixel holds fewer than 2³²
    /// samples (its count is a `u32`), each feature below 2³¹, so their sum
    /// stays below 2⁶³, what a [`Sum`] holds.
    #[inline(always)]
    pub fn add_with(
        &mut self,
        x: usize,
        index: u32,
        c: Color,
        features: &Features,
        unit: &mut UnitFeatures,
    ) -> bool {
        if !self.add(x, index, c) {
            return false;
        }
        let layers = self.layers;
        if layers.meets(UNIT_LAYERS) {
            unit.add(features.albedo, features.normal);
        }
        if !layers.meets(OTHER_LAYERS) {
            return true;
        }
        let mut add_feature = |layer: Layer, v: Vec3| {
            if layers.has(layer) {
                let sum = &mut self.layer_sums[layer as usize][x];
                *sum = sum.plus(Sum::of_feature(v));
            }
        };
        add_feature(Layer::Depth, Vec3::new(features.depth, 0.0, 0.0));
        add_feature(Layer::Position, features.position);
        if layers.has(Layer::Moment) {
            let sum = &mut self.layer_sums[Layer::Moment as usize][x];
            if let Some(added) = Sum::of_square(c * c).and_then(|v| sum.checked_plus(v)) {
                *sum = added;
            }
        }
        true
    }

    /// Adds the albedos and normals of samples of pixel `x` gathered in
    /// `unit` (by [`RowMut::add_with`]) to the layers the film keeps of
    /// them.
    #[inline(always)]
    pub fn add_unit_features(&mut self, x: usize, unit: &UnitFeatures) {
        if let Some(sums) = self.unit_sums.get_mut(x) {
            // No wrap: see `UnitSums`.
            for ((sum, add), mask) in sums.iter_mut().zip(unit.0).zip(self.unit_mask) {
                *sum = sum.wrapping_add(add & mask);
            }
        }
    }
}

/// The layers [`UnitFeatures`] gathers.
const UNIT_LAYERS: Layers = Layers::of(Layer::Albedo).with(Layers::of(Layer::Normal));
/// The layers [`RowMut::add_with`] adds sample by sample.
const OTHER_LAYERS: Layers = Layers::of(Layer::Depth)
    .with(Layers::of(Layer::Position))
    .with(Layers::of(Layer::Moment));

impl Film {
    /// A black film of `width`×`height` pixels with no samples.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            sums: vec![Sum::ZERO; n],
            counts: vec![0; n],
            odd_sums: Vec::new(),
            odd_counts: Vec::new(),
            layer_sums: Default::default(),
            unit_sums: Vec::new(),
            layers: Layers::NONE,
        }
    }

    /// This film with room for the sums of `layers` (zero), or `None` if
    /// this machine's memory cannot hold them.
    pub fn try_with_layers(mut self, layers: Layers) -> Option<Self> {
        let n = self.len();
        for layer in Layer::ALL {
            let sums = &mut self.layer_sums[layer as usize];
            sums.clear();
            if layers.has(layer) && unit_offset(layer).is_none() {
                sums.try_reserve_exact(n).ok()?;
                sums.resize(n, Sum::ZERO);
            }
        }
        self.unit_sums.clear();
        if layers.meets(UNIT_LAYERS) {
            self.unit_sums.try_reserve_exact(n).ok()?;
            self.unit_sums.resize(n, [0; 6]);
        }
        self.layers = layers;
        Some(self)
    }

    /// [`Film::try_with_layers`], aborting where the memory is refused.
    pub fn with_layers(self, layers: Layers) -> Self {
        self.try_with_layers(layers)
            .expect("memory for the film's feature layers")
    }

    /// The layers of features the film keeps.
    pub fn layers(&self) -> Layers {
        self.layers
    }

    /// The sum of `layer` over pixel `i`'s samples, as its files hold it
    /// (0 if the film does not keep the layer).
    pub fn layer_sum(&self, layer: Layer, i: usize) -> Sum {
        match unit_offset(layer) {
            Some(at) => match self.unit_sums.get(i) {
                Some(sums) if self.layers.has(layer) => {
                    Sum([0, 1, 2].map(|c| unit_to_sum(sums[at + c])))
                }
                _ => Sum::ZERO,
            },
            None => self.layer_sums[layer as usize]
                .get(i)
                .copied()
                .unwrap_or(Sum::ZERO),
        }
    }

    /// This film with `sums` as the sums of `layer`; `None` if their number
    /// is not the film's pixels', or (for the albedo and normal) a sum is
    /// not one that the film's samples could have made: of multiples of
    /// 2⁻³⁰, within ±2 a sample.
    pub fn with_layer(mut self, layer: Layer, sums: Vec<Sum>) -> Option<Self> {
        let n = self.len();
        if sums.len() != n {
            return None;
        }
        match unit_offset(layer) {
            None => self.layer_sums[layer as usize] = sums,
            Some(at) => {
                if self.unit_sums.is_empty() {
                    self.unit_sums = vec![[0; 6]; n];
                }
                for ((unit, sum), &count) in self.unit_sums.iter_mut().zip(&sums).zip(&self.counts)
                {
                    for c in 0..3 {
                        unit[at + c] = sum_to_unit(sum.0[c], count)?;
                    }
                }
            }
        }
        self.layers = self.layers.with(Layers::of(layer));
        Some(self)
    }

    /// The layers the film keeps in its [`UnitSums`] (the albedo and
    /// normal), where [`RowMut::layer_sums`] holds nothing of them.
    pub const PACKED: Layers = UNIT_LAYERS;

    /// Adds `sums`, sums of `layer` (one of [`Film::PACKED`]) over a block of
    /// pixels `width` wide whose top left pixel is `origin`, of `counts`
    /// samples each, to this film's (which keeps the layer). An error
    /// names the block's first pixel, `(x, y)` within it, whose sum is not
    /// one samples could have made (see [`Film::with_layer`]) or would
    /// pass what a sum holds, and which; the film is then left with some
    /// of the block added (a merge that meets it gives up).
    pub fn add_packed_layer(
        &mut self,
        layer: Layer,
        (origin, width): ((usize, usize), usize),
        sums: &[Sum],
        counts: &[u32],
    ) -> Result<(), (usize, usize, PackedError)> {
        let at = unit_offset(layer).expect("a layer the film packs");
        let film_width = self.width as usize;
        for (i, (sum, &count)) in sums.iter().zip(counts).enumerate() {
            let (x, y) = (i % width.max(1), i / width.max(1));
            let unit = &mut self.unit_sums[(origin.1 + y) * film_width + origin.0 + x];
            for c in 0..3 {
                let v = sum_to_unit(sum.0[c], count).ok_or((x, y, PackedError::NotSamples))?;
                unit[at + c] = unit[at + c]
                    .checked_add(v)
                    .ok_or((x, y, PackedError::Overflow))?;
            }
        }
        Ok(())
    }

    /// The mean of `layer` over pixel `i`'s samples (0 without samples or
    /// without the layer).
    pub fn feature(&self, layer: Layer, i: usize) -> Vec3 {
        if !self.layers.has(layer) || i >= self.len() {
            return Vec3::ZERO;
        }
        feature_mean(self.layer_sum(layer, i), self.counts[i])
    }

    /// The variance of pixel `i`'s estimate, per channel: the unbiased
    /// variance of its samples divided by their number, from the sum of
    /// their squares (0 with fewer than two samples or without
    /// [`Layer::Moment`]).
    pub fn variance(&self, i: usize) -> Color {
        let (Some(moment), n) = (
            self.layer_sums[Layer::Moment as usize].get(i),
            self.counts[i],
        ) else {
            return Color::ZERO;
        };
        if n < 2 {
            return Color::ZERO;
        }
        let n = f64::from(n);
        let (sum, squares) = (self.sums[i].to_f64(), moment.to_f64());
        let v = |c: usize| {
            let m = sum[c] / n;
            ((squares[c] / n - m * m).max(0.0) / (n - 1.0)) as f32
        };
        Color::new(v(0), v(1), v(2))
    }

    /// The number of samples pixel `i` holds.
    pub fn count(&self, i: usize) -> u32 {
        self.counts[i]
    }

    /// [`Film::new`], or `None` if this machine's memory cannot hold it.
    pub fn try_new(width: u32, height: u32) -> Option<Self> {
        let n = width as usize * height as usize;
        let (mut sums, mut counts) = (Vec::new(), Vec::new());
        sums.try_reserve_exact(n).ok()?;
        counts.try_reserve_exact(n).ok()?;
        sums.resize(n, Sum::ZERO);
        counts.resize(n, 0);
        Self::from_raw(width, height, sums, counts)
    }

    /// Bytes of a `width`×`height` film, with `halves` if it keeps them
    /// ([`Film::with_halves`]): 52 a pixel, 104 with the halves.
    pub fn bytes(width: u32, height: u32, halves: bool) -> u64 {
        let per_pixel = (std::mem::size_of::<Sum>() + std::mem::size_of::<u32>()) as u64;
        u64::from(width) * u64::from(height) * per_pixel * if halves { 2 } else { 1 }
    }

    /// Bytes of the sums of `layers` in a `width`×`height` film: 48 a pixel
    /// a layer, and 48 for the albedo and normal together.
    pub fn layer_bytes(width: u32, height: u32, layers: Layers) -> u64 {
        let kept = Layer::ALL
            .iter()
            .filter(|&&l| layers.has(l) && unit_offset(l).is_none())
            .count()
            + usize::from(layers.meets(UNIT_LAYERS));
        u64::from(width) * u64::from(height) * kept as u64 * std::mem::size_of::<Sum>() as u64
    }

    /// [`Film::with_halves`], or `None` if this machine's memory cannot
    /// hold it.
    pub fn try_with_halves(width: u32, height: u32) -> Option<Self> {
        let whole = Self::try_new(width, height)?;
        let n = whole.len();
        let (mut odd_sums, mut odd_counts) = (Vec::new(), Vec::new());
        odd_sums.try_reserve_exact(n).ok()?;
        odd_counts.try_reserve_exact(n).ok()?;
        odd_sums.resize(n, Sum::ZERO);
        odd_counts.resize(n, 0);
        Some(Self {
            odd_sums,
            odd_counts,
            ..whole
        })
    }

    /// A black film that also keeps the sums of each pixel's samples of odd
    /// index, for adaptive sampling's error estimate ([`Film::halves`]).
    pub fn with_halves(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            odd_sums: vec![Sum::ZERO; n],
            odd_counts: vec![0; n],
            ..Self::new(width, height)
        }
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Mutable access to the rows, for parallel rendering.
    pub fn rows_mut(&mut self) -> impl rayon::iter::IndexedParallelIterator<Item = RowMut<'_>> {
        let w = (self.width as usize).max(1);
        let layers = self.layers();
        // What only some films keep, row by row (empty slices elsewhere).
        type Kept<'a> = (
            &'a mut [Sum],
            &'a mut [u32],
            [&'a mut [Sum]; LAYERS],
            &'a mut [UnitSums],
        );
        let mut kept: Vec<Kept> = (0..self.sums.len() / w)
            .map(|_| (&mut [][..], &mut [][..], Default::default(), &mut [][..]))
            .collect();
        let halves = self
            .odd_sums
            .chunks_mut(w)
            .zip(self.odd_counts.chunks_mut(w));
        for (row, (sums, counts)) in kept.iter_mut().zip(halves) {
            (row.0, row.1) = (sums, counts);
        }
        for (l, sums) in self.layer_sums.iter_mut().enumerate() {
            for (row, sums) in kept.iter_mut().zip(sums.chunks_mut(w)) {
                row.2[l] = sums;
            }
        }
        for (row, sums) in kept.iter_mut().zip(self.unit_sums.chunks_mut(w)) {
            row.3 = sums;
        }
        let mut unit_mask = [0; 6];
        for layer in [Layer::Albedo, Layer::Normal] {
            if let (Some(at), true) = (unit_offset(layer), layers.has(layer)) {
                unit_mask[at..at + 3].fill(-1);
            }
        }
        self.sums
            .par_chunks_mut(w)
            .zip(self.counts.par_chunks_mut(w))
            .zip(kept)
            .map(
                move |((sums, counts), (odd_sums, odd_counts, layer_sums, unit_sums))| RowMut {
                    sums,
                    counts,
                    odd_sums,
                    odd_counts,
                    layer_sums,
                    unit_sums,
                    unit_mask,
                    layers,
                },
            )
    }

    /// Adds the samples of `other`, a film of the same size: its pixels'
    /// sums and counts are added to this film's (exactly, see [`Sum`]),
    /// and so are the sums of its feature layers. `false`, and nothing
    /// added, if the sizes or the layers differ, either film keeps the
    /// halves of adaptive sampling, or a pixel's sum or count would pass
    /// what it holds.
    pub fn add_film(&mut self, other: &Film) -> bool {
        if (self.width, self.height) != (other.width, other.height)
            || self.has_halves()
            || other.has_halves()
            || self.layers() != other.layers()
        {
            return false;
        }
        let added: Option<Vec<(Sum, u32)>> = (self.sums.iter().zip(&other.sums))
            .zip(self.counts.iter().zip(&other.counts))
            .map(|((a, b), (m, n))| Some((a.checked_plus(*b)?, m.checked_add(*n)?)))
            .collect();
        let Some(added) = added else {
            return false;
        };
        for (i, (sum, count)) in added.into_iter().enumerate() {
            self.sums[i] = sum;
            self.counts[i] = count;
        }
        // A feature that would pass what a sum holds counts as 0, as when
        // it is rendered.
        for (mine, theirs) in self.layer_sums.iter_mut().zip(&other.layer_sums) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                if let Some(sum) = a.checked_plus(*b) {
                    *a = sum;
                }
            }
        }
        // Within a sum's bounds: the counts were added without passing
        // what they hold (see `UnitSums`).
        for (a, b) in self.unit_sums.iter_mut().zip(&other.unit_sums) {
            for (a, b) in a.iter_mut().zip(b) {
                *a = a.wrapping_add(*b);
            }
        }
        true
    }

    /// Whether the film keeps the sums of the samples of odd index.
    pub fn has_halves(&self) -> bool {
        !self.odd_counts.is_empty()
    }

    /// Makes this film a copy of `other` (of the same size) without
    /// allocating: a pass keeps the film it started from this way.
    pub fn copy_from(&mut self, other: &Film) {
        self.width = other.width;
        self.height = other.height;
        copy_vec(&mut self.sums, &other.sums);
        copy_vec(&mut self.counts, &other.counts);
        copy_vec(&mut self.odd_sums, &other.odd_sums);
        copy_vec(&mut self.odd_counts, &other.odd_counts);
        for (mine, theirs) in self.layer_sums.iter_mut().zip(&other.layer_sums) {
            copy_vec(mine, theirs);
        }
        copy_vec(&mut self.unit_sums, &other.unit_sums);
        self.layers = other.layers;
    }

    /// The raw per-pixel sums and counts (for checkpoints).
    pub fn raw(&self) -> (&[Sum], &[u32]) {
        (&self.sums, &self.counts)
    }

    /// The raw per-pixel sums and counts of the samples of odd index (empty
    /// in a film without halves).
    pub fn raw_odd(&self) -> (&[Sum], &[u32]) {
        (&self.odd_sums, &self.odd_counts)
    }

    /// Rebuilds a film from raw sums and counts, with no record of which
    /// samples had odd indices; `None` if the sizes disagree.
    pub fn from_raw(width: u32, height: u32, sums: Vec<Sum>, counts: Vec<u32>) -> Option<Self> {
        let n = width as usize * height as usize;
        (sums.len() == n && counts.len() == n).then_some(Self {
            width,
            height,
            sums,
            counts,
            odd_sums: Vec::new(),
            odd_counts: Vec::new(),
            layer_sums: Default::default(),
            unit_sums: Vec::new(),
            layers: Layers::NONE,
        })
    }

    /// This film with the sums and counts of its samples of odd index;
    /// `None` if their sizes disagree with the film's or an odd count
    /// exceeds its pixel's count.
    pub fn with_odd(self, odd_sums: Vec<Sum>, odd_counts: Vec<u32>) -> Option<Self> {
        let n = self.sums.len();
        let fits = odd_sums.len() == n
            && odd_counts.len() == n
            && odd_counts.iter().zip(&self.counts).all(|(o, c)| o <= c);
        fits.then_some(Self {
            odd_sums,
            odd_counts,
            ..self
        })
    }

    /// The two half estimates of pixel `i` (row-major): the mean of its
    /// samples of even index and of odd index, if the film keeps them and
    /// each half has a sample.
    pub fn halves(&self, i: usize) -> Option<(Color, Color)> {
        let (n, odd) = (self.counts[i], *self.odd_counts.get(i)?);
        if odd == 0 || odd == n {
            return None;
        }
        let even_sum = self.sums[i].minus(self.odd_sums[i]);
        Some((mean(even_sum, n - odd), mean(self.odd_sums[i], odd)))
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.sums.len()
    }

    /// Whether the film has no pixels.
    pub fn is_empty(&self) -> bool {
        self.sums.is_empty()
    }

    /// The mean linear colour of pixel `i` (row-major); black if it has no samples.
    pub fn mean(&self, i: usize) -> Color {
        mean(self.sums[i], self.counts[i])
    }

    /// The mean linear colour of pixel `(x, y)`; black if it has no samples.
    pub fn pixel(&self, x: u32, y: u32) -> Color {
        let i = y as usize * self.width as usize + x as usize;
        mean(self.sums[i], self.counts[i])
    }

    /// All pixels' mean linear colours, row-major, top row first (on all
    /// threads).
    pub fn linear(&self) -> Vec<Color> {
        (0..self.len())
            .into_par_iter()
            .map(|i| self.mean(i))
            .collect()
    }

    /// 8-bit bytes, three a pixel: ⌊256·clamp(v, 0, 0.999)⌋ of the display value.
    /// Computed pixel by pixel, with no full-size intermediate image.
    pub fn to_rgb8(&self, gamma: f32) -> Vec<u8> {
        rgb8(self.pixels(), self.sums.len(), gamma)
    }

    /// The mean linear colour of every pixel, row-major, top row first.
    pub fn pixels(&self) -> impl Iterator<Item = Color> + '_ {
        self.sums
            .iter()
            .zip(&self.counts)
            .map(|(&s, &n)| mean(s, n))
    }
}

/// 8-bit bytes of `n` linear colours, as [`Film::to_rgb8`] makes them.
pub fn rgb8(colors: impl Iterator<Item = Color>, n: usize, gamma: f32) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(n * 3);
    for c in colors {
        for v in [c.x, c.y, c.z] {
            bytes.push((256.0 * to_display(v, gamma).clamp(0.0, 0.999)) as u8);
        }
    }
    bytes
}

/// The mean of `n` samples summing to `sum`; black if there are none.
#[inline]
fn mean(sum: Sum, n: u32) -> Color {
    if n == 0 {
        return Color::ZERO;
    }
    let n = f64::from(n);
    let [r, g, b] = sum.to_f64();
    Color::new((r / n) as f32, (g / n) as f32, (b / n) as f32)
}

/// [`mean`] of a feature's sum, the same to the bit, in fewer steps where
/// each channel is a multiple of 2⁻³² below 2³¹ in magnitude, as a
/// feature's are (see [`Sum::of_feature`], [`UnitFeatures`]): its value
/// in 2⁻³² then fits 64 bits, whose conversion to `f64` rounds the same
/// significant bits as the 128-bit one.
fn feature_mean(sum: Sum, n: u32) -> Color {
    let narrow = |v: i128| match i64::try_from(v >> 32) {
        Ok(w) if v & 0xffff_ffff == 0 => Some(w),
        _ => None,
    };
    match sum.0.map(narrow) {
        [Some(x), Some(y), Some(z)] if n > 0 => {
            let n = f64::from(n);
            let f = |v: i64| (v as f64 * (1.0 / TWO_32) / n) as f32;
            Color::new(f(x), f(y), f(z))
        }
        _ => mean(sum, n),
    }
}

/// Applies the display gamma (v^(1/γ)) and tone-maps by clamping to [0, 1].
#[inline]
pub fn to_display(linear: f32, gamma: f32) -> f32 {
    let v = linear.max(0.0);
    // Gamma 2 (the notes' choice, and the default) is a square root: exact,
    // and several times cheaper than `powf` when saving large images.
    let v = if gamma == 1.0 {
        v
    } else if gamma == 2.0 {
        v.sqrt()
    } else {
        v.powf(1.0 / gamma)
    };
    v.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel's sum of `layer`.
    fn layer_of(film: &Film, layer: Layer) -> Vec<Sum> {
        (0..film.len()).map(|i| film.layer_sum(layer, i)).collect()
    }

    /// The albedos' and the normals' sums `unit` gathered, as [`Sum`]s.
    fn sums_of(unit: &UnitFeatures) -> [Sum; 2] {
        let wide = |c: usize| unit_to_sum(unit.0[c]);
        [
            Sum([wide(0), wide(1), wide(2)]),
            Sum([wide(3), wide(4), wide(5)]),
        ]
    }

    #[test]
    fn sums_convert_to_f64_as_the_compiler_converts() {
        let mut edges = vec![0i128, 1, -1, i128::MAX, i128::MIN, i128::MIN + 1];
        for bit in 0..127 {
            let p = 1i128 << bit;
            // Powers of two, their neighbours, and halfway cases of the
            // rounding to 53 bits, odd and even.
            edges.extend([p, p - 1, p + 1, -p, 1 - p, -p - 1]);
            if bit > 53 {
                let half = 1i128 << (bit - 53);
                edges.extend([p + half, p + 3 * half, p + half + 1, p + half - 1]);
            }
        }
        for v in edges {
            assert_eq!(i128_to_f64(v).to_bits(), (v as f64).to_bits(), "{v}");
        }
        let word = |i: u64| crate::rng::mix64(i);
        for i in 0..200_000u64 {
            // A random value of a random length.
            let length = (word(4 * i) % 128) as u32;
            let wide = u128::from(word(4 * i + 1)) << 64 | u128::from(word(4 * i + 2));
            let v = (wide >> (128 - length.max(1))) as i128;
            let v = if word(4 * i + 3) % 2 == 0 { v } else { -v };
            assert_eq!(i128_to_f64(v).to_bits(), (v as f64).to_bits(), "{v}");
        }
    }

    /// `n` floats from their bits, spread over every exponent and sign.
    fn spread_floats(n: u64) -> impl Iterator<Item = f32> {
        (0..n).map(|k| f32::from_bits(crate::rng::mix64(k) as u32))
    }

    #[test]
    fn albedos_and_normals_round_to_two_to_the_minus_30() {
        for v in spread_floats(100_000) {
            let (x, y) = (f64::from(v), f64::from(v * 0.5));
            if x.abs() > 2.0 || y.abs() > 2.0 || x.is_nan() {
                continue;
            }
            let mut unit = UnitFeatures::default();
            unit.add(Color::new(v, 0.0, -v), Vec3::new(v * 0.5, 1.0, 0.0));
            let to_unit = |x: f64| {
                Sum::of([
                    (x * 1_073_741_824.0).round_ties_even() / 1_073_741_824.0,
                    0.0,
                    0.0,
                ])
                .unwrap()
                .0[0]
            };
            let [albedo, normal] = sums_of(&unit);
            assert_eq!(albedo.0, [to_unit(x), 0, to_unit(-x)], "{v:e}");
            assert_eq!(normal.0, [to_unit(y), 1 << 64, 0], "{v:e}");
        }
    }

    #[test]
    fn albedos_and_normals_beyond_two_or_nan_count_as_zero() {
        let mut unit = UnitFeatures::default();
        let odd = [f32::NAN, f32::INFINITY, -2.5, 1e30];
        unit.add(
            Color::new(odd[0], odd[1], 2.0),
            Vec3::new(odd[2], odd[3], -2.0),
        );
        let [albedo, normal] = sums_of(&unit);
        assert_eq!(albedo.0, [0, 0, 2 << 64]);
        assert_eq!(normal.0, [0, 0, -2 << 64]);
    }

    #[test]
    fn a_square_is_rounded_to_two_to_the_minus_32_below_two_to_the_19_and_exact_above() {
        let mut values = vec![
            0.0f32, -0.0, 1.0, 0.3, 1e-30, 524_287.97, 524_288.0, 1e19, 3e38,
        ];
        // Squares of every size from 2⁻⁴¹ to about 2³⁹.
        values.extend(
            (0..100_000u64)
                .map(|k| f32::from_bits(0x2b00_0000 + crate::rng::mix64(k) as u32 % 0x2800_0000)),
        );
        for v in values {
            let got = Sum::of_square(Color::new(v, 0.25, 0.0));
            if v < 524_288.0 {
                let rounded = (f64::from(v) * TWO_32).round_ties_even() / TWO_32;
                assert_eq!(got, Sum::of([rounded, 0.25, 0.0]), "{v:e}");
            } else {
                assert_eq!(got, Sum::of_color(Color::new(v, 0.25, 0.0)), "{v:e}");
            }
        }
        assert_eq!(Sum::of_square(Color::new(f32::NAN, 0.0, 0.0)), None);
        assert_eq!(Sum::of_square(Color::new(0.0, f32::INFINITY, 0.0)), None);
    }

    /// The albedo and normal, kept packed, read and write as the other
    /// layers do (as `Sum`s), and a sum no samples could have made is
    /// refused rather than kept.
    #[test]
    fn packed_albedos_and_normals_read_as_sums_and_refuse_what_samples_cannot_make() {
        let mut film = Film::new(3, 2).with_layers(UNIT_LAYERS.with(Layers::of(Layer::Depth)));
        let features = |i: usize| Features {
            albedo: Color::new(0.25 * i as f32, 1.0, 0.1),
            normal: Vec3::new(-0.6, 0.0, 0.8),
            depth: i as f32,
            ..Features::default()
        };
        for (y, mut row) in film.rows_mut().collect::<Vec<_>>().into_iter().enumerate() {
            for x in 0..3 {
                let mut unit = UnitFeatures::default();
                for index in 0..3 {
                    let f = features(y * 3 + x);
                    assert!(row.add_with(x, index, Color::ONE, &f, &mut unit));
                }
                row.add_unit_features(x, &unit);
            }
        }
        // What a sum of the layer gives, to the bit: as a `Sum` of the
        // rounded values.
        for i in 0..6 {
            let f = features(i);
            let rounded = |v: f32| (3 * round_to_integer(f64::from(v) * UNIT) as i128) << 34;
            let want = |v: Vec3| Sum([rounded(v.x), rounded(v.y), rounded(v.z)]);
            assert_eq!(film.layer_sum(Layer::Albedo, i), want(f.albedo));
            assert_eq!(film.layer_sum(Layer::Normal, i), want(f.normal));
            assert_eq!(
                film.feature(Layer::Albedo, i),
                feature_mean(want(f.albedo), 3)
            );
        }
        // Rebuilt from those sums, the film is the same.
        let (sums, counts) = film.raw();
        let mut rebuilt = Film::from_raw(3, 2, sums.to_vec(), counts.to_vec()).unwrap();
        for layer in [Layer::Albedo, Layer::Normal, Layer::Depth] {
            let sums = layer_of(&film, layer);
            rebuilt = rebuilt.with_layer(layer, sums).unwrap();
        }
        assert_eq!(rebuilt, film);
        // Not a multiple of 2⁻³⁰, or beyond 2 a sample: refused.
        let bare = || Film::from_raw(3, 2, sums.to_vec(), counts.to_vec()).unwrap();
        let two_each = (3i128 * 2) << 30 << 34;
        for bad in [
            Sum([1, 0, 0]),
            Sum([0, two_each + (1 << 34), 0]),
            Sum([0, 0, -two_each - (1 << 34)]),
        ] {
            let mut layer = layer_of(&film, Layer::Normal);
            layer[4] = bad;
            assert!(bare().with_layer(Layer::Normal, layer).is_none(), "{bad:?}");
        }
        let mut at_most = layer_of(&film, Layer::Normal);
        at_most[4] = Sum([two_each, -two_each, 0]);
        assert!(bare().with_layer(Layer::Normal, at_most).is_some());
    }

    /// A block of a layer's sums (a tile of a part) adds at its place; a
    /// sum no samples could have made is named by its place in the block.
    #[test]
    fn packed_blocks_add_at_their_place_and_name_a_bad_pixel() {
        let layers = UNIT_LAYERS;
        let mut film = Film::new(4, 3).with_layers(layers);
        let one = 1i128 << 30 << 34;
        let block = vec![Sum([one, 2 * one, -one]); 4];
        film.add_packed_layer(Layer::Normal, ((1, 1), 2), &block, &[2; 4])
            .unwrap();
        for i in 0..12 {
            let inside = (1..3).contains(&(i % 4)) && (1..3).contains(&(i / 4));
            let want = if inside { block[0] } else { Sum::ZERO };
            assert_eq!(film.layer_sum(Layer::Normal, i), want, "{i}");
            assert_eq!(film.layer_sum(Layer::Albedo, i), Sum::ZERO);
        }
        let mut bad = block.clone();
        bad[3] = Sum([3 * one, 0, 0]);
        let e = film.add_packed_layer(Layer::Albedo, ((1, 1), 2), &bad, &[1; 4]);
        assert_eq!(e, Err((1, 1, PackedError::NotSamples)));
    }

    #[test]
    fn a_feature_mean_equals_the_mean_to_the_bit() {
        for k in 0..200_000u64 {
            // Multiples of 2⁻³² of every size up to 2³¹ and a little
            // beyond, and some that are not multiples.
            let bits = crate::rng::mix64(2 * k);
            let magnitude = (bits >> (k % 64)) as i128;
            let v = if k % 2 == 0 { magnitude } else { -magnitude };
            let v = if k % 7 == 0 { v } else { v << 32 };
            let sum = Sum([v, v >> 3, -v]);
            let n = (crate::rng::mix64(2 * k + 1) % 100_000) as u32;
            let (fast, exact) = (feature_mean(sum, n), mean(sum, n));
            assert_eq!(
                fast.to_array().map(f32::to_bits),
                exact.to_array().map(f32::to_bits),
                "{sum:?} over {n}"
            );
        }
    }

    #[test]
    fn a_colour_converts_from_its_bits_as_through_f64() {
        let mut values = vec![
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-13,
            4.5e-13,
            5.4e-20,
            1e-30,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            f32::from_bits(0x7f_ffff),
            9.2e18,
            -9.2e18,
            f32::from_bits(0x5eff_ffff), // the largest below 2^63
            f32::from_bits(0x5f00_0000), // 2^63
            1e19,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        // And a spread of every exponent, both signs.
        let mut x = 0x9e37_79b9u32;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            values.push(f32::from_bits(x));
        }
        for v in values {
            let through_f64 = Sum::of([f64::from(v); 3]);
            assert_eq!(
                Sum::of_color(Color::splat(v)),
                through_f64,
                "{v:e} ({:#x})",
                v.to_bits()
            );
        }
    }
}
