//! A bounding volume hierarchy over spheres.
//!
//! Built top-down with the surface area heuristic (SAH) over binned centroids,
//! then flattened into an array in depth-first order: the left child of node
//! `i` is node `i + 1`, and each interior node stores the index of its right
//! child. Traversal visits the nearer child first and skips any node whose
//! box lies beyond the closest hit found so far.

use crate::geometry::Sphere;
use crate::math::{Interval, Point3, Vec3};
use crate::ray::Ray;

/// Leaves hold at most this many spheres.
const MAX_LEAF: usize = 4;
/// Number of centroid bins evaluated per axis when choosing a split.
const BINS: usize = 12;
/// Relative cost of visiting a node against testing one sphere.
const TRAVERSAL_COST: f32 = 1.0;
const INTERSECT_COST: f32 = 1.0;

#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: Point3,
    max: Point3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    fn grow_point(&mut self, p: Point3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    fn surface_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Slab test: the entry distance if the ray crosses the box within `[t_min, t_max]`.
    #[inline]
    fn entry(&self, origin: Vec3, inv_dir: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        let near = t0.min(t1).max_element().max(t_min);
        let far = t0.max(t1).min_element().min(t_max);
        (near <= far).then_some(near)
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of the first sphere. Interior: index of the right child.
    offset: u32,
    /// Number of spheres in a leaf; 0 for an interior node.
    count: u16,
    /// Split axis of an interior node (decides which child is nearer).
    axis: u16,
}

/// The nearest sphere a ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the sphere in the order the BVH was built from.
    pub index: u32,
}

/// A flattened SAH bounding volume hierarchy over a set of spheres.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// The spheres, reordered so that every leaf's spheres are contiguous.
    spheres: Vec<Sphere>,
    /// For each reordered sphere, its index in the input.
    indices: Vec<u32>,
}

struct BuildItem {
    bounds: Aabb,
    centroid: Point3,
    index: u32,
}

impl Bvh {
    /// Builds the hierarchy over `spheres`.
    pub fn new(spheres: &[Sphere]) -> Self {
        let mut items: Vec<BuildItem> = spheres
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (min, max) = s.bounds();
                BuildItem {
                    bounds: Aabb { min, max },
                    centroid: s.center,
                    index: i as u32,
                }
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * spheres.len().max(1));
        if !items.is_empty() {
            build(&mut items, 0, &mut nodes);
        }
        let indices: Vec<u32> = items.iter().map(|it| it.index).collect();
        let spheres = indices.iter().map(|&i| spheres[i as usize]).collect();
        Bvh {
            nodes,
            spheres,
            indices,
        }
    }

    /// Number of nodes (for statistics and memory estimates).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The nearest sphere hit by `ray` within `interval`.
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv_dir = ray.direction.recip();
        let dir_negative = [
            ray.direction.x < 0.0,
            ray.direction.y < 0.0,
            ray.direction.z < 0.0,
        ];
        let mut closest = interval.max;
        let mut best: Option<u32> = None;
        let mut stack = [0u32; 64];
        let mut top = 0usize;
        let mut node_index = 0usize;
        loop {
            let node = &self.nodes[node_index];
            if node
                .bounds
                .entry(ray.origin, inv_dir, interval.min, closest)
                .is_some()
            {
                if node.count > 0 {
                    let first = node.offset as usize;
                    for i in first..first + node.count as usize {
                        let range = Interval::new(interval.min, closest);
                        if let Some(t) = self.spheres[i].hit(ray, range) {
                            closest = t;
                            best = Some(i as u32);
                        }
                    }
                } else {
                    // Visit the child on the ray's side of the split first.
                    let (near, far) = if dir_negative[node.axis as usize] {
                        (node.offset as usize, node_index + 1)
                    } else {
                        (node_index + 1, node.offset as usize)
                    };
                    stack[top] = far as u32;
                    top += 1;
                    node_index = near;
                    continue;
                }
            }
            if top == 0 {
                break;
            }
            top -= 1;
            node_index = stack[top] as usize;
        }
        best.map(|i| Hit {
            t: closest,
            index: self.indices[i as usize],
        })
    }
}

/// Builds the subtree over `items` into `nodes`, returning its node index.
fn build(items: &mut [BuildItem], first: usize, nodes: &mut Vec<Node>) -> usize {
    let mut bounds = Aabb::EMPTY;
    let mut centroid_bounds = Aabb::EMPTY;
    for it in items.iter() {
        bounds.grow(&it.bounds);
        centroid_bounds.grow_point(it.centroid);
    }
    let node_index = nodes.len();
    nodes.push(Node {
        bounds,
        offset: first as u32,
        count: items.len() as u16,
        axis: 0,
    });
    if items.len() <= 1 {
        return node_index;
    }

    let split = best_split(items, &bounds, &centroid_bounds);
    let mid = match split {
        Some((axis, position)) => {
            let mid = partition(items, |it| it.centroid[axis] < position);
            nodes[node_index].axis = axis as u16;
            mid
        }
        None if items.len() <= MAX_LEAF => return node_index,
        None => {
            // SAH prefers one leaf but it would be too large (or all centroids
            // coincide): split at the median of the widest axis.
            let extent = centroid_bounds.max - centroid_bounds.min;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            items.sort_by(|a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
            nodes[node_index].axis = axis as u16;
            items.len() / 2
        }
    };
    let mid = if mid == 0 || mid == items.len() {
        items.len() / 2
    } else {
        mid
    };
    let (left, right) = items.split_at_mut(mid);
    build(left, first, nodes);
    let right_index = build(right, first + mid, nodes);
    nodes[node_index].offset = right_index as u32;
    nodes[node_index].count = 0;
    node_index
}

/// The SAH-best split `(axis, position)`, or `None` if a leaf is cheaper.
fn best_split(items: &[BuildItem], bounds: &Aabb, centroid_bounds: &Aabb) -> Option<(usize, f32)> {
    let leaf_cost = INTERSECT_COST * items.len() as f32;
    let parent_area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        let lo = centroid_bounds.min[axis];
        let extent = centroid_bounds.max[axis] - lo;
        if !(extent > 0.0) {
            continue;
        }
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_counts = [0usize; BINS];
        let scale = BINS as f32 / extent;
        for it in items {
            let b = (((it.centroid[axis] - lo) * scale) as usize).min(BINS - 1);
            bin_counts[b] += 1;
            bin_bounds[b].grow(&it.bounds);
        }
        // Sweep from the right to know the cost of each right-hand side.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for b in (1..BINS).rev() {
            acc.grow(&bin_bounds[b]);
            count += bin_counts[b];
            right_area[b] = acc.surface_area();
            right_count[b] = count;
        }
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for b in 1..BINS {
            acc.grow(&bin_bounds[b - 1]);
            count += bin_counts[b - 1];
            if count == 0 || right_count[b] == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + INTERSECT_COST
                    * (count as f32 * acc.surface_area() + right_count[b] as f32 * right_area[b])
                    / parent_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + b as f32 / scale));
            }
        }
    }
    match best {
        Some((cost, axis, position)) if cost < leaf_cost || items.len() > MAX_LEAF => {
            Some((axis, position))
        }
        _ => None,
    }
}

/// Moves the items satisfying `pred` to the front; returns how many there are.
fn partition(items: &mut [BuildItem], pred: impl Fn(&BuildItem) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn brute_force(spheres: &[Sphere], ray: &Ray, interval: Interval) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        for (i, s) in spheres.iter().enumerate() {
            let max = best.map_or(interval.max, |b| b.0);
            if let Some(t) = s.hit(ray, Interval::new(interval.min, max)) {
                best = Some((t, i as u32));
            }
        }
        best
    }

    #[test]
    fn bvh_finds_the_same_nearest_hit_as_brute_force() {
        let mut rng = Rng::new(3);
        let spheres: Vec<Sphere> = (0..500)
            .map(|_| {
                let c = Vec3::new(
                    rng.range_f32(-20.0, 20.0),
                    rng.range_f32(-20.0, 20.0),
                    rng.range_f32(-20.0, 20.0),
                );
                Sphere::new(c, rng.range_f32(0.1, 2.0))
            })
            .collect();
        let bvh = Bvh::new(&spheres);
        let interval = Interval::new(0.001, f32::INFINITY);
        for _ in 0..5000 {
            let origin = Vec3::new(
                rng.range_f32(-30.0, 30.0),
                rng.range_f32(-30.0, 30.0),
                rng.range_f32(-30.0, 30.0),
            );
            let ray = Ray::new(origin, crate::sampling::unit_vector(&mut rng));
            let expected = brute_force(&spheres, &ray, interval);
            let got = bvh.hit(&ray, interval).map(|h| (h.t, h.index));
            assert_eq!(got, expected);
        }
    }

    #[test]
    fn empty_and_single_sphere_scenes_work() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let all = Interval::new(0.0, f32::INFINITY);
        assert!(Bvh::new(&[]).hit(&ray, all).is_none());
        let one = Bvh::new(&[Sphere::new(Vec3::ZERO, 1.0)]);
        let hit = one.hit(&ray, all).expect("hits the sphere");
        assert_eq!((hit.t, hit.index), (4.0, 0));
    }
}
