//! The scene's participating media (`[media]`), and the names by which
//! materials and the camera refer to them.

use super::{albedo, color, finite, invalid, model_path, transform_at, vec3};
use crate::geometry::bvh_build::Aabb;
use crate::material::{MaterialDesc, MediumInterface};
use crate::phase::{Phase, MAX_ASYMMETRY};
use crate::scene::desc::{EdgeDesc, FieldDesc, MediumDesc, SceneDesc};
use crate::scene::SceneError;
use crate::volume::{Field, Grid, Volume};
use std::collections::HashMap;
use std::path::Path;

/// The media of a scene, in the order of their names, and each name's
/// index.
pub(super) struct Media<'a> {
    pub volumes: Vec<Volume>,
    index: HashMap<&'a str, u32>,
}

impl<'a> Media<'a> {
    /// The media `desc` describes; grid files are relative to `base`.
    pub fn compile(desc: &'a SceneDesc, base: &Path) -> Result<Media<'a>, SceneError> {
        let mut volumes = Vec::with_capacity(desc.media.len());
        let mut index = HashMap::with_capacity(desc.media.len());
        for (name, m) in &desc.media {
            index.insert(name.as_str(), volumes.len() as u32);
            volumes.push(medium(&format!("media.{name}"), m, base)?);
        }
        Ok(Media { volumes, index })
    }

    /// The index of the medium `name`, named at `field`.
    fn find(&self, field: &str, name: &str) -> Result<u32, SceneError> {
        self.index.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&str> = self.index.keys().copied().collect();
            known.sort_unstable();
            let message = if known.is_empty() {
                format!("names medium `{name}`, but the scene defines no [media]")
            } else {
                format!(
                    "names medium `{name}`, which the scene does not define (it defines {})",
                    known.join(", ")
                )
            };
            invalid(field, message)
        })
    }

    /// The media on the two sides of material `m` (at `field`), if it names
    /// any.
    pub fn of_material(
        &self,
        field: &str,
        m: &MaterialDesc,
    ) -> Result<Option<MediumInterface>, SceneError> {
        let surface = m.surface();
        let side = |which: &str, name: Option<&str>| {
            name.map(|n| self.find(&format!("{field}.{which}"), n))
                .transpose()
        };
        let interior = side("interior", surface.interior)?;
        let exterior = side("exterior", surface.exterior)?;
        Ok((interior.is_some() || exterior.is_some())
            .then_some(MediumInterface { interior, exterior }))
    }

    /// The medium the camera stands in.
    pub fn of_camera(&self, name: Option<&str>) -> Result<Option<u32>, SceneError> {
        name.map(|n| self.find("camera.medium", n)).transpose()
    }
}

/// The medium `m`, described at `field`.
fn medium(field: &str, m: &MediumDesc, base: &Path) -> Result<Volume, SceneError> {
    let scale = match m.scale {
        Some(s) if !(s.is_finite() && s >= 0.0) => {
            return Err(invalid(
                format!("{field}.scale"),
                format!("must be a finite number ≥ 0, got {s}"),
            ))
        }
        Some(s) => s as f32,
        None => 1.0,
    };
    let at = |name: &str| format!("{field}.{name}");
    let sigma_t = quantity(&at("sigma_t"), &m.sigma_t, scale, false, base)?;
    let albedo = quantity(&at("albedo"), &m.albedo, 1.0, true, base)?;
    let bounds = match (&m.bounds, &sigma_t) {
        (Some(b), _) => {
            let field = at("box");
            finite(&field, &b.min)?;
            finite(&field, &b.max)?;
            if !(0..3).all(|a| b.min[a] < b.max[a]) {
                return Err(invalid(field, "`max` must lie above `min` on every axis"));
            }
            Some(Aabb {
                min: vec3(b.min),
                max: vec3(b.max),
            })
        }
        (None, Field::Grid(g)) => Some(g.bounds()),
        (None, Field::Constant(_)) => None,
    };
    let g = match m.g {
        Some(g) if !(g.abs() <= f64::from(MAX_ASYMMETRY)) => {
            return Err(invalid(
                at("g"),
                format!("must lie between −{MAX_ASYMMETRY} and {MAX_ASYMMETRY}, got {g}"),
            ))
        }
        g => g.unwrap_or(0.0) as f32,
    };
    Ok(Volume::new(sigma_t, albedo, bounds).with_phase(Phase::with_asymmetry(g)))
}

/// A quantity of a medium at `field`, multiplied by `factor`: ≥ 0, and
/// at most 1 where it is an `albedo`.
fn quantity(
    field: &str,
    d: &FieldDesc,
    factor: f32,
    is_albedo: bool,
    base: &Path,
) -> Result<Field, SceneError> {
    let constant = |c: [f64; 3]| {
        let value = if is_albedo {
            albedo(field, c)?
        } else {
            color(field, c)?
        };
        Ok(Field::Constant(value * factor))
    };
    match d {
        FieldDesc::Value(v) => constant([*v; 3]),
        FieldDesc::Color(c) => constant(*c),
        FieldDesc::Grid(g) => {
            let transform = placement(field, &g.transform)?;
            let path = model_path(base, &g.grid);
            let grid = Grid::read(&path, factor, transform)
                .map_err(|e| invalid(format!("{field}.grid"), format!("{}: {e}", g.grid)))?;
            checked(field, "grid", &g.grid, grid, is_albedo)
        }
        FieldDesc::Voxels(v) => {
            let transform = placement(field, &v.transform)?;
            let size = v.voxels.map(|n| n as usize);
            let voxels = size.iter().try_fold(1usize, |n, &s| n.checked_mul(s));
            let channels = match voxels {
                Some(n) if v.values.len() == n => 1,
                Some(n) if Some(v.values.len()) == n.checked_mul(3) => 3,
                _ => {
                    return Err(invalid(
                        format!("{field}.values"),
                        format!(
                            "holds {} values for {}×{}×{} voxels: one per voxel, or three",
                            v.values.len(),
                            size[0],
                            size[1],
                            size[2]
                        ),
                    ))
                }
            };
            let values = v.values.iter().map(|&x| x as f32).collect();
            let grid = Grid::new(size, channels, values, factor, transform)
                .map_err(|e| invalid(format!("{field}.values"), format!("the grid {e}")))?;
            let grid = match v.edge {
                Some(EdgeDesc::Zero) => grid
                    .zero_outside()
                    .map_err(|e| invalid(format!("{field}.values"), format!("the grid {e}")))?,
                _ => grid,
            };
            checked(field, "values", "the grid", grid, is_albedo)
        }
    }
}

/// The placement of a medium's grid at `field`: transform steps, no
/// motion.
fn placement(
    field: &str,
    steps: &[crate::scene::desc::TransformDesc],
) -> Result<crate::geometry::transform::Transform, SceneError> {
    let (transform, motion) = transform_at(&format!("{field}.transform"), steps)?;
    if motion != crate::math::Vec3::ZERO {
        return Err(invalid(
            format!("{field}.transform"),
            "a medium cannot move: a `motion` step is for surfaces",
        ));
    }
    Ok(transform)
}

/// `grid` (named `name`, at `field`.`part`) as a field, refused above 1
/// where it is an albedo.
fn checked(
    field: &str,
    part: &str,
    name: &str,
    grid: Grid,
    is_albedo: bool,
) -> Result<Field, SceneError> {
    if is_albedo && grid.max() > 1.0 {
        return Err(invalid(
            format!("{field}.{part}"),
            format!("{name}: holds {}, above 1", grid.max()),
        ));
    }
    Ok(Field::Grid(Box::new(grid)))
}
