//! A projector: a point light that casts an image through a rectangular
//! frustum, as a slide projector does (Mitsuba's `projector`). The image
//! fills a rectangle across the axis at unit distance, `fov` wide and as
//! high as the image's shape makes it; `irradiance` times the image is
//! the irradiance that rectangle receives, so a plane across the axis is
//! lit evenly by an even image. The intensity towards a point θ off the
//! axis is therefore irradiance × image / cos³θ. Given an `intensity`
//! instead (pbrt's `projection` light), the intensity is intensity × image
//! in every direction of the frustum, and the plane is lit less towards
//! the rectangle's edges.

use super::{aim, check_color, check_point, image_frame, light_texture, slide, Incident};
use crate::material::param::Textures;
use crate::material::Invalid;
use crate::math::{Color, Point3, Vec3};
use crate::scene::desc::Triple;
use crate::texture::Texture;

/// The narrowest image a projector takes, width over height (and the
/// widest, its inverse).
const MIN_ASPECT: f64 = 1e-6;

/// A projector as a scene describes it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectorLightDesc {
    /// Where it is.
    pub position: Triple,
    /// The direction of its axis (any length but zero); give this or
    /// `target`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Triple>,
    /// A point on its axis, instead of `direction`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<Triple>,
    /// Which way is up in the projected image (any direction not along
    /// the axis); +y when absent, or +z when the axis is vertical.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Triple>,
    /// The angle the image spans across its width, in degrees, in (0, 180).
    pub fov: f64,
    /// The irradiance per channel, W/m², on the rectangle the image fills
    /// at unit distance (times the image there); give this or `intensity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub irradiance: Option<Triple>,
    /// The radiant intensity per channel, W/sr, in every direction of the
    /// frustum (times the image there), instead of `irradiance`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity: Option<Triple>,
    /// The image (the name of a colour texture); when absent, an even
    /// square of light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<String>,
    /// The image's width over its height; when absent, the texture's image
    /// gives it (1 for a texture that is no image, and without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<f64>,
}

/// A projector, compiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectorLight {
    /// Where it is.
    pub position: Point3,
    /// The unit direction of its axis.
    pub axis: Vec3,
    /// The image's right and up directions (unit, across the axis) over
    /// the half-width and half-height of its rectangle at unit distance.
    right: Vec3,
    up: Vec3,
    /// Irradiance on that rectangle, or intensity.
    pub emitted: Color,
    /// Whether `emitted` is the irradiance on the rectangle (the intensity
    /// grows as 1 / cos³θ off the axis), not the intensity.
    even_on_plane: bool,
    /// The image's texture.
    texture: Option<u32>,
    /// What a unit of `emitted` sends out: the rectangle's area, or the
    /// frustum's solid angle (in f64: the area of a wide frustum's
    /// rectangle can pass f32's range).
    spread: f64,
}

impl ProjectorLightDesc {
    /// The light described; `field` is its path for messages.
    pub fn compile(
        &self,
        field: &str,
        textures: &mut dyn Textures,
    ) -> Result<ProjectorLight, Invalid> {
        let position = check_point(&format!("{field}.position"), self.position)?;
        let axis = aim(field, position, self.direction, self.target)?;
        let (right, up) = image_frame(field, axis, self.up)?;
        if !(self.fov > 0.0 && self.fov < 180.0) {
            return Err(Invalid::new(
                format!("{field}.fov"),
                format!("must be above 0 and below 180 degrees, got {}", self.fov),
            ));
        }
        let texture = match &self.texture {
            None => None,
            Some(name) => Some(light_texture(field, name, textures)?),
        };
        let aspect = match self.aspect {
            Some(a) if (MIN_ASPECT..=1.0 / MIN_ASPECT).contains(&a) => a,
            Some(a) => {
                return Err(Invalid::new(
                    format!("{field}.aspect"),
                    format!(
                        "must be a positive number from {MIN_ASPECT:e} to {:e}, got {a}",
                        1.0 / MIN_ASPECT
                    ),
                ))
            }
            None => texture.and_then(|t| textures.aspect(t)).unwrap_or(1.0),
        };
        let half_width = (self.fov.to_radians() / 2.0).tan();
        let half_height = half_width / aspect;
        // Both sizes must be ordinary f32 numbers.
        let usable = |v: f64| v > 1e-12 && v < 1e30;
        if !(usable(half_width) && usable(half_height)) {
            return Err(Invalid::new(
                format!("{field}.fov"),
                format!(
                    "{} degrees with an image {aspect} times as wide as high makes its frame too \
                     small or too large to light anything",
                    self.fov
                ),
            ));
        }
        let (emitted, even_on_plane) = match (self.irradiance, self.intensity) {
            (Some(e), None) => (check_color(&format!("{field}.irradiance"), e)?, true),
            (None, Some(i)) => (check_color(&format!("{field}.intensity"), i)?, false),
            (Some(_), Some(_)) => {
                return Err(Invalid::new(
                    format!("{field}.intensity"),
                    "give `irradiance` or `intensity`, not both",
                ))
            }
            (None, None) => {
                return Err(Invalid::new(
                    format!("{field}.irradiance"),
                    "a projector needs `irradiance` or `intensity`",
                ))
            }
        };
        let (a, b) = (half_width, half_height);
        let spread = if even_on_plane {
            4.0 * a * b
        } else {
            // The solid angle of the rectangle [−a, a] × [−b, b] at unit
            // distance.
            4.0 * (a * b / ((1.0 + a * a) * (1.0 + b * b)).sqrt()).asin()
        };
        Ok(ProjectorLight {
            position,
            axis,
            right: right / a as f32,
            up: up / b as f32,
            emitted,
            even_on_plane,
            texture,
            spread,
        })
    }
}

impl ProjectorLight {
    /// The light arriving at `from` (`textures` holding its image).
    #[inline]
    pub fn illuminate(&self, from: Point3, textures: &[Texture]) -> Option<Incident> {
        let mut sample = Incident::from_point(from, self.position, self.emitted)?;
        // The direction the light leaves in, and where it crosses the
        // image's rectangle at unit distance, in half-sizes from its centre.
        let d = -sample.direction;
        let cos = d.dot(self.axis);
        if !(cos > 0.0) {
            return None;
        }
        let (x, y) = (d.dot(self.right) / cos, d.dot(self.up) / cos);
        if !(x.abs() <= 1.0 && y.abs() <= 1.0) {
            return None;
        }
        if self.even_on_plane {
            sample.radiance /= cos * cos * cos;
        }
        if let Some(t) = self.texture {
            sample.radiance *= slide(textures, t, [x, y], from);
        }
        Some(sample)
    }

    /// Whether it looks textures up.
    pub fn is_textured(&self) -> bool {
        self.texture.is_some()
    }

    /// Its power's luminance for an even image: the irradiance over the
    /// rectangle at unit distance, which catches all of it, or the
    /// intensity over the frustum's solid angle.
    pub fn power(&self) -> f64 {
        self.spread * f64::from(super::super::luminance(self.emitted))
    }
}
