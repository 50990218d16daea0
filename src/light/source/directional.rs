//! A directional light: parallel light from infinitely far away (pbrt's
//! `distant`, Mitsuba's `directional`), or, given an angular radius, a
//! disc of the sky like the sun, sampled over the cone it fills.

use super::{check_color, check_vector, Incident};
use crate::material::Invalid;
use crate::math::{Color, Point3, Vec3};
use crate::sampling;
use crate::scene::desc::Triple;
use std::f32::consts::PI;

/// A directional light as a scene describes it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightDesc {
    /// The direction the light travels in (any length but zero): [0, -1,
    /// 0] shines straight down.
    pub direction: Triple,
    /// Irradiance per channel, W/m², on a surface facing the light.
    pub irradiance: Triple,
    /// The angle in degrees between the disc's centre and its rim, in [0,
    /// 90): the sun's is about 0.27. 0 (the default) is a light of one
    /// direction, whose shadows are sharp.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_radius: Option<f64>,
}

/// A directional light, compiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// The unit direction towards the light (against the way it travels).
    pub towards: Vec3,
    /// Irradiance per channel facing it.
    pub irradiance: Color,
    /// For a disc: 1 − cos of its angular radius (0 for a single
    /// direction).
    one_minus_cos: f32,
    /// For a disc: its radiance, irradiance / (π sin² of its angular
    /// radius), so that a surface facing it receives `irradiance`.
    radiance: Color,
}

impl DirectionalLightDesc {
    /// The light described; `field` is its path for messages.
    pub fn compile(
        &self,
        field: &str,
        _textures: &mut dyn crate::material::param::Textures,
    ) -> Result<DirectionalLight, Invalid> {
        let travels = check_vector(&format!("{field}.direction"), self.direction)?;
        let irradiance = check_color(&format!("{field}.irradiance"), self.irradiance)?;
        let radius = self.angular_radius.unwrap_or(0.0);
        if !(0.0..90.0).contains(&radius) {
            return Err(Invalid::new(
                format!("{field}.angular_radius"),
                format!("must be at least 0 and below 90 degrees, got {radius}"),
            ));
        }
        let (sin, cos) = radius.to_radians().sin_cos();
        // 1 − cos without cancellation: sin² / (1 + cos).
        let one_minus_cos = (sin * sin / (1.0 + cos)) as f32;
        let radiance = if one_minus_cos > 0.0 {
            irradiance / (std::f64::consts::PI * sin * sin) as f32
        } else {
            Color::ZERO
        };
        Ok(DirectionalLight {
            towards: -travels,
            irradiance,
            one_minus_cos,
            radiance,
        })
    }
}

impl DirectionalLight {
    /// Whether it is a single direction (a delta light) rather than a disc.
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.one_minus_cos == 0.0
    }

    /// The light arriving at `from`: along its one direction, or along a
    /// direction drawn from `u` uniformly over its disc.
    #[inline]
    pub fn illuminate(&self, from: Point3, u: [f32; 2]) -> Option<Incident> {
        if self.is_delta() {
            return Some(Incident {
                point: from + self.towards,
                direction: self.towards,
                distance: f32::INFINITY,
                radiance: self.irradiance,
                pdf: 1.0,
                delta: true,
            });
        }
        let direction = sampling::in_cone(u, self.towards, self.one_minus_cos);
        Some(Incident {
            point: from + direction,
            direction,
            distance: f32::INFINITY,
            radiance: self.radiance,
            pdf: self.cone_pdf(),
            delta: false,
        })
    }

    /// The density of a direction of a disc, uniform over its cone.
    #[inline]
    fn cone_pdf(&self) -> f32 {
        1.0 / (2.0 * PI * self.one_minus_cos)
    }

    /// Whether unit `direction` looks into the disc (never for a delta
    /// light).
    #[inline]
    fn within(&self, direction: Vec3) -> bool {
        // 1 − cos of the angle to the centre, as |d − c|²/2 (no
        // cancellation near the centre).
        !self.is_delta() && 0.5 * (direction - self.towards).length_squared() <= self.one_minus_cos
    }

    /// The radiance seen looking along unit `direction` (an escaping ray),
    /// and the density with which [`DirectionalLight::illuminate`] draws
    /// it; `None` outside the disc.
    #[inline]
    pub fn seen_along(&self, direction: Vec3) -> Option<(Color, f32)> {
        self.within(direction)
            .then(|| (self.radiance, self.cone_pdf()))
    }

    /// Its power's luminance: its irradiance through the disc the scene
    /// presents to it.
    pub fn power(&self, scene_radius: f32) -> f64 {
        let disc = std::f64::consts::PI * f64::from(scene_radius.max(f32::MIN_POSITIVE)).powi(2);
        f64::from(super::super::luminance(self.irradiance)) * disc
    }
}
