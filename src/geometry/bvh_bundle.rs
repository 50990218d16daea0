//! Bundles of up to eight rays traced through the BVH together: the camera
//! rays of one pixel, or the bounces of a round of its paths.
//!
//! Single-ray traversal ([`Bvh::hit`]) is bound by latency: each box and
//! primitive test waits for the one before. The camera rays of one pixel start
//! within the lens and pass within one pixel of each other, so they visit
//! nearly the same nodes; the bounces of one pixel's paths start close
//! together, and many of them leave the scene at once. A bundle visits each
//! node once for all its rays, testing the eight rays against one box (or
//! one primitive) as eight independent lanes: the work per ray is about the
//! same, but it is spread over SIMD lanes and independent chains instead of
//! one long chain.
//!
//! The lanes are plain `[f32; 8]` arrays processed by simple loops, which the
//! compiler turns into 8-wide (AVX2) or 2×4-wide (SSE2, NEON) vector code in
//! each instruction-set version of the render loop. The box test performs
//! the operations of [`Bvh::hit`]'s, and each primitive is tested by the same
//! kernel on the same numbers, so a bundle finds bit for bit the same
//! distances as tracing its rays one at a time; a lane tests a leaf's
//! primitives only when its own ray enters the leaf's box, as it would alone.
//!
//! When every ray of a bundle meets each box's planes in the same order
//! and has the same triangle axes (a pixel's camera rays, nearly always),
//! the eight-wide box test and the triangle test take the shared order
//! once instead of choosing per lane: the same operations on the same
//! numbers, so the same bits.
//!
//! Children are visited in the order of a *reference* ray given by the
//! caller (the pixel's central ray, say), near to the bundle's rays. The order
//! only affects speed: each lane's result, like [`Bvh::hit`]'s, is the first
//! hit in the order of distance then primitive index, and boxes are kept with a
//! margin over the rounding of their tests (`bvh::SLACK`), so the result
//! does not depend on the order of the visit, nor on the other rays of the
//! bundle.

use super::bvh::{
    comes_before, leaf_parts, Bvh, Enter, Hit, InstancePacket, Node, Node8, Nodes, QuadPacket,
    QuadricPacket, Rays, SpherePacket, TrianglePacket, NO_CHILD, SLACK,
};
use crate::geometry::primitive::Kind;
use crate::geometry::quad;
use crate::geometry::sphere;
use crate::geometry::triangle::{self, TriangleLanes, TriangleRay};
use crate::lanes::{map3, Wide, F8};
use crate::math::Interval;
use crate::ray::{Ray, RayLanes};
use glam::Vec4;

/// Rays in a bundle.
pub const LANES: usize = crate::lanes::LANES;

type Lanes = [f32; LANES];

/// Up to [`LANES`] rays, structure of arrays. Lanes beyond
/// [`RayBundle::len`] repeat the first ray and are never reported.
#[derive(Clone, Copy, Debug)]
pub struct RayBundle {
    origin: [Lanes; 3],
    direction: [Lanes; 3],
    inverse: [Lanes; 3],
    /// Each ray's time in the shutter interval (for moving instances).
    time: Lanes,
    len: usize,
}

impl RayBundle {
    /// The bundle of `rays` (1 to [`LANES`] of them, unit-length directions).
    ///
    /// # Panics
    /// When `rays` is empty or longer than [`LANES`].
    #[inline]
    pub fn new(rays: &[Ray]) -> Self {
        const ALL: [u8; LANES] = [0, 1, 2, 3, 4, 5, 6, 7];
        assert!(
            rays.len() <= LANES,
            "a bundle holds 1 to {LANES} rays, not {}",
            rays.len()
        );
        Self::gather(rays, &ALL[..rays.len()])
    }

    /// The bundle of `rays[lanes[0]]`, `rays[lanes[1]]`, …: gathered straight
    /// into structure of arrays, without copying the rays out first.
    ///
    /// # Panics
    /// When `lanes` is empty or longer than [`LANES`], or names a ray
    /// `rays` does not have.
    #[inline]
    pub fn gather(rays: &[Ray], lanes: &[u8]) -> Self {
        assert!(
            (1..=LANES).contains(&lanes.len()),
            "a bundle holds 1 to {LANES} rays, not {}",
            lanes.len()
        );
        let mut b = RayBundle {
            origin: [[0.0; LANES]; 3],
            direction: [[0.0; LANES]; 3],
            inverse: [[0.0; LANES]; 3],
            time: [0.0; LANES],
            len: lanes.len(),
        };
        for lane in 0..LANES {
            let ray = &rays[usize::from(*lanes.get(lane).unwrap_or(&lanes[0]))];
            debug_assert!((ray.direction.length_squared() - 1.0).abs() < 1e-4);
            let inverse = ray.direction.recip();
            b.time[lane] = ray.time();
            for axis in 0..3 {
                b.origin[axis][lane] = ray.origin()[axis];
                b.direction[axis][lane] = ray.direction[axis];
                b.inverse[axis][lane] = inverse[axis];
            }
        }
        b
    }

    /// Number of rays in the bundle.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the bundle holds no rays (never: [`RayBundle::new`] refuses).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The ray of lane `lane`.
    #[inline(always)]
    pub fn ray(&self, lane: usize) -> Ray {
        let o = self.origin.map(|c| c[lane]);
        let d = self.direction.map(|c| c[lane]);
        Ray::timed(o.into(), d.into(), self.time[lane])
    }
}

/// `maxps` semantics: the second operand when either is NaN, so a NaN bound
/// given first never decides (as in [`Bvh::hit`]).
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `minps` semantics, as [`max_ps`].
#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

impl Bvh {
    /// The nearest primitive hit by each ray of `rays` within `interval`, in
    /// the bundle's order (`None` beyond its length). Each distance is the
    /// one [`Bvh::hit`] finds for that ray. `reference` orders the visit of
    /// children (see the module documentation); any ray close to the
    /// bundle's rays makes a good reference. Faster than single rays when
    /// the rays are close (a pixel's camera rays), or on trees of spheres
    /// only (see [`Bvh::spheres_only`]) for any rays.
    #[inline(always)]
    pub fn hit_bundle(
        &self,
        rays: &RayBundle,
        reference: &Ray,
        interval: Interval,
    ) -> [Option<Hit>; LANES] {
        // As for single rays: a tree of spheres only gets a loop without
        // the other kinds' tests.
        let (closest, best, sub) = if self.spheres_only() {
            let mut query = BundleRays::<true>::new(self, rays, reference, interval);
            if let Nodes::Four(nodes) = self.nodes() {
                self.traverse(nodes, &mut query);
            }
            (query.closest, query.best, query.best_subs())
        } else {
            let mut query = BundleRays::<false>::new(self, rays, reference, interval);
            match self.nodes() {
                Nodes::Four(nodes) => self.traverse(nodes, &mut query),
                Nodes::Eight(nodes) => self.traverse(nodes, &mut query),
            }
            (query.closest, query.best, query.best_subs())
        };
        let mut hits = [None; LANES];
        for lane in 0..rays.len {
            if closest[lane] < interval.max {
                hits[lane] = Some(Hit {
                    t: closest[lane],
                    index: best[lane],
                    sub: sub[lane],
                });
            }
        }
        hits
    }
}

/// A bundle's rays, with what the box and leaf tests need of them.
struct BundleRays<'a, const SPHERES: bool> {
    rays: &'a RayBundle,
    t_min: f32,
    /// Per lane and axis: whether the upper plane is met first.
    flip: [[bool; LANES]; 3],
    /// The reference ray's slab test, only to order children.
    ref_near: [usize; 3],
    ref_origin: [Vec4; 3],
    ref_inv: [Vec4; 3],
    /// Only prepared when the tree holds triangles: each ray in its own axes
    /// (see [`TriangleRay`]), lane by lane, and per permuted axis, the lanes
    /// (as bits) for which it is x, and those for which it is y (else z).
    triangle: TriangleRay<Lanes>,
    is_axis: [[u32; 2]; 3],
    /// When every lane's ray goes the same way along each axis (a pixel's
    /// camera rays, nearly always): per axis, whether the upper plane is
    /// met first, for all; the box test then makes no choice per lane.
    shared_flip: Option<[bool; 3]>,
    /// When every lane's ray has the same triangle axes: those, so that a
    /// triangle's vertices are permuted once for all lanes.
    shared_axes: Option<[usize; 3]>,
    /// Whether the processor has AVX2 (asked once, by the tree).
    avx2: bool,
    /// Per lane, the best hit so far as in `Bvh::hit`: (distance, index),
    /// starting from (interval.max, 0). Unused lanes start at −∞, so that
    /// they never enter a box or accept a primitive.
    closest: Lanes,
    best: [u32; LANES],
    /// Per lane, the instance the last hit inside an instance was on, and
    /// (`sub`) the primitive inside it: `best`'s sub-item when `best` is
    /// that instance, none otherwise (kept apart so that the packets' hot
    /// loop need not clear it).
    sub_owner: [u32; LANES],
    sub: [u32; LANES],
}

impl<'a, const SPHERES: bool> BundleRays<'a, SPHERES> {
    /// Per lane, the sub-item of the best hit (0 for a hit outside
    /// instances).
    fn best_subs(&self) -> [u32; LANES] {
        std::array::from_fn(|l| {
            if self.sub_owner[l] == self.best[l] {
                self.sub[l]
            } else {
                0
            }
        })
    }

    #[inline(always)]
    fn new(bvh: &Bvh, rays: &'a RayBundle, reference: &Ray, interval: Interval) -> Self {
        let ref_inv = reference.direction.recip();
        let mut closest = [f32::NEG_INFINITY; LANES];
        closest[..rays.len].fill(interval.max);
        let mut triangle = TriangleRay {
            origin: [[0.0; LANES]; 3],
            shear: [[0.0; LANES]; 3],
            t_min: [interval.min; LANES],
            origin2: [0.0; LANES],
        };
        let mut is_axis = [[0; 2]; 3];
        let mut shared_axes = None;
        if !SPHERES && bvh.has_triangles() {
            for lane in 0..LANES {
                let ray = rays.ray(lane);
                let axes = TriangleRay::axes_of(ray.direction);
                let r = TriangleRay::new(&ray, axes, interval.min);
                triangle.origin2[lane] = r.origin2;
                for k in 0..3 {
                    triangle.origin[k][lane] = r.origin[k];
                    triangle.shear[k][lane] = r.shear[k];
                    is_axis[k][0] |= u32::from(axes[k] == 0) << lane;
                    is_axis[k][1] |= u32::from(axes[k] == 1) << lane;
                }
            }
            const ALL: u32 = (1 << LANES) - 1;
            if is_axis
                .iter()
                .flatten()
                .all(|&bits| bits == 0 || bits == ALL)
            {
                shared_axes = Some(std::array::from_fn(|k| match is_axis[k] {
                    [ALL, _] => 0,
                    [_, ALL] => 1,
                    _ => 2,
                }));
            }
        }
        let flip: [[bool; LANES]; 3] =
            std::array::from_fn(|axis| std::array::from_fn(|l| rays.inverse[axis][l] < 0.0));
        // Only eight-wide nodes use it, and a tree of spheres only has none.
        let shared_flip = (!SPHERES
            && flip
                .iter()
                .all(|lanes| lanes.iter().all(|&f| f == lanes[0])))
        .then(|| flip.map(|lanes| lanes[0]));
        BundleRays {
            rays,
            t_min: interval.min,
            flip,
            ref_near: [
                usize::from(ref_inv.x < 0.0),
                usize::from(ref_inv.y < 0.0),
                usize::from(ref_inv.z < 0.0),
            ],
            ref_origin: reference.origin().to_array().map(Vec4::splat),
            ref_inv: ref_inv.to_array().map(Vec4::splat),
            triangle,
            is_axis,
            shared_flip,
            shared_axes,
            avx2: bvh.avx2(),
            closest,
            best: [0; LANES],
            sub_owner: [NO_CHILD; LANES],
            sub: [0; LANES],
        }
    }

    /// Takes in one primitive's distances `t` to the rays (valid where
    /// `valid`; only the lanes that `enter` its leaf count): per lane the
    /// first in the order of distance then index, as `Bvh::hit` keeps.
    #[inline(always)]
    fn found<R: Wide>(
        &mut self,
        closest: &mut R,
        t: R,
        valid: R::Mask,
        enter: R::Mask,
        index: u32,
    ) {
        let valid = valid & enter;
        let hit = valid & t.lt(*closest);
        let mut take = R::bits(hit);
        // Exactly as near as the best (coincident surfaces): the lower index
        // wins.
        let mut tie = R::bits(valid & t.eq(*closest));
        while tie != 0 {
            let l = tie.trailing_zeros() as usize;
            take |= u32::from(index < self.best[l]) << l;
            tie &= tie - 1;
        }
        *closest = R::select(hit, t, *closest);
        // Without a branch per taking lane: which lanes take is unpredictable.
        for l in 0..LANES {
            self.best[l] = if take >> l & 1 != 0 {
                index
            } else {
                self.best[l]
            };
        }
    }

    /// Where the lanes that enter a leaf's box at `entry` are set: only
    /// those test its primitives, as each ray alone would test them only
    /// then.
    #[inline(always)]
    fn entering<R: Wide>(&self, entry: &Lanes) -> R::Mask {
        R::from_array(*entry).le(R::from_array(self.closest) * R::splat(SLACK))
    }

    /// The bundle's rays on lanes `R`.
    #[inline(always)]
    fn ray_lanes<R: Wide>(&self) -> RayLanes<R> {
        RayLanes {
            origin: map3(&self.rays.origin, R::from_array),
            direction: map3(&self.rays.direction, R::from_array),
            t_min: R::splat(self.t_min),
        }
    }

    /// Tests every ray of the bundle that enters the leaf's box at `entry`
    /// against the primitives `index` of a packet one by one, on lanes `R`:
    /// `test(s)` gives the distances of the rays to primitive `s`, with the
    /// kernel the single-ray packet test runs (so the same distances).
    #[inline(always)]
    fn one_by_one<R: Wide>(
        &mut self,
        index: &[u32; 8],
        entry: &Lanes,
        test: impl Fn(usize) -> (R, R::Mask),
    ) {
        let enter = self.entering::<R>(entry);
        let mut closest = R::from_array(self.closest);
        for (s, &primitive) in index.iter().enumerate() {
            if primitive == NO_CHILD {
                break;
            }
            let (t, valid) = test(s);
            self.found(&mut closest, t, valid, enter, primitive);
        }
        self.closest = closest.to_array();
    }

    /// The spheres of `p` against the bundle (see [`Self::one_by_one`]).
    /// Each kind is its own function so that the AVX2 version of each stays
    /// small enough to be inlined into the render loop.
    #[inline(always)]
    fn spheres<R: Wide>(&mut self, p: &SpherePacket, entry: &Lanes) {
        let ray = self.ray_lanes::<R>();
        self.one_by_one(&p.index, entry, |s| {
            sphere::intersect_with::<R, false>(&ray, &p.splat(s))
        });
    }

    /// The triangles of `p` against the bundle, each triangle's vertices
    /// permuted into every ray's own axes.
    #[inline(always)]
    fn triangles<R: Wide>(&mut self, p: &TrianglePacket, entry: &Lanes) {
        let triangle = TriangleRay {
            origin: map3(&self.triangle.origin, R::from_array),
            shear: map3(&self.triangle.shear, R::from_array),
            t_min: R::from_array(self.triangle.t_min),
            origin2: R::from_array(self.triangle.origin2),
        };
        let is_axis = [0, 1, 2].map(|a| {
            let [x, y] = self.is_axis[a];
            (R::mask_from_bits(x), R::mask_from_bits(y))
        });
        // Written out rather than through `one_by_one`: a closure this large
        // is not inlined, and the vector operations in it, compiled outside
        // the AVX2 context, would each be a call.
        let enter = self.entering::<R>(entry);
        let mut closest = R::from_array(self.closest);
        for (s, &primitive) in p.index.iter().enumerate() {
            if primitive == NO_CHILD {
                break;
            }
            let tri = match self.shared_axes {
                Some(axes) => TriangleLanes {
                    vertices: [
                        shared(&p.vertices[0], s, axes),
                        shared(&p.vertices[1], s, axes),
                        shared(&p.vertices[2], s, axes),
                    ],
                },
                None => TriangleLanes {
                    vertices: [
                        permuted(&p.vertices[0], s, &is_axis),
                        permuted(&p.vertices[1], s, &is_axis),
                        permuted(&p.vertices[2], s, &is_axis),
                    ],
                },
            };
            let (t, valid) = triangle::intersect(&triangle, &tri);
            self.found(&mut closest, t, valid, enter, primitive);
        }
        self.closest = closest.to_array();
    }

    /// The quads of `p` against the bundle.
    #[inline(always)]
    fn quads<R: Wide>(&mut self, p: &QuadPacket, entry: &Lanes) {
        let ray = self.ray_lanes::<R>();
        self.one_by_one(&p.index, entry, |s| quad::intersect(&ray, &p.splat(s)));
    }
}

/// Vertex `v` of primitive `s` of a packet in every lane's own axes
/// (`is_axis`: per axis of the lane's frame, whether it is the world's x,
/// or else y, or else z).
#[inline(always)]
fn permuted<R: Wide>(v: &[[f32; LANES]; 3], s: usize, is_axis: &[(R::Mask, R::Mask); 3]) -> [R; 3] {
    let (x, y, z) = (R::splat(v[0][s]), R::splat(v[1][s]), R::splat(v[2][s]));
    [
        R::select(is_axis[0].0, x, R::select(is_axis[0].1, y, z)),
        R::select(is_axis[1].0, x, R::select(is_axis[1].1, y, z)),
        R::select(is_axis[2].0, x, R::select(is_axis[2].1, y, z)),
    ]
}

/// Vertex `v` of primitive `s` of a packet in the axes `axes` every lane
/// shares: what [`permuted`] gives then, without a choice per lane.
#[inline(always)]
fn shared<R: Wide>(v: &[[f32; LANES]; 3], s: usize, axes: [usize; 3]) -> [R; 3] {
    [
        R::splat(v[axes[0]][s]),
        R::splat(v[axes[1]][s]),
        R::splat(v[axes[2]][s]),
    ]
}

impl<const SPHERES: bool> BundleRays<'_, SPHERES> {
    /// The instances of packet `p` for the lanes of `enter` (bits), one ray
    /// at a time, keeping per lane the first hit in the order (distance,
    /// index) as `Bvh::hit` does.
    #[inline(never)]
    fn instances(&mut self, bvh: &Bvh, p: &InstancePacket, mut enter: u32) {
        while enter != 0 {
            let l = enter.trailing_zeros() as usize;
            enter &= enter - 1;
            let ray = self.rays.ray(l);
            for s in 0..LANES {
                let index = p.index[s];
                if index == NO_CHILD {
                    break;
                }
                let instance = &bvh.instances()[p.instance[s] as usize];
                if let Some((t, sub)) = instance.hit(&ray, self.t_min, self.closest[l]) {
                    if comes_before((t, index), (self.closest[l], self.best[l])) {
                        (self.closest[l], self.best[l]) = (t, index);
                        (self.sub_owner[l], self.sub[l]) = (index, sub);
                    }
                }
            }
        }
    }

    /// The disks and cylinders of packet `p` for the lanes of `enter`
    /// (bits), one ray and one shape at a time, as `Bvh::hit` tests them.
    #[inline(never)]
    fn quadrics(&mut self, p: &QuadricPacket, mut enter: u32) {
        while enter != 0 {
            let l = enter.trailing_zeros() as usize;
            enter &= enter - 1;
            let ray = self.rays.ray(l);
            for (t, index) in p.hits(&ray, self.t_min) {
                if comes_before((t, index), (self.closest[l], self.best[l])) {
                    (self.closest[l], self.best[l]) = (t, index);
                }
            }
        }
    }
}

/// The leaf tests of [`BundleRays`] on AVX lanes, each compiled for AVX2
/// and small enough to be inlined into the AVX2 render loop.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod bundle_avx2 {
    use super::{BundleRays, Lanes};
    use crate::geometry::bvh::{Node8, QuadPacket, SpherePacket, TrianglePacket};
    use crate::lanes::W8;

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn boxes8<const S: bool>(
        r: &BundleRays<S>,
        node: &Node8,
        flip: [bool; 3],
    ) -> (u32, [Lanes; 8]) {
        r.boxes8_shared::<W8>(node, flip)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn spheres<const S: bool>(
        r: &mut BundleRays<S>,
        p: &SpherePacket,
        entry: &Lanes,
    ) {
        r.spheres::<W8>(p, entry)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn triangles<const S: bool>(
        r: &mut BundleRays<S>,
        p: &TrianglePacket,
        entry: &Lanes,
    ) {
        r.triangles::<W8>(p, entry)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn quads<const S: bool>(
        r: &mut BundleRays<S>,
        p: &QuadPacket,
        entry: &Lanes,
    ) {
        r.quads::<W8>(p, entry)
    }
}

impl<const SPHERES: bool> BundleRays<'_, SPHERES> {
    /// The slab tests of every ray against the `W` boxes of `planes` (those
    /// set in `used`): the boxes some ray enters before its best hit so far
    /// (bit per box), and per box where each ray enters it.
    #[inline(always)]
    fn boxes<const W: usize>(&self, bounds: &[[[f32; W]; 2]; 3], used: u32) -> (u32, [Lanes; W]) {
        let rays = self.rays;
        let mut t_near = [[f32::NAN; LANES]; W];
        let mut hit_mask = 0u32;
        for child in 0..W {
            if used & (1 << child) == 0 {
                continue;
            }
            let mut any = false;
            let planes: [[f32; 2]; 3] =
                std::array::from_fn(|axis| [bounds[axis][0][child], bounds[axis][1][child]]);
            let (tn, closest) = (&mut t_near[child], &self.closest);
            for l in 0..LANES {
                let slab = |axis: usize| {
                    let (lo, hi) = (planes[axis][0], planes[axis][1]);
                    let (n, f) = if self.flip[axis][l] {
                        (hi, lo)
                    } else {
                        (lo, hi)
                    };
                    let o = rays.origin[axis][l];
                    let inv = rays.inverse[axis][l];
                    ((n - o) * inv, (f - o) * inv)
                };
                let (x0, x1) = slab(0);
                let (y0, y1) = slab(1);
                let (z0, z1) = slab(2);
                let near = max_ps(max_ps(max_ps(x0, y0), z0), self.t_min);
                let far = min_ps(min_ps(min_ps(x1, y1), z1), closest[l]) * SLACK;
                let hit = near <= far;
                tn[l] = if hit { near } else { f32::NAN };
                any |= hit;
            }
            hit_mask |= u32::from(any) << child;
        }
        (hit_mask, t_near)
    }

    /// [`Self::boxes`] of an eight-wide node on lanes `R`, for rays that
    /// all meet the planes in the order `flip` (per axis, upper first):
    /// the same operations on the same numbers, one box for every lane at
    /// once.
    #[inline(always)]
    fn boxes8_shared<R: Wide>(&self, node: &Node8, flip: [bool; 3]) -> (u32, [Lanes; 8]) {
        let rays = self.rays;
        let origin = map3(&rays.origin, R::from_array);
        let inverse = map3(&rays.inverse, R::from_array);
        let closest = R::from_array(self.closest);
        let (t_min, slack, nan) = (R::splat(self.t_min), R::splat(SLACK), R::splat(f32::NAN));
        let sides = flip.map(|upper| if upper { (1, 0) } else { (0, 1) });
        let mut t_near = [[0.0; LANES]; 8];
        let mut hit_mask = 0u32;
        let planes = &node.planes;
        // Without a branch per child: an unused slot's box is empty, so no
        // lane enters it, and its bit is cleared by `used` besides.
        for child in 0..8 {
            let x0 = (R::splat(planes[0][sides[0].0][child]) - origin[0]) * inverse[0];
            let x1 = (R::splat(planes[0][sides[0].1][child]) - origin[0]) * inverse[0];
            let y0 = (R::splat(planes[1][sides[1].0][child]) - origin[1]) * inverse[1];
            let y1 = (R::splat(planes[1][sides[1].1][child]) - origin[1]) * inverse[1];
            let z0 = (R::splat(planes[2][sides[2].0][child]) - origin[2]) * inverse[2];
            let z1 = (R::splat(planes[2][sides[2].1][child]) - origin[2]) * inverse[2];
            let near = x0.max_ps(y0).max_ps(z0).max_ps(t_min);
            let far = x1.min_ps(y1).min_ps(z1).min_ps(closest) * slack;
            let hit = near.le(far);
            hit_mask |= u32::from(R::bits(hit) != 0) << child;
            t_near[child] = R::select(hit, near, nan).to_array();
        }
        (hit_mask & node.used, t_near)
    }

    /// Where the reference ray meets four boxes, given as their planes.
    #[inline(always)]
    fn reference_entries(&self, p: &[[Vec4; 2]; 3]) -> Vec4 {
        let near = &self.ref_near;
        let (o, inv) = (&self.ref_origin, &self.ref_inv);
        let rx = (p[0][near[0]] - o[0]) * inv[0];
        let ry = (p[1][near[1]] - o[1]) * inv[1];
        let rz = (p[2][near[2]] - o[2]) * inv[2];
        rx.max(ry).max(rz).max(Vec4::splat(self.t_min))
    }
}

impl<const SPHERES: bool> Enter<Node> for BundleRays<'_, SPHERES> {
    type Entries = [Lanes; 4];
    type Order = [f32; 4];

    #[inline(always)]
    fn enter(&self, node: &Node) -> (u32, [Lanes; 4]) {
        // As arrays: indexing a `Vec4` by a variable lane compiles to a jump.
        self.boxes(
            &node.planes.map(|pair| pair.map(|v| v.to_array())),
            node.used,
        )
    }

    /// Where the reference ray meets the boxes.
    #[inline(always)]
    fn order(&self, node: &Node, _: &[Lanes; 4]) -> [f32; 4] {
        self.reference_entries(&node.planes).to_array()
    }
}

impl<const SPHERES: bool> Enter<Node8> for BundleRays<'_, SPHERES> {
    type Entries = [Lanes; 8];
    type Order = [f32; 8];

    #[inline(always)]
    fn enter(&self, node: &Node8) -> (u32, [Lanes; 8]) {
        let Some(flip) = self.shared_flip else {
            return self.boxes(&node.planes, node.used);
        };
        // SAFETY: `avx2` is true only when `Isa::detect` found AVX2.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        if self.avx2 {
            return unsafe { bundle_avx2::boxes8(self, node, flip) };
        }
        self.boxes8_shared::<F8>(node, flip)
    }

    /// Where the reference ray meets the boxes, four at a time.
    #[inline(always)]
    fn order(&self, node: &Node8, _: &[Lanes; 8]) -> [f32; 8] {
        let half = |h: usize| {
            self.reference_entries(
                &node
                    .planes
                    .map(|pair| pair.map(|lanes| Vec4::from_slice(&lanes[4 * h..4 * h + 4]))),
            )
        };
        let mut order = [0.0; 8];
        half(0).write_to_slice(&mut order[..4]);
        half(1).write_to_slice(&mut order[4..]);
        order
    }
}

impl<const SPHERES: bool> Rays for BundleRays<'_, SPHERES> {
    /// Per lane, where the ray enters the box (NaN for lanes that miss it,
    /// which no comparison accepts).
    type Entry = Lanes;

    #[inline(always)]
    fn needed(&self, t_near: &Lanes) -> bool {
        let (mut needed, closest) = (false, &self.closest);
        for l in 0..LANES {
            needed |= t_near[l] <= closest[l] * SLACK;
        }
        needed
    }

    #[inline(always)]
    fn leaf(&mut self, bvh: &Bvh, leaf: u32, entry: &Lanes) -> bool {
        let (kind, i) = leaf_parts(leaf);
        let kind = if SPHERES { Kind::Sphere } else { kind };
        if kind >= Kind::Instance {
            let enter = F8::bits(self.entering::<F8>(entry));
            if kind == Kind::Instance {
                self.instances(bvh, bvh.instance_packet(i), enter);
            } else {
                self.quadrics(bvh.quadric_packet(i), enter);
            }
            return false;
        }
        // SAFETY (the AVX2 calls): `avx2` is true only when `Isa::detect`
        // found AVX2.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        if bvh.avx2() {
            match kind {
                Kind::Sphere => unsafe { bundle_avx2::spheres(self, bvh.sphere_packet(i), entry) },
                Kind::Triangle => unsafe {
                    bundle_avx2::triangles(self, bvh.triangle_packet(i), entry)
                },
                _ => unsafe { bundle_avx2::quads(self, bvh.quad_packet(i), entry) },
            }
            return false;
        }
        match kind {
            Kind::Sphere => self.spheres::<F8>(bvh.sphere_packet(i), entry),
            Kind::Triangle => self.triangles::<F8>(bvh.triangle_packet(i), entry),
            _ => self.quads::<F8>(bvh.quad_packet(i), entry),
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Primitive, Quad, Sphere, Triangle};
    use crate::math::Vec3;
    use crate::rng::Rng;

    fn tree(spheres: &[Sphere]) -> Bvh {
        let prims: Vec<Primitive> = spheres.iter().map(|&s| Primitive::Sphere(s)).collect();
        Bvh::new(&prims)
    }

    /// Bundles of nearly parallel rays (as a pixel's camera rays) and of
    /// unrelated rays, of every length, through a sphere field: every lane
    /// must find exactly what `Bvh::hit` finds for its ray alone.
    #[test]
    fn bundles_find_exactly_what_single_rays_find() {
        bundles_agree_with_single_rays(false);
    }

    /// The same with triangles (a bundle's rays each in their own axes) and
    /// quads among the spheres, including a closed triangulated terrain
    /// whose shared edges and vertices tie.
    #[test]
    fn bundles_over_mixed_kinds_find_exactly_what_single_rays_find() {
        bundles_agree_with_single_rays(true);
    }

    #[test]
    fn bundles_among_instances_find_what_single_rays_find_with_their_sub_items() {
        let mut rng = Rng::new(43);
        let (bvh, _) = crate::geometry::bvh::tests::shapes_among_instances(&mut rng);
        let hits = bundles_match_single_rays(&bvh, &mut rng, Vec3::splat(-30.0), Vec3::splat(30.0));
        assert!(
            hits > 3000,
            "only {hits} hits: the test exercises too little"
        );
    }

    /// 400 spheres on a ground sphere, or (`mixed`) 200 of them among a
    /// triangulated terrain, quads and a floor of triangles far larger than
    /// the view.
    fn primitives(rng: &mut Rng, mixed: bool) -> Vec<Primitive> {
        let mut spheres: Vec<Sphere> = (0..400)
            .map(|_| {
                let c = Vec3::new(
                    rng.range_f32(-10.0, 10.0),
                    rng.range_f32(0.0, 1.0),
                    rng.range_f32(-10.0, 10.0),
                );
                Sphere::new(c, rng.range_f32(0.1, 0.5))
            })
            .collect();
        spheres.push(Sphere::new(Vec3::new(0.0, -1000.0, 0.0), 1000.0));
        let mut prims: Vec<Primitive> = spheres.iter().map(|&s| Primitive::Sphere(s)).collect();
        if mixed {
            prims.truncate(200);
            // A 20×20 height field of triangles over [-10, 10]², and boxes' faces.
            let height = |i: i32, j: i32| ((i * 7 + j * 13) % 5) as f32 * 0.1;
            let at = |i: i32, j: i32| Vec3::new(i as f32, height(i, j), j as f32);
            for i in -10..10 {
                for j in -10..10 {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    prims.push(Primitive::Triangle(Triangle::new(a, b, c)));
                    prims.push(Primitive::Triangle(Triangle::new(a, c, d)));
                }
            }
            for k in 0..30 {
                let c = Vec3::new(rng.range_f32(-8.0, 8.0), 0.5, rng.range_f32(-8.0, 8.0));
                let u = Vec3::new(rng.range_f32(0.2, 1.0), 0.0, k as f32 * 0.01);
                let v = Vec3::new(0.0, rng.range_f32(0.2, 1.0), 0.1);
                prims.push(Primitive::Quad(
                    Quad::new(c, u, v).expect("edges not parallel"),
                ));
            }
            // Below it all a floor far larger than the view, whose hits'
            // distances are worked out again in f64, lane by lane.
            let s = 1e8;
            let corner = |x: f32, z: f32| Vec3::new(x * s, -0.5, z * s);
            let (a, b, c, d) = (
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            );
            prims.push(Primitive::Triangle(Triangle::new(a, d, c)));
            prims.push(Primitive::Triangle(Triangle::new(a, c, b)));
        }
        prims
    }

    /// Up to `n` rays from near `origin` toward near `toward` (`coherent`, as
    /// a pixel's camera rays), or from `origin` in any direction.
    fn bundle_rays(
        rng: &mut Rng,
        n: usize,
        origin: Vec3,
        toward: Vec3,
        coherent: bool,
    ) -> Vec<Ray> {
        (0..n)
            .map(|_| {
                if coherent {
                    let jitter = crate::sampling::in_unit_sphere(rng) * 0.05;
                    let o = origin + jitter;
                    let target = toward + crate::sampling::in_unit_sphere(rng) * 0.05;
                    Ray::new(o, (target - o).normalize())
                } else {
                    Ray::new(origin, crate::sampling::unit_vector(rng.next_2d()))
                }
            })
            .collect()
    }

    /// For rays that meet every box's planes in the same order and share
    /// their triangle axes (a pixel's camera rays, nearly always), the box
    /// test of an eight-wide node and the triangle test skip the choices per
    /// lane: on portable and on AVX2 lanes they give bit for bit what the
    /// general tests give, on every node and triangle packet of a mesh's tree.
    #[test]
    fn shared_order_tests_equal_the_general_ones() {
        let mut rng = Rng::new(5);
        let bvh = Bvh::new(&primitives(&mut rng, true));
        let Nodes::Eight(nodes) = bvh.nodes() else {
            panic!("a tree with triangles is eight-wide")
        };
        let interval = Interval::new(0.001, f32::INFINITY);
        let (mut shared_flips, mut shared_axes) = (0, 0);
        for case in 0..200 {
            let origin = Vec3::new(rng.range_f32(-15.0, 15.0), 2.0, rng.range_f32(-15.0, 15.0));
            let toward = Vec3::new(rng.range_f32(-5.0, 5.0), 0.0, rng.range_f32(-5.0, 5.0));
            let rays = bundle_rays(&mut rng, 1 + case % LANES, origin, toward, true);
            let bundle = RayBundle::new(&rays);
            let reference = Ray::new(origin, (toward - origin).normalize());
            let mut q = BundleRays::<false>::new(&bvh, &bundle, &reference, interval);
            // Some lanes with a best hit already, as deeper in a traversal.
            for (l, c) in q.closest.iter_mut().enumerate().take(bundle.len()) {
                if l % 3 == 1 {
                    *c = rng.range_f32(1.0, 30.0);
                }
            }
            let bits = |(mask, t): (u32, [Lanes; 8])| (mask, t.map(|l| l.map(f32::to_bits)));
            if let Some(flip) = q.shared_flip {
                shared_flips += 1;
                for node in nodes {
                    let general = bits(q.boxes(&node.planes, node.used));
                    assert_eq!(bits(q.boxes8_shared::<F8>(node, flip)), general);
                    #[cfg(target_arch = "x86_64")]
                    if q.avx2 {
                        // SAFETY: `avx2` is true only when the processor has AVX2.
                        #[allow(unsafe_code)]
                        let avx2 = unsafe { bundle_avx2::boxes8(&q, node, flip) };
                        assert_eq!(bits(avx2), general);
                    }
                }
            }
            if q.shared_axes.is_some() {
                shared_axes += 1;
                let entry = [0.0; LANES];
                let mut general = BundleRays {
                    shared_axes: None,
                    ..q
                };
                for i in 0..bvh.triangle_packets() {
                    let p = bvh.triangle_packet(i as u32);
                    general.triangles::<F8>(p, &entry);
                    let mut portable = BundleRays { ..q };
                    portable.triangles::<F8>(p, &entry);
                    #[cfg(target_arch = "x86_64")]
                    if q.avx2 {
                        let mut avx2 = BundleRays { ..q };
                        // SAFETY: as above.
                        #[allow(unsafe_code)]
                        unsafe {
                            bundle_avx2::triangles(&mut avx2, p, &entry)
                        };
                        assert_eq!(
                            avx2.closest.map(f32::to_bits),
                            general.closest.map(f32::to_bits)
                        );
                        assert_eq!(avx2.best, general.best);
                    }
                    assert_eq!(
                        portable.closest.map(f32::to_bits),
                        general.closest.map(f32::to_bits)
                    );
                    assert_eq!(portable.best, general.best);
                    q = BundleRays {
                        closest: general.closest,
                        best: general.best,
                        ..q
                    };
                }
            }
        }
        // Nearly every such bundle shares both.
        assert!(
            shared_flips > 180 && shared_axes > 180,
            "{shared_flips} {shared_axes}"
        );
    }

    fn bundles_agree_with_single_rays(mixed: bool) {
        let mut rng = Rng::new(21);
        let prims = primitives(&mut rng, mixed);
        let bvh = Bvh::new(&prims);
        let (low, high) = (Vec3::new(-15.0, 0.1, -15.0), Vec3::new(15.0, 3.0, 15.0));
        let hits = bundles_match_single_rays(&bvh, &mut rng, low, high);
        assert!(
            hits > 5000,
            "only {hits} hits: the test exercises too little"
        );
    }

    /// 3,000 bundles of 1 to 8 rays from origins in the box `low`–`high`
    /// (half of them coherent) find in `bvh` what each ray alone finds, to
    /// the bit and with its sub-item; returns how many rays hit.
    fn bundles_match_single_rays(bvh: &Bvh, rng: &mut Rng, low: Vec3, high: Vec3) -> usize {
        let interval = Interval::new(0.001, f32::INFINITY);
        let key = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.index, h.sub));
        let mut hits = 0;
        for case in 0..3000 {
            let n = 1 + case % LANES;
            let origin = Vec3::new(
                rng.range_f32(low.x, high.x),
                rng.range_f32(low.y, high.y),
                rng.range_f32(low.z, high.z),
            );
            let toward = Vec3::new(rng.range_f32(-5.0, 5.0), 0.0, rng.range_f32(-5.0, 5.0));
            let reference = Ray::new(origin, (toward - origin).normalize());
            let rays = bundle_rays(rng, n, origin, toward, case % 2 == 0);
            let got = bvh.hit_bundle(&RayBundle::new(&rays), &reference, interval);
            for (lane, ray) in rays.iter().enumerate() {
                let expected = bvh.hit(ray, interval);
                assert_eq!(key(got[lane]), key(expected), "case {case}, lane {lane}");
                hits += usize::from(expected.is_some());
            }
            assert!(
                got[n..].iter().all(Option::is_none),
                "unused lanes report nothing"
            );
        }
        hits
    }

    #[test]
    fn a_lane_does_not_depend_on_the_rest_of_its_bundle() {
        // Duplicated spheres in different leaves tie exactly: which one a ray
        // reports must not change with the rays beside it.
        let mut spheres = vec![Sphere::new(Vec3::ZERO, 1.0); 20];
        spheres.extend((0..20).map(|i| Sphere::new(Vec3::new(i as f32, 3.0, 0.0), 0.5)));
        let bvh = tree(&spheres);
        let interval = Interval::new(0.001, f32::INFINITY);
        let reference = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let mut rng = Rng::new(4);
        for _ in 0..200 {
            let rays: Vec<Ray> = (0..LANES)
                .map(|_| {
                    let o = Vec3::new(rng.range_f32(-0.5, 0.5), rng.range_f32(-0.5, 3.5), 5.0);
                    Ray::new(o, -Vec3::Z)
                })
                .collect();
            let all = bvh.hit_bundle(&RayBundle::new(&rays), &reference, interval);
            for (lane, ray) in rays.iter().enumerate() {
                let alone = bvh.hit_bundle(&RayBundle::new(&[*ray]), &reference, interval);
                let key = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.index));
                assert_eq!(key(all[lane]), key(alone[0]));
            }
        }
    }

    fn key(h: Option<Hit>) -> Option<(u32, u32)> {
        h.map(|h| (h.t.to_bits(), h.index))
    }

    /// A sphere touching its box's face computes a hit a rounding error
    /// before the box's computed entry: the tie with an identical sphere in
    /// another leaf must still go to the lower index, whatever the order.
    #[test]
    fn ties_at_a_box_face_go_to_the_lowest_index_in_any_order() {
        let c = Vec3::new(-0.79811573, 0.90824604, 1.9778109);
        let mut spheres = vec![Sphere::new(c, 1.8841038); 20];
        spheres.extend((0..20).map(|i| Sphere::new(Vec3::new(i as f32, 8.0, 0.0), 0.5)));
        let bvh = tree(&spheres);
        let interval = Interval::new(0.001, f32::INFINITY);
        let o = Vec3::new(10.488633, 1.1547536, 0.70374763);
        let ray = Ray::new(o, Vec3::new(-0.9906112, -0.025959643, 0.13422203));
        let box_entry = (c.x + 1.8841038 - o.x) * ray.direction.x.recip();
        let t = spheres[0].hit(&ray, interval).expect("hits");
        assert!(
            box_entry > t,
            "the case lost its point: entry {box_entry}, hit {t}"
        );
        assert_eq!(key(bvh.hit(&ray, interval)), Some((t.to_bits(), 0)));
        for reference in [
            ray,
            Ray::new(Vec3::Y * 20.0, -Vec3::Y),
            Ray::new(-Vec3::X * 10.0, Vec3::X),
        ] {
            let got = bvh.hit_bundle(&RayBundle::new(&[ray]), &reference, interval);
            assert_eq!(key(got[0]), Some((t.to_bits(), 0)));
        }
    }

    /// A ray grazing a sphere whose box test misses: alone it hits nothing,
    /// and it must not hit the sphere because another ray of its bundle
    /// enters the box.
    #[test]
    fn a_lane_missing_a_box_does_not_test_its_spheres() {
        let sphere = Sphere::new(Vec3::new(0.4491043, -1.872978, -2.6306076), 0.5630208);
        let bvh = tree(&[sphere]);
        let interval = Interval::new(0.001, f32::INFINITY);
        let o = Vec3::new(3.1213696, 33.058666, -3.1936314);
        let grazing = Ray::new(o, Vec3::new(-0.07628037, -0.99708647, 8.617153e-8));
        let through = Ray::new(o, (sphere.center - o).normalize());
        let alone = bvh.hit(&grazing, interval);
        let bundle = bvh.hit_bundle(&RayBundle::new(&[through, grazing]), &through, interval);
        assert!(bundle[0].is_some());
        assert_eq!(key(bundle[1]), key(alone));
    }

    #[test]
    fn empty_trees_and_short_bundles() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let all = Interval::new(0.0, f32::INFINITY);
        let bundle = RayBundle::new(&[ray]);
        assert!(Bvh::new(&[])
            .hit_bundle(&bundle, &ray, all)
            .iter()
            .all(Option::is_none));
        let one = tree(&[Sphere::new(Vec3::ZERO, 1.0)]);
        let hits = one.hit_bundle(&bundle, &ray, all);
        assert_eq!(hits[0].map(|h| (h.t, h.index)), Some((4.0, 0)));
        assert!(hits[1..].iter().all(Option::is_none));
    }
}
