//! The path of one ray, from the camera to the sky, in one function.

use crate::math::{Color, Interval};
use crate::ray::Ray;
use crate::rng::Rng;
use crate::scene::{Scene, Shading};

/// Traces one camera ray and returns the colour it carries back.
///
/// `rays` is increased by the number of ray segments traced (for statistics).
#[inline]
pub fn radiance(scene: &Scene, ray: Ray, rng: &mut Rng, rays: &mut u64) -> Color {
    match scene.settings.shading {
        Shading::Path => trace_path(scene, ray, rng, rays),
        shading => first_hit_view(scene, ray, shading, rays),
    }
}

/// Path tracing: the ray bounces from surface to surface, each bounce
/// multiplying its colour by the surface's attenuation, until it escapes to
/// the background (which lights it), is absorbed (black), or reaches
/// `max_depth` segments (black: it never found light in time).
///
/// Always inlined, with the BVH traversal, into the render loop, so that the
/// loop's instruction-set versions (`render::Isa`) cover the whole path.
#[inline(always)]
fn trace_path(scene: &Scene, mut ray: Ray, rng: &mut Rng, rays: &mut u64) -> Color {
    let settings = &scene.settings;
    // Hits closer than epsilon are the surface the ray leaves from, seen again
    // through rounding error: counting them is what causes shadow acne.
    let range = Interval::new(settings.epsilon, f32::INFINITY);
    let mut throughput = Color::ONE;
    for _ in 0..settings.max_depth {
        *rays += 1;
        let Some(hit) = scene.hit(&ray, range) else {
            return throughput * scene.background.color(ray.direction);
        };
        let material = &scene.materials[hit.material as usize];
        let Some(scatter) = material.scatter(ray.direction, &hit, rng) else {
            return Color::ZERO;
        };
        throughput *= scatter.attenuation;
        if throughput == Color::ZERO {
            return Color::ZERO;
        }
        ray = Ray::new(hit.point, scatter.direction);
    }
    Color::ZERO
}

/// The debugging views of the notes' first chapters: what the camera ray hits
/// first, shown as a flat colour or as its normal.
fn first_hit_view(scene: &Scene, ray: Ray, shading: Shading, rays: &mut u64) -> Color {
    *rays += 1;
    let range = Interval::new(scene.settings.epsilon, f32::INFINITY);
    let Some(hit) = scene.hit(&ray, range) else {
        return scene.background.color(ray.direction);
    };
    let sphere = &scene.spheres[hit.object as usize];
    let outward = sphere.outward_normal(hit.point);
    match shading {
        Shading::Hit => Color::new(1.0, 0.0, 0.0),
        Shading::NormalsUnit => outward,
        Shading::NormalsRaw => outward * sphere.radius,
        Shading::NormalsBrightened | Shading::Path => 0.5 * (outward + Color::ONE),
    }
}
