#!/usr/bin/env python3
"""A lumen sphere scene (scripts/peers/spheres-scene.toml), rendered with Mitsuba 3.

    eval "$(scripts/peers/setup.sh --env)"
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_spheres.py --spp 64 --seed 1 --out spheres.pfm
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_spheres.py --spp 64 --sampler ldsampler --rr-depth 5 \\
        --seeds 1 2 --out-template /tmp/m-{seed}.pfm        # warm-up, then 2 timed renders

Translation of the scene (read with tomllib, see docs/scene-format.md):

- sphere -> Mitsuba `sphere` (analytic: exact surface and normals).
- diffuse (lambertian, attenuation "scale") -> `diffuse` with reflectance = albedo.
- metal with fuzz 0 -> `conductor` with material "none" (eta 0, k 1: the
  Fresnel reflectance is 1 at every angle) and specular_reflectance = albedo,
  i.e. a perfect mirror that reflects exactly `albedo`.
- solid background colour C -> `constant` emitter of radiance C.
- camera: `perspective`, fov_axis "y", fov = vfov, look_at(lookfrom, lookat, vup);
  box pixel filter (lumen averages uniformly over each pixel).
- `path` integrator, max_depth = lumen's max_depth (both count ray segments,
  camera ray included: docs/peers.md). Russian roulette from depth
  `--rr-depth` (Mitsuba's default is 5; the default here, "off", puts it
  above max_depth, as lumen has none).

With --seeds, the scene is built once, rendered once at the first seed to
warm up (JIT compilation not counted), then once per seed, timed; the images
go to --out-template (with {seed} replaced) and one JSON line with the times
and load averages is printed last.
"""

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402

HERE = Path(__file__).resolve().parent


def build_scene(mi, scene, spp, sampler="independent", seed=0, rr_depth=None, max_depth=None):
    d = peerlib.mitsuba_path_scene(mi, scene, spp, sampler, seed, max_depth, rr_depth)
    d["sky"] = {"type": "constant",
                "radiance": {"type": "rgb", "value": peerlib.rgb(scene["background"]["color"])}}
    bsdfs = {}
    for name, m in scene["materials"].items():
        if m["type"] == "diffuse":
            bsdfs[name] = {"type": "diffuse",
                           "reflectance": {"type": "rgb", "value": peerlib.rgb(m["albedo"])}}
        else:  # metal, fuzz 0 (checked by read_lumen_scene)
            bsdfs[name] = {"type": "conductor", "material": "none",
                           "specular_reflectance": {"type": "rgb", "value": peerlib.rgb(m["albedo"])}}
    for i, o in enumerate(scene["objects"]):
        d[f"sphere{i}"] = {"type": "sphere", "center": [float(x) for x in o["center"]],
                           "radius": float(o["radius"]), "bsdf": bsdfs[o["material"]]}
    return mi.load_dict(d)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?", default=str(HERE / "spheres-scene.toml"))
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the single render (--out)")
    ap.add_argument("--out", help="render once at --seed and write this .pfm or .exr (linear RGB)")
    ap.add_argument("--seeds", type=int, nargs="+", help="timed mode: warm up, then render each seed")
    ap.add_argument("--out-template", help="timed mode: image path with {seed}, e.g. /tmp/m-{seed}.pfm")
    ap.add_argument("--sampler", choices=["independent", "stratified", "multijitter", "ldsampler"],
                    default="independent")
    ap.add_argument("--rr-depth", default="off",
                    help="Russian roulette from this depth (Mitsuba's default: 5); 'off' (default)")
    ap.add_argument("--max-depth", type=int, help="default: the scene's max_depth")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit worker threads (default: all cores)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args(argv)
    if not args.out and not args.seeds:
        ap.error("give --out (one render) or --seeds (timed renders)")

    scene = peerlib.read_lumen_scene(args.scene)
    spp = args.spp or scene["render"]["samples_per_pixel"]
    rr_depth = None if args.rr_depth == "off" else int(args.rr_depth)

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    if args.threads > 0:
        dr.set_thread_count(args.threads)

    t0 = time.perf_counter()
    seed0 = args.seeds[0] if args.seeds else args.seed
    ms = build_scene(mi, scene, spp, args.sampler, seed0, rr_depth, args.max_depth)
    t_build = time.perf_counter() - t0
    spp_used = ms.sensors()[0].sampler().sample_count()
    if spp_used != spp:
        print(f"note: the {args.sampler} sampler takes {spp_used} spp, not {spp}", file=sys.stderr)

    def render(seed):
        img = mi.render(ms, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return img

    def save(seed, img, path=None):
        path = Path(path or args.out_template.format(seed=seed))
        if path.suffix.lower() == ".pfm":
            peerlib.write_pfm(path, np.asarray(img))
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            mi.Bitmap(img).write(str(path))

    result = {"renderer": "mitsuba", "version": mi.__version__, "variant": mi.variant(),
              "scene": Path(args.scene).name, "width": scene["render"]["width"],
              "height": scene["render"]["height"], "spp": spp_used,
              "max_depth": args.max_depth or scene["render"]["max_depth"],
              "sampler": args.sampler, "rr_depth": args.rr_depth, "threads": dr.thread_count(),
              "build_s": round(t_build, 3)}
    if args.out:
        t0 = time.perf_counter()
        img = render(args.seed)
        t = time.perf_counter() - t0
        save(args.seed, img, args.out)
        a = np.asarray(img)
        print(f"wrote {args.out}: seed {args.seed}, {t:.2f} s (includes JIT), "
              f"mean {a[..., :3].reshape(-1, 3).mean(0).round(5).tolist()}", file=sys.stderr)
        result.update(seed=args.seed, first_render_s=round(t, 3))
    if args.seeds:
        if not args.out_template or "{seed}" not in args.out_template:
            ap.error("--seeds needs --out-template with {seed}")
        result.update(peerlib.timed_renders(render, args.seeds, save))
    peerlib.print_json(result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
