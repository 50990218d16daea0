//! Beyond the books: the physically based materials, each in a row of
//! spheres from smooth to rough under an HDR sky, the chart pbrt's and
//! Mitsuba's documentation show.

use super::{Builder, CameraDesc};
use crate::material::roughness::DistributionDesc;
use crate::material::{ConductorDesc, DielectricDesc, PlasticDesc, PrincipledDesc};
use crate::scene::desc::{
    BackgroundDesc, IntegratorDesc, MaterialDesc, RenderDesc, SamplingDesc, SceneDesc,
};

/// The roughnesses across a row, smooth on the left.
pub const ROUGHNESSES: [f64; 6] = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];

/// A row of the chart: its name and its material at a roughness.
pub type Row = (&'static str, fn(f64) -> MaterialDesc);

/// The rows, top to bottom.
pub fn rows() -> [Row; 5] {
    [
        ("gold", |r| {
            MaterialDesc::Conductor(ConductorDesc::named("Au", r))
        }),
        ("glass", |r| {
            MaterialDesc::Dielectric(DielectricDesc {
                roughness: Some(r.into()),
                distribution: Some(DistributionDesc::Ggx),
                ..DielectricDesc::new(1.5)
            })
        }),
        ("plastic", |r| {
            MaterialDesc::Plastic(PlasticDesc::new([0.7, 0.08, 0.05], r))
        }),
        ("principled", |r| {
            MaterialDesc::Principled(PrincipledDesc {
                base_color: Some([0.1, 0.25, 0.65].into()),
                roughness: Some(r.into()),
                ..Default::default()
            })
        }),
        ("principled-metal", |r| {
            MaterialDesc::Principled(PrincipledDesc {
                base_color: Some([0.95, 0.64, 0.54].into()),
                metallic: Some(1.0.into()),
                roughness: Some(r.into()),
                ..Default::default()
            })
        }),
    ]
}

/// Rows of spheres in [`rows`]' materials, roughness 0 to 1 across, under
/// the built-in sky.
pub fn materials() -> SceneDesc {
    let render = RenderDesc {
        width: 640,
        aspect_ratio: 16.0 / 9.0,
        samples_per_pixel: 256,
        max_depth: 16,
        sampler: SamplingDesc::Sobol,
        integrator: IntegratorDesc::Path,
        ..RenderDesc::default()
    };
    let mut b = Builder::new(render)
        .background(BackgroundDesc::Image {
            file: "lumen:sky.hdr".to_string(),
            rotation: 0.0,
            intensity: 1.0,
            rows_at_poles: false,
            layout: Default::default(),
            frame: None,
        })
        .camera(CameraDesc {
            vfov: 25.0,
            lookfrom: [0.0, 2.0, 12.0],
            lookat: [0.0, 2.0, 0.0],
            ..CameraDesc::default()
        });
    for (row, (name, material)) in rows().into_iter().enumerate() {
        for (column, &r) in ROUGHNESSES.iter().enumerate() {
            let m = format!("{name}-{column}");
            b = b.material(&m, material(r)).sphere(
                [column as f64 * 1.1 - 2.75, 4.0 - row as f64, 0.0],
                0.45,
                &m,
            );
        }
    }
    b.build()
}
