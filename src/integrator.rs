//! The path of one ray, from the camera to the sky, in one function
//! ([`trace_path`]), and the same for a group of camera rays of one pixel
//! traced side by side ([`trace_paths`]), which is how the renderer runs it.

use crate::aov::{Features, Layer, Layers};
use crate::bsdf::{Bsdf, LobeFlags};
use crate::geometry::bvh::Hit;
use crate::geometry::bvh_bundle::LANES;
use crate::geometry::HitRecord;
use crate::halt::Halt;
use crate::material::Material;
use crate::math::{Color, Interval, Point3, Vec3};
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampler::{Dim, Sampler};
use crate::scene::{Integrator, Scene, Shading};
use crate::volume::Event;

/// Paths traced side by side by [`trace_paths`].
pub const PATHS: usize = 32;

/// The fewest rays worth tracing as a bundle: below this, one at a time is
/// faster (a bundle costs about as much as three or four single rays).
const MIN_BUNDLE: usize = 4;

/// Traces one camera ray and returns the colour it carries back.
///
/// `rays` is increased by the number of ray segments traced (for statistics).
#[inline]
pub fn radiance(scene: &Scene, ray: Ray, sampler: &mut impl Sampler, rays: &mut u64) -> Color {
    match scene.settings.shading {
        Shading::Path => trace_path(scene, ray, sampler, rays),
        shading => first_hit_view(scene, ray, shading, rays),
    }
}

/// Every distance along a ray: hits count from 0 (but see
/// [`Scene::intersect_leaving`]).
const ALL: Interval = Interval::new(0.0, f32::INFINITY);

/// What becomes of a path at the end of one segment.
enum Step {
    /// It goes on along this ray, leaving the surface of this hit (none
    /// where it left a particle of a medium): closer than the epsilon, that
    /// surface is not met again (see [`Scene::intersect_leaving`]).
    Continue(Ray, Option<Hit>),
    /// It ends, carrying this colour back.
    Done(Color),
}

/// A path on its way: what it carries and what it has gathered.
#[derive(Clone, Copy, Debug)]
struct PathState {
    /// The product of the attenuations so far.
    throughput: Color,
    /// The light gathered so far, already multiplied by the throughput at
    /// which it was met.
    radiance: Color,
    /// Where the current segment started, when a light was sampled there:
    /// the point, and the density (per unit solid angle) with which the
    /// bounce chose the segment's direction. A light this segment meets
    /// could also have been sampled from there, and counts only for its
    /// share of the two strategies.
    sampled_from: Option<(Point3, f32)>,
    /// Shadow rays and crossings of interfaces traced (for statistics).
    shadow_rays: u64,
    /// The medium the path travels in (an index in the scene's
    /// [`volumes`](Scene::volumes)), none in empty space.
    medium: Option<u32>,
}

/// A camera path's search for what the feature buffers hold (see
/// [`crate::aov`]), kept beside the path only in a render that keeps them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FeatureSearch {
    /// What the path found so far.
    pub features: Features,
    /// Whether it still looks for the albedo and normal: until it meets a
    /// surface that is not a delta.
    seeking: bool,
    /// Whether it still looks for the first visible surface (its depth and
    /// position).
    placing: bool,
    /// The tint of the delta surfaces followed while seeking.
    tint: Color,
}

impl PathState {
    /// A path leaving the camera of `scene`.
    #[inline(always)]
    fn start(scene: &Scene) -> PathState {
        PathState {
            throughput: Color::ONE,
            radiance: Color::ZERO,
            sampled_from: None,
            shadow_rays: 0,
            medium: scene.camera_medium,
        }
    }
}

impl FeatureSearch {
    /// The search of a path leaving the camera, for what `layers` need
    /// (the features no layer keeps are left at 0).
    pub fn start(layers: Layers) -> FeatureSearch {
        FeatureSearch {
            features: Features::default(),
            seeking: layers.has(Layer::Albedo) || layers.has(Layer::Normal),
            placing: layers.has(Layer::Depth) || layers.has(Layer::Position),
            tint: Color::ONE,
        }
    }

    /// Whether it still looks for something.
    #[inline(always)]
    fn is_open(&self) -> bool {
        self.seeking || self.placing
    }

    /// The features are those of a surface of albedo `albedo` (before the
    /// tint of the deltas followed) and shading normal `normal`, on the
    /// side the path came from.
    #[inline(always)]
    fn seen(&mut self, albedo: Color, normal: Vec3) {
        self.features.albedo = (self.tint * albedo).clamp(Color::ZERO, Color::ONE);
        self.features.normal = normal;
        self.seeking = false;
    }

    /// The path's segment of `length` ends at `point`, on a surface that is
    /// the first visible one if `visible` (the length then completes the
    /// depth, adding to those of the invisible ones crossed before).
    #[cold]
    #[inline(never)]
    fn placed(&mut self, point: Point3, length: f32, visible: bool) {
        self.features.depth += length;
        if visible {
            self.features.position = point;
            self.placing = false;
        }
    }
}

/// The most interfaces a path crosses between two bounces before it is
/// given up (a bound on the work of a ray caught between surfaces that
/// round it back and forth).
const MAX_CROSSINGS: u32 = 1024;

/// The power heuristic (β = 2): the weight of a strategy that chose a
/// sample with density `a` when another could have chosen it with density
/// `b`.
#[inline]
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    // Where the other strategy cannot make the sample, this one has it all.
    if a2.is_infinite() || b2 == 0.0 {
        1.0
    } else {
        a2 / (a2 + b2)
    }
}

/// The end of segment `depth` (0 for the camera ray) of a path: `ray` met
/// `hit` (or nothing, and the background lights it). The surface's emission
/// is added to what the path gathered; its material absorbs the path or
/// scatters it (bounce `depth`), multiplying the throughput by the sample's
/// value, unless this is the path's last segment, whose bounce could only
/// start a ray that is never traced. With the `path` integrator, a surface whose scattering has
/// a density (see [`Bsdf::has_density`]) also samples a light
/// (next-event estimation): a shadow ray towards a point chosen on it, the
/// light it brings weighted against the chance that the bounce would have
/// found the same light (multiple importance sampling).
///
/// In a scene with [`volumes`](Scene::volumes) the path also travels
/// through the medium it is in, which may scatter it before the surface
/// (see [`crate::volume::Volume::sample`]), and it crosses interfaces and thin
/// glass straight on without counting a bounce, into the medium beyond.
#[inline(always)]
fn step(
    scene: &Scene,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    path: &mut PathState,
    sampler: &mut impl Sampler,
    mut search: Option<&mut FeatureSearch>,
) -> Step {
    let (mut ray, mut hit) = (*ray, hit);
    for _ in 0..MAX_CROSSINGS {
        if !scene.media.is_empty() || path.medium.is_some() {
            if let Some(step) = through_media(scene, &ray, hit, depth, path, sampler) {
                if let (Some(s), Step::Continue(_, None)) = (&mut search, &step) {
                    // Scattered by a particle before any surface.
                    if s.seeking {
                        s.seen(Color::ONE, Vec3::ZERO);
                    }
                }
                return step;
            }
        }
        match bounce(
            scene,
            &ray,
            hit,
            depth,
            path,
            sampler,
            search.as_deref_mut(),
        ) {
            Bounce::Step(step) => return step,
            Bounce::Cross(next, left) => {
                path.shadow_rays += 1;
                hit = scene.intersect_leaving(&next, Some(&left), f32::INFINITY);
                ray = next;
            }
        }
    }
    Step::Done(path.radiance)
}

/// What a surface does with a path.
enum Bounce {
    /// It scatters it or ends it.
    Step(Step),
    /// The path crosses it straight on, along this ray, leaving this hit
    /// (an interface, a thin sheet of glass in a scene with media).
    Cross(Ray, Hit),
}

/// The media `ray` crosses before `hit`: the scene's fog (each draws how
/// far the ray gets into it, and the nearest particle counts), then the
/// medium the path is in. A step where a particle scatters or absorbs the
/// path (see [`scatter_at`]); otherwise the throughput takes what got
/// through.
#[inline(never)]
fn through_media(
    scene: &Scene,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    path: &mut PathState,
    sampler: &mut impl Sampler,
) -> Option<Step> {
    sampler.start_bounce(depth);
    let t_max = hit.map_or(f32::INFINITY, |h| h.t);
    if let Some((t, i)) = scene.medium_event(ray, t_max, sampler) {
        let albedo = scene.media[i].albedo;
        let phase = Phase::Isotropic;
        return Some(scatter_at(
            scene, ray, t, albedo, phase, depth, path, sampler,
        ));
    }
    let medium = path.medium?;
    let volume = &scene.volumes[medium as usize];
    match volume.sample(ray, t_max, sampler) {
        Event::Pass { weight } => {
            path.throughput *= weight;
            None
        }
        Event::Scatter { t, weight } => {
            path.throughput *= weight;
            let phase = volume.phase;
            Some(scatter_at(
                scene,
                ray,
                t,
                Color::ONE,
                phase,
                depth,
                path,
                sampler,
            ))
        }
        Event::Absorbed => Some(Step::Done(path.radiance)),
    }
}

/// The surface `ray` meets at `hit` (or the sky, where it meets none)
/// at the end of segment `depth`: see [`step`].
#[inline(always)]
fn bounce(
    scene: &Scene,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    path: &mut PathState,
    sampler: &mut impl Sampler,
    search: Option<&mut FeatureSearch>,
) -> Bounce {
    let done = |c| Bounce::Step(Step::Done(c));
    let Some(hit) = hit else {
        let background = scene.background.color(ray.direction);
        if let Some(s) = search.filter(|s| s.seeking) {
            s.seen(background, Vec3::ZERO);
        }
        let mut sky = path.throughput * background;
        if let Some((_, bsdf_pdf)) = path.sampled_from {
            sky *= power_heuristic(bsdf_pdf, scene.lights.environment_pdf(ray.direction));
        }
        if scene.lights.sources_seen() {
            sky += path.throughput * discs_of_sky(scene, ray.direction, path.sampled_from);
        }
        return done(path.radiance + sky);
    };
    let record = scene.record(ray, hit);
    let material = scene.material(&record);
    if !record.front_face {
        if let Some(sigma) = material.absorption(&record, &scene.textures) {
            // The segment ran inside an absorbing volume (Beer–Lambert).
            path.throughput *= (-sigma * hit.t).exp();
        }
    }
    if material.emission.is_some() {
        path.radiance += emission(scene, &record, &hit, material, path);
    }
    let mut search = search;
    if let Some(s) = search.as_deref_mut().filter(|s| s.placing) {
        // Interfaces are invisible: their segments add to the depth.
        s.placed(
            record.point,
            hit.t * ray.direction.length(),
            !material.is_interface(),
        );
    }
    if material.is_interface() {
        return cross(ray, &record, hit, material, path);
    }
    let mut search = search.filter(|s| s.seeking);
    // The last segment's bounce could only start a ray that is never
    // traced; in a scene with media it may still cross a sheet of glass.
    let last = depth + 1 >= scene.settings.max_depth;
    if last && !scene.volumetric && search.is_none() {
        return done(path.radiance);
    }
    let wo = -ray.direction;
    let Some(bsdf) = material.bsdf(&record, wo, &scene.textures) else {
        if let Some(s) = search {
            // A light without a surface.
            let n = record.shading_normal;
            s.seen(Color::ONE, if n.dot(wo) < 0.0 { -n } else { n });
        }
        return done(path.radiance);
    };
    if let Some(s) = search.as_deref_mut() {
        // Deltas and near mirrors are looked through.
        if let Some(albedo) = bsdf.lobe.feature_albedo_seen(bsdf.frame.to_local(wo)) {
            s.seen(albedo, bsdf.frame.n);
            search = None;
        }
    }
    if last && !scene.volumetric {
        return done(path.radiance);
    }
    sampler.start_bounce(depth);
    let nee = samples_lights(scene, depth) && bsdf.has_density();
    if nee {
        let (light, traced) =
            light_at_surface(scene, &record, &hit, &bsdf, wo, ray.time(), path, sampler);
        path.radiance += path.throughput * light;
        path.shadow_rays += u64::from(traced);
    }
    let Some(sample) = bsdf.sample(wo, sampler) else {
        return done(path.radiance);
    };
    if scene.volumetric && sample.flags.contains(LobeFlags::STRAIGHT) {
        path.throughput *= sample.value;
        return cross(ray, &record, hit, material, path);
    }
    if last {
        return done(path.radiance);
    }
    path.sampled_from = (nee && !sample.flags.is_specular()).then_some((record.point, sample.pdf));
    path.throughput *= sample.value;
    if let Some(s) = search {
        s.tint *= sample.value;
    }
    path.medium = material.medium_beyond(&record, sample.wi, path.medium);
    if !goes_on(scene, depth, path, sampler) {
        return done(path.radiance);
    }
    Bounce::Step(Step::Continue(
        Ray::timed(record.spawn_origin(sample.wi), sample.wi, ray.time()),
        Some(hit),
    ))
}

/// The path crosses the surface at `record` (of `hit`, made of `material`)
/// straight on, into the medium beyond it.
#[inline(never)]
fn cross(
    ray: &Ray,
    record: &HitRecord,
    hit: Hit,
    material: &Material,
    path: &mut PathState,
) -> Bounce {
    let d = ray.direction;
    path.medium = material.medium_beyond(record, d, path.medium);
    Bounce::Cross(Ray::timed(record.spawn_origin(d), d, ray.time()), hit)
}

/// The radiance of the discs of the sky (directional lights with an
/// angular radius) seen along unit `direction` by an escaping ray, each
/// weighted, where the segment's start sampled a light (`sampled_from`),
/// against the chance that it would have sampled that direction towards
/// the disc.
#[inline(never)]
fn discs_of_sky(scene: &Scene, direction: Vec3, sampled_from: Option<(Point3, f32)>) -> Color {
    scene
        .lights
        .seen_along(direction)
        .map(|(radiance, light_pdf)| match sampled_from {
            Some((_, bsdf_pdf)) => radiance * power_heuristic(bsdf_pdf, light_pdf),
            None => radiance,
        })
        .sum()
}

/// The light a path brings back from an emitter it met at `record` (`hit`):
/// its emission times the path's throughput, weighted against the chance
/// that the light would have been sampled from where the segment started.
#[inline(never)]
fn emission(
    scene: &Scene,
    record: &HitRecord,
    hit: &Hit,
    material: &Material,
    path: &PathState,
) -> Color {
    let emitted = path.throughput * material.emitted(record, &scene.textures);
    match (path.sampled_from, scene.light_of(hit)) {
        (Some((from, bsdf_pdf)), Some(i)) => {
            let light_pdf = scene
                .lights
                .pdf(i, from, record.point, record.outward_normal());
            emitted * power_heuristic(bsdf_pdf, light_pdf)
        }
        _ => emitted,
    }
}

/// [`direct_light`] at a surface point `record` (of `hit`) scattering by
/// `bsdf`, seen from `wo` (pointing back along the ray).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn light_at_surface(
    scene: &Scene,
    record: &HitRecord,
    hit: &Hit,
    bsdf: &Bsdf,
    wo: Vec3,
    time: f32,
    path: &PathState,
    sampler: &mut impl Sampler,
) -> (Color, bool) {
    direct_light(
        scene,
        record.point,
        time,
        |wi| bsdf.eval_and_pdf(wo, wi),
        |wi| record.spawn_origin(wi),
        // Asked only in scenes with media.
        |wi| {
            scene
                .material(record)
                .medium_beyond(record, wi, path.medium)
        },
        Some(hit),
        sampler,
    )
}

/// A path meets a particle at distance `t` along `ray` (the end of
/// segment `depth`), which scatters `albedo` of the light (1 for a medium
/// whose tracking weighted the throughput already) by `phase`: with the
/// `path` integrator it samples a light from there, and it goes on in a
/// direction drawn from the phase function, its throughput multiplied by
/// the albedo.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn scatter_at(
    scene: &Scene,
    ray: &Ray,
    t: f32,
    albedo: Color,
    phase: Phase,
    depth: u32,
    path: &mut PathState,
    sampler: &mut impl Sampler,
) -> Step {
    // The last segment's scattering could only start a ray never traced.
    if depth + 1 >= scene.settings.max_depth {
        return Step::Done(path.radiance);
    }
    let point = ray.at(t);
    let nee = samples_lights(scene, depth);
    if nee {
        let inside = path.medium;
        let (light, traced) = direct_light(
            scene,
            point,
            ray.time(),
            |wi| {
                let p = phase.pdf(ray.direction, wi);
                (albedo * p, p)
            },
            |_| point,
            |_| inside,
            None,
            sampler,
        );
        path.radiance += path.throughput * light;
        path.shadow_rays += u64::from(traced);
    }
    let (direction, pdf) = phase.sample(ray.direction, sampler.get_2d(Dim::Bsdf));
    path.sampled_from = nee.then_some((point, pdf));
    path.throughput *= albedo;
    if !goes_on(scene, depth, path, sampler) {
        return Step::Done(path.radiance);
    }
    Step::Continue(Ray::timed(point, direction, ray.time()), None)
}

/// Whether the path, its throughput updated by the scattering at the end
/// of segment `depth`, goes on: not if nothing is left of it, or if Russian
/// roulette ends it.
#[inline(always)]
fn goes_on(scene: &Scene, depth: u32, path: &mut PathState, sampler: &mut impl Sampler) -> bool {
    if path.throughput == Color::ZERO {
        return false;
    }
    // Russian roulette: a path whose throughput has fallen below 1 goes on
    // with that probability, and is counted 1/p times as much when it does.
    if roulette(scene, depth) {
        let p = path.throughput.max_element().sqrt();
        if p < 1.0 {
            if sampler.get_1d(Dim::Roulette) >= p {
                return false;
            }
            path.throughput /= p;
        }
    }
    true
}

/// Bounces from which the `path` integrator plays Russian roulette: the
/// first ones carry most of the light and are always continued.
pub const ROULETTE_FROM: u32 = 5;

/// Whether the bounce at the end of segment `depth` plays Russian roulette:
/// with the `path` integrator, from bounce [`ROULETTE_FROM`] on.
#[inline(always)]
fn roulette(scene: &Scene, depth: u32) -> bool {
    scene.settings.integrator == Integrator::Path && depth >= ROULETTE_FROM
}

/// Whether a bounce at the end of segment `depth` samples a light: with the
/// `path` integrator, when the scene has lights (the environment among
/// them, unless it is black) and the shadow ray (segment `depth + 1`) is
/// within the path's length.
#[inline(always)]
fn samples_lights(scene: &Scene, depth: u32) -> bool {
    scene.settings.integrator == Integrator::Path
        && !scene.lights.is_empty()
        && depth + 1 < scene.settings.max_depth
}

/// The light arriving at `point` (at `time`) from a point sampled on a
/// light, scattered towards the path, weighted by the power heuristic
/// against the path's own chance of finding it by scattering; and whether a
/// shadow ray was traced.
///
/// `scatter` gives, for a direction, what the scattering (a surface's or a
/// particle's) sends towards the path per unit light arriving from it
/// (f · |cos θ| for a surface) and the density with which it would scatter
/// there itself (0 where it cannot); `spawn` where a ray leaving along a
/// direction starts (a surface's rounding bound off it); `medium` the
/// medium a ray leaving along a direction travels in; `from` the surface's
/// hit (none at a particle).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn direct_light(
    scene: &Scene,
    point: Point3,
    time: f32,
    scatter: impl Fn(Vec3) -> (Color, f32),
    spawn: impl Fn(Vec3) -> Point3,
    medium: impl Fn(Vec3) -> Option<u32>,
    from: Option<&Hit>,
    sampler: &mut impl Sampler,
) -> (Color, bool) {
    let Some(sample) = scene.lights.sample(point, sampler) else {
        return (Color::ZERO, false);
    };
    let wi = sample.direction;
    let (value, scatter_pdf) = scatter(wi);
    if !(scatter_pdf > 0.0) || sample.radiance == Color::ZERO {
        return (Color::ZERO, false);
    }
    // The shadow ray starts off the surface (moved by its rounding bound)
    // and is aimed from there at the light point, ending just short of it by
    // the point's own rounding: along `wi` from the moved start it would
    // meet a light's plane before the point, and the light would shadow
    // itself (far from the origin, where the rounding bounds grow). The
    // environment is infinitely far along `wi`.
    let origin = spawn(wi);
    let (shadow, end) = if sample.distance.is_infinite() {
        (Ray::timed(origin, wi, time), f32::INFINITY)
    } else {
        let to = sample.point - origin;
        let length = to.length();
        let end = length * (1.0 - 1e-4) - sample.point.abs().max_element() * 1e-6;
        (Ray::timed(origin, to / length, time), end)
    };
    if !(end > 0.0) {
        // At the start: out of reach.
        return (Color::ZERO, false);
    }
    // In a scene with media the shadow ray crosses interfaces and thin
    // glass, and takes what gets through them and the media between.
    let share = if scene.volumetric {
        scene.transmittance_along(&shadow, from, end, medium(wi), sampler)
    } else if scene.occluded_leaving(&shadow, from, end) {
        Color::ZERO
    } else {
        Color::ONE
    };
    if share == Color::ZERO {
        return (Color::ZERO, true);
    }
    // No bounce finds a delta light: its sample has all the weight.
    let weight = if sample.delta {
        1.0
    } else {
        power_heuristic(sample.pdf, scatter_pdf)
    };
    let mut light = sample.radiance * value * (weight / sample.pdf) * share;
    if !scene.media.is_empty() {
        light *= scene.transmittance(&shadow, end);
    }
    (light, true)
}

/// Path tracing: the ray bounces from surface to surface, each bounce
/// multiplying its colour by the surface's attenuation, until it escapes to
/// the background (which lights it), meets a light (an emissive surface,
/// which ends it), is absorbed, or reaches `max_depth` segments (it never
/// found light in time). With the `path` integrator each diffuse bounce
/// also looks for light directly (next-event estimation, in the private `step`).
#[inline(always)]
pub fn trace_path(scene: &Scene, ray: Ray, sampler: &mut impl Sampler, rays: &mut u64) -> Color {
    trace_path_features(scene, ray, sampler, rays).0
}

/// [`trace_path`], and what the path found for the feature buffers (see
/// [`crate::aov`]; all 0 unless the scene's render keeps them).
#[inline(always)]
pub fn trace_path_features(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut impl Sampler,
    rays: &mut u64,
) -> (Color, Features) {
    let mut path = PathState::start(scene);
    let mut search = FeatureSearch::start(scene.settings.layers);
    let searching = scene.settings.layers.need_features();
    let mut from = None;
    // A path still going after `max_depth` segments keeps what it gathered.
    let mut colour = None;
    for depth in 0..scene.settings.max_depth {
        *rays += 1;
        let mut hit = scene.intersect_leaving(&ray, from.as_ref(), f32::INFINITY);
        if depth == 0 && scene.camera.clips_far() {
            clip_far(scene, &ray, &mut hit);
        }
        let s = searching.then_some(&mut search);
        match step(scene, &ray, hit, depth, &mut path, sampler, s) {
            Step::Continue(next, left) => (ray, from) = (next, left),
            Step::Done(c) => {
                colour = Some(c);
                break;
            }
        }
    }
    *rays += path.shadow_rays;
    // Untouched (all 0) unless searched.
    (colour.unwrap_or(path.radiance), search.features)
}

/// How many rounds of bounces [`trace_paths`] runs between looks at its
/// `halt`.
const HALT_CHECK_ROUNDS: u32 = 256;

/// Ends camera ray `ray` at the camera's far plane: its nearest hit
/// `hit`, when beyond the plane, is none (the nearest before it would have
/// been the nearest of all).
#[cold]
#[inline(never)]
fn clip_far(scene: &Scene, ray: &Ray, hit: &mut Option<Hit>) {
    let end = scene.camera.far(ray);
    if hit.is_some_and(|h| h.t >= end) {
        *hit = None;
    }
}

/// [`trace_path`] for up to [`PATHS`] camera rays of one pixel at once,
/// each with its own sampler: `colours[i]` gets exactly what
/// `trace_path(scene, rays[i], &mut samplers[i], ..)` returns, and
/// `searches[i]`, where `searches` is not empty (the render keeps feature
/// buffers), what the path found for them ([`trace_path_features`]): each
/// search starts as [`FeatureSearch::start`] of the render's layers.
///
/// The paths advance together, one segment each per round, so that the rays
/// of a round can be traced as bundles (see
/// [`RayBundle`](crate::geometry::RayBundle)): a single ray's traversal
/// waits on one test after another, while a bundle keeps the processor busy
/// with eight: the camera rays in every scene (without cut-outs), the
/// bounces in scenes of spheres only ([`Scene::camera_bundles_pay_off`],
/// [`Scene::bundles_pay_off`]).
/// `reference` (the pixel's central ray) orders the visit of the first
/// round's bundles; later rounds use a ray of the bundle. Once `halt`
/// says to stop, the paths are left where they are within a few hundred
/// bounces, and `colours` are not to be used.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn trace_paths<S: Sampler>(
    scene: &Scene,
    rays: &mut [Ray],
    samplers: &mut [S],
    reference: &Ray,
    colours: &mut [Color],
    searches: &mut [FeatureSearch],
    traced: &mut u64,
    halt: &Halt,
) {
    let n = rays.len();
    assert!(n <= PATHS && samplers.len() == n && colours.len() == n);
    assert!(searches.is_empty() || searches.len() == n);
    // Two versions: one without a search compiles the search away.
    let out = (colours, searches, traced);
    if out.1.is_empty() {
        rounds::<S, false>(scene, rays, samplers, reference, out, halt);
    } else {
        rounds::<S, true>(scene, rays, samplers, reference, out, halt);
    }
}

/// The rounds of [`trace_paths`], with the features searched for if
/// `FEATURES`.
#[inline(always)]
fn rounds<S: Sampler, const FEATURES: bool>(
    scene: &Scene,
    rays: &mut [Ray],
    samplers: &mut [S],
    reference: &Ray,
    (colours, searches, traced): (&mut [Color], &mut [FeatureSearch], &mut u64),
    halt: &Halt,
) {
    let n = rays.len();
    let mut paths = [PathState::start(scene); PATHS];
    let mut hits = [None; PATHS];
    // The surface each path's ray leaves.
    let mut from: [Option<Hit>; PATHS] = [None; PATHS];
    // The paths still going, in order.
    let mut live: [u8; PATHS] = std::array::from_fn(|i| i as u8);
    let mut n_live = n;
    for round in 0..scene.settings.max_depth {
        *traced += n_live as u64;
        let reference = (round == 0).then_some(reference);
        find_hits(scene, rays, &from, &live[..n_live], reference, &mut hits);
        let mut still = 0;
        for k in 0..n_live {
            let i = live[k] as usize;
            let sampler = &mut samplers[i];
            let (ray, hit, path) = (&rays[i], hits[i], &mut paths[i]);
            // A finished search is no longer passed down the path, which
            // then takes the step compiled without one, as in a render
            // without features.
            let open = if FEATURES {
                searches.get_mut(i).filter(|s| s.is_open())
            } else {
                None
            };
            let next = match open {
                Some(search) => step(scene, ray, hit, round, path, sampler, Some(search)),
                None => step(scene, ray, hit, round, path, sampler, None),
            };
            match next {
                Step::Continue(next, left) => {
                    (rays[i], from[i]) = (next, left);
                    live[still] = i as u8;
                    still += 1;
                }
                Step::Done(colour) => colours[i] = colour,
            }
        }
        n_live = still;
        if n_live == 0 {
            break;
        }
        // A render asked to stop abandons its pass, and with it these
        // paths, which could run for minutes at a great depth.
        if round % HALT_CHECK_ROUNDS == HALT_CHECK_ROUNDS - 1 && halt.asked() {
            break;
        }
    }
    // Paths still going after `max_depth` segments keep what they gathered.
    for &i in &live[..n_live] {
        colours[i as usize] = paths[i as usize].radiance;
    }
    *traced += paths[..n].iter().map(|p| p.shadow_rays).sum::<u64>();
}

/// Sets `hits[i]` to the hit of `rays[i]`, which leaves the surface of hit
/// `from[i]`, for every path `i` of `live`: eight at a time as bundles
/// where they pay off (camera rays, `reference` given; bounces among
/// spheres), the few left over (and every ray elsewhere) one by one.
#[inline(always)]
fn find_hits(
    scene: &Scene,
    rays: &[Ray],
    from: &[Option<Hit>; PATHS],
    live: &[u8],
    reference: Option<&Ray>,
    hits: &mut [Option<Hit>; PATHS],
) {
    // Where bundles do not pay off, no group is large enough for one.
    let pays = scene.bundles_pay_off() || (reference.is_some() && scene.camera_bundles_pay_off());
    let min_bundle = if pays { MIN_BUNDLE } else { usize::MAX };
    for group in live.chunks(LANES) {
        if group.len() < min_bundle {
            for &i in group {
                let i = i as usize;
                hits[i] = scene.intersect_leaving(&rays[i], from[i].as_ref(), f32::INFINITY);
            }
            continue;
        }
        let reference = reference.unwrap_or(&rays[group[0] as usize]);
        let found = scene.hit_bundle(rays, group, reference, ALL);
        for (&i, hit) in group.iter().zip(found) {
            let i = i as usize;
            hits[i] = hit;
            scene.keep_counted(&rays[i], &mut hits[i], from[i].as_ref(), f32::INFINITY);
        }
    }
    if reference.is_some() && scene.camera.clips_far() {
        for &i in live {
            clip_far(scene, &rays[i as usize], &mut hits[i as usize]);
        }
    }
}

/// The debugging views of the notes' first chapters: what the camera ray hits
/// first, shown as a flat colour or as its normal.
pub(crate) fn first_hit_view(scene: &Scene, ray: Ray, shading: Shading, rays: &mut u64) -> Color {
    *rays += 1;
    let Some(hit) = scene.hit(&ray, ALL) else {
        return scene.background.color(ray.direction);
    };
    let outward = hit.outward_normal();
    match shading {
        Shading::Hit => Color::new(1.0, 0.0, 0.0),
        Shading::NormalsUnit => outward,
        // P − C: the unit normal times the radius, for spheres; other
        // shapes have no centre and show their unit normal.
        Shading::NormalsRaw => outward * scene.sphere_radius(hit.object).unwrap_or(1.0),
        Shading::NormalsBrightened | Shading::Path => 0.5 * (outward + Color::ONE),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{PixelSampler, SamplerKind};
    use crate::scene::builtin;

    /// Side by side, every path must come out exactly as it does alone: the
    /// same colour bits and the same number of segments, whatever the group
    /// size and depth limit, on scenes with every material and with every
    /// sampler.
    #[test]
    fn paths_side_by_side_equal_paths_one_at_a_time() {
        let bits = |c: &[Color]| {
            c.iter()
                .map(|c| c.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        // bouncing-spheres: moving instances, whose hits depend on each
        // ray's time.
        let names = [
            "cover",
            "glass-hollow",
            "metal-fuzz-0.5",
            "bounce-cube",
            "bouncing-spheres",
        ];
        let mut descs: Vec<_> = names
            .iter()
            .map(|name| builtin::find(name).expect("built-in").desc())
            .collect();
        // A mesh, whose camera rays go as bundles and its bounces one by one.
        let mut bunny =
            crate::bench::bunny_scene(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny.glb"));
        bunny.render.height = Some(24);
        descs.push(bunny);
        let kinds = [SamplerKind::Independent, SamplerKind::Sobol];
        let all = crate::aov::Aov::ALL.to_vec();
        for (desc, kind) in descs.iter().flat_map(|d| kinds.map(|k| (d, k))) {
            let mut desc = desc.clone();
            desc.render.width = 24;
            // Features found or not, the paths are the same.
            let mut without_features = Vec::new();
            for (max_depth, aovs) in [1, 2, 3, 50]
                .into_iter()
                .flat_map(|d| [(d, vec![]), (d, all.clone())])
            {
                desc.render.max_depth = max_depth;
                let with_features = !aovs.is_empty();
                desc.render.aovs = aovs;
                let scene = Scene::from_desc(&desc).expect("compiles");
                let height = scene.settings.height;
                for (pixel, n) in [(0u32, 1usize), (5, 3), (100, 8), (200, 13), (300, PATHS)] {
                    let (x, y) = (pixel % 24, (pixel / 24).min(height - 1));
                    let mut rays = Vec::new();
                    let mut samplers = Vec::new();
                    let pixel_sampler = PixelSampler::new(kind, 7, (x, y), 24, 64);
                    for sample in 0..n as u32 {
                        let (mut sampler, (dx, dy)) = pixel_sampler.start(sample);
                        rays.push(scene.camera.ray(x, y, dx, dy, &mut sampler));
                        samplers.push(sampler);
                    }
                    let mut alone_rays = 0;
                    let (alone, alone_features): (Vec<Color>, Vec<Features>) = rays
                        .iter()
                        .zip(samplers.clone())
                        .map(|(&ray, mut s)| {
                            trace_path_features(&scene, ray, &mut s, &mut alone_rays)
                        })
                        .unzip();
                    let mut together = vec![Color::ZERO; n];
                    let mut searches = vec![
                        FeatureSearch::start(scene.settings.layers);
                        if with_features { n } else { 0 }
                    ];
                    let mut together_rays = 0;
                    let reference = scene.camera.central_ray(x, y);
                    trace_paths(
                        &scene,
                        &mut rays,
                        &mut samplers,
                        &reference,
                        &mut together,
                        &mut searches,
                        &mut together_rays,
                        &Halt::never(),
                    );
                    let features: Vec<Features> = match with_features {
                        true => searches.iter().map(|s| s.features).collect(),
                        false => vec![Features::default(); n],
                    };
                    assert_eq!(features, alone_features, "{}: features", desc.caption);
                    if with_features {
                        assert_eq!(
                            Some(without_features.remove(0)),
                            Some(bits(&together)),
                            "{}: features change the image",
                            desc.caption
                        );
                        // Every path found its albedo (the sky's, at least),
                        // but one that ended on glass.
                        let found = features.iter().all(|f| f.albedo != Color::ZERO);
                        assert!(found || max_depth < 50, "{}: no features", desc.caption);
                    } else {
                        without_features.push(bits(&together));
                    }
                    assert_eq!(
                        bits(&together),
                        bits(&alone),
                        "{}, {kind:?}, depth {max_depth}, {n} paths",
                        desc.caption
                    );
                    assert_eq!(
                        together_rays, alone_rays,
                        "{}, depth {max_depth}: segments",
                        desc.caption
                    );
                }
            }
        }
    }
}
