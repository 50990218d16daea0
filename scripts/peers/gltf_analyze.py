#!/usr/bin/env python3
"""Compare two sets of renders of one scene (lumen and Cycles) whose
renderers are expected to differ: where, by how much, and whether beyond
noise. numpy only (run with any python3 that has it, e.g. either peer venv).

    gltf_analyze.py --a lumen-*.pfm --b cycles-*.pfm --label-a lumen --label-b Cycles \
        --png side-by-side.png [--exposure 0] [--json out.json] \
        [--regions grid:N | --scene SCENE.toml --regions spheres|slabs|tiles|transmission|normals [--mark]]

Each set holds n >= 2 renders with different seeds (.pfm, linear RGB).
Reported (text, and --json):

- per-channel image means of each set with their standard errors (the
  spread of the per-seed image means / sqrt(n)), the difference A - B, its
  relative size, and Welch's t (difference / combined standard error);
- per region, the same means and the relative difference of their
  luminance with its t; with --object-mask, the means over the pixels
  where the objects are (regions: `grid:N` = an N x N grid of image blocks;
  or, placed by the camera of --scene: `spheres` = the 7 x 7 spheres of
  gltf_spheres.toml, `transmission` = the 12 spheres of
  gltf_transmission.toml, each sphere's inner disc (< 0.5 R, seen near
  normal incidence) and ring (0.5 R .. 0.9 R, towards grazing) apart;
  `tiles` = the 6 x 9 tiles of gltf_transmission_roughness.toml (centres);
  `slabs` = the 2 x 4 slabs of gltf_slabs.toml (centres); `normals` = the
  domes of gltf_normals.toml's 40 cells, inner disc and ring);
- the fraction of pixels whose Welch |t| (per pixel and channel, over the
  seeds) exceeds 4, and the mean relative difference of pixels by
  brightness;
- a PNG: A | B | signed difference (A - B) / max(B, 0.05) of the luminance,
  red where A is brighter, blue where B is, full colour at +-25%; A and B
  tone-mapped the same way (exposure, clamp, sRGB).
"""

import argparse
import json
import math
import struct
import sys
import zlib
from pathlib import Path

import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError(f"{path}: not a PFM file")
        dims = f.readline().split()
        w, h = int(dims[0]), int(dims[1])
        scale = float(f.readline().strip())
        nc = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(w * h * nc * 4), dtype="<f4" if scale < 0 else ">f4")
    img = data.reshape(h, w, nc)[::-1].astype(np.float64)
    return np.repeat(img, 3, axis=2) if nc == 1 else img


def write_png(path, rgb8):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    Path(path).write_bytes(png)


def srgb8(x):
    x = np.clip(x, 0.0, 1.0)
    y = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(y, 0, 1) * 255 + 0.5).astype(np.uint8)


def lum(img):
    return img @ np.array([0.2126, 0.7152, 0.0722])


def set_stats(imgs):
    """Per-pixel mean, variance of the mean; per-channel image means and s.e."""
    a = np.stack(imgs)                     # n, h, w, 3
    n = a.shape[0]
    m = a.mean(0)
    v = a.var(0, ddof=1) / n
    im = a.reshape(n, -1, 3).mean(1)       # n, 3 per-seed image means
    return a, m, v, im.mean(0), im.std(0, ddof=1) / math.sqrt(n)


def masked_means(a, mask):
    """Per-seed means of a set over `mask`, then mean and s.e. per channel."""
    n = a.shape[0]
    x = a[:, mask, :].mean(1)              # n, 3
    return x.mean(0), x.std(0, ddof=1) / math.sqrt(n)


def camera_projector(scene_path, w, h):
    """A function mapping lumen world points to (column, row, pixels per
    world unit at that depth), for the camera of the lumen scene file."""
    import tomllib
    cam = tomllib.loads(Path(scene_path).read_text())["camera"]
    eye = np.array(cam.get("lookfrom", [0, 0, 0]), float)
    at = np.array(cam.get("lookat", [0, 0, -1]), float)
    up = np.array(cam.get("vup", [0, 1, 0]), float)
    fw = at - eye
    fw /= np.linalg.norm(fw)
    right = np.cross(fw, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fw)
    t = math.tan(math.radians(cam.get("vfov", 90.0)) / 2)

    def project(p):
        d = np.asarray(p, float) - eye
        z = d @ fw
        x, y = d @ right / (z * t), d @ upv / (z * t)     # in [-aspect, aspect] x [-1, 1]
        return (w / 2 + x * h / 2, h / 2 - y * h / 2, h / 2 / (z * t))
    return project


def disc_masks(project, h, w, centre, radius, split=0.5, outer=0.9):
    """Inner disc (< split R) and ring (split R .. outer R) of a sphere's image."""
    cx, cy, s = project(centre)
    ys, xs = np.mgrid[0:h, 0:w] + 0.5
    d = np.hypot(xs - cx, ys - cy) / (radius * s)
    return d < split, (d >= split) & (d < outer)


def rect_mask(project, h, w, centre, hx, hy):
    """Pixels within hx, hy (world units, in the camera's image plane) of a point."""
    cx, cy, s = project(centre)
    ys, xs = np.mgrid[0:h, 0:w] + 0.5
    return (np.abs(xs - cx) < hx * s) & (np.abs(ys - cy) < hy * s)


# TransmissionTest's spheres: (row, column, material, centre); radius 0.1.
TT_SPHERES = [
    ("smooth", "yellow", [-0.3671, 0.2261, -0.0105]), ("smooth", "green mask", [-0.1329, 0.2294, 0.0032]),
    ("smooth", "red tex", [0.1014, 0.2327, 0.0168]), ("smooth", "blue mask+tex", [0.3356, 0.2359, 0.0305]),
    ("rough", "yellow", [-0.3671, 0.0, -0.0105]), ("rough", "green mask", [-0.1329, 0.0033, 0.0032]),
    ("rough", "red tex", [0.1014, 0.0065, 0.0168]), ("rough", "blue mask+tex", [0.3356, 0.0098, 0.0305]),
    ("metal", "yellow", [-0.3671, -0.234, -0.0105]), ("metal", "green mask", [-0.1329, -0.2307, 0.0032]),
    ("metal", "red tex", [0.1014, -0.2275, 0.0168]), ("metal", "blue mask+tex", [0.3356, -0.2242, 0.0305]),
]
TR_ROWS = [("mirror", -0.33), ("ior 1.0", -0.22), ("ior 1.33", -0.11), ("ior 1.5", 0.0),
           ("ior 1.76", 0.11), ("ior 2.42", 0.22)]


def named_regions(kind, project, h, w):
    """[(name, mask)] for a region set."""
    out = []
    if kind == "spheres":          # gltf_spheres.toml: centres (i, j, 0), radius 0.35
        for j in range(7):         # metallic j/6, bottom to top
            for i in range(7):     # roughness i/6, left to right
                inner, ring = disc_masks(project, h, w, [i, j, 0], 0.35)
                out += [(f"m{j}/6 r{i}/6 inner", inner), (f"m{j}/6 r{i}/6 ring", ring)]
    elif kind == "slabs":          # gltf_slabs.toml: slabs at (c, r), 0.8 wide
        cols = ["ior1.5 smooth vol", "ior1.5 r0.5 vol", "ior1.0 r0.5 vol", "ior1.5 r0.5 thin"]
        for r, tint in enumerate(["white", "tinted"]):
            for c, name in enumerate(cols):
                out.append((f"{tint} {name}", rect_mask(project, h, w, [c, r, 0.05], 0.25, 0.25)))
    elif kind == "tiles":          # gltf_transmission_roughness.toml: 9 columns x 6 rows
        for name, y in TR_ROWS:
            for k in range(9):
                x = 0.2 + (k - 4) * 0.11
                out.append((f"{name} col{k}", rect_mask(project, h, w, [x, y, 0.02], 0.03, 0.025)))
    elif kind == "normals":        # gltf_normals.toml: 5 rows x (4 + 4) cells, domes r 0.11
        cols = ["geometry", "normal map", "V mirror", "U mirror"]
        for y in (0.8, 0.4, 0.0, -0.4, -0.8):
            for panel, xs in (("white", (-1.275, -0.955, -0.629, -0.291)),
                              ("gold", (0.300, 0.620, 0.941, 1.264))):   # the cells' centres
                for x, c in zip(xs, cols):
                    inner, ring = disc_masks(project, h, w, [x, y, 0.04], 0.11)
                    out += [(f"{panel} y{y:+.1f} {c} inner", inner), (f"{panel} y{y:+.1f} {c} ring", ring)]
    elif kind == "transmission":   # gltf_transmission.toml: 3 x 4 spheres, radius 0.1
        for row, col, c in TT_SPHERES:
            inner, ring = disc_masks(project, h, w, c, 0.1)
            out += [(f"{row} {col} inner", inner), (f"{row} {col} ring", ring)]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--a", nargs="+", required=True)
    ap.add_argument("--b", nargs="+", required=True)
    ap.add_argument("--label-a", default="A")
    ap.add_argument("--label-b", default="B")
    ap.add_argument("--png")
    ap.add_argument("--exposure", type=float, default=0.0, help="stops, for the PNG only")
    ap.add_argument("--regions", default="grid:4")
    ap.add_argument("--json")
    ap.add_argument("--scene", help="the lumen scene file (its camera places the regions)")
    ap.add_argument("--object-mask", metavar="SKY.pfm",
                    help="a render of the scene without its objects: also report means over the "
                         "pixels that differ from it by more than 2% (the objects)")
    ap.add_argument("--mark", action="store_true", help="outline the regions (green) in the difference panel")
    args = ap.parse_args()

    A, mA, vA, imA, seA = set_stats([read_pfm(p) for p in args.a])
    B, mB, vB, imB, seB = set_stats([read_pfm(p) for p in args.b])
    h, w, _ = mA.shape
    res = {"a": args.label_a, "b": args.label_b, "n_a": len(args.a), "n_b": len(args.b),
           "size": [w, h]}
    d = imA - imB
    se = np.sqrt(seA ** 2 + seB ** 2)
    res["image"] = {"mean_a": imA.tolist(), "se_a": seA.tolist(), "mean_b": imB.tolist(),
                    "se_b": seB.tolist(), "diff": d.tolist(), "rel": (d / imB).tolist(),
                    "t": (d / np.maximum(se, 1e-30)).tolist()}
    print(f"image {w}x{h}, {len(args.a)} + {len(args.b)} renders")
    for c, name in enumerate("RGB"):
        print(f"  {name}: {args.label_a} {imA[c]:.5f} ± {seA[c]:.5f}   {args.label_b} {imB[c]:.5f} ± {seB[c]:.5f}"
              f"   diff {d[c]:+.5f} ({100 * d[c] / imB[c]:+.2f}%), t = {d[c] / max(se[c], 1e-30):+.1f}")

    if args.object_mask:
        sky = read_pfm(args.object_mask)
        obj = (np.abs(lum(mA) - lum(sky)) > 0.02 * np.maximum(lum(sky), 1e-3))
        ma, sa = masked_means(A, obj)
        mb, sb = masked_means(B, obj)
        do = ma - mb
        so = np.sqrt(sa ** 2 + sb ** 2)
        res["object"] = {"pixels": int(obj.sum()), "mean_a": ma.tolist(), "se_a": sa.tolist(),
                         "mean_b": mb.tolist(), "se_b": sb.tolist(), "rel": (do / mb).tolist(),
                         "t": (do / np.maximum(so, 1e-30)).tolist()}
        print(f"  object pixels ({obj.sum()}, not sky):")
        for c, name in enumerate("RGB"):
            print(f"  {name}: {args.label_a} {ma[c]:.5f} ± {sa[c]:.5f}   {args.label_b} {mb[c]:.5f} ± {sb[c]:.5f}"
                  f"   diff {do[c]:+.5f} ({100 * do[c] / mb[c]:+.2f}%), t = {do[c] / max(so[c], 1e-30):+.1f}")

    # per-pixel Welch t
    t = (mA - mB) / np.sqrt(np.maximum(vA + vB, 1e-30))
    const = (vA + vB) == 0
    t[const] = np.where(np.isclose(mA[const], mB[const], rtol=1e-4, atol=1e-6), 0.0, np.inf)
    frac4 = float((np.abs(t) > 4).mean())
    res["pixels_abs_t_gt_4"] = frac4
    print(f"  pixels (x channels) with |t| > 4: {100 * frac4:.2f}%")
    la, lb = lum(mA), lum(mB)
    rel = (la - lb) / np.maximum(lb, 0.05)
    res["pixel_rel_lum"] = {"mean": float(rel.mean()), "p5": float(np.percentile(rel, 5)),
                            "p50": float(np.percentile(rel, 50)), "p95": float(np.percentile(rel, 95)),
                            "frac_abs_gt_5pct": float((np.abs(rel) > 0.05).mean())}
    print("  luminance (A-B)/B per pixel: p5 {p5:+.3f}, median {p50:+.3f}, p95 {p95:+.3f}, "
          "|.|>5% in {f:.1f}% of pixels".format(f=100 * res['pixel_rel_lum']['frac_abs_gt_5pct'],
                                                 **res["pixel_rel_lum"]))

    regions = []
    wts = np.array([0.2126, 0.7152, 0.0722])
    outline = np.zeros((h, w), bool)
    if args.regions.startswith("grid:"):
        nb = int(args.regions.split(":")[1])
        named = []
        for by in range(nb):
            for bx in range(nb):
                mask = np.zeros((h, w), bool)
                mask[by * h // nb:(by + 1) * h // nb, bx * w // nb:(bx + 1) * w // nb] = True
                named.append((f"block {by},{bx}", mask))
    else:
        if not args.scene:
            ap.error("--regions other than grid:N need --scene (its camera)")
        named = named_regions(args.regions, camera_projector(args.scene, w, h), h, w)
    print(f"  regions ({args.regions}): mean luminance A, B, (A-B)/B, t of the difference")
    for name, mask in named:
        if mask.sum() == 0:
            continue
        ma, sa = masked_means(A, mask)
        mb, sb = masked_means(B, mask)
        la_, lb_ = float(ma @ wts), float(mb @ wts)
        sl = math.sqrt(float((sa @ wts) ** 2 + (sb @ wts) ** 2))
        r = {"region": name, "pixels": int(mask.sum()), "mean_a": ma.tolist(), "se_a": sa.tolist(),
             "mean_b": mb.tolist(), "se_b": sb.tolist(), "lum_a": la_, "lum_b": lb_,
             "rel_lum": la_ / lb_ - 1 if lb_ > 0 else float("nan"),
             "t_lum": (la_ - lb_) / sl if sl > 0 else float("inf")}
        regions.append(r)
        print(f"    {name:28s} {la_:8.4f} {lb_:8.4f} {100 * r['rel_lum']:+7.2f}%  t {r['t_lum']:+8.1f}"
              f"   ({mask.sum()} px)")
        inner = mask.copy()
        inner[1:-1, 1:-1] = mask[1:-1, 1:-1] & mask[:-2, 1:-1] & mask[2:, 1:-1] & mask[1:-1, :-2] & mask[1:-1, 2:]
        outline |= mask & ~inner
    res["regions"] = regions

    if args.png:
        k = 2.0 ** args.exposure
        ta, tb = srgb8(mA * k), srgb8(mB * k)
        s = np.clip(rel / 0.25, -1, 1)
        diff = np.empty((h, w, 3))
        diff[..., 0] = np.where(s > 0, 1, 1 + s)
        diff[..., 1] = 1 - np.abs(s)
        diff[..., 2] = np.where(s < 0, 1, 1 - s)
        diff = (diff * 255 + 0.5).astype(np.uint8)
        if args.mark:
            diff[outline] = (0, 160, 0)
        gap = np.full((h, 4, 3), 255, np.uint8)
        write_png(args.png, np.concatenate([ta, gap, tb, gap, diff], axis=1))
        print(f"  wrote {args.png}: {args.label_a} | {args.label_b} | (A-B)/B of luminance "
              "(red A brighter, blue B brighter, saturated at ±25%)")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
