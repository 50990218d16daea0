//! A spot light: a point light whose light leaves in a cone, full within
//! `beam_width` of its axis and falling off linearly in angle to nothing at
//! `cutoff_angle` (Mitsuba's `spot`).

use super::{aim, check_color, check_point, image_frame, light_texture, slide, Incident};
use crate::material::param::Textures;
use crate::material::Invalid;
use crate::math::{Color, Point3, Vec3};
use crate::scene::desc::Triple;
use crate::texture::Texture;
use std::f64::consts::PI;

/// A spot light as a scene describes it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpotLightDesc {
    /// Where it is.
    pub position: Triple,
    /// The direction of its axis (any length but zero); give this or
    /// `target`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Triple>,
    /// A point on its axis, instead of `direction`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<Triple>,
    /// Radiant intensity on the axis, W/sr per channel.
    pub intensity: Triple,
    /// The angle from the axis, in degrees, beyond which it sheds no
    /// light, in (0, 180); 20 when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_angle: Option<f64>,
    /// The angle from the axis, in degrees, within which it sheds its full
    /// intensity, in (0, `cutoff_angle`]; ¾ of `cutoff_angle` when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beam_width: Option<f64>,
    /// An image (the name of a colour texture) projected through the
    /// cone, as a slide projector does: its square fills the cone's
    /// cut-off, and it multiplies the intensity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<String>,
    /// Which way is up in the projected image (any direction not along
    /// the axis); +y when absent, or +z when the axis is vertical.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Triple>,
    /// How the intensity falls from the beam to the cut-off: "linear" in
    /// angle (Mitsuba's, the default) or "smoothstep" in the angle's
    /// cosine (pbrt's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub falloff: Option<SpotFalloffDesc>,
}

/// How a spot light's intensity falls from its beam to its cut-off.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpotFalloffDesc {
    /// Linearly in angle, as Mitsuba's `spot`.
    #[default]
    Linear,
    /// As the smooth step t²(3 − 2t) of t = (cos θ − cos cutoff) / (cos
    /// beam − cos cutoff), as pbrt's `spot`.
    Smoothstep,
}

/// The cut-off angle of a spot light that gives none, in degrees.
pub const DEFAULT_CUTOFF: f64 = 20.0;

/// A spot light, compiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    /// Where it is.
    pub position: Point3,
    /// The unit direction of its axis.
    pub axis: Vec3,
    /// Radiant intensity on the axis.
    pub intensity: Color,
    /// The cut-off angle, radians, and its cosine.
    cutoff: f32,
    cos_cutoff: f32,
    /// The cosine of the beam width.
    cos_beam: f32,
    /// 1 / (cutoff − beam width), per radian.
    inv_transition: f32,
    beam: f32,
    /// Fall off as pbrt's smooth step in cosine, not linearly in angle.
    smoothstep: bool,
    /// The projected image's texture, and its right and up directions
    /// (unit, perpendicular to the axis) over tan(cutoff).
    projection: Option<(u32, Vec3, Vec3)>,
}

impl SpotLightDesc {
    /// The light described; `field` is its path for messages.
    pub fn compile(&self, field: &str, textures: &mut dyn Textures) -> Result<SpotLight, Invalid> {
        let position = check_point(&format!("{field}.position"), self.position)?;
        let axis = aim(field, position, self.direction, self.target)?;
        let cutoff = self.cutoff_angle.unwrap_or(DEFAULT_CUTOFF);
        if !(cutoff > 0.0 && cutoff < 180.0) {
            return Err(Invalid::new(
                format!("{field}.cutoff_angle"),
                format!("must be above 0 and below 180 degrees, got {cutoff}"),
            ));
        }
        let beam = self.beam_width.unwrap_or(0.75 * cutoff);
        if !(beam > 0.0 && beam <= cutoff) {
            return Err(Invalid::new(
                format!("{field}.beam_width"),
                format!("must be above 0 and at most cutoff_angle ({cutoff}) degrees, got {beam}"),
            ));
        }
        let (cutoff, beam) = (cutoff.to_radians() as f32, beam.to_radians() as f32);
        let projection = match &self.texture {
            None => {
                if self.up.is_some() {
                    return Err(Invalid::new(
                        format!("{field}.up"),
                        "orients a projected `texture`, which the light does not have",
                    ));
                }
                None
            }
            Some(name) => {
                let t = light_texture(field, name, textures)?;
                if cutoff >= std::f32::consts::FRAC_PI_2 {
                    return Err(Invalid::new(
                        format!("{field}.cutoff_angle"),
                        "a projected texture needs a cutoff_angle below 90 degrees",
                    ));
                }
                let (right, up) = image_frame(field, axis, self.up)?;
                let tan = cutoff.tan();
                Some((t, right / tan, up / tan))
            }
        };
        Ok(SpotLight {
            projection,
            position,
            axis,
            intensity: check_color(&format!("{field}.intensity"), self.intensity)?,
            cutoff,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
            inv_transition: if cutoff > beam {
                1.0 / (cutoff - beam)
            } else {
                0.0
            },
            beam,
            smoothstep: self.falloff == Some(SpotFalloffDesc::Smoothstep),
        })
    }
}

impl SpotLight {
    /// The fraction of its axial intensity the light sends along unit
    /// `direction`: 1 within the beam, falling (linearly in angle, or by
    /// the smooth step) to 0 at the cut-off.
    #[inline]
    pub fn falloff(&self, direction: Vec3) -> f32 {
        let cos = direction.dot(self.axis);
        if !(cos > self.cos_cutoff) {
            0.0
        } else if cos >= self.cos_beam {
            1.0
        } else if self.smoothstep {
            let t = ((cos - self.cos_cutoff) / (self.cos_beam - self.cos_cutoff)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        } else {
            ((self.cutoff - cos.min(1.0).acos()) * self.inv_transition).clamp(0.0, 1.0)
        }
    }

    /// The light arriving at `from` (`textures` holding its projected
    /// image).
    #[inline]
    pub fn illuminate(&self, from: Point3, textures: &[Texture]) -> Option<Incident> {
        let mut sample = Incident::from_point(from, self.position, self.intensity)?;
        // The direction the light leaves in.
        let d = -sample.direction;
        let falloff = self.falloff(d);
        if falloff == 0.0 {
            return None;
        }
        sample.radiance *= falloff;
        if let Some((t, right, up)) = self.projection {
            // The image's square spans ±tan(cutoff) across the axis at
            // unit distance along it.
            let z = d.dot(self.axis);
            sample.radiance *= slide(textures, t, [d.dot(right) / z, d.dot(up) / z], from);
        }
        Some(sample)
    }

    /// Whether it projects an image (and so looks textures up).
    pub fn is_textured(&self) -> bool {
        self.projection.is_some()
    }

    /// Its power's luminance, as if the intensity fell off at the middle
    /// of the transition: 2π(1 − cos θ) × intensity, θ halfway between
    /// beam width and cut-off (it only steers the choice of lights).
    pub fn power(&self) -> f64 {
        let middle = 0.5 * f64::from(self.cutoff + self.beam);
        2.0 * PI * (1.0 - middle.cos()) * f64::from(super::super::luminance(self.intensity))
    }
}
