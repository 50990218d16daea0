//! A material as a mesh file describes it, in the terms of glTF's
//! metallic-roughness model and its KHR extensions: every parameter a
//! factor and, where the file gives one, an image map of it (the channel,
//! wrapping, filtering, coordinates and transform the file says). glTF
//! materials are read into it as they are; MTL materials are mapped onto it
//! (see the OBJ loader). The scene compiles it to a principled material.

use crate::texture::ImageMap;

/// A parameter: a factor, times a map where the file gives one.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapped<T> {
    /// The factor (the value where there is no map).
    pub value: T,
    /// The map, if any (for a scalar, one channel of an image).
    pub map: Option<ImageMap>,
}

impl<T> Mapped<T> {
    /// The factor `value` with no map.
    pub const fn value(value: T) -> Self {
        Mapped { value, map: None }
    }
}

/// How a material's alpha is used (glTF `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is all there.
    #[default]
    Opaque,
    /// The surface is there where alpha is at least the cutoff.
    Mask(f32),
    /// Alpha is the fraction of the surface that is there.
    Blend,
}

/// A material of a mesh file.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshMaterial {
    /// The material's name in the file (glTF materials without one are named
    /// `material N`).
    pub name: String,
    /// Linear RGB base colour (glTF `baseColorFactor` and texture; MTL `Kd`
    /// and `map_Kd`).
    pub base_color: Mapped<[f32; 3]>,
    /// Alpha (the base colour's fourth channel; MTL `d`, `map_d`).
    pub alpha: Mapped<f32>,
    /// How alpha is used.
    pub alpha_mode: AlphaMode,
    /// Whether the base colour and alpha are multiplied by the mesh's
    /// vertex colours (glTF `COLOR_0`).
    pub vertex_color: bool,
    /// How much is metal, in [0, 1] (glTF: the blue channel of the
    /// metallic-roughness texture; MTL `Pm`).
    pub metallic: Mapped<f32>,
    /// Perceptual roughness in [0, 1], α = roughness² (glTF: green channel;
    /// MTL `Pr`, or from `Ns`).
    pub roughness: Mapped<f32>,
    /// Whether the roughness map is a gloss map (roughness = 1 − its value:
    /// MTL `map_Ns`).
    pub roughness_from_gloss: bool,
    /// A tangent-space normal map and its scale (glTF `normalTexture`;
    /// MTL `norm`).
    pub normal_map: Option<(ImageMap, f32)>,
    /// A height map and the height of its 1 (MTL `bump`, `map_Bump`).
    pub bump_map: Option<(ImageMap, f32)>,
    /// Emitted radiance (glTF `emissiveFactor` × `emissiveStrength` and
    /// texture; MTL `Ke`, `map_Ke`).
    pub emission: Mapped<[f32; 3]>,
    /// Whether the surface is seen, and emits, from both sides (glTF
    /// `doubleSided`).
    pub double_sided: bool,
    /// Index of refraction (`KHR_materials_ior`; MTL `Ni`).
    pub ior: f32,
    /// Specular strength (`KHR_materials_specular`, alpha channel).
    pub specular: Mapped<f32>,
    /// Specular colour at normal incidence (its colour texture).
    pub specular_color: Mapped<[f32; 3]>,
    /// Transmission (`KHR_materials_transmission`, red channel; MTL
    /// transparency of glass illumination models).
    pub transmission: Mapped<f32>,
    /// Thickness of the volume behind (`KHR_materials_volume`, green).
    pub thickness: Mapped<f32>,
    /// The colour white light turns after `attenuation_distance`.
    pub attenuation_color: [f32; 3],
    /// That distance; infinite: no absorption.
    pub attenuation_distance: f32,
    /// Clear coat strength (`KHR_materials_clearcoat`, red channel).
    pub clearcoat: Mapped<f32>,
    /// Clear coat roughness (green channel).
    pub clearcoat_roughness: Mapped<f32>,
    /// The coat's own normal map and its scale.
    pub clearcoat_normal_map: Option<(ImageMap, f32)>,
    /// Sheen colour (`KHR_materials_sheen`).
    pub sheen_color: Mapped<[f32; 3]>,
    /// Sheen roughness (alpha channel).
    pub sheen_roughness: Mapped<f32>,
}

impl Default for MeshMaterial {
    /// A grey, rough dielectric: what a file's surfaces without a material
    /// are.
    fn default() -> Self {
        Self {
            name: String::new(),
            base_color: Mapped::value([0.8; 3]),
            alpha: Mapped::value(1.0),
            alpha_mode: AlphaMode::Opaque,
            vertex_color: false,
            metallic: Mapped::value(0.0),
            roughness: Mapped::value(1.0),
            roughness_from_gloss: false,
            normal_map: None,
            bump_map: None,
            emission: Mapped::value([0.0; 3]),
            double_sided: false,
            ior: super::DEFAULT_IOR,
            specular: Mapped::value(1.0),
            specular_color: Mapped::value([1.0; 3]),
            transmission: Mapped::value(0.0),
            thickness: Mapped::value(0.0),
            attenuation_color: [1.0; 3],
            attenuation_distance: f32::INFINITY,
            clearcoat: Mapped::value(0.0),
            clearcoat_roughness: Mapped::value(0.0),
            clearcoat_normal_map: None,
            sheen_color: Mapped::value([0.0; 3]),
            sheen_roughness: Mapped::value(0.0),
        }
    }
}

impl MeshMaterial {
    /// The image maps it uses.
    pub fn maps(&self) -> impl Iterator<Item = &ImageMap> {
        let scalars = [
            &self.alpha,
            &self.metallic,
            &self.roughness,
            &self.specular,
            &self.transmission,
            &self.thickness,
            &self.clearcoat,
            &self.clearcoat_roughness,
            &self.sheen_roughness,
        ];
        let colors = [
            &self.base_color,
            &self.emission,
            &self.specular_color,
            &self.sheen_color,
        ];
        scalars
            .into_iter()
            .filter_map(|m| m.map.as_ref())
            .chain(colors.into_iter().filter_map(|m| m.map.as_ref()))
            .chain(
                [&self.normal_map, &self.bump_map, &self.clearcoat_normal_map]
                    .into_iter()
                    .filter_map(|m| m.as_ref().map(|(map, _)| map)),
            )
    }

    /// Whether a normal or bump map needs the surface's tangents.
    pub fn needs_tangents(&self) -> bool {
        self.normal_map.is_some() || self.clearcoat_normal_map.is_some()
    }
}
