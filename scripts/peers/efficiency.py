#!/usr/bin/env python3
"""Efficiency of a renderer on a scene: 1 / (mean per-pixel variance x seconds per render).

    efficiency.py A.pfm B.pfm --seconds 3.42 [--label "mitsuba ldsampler"] [--json]
    efficiency.py A.pfm B.pfm --seconds 3.42 --seconds 3.51     # mean of several timings

A and B are two renders of the same scene at the same spp with different
seeds (independent noise), linear RGB .pfm (or .exr where Mitsuba's Python
module is importable, as in compare.py). Their difference has twice the
variance of one render, so

    var = mean over pixels and R, G, B channels of (A - B)^2 / 2

estimates the mean per-pixel variance of one render (no tone mapping).
efficiency = 1 / (var * seconds): halving the noise variance or the time
doubles it; for an unbiased Monte Carlo renderer it does not depend on spp
(variance ~ 1/spp, time ~ spp), so it compares renderers at equal quality.
The standard error of var is estimated from the spread of the per-pixel
terms (pixels are independent); it is printed as a relative error.

Runs with plain Python + numpy (either peer venv works).
"""

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np


def read_image(path):
    """Linear RGB of a .pfm or .exr image: compare.py's reader."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from compare import read_image as read

    return read(str(path))


def variance(a, b):
    """(mean variance of one render, its relative standard error)."""
    if a.shape != b.shape:
        raise ValueError(f"image sizes differ: {a.shape} and {b.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("non-finite pixel values")
    d2 = (a - b) ** 2 / 2
    var = float(d2.mean())
    per_pixel = d2.mean(axis=2).ravel()  # channels of a pixel are correlated: pixel = unit
    se = float(per_pixel.std(ddof=1) / math.sqrt(per_pixel.size)) if per_pixel.size > 1 else float("nan")
    return var, (se / var if var > 0 else float("nan"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--seconds", type=float, action="append", required=True,
                    help="wall seconds of one render (repeat to average several)")
    ap.add_argument("--label", default="", help="text put before the numbers")
    ap.add_argument("--json", action="store_true", help="print a JSON object instead")
    args = ap.parse_args(argv)
    a, b = read_image(args.a), read_image(args.b)
    var, rel = variance(a, b)
    secs = sum(args.seconds) / len(args.seconds)
    eff = 1.0 / (var * secs) if var > 0 and secs > 0 else float("inf")
    means = [a.reshape(-1, 3).mean(0).tolist(), b.reshape(-1, 3).mean(0).tolist()]
    if args.json:
        print(json.dumps({"label": args.label, "a": args.a, "b": args.b, "seconds": secs,
                          "variance": var, "variance_rel_se": rel, "efficiency": eff,
                          "mean_a": means[0], "mean_b": means[1]}))
    else:
        print(f"{args.label}{' ' if args.label else ''}seconds {secs:.4g} variance {var:.5g} "
              f"(±{100 * rel:.1f}%) efficiency {eff:.5g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
