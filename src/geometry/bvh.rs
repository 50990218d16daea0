//! A 4-wide bounding volume hierarchy over spheres, traversed with SIMD.
//!
//! The binary SAH tree of [`super::bvh_build`] is collapsed into nodes of four
//! children: a node stores the boxes of its four children as structure of
//! arrays (the lower x planes of all four in one 4-lane vector, and so on), so
//! one ray is tested against four boxes with a handful of vector operations.
//! Leaves are packets of up to eight spheres, also stored as structure of
//! arrays and tested together: as one 8-lane vector when the processor has
//! AVX2 (checked at run time), as two 4-lane halves otherwise. Traversal visits the hit children nearest first and skips
//! any entry of its stack whose box starts beyond the closest hit found so far.
//!
//! The vectors are glam's [`Vec4`], which uses SSE2 on x86-64 and NEON on
//! aarch64 (both always present there) and plain scalar code elsewhere.

use crate::geometry::bvh_build::{build_binary, Aabb, BinaryNode, MAX_LEAF};
use crate::geometry::Sphere;
use crate::isa::Isa;
use crate::math::Interval;
use crate::ray::Ray;
use glam::Vec4;
use std::mem::MaybeUninit;

/// Children of a node referring to a leaf have this bit set.
pub(super) const LEAF_BIT: u32 = 1 << 31;
/// An unused child slot (its box is empty, so it is never entered).
pub(super) const NO_CHILD: u32 = u32::MAX;
/// Entries of the traversal stack: a node pushes at most three children and
/// the tree is at most `MAX_SAH_DEPTH + 32` levels deep (see `bvh_build`).
pub(super) const STACK_SIZE: usize = 256;

/// Four children's boxes, structure of arrays, and their references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    /// `planes[axis][0]`: the four lower bounds along `axis`; `[1]`: the upper.
    pub(super) planes: [[Vec4; 2]; 3],
    /// Node index, `LEAF_BIT | packet index`, or `NO_CHILD`.
    pub(super) children: [u32; 4],
    /// Bit `lane` is set when `children[lane]` is used.
    pub(super) used: u32,
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

/// Up to eight spheres, structure of arrays: lanes 0–3 in the first `Vec4`
/// of each field, lanes 4–7 in the second, so the eight lanes of a field are
/// also one contiguous 8-float vector. Unused lanes have a radius² of −∞,
/// which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Packet {
    pub(super) cx: [Vec4; 2],
    pub(super) cy: [Vec4; 2],
    pub(super) cz: [Vec4; 2],
    pub(super) radius2: [Vec4; 2],
    /// Index of each sphere in the input; `NO_CHILD` in unused lanes (which
    /// come after the used ones).
    pub(super) index: [u32; 8],
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
    /// Whether the processor has AVX2, asked once when the tree is built:
    /// asking for every ray cost ≈ 20 instructions per ray.
    avx2: bool,
}

impl Bvh {
    /// Builds the hierarchy over `spheres`.
    pub fn new(spheres: &[Sphere]) -> Self {
        let (binary, order) = build_binary(spheres);
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(binary.len() / 3 + 1),
            packets: Vec::with_capacity(spheres.len().div_ceil(2)),
            avx2: Isa::detect() == Isa::Avx2,
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

    /// The nearest sphere hit by `ray` within `interval`; the ray's direction
    /// must have unit length (see [`Sphere::hit`]).
    #[inline(always)]
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<Hit> {
        debug_assert!(
            (ray.direction.length_squared() - 1.0).abs() < 1e-4,
            "ray direction {} is not unit length",
            ray.direction
        );
        if self.nodes.is_empty() {
            return None;
        }
        self.traverse(ray, interval)
    }

    /// Whether the tree is empty (there are no spheres).
    #[inline(always)]
    pub(super) fn nodes_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Node `i`, which the traversal reached through a child reference.
    #[inline(always)]
    pub(super) fn node(&self, i: u32) -> &Node {
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
    pub(super) fn packet(&self, i: u32) -> &Packet {
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
        let sphere_ray = SphereRay::new(ray, interval, self.avx2);
        // The best hit so far, compared as the pair (distance, sphere index)
        // so that, with boxes kept within `SLACK`, the result does not depend
        // on the order of the visit. No sphere ties the start
        // (interval.max, 0): index 0 is the lowest.
        let mut closest = interval.max;
        let mut best = 0;

        // Uninitialised: zeroing 2 KiB on every call cost ~10% of the render.
        let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); STACK_SIZE];
        let mut top = 0usize;
        let mut current = 0u32;
        loop {
            if current & LEAF_BIT != 0 {
                let packet = self.packet(current & !LEAF_BIT);
                if let Some((t, index)) = sphere_ray.hit_packet(packet, closest, best) {
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
                let t_near = max4(max4(max4(tx0, ty0), tz0), sphere_ray.t_min);
                let t_far = min4(min4(min4(tx1, ty1), tz1), Vec4::splat(closest)) * SLACK4;
                let mask = t_near.cmple(t_far).bitmask() & node.used;
                if mask != 0 && mask & (mask - 1) == 0 {
                    // One child hit (the most common case): go on with it.
                    current = node.children[mask.trailing_zeros() as usize & 3];
                    continue;
                }
                if mask != 0 {
                    let t_near = t_near.to_array();
                    let first = mask.trailing_zeros() as usize & 3;
                    let rest = mask & (mask - 1);
                    if rest & (rest - 1) == 0 {
                        // Two children (most of the rest): push the farther,
                        // go on with the nearer (the first lane on a tie).
                        let second = rest.trailing_zeros() as usize & 3;
                        let (near, far) = if t_near[second] < t_near[first] {
                            (second, first)
                        } else {
                            (first, second)
                        };
                        stack[top].write((node.children[far], t_near[far]));
                        top += 1;
                        current = node.children[near];
                        continue;
                    }
                    // Three or four: push the hit children farthest first; go
                    // on with the nearest.
                    let (order, n) = farthest_first(mask, t_near);
                    for &lane in &order[..n - 1] {
                        stack[top].write((node.children[lane], t_near[lane]));
                        top += 1;
                    }
                    current = node.children[order[n - 1]];
                    continue;
                }
            }
            // Pop the next entry that may still hold a nearer hit.
            loop {
                if top == 0 {
                    // Every accepted hit is nearer than interval.max.
                    return (closest < interval.max).then_some(Hit {
                        t: closest,
                        index: best,
                    });
                }
                top -= 1;
                // SAFETY: entries below `top` were all written by the pushes above.
                #[allow(unsafe_code)]
                let (child, t_near) = unsafe { stack[top].assume_init() };
                if t_near <= closest * SLACK {
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
    t_min: Vec4,
    /// Whether the processor has AVX2 (the tree's answer).
    avx2: bool,
}

impl SphereRay {
    #[inline(always)]
    fn new(ray: &Ray, interval: Interval, avx2: bool) -> Self {
        let (o, d) = (ray.origin, ray.direction);
        SphereRay {
            ox: Vec4::splat(o.x),
            oy: Vec4::splat(o.y),
            oz: Vec4::splat(o.z),
            dx: Vec4::splat(d.x),
            dy: Vec4::splat(d.y),
            dz: Vec4::splat(d.z),
            t_min: Vec4::splat(interval.min),
            avx2,
        }
    }

    /// The packet's hit (t, sphere index) that comes before `(closest, best)`
    /// in the order of distance then index, if any: the nearest sphere, the
    /// lowest index among spheres at exactly the same distance. Distances are
    /// bit-identical to [`Sphere::hit`] whichever version runs.
    #[inline(always)]
    fn hit_packet(&self, p: &Packet, closest: f32, best: u32) -> Option<(f32, u32)> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only when `Isa::detect` found AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.hit_packet_avx2(p, closest, best) };
        }
        self.hit_packet_halves(p, closest, best)
    }

    /// [`Self::hit_packet`] as two 4-lane tests.
    #[inline(always)]
    fn hit_packet_halves(&self, p: &Packet, closest: f32, best: u32) -> Option<(f32, u32)> {
        let first = self.hit_half(p, 0, closest, best);
        if p.index[4] == NO_CHILD {
            return first;
        }
        let (closest, best) = first.unwrap_or((closest, best));
        self.hit_half(p, 1, closest, best).or(first)
    }

    /// [`Self::hit_packet`] for lanes `4·half .. 4·half + 4`: [`Sphere::hit`]
    /// on four spheres at once, operation for operation, so both give
    /// bit-identical distances.
    #[inline(always)]
    fn hit_half(&self, p: &Packet, half: usize, closest: f32, best: u32) -> Option<(f32, u32)> {
        let radius2 = p.radius2[half];
        let fx = self.ox - p.cx[half];
        let fy = self.oy - p.cy[half];
        let fz = self.oz - p.cz[half];
        let half_b = fx * self.dx + fy * self.dy + fz * self.dz;
        let lx = fx - half_b * self.dx;
        let ly = fy - half_b * self.dy;
        let lz = fz - half_b * self.dz;
        let discriminant = radius2 - (lx * lx + ly * ly + lz * lz);
        let real = discriminant.cmpge(Vec4::ZERO);
        if !real.any() {
            return None;
        }
        let sqrt_d = sqrt4(discriminant);
        let near = -half_b - sqrt_d;
        let far = -half_b + sqrt_d;
        // The first root beyond t_min, if it is not beyond `closest`.
        let near_ok = self.t_min.cmplt(near);
        let t = Vec4::select(near_ok, near, far);
        let hit = real & (near_ok | self.t_min.cmplt(far)) & t.cmple(Vec4::splat(closest));
        if !hit.any() {
            return None;
        }
        let t = Vec4::select(hit, t, Vec4::INFINITY);
        let t_best = t.min_element();
        let equal = t.cmpeq(Vec4::splat(t_best)).bitmask();
        let lanes = &p.index[4 * half..4 * half + 4];
        finish(t_best, equal, lanes, closest, best)
    }

    /// [`Self::hit_half`] on all eight lanes at once with AVX, the same
    /// operations in the same order.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    #[allow(unsafe_code)]
    unsafe fn hit_packet_avx2(&self, p: &Packet, closest: f32, best: u32) -> Option<(f32, u32)> {
        use std::arch::x86_64::*;
        // Loop-invariant after inlining: hoisted out of the traversal loop.
        macro_rules! wide {
            ($v:expr) => {{
                let m: __m128 = $v.into();
                _mm256_set_m128(m, m)
            }};
        }
        macro_rules! load {
            ($f:expr) => {
                // SAFETY: the field is two adjacent `Vec4`s (`repr(C)`), 32 bytes.
                _mm256_loadu_ps($f.as_ptr().cast::<f32>())
            };
        }
        let (ox, oy, oz) = (wide!(self.ox), wide!(self.oy), wide!(self.oz));
        let (dx, dy, dz) = (wide!(self.dx), wide!(self.dy), wide!(self.dz));
        let t_min = wide!(self.t_min);
        let zero = _mm256_setzero_ps();
        let sign = _mm256_set1_ps(-0.0);
        let radius2 = load!(p.radius2);
        let fx = _mm256_sub_ps(ox, load!(p.cx));
        let fy = _mm256_sub_ps(oy, load!(p.cy));
        let fz = _mm256_sub_ps(oz, load!(p.cz));
        let dot = |x: __m256, y: __m256, z: __m256, u: __m256, v: __m256, w: __m256| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(x, u), _mm256_mul_ps(y, v)),
                _mm256_mul_ps(z, w),
            )
        };
        let half_b = dot(fx, fy, fz, dx, dy, dz);
        let lx = _mm256_sub_ps(fx, _mm256_mul_ps(half_b, dx));
        let ly = _mm256_sub_ps(fy, _mm256_mul_ps(half_b, dy));
        let lz = _mm256_sub_ps(fz, _mm256_mul_ps(half_b, dz));
        let discriminant = _mm256_sub_ps(radius2, dot(lx, ly, lz, lx, ly, lz));
        let real = _mm256_cmp_ps::<_CMP_GE_OQ>(discriminant, zero);
        if _mm256_movemask_ps(real) == 0 {
            return None;
        }
        let sqrt_d = _mm256_sqrt_ps(discriminant);
        let minus_b = _mm256_xor_ps(half_b, sign);
        let near = _mm256_sub_ps(minus_b, sqrt_d);
        let far = _mm256_add_ps(minus_b, sqrt_d);
        // The first root beyond t_min, if it is not beyond `closest`.
        let near_ok = _mm256_cmp_ps::<_CMP_LT_OQ>(t_min, near);
        let t = _mm256_blendv_ps(far, near, near_ok);
        let hit = _mm256_and_ps(
            _mm256_and_ps(
                real,
                _mm256_or_ps(near_ok, _mm256_cmp_ps::<_CMP_LT_OQ>(t_min, far)),
            ),
            _mm256_cmp_ps::<_CMP_LE_OQ>(t, _mm256_set1_ps(closest)),
        );
        if _mm256_movemask_ps(hit) == 0 {
            return None;
        }
        let t = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t, hit);
        // The minimum does not depend on the order of comparisons: every lane
        // is a number or +∞.
        let m = _mm_min_ps(_mm256_castps256_ps128(t), _mm256_extractf128_ps::<1>(t));
        let m = _mm_min_ps(m, _mm_shuffle_ps::<0b01_00_11_10>(m, m));
        let m = _mm_min_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m));
        let t_best = _mm_cvtss_f32(m);
        let equal = _mm256_cmp_ps::<_CMP_EQ_OQ>(t, _mm256_set1_ps(t_best));
        finish(
            t_best,
            _mm256_movemask_ps(equal) as u32,
            &p.index,
            closest,
            best,
        )
    }
}

/// The end of a packet test: `t_best` is the nearest distance found, not
/// beyond `closest`, and bit `lane` of `equal` is set for the lanes at that
/// distance, whose sphere indices are `index[lane]`. Returns the hit if
/// (t_best, lowest of those indices) comes before (closest, best).
#[inline(always)]
fn finish(t_best: f32, equal: u32, index: &[u32], closest: f32, best: u32) -> Option<(f32, u32)> {
    let first = equal.trailing_zeros() as usize;
    let mut lowest = index[first];
    if equal & (equal - 1) != 0 {
        // Several spheres at exactly the same distance (coincident surfaces):
        // the lowest index wins, wherever the spheres sit in the tree.
        let mut rest = equal & (equal - 1);
        while rest != 0 {
            lowest = lowest.min(index[rest.trailing_zeros() as usize]);
            rest &= rest - 1;
        }
    }
    (t_best < closest || lowest < best).then_some((t_best, lowest))
}

/// The lanes set in `mask` (at least one, of four) ordered by `distance`,
/// farthest first, and how many there are: a traversal pushes all but the
/// last and goes on with the last, the nearest.
#[inline(always)]
pub(super) fn farthest_first(mut mask: u32, distance: [f32; 4]) -> ([usize; 4], usize) {
    let mut order = [0usize; 4];
    let mut n = 0;
    while mask != 0 {
        let lane = mask.trailing_zeros() as usize & 3;
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
    (order, n)
}

/// Box tests keep a box whose entry is up to this factor beyond the far end
/// of the interval (the box's exit or the best hit so far). The box and
/// sphere tests round differently, and a sphere touching its box's face can
/// compute a hit a few ulp before the box's computed entry: without the
/// margin, such a box could be culled when the best hit so far has the same
/// distance, and which of two tied spheres is found would depend on the order
/// of the visit. 2⁻¹² is far above those few ulp and costs no measurable
/// extra visits.
pub(super) const SLACK: f32 = 1.0 + 1.0 / 4096.0;
const SLACK4: Vec4 = Vec4::splat(SLACK);

/// `maxps` semantics on every architecture: `a` if `a > b`, else `b` (so `b`
/// when either is NaN). NEON's and the scalar fallback's `max` differ on NaN.
#[inline(always)]
fn max4(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        a.max(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::select(a.cmpgt(b), a, b)
    }
}

/// `minps` semantics on every architecture, as [`max4`].
#[inline(always)]
fn min4(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        a.min(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::select(a.cmplt(b), a, b)
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
            cx: [Vec4::ZERO; 2],
            cy: [Vec4::ZERO; 2],
            cz: [Vec4::ZERO; 2],
            radius2: [Vec4::NEG_INFINITY; 2],
            index: [NO_CHILD; 8],
        };
        let first = leaf.offset as usize;
        for lane in 0..leaf.count as usize {
            let index = self.order[first + lane];
            let s = &self.spheres[index as usize];
            let (half, sub) = (lane / 4, lane % 4);
            p.cx[half][sub] = s.center.x;
            p.cy[half][sub] = s.center.y;
            p.cz[half][sub] = s.center.z;
            p.radius2[half][sub] = s.radius * s.radius;
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
            // Exactly the same: among coincident spheres, the lowest index.
            assert_eq!(got, expected);
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
    #[cfg(target_arch = "x86_64")]
    fn avx2_and_four_lane_packet_tests_agree_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rng = Rng::new(11);
        // Leaves of 1 to 8 spheres in a small box, with duplicates (ties)
        // and rays from inside and outside, so every branch is taken.
        let mut spheres = random_spheres(&mut rng, 300, 3.0);
        spheres.extend_from_within(..40);
        let bvh = Bvh::new(&spheres);
        let mut hits = 0;
        for _ in 0..20_000 {
            let origin = Vec3::new(
                rng.range_f32(-6.0, 6.0),
                rng.range_f32(-6.0, 6.0),
                rng.range_f32(-6.0, 6.0),
            );
            let d = crate::sampling::unit_vector(&mut rng);
            let interval = Interval::new(0.001, rng.range_f32(0.5, 20.0));
            let ray = SphereRay::new(&Ray::new(origin, d), interval, true);
            for p in &bvh.packets {
                let halves = ray.hit_packet_halves(p, interval.max, 0);
                // SAFETY: AVX2 was detected above.
                #[allow(unsafe_code)]
                let wide = unsafe { ray.hit_packet_avx2(p, interval.max, 0) };
                let bits = |h: Option<(f32, u32)>| h.map(|(t, i)| (t.to_bits(), i));
                assert_eq!(bits(halves), bits(wide));
                hits += usize::from(wide.is_some());
            }
        }
        assert!(
            hits > 1000,
            "only {hits} packet hits: the test exercises too little"
        );
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
