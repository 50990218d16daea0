//! Instances: a tree placed in the world by a transform. A mesh placed N
//! times is stored (and its BVH built) once; the scene's tree holds N
//! instances over it, each a box in the world and a transform (a two-level
//! BVH). A ray meeting an instance is taken into the object's space and
//! traced through the shared tree there.
//!
//! An instance may also move: placed by its transform at time 0, it is
//! carried along `motion` in a straight line, reaching the end at time 1
//! (motion blur, as the moving spheres of *The Next Week*). A ray at time t
//! sees it moved by t · `motion`.

use crate::geometry::bvh::{Bvh, SLACK};
use crate::geometry::bvh_build::Aabb;
use crate::geometry::transform::Transform;
use crate::math::{Interval, Point3, Vec3};
use crate::ray::Ray;
use std::sync::Arc;

/// A shared tree placed by a transform.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Object to world.
    pub transform: Transform,
    /// The tree, in object space (it holds no instances itself).
    pub bvh: Arc<Bvh>,
    /// How far it moves, in the world, from time 0 to time 1 (zero for an
    /// instance that stays put).
    pub motion: Vec3,
    /// Whether it only moves (its transform is the identity): a moving
    /// shape's ray needs no transform, only the shift.
    only_moves: bool,
}

impl Instance {
    /// Places `bvh` by `transform`.
    pub fn new(transform: Transform, bvh: Arc<Bvh>) -> Self {
        Self::moving(transform, Vec3::ZERO, bvh)
    }

    /// Places `bvh` by `transform` at time 0, moving by `motion` until
    /// time 1.
    pub fn moving(transform: Transform, motion: Vec3, bvh: Arc<Bvh>) -> Self {
        Instance {
            transform,
            bvh,
            motion,
            only_moves: motion != Vec3::ZERO && transform.is_identity(),
        }
    }

    /// The world box of the placed tree, over the whole of its movement
    /// from time 0 to time 1.
    pub fn bounds(&self) -> Aabb {
        let start = self.transform.bounds(&self.bvh.bounds());
        if self.motion == Vec3::ZERO || !start.min.cmple(start.max).all() {
            return start;
        }
        let end = Aabb {
            min: start.min + self.motion,
            max: start.max + self.motion,
        };
        // Widened by the rounding of the moved point (see `object_ray`).
        let margin = f32::EPSILON * (start.min.abs().max(start.max.abs()) + self.motion.abs());
        let mut all = start;
        all.grow(&end);
        all.min -= margin;
        all.max += margin;
        all
    }

    /// The world ray `ray` in the tree's space at the ray's time, with the
    /// scale between distances there and in the world (see
    /// [`Transform::to_object_ray`]).
    #[inline]
    pub fn object_ray(&self, ray: &Ray) -> (Ray, f32) {
        if self.motion == Vec3::ZERO {
            return self.transform.to_object_ray(ray);
        }
        // Moving the ray back is moving the instance forward.
        let back = Ray::timed(
            ray.origin() - ray.time() * self.motion,
            ray.direction,
            ray.time(),
        );
        if self.only_moves {
            return (back, 1.0);
        }
        self.transform.to_object_ray(&back)
    }

    /// Where the instance's point `p` (placed at time 0) is at `time`.
    #[inline]
    pub fn world_point(&self, p: Point3, time: f32) -> Point3 {
        if self.only_moves {
            return p + time * self.motion;
        }
        let placed = self.transform.point(p);
        if self.motion == Vec3::ZERO {
            placed
        } else {
            placed + time * self.motion
        }
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
        let (object_ray, scale) = self.object_ray(ray);
        let interval = Interval::new(t_min * scale, t_max * scale * SLACK);
        let hit = self.bvh.hit(&object_ray, interval)?;
        let t = hit.t / scale;
        (t > t_min).then_some((t, hit.index))
    }

    /// Whether the world ray hits the instance strictly inside `interval`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, interval: Interval) -> bool {
        self.any_hit(ray, interval).is_some()
    }

    /// The first hit the traversal finds of the world ray strictly inside
    /// `interval` (in the instance's space), not necessarily the nearest:
    /// its world distance and the index of the primitive in the
    /// instance's tree.
    #[inline]
    pub fn any_hit(&self, ray: &Ray, interval: Interval) -> Option<(f32, u32)> {
        let (object_ray, scale) = self.object_ray(ray);
        let within = Interval::new(interval.min * scale, interval.max * scale);
        let hit = self.bvh.any_hit(&object_ray, within)?;
        Some((hit.t / scale, hit.index))
    }
}
