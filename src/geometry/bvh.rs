//! A 4-wide bounding volume hierarchy over spheres, traversed with SIMD.
//!
//! The binary SAH tree of [`super::bvh_build`] is collapsed into nodes of four
//! children: a node stores the boxes of its four children as structure of
//! arrays (the lower x planes of all four in one 4-lane vector, and so on), so
//! one ray is tested against four boxes with a handful of vector operations.
//! Leaves are packets of four spheres, also stored as structure of arrays and
//! tested together. Traversal visits the hit children nearest first and skips
//! any entry of its stack whose box starts beyond the closest hit found so far.
//!
//! The vectors are glam's [`Vec4`], which uses SSE2 on x86-64 and NEON on
//! aarch64 (both always present there) and plain scalar code elsewhere.

use crate::geometry::bvh_build::{build_binary, Aabb, BinaryNode, MAX_LEAF};
use crate::geometry::Sphere;
use crate::math::Interval;
use crate::ray::Ray;
use glam::Vec4;
use std::mem::MaybeUninit;

/// Children of a node referring to a leaf have this bit set.
const LEAF_BIT: u32 = 1 << 31;
/// An unused child slot (its box is empty, so it is never entered).
const NO_CHILD: u32 = u32::MAX;
/// Entries of the traversal stack: a node pushes at most three children and
/// the tree is at most `MAX_SAH_DEPTH + 32` levels deep (see `bvh_build`).
const STACK_SIZE: usize = 256;

/// Four children's boxes, structure of arrays, and their references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    /// `planes[axis][0]`: the four lower bounds along `axis`; `[1]`: the upper.
    planes: [[Vec4; 2]; 3],
    /// Node index, `LEAF_BIT | packet index`, or `NO_CHILD`.
    children: [u32; 4],
    /// Bit `lane` is set when `children[lane]` is used.
    used: u32,
}

impl Node {
    const EMPTY: Node = Node {
        planes: [[Vec4::INFINITY, Vec4::NEG_INFINITY]; 3],
        children: [NO_CHILD; 4],
        used: 0,
    };

    fn set_child(&mut self, lane: usize, bounds: &Aabb, child: u32) {
        for axis in 0..3 {
            self.planes[axis][0][lane] = bounds.min[axis];
            self.planes[axis][1][lane] = bounds.max[axis];
        }
        self.children[lane] = child;
        self.used |= 1 << lane;
    }
}

/// Up to four spheres, structure of arrays. Unused lanes have a radius² of
/// −∞, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Packet {
    cx: Vec4,
    cy: Vec4,
    cz: Vec4,
    radius2: Vec4,
    /// Index of each sphere in the input.
    index: [u32; 4],
}

/// The nearest sphere a ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the sphere in the order the BVH was built from.
    pub index: u32,
}

/// A 4-wide SAH bounding volume hierarchy over a set of spheres.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Node 0 is the root; empty when there are no spheres.
    nodes: Vec<Node>,
    packets: Vec<Packet>,
}

impl Bvh {
    /// Builds the hierarchy over `spheres`.
    pub fn new(spheres: &[Sphere]) -> Self {
        let (binary, order) = build_binary(spheres);
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(binary.len() / 3 + 1),
            packets: Vec::with_capacity(spheres.len().div_ceil(2)),
        };
        if binary.is_empty() {
            return bvh;
        }
        let collapse = Collapse {
            binary: &binary,
            order: &order,
            spheres,
        };
        let roots = if binary[0].is_leaf() {
            vec![0]
        } else {
            collapse.open(0)
        };
        collapse.emit_node(&roots, &mut bvh);
        bvh.nodes.shrink_to_fit();
        bvh.packets.shrink_to_fit();
        bvh
    }

    /// Number of nodes (for statistics and memory estimates).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes of memory held by the hierarchy.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.packets.capacity() * std::mem::size_of::<Packet>()
    }

    /// The nearest sphere hit by `ray` within `interval`.
    #[inline(always)]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        self.traverse(ray, interval)
    }

    /// Node `i`, which the traversal reached through a child reference.
    #[inline(always)]
    fn node(&self, i: u32) -> &Node {
        debug_assert!((i as usize) < self.nodes.len());
        // SAFETY: the traversal starts at node 0 of a non-empty tree and only
        // follows references of used child slots, each of which `Collapse`
        // wrote after pushing the node it names, so every index is in bounds.
        // (Unchecked: the bounds checks were 3% of the render's instructions.)
        #[allow(unsafe_code)]
        unsafe {
            self.nodes.get_unchecked(i as usize)
        }
    }

    /// Packet `i`, reached through a leaf reference of a used child slot.
    #[inline(always)]
    fn packet(&self, i: u32) -> &Packet {
        debug_assert!((i as usize) < self.packets.len());
        // SAFETY: as for `node`: `Collapse::emit_packet` returns the index of
        // the packet it has just pushed.
        #[allow(unsafe_code)]
        unsafe {
            self.packets.get_unchecked(i as usize)
        }
    }

    #[inline(always)]
    fn traverse(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        let d = ray.direction;
        let o = ray.origin;
        let inv = d.recip();
        // Per axis: which of the two planes the ray meets first.
        let near = [
            usize::from(inv.x < 0.0),
            usize::from(inv.y < 0.0),
            usize::from(inv.z < 0.0),
        ];
        let inv4 = [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)];
        let o4 = [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)];
        let sphere_ray = SphereRay {
            ox: Vec4::splat(o.x),
            oy: Vec4::splat(o.y),
            oz: Vec4::splat(o.z),
            dx: Vec4::splat(d.x),
            dy: Vec4::splat(d.y),
            dz: Vec4::splat(d.z),
            a: Vec4::splat(d.length_squared()),
            t_min: Vec4::splat(interval.min),
        };
        let t_min = Vec4::splat(interval.min);
        let mut closest = interval.max;
        let mut best = NO_CHILD;

        // Uninitialised: zeroing 2 KiB on every call cost ~10% of the render.
        let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); STACK_SIZE];
        let mut top = 0usize;
        let mut current = 0u32;
        loop {
            if current & LEAF_BIT != 0 {
                let packet = self.packet(current & !LEAF_BIT);
                if let Some((t, index)) = sphere_ray.hit_packet(packet, closest) {
                    closest = t;
                    best = index;
                }
            } else {
                let node = self.node(current);
                let p = &node.planes;
                let tx0 = (p[0][near[0]] - o4[0]) * inv4[0];
                let tx1 = (p[0][1 - near[0]] - o4[0]) * inv4[0];
                let ty0 = (p[1][near[1]] - o4[1]) * inv4[1];
                let ty1 = (p[1][1 - near[1]] - o4[1]) * inv4[1];
                let tz0 = (p[2][near[2]] - o4[2]) * inv4[2];
                let tz1 = (p[2][1 - near[2]] - o4[2]) * inv4[2];
                // The bound given last wins when a lane is NaN (0·∞ for a ray
                // lying in a box's plane), so a NaN never culls a box it may hit.
                let t_near = tx0.max(ty0).max(tz0).max(t_min);
                let t_far = tx1.min(ty1).min(tz1).min(Vec4::splat(closest));
                let mut mask = t_near.cmple(t_far).bitmask() & node.used;
                if mask != 0 {
                    // Push the hit children farthest first; go on with the nearest.
                    let t_near = t_near.to_array();
                    let mut hits = [(0u32, 0.0f32); 4];
                    let mut n = 0;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize & 3;
                        mask &= mask - 1;
                        let entry = (node.children[lane], t_near[lane]);
                        // Insertion sort, descending distance.
                        let mut i = n;
                        while i > 0 && hits[i - 1].1 < entry.1 {
                            hits[i] = hits[i - 1];
                            i -= 1;
                        }
                        hits[i] = entry;
                        n += 1;
                    }
                    for &h in &hits[..n - 1] {
                        stack[top].write(h);
                        top += 1;
                    }
                    current = hits[n - 1].0;
                    continue;
                }
            }
            // Pop the next entry that may still hold a nearer hit.
            loop {
                if top == 0 {
                    return (best != NO_CHILD).then_some(Hit {
                        t: closest,
                        index: best,
                    });
                }
                top -= 1;
                // SAFETY: entries below `top` were all written by the pushes above.
                #[allow(unsafe_code)]
                let (child, t_near) = unsafe { stack[top].assume_init() };
                if t_near <= closest {
                    current = child;
                    break;
                }
            }
        }
    }
}

/// A ray broadcast to four lanes, for sphere packets.
struct SphereRay {
    ox: Vec4,
    oy: Vec4,
    oz: Vec4,
    dx: Vec4,
    dy: Vec4,
    dz: Vec4,
    /// |direction|².
    a: Vec4,
    t_min: Vec4,
}

impl SphereRay {
    /// The nearest hit among the packet's spheres closer than `closest`:
    /// [`Sphere::hit`] on four spheres at once, operation for operation, so
    /// both give bit-identical distances.
    #[inline(always)]
    fn hit_packet(&self, p: &Packet, closest: f32) -> Option<(f32, u32)> {
        let fx = self.ox - p.cx;
        let fy = self.oy - p.cy;
        let fz = self.oz - p.cz;
        let half_b = fx * self.dx + fy * self.dy + fz * self.dz;
        let c = fx * fx + fy * fy + fz * fz - p.radius2;
        let k = half_b / self.a;
        let lx = fx - k * self.dx;
        let ly = fy - k * self.dy;
        let lz = fz - k * self.dz;
        let discriminant = self.a * (p.radius2 - (lx * lx + ly * ly + lz * lz));
        let real = discriminant.cmpge(Vec4::ZERO);
        if !real.any() {
            return None;
        }
        let sqrt_d = sqrt4(discriminant);
        let q = -half_b - sqrt_d.copysign(half_b);
        let (r1, r2) = (c / q, q / self.a);
        let ordered = r1.cmple(r2);
        let near = Vec4::select(ordered, r1, r2);
        let far = Vec4::select(ordered, r2, r1);
        let closest4 = Vec4::splat(closest);
        let near_ok = self.t_min.cmplt(near) & near.cmplt(closest4);
        let far_ok = self.t_min.cmplt(far) & far.cmplt(closest4);
        let valid = real & q.cmpne(Vec4::ZERO);
        let hit = valid & (near_ok | far_ok);
        if !hit.any() {
            return None;
        }
        let t = Vec4::select(hit, Vec4::select(near_ok, near, far), Vec4::INFINITY);
        let t_best = t.min_element();
        // The lowest lane among equals, as a sequential loop would keep.
        let lane = t.cmpeq(Vec4::splat(t_best)).bitmask().trailing_zeros() as usize & 3;
        Some((t_best, p.index[lane]))
    }
}

/// Lane-wise square root (glam's `Vec4` has none).
#[inline(always)]
#[allow(unsafe_code)]
fn sqrt4(v: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE is part of the x86-64 baseline, so the instruction exists.
        Vec4::from(unsafe { std::arch::x86_64::_mm_sqrt_ps(v.into()) })
    }
    #[cfg(target_arch = "aarch64")]
    {
        // SAFETY: NEON is part of the aarch64 baseline, so the instruction exists.
        Vec4::from(unsafe { std::arch::aarch64::vsqrtq_f32(v.into()) })
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        Vec4::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt(), v.w.sqrt())
    }
}

/// Turns the binary tree into 4-wide nodes and sphere packets.
struct Collapse<'a> {
    binary: &'a [BinaryNode],
    order: &'a [u32],
    spheres: &'a [Sphere],
}

impl Collapse<'_> {
    /// The up to four binary nodes that become the children of the wide node
    /// replacing interior node `i`: its two children, then repeatedly the
    /// interior one of largest surface area replaced by its own two children.
    fn open(&self, i: usize) -> Vec<usize> {
        let b = self.binary;
        let mut list = vec![i + 1, b[i].offset as usize];
        while list.len() < 4 {
            let widest = list
                .iter()
                .enumerate()
                .filter(|(_, &n)| !b[n].is_leaf())
                .max_by(|x, y| {
                    b[*x.1]
                        .bounds
                        .surface_area()
                        .total_cmp(&b[*y.1].bounds.surface_area())
                });
            let Some((pos, &n)) = widest else { break };
            list[pos] = n + 1;
            list.push(b[n].offset as usize);
        }
        list
    }

    /// Emits the wide node whose children are the binary nodes `children`.
    fn emit_node(&self, children: &[usize], bvh: &mut Bvh) -> u32 {
        let index = bvh.nodes.len();
        bvh.nodes.push(Node::EMPTY);
        for (lane, &c) in children.iter().enumerate() {
            let node = &self.binary[c];
            let child = if node.is_leaf() {
                self.emit_packet(node, bvh)
            } else {
                let grandchildren = self.open(c);
                self.emit_node(&grandchildren, bvh)
            };
            bvh.nodes[index].set_child(lane, &node.bounds, child);
        }
        index as u32
    }

    fn emit_packet(&self, leaf: &BinaryNode, bvh: &mut Bvh) -> u32 {
        debug_assert!(leaf.count as usize <= MAX_LEAF);
        let mut p = Packet {
            cx: Vec4::ZERO,
            cy: Vec4::ZERO,
            cz: Vec4::ZERO,
            radius2: Vec4::NEG_INFINITY,
            index: [NO_CHILD; 4],
        };
        let first = leaf.offset as usize;
        for lane in 0..leaf.count as usize {
            let index = self.order[first + lane];
            let s = &self.spheres[index as usize];
            p.cx[lane] = s.center.x;
            p.cy[lane] = s.center.y;
            p.cz[lane] = s.center.z;
            p.radius2[lane] = s.radius * s.radius;
            p.index[lane] = index;
        }
        bvh.packets.push(p);
        LEAF_BIT | (bvh.packets.len() - 1) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
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

    fn random_spheres(rng: &mut Rng, n: usize, extent: f32) -> Vec<Sphere> {
        (0..n)
            .map(|_| {
                let c = Vec3::new(
                    rng.range_f32(-extent, extent),
                    rng.range_f32(-extent, extent),
                    rng.range_f32(-extent, extent),
                );
                Sphere::new(c, rng.range_f32(0.1, 2.0))
            })
            .collect()
    }

    fn check_against_brute_force(spheres: &[Sphere], rng: &mut Rng, rays: usize) {
        let bvh = Bvh::new(spheres);
        let interval = Interval::new(0.001, f32::INFINITY);
        for _ in 0..rays {
            let origin = Vec3::new(
                rng.range_f32(-30.0, 30.0),
                rng.range_f32(-30.0, 30.0),
                rng.range_f32(-30.0, 30.0),
            );
            let ray = Ray::new(origin, crate::sampling::unit_vector(rng));
            let expected = brute_force(spheres, &ray, interval);
            let got = bvh.hit(&ray, interval).map(|h| (h.t, h.index));
            assert_eq!(got.map(|g| g.0), expected.map(|e| e.0));
            if let (Some((t, i)), Some((_, j))) = (got, expected) {
                // Coincident spheres tie; either may be reported.
                let same = spheres[i as usize] == spheres[j as usize];
                assert!(i == j || same, "t = {t}: sphere {i} instead of {j}");
            }
        }
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
    fn bvh_handles_coincident_and_axis_aligned_cases() {
        let mut rng = Rng::new(5);
        // Many spheres with one centre (no SAH split exists), and a row of
        // spheres on an axis hit by axis-aligned rays (0·∞ in the slab test).
        let mut spheres = vec![Sphere::new(Vec3::new(1.0, 2.0, 3.0), 1.5); 9];
        spheres.extend((0..20).map(|i| Sphere::new(Vec3::new(i as f32 * 3.0, 0.0, 0.0), 1.0)));
        check_against_brute_force(&spheres, &mut rng, 2000);
        let bvh = Bvh::new(&spheres);
        for dir in [Vec3::X, -Vec3::X, Vec3::Y, Vec3::Z] {
            for origin in [Vec3::new(-10.0, 0.0, 0.0), Vec3::new(30.0, 1.0, 0.0)] {
                let ray = Ray::new(origin, dir);
                let all = Interval::new(0.001, f32::INFINITY);
                let expected = brute_force(&spheres, &ray, all).map(|b| b.0);
                assert_eq!(bvh.hit(&ray, all).map(|h| h.t), expected);
            }
        }
    }

    #[test]
    fn deep_trees_do_not_overflow_the_stack() {
        // Radii growing geometrically make SAH peel one sphere at a time.
        let spheres: Vec<Sphere> = (0..3000)
            .map(|i| Sphere::new(Vec3::new(i as f32 * 0.001, 0.0, 0.0), 1.002f32.powi(i)))
            .collect();
        let mut rng = Rng::new(9);
        check_against_brute_force(&spheres, &mut rng, 200);
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
