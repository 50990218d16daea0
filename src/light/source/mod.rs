//! Lights that are no surface: point, spot, directional lights and
//! projectors. Each
//! kind is declared once in its own file (its description's fields and
//! what it sheds) and listed in `source_kinds!` below, which makes the
//! description enum the scene readers decode, the table of kinds their
//! messages use, and the dispatch.
//!
//! A point, a spot, a projector and a directional light without angular
//! radius are
//! *delta* lights: no ray can meet them, so they are found only by
//! next-event estimation, whose sample then needs no weight against the
//! bounces. A directional light with an angular radius is a disc of the
//! sky, met by escaping rays too and weighted like the environment.

mod directional;
mod point;
mod projector;
mod spot;

pub use directional::{DirectionalLight, DirectionalLightDesc};
pub use point::{PointLight, PointLightDesc};
pub use projector::{ProjectorLight, ProjectorLightDesc};
pub use spot::{SpotFalloffDesc, SpotLight, SpotLightDesc, DEFAULT_CUTOFF};

use crate::material::param::{ColorDesc, ColorParam, ColorRange, Textures};
use crate::material::{Invalid, KindInfo};
use crate::math::{Color, Point3, Vec3};
use crate::scene::desc::Triple;
use crate::texture::{TexCoords, Texture};

/// Lists the kinds once: the description enum (tagged by `type` in scene
/// files), the table of kinds and their fields, and compilation.
macro_rules! source_kinds {
    ($( $(#[$meta:meta])* $variant:ident($desc:ty => $light:ty) = $name:literal, $what:literal; )*) => {
        /// A light that is no surface, as a scene describes it (`type =
        /// "…"` and the kind's fields).
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(tag = "type", rename_all = "kebab-case")]
        pub enum LightDesc {
            $( $(#[$meta])* $variant($desc), )*
        }

        /// A light that is no surface, compiled.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum LightSource {
            $( $(#[$meta])* $variant($light), )*
        }

        /// Every kind of light source: its `type`, how messages call it,
        /// and its fields (`type` among them).
        pub fn kinds() -> Vec<KindInfo> {
            vec![$(KindInfo {
                name: $name,
                what: $what,
                fields: std::iter::once("type")
                    .chain(crate::material::param::fields_of::<$desc>().iter().copied())
                    .collect(),
            },)*]
        }

        impl LightDesc {
            /// The kind's `type` name.
            pub fn type_name(&self) -> &'static str {
                match self {
                    $(LightDesc::$variant(_) => $name,)*
                }
            }

            /// Reads the fields of the kind called `name` from `d`.
            pub fn deserialize_kind<'de, D: serde::Deserializer<'de>>(
                name: &str,
                d: D,
            ) -> Result<LightDesc, D::Error> {
                use serde::Deserialize;
                match name {
                    $($name => <$desc>::deserialize(d).map(LightDesc::$variant),)*
                    _ => Err(serde::de::Error::unknown_variant(name, &[$($name),*])),
                }
            }

            /// The light described, compiled: `field` is its path
            /// (`lights[3]`) for messages, `textures` resolves texture
            /// names.
            pub fn compile(
                &self,
                field: &str,
                textures: &mut dyn Textures,
            ) -> Result<LightSource, Invalid> {
                Ok(match self {
                    $(LightDesc::$variant(d) => LightSource::$variant(d.compile(field, textures)?),)*
                })
            }
        }
    };
}

source_kinds! {
    /// All its light from one point, equally in every direction.
    Point(PointLightDesc => PointLight) = "point", "a point light";
    /// A point light shining in a cone.
    Spot(SpotLightDesc => SpotLight) = "spot", "a spot light";
    /// Parallel light from infinitely far, or a disc of the sky.
    Directional(DirectionalLightDesc => DirectionalLight) = "directional", "a directional light";
    /// A point light casting an image through a rectangular frustum.
    Projector(ProjectorLightDesc => ProjectorLight) = "projector", "a projector";
}

impl LightDesc {
    /// Whether no ray can meet the light: a point, a spot, or a
    /// directional light without angular radius.
    pub fn is_delta(&self) -> bool {
        match self {
            LightDesc::Directional(d) => d.angular_radius.unwrap_or(0.0) == 0.0,
            LightDesc::Point(_) | LightDesc::Spot(_) | LightDesc::Projector(_) => true,
        }
    }
}

/// The light a source sheds on a point: a light sample whose `pdf` is
/// that of the direction alone (1 for a delta light), before the choice of
/// the light.
pub type Incident = super::LightSample;

impl Incident {
    /// The light of intensity `intensity` at `position` arriving at `from`;
    /// `None` when the two coincide.
    #[inline]
    fn from_point(from: Point3, position: Point3, intensity: Color) -> Option<Incident> {
        let to = position - from;
        let d2 = to.length_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            return None;
        }
        let distance = d2.sqrt();
        Some(Incident {
            point: position,
            direction: to / distance,
            distance,
            radiance: intensity / d2,
            pdf: 1.0,
            delta: true,
        })
    }
}

impl LightSource {
    /// The light it sheds on `from`, its direction drawn from `u` where it
    /// has more than one (`textures` holding a spot's projected image);
    /// `None` where it sheds none.
    #[inline]
    pub fn illuminate(&self, from: Point3, u: [f32; 2], textures: &[Texture]) -> Option<Incident> {
        match self {
            LightSource::Point(l) => l.illuminate(from),
            LightSource::Spot(l) => l.illuminate(from, textures),
            LightSource::Directional(l) => l.illuminate(from, u),
            LightSource::Projector(l) => l.illuminate(from, textures),
        }
    }

    /// Whether it looks textures up.
    pub fn is_textured(&self) -> bool {
        match self {
            LightSource::Spot(l) => l.is_textured(),
            LightSource::Projector(l) => l.is_textured(),
            LightSource::Point(_) | LightSource::Directional(_) => false,
        }
    }

    /// The radiance an escaping ray sees looking along unit `direction`,
    /// and the density with which `illuminate` draws that direction: only
    /// a disc of the sky is seen.
    #[inline]
    pub fn seen_along(&self, direction: Vec3) -> Option<(Color, f32)> {
        match self {
            LightSource::Directional(l) => l.seen_along(direction),
            LightSource::Point(_) | LightSource::Spot(_) | LightSource::Projector(_) => None,
        }
    }

    /// Whether an escaping ray can see it.
    pub fn is_visible(&self) -> bool {
        matches!(self, LightSource::Directional(l) if !l.is_delta())
    }

    /// Its power's luminance, up to the constant factor every light's has:
    /// what the choice of lights goes by. Light from infinitely far counts
    /// through the disc of the scene's bounding sphere (`scene_radius`).
    pub fn power(&self, scene_radius: f32) -> f64 {
        match self {
            LightSource::Point(l) => l.power(),
            LightSource::Spot(l) => l.power(),
            LightSource::Directional(l) => l.power(scene_radius),
            LightSource::Projector(l) => l.power(),
        }
    }
}

/// A colour of a light: finite and not negative, per channel.
fn check_color(field: &str, c: [f64; 3]) -> Result<Color, Invalid> {
    if c.iter()
        .any(|v| !(v.is_finite() && *v >= 0.0 && *v <= f64::from(f32::MAX)))
    {
        return Err(Invalid::new(
            field,
            format!(
                "must be three finite numbers, none negative, got [{}, {}, {}]",
                c[0], c[1], c[2]
            ),
        ));
    }
    Ok(Color::new(c[0] as f32, c[1] as f32, c[2] as f32))
}

/// A position: finite.
fn check_point(field: &str, p: [f64; 3]) -> Result<Point3, Invalid> {
    if p.iter().any(|v| !(v.abs() <= f64::from(f32::MAX))) {
        return Err(Invalid::new(
            field,
            format!(
                "must be three finite numbers, got [{}, {}, {}]",
                p[0], p[1], p[2]
            ),
        ));
    }
    Ok(Point3::new(p[0] as f32, p[1] as f32, p[2] as f32))
}

/// A direction: finite and not zero; made unit length.
fn check_vector(field: &str, v: [f64; 3]) -> Result<Vec3, Invalid> {
    let d = glam::DVec3::from_array(v);
    let unit = d.normalize_or_zero();
    if !d.is_finite() || unit == glam::DVec3::ZERO {
        return Err(Invalid::new(
            field,
            format!(
                "must be a direction: three finite numbers, not all zero, got [{}, {}, {}]",
                v[0], v[1], v[2]
            ),
        ));
    }
    Ok(Vec3::new(unit.x as f32, unit.y as f32, unit.z as f32))
}

/// The unit axis of a light at `position` aimed along `direction` or at
/// `target` (one of them); `field` is its path for messages.
fn aim(
    field: &str,
    position: Point3,
    direction: Option<Triple>,
    target: Option<Triple>,
) -> Result<Vec3, Invalid> {
    match (direction, target) {
        (Some(d), None) => check_vector(&format!("{field}.direction"), d),
        (None, Some(t)) => {
            let t = check_point(&format!("{field}.target"), t)?;
            check_vector(
                &format!("{field}.target"),
                (t - position).as_dvec3().to_array(),
            )
            .map_err(|_| Invalid::new(format!("{field}.target"), "is the light's own position"))
        }
        (Some(_), Some(_)) => Err(Invalid::new(
            format!("{field}.target"),
            "give `direction` or `target`, not both",
        )),
        (None, None) => Err(Invalid::new(
            format!("{field}.direction"),
            "the light needs `direction` or `target`",
        )),
    }
}

/// The unit right and up directions, across `axis`, of an image a light
/// projects: `up` as given (any direction not along the axis), or +y, or
/// +z when the axis is vertical.
fn image_frame(field: &str, axis: Vec3, up: Option<Triple>) -> Result<(Vec3, Vec3), Invalid> {
    let up = match up {
        Some(u) => check_vector(&format!("{field}.up"), u)?,
        None if axis.y.abs() > 0.999 => Vec3::Z,
        None => Vec3::Y,
    };
    let right = axis.cross(up).normalize_or_zero();
    if right == Vec3::ZERO {
        return Err(Invalid::new(
            format!("{field}.up"),
            "lies along the light's axis",
        ));
    }
    Ok((right, right.cross(axis)))
}

/// The colour of the image (texture `t`) a light casts where a ray leaving
/// it crosses the image's frame at unit distance, at (x, y) in half-sizes
/// from its centre (the image spans [−1, 1]², its top at y = 1); `from` is
/// the point lit.
#[inline]
fn slide(textures: &[Texture], t: u32, [x, y]: [f32; 2], from: Point3) -> Color {
    let uv = [0.5 + 0.5 * x, 0.5 + 0.5 * y];
    textures[t as usize]
        .value(textures, &TexCoords::new(uv, from))
        .max(Color::ZERO)
}

/// The colour texture `name` a light of path `field` casts.
fn light_texture(field: &str, name: &str, textures: &mut dyn Textures) -> Result<u32, Invalid> {
    let at = format!("{field}.texture");
    match textures.color(
        &at,
        &ColorDesc::Texture(name.to_string()),
        ColorRange::NonNegative,
    )? {
        ColorParam::Texture(t) => Ok(t),
        ColorParam::Const(_) => Err(Invalid::new(at, "must name a texture")),
    }
}
