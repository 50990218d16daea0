#!/usr/bin/env python3
"""Per-object means of several materials_compare.sh runs pooled (their seeds
must differ), lumen against each Mitsuba mode; with the diagnosis of the
first run (trace.txt, materials_probe trace), also lumen's means scaled by
what making its sampled directions unit length changes (as is -> unit), a
forecast of lumen once its directions are normalised.

    materials_pool.py SCENE.toml OUT_DIR [OUT_DIR ...] [--modes separable correlated lumencoat]

Prints Markdown tables (those of docs/validation-materials.md).
"""

import argparse
import math
import re
import sys
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402
from compare import read_image, welch  # noqa: E402
from materials_regions import region_ids  # noqa: E402

TITLE = {"separable": "stock Mitsuba (separable Smith G)",
         "correlated": "Mitsuba with height-correlated G (hcsmith, hcplastic)",
         "lumencoat": "Mitsuba with height-correlated G and lumen's coat tables"}


def renders(out, prefix):
    files = sorted(Path(out).glob(f"{prefix}-*.pfm"), key=lambda p: int(p.stem.rsplit("-", 1)[1]))
    return [f for f in files if re.fullmatch(rf"{re.escape(prefix)}-\d+", f.stem)]


def trace_ratios(out, scene):
    """material -> (unit / as is) per channel, from OUT/trace.txt."""
    path = Path(out) / "trace.txt"
    rows = {}
    if path.exists():
        for line in path.read_text().splitlines():
            m = re.match(r"object (\d+): .*?(, directions normalised)?: mean (\S+) (\S+) (\S+);", line)
            if m:
                rows.setdefault(int(m[1]), {})["unit" if m[2] else "asis"] = np.array(
                    [float(m[3]), float(m[4]), float(m[5])])
    return {scene["objects"][i]["material"]: r["unit"] / r["asis"]
            for i, r in rows.items() if "unit" in r and "asis" in r}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("outs", nargs="+")
    ap.add_argument("--modes", nargs="+", default=["separable", "correlated", "lumencoat"])
    args = ap.parse_args(argv)
    scene = peerlib.fill_defaults(tomllib.loads(Path(args.scene).read_text()))
    ids = region_ids(scene)
    regions = [("image", np.ones(ids.shape, bool))]
    for i, o in enumerate(scene["objects"]):
        if (ids == i).any():
            regions.append((o["material"], ids == i))
    regions.append(("edges", ids == -2))
    lfiles = [f for o in args.outs for f in renders(o, "lumen")]
    L = np.stack([read_image(str(f)) for f in lfiles])
    ratios = trace_ratios(args.outs[0], scene)
    f4 = lambda v: " / ".join(f"{x:.4f}" for x in v)  # noqa: E731
    for mode in args.modes:
        mfiles = [f for o in args.outs for f in renders(o, f"mitsuba-{mode}")]
        if not mfiles:
            continue
        M = np.stack([read_image(str(f)) for f in mfiles])
        print(f"\n#### lumen ({len(L)} renders) against {TITLE.get(mode, mode)} ({len(M)} renders)\n")
        head = "| region | lumen R / G / B | Mitsuba R / G / B | (lumen − Mitsuba)/Mitsuba R / G / B | z R / G / B |"
        rule = "| --- | --- | --- | --- | --- |"
        if ratios:
            head += " lumen with unit directions (forecast) − Mitsuba, R / G / B |"
            rule += " --- |"
        print(head)
        print(rule)
        for name, mask in regions:
            pa, pb = L[:, mask].mean(1), M[:, mask].mean(1)
            d, se, z, _ = welch(pa, pb)
            mb = pb.mean(0)
            row = (f"| {name} | {f4(pa.mean(0))} | {f4(mb)} | "
                   + " / ".join(f"{100 * x:+.3f} ± {100 * e:.3f}%" for x, e in zip(d / mb, se / mb)) + " | "
                   + " / ".join(f"{x:+.2f}" for x in z) + " |")
            if ratios:
                if name in ratios:
                    fc = pa.mean(0) * ratios[name]
                    row += " " + " / ".join(f"{100 * x:+.3f}%" for x in fc / mb - 1) + " |"
                else:
                    row += " |"
            print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
