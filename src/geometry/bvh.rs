//! A wide bounding volume hierarchy over primitives of every kind,
//! traversed by one function for every query.
//!
//! The binary SAH tree of [`super::bvh_build`] is collapsed into nodes of
//! four children for trees of spheres only, which bundles of rays walk
//! together, and of eight for the rest (meshes), which single rays walk: a
//! mesh's tree is larger than the caches, and half as many levels are half
//! as many waits for memory. A node stores its children's boxes as structure
//! of arrays (the lower x planes of all children in one vector, and so on),
//! so one ray is tested against all of them with a handful of vector
//! operations: four lanes of SSE2 or NEON, or eight of AVX2 where the
//! processor has it. Leaves are packets of up to eight primitives of one
//! kind (the leaf's tag), stored as structure of arrays and tested together
//! by that kind's kernel on eight lanes (see [`crate::lanes`]).
//!
//! `Bvh::traverse` walks the tree for any `Rays`: one ray looking for
//! its nearest hit ([`Bvh::hit`]) or for any hit ([`Bvh::occluded`]), or a
//! bundle of rays ([`Bvh::hit_bundle`]). It visits the hit children nearest
//! first and skips any entry of its stack whose box starts beyond the
//! closest hit found so far. Which children are visited, and in which order,
//! changes no result: hits are kept in the order (distance, index) and boxes
//! with a margin (`SLACK`), so both widths and every instruction set find the
//! same hits to the bit.

use crate::geometry::bvh_build::{build_binary, Aabb, BinaryNode, BinaryTree, BuildItem, MAX_LEAF};
use crate::geometry::instance::Instance;
use crate::geometry::primitive::{Kind, Primitive, PrimitiveSet, KINDS};
use crate::geometry::quad::{self, QuadLanes};
use crate::geometry::quadric::Quadric;
use crate::geometry::sphere::{self, SphereLanes};
use crate::geometry::triangle::{self, TriangleLanes, TriangleRay};
use crate::lanes::{map3, max4, min4, Mask, Real, Wide, F8};
use crate::math::Interval;
use crate::memory::MemoryError;
use crate::ray::{Ray, RayLanes};
use glam::Vec4;
use std::mem::MaybeUninit;
use std::ops::{Index, IndexMut};

/// Children of a node referring to a leaf have this bit set.
pub(super) const LEAF_BIT: u32 = 1 << 31;
/// A leaf reference holds its kind in these bits…
const KIND_SHIFT: u32 = 28;
/// …and the index of its packet (of that kind) in these.
const INDEX_MASK: u32 = (1 << KIND_SHIFT) - 1;
/// An unused child slot (its box is empty, so it is never entered), and an
/// unused lane of a packet.
pub(super) const NO_CHILD: u32 = u32::MAX;
/// Entries of the traversal stack: a node pushes at most seven children
/// (three in a tree of four-wide nodes), a wide node lies at least one level
/// of the binary tree below its parent, and the binary tree is at most
/// `MAX_SAH_DEPTH + 32` = 80 levels deep (see `bvh_build`).
pub(super) const STACK_SIZE: usize = 7 * 80;

/// The boxes of a node's `W` children, structure of arrays (the lower x
/// planes of all children in one `P`, and so on), and their references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct WideNode<P, const W: usize> {
    /// `planes[axis][0]`: the lower bounds along `axis`; `[1]`: the upper.
    pub(super) planes: [[P; 2]; 3],
    /// Node index, `LEAF_BIT | kind | packet index`, or `NO_CHILD`.
    pub(super) children: [u32; W],
    /// Bit `lane` is set when `children[lane]` is used.
    pub(super) used: u32,
}

/// Four children: the node of trees of spheres only, which bundles of rays
/// walk together.
pub(super) type Node = WideNode<Vec4, 4>;

/// Eight children: the node of trees that hold other shapes than spheres
/// (see [`Bvh::over`]). One ray meets a mesh's tree half as many levels
/// deep as with four children, and the tree is larger than the caches: each
/// level is a wait for memory.
pub(super) type Node8 = WideNode<Lane8, 8>;

/// A tree's nodes, node 0 the root (none when there are no primitives).
#[derive(Clone, Debug)]
pub(super) enum Nodes {
    /// A tree of spheres only, which bundles of rays walk together.
    Four(Vec<Node>),
    /// A tree that holds other shapes (meshes), which single rays walk.
    Eight(Vec<Node8>),
}

/// The lanes of a node's planes.
pub(super) trait Planes: IndexMut<usize, Output = f32> + Copy {
    /// +∞ in every lane: the lower plane of no box.
    const NONE_LOW: Self;
    /// −∞ in every lane: the upper plane of no box.
    const NONE_HIGH: Self;
}

impl Planes for Vec4 {
    const NONE_LOW: Vec4 = Vec4::INFINITY;
    const NONE_HIGH: Vec4 = Vec4::NEG_INFINITY;
}

impl Planes for Lane8 {
    const NONE_LOW: Lane8 = [f32::INFINITY; 8];
    const NONE_HIGH: Lane8 = [f32::NEG_INFINITY; 8];
}

/// What the traversal and the collapse ask of a node, of four children or
/// eight.
pub(super) trait TreeNode: Copy {
    /// Children a node has room for.
    const WIDTH: usize;
    /// A list of up to `WIDTH` child lanes.
    type Lanes: Copy + Default + AsRef<[usize]> + AsMut<[usize]>;
    /// A node without children.
    const EMPTY: Self;
    /// The reference in child slot `lane`.
    fn child(&self, lane: usize) -> u32;
    /// Puts `child`, of box `bounds`, in slot `lane`.
    fn set_child(&mut self, lane: usize, bounds: &Aabb, child: u32);
}

impl<P: Planes, const W: usize> TreeNode for WideNode<P, W>
where
    [usize; W]: Default,
{
    const WIDTH: usize = W;
    type Lanes = [usize; W];
    const EMPTY: Self = WideNode {
        planes: [[P::NONE_LOW, P::NONE_HIGH]; 3],
        children: [NO_CHILD; W],
        used: 0,
    };

    #[inline(always)]
    fn child(&self, lane: usize) -> u32 {
        self.children[lane]
    }

    fn set_child(&mut self, lane: usize, bounds: &Aabb, child: u32) {
        for axis in 0..3 {
            self.planes[axis][0][lane] = bounds.min[axis];
            self.planes[axis][1][lane] = bounds.max[axis];
        }
        self.children[lane] = child;
        self.used |= 1 << lane;
    }
}

/// Eight lanes of one field of a packet, as stored.
pub(super) type Lane8 = [f32; 8];

/// Up to eight spheres, structure of arrays. Unused lanes have a radius² of
/// −∞, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct SpherePacket {
    pub(super) center: [Lane8; 3],
    pub(super) radius2: Lane8,
    /// Index of each primitive in the input; `NO_CHILD` in unused lanes
    /// (which come after the used ones).
    pub(super) index: [u32; 8],
}

/// Up to eight triangles, structure of arrays (vertex, axis). Unused lanes
/// are NaN, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct TrianglePacket {
    pub(super) vertices: [[Lane8; 3]; 3],
    pub(super) index: [u32; 8],
}

/// Up to eight quads, structure of arrays (see [`QuadLanes`]). Unused lanes
/// are NaN, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct QuadPacket {
    pub(super) corner: [Lane8; 3],
    pub(super) u: [Lane8; 3],
    pub(super) v: [Lane8; 3],
    pub(super) normal: [Lane8; 3],
    pub(super) w: [Lane8; 3],
    pub(super) d: Lane8,
    pub(super) index: [u32; 8],
}

/// Lane `s` of each of three fields, each in every lane of `R`. (Indexed in
/// place: mapping a copy of the arrays made the compiler store each one to
/// the stack before reading its lane back.)
#[inline(always)]
fn splat_lane<R: Real>(fields: &[Lane8; 3], s: usize) -> [R; 3] {
    [
        R::splat(fields[0][s]),
        R::splat(fields[1][s]),
        R::splat(fields[2][s]),
    ]
}

/// Up to eight instances.
#[derive(Clone, Copy, Debug)]
pub(super) struct InstancePacket {
    /// Each lane's instance, in [`Bvh::instances`].
    pub(super) instance: [u32; 8],
    pub(super) index: [u32; 8],
}

/// Up to eight disks and cylinders (lanes past the last hold none),
/// tested one at a time.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadricPacket {
    pub(super) shapes: [Option<Quadric>; 8],
    pub(super) index: [u32; 8],
}

impl QuadricPacket {
    /// The distance and index of each of the packet's shapes that `ray`
    /// hits beyond `t_min`.
    #[inline]
    pub(super) fn hits<'a>(
        &'a self,
        ray: &'a Ray,
        t_min: f32,
    ) -> impl Iterator<Item = (f32, u32)> + 'a {
        self.shapes
            .iter()
            .map_while(Option::as_ref)
            .zip(self.index)
            .filter_map(move |(shape, index)| Some((shape.hit(ray, t_min)?, index)))
    }
}

impl SpherePacket {
    /// The packet's spheres, one per lane.
    #[inline(always)]
    pub(super) fn lanes<R: Wide>(&self) -> SphereLanes<R> {
        SphereLanes {
            center: map3(&self.center, R::from_array),
            radius2: R::from_array(self.radius2),
        }
    }

    /// Sphere `s` of the packet in every lane.
    #[inline(always)]
    pub(super) fn splat<R: Real>(&self, s: usize) -> SphereLanes<R> {
        SphereLanes {
            center: splat_lane(&self.center, s),
            radius2: R::splat(self.radius2[s]),
        }
    }
}

impl TrianglePacket {
    /// The packet's triangles, one per lane, in the axes `axes`.
    #[inline(always)]
    pub(super) fn lanes<R: Wide>(&self, axes: [usize; 3]) -> TriangleLanes<R> {
        TriangleLanes {
            vertices: map3(&self.vertices, |v| map3(&axes, |k| R::from_array(v[k]))),
        }
    }
}

impl QuadPacket {
    /// The packet's quads, one per lane.
    #[inline(always)]
    pub(super) fn lanes<R: Wide>(&self) -> QuadLanes<R> {
        QuadLanes {
            corner: map3(&self.corner, R::from_array),
            u: map3(&self.u, R::from_array),
            v: map3(&self.v, R::from_array),
            normal: map3(&self.normal, R::from_array),
            w: map3(&self.w, R::from_array),
            d: R::from_array(self.d),
        }
    }

    /// Quad `s` of the packet in every lane.
    #[inline(always)]
    pub(super) fn splat<R: Real>(&self, s: usize) -> QuadLanes<R> {
        QuadLanes {
            corner: splat_lane(&self.corner, s),
            u: splat_lane(&self.u, s),
            v: splat_lane(&self.v, s),
            normal: splat_lane(&self.normal, s),
            w: splat_lane(&self.w, s),
            d: R::splat(self.d[s]),
        }
    }
}

/// The nearest primitive a ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the primitive in the order the BVH was built from.
    pub index: u32,
    /// For a hit inside an instance, the primitive's index in the
    /// instance's tree; 0 otherwise.
    pub sub: u32,
}

/// A wide SAH bounding volume hierarchy over a set of primitives.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Nodes,
    spheres: Vec<SpherePacket>,
    triangles: Vec<TrianglePacket>,
    quads: Vec<QuadPacket>,
    quadrics: Vec<QuadricPacket>,
    instance_packets: Vec<InstancePacket>,
    /// The instances that `Primitive::Instance` items name.
    instances: Vec<Instance>,
    /// The box around everything.
    bounds: Aabb,
    /// Whether the processor has AVX2, asked once when the tree is built:
    /// asking for every ray cost ≈ 20 instructions per ray.
    avx2: bool,
}

impl Bvh {
    /// Builds the hierarchy over `primitives`, which hold no instances.
    pub fn new(primitives: &[Primitive]) -> Self {
        Self::with_instances(primitives, Vec::new())
    }

    /// Builds the hierarchy over `primitives`, whose `Primitive::Instance`
    /// items name entries of `instances` (a two-level tree: the instances'
    /// own trees hold no instances).
    ///
    /// # Panics
    /// When an instance's tree itself holds instances, or an item names an
    /// instance that `instances` does not have.
    pub fn with_instances(primitives: &[Primitive], instances: Vec<Instance>) -> Self {
        Self::over(primitives, instances)
    }

    /// [`Bvh::over`], with the memory the build takes counted first (see
    /// [`crate::memory`]): a tree that cannot fit in what this machine has
    /// free is refused before it is started, rather than ending the process
    /// half-way.
    ///
    /// # Panics
    /// As [`Bvh::with_instances`].
    pub fn try_over<P: PrimitiveSet + ?Sized>(
        primitives: &P,
        instances: Vec<Instance>,
    ) -> Result<Self, MemoryError> {
        let n = primitives.count();
        // Below this, asking the system what it has free costs more than
        // the tree.
        let what = || format!("building the tree of {n} shapes");
        if n >= 1 << 16 {
            crate::memory::check(Self::build_bytes(n), &what())?;
        }
        // The count is the least the build takes; the system may still
        // refuse what the build reserves beyond it (under `ulimit -v`,
        // reservations count in full).
        Self::build(primitives, instances).map_err(|_| MemoryError {
            what: what(),
            bytes: Self::build_bytes(n),
            available: None,
        })
    }

    /// The least memory building a tree over `items` items takes at its
    /// peak, beside the items themselves: the binary build's record of
    /// each item and its nodes, both as many as the items.
    pub fn build_bytes(items: usize) -> u64 {
        (items as u64).saturating_mul((size_of::<BuildItem>() + size_of::<BinaryNode>()) as u64)
    }

    /// [`Bvh::with_instances`] over items made when the build asks for them
    /// (see [`PrimitiveSet`]).
    ///
    /// # Panics
    /// As [`Bvh::with_instances`], and when the system refuses the memory
    /// of the build.
    pub fn over<P: PrimitiveSet + ?Sized>(primitives: &P, instances: Vec<Instance>) -> Self {
        Self::build(primitives, instances)
            .unwrap_or_else(|e| panic!("building a tree of {} shapes: {e}", primitives.count()))
    }

    /// [`Bvh::over`], or the system's refusal of the build's memory.
    fn build<P: PrimitiveSet + ?Sized>(
        primitives: &P,
        instances: Vec<Instance>,
    ) -> Result<Self, std::collections::TryReserveError> {
        assert!(
            instances.iter().all(|i| i.bvh.instances.is_empty()),
            "instances hold no instances"
        );
        let BinaryTree {
            nodes: binary,
            order,
            leaves,
        } = build_binary(primitives)?;
        let mut bvh = Bvh {
            nodes: Nodes::Four(Vec::new()),
            spheres: Vec::new(),
            triangles: Vec::new(),
            quads: Vec::new(),
            quadrics: Vec::new(),
            instance_packets: Vec::new(),
            instances,
            bounds: binary.first().map_or(Aabb::EMPTY, BinaryNode::bounds),
            avx2: crate::isa::Isa::detect() == crate::isa::Isa::Avx2,
        };
        if binary.is_empty() {
            return Ok(bvh);
        }
        let collapse = Collapse {
            binary: &binary,
            order: &order,
            primitives,
        };
        // Bundles of any rays, which pay only on spheres, walk four-wide
        // nodes; single rays and a pixel's camera rays through anything
        // else, eight-wide ones.
        let spheres_only = leaves
            .iter()
            .enumerate()
            .all(|(kind, &n)| n == 0 || kind == Kind::Sphere as usize);
        let width = if spheres_only { 4 } else { 8 };
        let roots = if binary[0].is_leaf() {
            Opened([0; 8], 1)
        } else {
            collapse.open(0, width)
        };
        // The nodes in one pass, which numbers the packets; the packets
        // then on every core (making them reads the primitives: most of
        // the time of a large mesh's collapse).
        let mut packet_leaves = leaves.map(Vec::with_capacity);
        bvh.nodes = if spheres_only {
            Nodes::Four(collapse.emit_tree(&roots, &mut packet_leaves))
        } else {
            Nodes::Eight(collapse.emit_tree(&roots, &mut packet_leaves))
        };
        collapse.fill_packets(&packet_leaves, &mut bvh);
        bvh.spheres.shrink_to_fit();
        bvh.triangles.shrink_to_fit();
        bvh.quads.shrink_to_fit();
        bvh.quadrics.shrink_to_fit();
        bvh.instance_packets.shrink_to_fit();
        Ok(bvh)
    }

    /// The box around everything in the tree.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The instances the tree places.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Number of nodes (for statistics and memory estimates).
    pub fn node_count(&self) -> usize {
        match &self.nodes {
            Nodes::Four(nodes) => nodes.len(),
            Nodes::Eight(nodes) => nodes.len(),
        }
    }

    /// Bytes of memory held by the hierarchy.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let nodes = match &self.nodes {
            Nodes::Four(nodes) => nodes.capacity() * size_of::<Node>(),
            Nodes::Eight(nodes) => nodes.capacity() * size_of::<Node8>(),
        };
        nodes
            + self.spheres.capacity() * size_of::<SpherePacket>()
            + self.triangles.capacity() * size_of::<TrianglePacket>()
            + self.quads.capacity() * size_of::<QuadPacket>()
            + self.quadrics.capacity() * size_of::<QuadricPacket>()
            + self.instance_packets.capacity() * size_of::<InstancePacket>()
            + self.instances.capacity() * size_of::<Instance>()
    }

    /// The nearest primitive hit by `ray` within `interval`; the ray's
    /// direction must have unit length (see [`sphere::intersect`]).
    #[inline(always)]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        let (t, index, sub) = if self.spheres_only() {
            self.single::<Nearest, true>(ray, interval)
        } else {
            self.single::<Nearest, false>(ray, interval)
        };
        (t < interval.max).then_some(Hit { t, index, sub })
    }

    /// Whether `ray` hits anything within `interval` (the first hit found,
    /// not the nearest: a shadow ray's question).
    #[inline(always)]
    pub fn occluded(&self, ray: &Ray, interval: Interval) -> bool {
        self.any_hit(ray, interval).is_some()
    }

    /// The first hit of `ray` within `interval` that the traversal finds,
    /// not necessarily the nearest.
    #[inline(always)]
    pub fn any_hit(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        let (t, index, sub) = if self.spheres_only() {
            self.single::<AnyHit, true>(ray, interval)
        } else {
            self.single::<AnyHit, false>(ray, interval)
        };
        (t < interval.max).then_some(Hit { t, index, sub })
    }

    /// Traverses for one ray asking `Q`; `SPHERES` when the tree holds
    /// spheres only, whose traversal loop then carries no other kind's test
    /// (they would take registers from it). Returns the best (distance,
    /// index, index inside an instance), the distance `interval.max` when
    /// nothing counts.
    #[inline(always)]
    fn single<Q: Query, const SPHERES: bool>(
        &self,
        ray: &Ray,
        interval: Interval,
    ) -> (f32, u32, u32) {
        let mut query = SingleRay::<Q, SPHERES>::new(self, ray, interval);
        match &self.nodes {
            // Known at compile time not to be taken on spheres only.
            Nodes::Eight(nodes) if !SPHERES => self.traverse(nodes, &mut query),
            Nodes::Four(nodes) => self.traverse(nodes, &mut query),
            // A tree of spheres only is four-wide.
            Nodes::Eight(_) => {}
        }
        (query.closest, query.best, query.sub)
    }

    /// Whether every leaf holds spheres (including a tree of nothing).
    /// Bundles of any rays ([`Bvh::hit_bundle`]) pay off only on such
    /// trees: a leaf's eight primitives are cheap to test for eight rays at
    /// once. On a mesh, where the rays of a bundle soon reach different
    /// leaves and a triangle costs more, only a pixel's camera rays, which
    /// stay together, are faster as a bundle than alone.
    #[inline(always)]
    pub fn spheres_only(&self) -> bool {
        // Such a tree, and only such a tree, is four-wide (see `Bvh::over`).
        matches!(self.nodes, Nodes::Four(_))
    }

    /// The tree's nodes.
    #[inline(always)]
    pub(super) fn nodes(&self) -> &Nodes {
        &self.nodes
    }

    /// Sphere packet `i`, reached through a leaf reference of a used child
    /// slot.
    #[inline(always)]
    pub(super) fn sphere_packet(&self, i: u32) -> &SpherePacket {
        debug_assert!((i as usize) < self.spheres.len());
        // SAFETY: as for `node`: `Collapse::emit_leaf` returns the index of
        // the packet it has just pushed.
        #[allow(unsafe_code)]
        unsafe {
            self.spheres.get_unchecked(i as usize)
        }
    }

    /// How many triangle packets the tree has.
    #[cfg(test)]
    pub(super) fn triangle_packets(&self) -> usize {
        self.triangles.len()
    }

    /// Triangle packet `i` (bounds-checked: triangle tests dominate the
    /// check's cost).
    #[inline(always)]
    pub(super) fn triangle_packet(&self, i: u32) -> &TrianglePacket {
        &self.triangles[i as usize]
    }

    /// Quad packet `i`.
    #[inline(always)]
    pub(super) fn quad_packet(&self, i: u32) -> &QuadPacket {
        &self.quads[i as usize]
    }

    /// Instance packet `i`.
    #[inline(always)]
    pub(super) fn instance_packet(&self, i: u32) -> &InstancePacket {
        &self.instance_packets[i as usize]
    }

    /// Disk and cylinder packet `i`.
    #[inline(always)]
    pub(super) fn quadric_packet(&self, i: u32) -> &QuadricPacket {
        &self.quadrics[i as usize]
    }

    /// Whether leaves are tested with AVX2 (see [`crate::isa`]).
    #[inline(always)]
    pub(super) fn avx2(&self) -> bool {
        self.avx2
    }

    /// Whether the tree holds triangles (whose rays need preparing).
    #[inline(always)]
    pub(super) fn has_triangles(&self) -> bool {
        !self.triangles.is_empty()
    }

    /// Walks the tree for `rays`, nearest children first: the one traversal
    /// of every query, on four-wide nodes or eight-wide. `rays` tests the
    /// boxes, tells which stacked boxes are still worth entering, and tests
    /// the leaves.
    #[inline(always)]
    pub(super) fn traverse<N: TreeNode, R: Enter<N>>(&self, nodes: &[N], rays: &mut R) {
        if nodes.is_empty() {
            return;
        }
        // Uninitialised: zeroing the stack on every call cost ~10% of the render.
        let mut stack = [MaybeUninit::<(u32, R::Entry)>::uninit(); STACK_SIZE];
        let mut top = 0usize;
        let mut current = 0u32;
        let mut entry = R::Entry::default();
        loop {
            if current & LEAF_BIT != 0 {
                if rays.leaf(self, current, &entry) {
                    return;
                }
            } else {
                debug_assert!((current as usize) < nodes.len());
                // SAFETY: the traversal starts at node 0 of a non-empty tree
                // and only follows references of used child slots, each of
                // which `Collapse` wrote after pushing the node it names, so
                // every index is in bounds. (Unchecked: the bounds checks
                // were 3% of the render's instructions.)
                #[allow(unsafe_code)]
                let node = unsafe { nodes.get_unchecked(current as usize) };
                let (mask, entries) = rays.enter(node);
                if mask != 0 {
                    let first = mask.trailing_zeros() as usize & (N::WIDTH - 1);
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        // One child hit (the most common case): go on with it.
                        current = node.child(first);
                        entry = entries[first];
                        continue;
                    }
                    if rest & (rest - 1) == 0 {
                        // Two children (most of the rest): push the farther,
                        // go on with the nearer (the first lane on a tie).
                        let second = rest.trailing_zeros() as usize & (N::WIDTH - 1);
                        let order = rays.order(node, &entries);
                        let (near, far) = if order[second] < order[first] {
                            (second, first)
                        } else {
                            (first, second)
                        };
                        stack[top].write((node.child(far), entries[far]));
                        top += 1;
                        current = node.child(near);
                        entry = entries[near];
                        continue;
                    }
                    // More: push the hit children farthest first; go on
                    // with the nearest.
                    let (lanes, n) = farthest_first::<N, _>(mask, &rays.order(node, &entries));
                    let lanes = lanes.as_ref();
                    for &lane in &lanes[..n - 1] {
                        stack[top].write((node.child(lane), entries[lane]));
                        top += 1;
                    }
                    current = node.child(lanes[n - 1]);
                    entry = entries[lanes[n - 1]];
                    continue;
                }
            }
            // Pop the next entry that may still hold a hit that matters.
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                // SAFETY: entries below `top` were all written by the pushes above.
                #[allow(unsafe_code)]
                let (child, e) = unsafe { stack[top].assume_init() };
                if rays.needed(&e) {
                    current = child;
                    entry = e;
                    break;
                }
            }
        }
    }
}

/// What [`Bvh::traverse`] asks of the rays it walks the tree for, whatever
/// the width of the nodes.
pub(super) trait Rays {
    /// Where the rays enter a box: one distance, or one per ray.
    type Entry: Copy + Default;
    /// Whether a box the rays enter at `entry` may still hold a hit that matters.
    fn needed(&self, entry: &Self::Entry) -> bool;
    /// Tests the primitives of `leaf` (a leaf reference), which the rays
    /// enter at `entry`; `true` ends the traversal.
    fn leaf(&mut self, bvh: &Bvh, leaf: u32, entry: &Self::Entry) -> bool;
}

/// The box tests of [`Rays`] on nodes of type `N`.
pub(super) trait Enter<N: TreeNode>: Rays {
    /// Where the rays enter each child of a node.
    type Entries: Index<usize, Output = Self::Entry>;
    /// A distance per child, to order them by.
    type Order: Index<usize, Output = f32>;
    /// Tests the boxes of `node`: the children to visit (bit per child)
    /// and where the rays enter each.
    fn enter(&self, node: &N) -> (u32, Self::Entries);
    /// The order to visit the children of `node` in, nearest first (only
    /// speed depends on it), given where the rays enter them: asked only
    /// when two or more are hit.
    fn order(&self, node: &N, entries: &Self::Entries) -> Self::Order;
}

/// The kind and packet index of a leaf reference.
#[inline(always)]
pub(super) fn leaf_parts(leaf: u32) -> (Kind, u32) {
    (
        Kind::from_index((leaf & !LEAF_BIT) >> KIND_SHIFT),
        leaf & INDEX_MASK,
    )
}

/// What a single ray looks for.
pub(super) trait Query {
    /// Any hit ends the search (a shadow ray); otherwise the nearest is wanted.
    const ANY: bool;
}

/// The nearest hit.
pub(super) struct Nearest;
impl Query for Nearest {
    const ANY: bool = false;
}

/// Any hit.
pub(super) struct AnyHit;
impl Query for AnyHit {
    const ANY: bool = true;
}

/// One ray, with what the box and leaf tests need of it.
struct SingleRay<Q, const SPHERES: bool> {
    ray: Ray,
    near: [usize; 3],
    inv: [Vec4; 3],
    origin: [Vec4; 3],
    t_min: f32,
    /// The ray prepared for triangles, in its axes: only when the tree
    /// holds triangles.
    triangle: TriangleRay<f32>,
    axes: [usize; 3],
    /// The best hit so far, compared as the pair (distance, index) so that,
    /// with boxes kept within `SLACK`, the result does not depend on the
    /// order of the visit. No primitive ties the start (interval.max, 0):
    /// index 0 is the lowest.
    closest: f32,
    best: u32,
    /// The primitive inside the instance `best`, if it is one.
    sub: u32,
    /// Whether boxes are tested with AVX2 (see [`Bvh::avx2`]).
    avx2: bool,
    query: std::marker::PhantomData<Q>,
}

impl<Q: Query, const SPHERES: bool> SingleRay<Q, SPHERES> {
    #[inline(always)]
    fn new(bvh: &Bvh, ray: &Ray, interval: Interval) -> Self {
        debug_assert!(
            (ray.direction.length_squared() - 1.0).abs() < 1e-4,
            "ray direction {} is not unit length",
            ray.direction
        );
        let (o, inv) = (ray.origin(), ray.direction.recip());
        let (axes, triangle) = if !SPHERES && bvh.has_triangles() {
            let axes = TriangleRay::axes_of(ray.direction);
            (axes, TriangleRay::new(ray, axes, interval.min))
        } else {
            let none = TriangleRay {
                origin: [0.0; 3],
                shear: [0.0; 3],
                t_min: 0.0,
                origin2: 0.0,
            };
            ([0, 1, 2], none)
        };
        SingleRay {
            ray: *ray,
            // Per axis: which of the two planes the ray meets first.
            near: [
                usize::from(inv.x < 0.0),
                usize::from(inv.y < 0.0),
                usize::from(inv.z < 0.0),
            ],
            inv: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            origin: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            t_min: interval.min,
            triangle,
            axes,
            closest: interval.max,
            best: 0,
            sub: 0,
            avx2: bvh.avx2,
            query: std::marker::PhantomData,
        }
    }

    /// Takes in a packet's distances `t` (valid where `valid`) for the
    /// primitives `index`; `true` when the search is over.
    #[inline(always)]
    fn found<R: Wide>(&mut self, t: R, valid: R::Mask, index: &[u32; 8]) -> bool {
        let closest = R::splat(self.closest);
        if Q::ANY {
            let hit = valid & t.lt(closest);
            if hit.any() {
                // Which primitive, with its distance: a ray leaving a
                // surface asks whether it only found that surface again.
                let nearest = R::select(hit, t, closest);
                self.closest = nearest.min_lane();
                let at = R::bits(hit & nearest.eq(R::splat(self.closest)));
                self.best = index[at.trailing_zeros() as usize];
                self.sub = 0;
                return true;
            }
            return false;
        }
        let hit = valid & t.le(closest);
        if !hit.any() {
            return false;
        }
        let t = R::select(hit, t, R::splat(f32::INFINITY));
        let t_best = t.min_lane();
        let equal = R::bits(t.eq(R::splat(t_best)));
        if let Some((t, index)) = finish(t_best, equal, index, self.closest, self.best) {
            // A packet's primitive has no sub-item: what a farther
            // instance left there goes.
            (self.closest, self.best, self.sub) = (t, index, 0);
        }
        false
    }

    #[inline(always)]
    fn spheres<R: Wide>(&mut self, p: &SpherePacket) -> bool {
        let ray = RayLanes::splat(&self.ray, self.t_min);
        let (t, valid) = sphere::intersect(&ray, &p.lanes());
        self.found::<R>(t, valid, &p.index)
    }

    #[inline(always)]
    fn triangles<R: Wide>(&mut self, p: &TrianglePacket) -> bool {
        let ray = splat_triangle_ray::<R>(&self.triangle);
        let (t, valid) = triangle::intersect(&ray, &p.lanes(self.axes));
        self.found(t, valid, &p.index)
    }

    #[inline(always)]
    fn quads<R: Wide>(&mut self, p: &QuadPacket) -> bool {
        let ray = RayLanes::splat(&self.ray, self.t_min);
        let (t, valid) = quad::intersect(&ray, &p.lanes());
        self.found::<R>(t, valid, &p.index)
    }

    /// Tests the disks and cylinders of the packet one at a time, keeping
    /// the first hit in the order (distance, index) as for any primitive.
    #[inline(never)]
    fn quadrics(&mut self, p: &QuadricPacket) -> bool {
        for (t, index) in p.hits(&self.ray, self.t_min) {
            if Q::ANY {
                if t < self.closest {
                    (self.closest, self.best) = (t, index);
                    return true;
                }
            } else if comes_before((t, index), (self.closest, self.best)) {
                (self.closest, self.best, self.sub) = (t, index, 0);
            }
        }
        false
    }

    /// Traces the ray through each instance of the packet, keeping the
    /// first hit in the order (distance, index) as for any primitive.
    #[inline(never)]
    fn instances(&mut self, bvh: &Bvh, p: &InstancePacket) -> bool {
        for lane in 0..8 {
            let index = p.index[lane];
            if index == NO_CHILD {
                break;
            }
            let instance = &bvh.instances[p.instance[lane] as usize];
            if Q::ANY {
                let within = Interval::new(self.t_min, self.closest);
                if let Some((t, sub)) = instance.any_hit(&self.ray, within) {
                    // Any distance below the interval's end says "hit"; the
                    // world distance may round to the end.
                    self.closest = if t < self.closest { t } else { self.t_min };
                    (self.best, self.sub) = (index, sub);
                    return true;
                }
                continue;
            }
            if let Some((t, sub)) = instance.hit(&self.ray, self.t_min, self.closest) {
                if comes_before((t, index), (self.closest, self.best)) {
                    (self.closest, self.best, self.sub) = (t, index, sub);
                }
            }
        }
        false
    }
}

/// The packet tests of [`SingleRay`] on AVX lanes, each compiled for AVX2
/// and small enough to be inlined into the AVX2 render loop.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod single_avx2 {
    use super::{Node8, QuadPacket, Query, SingleRay, SpherePacket, TrianglePacket};
    use crate::lanes::W8;

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn boxes8<Q: Query, const S: bool>(
        r: &SingleRay<Q, S>,
        node: &Node8,
    ) -> (u32, [f32; 8]) {
        r.boxes8::<W8>(node)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn spheres<Q: Query, const S: bool>(
        r: &mut SingleRay<Q, S>,
        p: &SpherePacket,
    ) -> bool {
        r.spheres::<W8>(p)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn triangles<Q: Query, const S: bool>(
        r: &mut SingleRay<Q, S>,
        p: &TrianglePacket,
    ) -> bool {
        r.triangles::<W8>(p)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn quads<Q: Query, const S: bool>(
        r: &mut SingleRay<Q, S>,
        p: &QuadPacket,
    ) -> bool {
        r.quads::<W8>(p)
    }
}

/// A prepared triangle ray repeated in every lane.
#[inline(always)]
fn splat_triangle_ray<R: Real>(r: &TriangleRay<f32>) -> TriangleRay<R> {
    TriangleRay {
        origin: map3(&r.origin, R::splat),
        shear: map3(&r.shear, R::splat),
        t_min: R::splat(r.t_min),
        origin2: R::splat(r.origin2),
    }
}

impl<Q: Query, const SPHERES: bool> SingleRay<Q, SPHERES> {
    /// The slab test of four boxes, given as their planes: which the ray
    /// enters before its best hit so far (bit per box, of those in `used`),
    /// and where.
    #[inline(always)]
    fn boxes(&self, p: &[[Vec4; 2]; 3], used: u32) -> (u32, Vec4) {
        let (near, o, inv) = (&self.near, &self.origin, &self.inv);
        let tx0 = (p[0][near[0]] - o[0]) * inv[0];
        let tx1 = (p[0][1 - near[0]] - o[0]) * inv[0];
        let ty0 = (p[1][near[1]] - o[1]) * inv[1];
        let ty1 = (p[1][1 - near[1]] - o[1]) * inv[1];
        let tz0 = (p[2][near[2]] - o[2]) * inv[2];
        let tz1 = (p[2][1 - near[2]] - o[2]) * inv[2];
        // The bound given last wins when a lane is NaN (0·∞ for a ray
        // lying in a box's plane), so a NaN never culls a box it may hit.
        let t_near = max4(max4(max4(tx0, ty0), tz0), Vec4::splat(self.t_min));
        let t_far = min4(min4(min4(tx1, ty1), tz1), Vec4::splat(self.closest)) * SLACK4;
        (t_near.cmple(t_far).bitmask() & used, t_near)
    }

    /// The slab test of a node's eight boxes on lanes `R`, as
    /// [`SingleRay::boxes`] does for four.
    #[inline(always)]
    fn boxes8<R: Wide>(&self, node: &Node8) -> (u32, [f32; 8]) {
        let (p, near) = (&node.planes, &self.near);
        let slab = |axis: usize, side: usize| {
            let o = R::splat(self.origin[axis].x);
            let inv = R::splat(self.inv[axis].x);
            (R::from_array(p[axis][side]) - o) * inv
        };
        let tx0 = slab(0, near[0]);
        let tx1 = slab(0, 1 - near[0]);
        let ty0 = slab(1, near[1]);
        let ty1 = slab(1, 1 - near[1]);
        let tz0 = slab(2, near[2]);
        let tz1 = slab(2, 1 - near[2]);
        let t_near = tx0.max_ps(ty0).max_ps(tz0).max_ps(R::splat(self.t_min));
        let t_far = tx1.min_ps(ty1).min_ps(tz1).min_ps(R::splat(self.closest)) * R::splat(SLACK);
        (R::bits(t_near.le(t_far)) & node.used, t_near.to_array())
    }
}

impl<Q: Query, const SPHERES: bool> Enter<Node> for SingleRay<Q, SPHERES> {
    type Entries = [f32; 4];
    type Order = [f32; 4];

    #[inline(always)]
    fn enter(&self, node: &Node) -> (u32, [f32; 4]) {
        let (mask, t_near) = self.boxes(&node.planes, node.used);
        (mask, t_near.to_array())
    }

    #[inline(always)]
    fn order(&self, _: &Node, t_near: &[f32; 4]) -> [f32; 4] {
        *t_near
    }
}

impl<Q: Query, const SPHERES: bool> Enter<Node8> for SingleRay<Q, SPHERES> {
    type Entries = [f32; 8];
    type Order = [f32; 8];

    #[inline(always)]
    fn enter(&self, node: &Node8) -> (u32, [f32; 8]) {
        // SAFETY: `avx2` is true only when `Isa::detect` found AVX2.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        if self.avx2 {
            return unsafe { single_avx2::boxes8(self, node) };
        }
        self.boxes8::<F8>(node)
    }

    #[inline(always)]
    fn order(&self, _: &Node8, t_near: &[f32; 8]) -> [f32; 8] {
        *t_near
    }
}

impl<Q: Query, const SPHERES: bool> Rays for SingleRay<Q, SPHERES> {
    type Entry = f32;

    #[inline(always)]
    fn needed(&self, t_near: &f32) -> bool {
        *t_near <= self.closest * SLACK
    }

    #[inline(always)]
    fn leaf(&mut self, bvh: &Bvh, leaf: u32, _: &f32) -> bool {
        let (kind, i) = leaf_parts(leaf);
        let kind = if SPHERES { Kind::Sphere } else { kind };
        // Instances and quadrics, out of line: one test keeps them off the
        // path of the other kinds.
        if kind >= Kind::Instance {
            return if kind == Kind::Instance {
                self.instances(bvh, bvh.instance_packet(i))
            } else {
                self.quadrics(bvh.quadric_packet(i))
            };
        }
        // SAFETY (the AVX2 calls): `avx2` is true only when `Isa::detect`
        // found AVX2.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        if bvh.avx2 {
            return match kind {
                Kind::Sphere => unsafe { single_avx2::spheres(self, bvh.sphere_packet(i)) },
                Kind::Triangle => unsafe { single_avx2::triangles(self, bvh.triangle_packet(i)) },
                _ => unsafe { single_avx2::quads(self, bvh.quad_packet(i)) },
            };
        }
        match kind {
            Kind::Sphere => self.spheres::<F8>(bvh.sphere_packet(i)),
            Kind::Triangle => self.triangles::<F8>(bvh.triangle_packet(i)),
            _ => self.quads::<F8>(bvh.quad_packet(i)),
        }
    }
}

/// Whether hit (distance, index) comes before hit `other` in the order every
/// query keeps: nearer first, the lower index among hits at exactly the same
/// distance (coincident surfaces), so that the result does not depend on the
/// order of the visit.
#[inline(always)]
pub(super) fn comes_before((t, index): (f32, u32), (closest, best): (f32, u32)) -> bool {
    t < closest || (t == closest && index < best)
}

/// The end of a packet test: `t_best` is the nearest distance found, not
/// beyond `closest`, and bit `lane` of `equal` is set for the lanes at that
/// distance, whose primitive indices are `index[lane]`. Returns the hit if
/// (t_best, lowest of those indices) comes before (closest, best).
#[inline(always)]
fn finish(t_best: f32, equal: u32, index: &[u32], closest: f32, best: u32) -> Option<(f32, u32)> {
    let first = equal.trailing_zeros() as usize;
    let mut lowest = index[first];
    if equal & (equal - 1) != 0 {
        // Several primitives at exactly the same distance (coincident surfaces):
        // the lowest index wins, wherever the spheres sit in the tree.
        let mut rest = equal & (equal - 1);
        while rest != 0 {
            lowest = lowest.min(index[rest.trailing_zeros() as usize]);
            rest &= rest - 1;
        }
    }
    // t_best is not beyond closest: equal or nearer.
    comes_before((t_best, lowest), (closest, best)).then_some((t_best, lowest))
}

/// The lanes set in `mask` (at least one, of a node of type `N`) ordered
/// by `distance`, farthest first, and how many there are: a traversal
/// pushes all but the last and goes on with the last, the nearest.
#[inline(always)]
pub(super) fn farthest_first<N: TreeNode, D: Index<usize, Output = f32>>(
    mut mask: u32,
    distance: &D,
) -> (N::Lanes, usize) {
    let mut lanes = N::Lanes::default();
    let order = lanes.as_mut();
    let mut n = 0;
    while mask != 0 {
        let lane = mask.trailing_zeros() as usize & (N::WIDTH - 1);
        mask &= mask - 1;
        // Insertion sort, descending distance.
        let mut i = n;
        while i > 0 && distance[order[i - 1]] < distance[lane] {
            order[i] = order[i - 1];
            i -= 1;
        }
        order[i] = lane;
        n += 1;
    }
    (lanes, n)
}

/// Box tests keep a box whose entry is up to this factor beyond the far end
/// of the interval (the box's exit or the best hit so far). The box and
/// sphere tests round differently, and a sphere touching its box's face can
/// compute a hit a few ulp before the box's computed entry: without the
/// margin, such a box could be culled when the best hit so far has the same
/// distance, and which of two tied spheres is found would depend on the order
/// of the visit. 2⁻¹² is far above those few ulp and costs no measurable
/// extra visits.
pub(crate) const SLACK: f32 = 1.0 + 1.0 / 4096.0;
const SLACK4: Vec4 = Vec4::splat(SLACK);

/// The two to eight binary nodes that become a wide node's children (in
/// place: a vector each cost an allocation a node).
struct Opened([usize; 8], usize);

impl std::ops::Deref for Opened {
    type Target = [usize];

    fn deref(&self) -> &[usize] {
        &self.0[..self.1]
    }
}

/// Turns the binary tree into wide nodes and packets.
struct Collapse<'a, P: ?Sized> {
    binary: &'a [BinaryNode],
    order: &'a [u32],
    primitives: &'a P,
}

impl<P: PrimitiveSet + ?Sized> Collapse<'_, P> {
    /// The up to `width` binary nodes that become the children of the wide
    /// node replacing interior node `i`: its two children, then repeatedly
    /// the interior one of largest surface area replaced by its own two
    /// children.
    fn open(&self, i: usize, width: usize) -> Opened {
        let b = self.binary;
        let mut list = Opened([i + 1, b[i].offset as usize, 0, 0, 0, 0, 0, 0], 2);
        while list.len() < width {
            let widest = list
                .iter()
                .enumerate()
                .filter(|(_, &n)| !b[n].is_leaf())
                .max_by(|x, y| {
                    b[*x.1]
                        .bounds()
                        .surface_area()
                        .total_cmp(&b[*y.1].bounds().surface_area())
                });
            let Some((pos, &n)) = widest else { break };
            list.0[pos] = n + 1;
            list.0[list.1] = b[n].offset as usize;
            list.1 += 1;
        }
        list
    }

    /// The number of wide nodes of `width` children that
    /// [`Collapse::emit_node`] emits for `children`.
    fn count_nodes(&self, children: &[usize], width: usize) -> usize {
        1 + children
            .iter()
            .filter(|&&c| !self.binary[c].is_leaf())
            .map(|&c| self.count_nodes(&self.open(c, width), width))
            .sum::<usize>()
    }

    /// The nodes of type `N` of the tree whose root's children are the
    /// binary nodes `roots` (see [`Collapse::emit_node`]).
    fn emit_tree<N: TreeNode>(&self, roots: &[usize], leaves: &mut [Vec<u32>; KINDS]) -> Vec<N> {
        // Reserved at its size: an estimate took twice the nodes' memory
        // when it was shrunk (a copy).
        let mut nodes = Vec::with_capacity(self.count_nodes(roots, N::WIDTH));
        self.emit_node(roots, &mut nodes, leaves);
        nodes
    }

    /// Emits the wide node whose children are the binary nodes `children`.
    /// A leaf child is given the next packet of its kind, made afterwards
    /// ([`Collapse::fill_packets`]): `leaves[kind]` gets its binary node.
    fn emit_node<N: TreeNode>(
        &self,
        children: &[usize],
        nodes: &mut Vec<N>,
        leaves: &mut [Vec<u32>; KINDS],
    ) -> u32 {
        let index = nodes.len();
        nodes.push(N::EMPTY);
        for (lane, &c) in children.iter().enumerate() {
            let node = &self.binary[c];
            let child = if node.is_leaf() {
                let kind = self
                    .primitives
                    .kind(self.order[node.offset as usize] as usize);
                let packets = &mut leaves[kind as usize];
                packets.push(c as u32);
                let packet = packets.len() - 1;
                debug_assert!(packet <= INDEX_MASK as usize);
                LEAF_BIT | (kind as u32) << KIND_SHIFT | packet as u32
            } else {
                let grandchildren = self.open(c, N::WIDTH);
                self.emit_node(&grandchildren, nodes, leaves)
            };
            nodes[index].set_child(lane, &node.bounds(), child);
        }
        index as u32
    }

    /// The primitives of binary leaf `leaf`, and their indices as a
    /// packet's lanes hold them (`NO_CHILD` in unused lanes).
    fn members(&self, leaf: u32) -> (&[u32], [u32; 8]) {
        let leaf = &self.binary[leaf as usize];
        debug_assert!(leaf.count as usize <= MAX_LEAF);
        let first = leaf.offset as usize;
        let members = &self.order[first..first + leaf.count as usize];
        let mut index = [NO_CHILD; 8];
        index[..members.len()].copy_from_slice(members);
        (members, index)
    }

    /// The packets of binary leaves `leaves`, in order, made by `make` from
    /// each leaf's primitives on every core.
    fn packets<T: Send>(
        &self,
        leaves: &[u32],
        make: impl Fn(&mut dyn Iterator<Item = Primitive>, [u32; 8]) -> T + Sync,
    ) -> Vec<T> {
        use rayon::prelude::*;
        leaves
            .par_iter()
            .map(|&leaf| {
                let (members, index) = self.members(leaf);
                let mut primitives = members
                    .iter()
                    .map(|&m| self.primitives.primitive(m as usize));
                make(&mut primitives, index)
            })
            .collect()
    }

    /// Makes the packets of the leaves [`Collapse::emit_node`] numbered:
    /// `leaves[kind]` lists the binary leaf of each packet of that kind.
    fn fill_packets(&self, leaves: &[Vec<u32>; KINDS], bvh: &mut Bvh) {
        // Fills lane `lane` of each field; unused lanes keep their filler.
        fn fill<const N: usize>(fields: &mut [Lane8; N], lane: usize, values: [f32; N]) {
            for (field, v) in fields.iter_mut().zip(values) {
                field[lane] = v;
            }
        }
        bvh.spheres = self.packets(&leaves[Kind::Sphere as usize], |members, index| {
            let mut p = SpherePacket {
                center: [[0.0; 8]; 3],
                radius2: [f32::NEG_INFINITY; 8],
                index,
            };
            for (lane, primitive) in members.enumerate() {
                let Primitive::Sphere(s) = primitive else {
                    unreachable!("a leaf holds one kind")
                };
                fill(&mut p.center, lane, s.center.to_array());
                p.radius2[lane] = s.radius * s.radius;
            }
            p
        });
        bvh.triangles = self.packets(&leaves[Kind::Triangle as usize], |members, index| {
            let mut p = TrianglePacket {
                vertices: [[[f32::NAN; 8]; 3]; 3],
                index,
            };
            for (lane, primitive) in members.enumerate() {
                let Primitive::Triangle(t) = primitive else {
                    unreachable!("a leaf holds one kind")
                };
                for (v, x) in p.vertices.iter_mut().zip(t.vertices) {
                    fill(v, lane, x.to_array());
                }
            }
            p
        });
        bvh.quads = self.packets(&leaves[Kind::Quad as usize], |members, index| {
            let nan = [[f32::NAN; 8]; 3];
            let mut p = QuadPacket {
                corner: nan,
                u: nan,
                v: nan,
                normal: nan,
                w: nan,
                d: [f32::NAN; 8],
                index,
            };
            for (lane, primitive) in members.enumerate() {
                let Primitive::Quad(q) = primitive else {
                    unreachable!("a leaf holds one kind")
                };
                fill(&mut p.corner, lane, q.corner.to_array());
                fill(&mut p.u, lane, q.u.to_array());
                fill(&mut p.v, lane, q.v.to_array());
                fill(&mut p.normal, lane, q.normal.to_array());
                fill(&mut p.w, lane, q.w.to_array());
                p.d[lane] = q.d;
            }
            p
        });
        bvh.quadrics = self.packets(&leaves[Kind::Quadric as usize], |members, index| {
            let mut p = QuadricPacket {
                shapes: [None; 8],
                index,
            };
            for (lane, primitive) in members.enumerate() {
                let Primitive::Quadric(q) = primitive else {
                    unreachable!("a leaf holds one kind")
                };
                p.shapes[lane] = Some(q);
            }
            p
        });
        let instances = bvh.instances.len();
        bvh.instance_packets = self.packets(&leaves[Kind::Instance as usize], |members, index| {
            let mut p = InstancePacket {
                instance: [NO_CHILD; 8],
                index,
            };
            for (lane, primitive) in members.enumerate() {
                let Primitive::Instance { index, .. } = primitive else {
                    unreachable!("a leaf holds one kind")
                };
                assert!(
                    (index as usize) < instances,
                    "instance {index} is not among the {instances} given"
                );
                p.instance[lane] = index;
            }
            p
        });
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::{Quad, Sphere, Triangle};
    use crate::math::Vec3;
    use crate::rng::Rng;

    fn brute_force(prims: &[Primitive], ray: &Ray, interval: Interval) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        for (i, p) in prims.iter().enumerate() {
            let max = best.map_or(interval.max, |b| b.0);
            if let Some(t) = p.hit(ray, Interval::new(interval.min, max)) {
                best = Some((t, i as u32));
            }
        }
        best
    }

    fn point(rng: &mut Rng, extent: f32) -> Vec3 {
        Vec3::new(
            rng.range_f32(-extent, extent),
            rng.range_f32(-extent, extent),
            rng.range_f32(-extent, extent),
        )
    }

    fn random_spheres(rng: &mut Rng, n: usize, extent: f32) -> Vec<Primitive> {
        (0..n)
            .map(|_| Primitive::Sphere(Sphere::new(point(rng, extent), rng.range_f32(0.1, 2.0))))
            .collect()
    }

    /// Spheres, triangles and quads mixed, in random order.
    fn random_mixed(rng: &mut Rng, n: usize, extent: f32) -> Vec<Primitive> {
        (0..n)
            .map(|_| {
                let c = point(rng, extent);
                match rng.next_u32() % 5 {
                    0 => Primitive::Sphere(Sphere::new(c, rng.range_f32(0.1, 2.0))),
                    1 => Primitive::Triangle(Triangle::new(
                        c,
                        c + point(rng, 3.0),
                        c + point(rng, 3.0),
                    )),
                    2 => Primitive::Quad(
                        Quad::new(c, point(rng, 3.0), point(rng, 3.0)).expect("random edges"),
                    ),
                    k => {
                        use crate::geometry::transform::{Transform, TransformStep};
                        use crate::geometry::{Quadric, QuadricForm};
                        let form = [QuadricForm::Disk, QuadricForm::Cylinder][k as usize - 3];
                        let size = [0; 3].map(|_| f64::from(rng.range_f32(0.2, 2.0)));
                        let axis = point(rng, 1.0).to_array().map(f64::from);
                        let steps = [
                            TransformStep::Scale(size),
                            TransformStep::Rotate {
                                axis,
                                degrees: f64::from(rng.range_f32(0.0, 360.0)),
                            },
                            TransformStep::Translate(c.to_array().map(f64::from)),
                        ];
                        let transform = Transform::from_steps(&steps).expect("a placement");
                        Primitive::Quadric(Quadric::new(form, &transform))
                    }
                }
            })
            .collect()
    }

    fn check_against_brute_force(prims: &[Primitive], rng: &mut Rng, rays: usize) -> usize {
        let bvh = Bvh::new(prims);
        let interval = Interval::new(0.001, f32::INFINITY);
        let mut hits = 0;
        for k in 0..rays {
            // Half in random directions, half aimed into the scene.
            let origin = point(rng, 30.0);
            let direction = if k % 2 == 0 {
                crate::sampling::unit_vector(rng.next_2d())
            } else {
                (point(rng, 10.0) - origin).normalize()
            };
            let ray = Ray::new(origin, direction);
            let expected = brute_force(prims, &ray, interval);
            let got = bvh.hit(&ray, interval).map(|h| (h.t, h.index));
            // Exactly the same: among coincident primitives, the lowest index.
            assert_eq!(got, expected);
            assert_eq!(bvh.occluded(&ray, interval), expected.is_some());
            hits += usize::from(expected.is_some());
        }
        hits
    }

    #[test]
    fn bvh_finds_the_same_nearest_hit_as_brute_force() {
        let mut rng = Rng::new(3);
        // Sizes that fill packets and nodes partly and fully.
        for n in [2, 3, 4, 5, 7, 16, 17, 500] {
            let spheres = random_spheres(&mut rng, n, 20.0);
            check_against_brute_force(&spheres, &mut rng, 5000);
        }
    }

    #[test]
    fn bvh_over_mixed_kinds_agrees_with_brute_force() {
        let mut rng = Rng::new(17);
        let mut hits = 0;
        for n in [1, 2, 3, 9, 30, 300, 2000] {
            let prims = random_mixed(&mut rng, n, 15.0);
            hits += check_against_brute_force(&prims, &mut rng, 3000);
        }
        assert!(
            hits > 2500,
            "only {hits} hits: the test exercises too little"
        );
    }

    #[test]
    fn leaves_hold_one_kind() {
        let mut rng = Rng::new(8);
        // Every kind at one place: SAH sees nothing to split.
        let c = Vec3::new(1.0, 1.0, 1.0);
        let mut prims = vec![Primitive::Sphere(Sphere::new(c, 1.0)); 3];
        prims.extend([Primitive::Triangle(Triangle::new(c, c + Vec3::X, c + Vec3::Y)); 3]);
        prims.extend([Primitive::Quad(Quad::new(c, Vec3::X, Vec3::Z).unwrap()); 2]);
        let disk = crate::geometry::Quadric::new(
            crate::geometry::QuadricForm::Disk,
            &crate::geometry::transform::Transform::IDENTITY,
        );
        prims.extend([Primitive::Quadric(disk); 2]);
        let bvh = Bvh::new(&prims);
        assert_eq!(
            (
                bvh.spheres.len(),
                bvh.triangles.len(),
                bvh.quads.len(),
                bvh.quadrics.len()
            ),
            (1, 1, 1, 1)
        );
        check_against_brute_force(&prims, &mut rng, 2000);
    }

    #[test]
    fn bvh_handles_coincident_and_axis_aligned_cases() {
        let mut rng = Rng::new(5);
        // Many spheres with one centre (no SAH split exists), and a row of
        // spheres on an axis hit by axis-aligned rays (0·∞ in the slab test).
        let mut prims = vec![Primitive::Sphere(Sphere::new(Vec3::new(1.0, 2.0, 3.0), 1.5)); 9];
        prims.extend(
            (0..20)
                .map(|i| Primitive::Sphere(Sphere::new(Vec3::new(i as f32 * 3.0, 0.0, 0.0), 1.0))),
        );
        check_against_brute_force(&prims, &mut rng, 2000);
        let bvh = Bvh::new(&prims);
        for dir in [Vec3::X, -Vec3::X, Vec3::Y, Vec3::Z] {
            for origin in [Vec3::new(-10.0, 0.0, 0.0), Vec3::new(30.0, 1.0, 0.0)] {
                let ray = Ray::new(origin, dir);
                let all = Interval::new(0.001, f32::INFINITY);
                let expected = brute_force(&prims, &ray, all).map(|b| b.0);
                assert_eq!(bvh.hit(&ray, all).map(|h| h.t), expected);
            }
        }
    }

    /// Each lane of a packet's eight-lane test gives the bits of the
    /// one-lane test of its primitive, for every kind.
    #[test]
    fn packet_lanes_agree_with_single_lane_tests_bit_for_bit() {
        let mut rng = Rng::new(11);
        let mut prims = random_mixed(&mut rng, 600, 3.0);
        prims.extend_from_within(..60);
        let bvh = Bvh::new(&prims);
        let mut hits = 0;
        for _ in 0..4_000 {
            let d = crate::sampling::unit_vector(rng.next_2d());
            let ray = Ray::new(point(&mut rng, 6.0), d);
            let interval = Interval::new(0.001, rng.range_f32(0.5, 20.0));
            let lanes = RayLanes::<F8>::splat(&ray, interval.min);
            let axes = TriangleRay::axes_of(d);
            let tri_ray = splat_triangle_ray(&TriangleRay::new(&ray, axes, interval.min));
            let mut check = |t: F8, valid: crate::lanes::M8, index: &[u32; 8]| {
                for lane in 0..8 {
                    if index[lane] == NO_CHILD {
                        assert!(!valid.lane(lane), "an unused lane hits");
                        continue;
                    }
                    let prim = &prims[index[lane] as usize];
                    let single = prim.hit(&ray, Interval::new(interval.min, f32::INFINITY));
                    let packet = valid.lane(lane).then_some(t.lane(lane));
                    assert_eq!(packet.map(f32::to_bits), single.map(f32::to_bits));
                    hits += usize::from(single.is_some());
                }
            };
            for p in &bvh.spheres {
                let (t, valid) = sphere::intersect(&lanes, &p.lanes());
                check(t, valid, &p.index);
            }
            for p in &bvh.triangles {
                let (t, valid) = triangle::intersect(&tri_ray, &p.lanes(axes));
                check(t, valid, &p.index);
            }
            for p in &bvh.quads {
                let (t, valid) = quad::intersect(&lanes, &p.lanes());
                check(t, valid, &p.index);
            }
        }
        // (Disks and cylinders, two kinds in five, have no packet test.)
        assert!(
            hits > 15_000,
            "only {hits} hits: the test exercises too little"
        );
    }

    /// 600 shapes of every kind among 30 instances of a tree of 40
    /// triangles, and the index of the first instance among its items.
    pub(in crate::geometry) fn shapes_among_instances(rng: &mut Rng) -> (Bvh, usize) {
        let mut prims = random_mixed(rng, 600, 20.0);
        let triangles: Vec<Primitive> = (0..40)
            .map(|_| {
                let c = point(rng, 3.0);
                Primitive::Triangle(Triangle::new(c, c + point(rng, 2.0), c + point(rng, 2.0)))
            })
            .collect();
        let group = std::sync::Arc::new(Bvh::new(&triangles));
        let instances: Vec<Instance> = (0..30)
            .map(|_| {
                let at = point(rng, 20.0).to_array().map(f64::from);
                let steps = [crate::geometry::transform::TransformStep::Translate(at)];
                let placed =
                    crate::geometry::transform::Transform::from_steps(&steps).expect("a move");
                Instance::new(placed, group.clone())
            })
            .collect();
        let first_instance = prims.len();
        for (index, instance) in instances.iter().enumerate() {
            prims.push(Primitive::Instance {
                bounds: instance.bounds(),
                index: index as u32,
            });
        }
        (Bvh::with_instances(&prims, instances), first_instance)
    }

    #[test]
    fn a_hit_outside_instances_has_no_sub_item() {
        // A nearer shape found after a farther instance (whose box the ray
        // entered first) must not keep the instance's sub-item.
        let mut rng = Rng::new(41);
        let (bvh, first_instance) = shapes_among_instances(&mut rng);
        let (mut in_instances, mut outside) = (0, 0);
        for _ in 0..20_000 {
            let origin = point(&mut rng, 30.0);
            let ray = Ray::new(origin, (point(&mut rng, 10.0) - origin).normalize());
            let interval = Interval::new(0.001, f32::INFINITY);
            let hits = [bvh.hit(&ray, interval), bvh.any_hit(&ray, interval)];
            for hit in hits.into_iter().flatten() {
                if (hit.index as usize) < first_instance {
                    assert_eq!(hit.sub, 0, "a shape's hit with a sub-item: {hit:?}");
                    outside += 1;
                } else {
                    in_instances += usize::from(hit.sub != 0);
                }
            }
        }
        assert!(
            outside > 5_000 && in_instances > 500,
            "{outside} and {in_instances} hits"
        );
    }

    #[test]
    fn eight_wide_trees_give_the_same_hits_with_and_without_avx2() {
        let mut rng = Rng::new(21);
        let prims = random_mixed(&mut rng, 3000, 20.0);
        let bvh = Bvh::new(&prims);
        assert!(
            matches!(&bvh.nodes, Nodes::Eight(wide) if wide.len() > 50),
            "an eight-wide tree"
        );
        let mut portable = bvh.clone();
        portable.avx2 = false;
        if !bvh.avx2 {
            eprintln!("this processor has no AVX2: only the portable box tests ran");
        }
        let key = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.index, h.sub));
        let mut hits = 0;
        for k in 0..20_000 {
            let origin = point(&mut rng, 30.0);
            let direction = if k % 2 == 0 {
                crate::sampling::unit_vector(rng.next_2d())
            } else {
                (point(&mut rng, 10.0) - origin).normalize()
            };
            let ray = Ray::new(origin, direction);
            let interval = Interval::new(0.001, rng.range_f32(5.0, 80.0));
            let hit = bvh.hit(&ray, interval);
            assert_eq!(key(hit), key(portable.hit(&ray, interval)));
            assert_eq!(
                key(bvh.any_hit(&ray, interval)),
                key(portable.any_hit(&ray, interval))
            );
            if k % 16 == 0 {
                let expected = brute_force(&prims, &ray, interval);
                assert_eq!(hit.map(|h| (h.t, h.index)), expected);
            }
            hits += usize::from(hit.is_some());
        }
        assert!(hits > 5_000, "only {hits} hits");
    }

    #[test]
    fn deep_trees_do_not_overflow_the_stack() {
        // Radii growing geometrically make SAH peel one sphere at a time.
        let prims: Vec<Primitive> = (0..3000)
            .map(|i| {
                Primitive::Sphere(Sphere::new(
                    Vec3::new(i as f32 * 0.001, 0.0, 0.0),
                    1.002f32.powi(i),
                ))
            })
            .collect();
        let mut rng = Rng::new(9);
        check_against_brute_force(&prims, &mut rng, 200);
    }

    #[test]
    fn deep_eight_wide_trees_do_not_overflow_the_stack() {
        // Triangles growing geometrically around one point: SAH peels one
        // at a time, and the tree is as deep as the build allows.
        let prims: Vec<Primitive> = (0..3000)
            .map(|i| {
                let s = 1.002f32.powi(i);
                let c = Vec3::new(i as f32 * 0.001, 0.0, 0.0);
                Primitive::Triangle(Triangle::new(
                    c + Vec3::new(-s, -s, 0.0),
                    c + Vec3::new(s, -s, 0.1 * s),
                    c + Vec3::new(0.0, s, -0.1 * s),
                ))
            })
            .collect();
        let mut rng = Rng::new(10);
        assert!(check_against_brute_force(&prims, &mut rng, 200) > 50);
    }

    #[test]
    fn empty_and_single_primitive_scenes_work() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let all = Interval::new(0.0, f32::INFINITY);
        assert!(Bvh::new(&[]).hit(&ray, all).is_none());
        assert!(!Bvh::new(&[]).occluded(&ray, all));
        let one = Bvh::new(&[Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0))]);
        let hit = one.hit(&ray, all).expect("hits the sphere");
        assert_eq!((hit.t, hit.index), (4.0, 0));
        assert!(one.occluded(&ray, all));
        assert!(!one.occluded(&ray, Interval::new(0.0, 3.5)));
    }
}
