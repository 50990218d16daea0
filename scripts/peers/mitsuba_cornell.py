#!/usr/bin/env python3
"""A lumen scene of quads, boxes and lights (the Cornell box), rendered with Mitsuba 3.

    eval "$(scripts/peers/setup.sh --env)"
    lumen scenes export cornell-box -o /tmp/cornell.toml
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_cornell.py /tmp/cornell.toml --one-sided \\
        --width 200 --spp 1024 --seeds 0 1 2 3 --out-template /tmp/mc-{seed}.pfm

Translation (the scene read with tomllib, see docs/scene-format.md):

- quad (corner Q, edges u, v) -> `rectangle` whose to_world maps [-1, 1]^2 onto
  Q + s u + t v: columns u/2, v/2, the unit normal u x v, centre Q + (u + v)/2.
- box (min, max) -> `cube` ([-1, 1]^3) scaled by (max - min)/2 and moved to
  the box's centre; then the object's `transform` steps in order (rotate
  about an axis through the origin, counter-clockwise looking down the
  axis, in degrees; translate; scale), as lumen applies them.
- diffuse (lambertian, attenuation "scale") -> `twosided` `diffuse` of
  reflectance = albedo (lumen's diffuse surfaces reflect on both sides).
- emissive -> a black `twosided` diffuse with an `area` emitter of that
  radiance, which Mitsuba emits towards the shape's normal only: one-sided
  lights only, or --one-sided to make every light one-sided (the Cornell
  box's light faces down; its back faces the ceiling 1 unit above, which
  the one-sided light leaves dark).
- solid background: black only (Mitsuba would need a `constant` emitter).
- camera: `perspective`, fov_axis "y", box pixel filter; `path` integrator
  with max_depth = lumen's (both count ray segments, the camera ray and the
  shadow ray included); Russian roulette from depth --rr-depth (Mitsuba's
  default is 5; "off", the default here, puts it above max_depth).

The scene is built once; one render per seed, as .pfm (linear RGB) for
compare.py. With --timed, a warm-up render first (kernel compilation not
counted) and a JSON line of the per-seed times last, as the other peer
scripts print (efficiency.py turns two seeds' images and a time into an
efficiency).
"""

import argparse
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402


def read_scene(path, one_sided):
    scene = peerlib.fill_defaults(tomllib.loads(Path(path).read_text()))
    c = scene["camera"]
    if c.get("defocus_angle", 0.0) != 0.0:
        raise ValueError(f"{path}: only a pinhole camera is supported")
    bg = scene.get("background", {})
    if bg.get("type") != "solid" or any(x != 0 for x in bg.get("color", [1, 1, 1])):
        raise ValueError(f"{path}: only a black solid background is supported")
    for name, m in scene.get("materials", {}).items():
        if m["type"] == "diffuse":
            if m.get("bounce", "lambertian") != "lambertian" or m.get("attenuation", "scale") != "scale":
                raise ValueError(f"{path}: material {name}: only lambertian/scale diffuse")
        elif m["type"] == "emissive":
            if m.get("two_sided", False):
                if not one_sided:
                    raise ValueError(f"{path}: material {name} is two-sided: pass --one-sided")
                m["two_sided"] = False
        else:
            raise ValueError(f"{path}: material {name}: type {m['type']} not supported")
    for i, o in enumerate(scene.get("objects", [])):
        if o["type"] not in ("quad", "box"):
            raise ValueError(f"{path}: objects[{i}]: only quads and boxes are supported")
        if o["type"] == "quad" and o.get("transform"):
            raise ValueError(f"{path}: objects[{i}]: transformed quads are not supported")
    return scene


def placement(mi, steps):
    """lumen's transform steps, the first applied first, as one Mitsuba transform."""
    t = mi.ScalarTransform4f()
    for step in steps:
        if "translate" in step:
            t = mi.ScalarTransform4f().translate(step["translate"]) @ t
        elif "rotate" in step:
            rot = step["rotate"]
            t = mi.ScalarTransform4f().rotate(rot["axis"], rot["degrees"]) @ t
        elif "scale" in step:
            s = step["scale"]
            s = [s, s, s] if isinstance(s, (int, float)) else s
            t = mi.ScalarTransform4f().scale(s) @ t
        else:
            raise ValueError(f"transform step {step} not supported")
    return t


def build_scene(mi, scene, spp, seed, width, sampler="independent", rr_depth=None):
    d = peerlib.mitsuba_path_scene(mi, scene, spp, sampler, seed, rr_depth=rr_depth, width=width,
                                   clip=(1e-2, 1e6))

    def material(name):
        m = scene["materials"][name]
        if m["type"] == "diffuse":
            return {"bsdf": {"type": "twosided", "bsdf": {
                "type": "diffuse", "reflectance": {"type": "rgb", "value": peerlib.rgb(m["albedo"])}}}}
        return {"bsdf": {"type": "twosided", "bsdf": {
                    "type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}},
                "emitter": {"type": "area",
                            "radiance": {"type": "rgb", "value": peerlib.rgb(m["radiance"])}}}

    for i, o in enumerate(scene["objects"]):
        if o["type"] == "quad":
            q, u, v = (np.array(o[k], dtype=float) for k in ("corner", "u", "v"))
            n = np.cross(u, v)
            n /= np.linalg.norm(n)
            centre = q + (u + v) / 2
            m = np.identity(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, centre
            shape = {"type": "rectangle", "to_world": mi.ScalarTransform4f(m.tolist())}
        else:
            lo, hi = np.array(o["min"], dtype=float), np.array(o["max"], dtype=float)
            box = mi.ScalarTransform4f().translate(((lo + hi) / 2).tolist()) @ \
                mi.ScalarTransform4f().scale(((hi - lo) / 2).tolist())
            shape = {"type": "cube", "to_world": placement(mi, o.get("transform", [])) @ box}
        shape.update(material(o["material"]))
        d[f"object{i}"] = shape
    return mi.load_dict(d)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="a lumen TOML scene of quads, boxes, diffuse and emissive materials")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--width", type=int, help="image width (the height in proportion)")
    ap.add_argument("--seeds", type=int, nargs="+", required=True)
    ap.add_argument("--out-template", required=True, help="image path with {seed}, e.g. /tmp/m-{seed}.pfm")
    ap.add_argument("--one-sided", action="store_true", help="make two-sided lights one-sided")
    ap.add_argument("--sampler", choices=["independent", "stratified", "multijitter", "ldsampler"],
                    default="independent")
    ap.add_argument("--rr-depth", default="off",
                    help="Russian roulette from this depth (Mitsuba's default: 5); 'off' (default)")
    ap.add_argument("--timed", action="store_true", help="warm up, then time each seed's render")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit worker threads (default: all cores)")
    args = ap.parse_args(argv)
    scene = read_scene(args.scene, args.one_sided)

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    if args.threads > 0:
        dr.set_thread_count(args.threads)
    rr_depth = None if args.rr_depth == "off" else int(args.rr_depth)
    ms = build_scene(mi, scene, args.spp, args.seeds[0], args.width, args.sampler, rr_depth)

    def render(seed):
        img = mi.render(ms, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return img

    def save(seed, img):
        out = Path(args.out_template.format(seed=seed))
        peerlib.write_pfm(out, np.asarray(img))
        mean = np.asarray(img)[..., :3].reshape(-1, 3).mean(0)
        print(f"wrote {out}: seed {seed}, mean {mean.round(5).tolist()}", file=sys.stderr)

    if args.timed:
        result = {"renderer": "mitsuba", "version": mi.__version__, "variant": mi.variant(),
                  "scene": Path(args.scene).name, "spp": args.spp, "sampler": args.sampler,
                  "rr_depth": args.rr_depth, "threads": dr.thread_count()}
        result.update(peerlib.timed_renders(render, args.seeds, save))
        peerlib.print_json(result)
    else:
        for seed in args.seeds:
            t0 = time.perf_counter()
            img = render(seed)
            print(f"seed {seed}: {time.perf_counter() - t0:.2f} s", file=sys.stderr)
            save(seed, img)
    return 0


if __name__ == "__main__":
    sys.exit(main())
