//! # lumen
//!
//! A physically based CPU path tracer that reproduces, step by step, Peter
//! Shirley's *Ray Tracing in One Weekend*, and renders scenes of your own.
//!
//! The modules follow the path of a ray:
//!
//! - [`ray`]: p(t) = A + tB; [`math`]: vectors, colours, intervals.
//! - [`camera`]: from a pixel to a ray, with field of view and defocus blur.
//! - [`geometry`]: spheres, triangles and quads, hit records, and the
//!   [`geometry::Bvh`] that finds the nearest hit (or any hit).
//! - [`lanes`]: arithmetic written once for one lane or eight, so that each
//!   intersection kernel exists once.
//! - [`material`]: diffuse (four bounce models, two attenuation forms),
//!   metal, dielectric.
//! - [`light`]: emissive surfaces and the background, gathered to be aimed at
//!   (next-event estimation); [`distribution`]: drawing in proportion to a
//!   table of weights.
//! - [`medium`]: fog and smoke of constant density.
//! - [`volume`]: participating media that fill what surfaces enclose
//!   (constant or voxel grids), entered and left through surfaces.
//! - [`texture`]: solid colours, checkers, images and noise.
//! - [`mesh`]: triangle meshes and their materials from OBJ, glTF and PLY files.
//! - [`integrator`]: the path of one ray, top to bottom, in one function.
//! - [`sampler`]: the numbers behind every random decision of a path
//!   (independent, stratified, Owen-scrambled Sobol per pixel or over the
//!   pixels in Morton order); [`sampling`]: random
//!   points and directions made from them; [`rng`]: seeded random numbers.
//! - [`render`]: every sample of every pixel, in parallel, deterministically.
//! - [`film`] and [`output`]: accumulation, gamma, tone mapping, image files.
//! - [`progressive`] and [`checkpoint`]: rendering in passes that can be
//!   stopped, saved and resumed, within a time budget; [`adaptive`]: pixels
//!   that stop once clean.
//! - [`files`] and [`lock`]: the files beside an output (checkpoint,
//!   temporaries, lock files): names that fit, regular files only, and one
//!   render at a time.
//! - [`scene`]: scene descriptions, the built-in scenes, and the compiled scene.
//! - [`gallery`] and [`bench`](mod@bench): all the notes' figures at once; throughput.
//!
//! ```
//! use lumen::scene::{builtin, Scene};
//!
//! let mut desc = builtin::find("metal-mirror").unwrap().desc();
//! desc.render.width = 32;
//! desc.render.samples_per_pixel = 4;
//! let scene = Scene::from_desc(&desc).unwrap();
//! let (film, stats) = lumen::render::render(&scene, &|_| {});
//! assert_eq!(stats.samples, 32 * 18 * 4);
//! let png_bytes = film.to_rgb8(scene.settings.gamma);
//! assert_eq!(png_bytes.len(), 32 * 18 * 3);
//! ```
#![deny(unsafe_code)]
#![warn(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adaptive;
pub mod aov;
pub mod bench;
pub mod bsdf;
pub mod camera;
pub mod checkpoint;
pub mod denoise;
pub mod distribution;
pub mod files;
pub mod film;
pub mod filter;
pub mod gallery;
pub mod geometry;
pub mod halt;
pub mod hint;
pub mod input;
pub mod integrator;
pub mod isa;
pub mod lanes;
pub mod light;
pub mod lock;
pub mod material;
pub mod math;
pub mod medium;
pub mod memory;
pub mod mesh;
pub mod output;
pub mod part;
pub mod phase;
pub mod preview;
pub mod progressive;
pub mod ray;
pub mod render;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod scene;
#[cfg(test)]
mod testing;
pub mod texture;
pub mod tile;
pub mod volume;
