//! Building the hierarchy: a binary tree chosen by the surface area heuristic.
//!
//! Built top-down with the surface area heuristic (SAH) over binned centroids,
//! into an array in depth-first order: the left child of node `i` is node
//! `i + 1`, and each interior node stores the index of its right child.
//! [`super::bvh::Bvh`] then collapses this binary tree into its 4-wide form.

use crate::geometry::primitive::{Kind, Primitive};
use crate::math::{Point3, Vec3};

/// Leaves hold at most this many primitives, all of one kind: one packet,
/// tested as one 8-lane vector with AVX2 or as two 4-lane halves otherwise.
pub const MAX_LEAF: usize = 8;
/// Number of centroid bins evaluated per axis when choosing a split.
const BINS: usize = 12;
/// Relative cost of visiting a node against testing one packet of
/// primitives. A packet tests up to eight for the price of one, so the leaf
/// cost counts packets, not primitives.
const TRAVERSAL_COST: f32 = 1.0;
const INTERSECT_COST: f32 = 1.0;
/// Below this depth every split is a median split, which halves the items:
/// the tree depth stays bounded (and the traversal stack can be fixed) even
/// for adversarial inputs on which SAH peels one item at a time.
const MAX_SAH_DEPTH: usize = 48;

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Point3,
    /// Largest corner.
    pub max: Point3,
}

impl Aabb {
    /// The box that contains nothing.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box of `(min, max)`.
    pub fn new((min, max): (Point3, Point3)) -> Aabb {
        Aabb { min, max }
    }

    /// The box's centre.
    pub fn center(&self) -> Point3 {
        0.5 * (self.min + self.max)
    }

    /// Grows the box to contain `other`.
    pub fn grow(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    fn grow_point(&mut self, p: Point3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Surface area (0 for an empty box).
    pub fn surface_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

/// A node of the binary tree.
#[derive(Clone, Copy, Debug)]
pub struct BinaryNode {
    /// Bounds of everything below.
    pub bounds: Aabb,
    /// Leaf: index of the first primitive. Interior: index of the right child.
    pub offset: u32,
    /// Number of primitives in a leaf; 0 for an interior node.
    pub count: u32,
}

impl BinaryNode {
    /// Whether this node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

struct BuildItem {
    bounds: Aabb,
    centroid: Point3,
    kind: Kind,
    index: u32,
}

/// The binary SAH tree over `primitives` (empty for none), and the order of
/// the primitives in its leaves: leaf primitives `offset..offset + count`
/// are `primitives[order[offset]]`, …. Every leaf holds one kind.
pub fn build_binary(primitives: &[Primitive]) -> (Vec<BinaryNode>, Vec<u32>) {
    let mut items: Vec<BuildItem> = primitives
        .iter()
        .enumerate()
        .map(|(i, p)| BuildItem {
            bounds: p.bounds(),
            centroid: p.centroid(),
            kind: p.kind(),
            index: i as u32,
        })
        .collect();
    let mut nodes = Vec::with_capacity(2 * primitives.len().div_ceil(2));
    if !items.is_empty() {
        build(&mut items, 0, 0, &mut nodes);
    }
    let order = items.iter().map(|it| it.index).collect();
    (nodes, order)
}

/// Builds the subtree over `items` into `nodes`, returning its node index.
fn build(
    items: &mut [BuildItem],
    first: usize,
    depth: usize,
    nodes: &mut Vec<BinaryNode>,
) -> usize {
    let mut bounds = Aabb::EMPTY;
    let mut centroid_bounds = Aabb::EMPTY;
    for it in items.iter() {
        bounds.grow(&it.bounds);
        centroid_bounds.grow_point(it.centroid);
    }
    let node_index = nodes.len();
    nodes.push(BinaryNode {
        bounds,
        offset: first as u32,
        count: items.len() as u32,
    });
    if items.len() <= 1 {
        return node_index;
    }

    let split = if depth < MAX_SAH_DEPTH {
        best_split(items, &bounds, &centroid_bounds)
    } else {
        None
    };
    let first_kind = items[0].kind;
    let one_kind = items.iter().all(|it| it.kind == first_kind);
    let mid = match split {
        Some((axis, position)) => partition(items, |it| it.centroid[axis] < position),
        None if items.len() <= MAX_LEAF && one_kind => return node_index,
        // A leaf holds one kind: kinds that would share one part company.
        None if items.len() <= MAX_LEAF => partition(items, |it| it.kind == first_kind),
        None => {
            // SAH prefers one leaf but it would be too large (or all centroids
            // coincide, or the tree is already deep): split at the median of
            // the widest axis.
            let extent = centroid_bounds.max - centroid_bounds.min;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
            mid
        }
    };
    let mid = if mid == 0 || mid == items.len() {
        items.len() / 2
    } else {
        mid
    };
    let (left, right) = items.split_at_mut(mid);
    build(left, first, depth + 1, nodes);
    let right_index = build(right, first + mid, depth + 1, nodes);
    nodes[node_index].offset = right_index as u32;
    nodes[node_index].count = 0;
    node_index
}

/// Cost of a leaf of `n` primitives, tested a packet at a time.
fn leaf_cost(n: usize) -> f32 {
    INTERSECT_COST * n.div_ceil(MAX_LEAF) as f32
}

/// The SAH-best split `(axis, position)`, or `None` if a leaf is cheaper.
fn best_split(items: &[BuildItem], bounds: &Aabb, centroid_bounds: &Aabb) -> Option<(usize, f32)> {
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
                + (leaf_cost(count) * acc.surface_area()
                    + leaf_cost(right_count[b]) * right_area[b])
                    / parent_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + b as f32 / scale));
            }
        }
    }
    match best {
        Some((cost, axis, position)) if cost < leaf_cost(items.len()) || items.len() > MAX_LEAF => {
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
