#!/usr/bin/env python3
"""Do two renderers agree on a scene, up to Monte Carlo noise?

    compare.py --a A1.exr A2.exr A3.exr A4.exr --b B1.pfm B2.pfm B3.pfm B4.pfm

Each set (A, B) holds n >= 2 renders of the same scene made with different
seeds (independent noise); the two sets may come from different renderers,
sample counts or samplers. Images are linear RGB: .exr (read with Mitsuba's
Bitmap, so run this in the venv of scripts/peers/setup.sh) or .pfm (read here).
Exit status: 0 when the difference is explained by noise, 1 when it is not,
2 on bad input.

Statistics
----------
For every pixel p and channel c, set A gives n_A values x_i (one per seed).
Their mean m_A estimates the pixel's expected value, and the sample variance
s_A^2 (with n_A - 1 in the denominator) the variance of one render, so the
variance of m_A is v_A = s_A^2 / n_A. Likewise for B. The difference of the
means is then tested with Welch's t statistic

    t = (m_A - m_B) / sqrt(v_A + v_B),
    nu = (v_A + v_B)^2 / (v_A^2 / (n_A - 1) + v_B^2 / (n_B - 1))   (Welch-Satterthwaite)

Under the hypothesis that both renderers have the same expected image (and
per-render noise close to Gaussian, which holds for averages of many samples),
t follows Student's t distribution with nu degrees of freedom. With only a
few seeds nu is small (3..6 for 4 + 4 seeds) and t has heavy tails (|t| > 3 in
2.4% of pixels at nu = 6, not 0.27%), so each t is mapped to the equivalent
standard normal score z with the same two-sided tail probability:
p = P(|T_nu| > |t|) = I_{nu/(nu+t^2)}(nu/2, 1/2) (regularised incomplete
beta), z = sign(t) * Phi^-1(1 - p/2). Under the hypothesis z is N(0, 1)
whatever nu: P(|z| > 3) = 0.27%, and RMS(z) = 1.

Three scales are tested, each with this same z:

1. The whole image (bias test): the per-seed image means of each channel are
   the samples. Reported: each set's mean, the difference, its standard error
   sqrt(v_A + v_B), the ratio t = difference / s.e., and z. Fails when
   |z| > 3 in any channel (with 4 + 4 seeds that is |t| > 4.9 at 6 degrees
   of freedom, up to 9.2 at 3; |t| > 3 alone would fail 2-6% of fair tests).
2. Pixels: the per-pixel z. Reported: the fraction with |z| > 3 (expected
   0.27%) and RMS(z) (expected 1). Fails when the count with |z| > 3 exceeds
   its binomial expectation by more than 5 standard deviations, or RMS(z)
   exceeds 1.1 (allowing for the approximate Welch dof).
3. Blocks of B x B pixels (default 8): each render is first averaged over
   blocks, then treated as in 2. A bias too small to stand out of one pixel's
   noise (a 1% bias under 10% noise) is 8 times larger relative to the noise
   of a 64-pixel block. Because the block variance comes from the per-seed
   block means, correlations between neighbouring pixels within a render
   are accounted for. Same failure rules as 2.

A grey scene (R = G = B in every render) is tested on one channel only.
Counts are over (pixel, channel) values; the limit in 2 and 3 allows for the
channels of a pixel being correlated.

The sets must have independent noise: the same seeds in both sets (same
renderer, same or nearly the same scene) correlate them, which shows as
RMS(z) well below 1 and is warned about (the test is then too lenient).

Pixels with zero variance in both sets (e.g. sky seen directly: every sample
is the same) have no z; they are counted apart and must agree to within
a relative 1e-4 (else they count as mismatches and the comparison fails).
"""

import argparse
import json
import math
import sys
from statistics import NormalDist

import numpy as np

P_GAUSS_3 = 2 * (1 - NormalDist().cdf(3.0))  # 0.0027


# ---------------------------------------------------------------- images
def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError(f"{path}: not a PFM file")
        dims = f.readline().split()
        while not dims:
            dims = f.readline().split()
        w, h = int(dims[0]), int(dims[1])
        scale = float(f.readline().strip())
        nc = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(w * h * nc * 4), dtype="<f4" if scale < 0 else ">f4")
    if data.size != w * h * nc:
        raise ValueError(f"{path}: truncated")
    img = data.reshape(h, w, nc)[::-1].astype(np.float64)  # rows are stored bottom to top
    return np.repeat(img, 3, axis=2) if nc == 1 else img


def read_exr(path):
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    bmp = mi.Bitmap(path)
    bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    return np.array(bmp, dtype=np.float64)


def read_image(path):
    if path.lower().endswith(".pfm"):
        return read_pfm(path)
    return read_exr(path)


# ---------------------------------------------------------------- Student t -> z
def _betacf(a, b, x, iters=300, eps=1e-15):
    """Continued fraction of the incomplete beta function (Lentz), vectorised."""
    tiny = 1e-300
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c = np.ones_like(x)
    d = 1.0 - qab * x / qap
    d = np.where(np.abs(d) < tiny, tiny, d)
    d = 1.0 / d
    h = d.copy()
    for m in range(1, iters + 1):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = np.where(np.abs(d) < tiny, tiny, d)
        c = 1.0 + aa / c
        c = np.where(np.abs(c) < tiny, tiny, c)
        d = 1.0 / d
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = np.where(np.abs(d) < tiny, tiny, d)
        c = 1.0 + aa / c
        c = np.where(np.abs(c) < tiny, tiny, c)
        d = 1.0 / d
        delta = d * c
        h *= delta
        if np.all(np.abs(delta - 1.0) < eps):
            break
    return h


def betainc(a, b, x):
    """Regularised incomplete beta I_x(a, b), elementwise (a, b > 0, 0 <= x <= 1)."""
    a, b, x = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float), np.asarray(x, float))
    lg = np.vectorize(math.lgamma, otypes=[float])
    xc = np.clip(x, 1e-300, 1 - 1e-16)
    lbt = lg(a + b) - lg(a) - lg(b) + a * np.log(xc) + b * np.log1p(-xc)
    bt = np.exp(lbt)
    direct = x < (a + 1) / (a + b + 2)
    out = np.empty_like(x)
    if direct.any():
        out[direct] = bt[direct] * _betacf(a[direct], b[direct], xc[direct]) / a[direct]
    if (~direct).any():
        i = ~direct
        out[i] = 1.0 - bt[i] * _betacf(b[i], a[i], 1.0 - xc[i]) / b[i]
    out[x <= 0] = 0.0
    out[x >= 1] = 1.0
    return out


def t_to_z(t, nu):
    """Normal score with the same two-sided tail probability as t under Student's t(nu)."""
    t = np.asarray(t, float)
    nu = np.broadcast_to(np.asarray(nu, float), t.shape)
    p = betainc(nu / 2, 0.5, nu / (nu + t * t))  # P(|T| > |t|)
    inv = np.vectorize(lambda q: -NormalDist().inv_cdf(min(max(q, 1e-300), 0.5)), otypes=[float])
    return np.sign(t) * inv(p / 2)


# ---------------------------------------------------------------- tests
def welch(a, b):
    """a: (n_A, ...) and b: (n_B, ...) -> (diff, se, z, zero_var mask)."""
    na, nb = a.shape[0], b.shape[0]
    ma, mb = a.mean(0), b.mean(0)
    va, vb = a.var(0, ddof=1) / na, b.var(0, ddof=1) / nb
    v = va + vb
    diff = ma - mb
    zero = v <= 0
    vs = np.where(zero, 1.0, v)
    nu = vs * vs / (va * va / (na - 1) + vb * vb / (nb - 1) + 1e-300 * zero)
    nu = np.clip(nu, min(na, nb) - 1, na + nb - 2)  # Welch dof lies in this range
    t = np.where(zero, 0.0, diff / np.sqrt(vs))
    z = np.where(zero, 0.0, t_to_z(t, nu))
    return diff, np.sqrt(v), z, zero


def block_mean(imgs, k):
    n, h, w, c = imgs.shape
    h2, w2 = h // k * k, w // k * k
    return imgs[:, :h2, :w2].reshape(n, h2 // k, k, w2 // k, k, c).mean(axis=(2, 4))


def field_test(a, b, label, sigmas=5.0, rms_max=1.1):
    """Per-value z of two stacks of images (n, H, W, C) and the pass/fail rules."""
    diff, se, z, zero = welch(a, b)
    nchan = a.shape[-1]
    ma, mb = a.mean(0), b.mean(0)
    const_bad = zero & (np.abs(diff) > 1e-4 * np.maximum(np.abs(ma), np.abs(mb)) + 1e-7)
    zz = z[~zero]
    n = zz.size
    over = int((np.abs(zz) > 3).sum())
    expect = n * P_GAUSS_3
    # The channels of one pixel may be correlated (fully, for a grey scene
    # that is not collapsed): the count's s.d. is at most sqrt(C) times the
    # binomial one, which the limit allows for.
    limit = expect + sigmas * math.sqrt(nchan * n * P_GAUSS_3 * (1 - P_GAUSS_3))
    rms = float(np.sqrt(np.mean(zz * zz))) if n else 0.0
    res = {
        "scale": label, "values": n, "constant_values": int(zero.sum()),
        "constant_mismatches": int(const_bad.sum()),
        "over_3": over, "frac_over_3": over / n if n else 0.0,
        "expected_over_3": round(expect, 1), "limit_over_3": round(limit, 1),
        "rms_z": rms, "max_abs_z": float(np.abs(zz).max()) if n else 0.0,
        "mean_z": float(zz.mean()) if n else 0.0,
    }
    res["pass"] = bool(over <= limit and rms <= rms_max and res["constant_mismatches"] == 0)
    return res, z


def main(argv=None):
    ap = argparse.ArgumentParser(description="Compare two sets of renders of one scene up to noise.")
    ap.add_argument("--a", nargs="+", required=True, help="renders of set A (different seeds)")
    ap.add_argument("--b", nargs="+", required=True, help="renders of set B (different seeds)")
    ap.add_argument("--block", type=int, default=8, help="block size for the block test (default 8)")
    ap.add_argument("--z-map", help="write |z| of the pixel test (max over channels) to this .pfm")
    ap.add_argument("--json", action="store_true", help="print the report as JSON only")
    args = ap.parse_args(argv)

    if len(args.a) < 2 or len(args.b) < 2:
        print("compare.py: each set needs at least 2 renders (different seeds)", file=sys.stderr)
        return 2
    try:
        A = np.stack([read_image(p) for p in args.a])
        B = np.stack([read_image(p) for p in args.b])
    except (OSError, ValueError, RuntimeError) as e:
        print(f"compare.py: {e}", file=sys.stderr)
        return 2
    if A.shape[1:] != B.shape[1:]:
        print(f"compare.py: image sizes differ: {A.shape[1:]} vs {B.shape[1:]}", file=sys.stderr)
        return 2
    bad = ~np.isfinite(A).all() or ~np.isfinite(B).all()
    if bad:
        print("compare.py: an image holds NaN or infinite values", file=sys.stderr)
        return 2

    # A grey scene (R = G = B in every render) is tested on one channel:
    # three identical copies would only triple the counts.
    grey = all(np.array_equal(X[..., 0], X[..., 1]) and np.array_equal(X[..., 0], X[..., 2]) for X in (A, B))
    if grey:
        A, B = A[..., :1], B[..., :1]

    # 1. whole-image means per channel
    mean_a, mean_b = A.mean(axis=(1, 2)), B.mean(axis=(1, 2))  # (n, 3)
    d, se, z, _ = welch(mean_a, mean_b)
    bias = {
        "mean_a": mean_a.mean(0).tolist(), "mean_b": mean_b.mean(0).tolist(),
        "diff": d.tolist(), "se": se.tolist(), "t": (d / np.where(se > 0, se, np.inf)).tolist(), "z": z.tolist(),
        "rel_diff": (d / mean_b.mean(0)).tolist(),
    }
    bias["pass"] = bool(np.all(np.abs(z) <= 3))

    # 2. pixels, 3. blocks
    pix, zmap = field_test(A, B, "pixel")
    blk, _ = field_test(block_mean(A, args.block), block_mean(B, args.block), f"{args.block}x{args.block} block")

    ok = bias["pass"] and pix["pass"] and blk["pass"]
    warnings = []
    if pix["values"] >= 100 and pix["rms_z"] < 0.8:
        warnings.append(f"RMS z of the pixels is {pix['rms_z']:.2f}, well below 1: the noise of the two "
                        "sets is correlated (the same seeds in both?) or the variance is overestimated "
                        "(rare bright samples), and the test is too lenient")
    report = {"n_a": len(args.a), "n_b": len(args.b), "size": list(A.shape[1:3]), "grey": grey,
              "image_mean": bias, "pixels": pix, "blocks": blk, "warnings": warnings, "pass": ok}

    if args.z_map:
        m = np.abs(zmap).max(axis=2).astype("<f4")  # (H, W)
        with open(args.z_map, "wb") as f:
            f.write(f"Pf\n{m.shape[1]} {m.shape[0]}\n-1.0\n".encode())
            f.write(np.ascontiguousarray(m[::-1]).tobytes())

    if not args.json:
        print(f"set A: {len(args.a)} renders, set B: {len(args.b)} renders, {A.shape[2]}x{A.shape[1]}"
              + (", grey (R = G = B): one channel tested" if grey else ""))
        print("image mean     A           B           A-B          s.e.     (A-B)/se    z      rel")
        for c, name in enumerate("Y" if grey else "RGB"):
            print(f"  {name}      {bias['mean_a'][c]:.6f}    {bias['mean_b'][c]:.6f}   "
                  f"{bias['diff'][c]:+.3e}  {bias['se'][c]:.3e}  {bias['t'][c]:+8.2f}  {bias['z'][c]:+6.2f}  "
                  f"{bias['rel_diff'][c]:+.2%}")
        print(f"  bias test |z| <= 3: {'pass' if bias['pass'] else 'FAIL'}")
        for r in (pix, blk):
            print(f"{r['scale']} z ({r['values']} values, {r['constant_values']} constant, "
                  f"{r['constant_mismatches']} constant mismatches): "
                  f"|z|>3 in {r['over_3']} = {r['frac_over_3']:.3%} (expected {r['expected_over_3']}, "
                  f"limit {r['limit_over_3']}), RMS z {r['rms_z']:.3f}, mean z {r['mean_z']:+.3f}, "
                  f"max |z| {r['max_abs_z']:.1f}: {'pass' if r['pass'] else 'FAIL'}")
        for w in warnings:
            print(f"warning: {w}")
        print("AGREE (difference explained by noise)" if ok else "DISAGREE (difference beyond noise)")
    print(json.dumps(report))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
