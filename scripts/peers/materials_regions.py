#!/usr/bin/env python3
"""Per-object means of two (or more) sets of renders of a sphere scene.

    materials_regions.py SCENE.toml --set lumen L1.pfm L2.pfm ... --set mitsuba M1.pfm M2.pfm ...
        [--ref mitsuba] [--json OUT.json] [--save-masks DIR]

Each set is >= 2 renders with different seeds (.pfm, or .exr read with
Mitsuba's Bitmap). The regions are computed geometrically from the scene's
camera (lumen's pinhole model, docs/scene-format.md): a pixel belongs to
object i when all of a 4 x 4 grid of rays through it first hit object i
(spheres and quads)
(pixels that straddle an edge belong to no region, so that a region's mean
does not depend on how each renderer filters edges), to "sky" when all miss.
For every region and channel the per-seed means are the samples: the set's
mean, its standard error (sample s.d. over seeds / sqrt(n)), and against the
reference set (--ref, default the last) the relative difference, its
standard error and Welch's t. Plain Python + numpy (+ Mitsuba for .exr).
"""

import argparse
import json
import math
import sys
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402
from compare import read_image  # noqa: E402


def region_ids(scene, sub=4):
    """H x W array: index of the object every sub x sub ray of the pixel hits
    first, -1 for all sky, -2 for mixed pixels."""
    r, cam = scene["render"], scene["camera"]
    W, H = r["width"], r["height"]
    eye, w, u, v = peerlib.camera_basis(cam)
    fd = cam.get("focus_dist", float(np.linalg.norm(np.array(cam["lookfrom"], float)
                                                    - np.array(cam["lookat"], float))))
    vh = 2 * math.tan(math.radians(cam["vfov"]) / 2) * fd
    vw = vh * W / H
    du, dv = vw * u / W, -vh * v / H
    ul = eye - fd * w - vw * u / 2 + vh * v / 2
    offs = (np.arange(sub) + 0.5) / sub  # sub-pixel positions in [0, 1)
    xs = (np.arange(W)[None, :, None, None] + offs[None, None, None, :])
    ys = (np.arange(H)[:, None, None, None] + offs[None, None, :, None])
    target = (ul + xs[..., None] * du + ys[..., None] * dv)  # H, W, sub, sub, 3
    d = target - eye
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    best_t = np.full(d.shape[:-1], np.inf)
    best = np.full(d.shape[:-1], -1)
    for i, o in enumerate(scene["objects"]):
        if o["type"] == "sphere":
            c, rad = np.array(o["center"], float), float(o["radius"])
            oc = eye - c
            b = (d * oc).sum(-1)
            disc = b * b - (oc @ oc - rad * rad)
            sq = np.sqrt(np.maximum(disc, 0))
            t = -b - sq
            t = np.where(t > 1e-6, t, -b + sq)
            hit = (disc > 0) & (t > 1e-6) & (t < best_t)
        elif o["type"] == "quad":
            q, qu, qv = (np.array(o[k], float) for k in ("corner", "u", "v"))
            n = np.cross(qu, qv)
            denom = d @ n
            with np.errstate(divide="ignore", invalid="ignore"):
                t = ((q - eye) @ n) / denom
            p = eye + t[..., None] * d - q
            # (alpha, beta) of p in the basis u, v
            w = n / (n @ n)
            alpha = np.cross(p, qv) @ w
            beta = np.cross(qu, p) @ w
            hit = ((t > 1e-6) & (t < best_t) & (alpha >= 0) & (alpha <= 1)
                   & (beta >= 0) & (beta <= 1))
        else:
            raise ValueError(f"objects[{i}]: type {o['type']} not supported")
        best_t = np.where(hit, t, best_t)
        best = np.where(hit, i, best)
    flat = best.reshape(H, W, -1)
    same = (flat == flat[..., :1]).all(-1)
    return np.where(same, flat[..., 0], -2)


def region_names(scene):
    names = {}
    for i, o in enumerate(scene["objects"]):
        names[i] = f"{i}:{o['material']}"
    names[-1] = "sky"
    return names


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--set", nargs="+", action="append", required=True, metavar=("NAME", "IMG"),
                    help="a set: its name, then its renders (repeat for each set)")
    ap.add_argument("--ref", help="the set the others are compared with (default: the last)")
    ap.add_argument("--json", help="also write the table as JSON here")
    ap.add_argument("--save-masks", help="write regions.npy (object index per pixel) into this folder")
    args = ap.parse_args(argv)

    scene = peerlib.fill_defaults(tomllib.loads(Path(args.scene).read_text()))
    ids = region_ids(scene)
    if args.save_masks:
        Path(args.save_masks).mkdir(parents=True, exist_ok=True)
        np.save(Path(args.save_masks) / "regions.npy", ids)
    names = region_names(scene)
    sets = {}
    for s in args.set:
        if len(s) < 3:
            ap.error(f"set {s[0]}: give a name and at least 2 renders")
        sets[s[0]] = np.stack([read_image(p) for p in s[1:]])
    ref = args.ref or args.set[-1][0]
    if ref not in sets:
        ap.error(f"--ref {ref}: no such set")
    H, W = ids.shape
    for k, a in sets.items():
        if a.shape[1:3] != (H, W):
            ap.error(f"set {k}: images are {a.shape[2]}x{a.shape[1]}, the scene {W}x{H}")

    regions = [("image", np.ones_like(ids, bool))]
    for i in sorted(set(np.unique(ids)) - {-2}):
        regions.append((names[i], ids == i))
    out = []
    chans = "RGB"
    print(f"per-region means over seeds (s.e. = s.d. of the per-seed means / sqrt(n)); "
          f"relative difference against {ref}")
    for rname, mask in regions:
        npx = int(mask.sum())
        if npx == 0:
            continue
        per = {k: a[:, mask].mean(1) for k, a in sets.items()}  # (n, 3)
        row = {"region": rname, "pixels": npx, "sets": {}}
        mr, ser = per[ref].mean(0), per[ref].std(0, ddof=1) / math.sqrt(len(per[ref]))
        line = [f"{rname:>14} {npx:6d} px"]
        for k, p in per.items():
            m, se = p.mean(0), p.std(0, ddof=1) / math.sqrt(len(p))
            entry = {"mean": m.tolist(), "se": se.tolist()}
            cells = " ".join(f"{m[c]:.5f}±{se[c]:.5f}" for c in range(3))
            if k != ref:
                diff = m - mr
                dse = np.sqrt(se ** 2 + ser ** 2)
                rel = diff / np.where(mr != 0, mr, 1)
                rel_se = dse / np.where(mr != 0, np.abs(mr), 1)
                t = np.where(dse > 0, diff / np.where(dse > 0, dse, 1), 0)
                entry.update(diff=diff.tolist(), diff_se=dse.tolist(), rel=rel.tolist(),
                             rel_se=rel_se.tolist(), t=t.tolist())
                cells += "  Δ " + " ".join(f"{chans[c]} {100 * rel[c]:+.2f}±{100 * rel_se[c]:.2f}% "
                                            f"(t {t[c]:+.1f})" for c in range(3))
            row["sets"][k] = entry
            line.append(f"  {k}: {cells}")
        print("\n".join(line))
        out.append(row)
    if args.json:
        Path(args.json).write_text(json.dumps({"ref": ref, "regions": out}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
