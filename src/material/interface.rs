//! The boundary between two media that is no surface: the outline of a
//! cloud, the edge of fog in a room. Paths cross it undeviated and
//! unattenuated, without counting a bounce, and only change the medium
//! they travel in (Mitsuba's `null` BSDF on a shape with media, pbrt's
//! `interface` material).

use super::param::{Invalid, Textures};
use super::{Kind, Material};

material_desc! {
    /// No surface: the boundary between the media its `interior` and
    /// `exterior` name.
    pub struct InterfaceDesc {}
}

impl InterfaceDesc {
    pub(super) fn compile(
        &self,
        _field: &str,
        _textures: &mut dyn Textures,
    ) -> Result<Material, Invalid> {
        Ok(Material::new(Kind::Interface))
    }
}
