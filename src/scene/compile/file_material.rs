//! A mesh file's material ([`MeshMaterial`]: glTF's, or MTL's mapped onto
//! glTF's terms) compiled to a principled material: each factor a
//! constant, each map a texture of the scene's table (times its factor),
//! alpha an opacity, the normal map the material's shape, emission added.

use crate::material::roughness::Roughness;
use crate::material::{
    ColorParam, Diffuse, Emission, Kind, Material, Opacity, Principled, ScalarParam, Shape,
};
use crate::math::Color;
use crate::mesh::{AlphaMode, Mapped, MeshMaterial};
use crate::texture::{ImageMap, Texture};
use std::sync::Arc;

/// The material surfaces of a file without materials have: grey and
/// matte, as lumen has always rendered them.
pub(super) fn no_material() -> Material {
    Material::new(Kind::Diffuse(Diffuse::lambertian(Color::splat(0.8))))
}

/// `m` compiled; its maps are added to `textures`.
pub(super) fn compile(m: &MeshMaterial, textures: &mut Vec<Texture>) -> Material {
    let mut table = Table { textures };
    let unit = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let roughness = if m.roughness_from_gloss {
        let gloss = table.scalar(&m.roughness);
        match gloss {
            ScalarParam::Texture(t) => {
                ScalarParam::Texture(table.push(Texture::Inverted { texture: t }))
            }
            ScalarParam::Const(g) => ScalarParam::Const(1.0 - g),
        }
    } else {
        table.scalar(&m.roughness)
    };
    let thin = m.thickness.value == 0.0 && m.thickness.map.is_none();
    let absorption = (!thin && m.attenuation_distance.is_finite() && m.attenuation_distance > 0.0)
        .then(|| {
            Color::from_array(m.attenuation_color)
                .map(|c| -c.max(1e-6).ln() / m.attenuation_distance)
        })
        .filter(|s| *s != Color::ZERO);
    let principled = Principled {
        base_color: table.color(&m.base_color, unit),
        vertex_color: m.vertex_color,
        metallic: table.scalar(&m.metallic),
        roughness: Roughness {
            u: roughness,
            v: roughness,
            squared: true,
            ..Roughness::SMOOTH
        },
        ior: m.ior,
        specular: table.scalar(&m.specular),
        specular_color: table.color(&m.specular_color, |x| x.max(0.0)),
        transmission: table.scalar(&m.transmission),
        thickness: table.scalar(&m.thickness),
        absorption,
        clearcoat: table.scalar(&m.clearcoat),
        clearcoat_roughness: table.scalar(&m.clearcoat_roughness),
        coat_normal: m
            .clearcoat_normal_map
            .as_ref()
            .map(|(map, scale)| (table.map(map), *scale)),
        sheen_color: table.color(&m.sheen_color, unit),
        sheen_roughness: table.scalar(&m.sheen_roughness),
        multiscatter: false,
    };
    let mut material = Material::new(Kind::Principled(Box::new(principled)));
    let emission = table.color(
        &m.emission,
        |x| if x > 0.0 && x.is_finite() { x } else { 0.0 },
    );
    if emission != ColorParam::Const(Color::ZERO) {
        material.emission = Some(Emission {
            radiance: emission,
            two_sided: m.double_sided,
        });
    }
    material.shape = match (&m.normal_map, &m.bump_map) {
        (Some((map, scale)), _) => Some(Shape::Normal {
            texture: table.map(map),
            scale: *scale,
        }),
        (None, Some((map, scale))) => Some(Shape::Bump {
            texture: table.map(map),
            scale: *scale,
        }),
        (None, None) => None,
    };
    material.opacity = match m.alpha_mode {
        AlphaMode::Opaque => None,
        mode => {
            let value = table.scalar(&m.alpha);
            let cutoff = match mode {
                AlphaMode::Mask(c) => Some(c),
                _ => None,
            };
            // A constant 1 with no vertex colours is all there.
            let whole = value == ScalarParam::Const(1.0) && !m.vertex_color;
            (!whole).then_some(Opacity {
                value,
                cutoff,
                vertex: m.vertex_color,
            })
        }
    };
    material
}

/// The scene's texture table as a file's materials add to it.
struct Table<'t> {
    textures: &'t mut Vec<Texture>,
}

impl Table<'_> {
    fn push(&mut self, t: Texture) -> u32 {
        self.textures.push(t);
        self.textures.len() as u32 - 1
    }

    fn map(&mut self, map: &ImageMap) -> u32 {
        self.push(Texture::Map(Arc::new(map.clone())))
    }

    /// A scalar factor times its map.
    fn scalar(&mut self, p: &Mapped<f32>) -> ScalarParam {
        let value = if p.value.is_nan() { 0.0 } else { p.value };
        match &p.map {
            None => ScalarParam::Const(value),
            Some(map) => {
                let t = self.map(map);
                ScalarParam::Texture(if value == 1.0 {
                    t
                } else {
                    self.push(Texture::Scaled {
                        texture: t,
                        factor: Color::splat(value),
                    })
                })
            }
        }
    }

    /// A colour factor (each channel passed through `fix`) times its map.
    fn color(&mut self, p: &Mapped<[f32; 3]>, fix: impl Fn(f32) -> f32) -> ColorParam {
        let value = Color::from_array(p.value.map(fix));
        match &p.map {
            None => ColorParam::Const(value),
            Some(map) => {
                let t = self.map(map);
                ColorParam::Texture(if value == Color::ONE {
                    t
                } else {
                    self.push(Texture::Scaled {
                        texture: t,
                        factor: value,
                    })
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Image;

    /// The coat's normal map keeps its scale (glTF's
    /// `clearcoatNormalTexture.scale`) and refers to the map's texture.
    #[test]
    fn the_coats_normal_map_keeps_its_scale() {
        let image = Arc::new(Image::from_rgba8(1, 1, vec![[128, 128, 255, 255]]));
        let m = MeshMaterial {
            clearcoat: Mapped::value(1.0),
            clearcoat_normal_map: Some((ImageMap::color(image), 0.5)),
            ..MeshMaterial::default()
        };
        let mut textures = Vec::new();
        let material = compile(&m, &mut textures);
        match &material.kind {
            Kind::Principled(p) => {
                let (texture, scale) = p.coat_normal.expect("the coat's normal map");
                assert_eq!(scale, 0.5);
                assert!((texture as usize) < textures.len());
            }
            other => panic!("compiled to {other:?}"),
        }
    }
}
