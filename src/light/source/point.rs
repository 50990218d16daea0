//! A point light: all of its light leaves one point, the same in every
//! direction (pbrt's and Mitsuba's `point`).

use super::{check_color, check_point, Incident};
use crate::material::Invalid;
use crate::math::{Color, Point3};
use crate::scene::desc::Triple;
use std::f64::consts::PI;

/// A point light as a scene describes it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightDesc {
    /// Where it is.
    pub position: Triple,
    /// Radiant intensity, W/sr per channel: the irradiance at distance d
    /// facing it is intensity / d².
    pub intensity: Triple,
}

/// A point light, compiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where it is.
    pub position: Point3,
    /// Radiant intensity per channel.
    pub intensity: Color,
}

impl PointLightDesc {
    /// The light described; `field` is its path for messages.
    pub fn compile(
        &self,
        field: &str,
        _textures: &mut dyn crate::material::param::Textures,
    ) -> Result<PointLight, Invalid> {
        Ok(PointLight {
            position: check_point(&format!("{field}.position"), self.position)?,
            intensity: check_color(&format!("{field}.intensity"), self.intensity)?,
        })
    }
}

impl PointLight {
    /// The light arriving at `from`.
    #[inline]
    pub fn illuminate(&self, from: Point3) -> Option<Incident> {
        Incident::from_point(from, self.position, self.intensity)
    }

    /// Its power per channel's luminance: 4π × intensity.
    pub fn power(&self) -> f64 {
        4.0 * PI * f64::from(super::super::luminance(self.intensity))
    }
}
