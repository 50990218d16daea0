#!/usr/bin/env python3
"""Markdown tables of gltf_compare.sh's results (the NAME-VARIANT.json files
gltf_analyze.py wrote), for docs/validation-gltf.md. numpy-free.

    gltf_tables.py OUT_DIR > OUT_DIR/report.md
"""

import json
import sys
from pathlib import Path


def fmt_mean(m, se):
    return ", ".join(f"{x:.4f}" for x in m) + " (± " + ", ".join(f"{s:.1e}" for s in se) + ")"


def image_table(out, name):
    rows = []
    for f in sorted(Path(out).glob(f"{name}-*.json")):
        v = f.stem[len(name) + 1:]
        if v.startswith("cycles") or "-vs-" in v:
            continue
        rows.append((v, json.loads(f.read_text())))
    if not rows:
        return ""
    s = [f"| set | R, G, B image mean (± s.e.) | lumen − Cycles (R, G, B) | t (R, G, B) | pixels \\|t\\| > 4 |",
         "| --- | --- | --- | --- | ---: |"]
    first = rows[0][1]["image"]
    s.append(f"| lumen ({rows[0][1]['n_a']} seeds) | {fmt_mean(first['mean_a'], first['se_a'])} | | | |")
    for v, d in rows:
        im = d["image"]
        s.append(f"| Cycles `{v}` ({d['n_b']} seeds) | {fmt_mean(im['mean_b'], im['se_b'])} | "
                 + ", ".join(f"{100 * r:+.2f}%" for r in im["rel"]) + " | "
                 + ", ".join(f"{t:+.0f}" for t in im["t"]) + f" | {100 * d['pixels_abs_t_gt_4']:.1f}% |")
    objs = [(v, d) for v, d in rows if d.get("object")]
    if objs:
        o = objs[0][1]["object"]
        s.append(f"| object pixels only ({o['pixels']}): lumen | {fmt_mean(o['mean_a'], o['se_a'])} | | | |")
    for v, d in objs:
        o = d["object"]
        if o:
            s.append(f"| object pixels only: Cycles `{v}` | {fmt_mean(o['mean_b'], o['se_b'])} | "
                     + ", ".join(f"{100 * r:+.2f}%" for r in o["rel"]) + " | "
                     + ", ".join(f"{t:+.0f}" for t in o["t"]) + " | |")
    return "\n".join(s) + "\n"


def grid_table(d, row_names, col_names, key, fmt="{:+.1f}"):
    by = {r["region"]: r for r in d["regions"]}
    s = ["| | " + " | ".join(col_names) + " |", "| --- |" + " ---: |" * len(col_names)]
    for rn, rkeys in row_names:
        cells = []
        for ck in rkeys:
            parts = [by[k][key] * 100 if k in by else float("nan") for k in ck]
            cells.append(" / ".join(fmt.format(p) for p in parts))
        s.append(f"| {rn} | " + " | ".join(cells) + " |")
    return "\n".join(s) + "\n"


def spheres(d):
    rows = []
    for j in range(6, -1, -1):
        rows.append((f"metallic {j}/6", [[f"m{j}/6 r{i}/6 inner", f"m{j}/6 r{i}/6 ring"] for i in range(7)]))
    return grid_table(d, rows, [f"r {i}/6" for i in range(7)], "rel_lum")


def tiles(d):
    names = ["ior 2.42", "ior 1.76", "ior 1.5", "ior 1.33", "ior 1.0", "mirror"]
    rows = [(n, [[f"{n} col{k}"] for k in range(9)]) for n in names]
    return grid_table(d, rows, [f"c{k}" for k in range(9)], "rel_lum")


def transmission(d):
    cols = ["yellow", "green mask", "red tex", "blue mask+tex"]
    rows = [(r, [[f"{r} {c} inner", f"{r} {c} ring"] for c in cols]) for r in ("smooth", "rough", "metal")]
    return grid_table(d, rows, cols, "rel_lum")


def slabs(d):
    a, b = d["a"], d["b"]
    s = [f"| slab | {a} | {b} | ({a} − {b}) / {b} |", "| --- | ---: | ---: | ---: |"]
    for r in d["regions"]:
        a = ", ".join(f"{x:.3f}" for x in r["mean_a"])
        b = ", ".join(f"{x:.3f}" for x in r["mean_b"])
        s.append(f"| {r['region']} | {a} | {b} | {100 * r['rel_lum']:+.1f}% |")
    return "\n".join(s) + "\n"


def blocks(d, n=6):
    rs = sorted(d["regions"], key=lambda r: abs(r["rel_lum"]), reverse=True)[:n]
    return "largest blocks: " + "; ".join(f"{r['region']} {100 * r['rel_lum']:+.2f}% (t {r['t_lum']:+.0f})" for r in rs) + "\n"


KIND = {"spheres": spheres, "transmission_roughness": tiles, "transmission": transmission, "slabs": slabs}


def main(out):
    out = Path(out)
    names = sorted({f.name.split("-")[0] for f in out.glob("*-lumen-times.txt")})
    for name in names:
        print(f"## {name}\n")
        print(image_table(out, name))
        for f in sorted(out.glob(f"{name}-*.json")):
            v = f.stem[len(name) + 1:]
            if v.startswith("cycles"):
                continue
            d = json.loads(f.read_text())
            pr = d.get("pixel_rel_lum", {})
            print(f"### {d['a']} against {d['b']}\n")
            print(f"per pixel (A−B)/B of luminance: 5th percentile {100 * pr.get('p5', 0):+.1f}%, "
                  f"median {100 * pr.get('p50', 0):+.1f}%, 95th {100 * pr.get('p95', 0):+.1f}%; "
                  f"|.| > 5% in {100 * pr.get('frac_abs_gt_5pct', 0):.1f}% of pixels\n")
            fn = KIND.get(name)
            print(fn(d) if fn else blocks(d))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
