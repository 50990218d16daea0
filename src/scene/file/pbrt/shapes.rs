//! pbrt's shapes as lumen's objects: spheres, triangle meshes written in
//! the scene, PLY meshes, bilinear patches that are flat parallelograms
//! (two triangles each), and Loop subdivision surfaces (subdivided here,
//! onto their limit surface).

use super::lex::At;
use super::params::{Params, Problem};
use super::scene::Builder;
use super::Input;
use crate::scene::desc::{ObjectDesc, TransformDesc};
use crate::scene::file::{matrix, tessellate};

/// The shapes lumen reads.
const SHAPES: &[&str] = &[
    "sphere",
    "trianglemesh",
    "plymesh",
    "bilinearmesh",
    "loopsubdiv",
];

impl Builder {
    /// Whether pbrt finds a sphere, disk or cylinder placed now with its
    /// outside turned in: for ReverseOrientation and, separately, for a
    /// transform that mirrors (a mirror keeps lumen's outside).
    fn quadric_turned(&self) -> bool {
        self.state.reverse != (matrix::det3(&self.state.ctm) < 0.0)
    }

    pub(super) fn shape(
        &mut self,
        ty: &str,
        at: At,
        p: &Params,
        input: &Input,
    ) -> Result<(), Problem> {
        // What changes nothing in lumen's image.
        p.ignore(&["emissionfilename"]);
        match ty {
            "sphere" => {
                let radius = p.float("radius")?.unwrap_or(1.0);
                if !(radius > 0.0) {
                    return Err((
                        at,
                        format!("a sphere's `radius` must be above 0, got {radius}"),
                        None,
                    ));
                }
                let zmin = p.float("zmin")?.unwrap_or(-radius);
                let zmax = p.float("zmax")?.unwrap_or(radius);
                let phimax = p.float("phimax")?.unwrap_or(360.0);
                if zmin > -radius || zmax < radius || phimax < 360.0 {
                    self.lacks(
                        at,
                        "part of a sphere (zmin, zmax, phimax)",
                        "the whole sphere",
                    )?;
                }
                // pbrt's area of a sphere: in its own space.
                let area = 4.0 * std::f64::consts::PI * radius * radius;
                let material = self.surface(p, at, Some(area))?;
                p.finish("a sphere", &["radius", "zmin", "zmax", "phimax", "alpha"])?;
                let turned = self.quadric_turned();
                // Turned so that its (u, v) are pbrt's.
                let turn = matrix::z_up_sphere([0.0; 3]);
                let transform = vec![TransformDesc::Matrix(matrix::mul(&self.state.ctm, &turn))];
                self.add(ObjectDesc::Sphere {
                    flip_normals: turned,
                    center: [0.0; 3],
                    radius,
                    material,
                    transform,
                });
            }
            "trianglemesh" => {
                let (positions, pat) = p.tuples::<3>("P", &["point3"])?.ok_or((
                    at,
                    "a trianglemesh needs its points `P`".into(),
                    None,
                ))?;
                let indices = match p.indices("indices")? {
                    Some((i, _)) => i,
                    None if positions.len() == 3 => vec![0, 1, 2],
                    None => {
                        return Err((
                            at,
                            "a trianglemesh of more than 3 points needs `indices`".into(),
                            None,
                        ))
                    }
                };
                let triangles = triples(&indices, positions.len(), at)?;
                let normals = p.tuples::<3>("N", &["normal", "normal3"])?.map(|(n, _)| n);
                let uvs = self.uvs(p)?;
                self.triangles(
                    positions,
                    pat,
                    triangles,
                    normals,
                    uvs,
                    p,
                    at,
                    "a trianglemesh",
                    Lights::Each(1),
                )?;
            }
            "bilinearmesh" => {
                let (positions, pat) = p.tuples::<3>("P", &["point3"])?.ok_or((
                    at,
                    "a bilinearmesh needs its points `P`".into(),
                    None,
                ))?;
                let quads = match p.indices("indices")? {
                    Some((i, _)) => i,
                    None if positions.len() == 4 => vec![0, 1, 2, 3],
                    None => {
                        return Err((
                            at,
                            "a bilinearmesh of more than 4 points needs `indices`".into(),
                            None,
                        ))
                    }
                };
                if !quads.len().is_multiple_of(4) {
                    return Err((
                        at,
                        format!(
                            "a bilinearmesh's `indices` hold {} numbers, not 4 a patch",
                            quads.len()
                        ),
                        None,
                    ));
                }
                if let Some(&i) = quads.iter().find(|&&i| i as usize >= positions.len()) {
                    return Err((
                        at,
                        format!(
                            "`indices` names point {i}, but there are {} points",
                            positions.len()
                        ),
                        None,
                    ));
                }
                // Each patch p00 p10 p01 p11 is two triangles; exact when it
                // is a flat parallelogram.
                let mut curved = false;
                let mut triangles = Vec::with_capacity(quads.len() / 2);
                for q in quads.chunks_exact(4) {
                    let [p00, p10, p01, p11] =
                        [q[0], q[1], q[2], q[3]].map(|i| positions[i as usize]);
                    let expected = [0, 1, 2].map(|k| p10[k] + p01[k] - p00[k]);
                    let size = [0, 1, 2]
                        .map(|k| (p10[k] - p00[k]).abs() + (p01[k] - p00[k]).abs())
                        .iter()
                        .fold(0.0f64, |a, b| a.max(*b));
                    if (0..3)
                        .any(|k| (expected[k] - p11[k]).abs() > 1e-6 * size.max(f64::MIN_POSITIVE))
                    {
                        curved = true;
                    }
                    triangles.extend([[q[0], q[1], q[3]], [q[0], q[3], q[2]]]);
                }
                if curved {
                    self.lacks(at, "curved bilinear patch", "two flat triangles a patch")?;
                }
                let normals = p.tuples::<3>("N", &["normal", "normal3"])?.map(|(n, _)| n);
                let uvs = self.uvs(p)?;
                self.triangles(
                    positions,
                    pat,
                    triangles,
                    normals,
                    uvs,
                    p,
                    at,
                    "a bilinearmesh",
                    Lights::Each(2),
                )?;
            }
            "plymesh" => {
                let (file, fat) = p.string_of("filename", "string")?.ok_or((
                    at,
                    "a plymesh needs a `filename`".into(),
                    None,
                ))?;
                let file = input.file(file, fat)?;
                if p.has("displacement") {
                    let _ = p.get("displacement");
                    p.ignore(&["edgelength"]);
                    self.lacks(
                        at,
                        "displacement of a mesh's vertices",
                        "the undisplaced mesh",
                    )?;
                }
                let material = self.surface(p, at, None)?;
                p.finish(
                    "a plymesh",
                    &["filename", "displacement", "edgelength", "alpha"],
                )?;
                // pbrt's outside is the file's winding's as written, turned
                // by ReverseOrientation; a mirror keeps it, as lumen's.
                let transform = self.placement();
                self.add(ObjectDesc::Mesh {
                    flip_normals: self.state.reverse,
                    file,
                    material: Some(material),
                    smooth: true,
                    allow_outside: false,
                    part: None,
                    flip_v: false,
                    transform,
                });
            }
            "loopsubdiv" => {
                let (positions, pat) = p.tuples::<3>("P", &["point3"])?.ok_or((
                    at,
                    "a loopsubdiv needs its points `P`".into(),
                    None,
                ))?;
                let (indices, iat) = p.indices("indices")?.ok_or((
                    at,
                    "a loopsubdiv needs `indices`".into(),
                    None,
                ))?;
                let levels = p.int("levels")?.unwrap_or(3);
                let levels = u32::try_from(levels).map_err(|_| {
                    (
                        at,
                        format!("`levels` must be a whole number ≥ 0, got {levels}"),
                        None,
                    )
                })?;
                let triangles = triples(&indices, positions.len(), iat)?;
                let (positions, triangles, normals) =
                    crate::mesh::loop_subdivision::subdivide(&positions, &triangles, levels)
                        .map_err(|m| (at, format!("loopsubdiv: {m}"), None))?;
                self.triangles(
                    positions,
                    pat,
                    triangles,
                    Some(normals),
                    None,
                    p,
                    at,
                    "a loopsubdiv",
                    Lights::Each(1),
                )?;
            }
            "disk" | "cylinder" => {
                let radius = p.float("radius")?.unwrap_or(1.0);
                let phimax = p.float("phimax")?.unwrap_or(360.0);
                if !(radius > 0.0) {
                    return Err((
                        at,
                        format!("the `radius` must be above 0, got {radius}"),
                        None,
                    ));
                }
                if phimax < 360.0 {
                    self.lacks(at, &format!("part of a {ty} (phimax)"), "the whole")?;
                }
                let inner = if ty == "disk" {
                    p.float("innerradius")?.unwrap_or(0.0)
                } else {
                    0.0
                };
                if inner > 0.0 {
                    // A ring: as triangles, with its hole.
                    self.lacks(
                        at,
                        "a disk with a hole (innerradius)",
                        "a polygon of 128 sides of its area",
                    )?;
                    let height = p.float("height")?.unwrap_or(0.0);
                    let inner = inner.min(radius);
                    // pbrt's area of a ring: in its own space.
                    let area = std::f64::consts::PI * (radius * radius - inner * inner);
                    let mesh = tessellate::disk(radius, inner, height);
                    let (positions, triangles, normals) = mesh;
                    return self.triangles(
                        positions,
                        at,
                        triangles,
                        Some(normals),
                        None,
                        p,
                        at,
                        "a disk",
                        Lights::Whole(area),
                    );
                }
                let ctm = self.state.ctm;
                let turned = self.quadric_turned();
                let object = if ty == "disk" {
                    let height = p.float("height")?.unwrap_or(0.0);
                    let area = std::f64::consts::PI * radius * radius;
                    let material = self.surface(p, at, Some(area))?;
                    p.finish(
                        "a disk",
                        &["radius", "height", "innerradius", "phimax", "alpha"],
                    )?;
                    let place = matrix::translation([0.0, 0.0, height]);
                    ObjectDesc::Disk {
                        flip_normals: turned,
                        center: [0.0; 3],
                        normal: [0.0, 0.0, 1.0],
                        radius,
                        material,
                        transform: vec![TransformDesc::Matrix(matrix::mul(&ctm, &place))],
                    }
                } else {
                    let z0 = p.float("zmin")?.unwrap_or(-1.0);
                    let z1 = p.float("zmax")?.unwrap_or(1.0);
                    if z0 == z1 {
                        return Err((
                            at,
                            format!("a cylinder's zmin and zmax are both {z0}"),
                            None,
                        ));
                    }
                    let area = 2.0 * std::f64::consts::PI * radius * (z1 - z0).abs();
                    let material = self.surface(p, at, Some(area))?;
                    p.finish("a cylinder", &["radius", "zmin", "zmax", "phimax", "alpha"])?;
                    ObjectDesc::Cylinder {
                        flip_normals: turned,
                        p0: [0.0, 0.0, z0.min(z1)],
                        p1: [0.0, 0.0, z0.max(z1)],
                        radius,
                        material,
                        transform: vec![TransformDesc::Matrix(ctm)],
                    }
                };
                self.add(object);
            }
            "curve" | "cone" | "paraboloid" | "hyperboloid" => {
                p.ignore_all();
                self.lacks(at, &format!("`{ty}` shape"), "no shape")?;
            }
            other => {
                return Err((
                    at,
                    format!(
                        "shape `{other}` is not one lumen reads; it reads {}",
                        SHAPES.join(", ")
                    ),
                    crate::hint::closest(other, SHAPES.iter().copied())
                        .map(|k| format!("did you mean `{k}`?")),
                ))
            }
        }
        Ok(())
    }

    /// A mesh's texture coordinates: "point2 uv" (or pbrt-v3's "float uv").
    fn uvs(&self, p: &Params) -> Result<Option<Vec<[f64; 2]>>, Problem> {
        Ok(p.tuples::<2>("uv", &["point2", "float"])?.map(|(t, _)| t))
    }

    /// Adds a triangle mesh of `triangles` (indices in range) over
    /// `positions`, made into lights by an area light as `lights` says.
    #[allow(clippy::too_many_arguments)]
    fn triangles(
        &mut self,
        positions: Vec<[f64; 3]>,
        pat: At,
        mut triangles: Vec<[u32; 3]>,
        normals: Option<Vec<[f64; 3]>>,
        uvs: Option<Vec<[f64; 2]>>,
        p: &Params,
        at: At,
        what: &str,
        lights: Lights,
    ) -> Result<(), Problem> {
        let n = positions.len();
        for (name, len) in [
            ("N", normals.as_ref().map(Vec::len)),
            ("uv", uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|l| *l != n) {
                return Err((
                    pat,
                    format!("`{name}` has {len} entries for {n} points `P`: give one a point"),
                    None,
                ));
            }
        }
        p.ignore(&["S", "faceIndices"]);
        let area = match lights {
            _ if self.state.area_power.is_none() => None,
            Lights::Each(per_light) => {
                light_area(&positions, &triangles, per_light, &self.state.ctm)
            }
            Lights::Whole(area) => Some(area),
        };
        let material = self.surface(p, at, area)?;
        p.finish(
            what,
            &["P", "indices", "N", "uv", "S", "faceIndices", "alpha"],
        )?;
        // The side that shines: with normals, theirs (turned by
        // ReverseOrientation); otherwise the winding's, so turned.
        let reverse = self.state.reverse;
        let normals = normals.map(|nv| {
            if reverse {
                nv.iter().map(|v| v.map(|x| -x)).collect::<Vec<_>>()
            } else {
                nv
            }
        });
        for t in &mut triangles {
            let flip = match &normals {
                Some(nv) => {
                    let [a, b, c] = t.map(|i| positions[i as usize]);
                    let u = [0, 1, 2].map(|k| b[k] - a[k]);
                    let v = [0, 1, 2].map(|k| c[k] - a[k]);
                    let g = [
                        u[1] * v[2] - u[2] * v[1],
                        u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0],
                    ];
                    let s: [f64; 3] = [0, 1, 2].map(|k| t.iter().map(|&i| nv[i as usize][k]).sum());
                    g[0] * s[0] + g[1] * s[1] + g[2] * s[2] < 0.0
                }
                None => reverse,
            };
            // lumen's side is the winding's as written, which a mirror
            // keeps, as pbrt's.
            if flip {
                t.swap(1, 2);
            }
        }
        let transform = self.placement();
        self.add(ObjectDesc::Triangles {
            flip_normals: false,
            positions,
            indices: triangles,
            normals,
            uvs,
            material,
            transform,
        });
        Ok(())
    }
}

/// `indices` in threes, each naming one of `n` points.
fn triples(indices: &[u32], n: usize, at: At) -> Result<Vec<[u32; 3]>, Problem> {
    if !indices.len().is_multiple_of(3) {
        return Err((
            at,
            format!("`indices` hold {} numbers, not 3 a triangle", indices.len()),
            None,
        ));
    }
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= n) {
        return Err((
            at,
            format!("`indices` names point {i}, but there are {n} points `P`"),
            None,
        ));
    }
    Ok(indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect())
}

/// How pbrt divides a shape's triangles into lights (for an area light
/// given by its `power`, which each light gives off).
#[derive(Clone, Copy)]
enum Lights {
    /// Each run of this many triangles (a triangle, a bilinear patch), of
    /// its area as placed.
    Each(usize),
    /// The whole shape, of this area (a ring's, in its own space).
    Whole(f64),
}

/// The area each light of `triangles` over `positions`, placed by `ctm`,
/// has when they are alike (to 10⁻⁶), a light being `per_light`
/// consecutive triangles: `None` when they differ.
fn light_area(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    per_light: usize,
    ctm: &matrix::Mat4,
) -> Option<f64> {
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| glam::DVec3::from(matrix::point(ctm, positions[i as usize])));
        0.5 * (b - a).cross(c - a).length()
    };
    let areas: Vec<f64> = triangles
        .chunks(per_light)
        .map(|light| light.iter().map(area).sum())
        .collect();
    let first = *areas.first()?;
    areas
        .iter()
        .all(|a| (a - first).abs() <= 1e-6 * first)
        .then_some(first)
}
