//! The closed set of shapes a BVH holds: spheres, triangles, quads, disks
//! and cylinders, and instances of other trees. Each operation is one
//! `match` over the kind; each kind's intersection is one kernel (see
//! [`crate::lanes`]), disks and cylinders one at a time.

use crate::geometry::bvh_build::Aabb;
use crate::geometry::{Quad, Quadric, Sphere, Triangle};
use crate::math::Interval;
use crate::ray::Ray;

/// The kind of a primitive, which tags the BVH's leaves: a leaf holds
/// primitives of one kind, tested by that kind's kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// A sphere.
    Sphere = 0,
    /// A triangle.
    Triangle = 1,
    /// A parallelogram.
    Quad = 2,
    /// A placed copy of another tree.
    Instance = 3,
    /// A disk or a cylinder ([`Quadric`]). It and the instances are tested
    /// out of line, one at a time (see `Bvh`'s leaf tests).
    Quadric = 4,
}

/// How many kinds there are.
pub const KINDS: usize = 5;

impl Kind {
    /// The kind numbered `n` (its discriminant).
    #[inline(always)]
    pub fn from_index(n: u32) -> Kind {
        match n & 7 {
            0 => Kind::Sphere,
            1 => Kind::Triangle,
            2 => Kind::Quad,
            3 => Kind::Instance,
            _ => Kind::Quadric,
        }
    }
}

/// The items a BVH is built over, numbered from 0, each made when the
/// build asks for it: a slice of primitives, or shapes stored otherwise (a
/// scene's meshes), which then need not be copied into a [`Primitive`] each
/// (112 bytes, five times a mesh's own triangle) for the build.
pub trait PrimitiveSet: Sync {
    /// How many items there are.
    fn count(&self) -> usize;
    /// Item `i`, for `i < self.count()`.
    fn primitive(&self, i: usize) -> Primitive;

    /// The kind of item `i` (which a set may know without making it).
    fn kind(&self, i: usize) -> Kind {
        self.primitive(i).kind()
    }
}

impl PrimitiveSet for [Primitive] {
    fn count(&self) -> usize {
        self.len()
    }

    fn primitive(&self, i: usize) -> Primitive {
        self[i]
    }
}

/// One primitive, as a BVH is built from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// A sphere.
    Sphere(Sphere),
    /// A triangle.
    Triangle(Triangle),
    /// A parallelogram.
    Quad(Quad),
    /// A disk or a cylinder.
    Quadric(Quadric),
    /// Instance number `index` of the scene, whose world bounds are `bounds`.
    Instance {
        /// The instance's world-space bounding box.
        bounds: Aabb,
        /// Its number among the scene's instances.
        index: u32,
    },
}

impl Primitive {
    /// The kind of this primitive.
    pub fn kind(&self) -> Kind {
        match self {
            Primitive::Sphere(_) => Kind::Sphere,
            Primitive::Triangle(_) => Kind::Triangle,
            Primitive::Quad(_) => Kind::Quad,
            Primitive::Quadric(_) => Kind::Quadric,
            Primitive::Instance { .. } => Kind::Instance,
        }
    }

    /// The axis-aligned bounding box.
    pub fn bounds(&self) -> Aabb {
        match self {
            Primitive::Sphere(s) => Aabb::new(s.bounds()),
            Primitive::Triangle(t) => Aabb::new(t.bounds()),
            Primitive::Quad(q) => Aabb::new(q.bounds()),
            Primitive::Quadric(q) => q.bounds(),
            Primitive::Instance { bounds, .. } => *bounds,
        }
    }

    /// The distance along unit `ray` to the primitive, if it is hit strictly
    /// inside `interval`: the one-lane kernel of its kind, which gives the
    /// same bits as the BVH's packet tests. Instances answer `None` (their
    /// shapes are in another tree).
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<f32> {
        match self {
            Primitive::Sphere(s) => s.hit(ray, interval),
            Primitive::Triangle(t) => t.hit(ray, interval),
            Primitive::Quad(q) => q.hit(ray, interval),
            Primitive::Quadric(q) => q.hit(ray, interval.min).filter(|&t| t < interval.max),
            Primitive::Instance { .. } => None,
        }
    }

    /// The point the BVH build sorts the primitive by.
    pub fn centroid(&self) -> crate::math::Point3 {
        match self {
            Primitive::Sphere(s) => s.center,
            other => other.bounds().center(),
        }
    }
}
