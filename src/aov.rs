//! Feature buffers (AOVs, "arbitrary output variables"): what a render can
//! write beside its image for a denoiser, a compositor or an error map.
//!
//! As Open Image Denoise defines its auxiliary images:
//! - **albedo**: the colour of the first surface a camera path meets that is
//!   not a perfect mirror or clear glass, independent of the light. Such
//!   delta surfaces are followed, their tint (the sample's weight) carried
//!   on, and so are near mirrors: microfacets no wider than
//!   [`NEAR_MIRROR_ALPHA`](crate::bsdf::microfacet::NEAR_MIRROR_ALPHA), or
//!   layered surfaces that reflect three quarters of their light or more
//!   by such layers (Blender Cycles' rule). The albedo is then the lobe's
//!   own colour (see
//!   [`Lobe::feature_albedo_seen`](crate::bsdf::Lobe::feature_albedo_seen)),
//!   times that tint, clamped to [0, 1]. A path that escapes takes the sky's
//!   colour (clamped); one that meets a light without a surface, or
//!   scatters in a medium before any surface, the tint (white where there
//!   was none).
//! - **normal**: that surface's shading normal, in world space, unit
//!   length, turned towards the side the camera path came from (0 where
//!   the path escaped).
//! - **depth** and **position**: the first visible surface the camera ray
//!   meets (invisible interfaces are passed): its distance from the ray's
//!   origin on the lens, and its point in world space (0 where it meets
//!   none).
//! - **variance**: per channel, the variance of the pixel's estimate (the
//!   samples' unbiased variance divided by their number), from a sum of
//!   the squared samples.
//! - **spp**: the samples the pixel holds.
//!
//! Each is averaged over the pixel's samples, the beauty's own, so it is
//! filtered as the image is; its sums are fixed-point like the image's
//! ([`crate::film::Sum`]; the albedo and normal to 2⁻³⁰ in 64 bits, see
//! [`UnitFeatures`](crate::film::UnitFeatures) and
//! [`UnitSums`](crate::film::UnitSums), the depth and position to
//! 2⁻³² within ±2³¹, see
//! [`Sum::of_feature`](crate::film::Sum::of_feature)), so an image split
//! into passes, threads, parts or resumed runs has bit-identical features.

use crate::math::{Color, Vec3};

/// A feature buffer a render can write.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// See the module's documentation.
    Albedo,
    /// See the module's documentation.
    Normal,
    /// See the module's documentation.
    Depth,
    /// See the module's documentation.
    Position,
    /// See the module's documentation.
    Variance,
    /// See the module's documentation.
    Spp,
}

impl Aov {
    /// Every feature, in the order layers are written.
    pub const ALL: [Aov; 6] = [
        Aov::Albedo,
        Aov::Normal,
        Aov::Depth,
        Aov::Position,
        Aov::Variance,
        Aov::Spp,
    ];

    /// Its name: on the command line, in scene files, and as the layer's
    /// name in an EXR file.
    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Position => "position",
            Aov::Variance => "variance",
            Aov::Spp => "spp",
        }
    }

    /// Its channels' names within its layer.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo | Aov::Variance => &["R", "G", "B"],
            Aov::Normal | Aov::Position => &["X", "Y", "Z"],
            Aov::Depth => &["Z"],
            Aov::Spp => &["Y"],
        }
    }

    /// The feature named `name`, or an error listing the valid names.
    pub fn parse(name: &str) -> Result<Aov, String> {
        Aov::ALL
            .into_iter()
            .find(|a| a.name() == name)
            .ok_or_else(|| format!("unknown AOV `{name}`; the AOVs are {}", names()))
    }

    /// The features of a comma-separated list (`albedo,normal`), each
    /// once, in [`Aov::ALL`]'s order.
    pub fn parse_list(list: &str) -> Result<Vec<Aov>, String> {
        let mut aovs = list
            .split(',')
            .map(|n| Aov::parse(n.trim()))
            .collect::<Result<Vec<_>, _>>()?;
        aovs.sort();
        aovs.dedup();
        Ok(aovs)
    }

    /// The sums a film keeps for it.
    pub fn layers(self) -> Layers {
        match self {
            Aov::Albedo => Layers::of(Layer::Albedo),
            Aov::Normal => Layers::of(Layer::Normal),
            Aov::Depth => Layers::of(Layer::Depth),
            Aov::Position => Layers::of(Layer::Position),
            Aov::Variance => Layers::of(Layer::Moment),
            // The film's counts.
            Aov::Spp => Layers::NONE,
        }
    }
}

/// Every feature's name, for messages.
pub fn names() -> String {
    Aov::ALL.map(Aov::name).join(", ")
}

/// A per-sample sum a film can keep beside the image's (see
/// [`crate::film::Film::with_layers`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layer {
    /// The sample's [`Features::albedo`].
    Albedo,
    /// The sample's [`Features::normal`].
    Normal,
    /// The sample's [`Features::depth`] (in the first channel).
    Depth,
    /// The sample's [`Features::position`].
    Position,
    /// The sample's colour squared, channel by channel.
    Moment,
}

/// How many kinds of [`Layer`] there are.
pub const LAYERS: usize = 5;

impl Layer {
    /// Its name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Albedo => "albedo",
            Layer::Normal => "normal",
            Layer::Depth => "depth",
            Layer::Position => "position",
            Layer::Moment => "squared-colour",
        }
    }

    /// Every layer, in the order a film and a checkpoint hold them.
    pub const ALL: [Layer; LAYERS] = [
        Layer::Albedo,
        Layer::Normal,
        Layer::Depth,
        Layer::Position,
        Layer::Moment,
    ];
}

/// A set of [`Layer`]s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Layers(u8);

impl Layers {
    /// No layer.
    pub const NONE: Layers = Layers(0);

    /// The one layer `layer`.
    pub const fn of(layer: Layer) -> Layers {
        Layers(1 << layer as u8)
    }

    /// The layers the features `aovs` need.
    pub fn for_aovs(aovs: &[Aov]) -> Layers {
        aovs.iter()
            .fold(Layers::NONE, |all, a| all.with(a.layers()))
    }

    /// These and `other`.
    pub const fn with(self, other: Layers) -> Layers {
        Layers(self.0 | other.0)
    }

    /// Whether `layer` is one of them.
    #[inline(always)]
    pub const fn has(self, layer: Layer) -> bool {
        self.0 & (1 << layer as u8) != 0
    }

    /// Whether any of `other` is one of them.
    #[inline(always)]
    pub const fn meets(self, other: Layers) -> bool {
        self.0 & other.0 != 0
    }

    /// Whether there are none.
    #[inline(always)]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether a path needs to find its features (any layer but the
    /// moment, which the colour gives).
    #[inline(always)]
    pub const fn need_features(self) -> bool {
        self.0 & !(1 << Layer::Moment as u8) != 0
    }

    /// The set as a byte (for checkpoints).
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// The set a byte written by [`Layers::bits`] names, if it names one.
    pub fn from_bits(bits: u8) -> Option<Layers> {
        (bits >> LAYERS == 0).then_some(Layers(bits))
    }
}

/// What one camera path found for the feature buffers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Features {
    /// See the module's documentation.
    pub albedo: Color,
    /// See the module's documentation.
    pub normal: Vec3,
    /// See the module's documentation.
    pub position: Vec3,
    /// See the module's documentation.
    pub depth: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_unknown_ones_list_the_valid() {
        for a in Aov::ALL {
            assert_eq!(Aov::parse(a.name()), Ok(a));
        }
        assert_eq!(
            Aov::parse_list("spp, albedo,normal,albedo"),
            Ok(vec![Aov::Albedo, Aov::Normal, Aov::Spp])
        );
        let e = Aov::parse_list("albedo,normals").unwrap_err();
        assert_eq!(
            e,
            "unknown AOV `normals`; the AOVs are albedo, normal, depth, position, variance, spp"
        );
        assert!(Aov::parse_list("").is_err());
    }

    #[test]
    fn layers_are_those_the_features_need() {
        let l = Layers::for_aovs(&[Aov::Albedo, Aov::Variance, Aov::Spp]);
        assert!(l.has(Layer::Albedo) && l.has(Layer::Moment));
        assert!(!l.has(Layer::Normal) && !l.has(Layer::Depth));
        assert!(l.need_features());
        assert!(!Layers::for_aovs(&[Aov::Variance]).need_features());
        assert!(Layers::for_aovs(&[Aov::Spp]).is_empty());
        assert_eq!(Layers::from_bits(l.bits()), Some(l));
        assert_eq!(Layers::from_bits(1 << LAYERS), None);
    }
}
