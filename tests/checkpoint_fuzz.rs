//! Damaged and crafted checkpoints: random bit flips, and field changes
//! whose checksum is made right again so that the checks behind it are
//! reached. Every case must end in one clear error or, when the change
//! does not touch the samples, in a resume that gives the image of a render
//! never stopped; none may panic or silently change the image.

use lumen::checkpoint::{Checkpoint, HEADER_LEN};
use lumen::film::Film;
use lumen::progressive::Session;
use lumen::scene::{builtin, Sampling, SceneDesc};
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

const PATH: &str = "fuzz.ckpt";

/// splitmix64: a fixed, seedable stream, so that a failure reproduces.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn tiny(adaptive: bool) -> SceneDesc {
    let mut desc = builtin::find("metal-mirror").unwrap().desc();
    desc.render.width = 8;
    desc.render.height = Some(4);
    desc.render.samples_per_pixel = if adaptive { 64 } else { 16 };
    if adaptive {
        desc.render.sampler = Sampling::Sobol;
        desc.render.noise_target = Some(0.05);
    }
    desc
}

/// A render of `desc` stopped once it holds at least `stop_at` spp: its
/// checkpoint's bytes, and the finished render's film and flags.
fn case(desc: &SceneDesc, stop_at: u32) -> (Vec<u8>, Film, Option<Vec<bool>>) {
    let stop = AtomicBool::new(false);
    let mut session = Session::new(desc).unwrap();
    session
        .run(&stop, None, &|_| {}, &mut |s, _| {
            if s.spp_done() >= stop_at {
                stop.store(true, Ordering::SeqCst);
            }
            Ok::<(), ()>(())
        })
        .unwrap();
    let bytes = session.checkpoint().encode();
    stop.store(false, Ordering::SeqCst);
    session
        .run(&stop, None, &|_| {}, &mut |_, _| Ok::<(), ()>(()))
        .unwrap();
    let active = session.active().map(<[bool]>::to_vec);
    (bytes, session.film().clone(), active)
}

/// Where the fields of a checkpoint's bytes are.
struct Layout {
    id: Range<usize>,
    desc: Range<usize>,
    spp: usize,
    width: usize,
    samples: usize,
    rays: usize,
    dropped: usize,
    counts: usize,
    adaptive: usize,
    odd_counts: usize,
    flags: usize,
    pixels: usize,
}

fn layout(bytes: &[u8]) -> Layout {
    let u32_at = |at: usize| get_u32(bytes, at) as usize;
    let id = HEADER_LEN + 4..HEADER_LEN + 4 + u32_at(HEADER_LEN);
    let desc = id.end + 4..id.end + 4 + u32_at(id.end);
    let spp = desc.end;
    // After spp_done: the share (start, end) and the gamma; after the
    // film's size, the tile's corner and the image's size.
    let width = spp + 16;
    let height = u32_at(width + 4);
    let pixels = u32_at(width) * height;
    let counts = width + 24 + 24;
    // The sums, row by row, each row after its length.
    let rows_end = |mut at: usize| {
        for _ in 0..height {
            at += 4 + u32_at(at);
        }
        at
    };
    let adaptive = rows_end(counts + 4 * pixels);
    let odd_counts = adaptive + 1;
    let flags = if bytes[adaptive] == 1 {
        rows_end(odd_counts + 4 * pixels)
    } else {
        0
    };
    Layout {
        id,
        desc,
        spp,
        width,
        samples: width + 24,
        rays: width + 32,
        dropped: width + 40,
        counts,
        adaptive,
        odd_counts,
        flags,
        pixels,
    }
}

/// Makes the header's length and checksum those of the payload again.
fn reseal(bytes: &mut [u8]) {
    let len = (bytes.len() - HEADER_LEN) as u64;
    bytes[12..20].copy_from_slice(&len.to_le_bytes());
    let crc = crc32fast::hash(&bytes[HEADER_LEN..]);
    bytes[20..24].copy_from_slice(&crc.to_le_bytes());
}

fn put_u32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn put_u64(bytes: &mut [u8], at: usize, v: u64) {
    bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

fn get_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

fn get_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

/// Replaces the u32 at `at` by another value (see [`other_than`]).
fn perturb_u32(rng: &mut Rng, bytes: &mut [u8], at: usize) {
    let old = get_u32(bytes, at);
    put_u32(
        bytes,
        at,
        other_than(rng, old.into(), u32::MAX.into()) as u32,
    );
}

/// A value other than `old`: small neighbours, extremes, or random.
fn other_than(rng: &mut Rng, old: u64, max: u64) -> u64 {
    loop {
        let v = match rng.below(5) {
            0 => 0,
            1 => old.wrapping_add(1),
            2 => old.wrapping_sub(1),
            3 => max,
            _ => rng.next(),
        } & max;
        if v != old {
            return v;
        }
    }
}

/// Changes one field of `bytes` (a consistent checkpoint) so that the
/// result either is refused or resumes to the same image; returns what
/// changed. Left out, because no check can tell them from a real
/// checkpoint: a different finite sum, and a pixel that stopped at the last
/// pass marked still sampling, or the other way round.
fn craft(rng: &mut Rng, bytes: &mut Vec<u8>, l: &Layout, active: bool) -> String {
    let pixel = rng.below(l.pixels);
    let what = match rng.below(if active { 11 } else { 9 }) {
        0 => {
            let at = rng.below(l.id.len()) + l.id.start;
            bytes[at] ^= 1 << rng.below(8);
            format!("renderer identity byte {at}")
        }
        1 => {
            let at = rng.below(l.desc.len()) + l.desc.start;
            bytes[at] ^= 1 << rng.below(8);
            format!("description byte {at}")
        }
        2 => {
            perturb_u32(rng, bytes, l.spp);
            "spp done".into()
        }
        3 => {
            // The film's width and height, the tile's corner, the image's
            // width and height.
            let at = l.width + 4 * rng.below(6);
            if rng.below(2) == 0 {
                // The other side's value, or one more if they are equal.
                let old = get_u32(bytes, at);
                let v = get_u32(bytes, l.width + 4 * usize::from(at == l.width));
                put_u32(bytes, at, if v == old { old + 1 } else { v });
            } else {
                perturb_u32(rng, bytes, at);
            }
            format!("image size field at {at}")
        }
        4 => {
            // The ray count only feeds the closing summary: a change is
            // accepted, and the image is the same.
            let at = [l.samples, l.dropped, l.rays][rng.below(3)];
            let old = get_u64(bytes, at);
            put_u64(bytes, at, other_than(rng, old, u64::MAX));
            format!("statistic at {at}")
        }
        5 => {
            perturb_u32(rng, bytes, l.counts + 4 * pixel);
            format!("count of pixel {pixel}")
        }
        6 => {
            // A pixel without samples must have a sum of zero.
            put_u32(bytes, l.counts + 4 * pixel, 0);
            format!("count of pixel {pixel} zeroed")
        }
        7 => {
            let n = rng.below(64) + 1;
            if rng.below(2) == 0 {
                bytes.truncate(bytes.len() - n);
            } else {
                bytes.extend((0..n).map(|_| rng.next() as u8));
            }
            "payload length".into()
        }
        8 => {
            bytes[l.adaptive] = other_than(rng, bytes[l.adaptive].into(), 255) as u8;
            "adaptive byte".into()
        }
        9 => {
            // Only pixels still sampling: their odd count is fixed by the
            // samples done (no sample of this scene is dropped).
            let at = l.flags + pixel;
            if bytes[at] == 1 {
                perturb_u32(rng, bytes, l.odd_counts + 4 * pixel);
                format!("odd count of pixel {pixel}")
            } else if get_u32(bytes, l.counts + 4 * pixel) < get_u32(bytes, l.spp) {
                bytes[at] = 1;
                format!("pixel {pixel} marked sampling again")
            } else {
                // Stopped at the last pass, it may as well not have.
                bytes[at] = 7;
                format!("flag of pixel {pixel}")
            }
        }
        _ => {
            let at = l.flags + pixel;
            bytes[at] = (rng.below(254) + 2) as u8;
            format!("flag of pixel {pixel}")
        }
    };
    reseal(bytes);
    what
}

/// Decodes `bytes` as the checkpoint of a render of `desc` and resumes it;
/// an error is the message.
fn resume(bytes: &[u8], desc: &SceneDesc) -> Result<Session, String> {
    let path = Path::new(PATH);
    Checkpoint::decode(bytes, path)
        .map_err(|e| e.to_string())
        .and_then(|c| Session::resume(desc, c, path).map_err(|e| e.to_string()))
}

/// Decodes and resumes `bytes`: a refusal must be one clear line naming the
/// file; an acceptance must finish as the render never stopped. Returns
/// whether it was accepted.
fn check(
    bytes: &[u8],
    desc: &SceneDesc,
    film: &Film,
    active: &Option<Vec<bool>>,
    what: &str,
) -> bool {
    match resume(bytes, desc) {
        Err(e) => {
            assert!(
                e.contains(PATH) && !e.contains('\n'),
                "{what}: unclear: {e}"
            );
            false
        }
        Ok(mut s) => {
            let stop = AtomicBool::new(false);
            s.run(&stop, None, &|_| {}, &mut |_, _| Ok::<(), ()>(()))
                .unwrap();
            assert!(s.film() == film, "{what}: accepted, and the image changed");
            assert_eq!(&s.active().map(<[bool]>::to_vec), active, "{what}");
            true
        }
    }
}

fn fuzz(adaptive: bool, stop_at: u32, seed: u64) {
    let desc = tiny(adaptive);
    let (good, film, active) = case(&desc, stop_at);
    let l = layout(&good);
    let ckpt = Checkpoint::decode(&good, Path::new(PATH)).unwrap();
    assert_eq!(
        ckpt.stats.dropped, 0,
        "the crafted cases assume no dropped sample"
    );
    if adaptive {
        let flags = &good[l.flags..];
        assert!(
            flags.contains(&0) && flags.contains(&1),
            "want pixels stopped and not"
        );
    }
    assert!(check(&good, &desc, &film, &active, "unchanged"));
    let mut rng = Rng(seed);
    let mut accepted = 0;
    const CASES: usize = 1500;
    for i in 0..CASES {
        // A random bit flip: always refused.
        let mut bad = good.clone();
        let at = rng.below(bad.len());
        bad[at] ^= 1 << rng.below(8);
        let e = Checkpoint::decode(&bad, Path::new(PATH));
        assert!(e.is_err(), "case {i}: flip at {at} accepted");
        // A crafted field with a valid checksum.
        let mut crafted = good.clone();
        let what = craft(&mut rng, &mut crafted, &l, adaptive);
        accepted += usize::from(check(
            &crafted,
            &desc,
            &film,
            &active,
            &format!("case {i}: {what}"),
        ));
    }
    // Changes that leave the samples alone (the ray count, a description
    // equal once parsed) are accepted; the rest are refused.
    eprintln!(
        "{CASES} bit flips refused; of {CASES} crafted checkpoints, {accepted} resumed correctly, the rest were refused"
    );
    assert!(accepted < CASES / 4, "{accepted} accepted");
}

#[test]
fn damaged_and_crafted_checkpoints_are_refused_or_resume_correctly() {
    fuzz(false, 4, 1);
}

#[test]
fn damaged_and_crafted_adaptive_checkpoints_are_refused_or_resume_correctly() {
    fuzz(true, 24, 2);
}

#[test]
fn inconsistent_contents_are_named() {
    let desc = tiny(false);
    let (good, ..) = case(&desc, 4);
    let l = layout(&good);
    let refused = |bytes: &[u8]| -> String { resume(bytes, &desc).map(|_| ()).unwrap_err() };
    let mut zero_spp = good.clone();
    put_u32(&mut zero_spp, l.spp, 0);
    reseal(&mut zero_spp);
    assert!(refused(&zero_spp).contains("holds no samples"));
    let mut no_counts = good.clone();
    for p in 0..l.pixels {
        put_u32(&mut no_counts, l.counts + 4 * p, 0);
    }
    reseal(&mut no_counts);
    let e = refused(&no_counts);
    assert!(
        e.contains("no samples but a sum") || e.contains("its pixels hold 0 samples"),
        "{e}"
    );
    let mut emptied = good.clone();
    put_u32(&mut emptied, l.counts, 0);
    put_u64(&mut emptied, l.dropped, get_u64(&good, l.dropped) + 4);
    reseal(&mut emptied);
    let e = refused(&emptied);
    assert!(e.contains("pixel (0, 0) has no samples but a sum"), "{e}");
    // 3 spp is not where a pass of a 16 spp render ends (4 is); the counts
    // agree with it, so only the schedule tells.
    let mut off_schedule = good.clone();
    put_u32(&mut off_schedule, l.spp, 3);
    put_u64(&mut off_schedule, l.samples, 3 * l.pixels as u64);
    for p in 0..l.pixels {
        put_u32(&mut off_schedule, l.counts + 4 * p, 3);
    }
    reseal(&mut off_schedule);
    let e = refused(&off_schedule);
    assert!(e.contains("no pass of a 16 spp render ends"), "{e}");
}
