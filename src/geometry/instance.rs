//! Instances: a tree placed in the world by a transform. A mesh placed N
//! times is stored (and its BVH built) once; the scene's tree holds N
//! instances over it, each a box in the world and a transform (a two-level
//! BVH). A ray meeting an instance is taken into the object's space and
//! traced through the shared tree there.

use crate::geometry::bvh::{Bvh, SLACK};
use crate::geometry::bvh_build::Aabb;
use crate::geometry::transform::Transform;
use crate::math::Interval;
use crate::ray::Ray;
use std::sync::Arc;

/// A shared tree placed by a transform.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Object to world.
    pub transform: Transform,
    /// The tree, in object space (it holds no instances itself).
    pub bvh: Arc<Bvh>,
}

impl Instance {
    /// Places `bvh` by `transform`.
    pub fn new(transform: Transform, bvh: Arc<Bvh>) -> Self {
        Instance { transform, bvh }
    }

    /// The world box of the placed tree.
    pub fn bounds(&self) -> Aabb {
        self.transform.bounds(&self.bvh.bounds())
    }

    /// The nearest hit of the world ray `ray` strictly beyond `t_min` and
    /// not beyond `t_max` (with the traversal's margin): the world distance
    /// and the index of the primitive in the instance's tree.
    ///
    /// The object-space interval is widened by the traversal's margin, so
    /// that a hit whose world distance rounds to `t_max` is still found
    /// whatever `t_max` is when the instance is visited: the caller orders
    /// the result by (distance, index) as for any other primitive, and the
    /// nearest hit does not depend on the order of the visit.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<(f32, u32)> {
        let (object_ray, scale) = self.transform.to_object_ray(ray);
        let interval = Interval::new(t_min * scale, t_max * scale * SLACK);
        let hit = self.bvh.hit(&object_ray, interval)?;
        let t = hit.t / scale;
        (t > t_min).then_some((t, hit.index))
    }

    /// Whether the world ray hits the instance strictly inside `interval`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, interval: Interval) -> bool {
        let (object_ray, scale) = self.transform.to_object_ray(ray);
        let within = Interval::new(interval.min * scale, interval.max * scale);
        self.bvh.occluded(&object_ray, within)
    }
}
