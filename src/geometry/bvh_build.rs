//! Building the hierarchy: a binary tree chosen by the surface area heuristic.
//!
//! Built top-down with the surface area heuristic (SAH) over binned centroids,
//! into an array in depth-first order: the left child of node `i` is node
//! `i + 1`, and each interior node stores the index of its right child.
//! [`super::bvh::Bvh`] then collapses this binary tree into its wide form.

use crate::geometry::primitive::{Kind, PrimitiveSet, KINDS};
use crate::math::{Point3, Vec3};
use std::collections::TryReserveError;

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

/// A node of the binary tree: 32 bytes (its box in plain arrays; as an
/// [`Aabb`] of aligned vectors it took 48).
#[derive(Clone, Copy, Debug)]
pub struct BinaryNode {
    min: [f32; 3],
    max: [f32; 3],
    /// Leaf: index of the first primitive. Interior: index of the right child.
    pub offset: u32,
    /// Number of primitives in a leaf; 0 for an interior node.
    pub count: u32,
}

impl BinaryNode {
    fn new(bounds: Aabb, offset: usize, count: usize) -> Self {
        BinaryNode {
            min: bounds.min.to_array(),
            max: bounds.max.to_array(),
            offset: offset as u32,
            count: count as u32,
        }
    }

    /// Bounds of everything below.
    #[inline(always)]
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: Vec3::from_array(self.min),
            max: Vec3::from_array(self.max),
        }
    }

    /// Whether this node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// A primitive as the build sorts it: in plain arrays, 44 bytes, where the
/// aligned vectors of an [`Aabb`] and a [`Point3`] took 64 (the build's
/// largest array, one per primitive).
#[derive(Clone, Copy)]
pub(super) struct BuildItem {
    min: [f32; 3],
    max: [f32; 3],
    centroid: [f32; 3],
    index: u32,
    kind: Kind,
}

impl BuildItem {
    #[inline(always)]
    fn bounds(&self) -> Aabb {
        Aabb {
            min: Vec3::from_array(self.min),
            max: Vec3::from_array(self.max),
        }
    }
}

/// Subtrees of at least this many items are built two at a time, each on a
/// thread of its own (below it, handing work to another thread costs more
/// than it saves).
const PARALLEL_ITEMS: usize = 1 << 14;

/// A binary tree as built.
pub struct BinaryTree {
    /// The nodes, the root first (empty for no primitives).
    pub nodes: Vec<BinaryNode>,
    /// The order of the primitives in the leaves: leaf primitives
    /// `offset..offset + count` are `primitives[order[offset]]`, ….
    pub order: Vec<u32>,
    /// The number of leaves of each [`Kind`] (every leaf holds one kind).
    pub leaves: [usize; KINDS],
}

/// The binary SAH tree over `primitives`.
///
/// Large trees are built on several threads; the tree is the same, node
/// for node, as the one built on one thread.
///
/// Its large vectors are reserved fallibly: where the system refuses one
/// (a limit on the address space), the build ends with the error rather
/// than the process.
pub fn build_binary<P: PrimitiveSet + ?Sized>(
    primitives: &P,
) -> Result<BinaryTree, TryReserveError> {
    use rayon::prelude::*;
    let n = primitives.count();
    let mut items: Vec<BuildItem> = Vec::new();
    items.try_reserve_exact(n)?;
    items.par_extend((0..n).into_par_iter().map(|i| {
        let p = primitives.primitive(i);
        let bounds = p.bounds();
        BuildItem {
            min: bounds.min.to_array(),
            max: bounds.max.to_array(),
            centroid: p.centroid().to_array(),
            index: i as u32,
            kind: p.kind(),
        }
    }));
    let nodes = if items.is_empty() {
        Vec::new()
    } else {
        // As for the halves below.
        let mut nodes = build_parallel(&mut items, 0, 0, reserved(n)?)?;
        nodes.shrink_to_fit();
        nodes
    };
    let mut leaves = [0; KINDS];
    for n in nodes.iter().filter(|n| n.is_leaf()) {
        leaves[items[n.offset as usize].kind as usize] += 1;
    }
    let order = items.iter().map(|it| it.index).collect();
    Ok(BinaryTree {
        nodes,
        order,
        leaves,
    })
}

/// An empty node vector with room for `n` nodes, or the system's refusal.
fn reserved(n: usize) -> Result<Vec<BinaryNode>, TryReserveError> {
    let mut nodes = Vec::new();
    nodes.try_reserve_exact(n)?;
    Ok(nodes)
}

/// [`build`] of the subtree over `items` appended to `nodes`, its two
/// halves on two threads when it is large: the left half goes on into
/// `nodes`, the right into a vector of its own, appended after it with its
/// node indices moved by where it lands.
fn build_parallel(
    items: &mut [BuildItem],
    first: usize,
    depth: usize,
    mut nodes: Vec<BinaryNode>,
) -> Result<Vec<BinaryNode>, TryReserveError> {
    if items.len() < PARALLEL_ITEMS {
        build(items, first, depth, &mut nodes);
        return Ok(nodes);
    }
    let node_index = nodes.len();
    let (bounds, mid) = split(items, depth);
    nodes.push(BinaryNode::new(bounds, first, items.len()));
    let Some(mid) = mid else {
        return Ok(nodes);
    };
    let (left, right) = items.split_at_mut(mid);
    let (nodes, right) = rayon::join(
        move || build_parallel(left, first, depth + 1, nodes),
        // Reserved at a node an item, more than the tree usually takes
        // (about 0.3 for triangles: its leaves hold several), and only the
        // pages written take memory: grown by doubling from nothing, each
        // subtree left its freed copies behind.
        || build_parallel(right, first + mid, depth + 1, reserved(right.len())?),
    );
    let (mut nodes, right) = (nodes?, right?);
    let right_index = nodes.len();
    nodes.extend(right.iter().map(|n| {
        let mut n = *n;
        if !n.is_leaf() {
            n.offset += right_index as u32;
        }
        n
    }));
    nodes[node_index].offset = right_index as u32;
    nodes[node_index].count = 0;
    Ok(nodes)
}

/// Builds the subtree over `items` into `nodes`, returning its node index.
fn build(
    items: &mut [BuildItem],
    first: usize,
    depth: usize,
    nodes: &mut Vec<BinaryNode>,
) -> usize {
    let node_index = nodes.len();
    let (bounds, mid) = split(items, depth);
    nodes.push(BinaryNode::new(bounds, first, items.len()));
    let Some(mid) = mid else {
        return node_index;
    };
    let (left, right) = items.split_at_mut(mid);
    build(left, first, depth + 1, nodes);
    let right_index = build(right, first + mid, depth + 1, nodes);
    nodes[node_index].offset = right_index as u32;
    nodes[node_index].count = 0;
    node_index
}

/// The box around `items`, and where they split: `items[..mid]` and
/// `items[mid..]`, once reordered, are the node's two children; `None` for
/// a leaf.
fn split(items: &mut [BuildItem], depth: usize) -> (Aabb, Option<usize>) {
    let (bounds, centroid_bounds) = over_chunks(items, span, |a, b| {
        a.0.grow(&b.0);
        a.1.grow(&b.1);
    });
    if items.len() <= 1 {
        return (bounds, None);
    }

    let split = if depth < MAX_SAH_DEPTH {
        best_split(items, &bounds, &centroid_bounds)
    } else {
        None
    };
    let first_kind = items[0].kind;
    // (Asked only of a leaf: a pass over every item of every node cost 5%
    // of a large build.)
    let one_kind = |items: &[BuildItem]| items.iter().all(|it| it.kind == first_kind);
    let mid = match split {
        Some((axis, position)) => partition(items, |it| it.centroid[axis] < position),
        None if items.len() <= MAX_LEAF && one_kind(items) => return (bounds, None),
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
    (bounds, Some(mid))
}

/// Items of a node of at least this many are read on several threads (in
/// chunks of this many) to find its boxes and fill its bins.
const PARALLEL_PASS: usize = 1 << 15;

/// `pass` of `items`, on several threads for many items: `pass` of each
/// chunk, combined in order by `merge` (which must give `pass` of the two
/// chunks one after the other). Boxes merge exactly so, whatever the
/// chunks: a box grown by a box is the box grown by its items in turn.
fn over_chunks<T: Send>(
    items: &[BuildItem],
    pass: impl Fn(&[BuildItem]) -> T + Sync,
    merge: impl Fn(&mut T, T) + Sync,
) -> T {
    use rayon::prelude::*;
    if items.len() < 2 * PARALLEL_PASS {
        return pass(items);
    }
    items
        .par_chunks(PARALLEL_PASS)
        .map(&pass)
        .reduce_with(|mut a, b| {
            merge(&mut a, b);
            a
        })
        .expect("items")
}

/// The box around `items` and the box around their centroids.
fn span(items: &[BuildItem]) -> (Aabb, Aabb) {
    let mut bounds = Aabb::EMPTY;
    let mut centroids = Aabb::EMPTY;
    for it in items {
        bounds.grow(&it.bounds());
        centroids.grow_point(Vec3::from_array(it.centroid));
    }
    (bounds, centroids)
}

/// Per axis, each bin's box and number of items.
type Bins = [([Aabb; BINS], [usize; BINS]); 3];

/// Cost of a leaf of `n` primitives, tested a packet at a time.
fn leaf_cost(n: usize) -> f32 {
    INTERSECT_COST * n.div_ceil(MAX_LEAF) as f32
}

/// The SAH-best split `(axis, position)`, or `None` if a leaf is cheaper.
fn best_split(items: &[BuildItem], bounds: &Aabb, centroid_bounds: &Aabb) -> Option<(usize, f32)> {
    let parent_area = bounds.surface_area().max(f32::MIN_POSITIVE);
    // The axes along which the centroids spread: (axis, lowest, bins per
    // unit).
    let mut spread = [(0, 0.0, 0.0); 3];
    let mut n = 0;
    for axis in 0..3 {
        let lo = centroid_bounds.min[axis];
        let extent = centroid_bounds.max[axis] - lo;
        if extent > 0.0 {
            spread[n] = (axis, lo, BINS as f32 / extent);
            n += 1;
        }
    }
    let axes = &spread[..n];
    // Every axis's bins in one pass over the items (a pass an axis read
    // every item three times).
    let fill = |items: &[BuildItem]| {
        let mut bins: Bins = [([Aabb::EMPTY; BINS], [0usize; BINS]); 3];
        for it in items {
            let bounds = it.bounds();
            for &(axis, lo, scale) in axes {
                let b = (((it.centroid[axis] - lo) * scale) as usize).min(BINS - 1);
                let (bin_bounds, bin_counts) = &mut bins[axis];
                bin_counts[b] += 1;
                bin_bounds[b].grow(&bounds);
            }
        }
        bins
    };
    let bins = over_chunks(items, fill, |a: &mut Bins, b: Bins| {
        for (a, b) in a.iter_mut().zip(b) {
            for k in 0..BINS {
                a.0[k].grow(&b.0[k]);
                a.1[k] += b.1[k];
            }
        }
    });
    let mut best: Option<(f32, usize, f32)> = None;
    for &(axis, lo, scale) in axes {
        let (bin_bounds, bin_counts) = &bins[axis];
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
            // An item already in place is not swapped with itself; others
            // are swapped through registers (`slice::swap` went through a
            // copy on the stack whose store stalled: 10% of a large build).
            if i != mid {
                let (front, back) = items.split_at_mut(i);
                std::mem::swap(&mut front[mid], &mut back[0]);
            }
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Primitive, Quad, Sphere, Triangle};
    use crate::rng::Rng;

    /// A node's fields, its box by bits (−0 is not 0 here).
    fn bits(n: &BinaryNode) -> ([u32; 6], u32, u32) {
        let b = n.bounds();
        let corners = [b.min.to_array(), b.max.to_array()];
        let mut out = [0; 6];
        for (o, c) in out.iter_mut().zip(corners.iter().flatten()) {
            *o = c.to_bits();
        }
        (out, n.offset, n.count)
    }

    /// Primitives of every kind but instances: clustered and spread
    /// triangles (some of −0 coordinates, some coincident), spheres and
    /// quads, enough for the parallel build and passes.
    fn primitives(rng: &mut Rng, n: usize) -> Vec<Primitive> {
        let point = |rng: &mut Rng, scale: f32| {
            let mut c = [0.0; 3].map(|_| (rng.next_f32() - 0.5) * scale);
            if rng.next_u32().is_multiple_of(16) {
                c[0] = -0.0;
            }
            Vec3::from_array(c)
        };
        (0..n)
            .map(|i| match i % 7 {
                0 => Primitive::Sphere(Sphere::new(point(rng, 100.0), 0.1 + rng.next_f32())),
                1 => {
                    let q = point(rng, 100.0);
                    Primitive::Quad(Quad::new(q, Vec3::X, Vec3::Z).unwrap())
                }
                // Coincident triangles: centroids that tie.
                2 => Primitive::Triangle(Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)),
                _ => {
                    let a = point(rng, if i % 2 == 0 { 100.0 } else { 1.0 });
                    let (b, c) = (a + point(rng, 1.0), a + point(rng, 1.0));
                    Primitive::Triangle(Triangle::new(a, b, c))
                }
            })
            .collect()
    }

    #[test]
    fn the_parallel_build_makes_the_tree_of_the_sequential_one() {
        let mut rng = Rng::new(7);
        for n in [1, 2, 9, 1000, 3 * PARALLEL_ITEMS + 17, 3 * PARALLEL_PASS] {
            let prims = primitives(&mut rng, n);
            let tree = build_binary(prims.as_slice()).unwrap();
            // The same items, one thread, one node after another.
            let mut items: Vec<BuildItem> = prims
                .iter()
                .enumerate()
                .map(|(i, p)| BuildItem {
                    min: p.bounds().min.to_array(),
                    max: p.bounds().max.to_array(),
                    centroid: p.centroid().to_array(),
                    index: i as u32,
                    kind: p.kind(),
                })
                .collect();
            let mut nodes = Vec::new();
            build(&mut items, 0, 0, &mut nodes);
            let order: Vec<u32> = items.iter().map(|it| it.index).collect();
            assert_eq!(tree.order, order, "{n} primitives");
            assert_eq!(
                tree.nodes.iter().map(bits).collect::<Vec<_>>(),
                nodes.iter().map(bits).collect::<Vec<_>>(),
                "{n} primitives"
            );
            // Every primitive in one leaf of one kind, counted by kind.
            let mut seen = vec![false; n];
            let mut leaves = [0; KINDS];
            for leaf in tree.nodes.iter().filter(|l| l.is_leaf()) {
                let members = &tree.order[leaf.offset as usize..][..leaf.count as usize];
                assert!(members.len() <= MAX_LEAF);
                let kind = prims[members[0] as usize].kind();
                assert!(members.iter().all(|&m| prims[m as usize].kind() == kind));
                members.iter().for_each(|&m| seen[m as usize] = true);
                leaves[kind as usize] += 1;
            }
            assert!(seen.iter().all(|&s| s));
            assert_eq!(tree.leaves, leaves);
        }
    }
}
