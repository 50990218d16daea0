//! The scene's shapes compiled for tracing: the tree over them, and what
//! shading needs of each (materials, normals, texture coordinates), so that
//! a hit found by the tree becomes a [`HitRecord`].
//!
//! The tree's items are numbered spheres first, then quads, then disks and
//! cylinders, then the triangles of each mesh placed once (stored in world
//! space), then the instances of meshes placed several times (stored once,
//! in object space, with a tree of their own). A shape's number is its
//! place in the order of hits at exactly the same distance.

use crate::geometry::bvh::Hit;
use crate::geometry::hit::face_normal;
use crate::geometry::transform::Transform;
use crate::geometry::{
    Bvh, HitRecord, Instance, Kind, Primitive, PrimitiveSet, Quad, Quadric, Sphere, Triangle,
};
use crate::light::{Light, LightTexture, Shape as LightShape};
use crate::material::{Emissive, Material};
use crate::math::{Color, Point3, Vec3};
use crate::memory::MemoryError;
use crate::mesh::TriangleMesh;
use crate::ray::Ray;
use std::sync::Arc;

/// The part of a sphere and its material that the record of a hit needs,
/// together in 32 bytes: one cache line per hit instead of two, and a
/// multiplication by the inverse radius instead of a division.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Surface {
    pub(crate) center: Point3,
    pub(crate) inverse_radius: f32,
    pub(crate) radius: f32,
    pub(crate) material: u32,
    /// Whether hit records on it carry their (u, v) (the inverse
    /// trigonometry is worth paying only for a texture that uses them).
    pub(crate) uv: bool,
    /// Whether its outside is turned in, towards the centre.
    pub(crate) inward: bool,
}

impl Surface {
    /// `sphere` in `material`, its outside turned in if `inward`.
    pub(crate) fn new(sphere: &Sphere, material: u32, uv: bool, inward: bool) -> Self {
        Surface {
            center: sphere.center,
            inverse_radius: 1.0 / sphere.radius,
            radius: sphere.radius,
            material,
            uv,
            inward,
        }
    }
}

/// A triangle mesh with a scene material per triangle (or one for all).
#[derive(Clone, Debug)]
pub(crate) struct Mesh {
    pub(crate) data: TriangleMesh,
    /// Whether its outside is the side from which its triangles run
    /// clockwise, against the file's winding.
    pub(crate) flipped: bool,
}

impl Mesh {
    fn triangle(&self, k: usize) -> Triangle {
        let [a, b, c] = self.data.triangles[k].map(|i| Vec3::from(self.data.positions[i as usize]));
        Triangle::new(a, b, c)
    }

    /// Triangle `k`'s corners and their texture coordinates, in the order
    /// that runs counter-clockwise seen from its outside (a light's).
    fn outward_corners(&self, k: usize) -> ([Point3; 3], [[f32; 2]; 3]) {
        let [a, b, c] = self.triangle(k).vertices;
        let [p, q, r] = match &self.data.uvs {
            Some(uvs) => self.data.triangles[k].map(|i| uvs[i as usize]),
            None => CORNER_UVS,
        };
        if self.flipped {
            ([a, c, b], [p, r, q])
        } else {
            ([a, b, c], [p, q, r])
        }
    }

    fn material(&self, k: usize) -> u32 {
        let m = &self.data.material;
        if m.len() == 1 {
            m[0]
        } else {
            m[k]
        }
    }
}

/// Shapes numbered as the items of one tree (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct Shapes {
    pub(crate) spheres: Vec<Surface>,
    pub(crate) quads: Vec<(Quad, u32)>,
    /// Disks and cylinders, with their materials.
    pub(crate) quadrics: Vec<(Quadric, u32)>,
    meshes: Vec<Mesh>,
    /// Per mesh, the number of triangles of it and the meshes before it:
    /// where its triangles end among the triangle items.
    mesh_end: Vec<usize>,
}

/// Which shape item `index` of a tree is (an instance is told apart by
/// [`Shapes::locate`] before, so that a record is built in place rather
/// than wrapped).
#[derive(Clone, Copy)]
enum Shape {
    Sphere(usize),
    Quad(usize),
    Quadric(usize),
    /// Mesh, triangle in it.
    Triangle(usize, usize),
}

impl Shapes {
    /// Shapes holding `mesh` alone.
    pub(crate) fn of_mesh(mesh: Mesh) -> Shapes {
        let mut shapes = Shapes::default();
        shapes.push_mesh(mesh);
        shapes
    }

    /// Adds a mesh after those already there.
    pub(crate) fn push_mesh(&mut self, mesh: Mesh) {
        let start = self.mesh_end.last().copied().unwrap_or(0);
        self.mesh_end.push(start + mesh.data.triangles.len());
        self.meshes.push(mesh);
    }

    /// How many of the tree's items are shapes (the instances come after).
    fn shape_count(&self) -> usize {
        self.spheres.len()
            + self.quads.len()
            + self.quadrics.len()
            + self.mesh_end.last().copied().unwrap_or(0)
    }

    /// The kind of shape item `index`.
    fn shape_kind(&self, index: usize) -> Kind {
        match self.locate(index) {
            Ok(Shape::Sphere(_)) => Kind::Sphere,
            Ok(Shape::Quad(_)) => Kind::Quad,
            Ok(Shape::Quadric(_)) => Kind::Quadric,
            Ok(Shape::Triangle(..)) => Kind::Triangle,
            Err(_) => panic!("shape {index} of {}", self.shape_count()),
        }
    }

    /// Shape item `index` as the tree is built from it.
    fn shape_primitive(&self, index: usize) -> Primitive {
        match self.locate(index) {
            Ok(Shape::Sphere(k)) => {
                let s = &self.spheres[k];
                Primitive::Sphere(Sphere::new(s.center, s.radius))
            }
            Ok(Shape::Quad(k)) => Primitive::Quad(self.quads[k].0.grown()),
            Ok(Shape::Quadric(k)) => Primitive::Quadric(self.quadrics[k].0),
            Ok(Shape::Triangle(m, k)) => Primitive::Triangle(self.meshes[m].triangle(k)),
            Err(_) => panic!("shape {index} of {}", self.shape_count()),
        }
    }

    /// The shape item `index` is, or the number of the instance it is.
    #[inline(always)]
    fn locate(&self, mut index: usize) -> Result<Shape, usize> {
        if index < self.spheres.len() {
            return Ok(Shape::Sphere(index));
        }
        index -= self.spheres.len();
        if index < self.quads.len() {
            return Ok(Shape::Quad(index));
        }
        index -= self.quads.len();
        if index < self.quadrics.len() {
            return Ok(Shape::Quadric(index));
        }
        index -= self.quadrics.len();
        // The first mesh ending after `index`.
        let m = self.mesh_end.partition_point(|&end| end <= index);
        match self.meshes.get(m) {
            Some(mesh) => {
                let first = self.mesh_end[m] - mesh.data.triangles.len();
                Ok(Shape::Triangle(m, index - first))
            }
            None => Err(index - self.mesh_end.last().copied().unwrap_or(0)),
        }
    }

    /// The record of a hit on `shape` (item `index`) at distance `t` of
    /// `ray`, in the space the shapes are stored in. A quad's or a
    /// triangle's hit point is kept at least its error bound, and at least
    /// `margin`, inside its edges.
    #[inline(always)]
    fn record(
        &self,
        ray: &Ray,
        t: f32,
        shape: Shape,
        index: u32,
        rounding: Rounding,
        margin: f32,
    ) -> HitRecord {
        let error_scale = rounding.scale;
        match shape {
            Shape::Sphere(k) => {
                let surface = &self.spheres[k];
                let mut point = ray.at(t);
                if rounding.onto_spheres {
                    // Moved back onto the sphere: the rounding of o + t·d
                    // grows with the ray's origin and length, and could
                    // leave the point inside a sphere a ray then leaves.
                    let off = point - surface.center;
                    point = surface.center + off * (surface.radius / off.length());
                }
                let outward = (point - surface.center) * surface.inverse_radius;
                let (normal, front_face) = if surface.inward {
                    face_normal(ray, -outward)
                } else {
                    face_normal(ray, outward)
                };
                // Along u = φ/2π about +y (see `Sphere::uv`).
                let along_u = Vec3::new(outward.z, 0.0, -outward.x);
                // Only for textures that use them: the inverse
                // trigonometry cost a fifth of the cover's render.
                let (uv, dpdu, dpdv) = if surface.uv {
                    let (du, dv) = sphere_derivatives(outward, surface.radius);
                    (Sphere::uv(outward), du, dv)
                } else {
                    ([0.0, 0.0], along_u, Vec3::ZERO)
                };
                HitRecord {
                    point,
                    normal,
                    shading_normal: normal,
                    uv,
                    t,
                    front_face,
                    material: surface.material,
                    object: index,
                    uv1: uv,
                    dpdu,
                    dpdv,
                    color: glam::Vec4::ONE,
                    error: (point.abs().max_element() + surface.radius) * error_scale,
                }
            }
            Shape::Quad(k) => {
                let (quad, material) = &self.quads[k];
                // On the plane: the ray's rounding along its length removed.
                let p = ray.at(t);
                let point = p - (quad.normal.dot(p) - quad.d) * quad.normal;
                let error = (point.abs().max_element() + quad.d.abs()) * error_scale;
                // Kept a rounding bound inside the edges, where a wall
                // meeting the quad is surely ahead of a ray leaving it.
                let (point, uv) = quad.within(point, quad.coordinates(point), error.max(margin));
                let (normal, front_face) = face_normal(ray, quad.normal);
                HitRecord {
                    point,
                    normal,
                    shading_normal: normal,
                    uv,
                    t,
                    front_face,
                    material: *material,
                    object: index,
                    uv1: uv,
                    dpdu: quad.u,
                    dpdv: quad.v,
                    color: glam::Vec4::ONE,
                    error,
                }
            }
            Shape::Quadric(k) => {
                let (quadric, material) = &self.quadrics[k];
                quadric_record(ray, t, quadric, *material, index, error_scale)
            }
            Shape::Triangle(m, k) => {
                let mesh = &self.meshes[m];
                triangle_record(ray, t, mesh, k, index, error_scale, margin)
            }
        }
    }
}

/// The items of a group's tree: its shapes, each made when the build asks
/// for it (a mesh's triangles are not copied into primitives first).
impl PrimitiveSet for Shapes {
    fn count(&self) -> usize {
        self.shape_count()
    }

    fn primitive(&self, i: usize) -> Primitive {
        self.shape_primitive(i)
    }

    fn kind(&self, i: usize) -> Kind {
        self.shape_kind(i)
    }
}

/// The items of the world's tree: the shapes, then the instances.
struct WorldItems<'a> {
    shapes: &'a Shapes,
    instances: Vec<Primitive>,
}

impl PrimitiveSet for WorldItems<'_> {
    fn count(&self) -> usize {
        self.shapes.shape_count() + self.instances.len()
    }

    fn primitive(&self, i: usize) -> Primitive {
        match i.checked_sub(self.shapes.shape_count()) {
            Some(k) => self.instances[k],
            None => self.shapes.shape_primitive(i),
        }
    }

    fn kind(&self, i: usize) -> Kind {
        match i.checked_sub(self.shapes.shape_count()) {
            Some(_) => Kind::Instance,
            None => self.shapes.shape_kind(i),
        }
    }
}

/// ∂p/∂u and ∂p/∂v of a sphere of radius `r` at unit outward normal `n`
/// (u = φ/2π, v = θ/π, see [`Sphere::uv`]); ∂p/∂v is zero at the poles.
fn sphere_derivatives(n: Vec3, r: f32) -> (Vec3, Vec3) {
    use std::f32::consts::PI;
    let dpdu = 2.0 * PI * r * Vec3::new(n.z, 0.0, -n.x);
    let s2 = 1.0 - n.y * n.y;
    let dpdv = if s2 > 1e-12 {
        PI * r / s2.sqrt() * Vec3::new(-n.x * n.y, s2, -n.z * n.y)
    } else {
        Vec3::ZERO
    };
    (dpdu, dpdv)
}

/// The record of a hit on a disk or a cylinder: the point moved onto the
/// surface in the shape's own space, and placed back in the world.
#[inline(never)]
fn quadric_record(
    ray: &Ray,
    t: f32,
    quadric: &Quadric,
    material: u32,
    index: u32,
    error_scale: f32,
) -> HitRecord {
    let s = quadric.surface(ray, t);
    let (normal, front_face) = face_normal(ray, s.outward);
    HitRecord {
        point: s.point,
        normal,
        shading_normal: normal,
        uv: s.uv,
        t,
        front_face,
        material,
        object: index,
        uv1: s.uv,
        dpdu: s.dpdu,
        dpdv: s.dpdv,
        color: glam::Vec4::ONE,
        error: (s.point.abs().max_element() + s.extent) * error_scale,
    }
}

/// The record of a hit on triangle `k` of `mesh`. The point is rebuilt
/// from its barycentric coordinates, so that it lies on the triangle to
/// within the rounding of the vertices, whatever the ray's length, and at
/// least its error bound and `margin` inside the edges.
fn triangle_record(
    ray: &Ray,
    t: f32,
    mesh: &Mesh,
    k: usize,
    index: u32,
    error_scale: f32,
    margin: f32,
) -> HitRecord {
    let tri = mesh.triangle(k);
    let [a, b, c] = tri.vertices;
    let area_normal = tri.area_normal();
    let b_ = barycentrics(&tri, area_normal, ray.at(t));
    let extent = ((b_[0] * a).abs() + (b_[1] * b).abs() + (b_[2] * c).abs()).max_element();
    // Rebuilt from its barycentric coordinates, the point is rounded to
    // the size of the vertices; on a triangle much larger than the ray (a
    // floor of 1e8 seen from 1 above it) that is more than the ray's own
    // rounding, and the point is taken along the ray instead (see
    // `large_hit`), as it is where the normal's square overflows f32 (a
    // triangle beyond about 1e9).
    let reach = ray.origin().abs().max_element() + t.abs();
    let (geometric, point, b_, error) =
        if area_normal.length_squared().is_normal() && extent <= ALONG * reach {
            let error = extent * error_scale;
            // Kept a rounding bound inside the edges, where a triangle
            // meeting this one at a crease is surely ahead of a ray
            // leaving it.
            let b_ = within(&tri, area_normal, b_, error.max(margin));
            let point = b_[0] * a + b_[1] * b + b_[2] * c;
            (area_normal.normalize(), point, b_, error)
        } else {
            large_hit(&tri, ray, t, error_scale, margin)
        };
    let geometric = if mesh.flipped { -geometric } else { geometric };
    let (normal, front_face) = face_normal(ray, geometric);
    let idx = mesh.data.triangles[k].map(|i| i as usize);
    let shading_normal = match &mesh.data.normals {
        Some(ns) => {
            let n = b_[0] * Vec3::from(ns[idx[0]])
                + b_[1] * Vec3::from(ns[idx[1]])
                + b_[2] * Vec3::from(ns[idx[2]]);
            facing(n.normalize_or_zero(), normal)
        }
        None => normal,
    };
    let interpolate2 = |v: &[[f32; 2]]| {
        let [p, q, r] = idx.map(|i| v[i]);
        [
            b_[0] * p[0] + b_[1] * q[0] + b_[2] * r[0],
            b_[0] * p[1] + b_[1] * q[1] + b_[2] * r[1],
        ]
    };
    let (uv, (mut dpdu, mut dpdv)) = match &mesh.data.uvs {
        Some(uvs) => (
            interpolate2(uvs),
            triangle_derivatives([a, b, c], idx.map(|i| uvs[i])),
        ),
        None => ([b_[1], b_[2]], (b - a, c - a)),
    };
    let uv1 = mesh.data.uvs1.as_deref().map_or(uv, interpolate2);
    let interpolate4 = |v: &[[f32; 4]]| {
        let [p, q, r] = idx.map(|i| glam::Vec4::from(v[i]));
        b_[0] * p + b_[1] * q + b_[2] * r
    };
    let color = mesh
        .data
        .colors
        .as_deref()
        .map_or(glam::Vec4::ONE, interpolate4);
    if let Some(tangents) = &mesh.data.tangents {
        // The file's tangent frame, at the lengths of the surface's own
        // derivatives (which bump maps need).
        let t = interpolate4(tangents);
        let n = if front_face {
            shading_normal
        } else {
            -shading_normal
        };
        let tangent = Vec3::from_vec4(t).normalize_or_zero();
        let sign = if tangents[idx[0]][3] < 0.0 { -1.0 } else { 1.0 };
        let bitangent = sign * n.cross(tangent).normalize_or_zero();
        if tangent != Vec3::ZERO && bitangent != Vec3::ZERO {
            dpdu = tangent * dpdu.length();
            dpdv = bitangent * dpdv.length();
        }
    }
    HitRecord {
        point,
        normal,
        shading_normal,
        uv,
        t,
        front_face,
        material: mesh.material(k),
        object: index,
        uv1,
        dpdu,
        dpdv,
        color,
        error,
    }
}

/// ∂p/∂u and ∂p/∂v of the triangle of corners `p` with texture
/// coordinates `uv` (from the two edges and their differences of (u, v));
/// the two edges where the coordinates are degenerate.
fn triangle_derivatives(p: [Vec3; 3], uv: [[f32; 2]; 3]) -> (Vec3, Vec3) {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (du1, dv1) = (uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]);
    let (du2, dv2) = (uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]);
    let det = du1 * dv2 - dv1 * du2;
    let dpdu = (e1 * dv2 - e2 * dv1) / det;
    let dpdv = (e2 * du1 - e1 * du2) / det;
    if det != 0.0 && dpdu.is_finite() && dpdv.is_finite() {
        (dpdu, dpdv)
    } else {
        (e1, e2)
    }
}

/// Unit shading normal `n` turned to the side the geometric `normal` faces;
/// `normal` itself when `n` is zero (vertex normals that cancel).
fn facing(n: Vec3, normal: Vec3) -> Vec3 {
    if n == Vec3::ZERO {
        normal
    } else if n.dot(normal) < 0.0 {
        -n
    } else {
        n
    }
}

/// The barycentric coordinates of `p` (near the triangle's plane) in
/// `tri`, whose [`Triangle::area_normal`] is `n`, from the areas of the
/// sub-triangles, clamped to the triangle.
fn barycentrics(tri: &Triangle, n: Vec3, p: Point3) -> [f32; 3] {
    let [a, b, c] = tri.vertices;
    let n2 = n.length_squared();
    let b1 = (p - a).cross(c - a).dot(n) / n2;
    let b2 = (b - a).cross(p - a).dot(n) / n2;
    let (b1, b2) = (b1.clamp(0.0, 1.0), b2.clamp(0.0, 1.0));
    let s = b1 + b2;
    let (b1, b2) = if s > 1.0 { (b1 / s, b2 / s) } else { (b1, b2) };
    [1.0 - b1 - b2, b1, b2]
}

/// How much larger than the ray's origin and length a triangle's hit point
/// (by the size of its coordinates) may be before the point is taken along
/// the ray rather than rebuilt from the vertices: 16 times less rounded
/// there.
const ALONG: f32 = 16.0;

/// Barycentric coordinates `b` in `tri` (of area normal `n`) moved into
/// the triangle until the point is at least `margin` from every edge (to
/// the centroid where the triangle is narrower than that): a point a
/// rounding away from an edge may lie on the plane of a triangle meeting
/// this one at a crease, or past it, and a ray leaving from it would not
/// meet that triangle.
#[inline(always)]
fn within(tri: &Triangle, n: Vec3, b: [f32; 3], margin: f32) -> [f32; 3] {
    let [p, q, r] = tri.vertices;
    // bᵢ is bᵢ·|n|/|eᵢ| from the edge eᵢ opposite vertex i: the margin is
    // margin·|eᵢ|/|n| in bᵢ (compared squared and multiplied out, to leave
    // the square roots and the division to the rare points that close).
    let (n2, margin2) = (n.length_squared(), margin * margin);
    let e2 = [r - q, p - r, q - p].map(|e| e.length_squared());
    if (0..3).all(|i| b[i] * b[i] * n2 >= margin2 * e2[i]) {
        return b;
    }
    raise(
        b,
        e2.map(|e2| (f64::from(margin2 * e2) / f64::from(n2)).sqrt()),
    )
}

/// [`within`] for a point closer than the margins `m` to an edge.
#[cold]
#[inline(never)]
fn raise(b: [f32; 3], m: [f64; 3]) -> [f32; 3] {
    lift(b.map(f64::from), m).map(|b| b as f32)
}

/// The geometric normal, point, barycentric coordinates and error bound of
/// a hit at distance `t` along `ray` on `tri`, a triangle far larger than
/// the ray (see `triangle_record`): the distance worked out again in f64
/// (the test's may be off by 2⁻¹² of it), the point taken along the ray
/// there, and its coordinates and margin from the edges in f64.
#[cold]
#[inline(never)]
fn large_hit(
    tri: &Triangle,
    ray: &Ray,
    t: f32,
    error_scale: f32,
    margin: f32,
) -> (Vec3, Point3, [f32; 3], f32) {
    let geometric = Vec3::from(tri.area_normal().as_dvec3().normalize().as_vec3());
    let p = ray.at(tri.plane_distance(ray).unwrap_or(t));
    let origin = ray.origin().abs().max_element();
    let error = (origin + (p - ray.origin()).abs().max_element()) * error_scale;
    let (point, b) = within_large(tri, p, error.max(margin));
    (geometric, point, b, error)
}

/// [`within`] for a point `p` of the plane of `tri` far smaller than the
/// triangle (see [`ALONG`]), and its barycentric coordinates, worked out
/// in f64: in f32 they are rounded to the size of the triangle, which is
/// more than the point's distance from an edge can tell.
fn within_large(tri: &Triangle, p: Point3, margin: f32) -> (Point3, [f32; 3]) {
    let [a, b, c] = tri.vertices.map(|v| v.as_dvec3());
    let q = p.as_dvec3();
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    // Each from the triangle the point spans with the opposite edge (not 1
    // minus the others, which cancels near that edge).
    let part = |s: glam::DVec3, t: glam::DVec3| (s - q).cross(t - q).dot(n) / n2;
    let bary = [part(b, c), part(c, a), part(a, b)];
    let scale = f64::from(margin) / n2.sqrt();
    let m = [c - b, a - c, b - a].map(|e| scale * e.length());
    if (0..3).all(|i| bary[i] >= m[i]) {
        return (p, bary.map(|x| x as f32));
    }
    if (0..3).any(|i| bary[i] < -m[i]) {
        // Outside by more than the margin: the test's edges are rounded to
        // the size of the vertices, and the ray met the plane by the
        // neighbour's side of an edge it shares; the point stays there.
        return (p, lift(bary, [0.0; 3]).map(|x| x as f32));
    }
    // Raised to their margins as `lift` does it (the centroid where the
    // margins leave no room), the point moved by the change of its
    // coordinates, whose weights sum to 0, along the edges (adding the
    // vertices themselves would round the point to their size).
    let lifted = lift(bary, m);
    let shift = [0, 1, 2].map(|i| lifted[i] - bary[i]);
    let point = q + shift[1] * (b - a) + shift[2] * (c - a);
    (point.as_vec3().into(), lifted.map(|x| x as f32))
}

/// Barycentric coordinates `b` with every `bᵢ` at least `m[i]`: those
/// below raised to it, the others' excess over theirs shrunk to make up
/// the sum of 1 (the centroid where the margins leave no room).
fn lift(b: [f64; 3], m: [f64; 3]) -> [f64; 3] {
    let total = m[0] + m[1] + m[2];
    if !(total < 1.0) {
        return [1.0 / 3.0; 3];
    }
    let raised = [0, 1, 2].map(|i| b[i].max(m[i]) - m[i]);
    let k = (1.0 - total) / (raised[0] + raised[1] + raised[2]);
    [0, 1, 2].map(|i| m[i] + raised[i] * k)
}

/// Shapes shared by instances, with their own tree.
#[derive(Clone, Debug)]
pub(crate) struct Group {
    pub(crate) shapes: Shapes,
    pub(crate) bvh: Arc<Bvh>,
}

impl Group {
    /// The shapes with their tree (refused when the tree cannot fit: see
    /// [`Bvh::try_over`]).
    pub(crate) fn new(shapes: Shapes) -> Result<Group, MemoryError> {
        let bvh = Arc::new(Bvh::try_over(&shapes, Vec::new())?);
        Ok(Group { shapes, bvh })
    }
}

/// A group placed in the world: what an instance is made from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlacedGroup {
    /// The group placed.
    pub(crate) group: u32,
    /// Object to world at time 0.
    pub(crate) transform: Transform,
    /// The material replacing the group's own, if any.
    pub(crate) material: Option<u32>,
    /// How far it moves from time 0 to time 1.
    pub(crate) motion: Vec3,
}

/// What the record of a hit in an instance needs beyond the instance.
#[derive(Clone, Copy, Debug)]
struct Placed {
    /// The group placed.
    group: u32,
    /// The material replacing the group's own, if any.
    material: Option<u32>,
    /// The transform's linear part's Frobenius norm: at most how much it
    /// stretches the object's rounding.
    stretch: f32,
    /// The same of its inverse: a length of `shrink` × ℓ in the object is
    /// at least ℓ in the world.
    shrink: f32,
}

/// The compiled shapes of a scene.
#[derive(Clone, Debug)]
pub(crate) struct World {
    pub(crate) bvh: Bvh,
    top: Shapes,
    groups: Vec<Group>,
    /// Per instance of `bvh`.
    placed: Vec<Placed>,
    rounding: Rounding,
}

/// How a hit's rounding is handled: the factor of its error bound (0: rays
/// leave from the hit point itself, the notes' shadow acne), and whether a
/// sphere's hit point is moved back onto the sphere (scenes that give no
/// epsilon, where nothing else keeps a ray from finding again the sphere it
/// leaves; the books' figures keep their points as they were).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rounding {
    pub(crate) scale: f32,
    pub(crate) onto_spheres: bool,
}

/// The shapes of a scene as placed in the world, as plain coordinates: what
/// another intersector needs to trace the same rays against the same
/// surfaces (see [`crate::bench::traversal`]). Item numbers follow the
/// tree's: spheres, then quads, then triangles, so that a hit's
/// [`Hit::index`] names the same shape in each list.
#[derive(Clone, Debug, Default)]
pub struct PlacedShapes {
    /// Centre and radius of each sphere.
    pub spheres: Vec<[f32; 4]>,
    /// The corners Q, Q + u, Q + u + v, Q + v of each quad.
    pub quads: Vec<[[f32; 3]; 4]>,
    /// The vertices of each triangle.
    pub triangles: Vec<[[f32; 3]; 3]>,
}

impl World {
    /// Builds the tree over `top` and the placements `instances` of
    /// `groups` (refused when the tree cannot fit: see [`Bvh::try_over`]).
    pub(crate) fn new(
        top: Shapes,
        groups: Vec<Group>,
        instances: &[PlacedGroup],
        rounding: Rounding,
    ) -> Result<World, MemoryError> {
        let trees: Vec<Instance> = instances
            .iter()
            .map(|p| {
                let bvh = groups[p.group as usize].bvh.clone();
                Instance::moving(p.transform, p.motion, bvh)
            })
            .collect();
        let items = WorldItems {
            shapes: &top,
            instances: trees
                .iter()
                .enumerate()
                .map(|(i, inst)| Primitive::Instance {
                    bounds: inst.bounds(),
                    index: i as u32,
                })
                .collect(),
        };
        let bvh = Bvh::try_over(&items, trees)?;
        drop(items);
        let norm = |t: &Transform| {
            [Vec3::X, Vec3::Y, Vec3::Z]
                .map(|e| t.vector(e).length_squared())
                .iter()
                .sum::<f32>()
                .sqrt()
        };
        let placed = instances
            .iter()
            .map(|p| Placed {
                group: p.group,
                material: p.material,
                stretch: norm(&p.transform),
                shrink: norm(&p.transform.inverse()),
            })
            .collect();
        Ok(World {
            bvh,
            top,
            groups,
            placed,
            rounding,
        })
    }

    /// The world's shapes as placed, or `None` when some are placed by
    /// instances (which another intersector would need as instances too) or
    /// are disks or cylinders (which it would need to trace as lumen does).
    pub(crate) fn placed_shapes(&self) -> Option<PlacedShapes> {
        if !self.placed.is_empty() || !self.top.quadrics.is_empty() {
            return None;
        }
        let top = &self.top;
        let mut shapes = PlacedShapes {
            spheres: top
                .spheres
                .iter()
                .map(|s| s.center.extend(s.radius).to_array())
                .collect(),
            quads: top
                .quads
                .iter()
                .map(|(q, _)| {
                    [
                        q.corner,
                        q.corner + q.u,
                        q.corner + q.u + q.v,
                        q.corner + q.v,
                    ]
                    .map(|p| p.to_array())
                })
                .collect(),
            triangles: Vec::new(),
        };
        for mesh in &top.meshes {
            let positions = &mesh.data.positions;
            shapes.triangles.extend(
                mesh.data
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| positions[i as usize])),
            );
        }
        Some(shapes)
    }

    /// The radius of a sphere around everything (half the diagonal of the
    /// bounding box; 0 for an empty scene).
    pub(crate) fn bounding_radius(&self) -> f32 {
        let b = self.bvh.bounds();
        let diagonal = (b.max - b.min).length();
        if diagonal.is_finite() {
            0.5 * diagonal
        } else {
            0.0
        }
    }

    /// Bytes held by the meshes and the trees.
    pub(crate) fn memory_bytes(&self) -> usize {
        let shapes = std::iter::once(&self.top).chain(self.groups.iter().map(|g| &g.shapes));
        let meshes: usize = shapes
            .flat_map(|s| &s.meshes)
            .map(|m| m.data.heap_bytes())
            .sum();
        meshes + self.bvh_memory_bytes()
    }

    /// Bytes held by the scene's tree and the trees of its groups.
    pub(crate) fn bvh_memory_bytes(&self) -> usize {
        self.bvh.memory_bytes()
            + self
                .groups
                .iter()
                .map(|g| g.bvh.memory_bytes())
                .sum::<usize>()
    }

    /// The full record of a hit the tree found.
    #[inline(always)]
    pub(crate) fn record(&self, ray: &Ray, hit: Hit) -> HitRecord {
        match self.top.locate(hit.index as usize) {
            Ok(shape) => self
                .top
                .record(ray, hit.t, shape, hit.index, self.rounding, 0.0),
            Err(i) => self.instance_record(ray, hit, i),
        }
    }

    #[inline(never)]
    fn instance_record(&self, ray: &Ray, hit: Hit, i: usize) -> HitRecord {
        let placed = self.placed[i];
        let instance = &self.bvh.instances()[i];
        let transform = &instance.transform;
        let group = &self.groups[placed.group as usize];
        let (object_ray, scale) = instance.object_ray(ray);
        let shape = group
            .shapes
            .locate(hit.sub as usize)
            .expect("instances hold no instances");
        // Kept inside its edges by the world's rounding too: the point is
        // placed in the world with it, which could undo a margin of the
        // object's own (an instance far from the origin).
        let margin = ray.at(hit.t).abs().max_element() * self.rounding.scale * placed.shrink;
        let inner = group.shapes.record(
            &object_ray,
            hit.t * scale,
            shape,
            hit.sub,
            self.rounding,
            margin,
        );
        let point = instance.world_point(inner.point, ray.time());
        let (normal, front_face) = face_normal(ray, transform.normal(inner.outward_normal()));
        let shading_normal = if inner.is_smooth() {
            facing(transform.normal(inner.shading_normal), normal)
        } else {
            normal
        };
        HitRecord {
            point,
            normal,
            shading_normal,
            uv: inner.uv,
            t: hit.t,
            front_face,
            material: placed.material.unwrap_or(inner.material),
            object: hit.index,
            uv1: inner.uv1,
            dpdu: transform.vector(inner.dpdu),
            dpdv: transform.vector(inner.dpdv),
            color: inner.color,
            error: inner.error * placed.stretch * 4.0
                + point.abs().max_element() * self.rounding.scale,
        }
    }
}

/// Where each primitive's light is in the scene's [`Lights`] list.
#[derive(Clone, Debug, Default)]
pub(crate) struct LightIds {
    /// Per primitive of the top-level tree: its light, or [`NO_LIGHT`].
    top: Vec<u32>,
    /// Per instance: the light of its tree's primitive 0 (primitive k's is
    /// k further on), or [`NO_LIGHT`] when it holds no light.
    instance_first: Vec<u32>,
}

const NO_LIGHT: u32 = u32::MAX;

/// What a material emits: its emission, and the texture of its radiance.
type Emission = (Emissive, Option<u32>);

/// The texture coordinates a triangle without any has at its corners (its
/// record's (u, v) are then the barycentrics (b₁, b₂)).
const CORNER_UVS: [[f32; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

impl LightIds {
    /// The light that `hit` met, if it met one that can be sampled.
    #[inline]
    pub(crate) fn of(&self, hit: &Hit) -> Option<usize> {
        let index = hit.index as usize;
        let id = match self.top.get(index) {
            Some(&id) => id,
            None => {
                let first = *self.instance_first.get(index - self.top.len())?;
                if first == NO_LIGHT {
                    return None;
                }
                first + hit.sub
            }
        };
        (id != NO_LIGHT).then_some(id as usize)
    }
}

impl World {
    /// Every emissive primitive as a light in world space, and where each
    /// primitive's light is. A light's radiance (constant or a texture) and
    /// sides are its material's emission's; an instance holding any light gets one entry per
    /// primitive of its tree (black for the others), so that a hit's light
    /// is found by arithmetic.
    pub(crate) fn lights(&self, materials: &[Material]) -> (Vec<Light>, LightIds) {
        // What material `m` emits: its emission and texture, if any.
        let emitter = |m: u32| -> Option<Emission> {
            let material = &materials[m as usize];
            let emission = material.emission.filter(|_| material.emits())?;
            Some((emission.constant(), emission.radiance.texture()))
        };
        let mut lights = Vec::new();
        let mut ids = LightIds::default();
        // The emitting object the next light belongs to.
        let mut object = 0u32;
        let add = |shape: LightShape,
                   (emission, texture): Emission,
                   uvs,
                   object: u32,
                   lights: &mut Vec<Light>| {
            let texture = texture.map(|texture| LightTexture { texture, uvs });
            lights.push(Light {
                shape,
                emission,
                texture,
                object,
            });
            (lights.len() - 1) as u32
        };
        let top = &self.top;
        for s in &top.spheres {
            // A sphere that shines inwards only is found by the bounces.
            let sampled = emitter(s.material).filter(|(e, _)| !s.inward || e.two_sided);
            ids.top.push(sampled.map_or(NO_LIGHT, |e| {
                let shape = LightShape::Sphere {
                    center: s.center,
                    radius: s.radius,
                };
                object += 1;
                add(shape, e, CORNER_UVS, object, &mut lights)
            }));
        }
        for (q, material) in &top.quads {
            ids.top.push(emitter(*material).map_or(NO_LIGHT, |e| {
                // A light's outside is along u × v: a flipped quad is the
                // same parallelogram from its far corner along u, its
                // (α, β) then 1 − s and t of the sample's (s, t).
                let (shape, uvs) = if q.is_flipped() {
                    let shape = LightShape::Quad {
                        corner: q.corner + q.u,
                        u: -q.u,
                        v: q.v,
                    };
                    (shape, [[1.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
                } else {
                    let shape = LightShape::Quad {
                        corner: q.corner,
                        u: q.u,
                        v: q.v,
                    };
                    (shape, CORNER_UVS)
                };
                object += 1;
                add(shape, e, uvs, object, &mut lights)
            }));
        }
        for (q, material) in &top.quadrics {
            // A cylinder stretched across its axis is found by the bounces
            // only (as a stretched sphere): uniform (u, v) is not uniform
            // over its area.
            let sampled = emitter(*material).filter(|_| q.round());
            ids.top.push(sampled.map_or(NO_LIGHT, |e| {
                object += 1;
                add(LightShape::Quadric(*q), e, CORNER_UVS, object, &mut lights)
            }));
        }
        for mesh in &top.meshes {
            object += 1;
            for k in 0..mesh.data.triangles.len() {
                ids.top
                    .push(emitter(mesh.material(k)).map_or(NO_LIGHT, |e| {
                        let (vertices, uvs) = mesh.outward_corners(k);
                        add(
                            LightShape::Triangle { vertices },
                            e,
                            uvs,
                            object,
                            &mut lights,
                        )
                    }));
            }
        }
        for (i, placed) in self.placed.iter().enumerate() {
            let group = &self.groups[placed.group as usize];
            let material = |m: u32| emitter(placed.material.unwrap_or(m));
            let meshes = &group.shapes.meshes;
            let any = meshes.iter().any(|mesh| {
                (0..mesh.data.triangles.len()).any(|k| material(mesh.material(k)).is_some())
            });
            // A moving light is found by the bounces only: its samples would
            // have to be drawn where it is at each path's time.
            let moves = self.bvh.instances()[i].motion != Vec3::ZERO;
            let only_meshes = group.shapes.spheres.is_empty()
                && group.shapes.quads.is_empty()
                && group.shapes.quadrics.is_empty();
            if !any || moves || !only_meshes {
                ids.instance_first.push(NO_LIGHT);
                continue;
            }
            ids.instance_first.push(lights.len() as u32);
            object += 1;
            let transform = &self.bvh.instances()[i].transform;
            // Keep the outward side the hit record's: a mirroring transform
            // reverses the corners' order.
            let mirrors = transform.mirrors();
            for mesh in meshes {
                for k in 0..mesh.data.triangles.len() {
                    let (corners, [p, q, r]) = mesh.outward_corners(k);
                    let [a, b, c] = corners.map(|p| transform.point(p));
                    let (vertices, uvs) = if mirrors {
                        ([a, c, b], [p, r, q])
                    } else {
                        ([a, b, c], [p, q, r])
                    };
                    let black = Emissive {
                        radiance: Color::ZERO,
                        two_sided: false,
                    };
                    let e = material(mesh.material(k)).unwrap_or((black, None));
                    add(
                        LightShape::Triangle { vertices },
                        e,
                        uvs,
                        object,
                        &mut lights,
                    );
                }
            }
        }
        if lights.is_empty() {
            ids = LightIds::default();
        }
        (lights, ids)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_at_a_triangles_edge_are_moved_in_by_the_margin() {
        // The right triangle (0,0), (2,0), (0,2) in z = 0.
        let tri = Triangle::new(Vec3::ZERO, 2.0 * Vec3::X, 2.0 * Vec3::Y);
        let n = tri.area_normal();
        let point =
            |b: [f32; 3]| b[0] * tri.vertices[0] + b[1] * tri.vertices[1] + b[2] * tri.vertices[2];
        let margin = 1e-3;
        // On the edge y = 0: moved to y = margin.
        let b = within(&tri, n, [0.5, 0.5, 0.0], margin);
        assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert!((point(b).y - margin).abs() < 1e-6, "{b:?}");
        // On the hypotenuse x + y = 2, at a corner of it: at least the
        // margin from all three edges.
        let b = within(&tri, n, [0.0, 1.0, 0.0], margin);
        let p = point(b);
        assert!(p.y >= margin * 0.999 && (2.0 - p.x - p.y) / 2f32.sqrt() >= margin * 0.999);
        // Inside the margin nothing moves, and nothing without one.
        assert_eq!(within(&tri, n, [0.2, 0.3, 0.5], margin), [0.2, 0.3, 0.5]);
        assert_eq!(within(&tri, n, [0.5, 0.5, 0.0], 0.0), [0.5, 0.5, 0.0]);
        // Narrower than the margin: the centroid.
        assert_eq!(within(&tri, n, [1.0, 0.0, 0.0], 1.0), [1.0 / 3.0; 3]);
    }
}
