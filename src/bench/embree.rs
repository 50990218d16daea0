//! The same recorded rays traced by Intel's Embree 3 (the `embree` cargo
//! feature, a benchmark-only binding never in the default build): the bar
//! for lumen's tree in [`super::traversal`].
//!
//! Spheres are Embree's sphere points, quads its quads, triangles its
//! triangles, each kind one geometry, attached in lumen's order of items so
//! that a hit names the same shape in both. The scene is built at Embree's
//! high quality, as for a static scene rendered many times, and rays are
//! traced one at a time (`rtcIntersect1`) with the incoherent context, which
//! is Embree's best configuration for a path tracer's rays.

use super::traversal::Found;
use crate::ray::Ray;
use crate::scene::PlacedShapes;
use embree3::{
    BufferUsage, BuildQuality, Config, Device, Format, GeometryKind, IntersectContext, Isa, RayHit,
    Scene, INVALID_ID,
};
use std::time::{Duration, Instant};

/// The widest instructions Embree may choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EmbreeIsa {
    /// AVX2 (8-wide).
    Avx2,
    /// AVX-512 (16-wide), where the processor has it.
    Avx512,
}

/// An Embree scene over a lumen scene's shapes.
pub struct EmbreeScene {
    scene: Scene<'static>,
    /// The first item number of each attached geometry, by geometry id.
    first_item: Vec<u32>,
    _device: Device,
}

impl EmbreeScene {
    /// Builds Embree's tree over `shapes`, Embree choosing its instructions
    /// up to `isa`.
    pub fn new(shapes: &PlacedShapes, isa: EmbreeIsa) -> Result<EmbreeScene, String> {
        let config = Config {
            max_isa: match isa {
                EmbreeIsa::Avx2 => Isa::Avx2,
                EmbreeIsa::Avx512 => Isa::Avx512,
            },
            ..Config::default()
        };
        let device = Device::with_config(config).map_err(|e| format!("Embree device: {e:?}"))?;
        let mut scene = device
            .create_scene()
            .map_err(|e| format!("Embree scene: {e:?}"))?;
        scene.set_build_quality(BuildQuality::HIGH);
        let mut first_item = Vec::new();
        let mut next = 0u32;
        let fail = |what: &str, e: embree3::Error| format!("Embree {what}: {e:?}");
        if !shapes.spheres.is_empty() {
            let mut g = device
                .create_geometry(GeometryKind::SPHERE_POINT)
                .map_err(|e| fail("spheres", e))?;
            g.set_new_buffer::<[f32; 4]>(
                BufferUsage::VERTEX,
                0,
                Format::FLOAT4,
                16,
                shapes.spheres.len(),
            )
            .map_err(|e| fail("sphere buffer", e))?
            .copy_from_slice(&shapes.spheres);
            scene.attach_geometry(&g.commit());
            first_item.push(next);
            next += shapes.spheres.len() as u32;
        }
        for (kind, polygons) in [
            (GeometryKind::QUAD, Polygons::Quads(&shapes.quads)),
            (
                GeometryKind::TRIANGLE,
                Polygons::Triangles(&shapes.triangles),
            ),
        ] {
            if polygons.len() == 0 {
                continue;
            }
            let mut g = device
                .create_geometry(kind)
                .map_err(|e| fail("geometry", e))?;
            let (vertices, index) = polygons.buffers();
            let corners = polygons.corners();
            g.set_new_buffer::<[f32; 3]>(
                BufferUsage::VERTEX,
                0,
                Format::FLOAT3,
                12,
                vertices.len(),
            )
            .map_err(|e| fail("vertices", e))?
            .copy_from_slice(&vertices);
            let format = if corners == 4 {
                Format::UINT4
            } else {
                Format::UINT3
            };
            g.set_new_buffer::<u32>(BufferUsage::INDEX, 0, format, 4 * corners, polygons.len())
                .map_err(|e| fail("index", e))?
                .copy_from_slice(&index);
            scene.attach_geometry(&g.commit());
            first_item.push(next);
            next += polygons.len() as u32;
        }
        scene.commit();
        Ok(EmbreeScene {
            scene,
            first_item,
            _device: device,
        })
    }

    /// Traces `rays` one at a time for their nearest hits from distance 0;
    /// returns them and the time taken.
    pub fn trace(&self, rays: &[Ray]) -> (Vec<Found>, Duration) {
        let mut found = Vec::with_capacity(rays.len());
        let mut context = IntersectContext::incoherent();
        let start = Instant::now();
        for ray in rays {
            let mut query = RayHit::from(embree3::Ray::segment(
                ray.origin().to_array(),
                ray.direction.to_array(),
                0.0,
                f32::INFINITY,
            ));
            self.scene.intersect(&mut context, &mut query);
            let hit = &query.hit;
            found.push((hit.geomID != INVALID_ID).then(|| {
                (
                    query.ray.tfar,
                    self.first_item[hit.geomID as usize] + hit.primID,
                )
            }));
        }
        (found, start.elapsed())
    }
}

/// Quads or triangles, as the scene places them.
enum Polygons<'a> {
    Quads(&'a [[[f32; 3]; 4]]),
    Triangles(&'a [[[f32; 3]; 3]]),
}

impl Polygons<'_> {
    fn len(&self) -> usize {
        match self {
            Polygons::Quads(q) => q.len(),
            Polygons::Triangles(t) => t.len(),
        }
    }

    fn corners(&self) -> usize {
        match self {
            Polygons::Quads(_) => 4,
            Polygons::Triangles(_) => 3,
        }
    }

    /// Every polygon's corners, one after another, and the index buffer
    /// naming them in order.
    fn buffers(&self) -> (Vec<[f32; 3]>, Vec<u32>) {
        let vertices: Vec<[f32; 3]> = match self {
            Polygons::Quads(q) => q.iter().flatten().copied().collect(),
            Polygons::Triangles(t) => t.iter().flatten().copied().collect(),
        };
        let index = (0..vertices.len() as u32).collect();
        (vertices, index)
    }
}
