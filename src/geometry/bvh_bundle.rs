//! Bundles of up to eight rays traced through the BVH together: the camera
//! rays of one pixel, or the bounces of a round of its paths.
//!
//! Single-ray traversal ([`Bvh::hit`]) is bound by latency: each box and
//! sphere test waits for the one before. The camera rays of one pixel start
//! within the lens and pass within one pixel of each other, so they visit
//! nearly the same nodes; the bounces of one pixel's paths start close
//! together, and many of them leave the scene at once. A bundle visits each
//! node once for all its rays, testing the eight rays against one box (or
//! one sphere) as eight independent lanes: the work per ray is about the
//! same, but it is spread over SIMD lanes and independent chains instead of
//! one long chain.
//!
//! The lanes are plain `[f32; 8]` arrays processed by simple loops, which the
//! compiler turns into 8-wide (AVX2) or 2×4-wide (SSE2, NEON) vector code in
//! each instruction-set version of the render loop. Every arithmetic
//! operation is the one [`Bvh::hit`] performs, in the same order, so a bundle
//! finds bit for bit the same distances as tracing its rays one at a time,
//! and a lane tests a leaf's spheres only when its own ray enters the leaf's
//! box, as it would alone.
//!
//! Children are visited in the order of a *reference* ray given by the
//! caller (the pixel's central ray, say), near to the bundle's rays. The order
//! only affects speed: each lane's result, like [`Bvh::hit`]'s, is the first
//! hit in the order of distance then sphere index, and boxes are kept with a
//! margin over the rounding of their tests (`bvh::SLACK`), so the result
//! does not depend on the order of the visit, nor on the other rays of the
//! bundle.

use super::bvh::{farthest_first, Bvh, Hit, LEAF_BIT, NO_CHILD, SLACK, STACK_SIZE};
use crate::math::Interval;
use crate::ray::Ray;
use glam::Vec4;
use std::mem::MaybeUninit;

/// Rays in a bundle.
pub const LANES: usize = 8;

type Lanes = [f32; LANES];

/// Up to [`LANES`] rays, structure of arrays. Lanes beyond
/// [`RayBundle::len`] repeat the first ray and are never reported.
#[derive(Clone, Copy, Debug)]
pub struct RayBundle {
    origin: [Lanes; 3],
    direction: [Lanes; 3],
    inverse: [Lanes; 3],
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
            len: lanes.len(),
        };
        for lane in 0..LANES {
            let ray = &rays[usize::from(*lanes.get(lane).unwrap_or(&lanes[0]))];
            debug_assert!((ray.direction.length_squared() - 1.0).abs() < 1e-4);
            let inverse = ray.direction.recip();
            for axis in 0..3 {
                b.origin[axis][lane] = ray.origin[axis];
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
    /// The nearest sphere hit by each ray of `rays` within `interval`, in the
    /// bundle's order (`None` beyond its length). Each distance is the one
    /// [`Bvh::hit`] finds for that ray. `reference` orders the visit of
    /// children (see the module documentation); any ray close to the
    /// bundle's rays makes a good reference.
    #[inline(always)]
    pub fn hit_bundle(
        &self,
        rays: &RayBundle,
        reference: &Ray,
        interval: Interval,
    ) -> [Option<Hit>; LANES] {
        // Per lane, the best hit so far as in `Bvh::hit`: (distance, index),
        // starting from (interval.max, 0). Unused lanes start at −∞, so that
        // they never enter a box or accept a sphere.
        let mut closest = [f32::NEG_INFINITY; LANES];
        closest[..rays.len].fill(interval.max);
        let mut best = [0; LANES];
        if !self.nodes_empty() {
            (closest, best) = self.traverse_bundle(rays, reference, interval.min, closest, best);
        }
        let mut hits = [None; LANES];
        for lane in 0..rays.len {
            if closest[lane] < interval.max {
                hits[lane] = Some(Hit {
                    t: closest[lane],
                    index: best[lane],
                });
            }
        }
        hits
    }

    #[inline(always)]
    fn traverse_bundle(
        &self,
        rays: &RayBundle,
        reference: &Ray,
        t_min: f32,
        mut closest: Lanes,
        mut best: [u32; LANES],
    ) -> (Lanes, [u32; LANES]) {
        // The best hits are passed by value, not by reference: in memory, the
        // compiler updates them with masked stores, and the next read stalls.
        // The reference ray's slab test, only to order children.
        let ref_inv = reference.direction.recip();
        let ref_near = [
            usize::from(ref_inv.x < 0.0),
            usize::from(ref_inv.y < 0.0),
            usize::from(ref_inv.z < 0.0),
        ];
        let ref_o = [
            Vec4::splat(reference.origin.x),
            Vec4::splat(reference.origin.y),
            Vec4::splat(reference.origin.z),
        ];
        let ref_inv4 = [
            Vec4::splat(ref_inv.x),
            Vec4::splat(ref_inv.y),
            Vec4::splat(ref_inv.z),
        ];
        // Per lane and axis: whether the upper plane is met first.
        let flip: [[bool; LANES]; 3] =
            std::array::from_fn(|axis| std::array::from_fn(|l| rays.inverse[axis][l] < 0.0));

        // Entries: a child and, per lane, where its box starts (NaN for lanes
        // that miss it, which no comparison accepts). Uninitialised, as in
        // `Bvh::hit`. `entry` is the same for `current`.
        let mut stack = [MaybeUninit::<(u32, Lanes)>::uninit(); STACK_SIZE];
        let mut top = 0usize;
        let mut current = 0u32;
        let mut entry = [f32::NAN; LANES];
        loop {
            if current & LEAF_BIT != 0 {
                // Only the lanes that enter the leaf's box test its spheres,
                // as each ray alone would.
                let mut enter = [false; LANES];
                for l in 0..LANES {
                    enter[l] = entry[l] <= closest[l] * SLACK;
                }
                (closest, best) =
                    self.bundle_leaf(current & !LEAF_BIT, rays, t_min, &enter, closest, best);
            } else {
                let node = self.node(current);
                // As arrays: indexing a `Vec4` by a variable lane compiles to a jump.
                let bounds = node.planes.map(|pair| pair.map(|v| v.to_array()));
                let mut t_near = [[f32::NAN; LANES]; 4];
                let mut hit_mask = 0u32;
                for child in 0..4 {
                    if node.used & (1 << child) == 0 {
                        continue;
                    }
                    let mut any = false;
                    let planes: [[f32; 2]; 3] = std::array::from_fn(|axis| {
                        [bounds[axis][0][child], bounds[axis][1][child]]
                    });
                    let tn = &mut t_near[child];
                    for l in 0..LANES {
                        let slab = |axis: usize| {
                            let (lo, hi) = (planes[axis][0], planes[axis][1]);
                            let (n, f) = if flip[axis][l] { (hi, lo) } else { (lo, hi) };
                            let o = rays.origin[axis][l];
                            let inv = rays.inverse[axis][l];
                            ((n - o) * inv, (f - o) * inv)
                        };
                        let (x0, x1) = slab(0);
                        let (y0, y1) = slab(1);
                        let (z0, z1) = slab(2);
                        let near = max_ps(max_ps(max_ps(x0, y0), z0), t_min);
                        let far = min_ps(min_ps(min_ps(x1, y1), z1), closest[l]) * SLACK;
                        let hit = near <= far;
                        tn[l] = if hit { near } else { f32::NAN };
                        any |= hit;
                    }
                    hit_mask |= u32::from(any) << child;
                }
                if hit_mask != 0 {
                    // Order the hit children by where the reference ray
                    // meets their boxes: push the farther ones, go on with
                    // the nearest.
                    let p = &node.planes;
                    let rx = (p[0][ref_near[0]] - ref_o[0]) * ref_inv4[0];
                    let ry = (p[1][ref_near[1]] - ref_o[1]) * ref_inv4[1];
                    let rz = (p[2][ref_near[2]] - ref_o[2]) * ref_inv4[2];
                    let distance = rx.max(ry).max(rz).max(Vec4::splat(t_min)).to_array();
                    let (order, n) = farthest_first(hit_mask, distance);
                    for &child in &order[..n - 1] {
                        stack[top].write((node.children[child], t_near[child]));
                        top += 1;
                    }
                    current = node.children[order[n - 1]];
                    entry = t_near[order[n - 1]];
                    continue;
                }
            }
            // Pop the next entry that may still hold a nearer hit for a lane.
            loop {
                if top == 0 {
                    return (closest, best);
                }
                top -= 1;
                // SAFETY: entries below `top` were all written by the pushes above.
                #[allow(unsafe_code)]
                let (child, t_near) = unsafe { stack[top].assume_init() };
                let mut needed = false;
                for l in 0..LANES {
                    needed |= t_near[l] <= closest[l] * SLACK;
                }
                if needed {
                    current = child;
                    entry = t_near;
                    break;
                }
            }
        }
    }

    /// Tests every ray of the bundle against the spheres of packet `index`,
    /// sphere by sphere, with the operations of the single-ray packet test
    /// (so the same distances), keeping per lane the first in the order of
    /// distance then sphere index, as `Bvh::hit` does.
    #[inline(always)]
    fn bundle_leaf(
        &self,
        index: u32,
        rays: &RayBundle,
        t_min: f32,
        enter: &[bool; LANES],
        mut closest: Lanes,
        mut best: [u32; LANES],
    ) -> (Lanes, [u32; LANES]) {
        let p = self.packet(index);
        // As arrays: indexing a `Vec4` by a variable lane compiles to a jump.
        let eight = |v: &[Vec4; 2]| -> [f32; 8] {
            let (a, b) = (v[0].to_array(), v[1].to_array());
            [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
        };
        let (pcx, pcy, pcz, pr2) = (eight(&p.cx), eight(&p.cy), eight(&p.cz), eight(&p.radius2));
        for s in 0..8 {
            let sphere = p.index[s];
            if sphere == NO_CHILD {
                break;
            }
            let (cx, cy, cz, radius2) = (pcx[s], pcy[s], pcz[s], pr2[s]);
            let [ox, oy, oz] = &rays.origin;
            let [dx, dy, dz] = &rays.direction;
            let (mut new_closest, mut new_best) = (closest, best);
            for l in 0..LANES {
                let fx = ox[l] - cx;
                let fy = oy[l] - cy;
                let fz = oz[l] - cz;
                let half_b = fx * dx[l] + fy * dy[l] + fz * dz[l];
                let lx = fx - half_b * dx[l];
                let ly = fy - half_b * dy[l];
                let lz = fz - half_b * dz[l];
                let discriminant = radius2 - (lx * lx + ly * ly + lz * lz);
                let real = discriminant >= 0.0;
                let sqrt_d = discriminant.sqrt();
                let near = -half_b - sqrt_d;
                let far = -half_b + sqrt_d;
                // The first root beyond t_min, if it is nearer than the best.
                let near_ok = t_min < near;
                let t = if near_ok { near } else { far };
                let valid = enter[l] & real & (near_ok | (t_min < far));
                let hit = valid & (t < closest[l]);
                // Exactly as near as the best (coincident surfaces): the lower
                // sphere index wins.
                let tie = valid & (t == closest[l]) & (sphere < best[l]);
                new_closest[l] = if hit { t } else { closest[l] };
                new_best[l] = if hit | tie { sphere } else { best[l] };
            }
            (closest, best) = (new_closest, new_best);
        }
        (closest, best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::math::Vec3;
    use crate::rng::Rng;

    /// Bundles of nearly parallel rays (as a pixel's camera rays) and of
    /// unrelated rays, of every length, through a sphere field: every lane
    /// must find exactly what `Bvh::hit` finds for its ray alone.
    #[test]
    fn bundles_find_exactly_what_single_rays_find() {
        let mut rng = Rng::new(21);
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
        let bvh = Bvh::new(&spheres);
        let interval = Interval::new(0.001, f32::INFINITY);
        let mut hits = 0;
        for case in 0..3000 {
            let n = 1 + case % LANES;
            let origin = Vec3::new(
                rng.range_f32(-15.0, 15.0),
                rng.range_f32(0.1, 3.0),
                rng.range_f32(-15.0, 15.0),
            );
            let toward = Vec3::new(rng.range_f32(-5.0, 5.0), 0.0, rng.range_f32(-5.0, 5.0));
            let reference = Ray::new(origin, (toward - origin).normalize());
            let coherent = case % 2 == 0;
            let rays: Vec<Ray> = (0..n)
                .map(|_| {
                    if coherent {
                        let jitter = crate::sampling::in_unit_sphere(&mut rng) * 0.05;
                        let o = origin + jitter;
                        let target = toward + crate::sampling::in_unit_sphere(&mut rng) * 0.05;
                        Ray::new(o, (target - o).normalize())
                    } else {
                        Ray::new(origin, crate::sampling::unit_vector(&mut rng))
                    }
                })
                .collect();
            let got = bvh.hit_bundle(&RayBundle::new(&rays), &reference, interval);
            for (lane, ray) in rays.iter().enumerate() {
                let expected = bvh.hit(ray, interval);
                let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.index));
                assert_eq!(bits(got[lane]), bits(expected), "case {case}, lane {lane}");
                hits += usize::from(expected.is_some());
            }
            assert!(
                got[n..].iter().all(Option::is_none),
                "unused lanes report nothing"
            );
        }
        assert!(
            hits > 5000,
            "only {hits} hits: the test exercises too little"
        );
    }

    #[test]
    fn a_lane_does_not_depend_on_the_rest_of_its_bundle() {
        // Duplicated spheres in different leaves tie exactly: which one a ray
        // reports must not change with the rays beside it.
        let mut spheres = vec![Sphere::new(Vec3::ZERO, 1.0); 20];
        spheres.extend((0..20).map(|i| Sphere::new(Vec3::new(i as f32, 3.0, 0.0), 0.5)));
        let bvh = Bvh::new(&spheres);
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
        let bvh = Bvh::new(&spheres);
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
        let bvh = Bvh::new(&[sphere]);
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
        let one = Bvh::new(&[Sphere::new(Vec3::ZERO, 1.0)]);
        let hits = one.hit_bundle(&bundle, &ray, all);
        assert_eq!(hits[0].map(|h| (h.t, h.index)), Some((4.0, 0)));
        assert!(hits[1..].iter().all(Option::is_none));
    }
}
