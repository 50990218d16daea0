//! How a surface scatters light at one point: a [`Bsdf`] is a shading
//! [`Frame`] and one [`Lobe`] (a closed enum, dispatched with `match`), made by
//! a [`Material`](crate::material::Material) where a ray hits it.
//!
//! Every lobe answers three questions, in the surface's local frame (z along
//! the shading normal, on the side the ray came from; `wo` points away from
//! the surface, back along the ray, and so does `wi`, towards the light):
//!
//! - `sample(wo, …)`: a direction `wi` drawn with density `pdf`, and the
//!   *value* f(wo, wi)·|cos θi| / pdf that a path's throughput is multiplied
//!   by ([`BsdfSample`]);
//! - `eval(wo, wi)`: f(wo, wi)·|cos θi|, the light scattered towards `wo` per
//!   unit light arriving from `wi`;
//! - `pdf(wo, wi)`: the density (per unit solid angle) with which `sample`
//!   draws `wi`.
//!
//! [`Bsdf`] turns world directions into local ones and back, and keeps a
//! lobe's reflection and transmission on the sides of the true (geometric)
//! surface that they belong to.
//!
//! The notes' lobes ([`diffuse`], [`metal`], [`dielectric`]) scatter around
//! the shading normal in world space exactly as the book does, so that its
//! figures keep their bits; the fuzzy metal and the bounce models other than
//! the Lambertian have no density written down and are sampled only.

pub mod albedo;
pub mod coat;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod metal;
pub mod microfacet;
pub mod plastic;
pub mod principled;
pub mod sheen;
#[cfg(test)]
mod tests;
pub mod thin_dielectric;

use crate::math::{Color, Vec3};
use crate::sampler::{Dim, Sampler};
use microfacet::Microfacet;

/// An orthonormal frame: tangent `t`, bitangent `b` and normal `n`, with
/// `t × b = n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The tangent (x in the local frame).
    pub t: Vec3,
    /// The bitangent (y).
    pub b: Vec3,
    /// The normal (z).
    pub n: Vec3,
}

impl Frame {
    /// Some frame around unit `n` (for a lobe that is the same whichever
    /// way round the normal it is turned).
    #[inline]
    pub fn from_normal(n: Vec3) -> Frame {
        let (t, b) = n.any_orthonormal_pair();
        Frame { t, b, n }
    }

    /// A frame of which only the normal `n` is known, for the notes'
    /// lobes, which scatter about the normal in world space and never turn
    /// a direction into local coordinates (its tangents are zero).
    #[inline(always)]
    pub fn normal_only(n: Vec3) -> Frame {
        Frame {
            t: Vec3::ZERO,
            b: Vec3::ZERO,
            n,
        }
    }

    /// The frame around unit `n` whose tangent is `tangent` made
    /// perpendicular to it (Gram–Schmidt); [`Frame::from_normal`] when
    /// `tangent` is zero or along `n`.
    #[inline]
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Frame {
        // A normal a little off unit length (a sphere's (p − c)/r at a
        // rounded point) would make every direction turned through the
        // frame a little longer or shorter, and paths compound it.
        let n = n.normalize();
        let t = (tangent - n * n.dot(tangent)).normalize_or_zero();
        if t == Vec3::ZERO {
            return Frame::from_normal(n);
        }
        Frame {
            t,
            b: n.cross(t),
            n,
        }
    }

    /// `v` in this frame's coordinates.
    #[inline(always)]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    /// The world vector whose coordinates in this frame are `v`.
    #[inline(always)]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// What kind of scattering a sample or a lobe does: reflection or
/// transmission, and diffuse, glossy or specular (a single direction, which
/// no light sample can find).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LobeFlags(u8);

impl LobeFlags {
    /// Back to the side the light came from.
    pub const REFLECTION: LobeFlags = LobeFlags(1);
    /// Through to the other side.
    pub const TRANSMISSION: LobeFlags = LobeFlags(2);
    /// Spread over the hemisphere.
    pub const DIFFUSE: LobeFlags = LobeFlags(4);
    /// Spread about a direction.
    pub const GLOSSY: LobeFlags = LobeFlags(8);
    /// Along a single direction (a delta distribution).
    pub const SPECULAR: LobeFlags = LobeFlags(16);
    /// Transmission that leaves the direction as it was (a thin sheet's):
    /// in a scene with media, a crossing rather than a bounce.
    pub const STRAIGHT: LobeFlags = LobeFlags(32);

    /// Both sets of flags.
    #[inline(always)]
    pub const fn union(self, other: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 | other.0)
    }

    /// Whether every flag of `other` is set.
    #[inline(always)]
    pub const fn contains(self, other: LobeFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether the sample or lobe is a delta (a mirror's, clear glass's).
    #[inline(always)]
    pub const fn is_specular(self) -> bool {
        self.contains(LobeFlags::SPECULAR)
    }

    /// Whether it goes through the surface.
    #[inline(always)]
    pub const fn is_transmission(self) -> bool {
        self.contains(LobeFlags::TRANSMISSION)
    }

    /// Whether some of it is spread out (diffuse or glossy), which a light
    /// sample can find.
    #[inline(always)]
    pub const fn is_spread(self) -> bool {
        self.0 & (LobeFlags::DIFFUSE.0 | LobeFlags::GLOSSY.0) != 0
    }
}

impl std::ops::BitOr for LobeFlags {
    type Output = LobeFlags;
    #[inline(always)]
    fn bitor(self, other: LobeFlags) -> LobeFlags {
        self.union(other)
    }
}

/// A direction drawn by a lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// f(wo, wi)·|cos θi| / pdf: what the path's throughput is multiplied
    /// by.
    pub value: Color,
    /// The unit direction drawn, pointing away from the surface.
    pub wi: Vec3,
    /// Its density per unit solid angle (for a specular sample, the
    /// probability of choosing that component; 0 for a lobe sampled only).
    pub pdf: f32,
    /// What kind of scattering it is.
    pub flags: LobeFlags,
}

impl BsdfSample {
    /// The sample of direction `wi` drawn by a lobe whose `eval_and_pdf`
    /// gives `(f_cos, pdf)` there: evaluated as `eval_and_pdf` evaluates
    /// it, so that its density is the one light sampling weighs it
    /// against; `None` where the density is zero or the value not finite.
    #[inline]
    pub fn evaluated((f_cos, pdf): (Color, f32), wi: Vec3, flags: LobeFlags) -> Option<BsdfSample> {
        let value = f_cos / pdf;
        (pdf > 0.0 && value.is_finite()).then_some(BsdfSample {
            value,
            wi,
            pdf,
            flags,
        })
    }
}

/// The share of a layered lobe's reflectance in near-mirror layers from
/// which the feature buffers look through it (see
/// [`Lobe::feature_albedo_seen`]).
const NEAR_MIRROR_SHARE: f32 = 0.75;

/// The lobe of a [`Bsdf`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// The notes' diffuse surface: four bounce models, two attenuations.
    Diffuse(diffuse::BookDiffuse),
    /// The notes' metal: a mirror blurred by a fuzz sphere.
    Metal(metal::FuzzyMetal),
    /// The notes' glass: Snell refraction, Schlick reflection.
    Dielectric(dielectric::SmoothDielectric),
    /// A metal: smooth or rough, by its complex index of refraction.
    Conductor(conductor::Conductor),
    /// Glass by the exact Fresnel equations, smooth or rough.
    ExactDielectric(dielectric::ExactDielectric),
    /// A thin sheet of glass: mirror or straight through.
    ThinDielectric(thin_dielectric::ThinDielectric),
    /// A diffuse base under a clear coat.
    Plastic(plastic::Plastic),
    /// The glTF metallic-roughness material and its layers.
    Principled(principled::Principled),
}

impl Lobe {
    /// Whether it works in the local frame (every lobe but the notes').
    #[inline(always)]
    pub fn is_local(&self) -> bool {
        !matches!(
            self,
            Lobe::Diffuse(_) | Lobe::Metal(_) | Lobe::Dielectric(_)
        )
    }

    /// What kind of scattering it can do.
    pub fn flags(&self) -> LobeFlags {
        let book = |f| LobeFlags::REFLECTION | f;
        match self {
            Lobe::Diffuse(_) => book(LobeFlags::DIFFUSE),
            Lobe::Metal(m) if m.fuzz == 0.0 => book(LobeFlags::SPECULAR),
            Lobe::Metal(_) => book(LobeFlags::GLOSSY),
            Lobe::Dielectric(_) => {
                LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | LobeFlags::SPECULAR
            }
            Lobe::Conductor(c) => c.flags(),
            Lobe::ExactDielectric(d) => d.flags(),
            Lobe::ThinDielectric(d) => d.flags(),
            Lobe::Plastic(p) => p.flags(),
            Lobe::Principled(p) => p.flags(),
        }
    }

    /// Its colour for the albedo feature buffer (see [`crate::aov`]), as
    /// Open Image Denoise asks: a diffuse surface's reflectance, a metal's
    /// reflectance at normal incidence, glass white, a coated or glTF
    /// surface its base's colour.
    pub fn feature_albedo(&self) -> Color {
        match self {
            Lobe::Diffuse(d) => d.albedo,
            Lobe::Metal(m) => m.albedo,
            Lobe::Conductor(c) => fresnel::conductor(1.0, c.eta, c.k) * c.tint,
            Lobe::Dielectric(_) | Lobe::ExactDielectric(_) | Lobe::ThinDielectric(_) => Color::ONE,
            Lobe::Plastic(p) => p.albedo,
            Lobe::Principled(p) => p.base_color,
        }
    }

    /// Its colour for the albedo feature buffer seen along local `wo`, or
    /// `None` where the feature buffers look through it to what it
    /// reflects or lets through: a delta lobe (a perfect mirror, clear
    /// glass), a conductor or glass whose microfacets are near mirrors
    /// ([`Microfacet::is_near_mirror`]), or a coated or glTF surface that
    /// reflects three quarters or more of what it reflects at all by such
    /// layers (as Blender Cycles decides).
    #[inline(always)]
    pub fn feature_albedo_seen(&self, wo: Vec3) -> Option<Color> {
        let near_mirror = |m: &Option<Microfacet>| m.is_some_and(|m| m.is_near_mirror());
        // The book's lobes first, without a look at their flags: they are
        // the commonest, and the cheapest to shade.
        let followed = match self {
            Lobe::Diffuse(d) => return Some(d.albedo),
            Lobe::Metal(m) => return (m.fuzz != 0.0).then_some(m.albedo),
            Lobe::Dielectric(_) => return None,
            _ if !self.flags().is_spread() => true,
            Lobe::Conductor(c) => near_mirror(&c.roughness),
            Lobe::ExactDielectric(d) => near_mirror(&d.roughness),
            Lobe::Plastic(p) => p.near_mirror_share(wo) >= NEAR_MIRROR_SHARE,
            Lobe::Principled(p) => p.near_mirror_share(wo) >= NEAR_MIRROR_SHARE,
            Lobe::ThinDielectric(_) => false,
        };
        (!followed).then(|| self.feature_albedo())
    }

    /// A direction for light leaving along local `wo`, from `uc` (a
    /// discrete choice) and `u`, uniform in [0, 1); the local lobes only.
    #[inline(always)]
    pub fn sample_local(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        match self {
            Lobe::Conductor(c) => c.sample(wo, u),
            Lobe::ExactDielectric(d) => d.sample(wo, uc, u),
            Lobe::ThinDielectric(d) => d.sample(wo, uc),
            Lobe::Plastic(p) => p.sample(wo, uc, u),
            Lobe::Principled(p) => p.sample(wo, uc, u),
            Lobe::Diffuse(_) | Lobe::Metal(_) | Lobe::Dielectric(_) => None,
        }
    }

    /// f(wo, wi)·|cos θi| and the density of `wi` for local directions;
    /// the local lobes only.
    #[inline(always)]
    pub fn eval_and_pdf_local(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        match self {
            Lobe::Conductor(c) => c.eval_and_pdf(wo, wi),
            Lobe::ExactDielectric(d) => d.eval_and_pdf(wo, wi),
            Lobe::Plastic(p) => p.eval_and_pdf(wo, wi),
            Lobe::Principled(p) => p.eval_and_pdf(wo, wi),
            Lobe::Diffuse(_) | Lobe::Metal(_) | Lobe::Dielectric(_) | Lobe::ThinDielectric(_) => {
                (Color::ZERO, 0.0)
            }
        }
    }
}

/// How a surface scatters at one point: its frame and its lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// The shading frame, its normal on the side the ray came from.
    pub frame: Frame,
    /// The unit geometric normal on the same side.
    pub ng: Vec3,
    /// The lobe.
    pub lobe: Lobe,
    /// Where a normal or bump map tilted the frame and the surface is
    /// darkened by the shadowing of its bumps ([`Terminator::NONE`]
    /// elsewhere).
    pub terminator: Terminator,
}

/// The shadowing of a bumpy surface whose shading normal a map tilted
/// (Conty Estevez et al. 2019, "A microfacet-based shadowing function to
/// solve the bump terminator problem", as Mitsuba 3 and Cycles apply it):
/// the bumps are taken as microfacets of width α² = min(⅛ tan²θ, 1), θ the
/// tilt, and light arriving at θi from the untilted normal is let through
/// by Smith's G₁ = 2 / (1 + √(1 + α² tan²θi)). Light on different sides
/// of the untilted normal and the tilted one is none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terminator {
    /// The shading normal before the map tilted it (unit, on the side the
    /// ray came from). Kept unaligned: the BSDF is copied at every bounce.
    pub normal: [f32; 3],
    /// The bumps' α²; 0 where nothing is tilted, and nothing shadowed.
    pub alpha2: f32,
}

impl Terminator {
    /// No shadowing.
    pub const NONE: Terminator = Terminator {
        normal: [0.0; 3],
        alpha2: 0.0,
    };

    /// Whether it shadows anything.
    #[inline(always)]
    pub fn is_some(&self) -> bool {
        self.alpha2 > 0.0
    }

    /// Whether the surface is one whose bumps shadow (tilted or not here):
    /// light it would reflect below the true surface is lost.
    #[inline(always)]
    pub fn is_present(&self) -> bool {
        self.normal != [0.0; 3]
    }

    /// The terminator of a surface whose shading normal `untilted` a map
    /// tilted to `tilted` (both unit, on the side the ray came from).
    pub fn new(untilted: Vec3, tilted: Vec3) -> Terminator {
        let cos2 = untilted.dot(tilted).powi(2).min(1.0);
        let tan2 = (1.0 - cos2) / cos2.max(1e-12);
        Terminator {
            normal: untilted.to_array(),
            alpha2: (0.125 * tan2).min(1.0),
        }
    }

    /// A sample off the surface whose tilted normal is `tilted`, shadowed.
    #[cold]
    #[inline(never)]
    fn shadow_sample(&self, tilted: Vec3, sample: BsdfSample) -> Option<BsdfSample> {
        let factor = self.factor(tilted, sample.wi);
        (factor > 0.0).then(|| BsdfSample {
            value: sample.value * factor,
            ..sample
        })
    }

    /// `value`, the light arriving from `wi`, shadowed.
    #[cold]
    #[inline(never)]
    fn shadow(&self, tilted: Vec3, wi: Vec3, value: Color) -> Color {
        value * self.factor(tilted, wi)
    }

    /// The fraction of light arriving from unit `wi` (reflected off a
    /// surface whose tilted normal is `tilted`) that its bumps let through.
    #[inline]
    pub fn factor(&self, tilted: Vec3, wi: Vec3) -> f32 {
        let cos = wi.dot(Vec3::from_array(self.normal));
        if !(cos * wi.dot(tilted) > 0.0) {
            return 0.0;
        }
        let cos2 = cos * cos;
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        2.0 / (1.0 + (1.0 + self.alpha2 * tan2).sqrt())
    }
}

impl Bsdf {
    /// A lobe in the frame around shading normal `n` (unit, on the side
    /// the ray came from), on a surface of unit geometric normal `ng` (same
    /// side).
    #[inline(always)]
    pub fn new(frame: Frame, ng: Vec3, lobe: Lobe) -> Bsdf {
        Bsdf {
            frame,
            ng,
            lobe,
            terminator: Terminator::NONE,
        }
    }

    /// The BSDF darkened by the shadowing of its surface's bumps.
    #[inline]
    pub fn with_terminator(mut self, terminator: Terminator) -> Bsdf {
        self.terminator = terminator;
        self
    }

    /// Whether the shading normal differs from the geometric one.
    #[inline(always)]
    pub fn is_smooth(&self) -> bool {
        self.frame.n != self.ng
    }

    /// Whether [`eval`](Self::eval) and [`pdf`](Self::pdf) describe how it
    /// scatters, so that a light can be sampled from here and weighed
    /// against the lobe's own sampling: every lobe but the deltas and the
    /// notes' sampled-only models.
    #[inline(always)]
    pub fn has_density(&self) -> bool {
        match &self.lobe {
            Lobe::Diffuse(d) => d.is_lambertian(),
            Lobe::Metal(_) | Lobe::Dielectric(_) => false,
            lobe => lobe.flags().is_spread(),
        }
    }

    /// Draws a direction towards which light leaving along unit `wo`
    /// (pointing away from the surface) is scattered from; `None` when the
    /// path is absorbed.
    #[inline(always)]
    pub fn sample(&self, wo: Vec3, sampler: &mut impl Sampler) -> Option<BsdfSample> {
        let sample = self.sample_lobe(wo, sampler)?;
        if self.terminator.is_some() {
            self.terminator.shadow_sample(self.frame.n, sample)
        } else {
            Some(sample)
        }
    }

    /// [`Bsdf::sample`] without the terminator.
    #[inline(always)]
    fn sample_lobe(&self, wo: Vec3, sampler: &mut impl Sampler) -> Option<BsdfSample> {
        match &self.lobe {
            Lobe::Diffuse(d) => d.sample(self, sampler),
            Lobe::Metal(m) => m.sample(self, wo, sampler),
            Lobe::Dielectric(d) => d.sample(self, wo, sampler),
            lobe => {
                let uc = sampler.get_1d(Dim::BsdfChoice);
                let u = sampler.get_2d(Dim::Bsdf);
                let s = lobe.sample_local(self.frame.to_local(wo), uc, u)?;
                // Unit, as the intersection tests assume, whatever the
                // rounding of the turn.
                let wi = self.frame.to_world(s.wi).normalize();
                (self.sides_agree(wo, wi, s.flags.is_transmission()) && s.value.is_finite())
                    .then_some(BsdfSample { wi, ..s })
            }
        }
    }

    /// Whether `wi` lies on the side of the true surface that reflection
    /// (or transmission) from `wo` goes to: a shading normal that differs
    /// from the geometric one must not let light through a surface, nor
    /// reflect it from behind.
    #[inline(always)]
    fn sides_agree(&self, wo: Vec3, wi: Vec3, transmission: bool) -> bool {
        let (o, i) = (wo.dot(self.ng), wi.dot(self.ng));
        o != 0.0 && i != 0.0 && ((o * i < 0.0) == transmission)
    }

    /// f(wo, wi)·|cos θi| for unit world directions `wo` and `wi` (both
    /// pointing away from the surface); zero for the deltas and for lobes
    /// without a density.
    #[inline(always)]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.eval_and_pdf(wo, wi).0
    }

    /// The density with which [`sample`](Self::sample) draws `wi` for `wo`.
    #[inline(always)]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_and_pdf(wo, wi).1
    }

    /// [`eval`](Self::eval) and [`pdf`](Self::pdf) together.
    #[inline(always)]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let (value, pdf) = self.eval_and_pdf_lobe(wo, wi);
        if self.terminator.is_some() {
            (self.terminator.shadow(self.frame.n, wi, value), pdf)
        } else {
            (value, pdf)
        }
    }

    /// [`Bsdf::eval_and_pdf`] without the terminator.
    #[inline(always)]
    fn eval_and_pdf_lobe(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        match &self.lobe {
            Lobe::Diffuse(d) => d.eval_and_pdf(self, wi),
            Lobe::Metal(_) | Lobe::Dielectric(_) => (Color::ZERO, 0.0),
            lobe => {
                let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
                let transmission = lo.z * li.z < 0.0;
                if !self.sides_agree(wo, wi, transmission) {
                    return (Color::ZERO, 0.0);
                }
                lobe.eval_and_pdf_local(lo, li)
            }
        }
    }

    /// `direction` kept on the side of the surface it was meant for: a
    /// reflection scattered around a smooth shading normal can point below
    /// the true (geometric) surface, where the path would enter the object
    /// and darken it; it is mirrored back above. A surface whose bumps
    /// shadow ([`Terminator`]) loses it instead (`None`), as Mitsuba 3 and
    /// Cycles do. Transmitted directions and flat surfaces are left alone.
    #[inline(always)]
    pub fn reflected_above(&self, direction: Vec3) -> Option<Vec3> {
        let cos = direction.dot(self.ng);
        if !(self.is_smooth() && cos <= 0.0) {
            Some(direction)
        } else if self.mirrors_below() {
            Some((direction - 2.0 * cos * self.ng).normalize())
        } else {
            None
        }
    }

    /// Whether reflections that fall below the true surface are mirrored
    /// above it (see [`reflected_above`](Self::reflected_above)).
    #[inline(always)]
    pub fn mirrors_below(&self) -> bool {
        self.is_smooth() && !self.terminator.is_present()
    }
}
