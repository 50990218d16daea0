#!/usr/bin/env python3
"""lumen + Open Image Denoise against Blender Cycles + its own OIDN: the
same scenes at the same sample counts, measured against lumen's converged
image (and Cycles' also against its own where the two converged images
differ).

For each scene:

1. Reference: lumen at --reference-spp (seed 7919, so that no test render
   shares its samples), kept in --cache under denoise-bench.py's name
   (SCENE-WIDTH-SPP.exr): the two scripts share references. Rendered
   under nice to SCENE-WIDTH-SPP.part.exr with a checkpoint every 10
   minutes; a render stopped with its checkpoint left is resumed.
2. Agreement: lumen and Cycles without denoising at --compare-spp (1,024 by
   default), kept in --cache. Cycles' per-channel means over the
   reference's must be within ~1-2 %, or the comparison is meaningless.
   Printed with the HDR-FLIP of both against the reference. With
   --cycles-reference-spp, Cycles' own converged image (seed 7919) too:
   what is left between the two converged images puts a floor under
   Cycles' FLIP against lumen's reference (gltf-models at 320 px: Cycles
   at 1,024 spp has FLIP 0.020 against lumen's reference, two Cycles
   1,024-spp images 0.004 against each other, lumen's 1,024 spp 0.0035;
   the difference is on the normal-mapped dome rims of
   NormalTangentMirrorTest, darker in Cycles, and on ClearCoatTest's
   coated tiles, brighter in Cycles), so Cycles' FLIP is also given
   against its own reference. The Cornell box has no such floor (at 64 px,
   16,384 spp: means within 0.02 %; Cycles' 1,024-spp FLIP 0.0335 against
   lumen's reference, 0.0340 against its own), so by default only
   gltf-models gets a Cycles reference.
3. Ladders (timed; never cached): at 4, 8, 16, ... up to --ladder-max and
   at every --spp, lumen with --denoise (its noisy and denoised images),
   Cycles denoised, and at every --spp Cycles noisy. lumen's ladder stops
   once every --spp is done and its denoised FLIP is at or below the FLIP
   of both renderers' undenoised --compare-spp images; Cycles' once its
   denoised FLIP (against its own reference if it has one) is at or below
   lumen's denoised FLIP at every --spp too, so that the time Cycles needs
   for it can be read off.

Each image: relMSE, PSNR, HDR-FLIP and channel means against the
reference (denoise-bench.py's metrics), and its times:
  - lumen: the whole `lumen render` process, wall clock, measured here
    ("wall": scene and texture loading, BVH, render, denoise, writing the
    images), and lumen's own `time` (render passes) + `denoised in`;
  - Cycles: bpy.ops.render.render() measured in the Cycles process (scene
    sync, image loading, the sky's importance map, BVH, render, OIDN),
    excluding Blender's start-up, the scene's construction and the glTF
    import. Each Cycles image is rendered by a fresh process, as each lumen
    image is (--cycles-warm: a warm-up render first, then the timed one).
    Under assets/sky.hdr (256 x 128), Cycles' default importance map
    (world sampling AUTOMATIC) takes 2.5-4.5 s of every render call on
    this 2-core machine, even at 32 x 16 px and 1 spp (MANUAL at 1,024: 0.3
    s; at 256: 0.02 s): that fixed cost dominates Cycles' low-spp times on
    gltf-models. It is Cycles' default and is kept; --cycles-world-map N
    measures without it.
  - Cycles' glTF import (bpy.ops.import_scene.gltf, timed in the Cycles
    process: the JSON, meshes and materials; textures are decoded in the
    render call), reported as import_s.
The times compared: lumen wall against Cycles' render call (lumen carries
its process start, scene parsing and image writing, Cycles does not),
lumen wall against Cycles' import + render call (both from the files to
the image, but for Cycles' scene construction and Blender's start), and
lumen time + denoise against the same Cycles call (Cycles carries its sync
and BVH build, lumen does not). The truth is between the two ratios.

Results:
  - per spp, every image's metrics and times (markdown);
  - the spp at which each renderer's denoised image first reaches a FLIP
    at or below lumen's, and Cycles', undenoised --compare-spp image;
  - for each lumen denoised point, the time Cycles + OIDN needs for the
    same FLIP, log-log interpolated (log time against log FLIP) between
    the points of Cycles' denoised ladder that bracket it, and the ratio
    lumen / Cycles (the aim: at most 0.5);
  - all numbers in --cache/denoise-cycles-WIDTH.json.

Scenes: cornell-box (lumen's built-in, as `lumen scenes export` writes it
for cycles_cornell.py: light two-sided, both sides sampled; lumen with
--integrator path --sampler zsobol, its best, instead of the book's
bsdf/independent) and gltf-models (examples/gltf-models.toml: Khronos
NormalTangentMirrorTest and ClearCoatTest under assets/sky.hdr; for
cycles_gltf.py the file is copied with absolute file paths, `lumen:` naming
the assets folder, and the models' Principled BSDFs set to single-scattering
GGX, the glTF model, docs/validation-gltf.md; the 8-bit textures are left
as Cycles keeps them, interpolated before their sRGB decoding (0.02-0.1 %
in the image means of the validated models): --cycles-linear-textures
decodes them first, at the price of float textures in Cycles' sync).

Cycles settings (cycles_common.configure, then): CPU, --threads threads,
samples = spp exactly (adaptive sampling off), seed 0, sampling pattern
--cycles-pattern (AUTOMATIC: a new scene's default, blue noise in final
renders, as lumen's zsobol), pixel filter box 1 px (lumen's), no clamping,
light tree on, bounces max_depth - 2 (the same paths as lumen's
max_depth), view transform Standard, exposure 0 (the EXR is linear). When
denoised: use_denoising, denoiser OPENIMAGEDENOISE on the CPU, input passes
RGB_ALBEDO_NORMAL, prefilter ACCURATE, quality HIGH: OIDN RT, HDR, albedo
and normal prefiltered and then clean, as lumen's (whose prefilters run at
balanced quality). --cycles-prefilter FAST (the guides go to the image's
filter as they are: one filter run where ACCURATE makes three) and
--cycles-quality BALANCED measure Cycles' cheaper settings; --lumen-prefilter
none lumen's (`--denoise-prefilter none`: one filter run, as Cycles' FAST).

usage: scripts/peers/denoise_cycles.py LUMEN [--scenes cornell-box,gltf-models]
       [--width 320] [--spp 16,64,256] [--reference-spp 16384] [--cache DIR]
       [--compare-spp 1024] [--ladder-max 1024]
       [--cycles-reference-spp gltf-models=16384] [--prepare] [--nice]
--prepare renders and checks only what is cached (references, the
--compare-spp images) and prints the agreement: run it first, on a quiet
machine or not; the timed ladders want a quiet one.

Requirements: a lumen built with the `oidn` feature and OIDN_DIR set
(docs/denoising.md); run by the Python of scripts/peers/setup.sh (numpy,
mitsuba to read EXR, flip-evaluator), with $LUMEN_CYCLES_PYTHON from
scripts/peers/setup_cycles.sh --env (bpy) in the environment:

    export OIDN_DIR=...
    eval "$(scripts/peers/setup.sh --env)"; eval "$(scripts/peers/setup_cycles.sh --env)"
    $LUMEN_PEERS_PYTHON scripts/peers/denoise_cycles.py target/release/lumen --prepare
    $LUMEN_PEERS_PYTHON scripts/peers/denoise_cycles.py target/release/lumen
"""
import argparse
import importlib.util
import json
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
REF_SEED = 7919
SCENES = {
    # name: lumen scene, lumen's extra arguments, the Cycles translation
    "cornell-box": {"lumen": "cornell-box", "args": ["--integrator", "path", "--sampler", "zsobol"],
                    "cycles": "cornell"},
    "gltf-models": {"lumen": "examples/gltf-models.toml", "args": [], "cycles": "gltf"},
}


# ------------------------------------------------------------ Cycles side
def cycles_render(job):
    """Runs in $LUMEN_CYCLES_PYTHON: build the scene, render once (timed),
    write the EXR, print one JSON line."""
    sys.path.insert(0, str(HERE))
    import bpy
    if job["kind"] == "cornell":
        import cycles_cornell as m
        lscene = m.read_scene(job["file"], False)
        scene, _, _ = m.build(lscene, job["width"], job["spp"], job["seed"], job["threads"],
                                       True, job["pattern"], lscene["render"]["max_depth"], True,
                                       "FRONT")
    else:
        import cycles_gltf as m
        args = argparse.Namespace(scene=job["file"], width=job["width"], max_depth=None,
                                  spp=job["spp"], seeds=None, seed=job["seed"],
                                  threads=job["threads"], rr="on", pattern=job["pattern"],
                                  sky_only=False, linear_textures=job["linear_textures"],
                                  tint_per_interface=False, distribution=job["distribution"])
        scene, _ = m.build(args)
        if job.get("world_map"):
            scene.world.cycles.sampling_method = "MANUAL"
            scene.world.cycles.sample_map_resolution = job["world_map"]
    c = scene.cycles
    c.use_adaptive_sampling = False
    c.samples = job["spp"]
    c.use_denoising = job["denoise"]
    scene.view_layers[0].cycles.use_denoising = job["denoise"]
    c.denoiser = "OPENIMAGEDENOISE"
    c.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    c.denoising_prefilter = job.get("prefilter", "ACCURATE")
    if hasattr(c, "denoising_quality"):
        c.denoising_quality = job.get("quality", "HIGH")
    if hasattr(c, "denoising_use_gpu"):
        c.denoising_use_gpu = False
    if job.get("warm"):
        bpy.ops.render.render(write_still=False)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - t0
    bpy.data.images["Render Result"].save_render(filepath=job["out"], scene=scene)
    print(json.dumps({
        "render_s": seconds, "import_s": getattr(m, "IMPORT_SECONDS", 0.0),
        "blender": bpy.app.version_string,
        "settings": {"samples": c.samples, "seed": c.seed, "adaptive": c.use_adaptive_sampling,
                     "pattern": c.sampling_pattern, "filter": [c.pixel_filter_type, c.filter_width],
                     "max_bounces": c.max_bounces, "light_tree": c.use_light_tree,
                     "denoise": c.use_denoising, "denoiser": c.denoiser,
                     "passes": c.denoising_input_passes, "prefilter": c.denoising_prefilter,
                     "quality": getattr(c, "denoising_quality", None),
                     "threads": scene.render.threads,
                     "world_sampling": None if scene.world is None else
                     [scene.world.cycles.sampling_method, scene.world.cycles.sample_map_resolution],
                     "view_transform": scene.view_settings.view_transform,
                     "exposure": scene.view_settings.exposure}}), flush=True)


# ------------------------------------------------------------ driver side
def load_bench():
    """denoise-bench.py's rgb() and metrics() (its file name is no module name)."""
    spec = importlib.util.spec_from_file_location("denoise_bench", ROOT / "scripts" / "denoise-bench.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def scene_path(scene):
    p = ROOT / scene
    return str(p) if p.exists() else scene


def run_lumen(a, name, spp, out, denoise, seed=None, nice=False, extra=()):
    s = SCENES[name]
    command = [a.lumen, "render", scene_path(s["lumen"]), "--width", str(a.width), "--spp", str(spp),
               "--threads", str(a.threads), "-o", out] + list(extra or ["--checkpoint-interval", "1h"]) \
        + s["args"]
    if seed is not None:
        command += ["--seed", str(seed)]
    if denoise:
        command.append("--denoise")
        if a.lumen_prefilter:
            command += ["--denoise-prefilter", a.lumen_prefilter]
    if a.nice or nice:
        command = ["nice", "-n", "19"] + command
    t0 = time.perf_counter()
    seconds, denoise_s = a.bench.run_render(command)
    wall = time.perf_counter() - t0
    return {"wall_s": wall, "time_s": seconds, "denoise_s": denoise_s}


def cycles_file(a, name):
    """The scene file cycles_cornell.py / cycles_gltf.py reads, in the cache."""
    s = SCENES[name]
    out = os.path.join(a.cache, f"{name}.cycles.toml")
    if s["cycles"] == "cornell":
        subprocess.run([a.lumen, "scenes", "export", s["lumen"], "-o", out], check=True,
                       capture_output=True)
        return out
    src = Path(scene_path(s["lumen"])).resolve()

    def absolute(m):
        f = m.group(2)
        if f.startswith("lumen:"):
            f = str(ROOT / "assets" / f[len("lumen:"):])
        elif not os.path.isabs(f):
            f = str((src.parent / f).resolve())
        return f'{m.group(1)}"{f}"'
    text = re.sub(r'^(\s*file\s*=\s*)"([^"]*)"', absolute, src.read_text(), flags=re.M)
    Path(out).write_text(text)
    return out


def run_cycles(a, name, spp, out, denoise, seed=0, nice=False):
    s = SCENES[name]
    job = {"kind": s["cycles"], "file": a.cycles_files[name], "width": a.width, "spp": spp,
           "seed": seed, "threads": a.threads, "pattern": a.cycles_pattern, "denoise": denoise,
           "out": os.path.abspath(out), "warm": a.cycles_warm,
           "distribution": a.cycles_distribution, "linear_textures": a.cycles_linear_textures,
           "world_map": a.cycles_world_map, "prefilter": a.cycles_prefilter,
           "quality": a.cycles_quality}
    command = [a.cycles_python, str(Path(__file__).resolve()), "--cycles-render", json.dumps(job)]
    if a.nice or nice:
        command = ["nice", "-n", "19"] + command
    t0 = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    lines = [x for x in done.stdout.splitlines() if x.startswith("{")]
    if done.returncode != 0 or not lines:
        sys.exit(f"Cycles {name} {spp} spp failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    r = json.loads(lines[-1])
    a.cycles_settings = r["settings"]
    a.blender = r["blender"]
    return {"render_s": r["render_s"], "import_s": r.get("import_s", 0.0), "process_wall_s": wall}


def cached(path, make):
    """`make()`'s times, kept beside the image as PATH.json; the image and
    its times are made once."""
    meta = path + ".json"
    if os.path.exists(path) and os.path.exists(meta):
        return json.loads(Path(meta).read_text()) | {"cached": True}
    times = make()
    Path(meta).write_text(json.dumps(times))
    return times


def measure(a, path, refs):
    """The image's metrics against each reference in `refs` (name: image)."""
    image = a.bench.rgb(path)
    out = {}
    for ref_name, ref in refs.items():
        rel, psnr, flip, means = a.bench.metrics(image, ref)
        out[ref_name] = {"relmse": float(rel), "psnr": float(psnr), "flip": float(flip),
                         "means": [float(x) for x in means]}
    return out


def interpolate_time(points, flip):
    """Time to reach `flip` on a ladder of (flip, seconds), in spp order:
    log seconds linear in log FLIP between the first point at or below it
    and the one before. Returns (seconds, how): how is 'interpolated',
    'at most' (the first point already reaches it) or 'more than' (none
    does; seconds of the last)."""
    for i, (f, t) in enumerate(points):
        if f <= flip:
            if i == 0:
                return t, "at most"
            f0, t0 = points[i - 1]
            if f0 == f:
                return t, "interpolated"
            x = (math.log(flip) - math.log(f0)) / (math.log(f) - math.log(f0))
            return math.exp(math.log(t0) + x * (math.log(t) - math.log(t0))), "interpolated"
    return (points[-1][1] if points else float("nan")), "more than"


def fmt_means(m):
    return ", ".join(f"{v:.4f}" for v in m)


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--cycles-render":
        cycles_render(json.loads(sys.argv[2]))
        return
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("lumen")
    p.add_argument("--scenes", default="cornell-box,gltf-models")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--spp", default="16,64,256", help="the sample counts of the main table")
    p.add_argument("--reference-spp", type=int, default=16384)
    p.add_argument("--compare-spp", type=int, default=1024,
                   help="the undenoised images whose FLIP the denoised ladders aim at")
    p.add_argument("--ladder-max", type=int, default=1024, help="the ladders' last spp")
    p.add_argument("--cycles-reference-spp", default="gltf-models=16384",
                   help="Cycles' own reference: N for every scene, or SCENE=N,... (0 or absent: none); "
                        "by default for gltf-models, where Cycles' converged image differs from lumen's "
                        "enough to put a floor of about 0.02 under its FLIP at 320 px")
    p.add_argument("--cache", default="denoise-bench")
    p.add_argument("--threads", type=int, default=2, help="worker threads of both renderers")
    p.add_argument("--cycles-pattern", default="AUTOMATIC")
    p.add_argument("--cycles-distribution", default="GGX", choices=["import", "GGX", "MULTI_GGX"],
                   help="glTF scenes: the Principled BSDFs' distribution (glTF: single-scattering GGX)")
    p.add_argument("--cycles-linear-textures", action="store_true",
                   help="glTF scenes: decode 8-bit sRGB textures to float first (interpolated as "
                        "lumen does; Cycles then holds and syncs float textures)")
    p.add_argument("--cycles-world-map", type=int, default=0,
                   help="glTF scenes: the sky's importance map MANUAL at this resolution (0: Cycles' "
                        "default, AUTOMATIC, whose map costs seconds in every render call here)")
    p.add_argument("--lumen-prefilter", choices=["high", "balanced", "fast", "none"],
                   help="lumen's --denoise-prefilter (default: lumen's, balanced)")
    p.add_argument("--cycles-prefilter", default="ACCURATE", choices=["ACCURATE", "FAST", "NONE"],
                   help="Cycles' denoising prefilter (ACCURATE: albedo and normal prefiltered, "
                        "as lumen's; FAST: passed to the image's filter as they are)")
    p.add_argument("--cycles-quality", default="HIGH", choices=["HIGH", "BALANCED", "FAST"],
                   help="Cycles' denoising quality (OIDN's, for every filter it runs)")
    p.add_argument("--cycles-warm", action="store_true",
                   help="a warm-up Cycles render before each timed one, in the same process")
    p.add_argument("--prepare", action="store_true",
                   help="only the cached images (references, --compare-spp) and the agreement check")
    p.add_argument("--nice", action="store_true", help="run every render under nice -n 19")
    a = p.parse_args()
    a.cycles_python = os.environ.get("LUMEN_CYCLES_PYTHON")
    if not a.cycles_python:
        sys.exit("LUMEN_CYCLES_PYTHON is not set: eval \"$(scripts/peers/setup_cycles.sh --env)\"")
    a.lumen = os.path.abspath(a.lumen) if os.path.sep in a.lumen else a.lumen
    a.bench = load_bench()
    a.cycles_settings, a.blender = None, None
    v = a.cycles_reference_spp
    a.cycles_reference = ({k: int(n) for k, n in (x.split("=") for x in v.split(","))} if "=" in v
                          else {name: int(v) for name in a.scenes.split(",")})
    os.makedirs(a.cache, exist_ok=True)
    spps = sorted({int(s) for s in a.spp.split(",")})
    ladder = sorted(set(spps) | {2 ** k for k in range(2, 40) if 2 ** k <= a.ladder_max})
    results = {"width": a.width, "spp": spps, "reference_spp": a.reference_spp,
               "compare_spp": a.compare_spp, "threads": a.threads, "loadavg_start": os.getloadavg(),
               "scenes": {}}
    a.cycles_files = {}
    for name in a.scenes.split(","):
        a.cycles_files[name] = cycles_file(a, name)
        results["scenes"][name] = scene_result(a, name, spps, ladder)
        results["scenes"][name]["cycles_settings"] = a.cycles_settings
        results["blender"] = a.blender
        out = os.path.join(a.cache, f"denoise-cycles-{a.width}{'-prepare' if a.prepare else ''}.json")
        Path(out).write_text(json.dumps(results, indent=1))
    results["loadavg_end"] = os.getloadavg()
    Path(out).write_text(json.dumps(results, indent=1))
    print(f"\nwrote {out}")


def scene_result(a, name, spps, ladder):
    c = a.cache
    w = a.width
    base = os.path.join(c, f"{name}-{w}")
    res = {"lumen_args": SCENES[name]["args"]}
    # 1. references
    ref_path = f"{base}-{a.reference_spp}.exr"
    if not os.path.exists(ref_path):
        # rendered to a part file, checkpointed every 10 minutes; a stopped
        # render (its checkpoint left) is resumed
        part = f"{base}-{a.reference_spp}.part.exr"
        resume = os.path.exists(part + ".lumen-ckpt")
        print(f"{name}: lumen reference, {a.reference_spp} spp{' (resumed)' if resume else ''} ...",
              file=sys.stderr, flush=True)
        t = run_lumen(a, name, a.reference_spp, part, False, seed=REF_SEED, nice=True,
                      extra=["--checkpoint-interval", "10m"] + (["--resume"] if resume else []))
        os.replace(part, ref_path)
        Path(ref_path + ".json").write_text(json.dumps(t | {"resumed": resume}))
    refs = {"lumen_ref": a.bench.rgb(ref_path)}
    res["reference"] = {"path": ref_path, "means": refs["lumen_ref"].mean(axis=(0, 1)).tolist()}
    cref_spp = a.cycles_reference.get(name, 0)
    res["cycles_reference_spp"] = cref_spp
    if cref_spp:
        cref_path = f"{base}-{cref_spp}.cycles.exr"
        print(f"{name}: Cycles reference, {cref_spp} spp ...", file=sys.stderr, flush=True)
        cached(cref_path, lambda: run_cycles(a, name, cref_spp, cref_path, False, seed=REF_SEED, nice=True))
        refs["cycles_ref"] = a.bench.rgb(cref_path)
        res["cycles_reference"] = {"path": cref_path,
                                   "vs_lumen_ref": measure(a, cref_path, {"lumen_ref": refs["lumen_ref"]})}
    # 2. agreement at --compare-spp, undenoised
    n = a.compare_spp
    lp, cp = f"{base}-{n}.lumen-noisy.exr", f"{base}-{n}.cycles-noisy.exr"
    print(f"{name}: lumen and Cycles at {n} spp, undenoised ...", file=sys.stderr, flush=True)
    lt = cached(lp, lambda: run_lumen(a, name, n, lp, False, nice=True))
    ct = cached(cp, lambda: run_cycles(a, name, n, cp, False, nice=True))
    res["compare"] = {"lumen": {"times": lt, **measure(a, lp, refs)},
                      "cycles": {"times": ct, **measure(a, cp, refs)}}
    cm = res["compare"]["cycles"]["lumen_ref"]["means"]
    print(f"\n### {name}, {w} px: agreement at {n} spp, undenoised\n")
    print("| image | against | mean R, G, B / reference's | FLIP | relMSE |")
    print("| --- | --- | --- | ---: | ---: |")
    rows = [(f"lumen {n} spp", res["compare"]["lumen"]), (f"Cycles {n} spp", res["compare"]["cycles"])]
    if "cycles_reference" in res:
        rows.append((f"Cycles {cref_spp} spp", res["cycles_reference"]["vs_lumen_ref"]))
    for label, r in rows:
        for ref_name in ("lumen_ref", "cycles_ref"):
            if ref_name in r:
                m = r[ref_name]
                print(f"| {label} | {ref_name.replace('_', ' ')} | {fmt_means(m['means'])} | "
                      f"{m['flip']:.4f} | {m['relmse']:.5f} |")
    ok = all(abs(x - 1) <= 0.02 for x in cm)
    res["agree"] = ok
    print(f"\nCycles / lumen means {fmt_means(cm)}: {'within' if ok else 'NOT within'} 2 %", flush=True)
    if a.prepare:
        return res
    # 3. ladders
    targets = {"lumen": res["compare"]["lumen"]["lumen_ref"]["flip"],
               "cycles": res["compare"]["cycles"]["lumen_ref"]["flip"]}
    own_target = res["compare"]["cycles"].get("cycles_ref", {}).get("flip")
    lumen_pts, cycles_pts = [], []
    for spp in ladder:
        out = f"{base}-{spp}.lumen.exr"
        t = run_lumen(a, name, spp, out, True)
        pt = {"spp": spp, "times": t, "noisy": measure(a, out[:-4] + ".noisy.exr", refs),
              "denoised": measure(a, out, refs)}
        lumen_pts.append(pt)
        print(f"  lumen {spp} spp: denoised FLIP {pt['denoised']['lumen_ref']['flip']:.4f}, "
              f"wall {t['wall_s']:.2f} s", file=sys.stderr, flush=True)
        if spp >= spps[-1] and pt["denoised"]["lumen_ref"]["flip"] <= min(targets.values()):
            break
    lumen_goal = min([p["denoised"]["lumen_ref"]["flip"] for p in lumen_pts if p["spp"] in spps]
                     + list(targets.values()))
    for spp in ladder:
        out = f"{base}-{spp}.cycles.exr"
        t = run_cycles(a, name, spp, out, True)
        pt = {"spp": spp, "times": t, "denoised": measure(a, out, refs)}
        if spp in spps:
            noisy = f"{base}-{spp}.cycles-noisy.exr"
            pt["noisy_times"] = run_cycles(a, name, spp, noisy, False)
            pt["noisy"] = measure(a, noisy, refs)
        cycles_pts.append(pt)
        print(f"  Cycles {spp} spp: denoised FLIP {pt['denoised']['lumen_ref']['flip']:.4f}, "
              f"render {t['render_s']:.2f} s", file=sys.stderr, flush=True)
        # against its own reference when it has one: lumen's may be out of reach
        ref = "lumen_ref" if own_target is None else "cycles_ref"
        goal = lumen_goal if own_target is None else min(lumen_goal, own_target)
        done = spp >= spps[-1] and pt["denoised"][ref]["flip"] <= goal
        if done:
            break
    res["lumen"], res["cycles"] = lumen_pts, cycles_pts
    report(a, name, res, spps, targets, own_target)
    return res


def report(a, name, res, spps, targets, own_target):
    lumen_pts, cycles_pts = res["lumen"], res["cycles"]
    print(f"\n### {name}, {a.width} px: per spp (FLIP etc. against lumen's {a.reference_spp}-spp reference"
          + (f"; Cycles' also against its own {res['cycles_reference_spp']}-spp one" if own_target else "")
          + ")\n")
    print("| spp | renderer | image | relMSE | PSNR dB | FLIP | FLIP own ref | mean R, G, B | "
          "lumen wall s | lumen time + denoise s | Cycles render call s |")
    print("| ---: | --- | --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: |")
    for spp in spps:
        lp = next((p for p in lumen_pts if p["spp"] == spp), None)
        cp = next((p for p in cycles_pts if p["spp"] == spp), None)
        if lp:
            t = lp["times"]
            for label in ("noisy", "denoised"):
                m = lp[label]["lumen_ref"]
                wall = f"{t['wall_s']:.2f}" if label == "denoised" else ""
                td = t["time_s"] + (t["denoise_s"] or 0) if label == "denoised" else t["time_s"]
                print(f"| {spp} | lumen | {label} | {m['relmse']:.5f} | {m['psnr']:.2f} | {m['flip']:.4f} | "
                      f"| {fmt_means(m['means'])} | {wall} | {td:.2f} | |")
        if cp:
            for label, tk in (("noisy", "noisy_times"), ("denoised", "times")):
                if label not in cp:
                    continue
                m = cp[label]["lumen_ref"]
                own = f"{cp[label]['cycles_ref']['flip']:.4f}" if "cycles_ref" in cp[label] else ""
                print(f"| {spp} | Cycles | {label} | {m['relmse']:.5f} | {m['psnr']:.2f} | {m['flip']:.4f} | "
                      f"{own} | {fmt_means(m['means'])} | | | {cp[tk]['render_s']:.2f} |")
    # spp at which the denoised ladders reach the undenoised --compare-spp FLIPs
    n = a.compare_spp
    print(f"\n### {name}: first spp whose denoised FLIP is at or below an undenoised {n}-spp image's\n")
    print(f"| renderer + OIDN | ≤ lumen {n} spp ({targets['lumen']:.4f}) | "
          f"≤ Cycles {n} spp ({targets['cycles']:.4f}) |"
          + (f" own ref: ≤ Cycles {n} spp ({own_target:.4f}) | own ref: ≤ lumen {n} spp |"
             if own_target is not None else ""))
    print("| --- | ---: | ---: |" + (" ---: | ---: |" if own_target is not None else ""))
    res["reaches"] = {}
    for label, pts, own_key in (("lumen", lumen_pts, None), ("Cycles", cycles_pts, "cycles_ref")):
        row = {}
        for key, target, ref in (("lumen", targets["lumen"], "lumen_ref"),
                                 ("cycles", targets["cycles"], "lumen_ref"),
                                 ("own", own_target, own_key),
                                 ("own_lumen", targets["lumen"], own_key)):
            if key.startswith("own") and (own_key is None or own_target is None):
                continue
            hit = next((p for p in pts if p["denoised"][ref]["flip"] <= target), None)
            row[key] = hit["spp"] if hit else None
        res["reaches"][label] = row
        cell = lambda k: (str(row[k]) if row.get(k) else f"> {pts[-1]['spp']}") if k in row else "–"
        print(f"| {label} | {cell('lumen')} | {cell('cycles')} |"
              + (f" {cell('own')} | {cell('own_lumen')} |" if own_target is not None else ""))
    # the time Cycles needs for lumen's FLIP
    print(f"\n### {name}: time for the same FLIP (Cycles' time interpolated over its denoised ladder)\n")
    print("| lumen spp | lumen denoised FLIP | lumen wall s | lumen time + denoise s | "
          "Cycles s for that FLIP | wall / Cycles | (time + denoise) / Cycles |"
          + (" Cycles s, own ref | wall / Cycles, own ref |" if own_target is not None else "")
          + " Cycles import + render s | wall / that |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |" + (" ---: | ---: |" if own_target is not None else "")
          + " ---: | ---: |")
    res["same_flip"] = []
    cyc = [(p["denoised"]["lumen_ref"]["flip"], p["times"]["render_s"]) for p in cycles_pts]
    cyc_own = [(p["denoised"]["cycles_ref"]["flip"], p["times"]["render_s"]) for p in cycles_pts] \
        if own_target is not None else None
    # From the files to the image, as lumen's wall clock: Cycles' glTF import
    # (the glTF parsed, meshes and materials built; textures are decoded in
    # the render call) and its render call; its own reference if it has one.
    full_ref = "cycles_ref" if own_target is not None else "lumen_ref"
    cyc_full = [(p["denoised"][full_ref]["flip"], p["times"]["render_s"] + p["times"].get("import_s", 0.0))
                for p in cycles_pts]
    for lp in lumen_pts:
        f = lp["denoised"]["lumen_ref"]["flip"]
        wall = lp["times"]["wall_s"]
        td = lp["times"]["time_s"] + (lp["times"]["denoise_s"] or 0)
        tc, how = interpolate_time(cyc, f)
        row = {"spp": lp["spp"], "flip": f, "lumen_wall_s": wall, "lumen_time_denoise_s": td,
               "cycles_s": tc, "cycles_how": how, "ratio_wall": wall / tc, "ratio_time_denoise": td / tc}
        mark = {"interpolated": "", "at most": "≤ ", "more than": "> "}[how]
        rmark = {"interpolated": "", "at most": "≥ ", "more than": "< "}[how]
        line = (f"| {lp['spp']} | {f:.4f} | {wall:.2f} | {td:.2f} | {mark}{tc:.2f} | "
                f"{rmark}{wall / tc:.2f} | {rmark}{td / tc:.2f} |")
        if cyc_own is not None:
            to, how_o = interpolate_time(cyc_own, f)
            row.update(cycles_own_s=to, cycles_own_how=how_o, ratio_wall_own=wall / to)
            line += (f" {({'interpolated': '', 'at most': '≤ ', 'more than': '> '})[how_o]}{to:.2f} | "
                     f"{({'interpolated': '', 'at most': '≥ ', 'more than': '< '})[how_o]}{wall / to:.2f} |")
        tf, how_f = interpolate_time(cyc_full, f)
        row.update(cycles_import_render_s=tf, cycles_import_render_how=how_f,
                   ratio_wall_import_render=wall / tf)
        line += (f" {({'interpolated': '', 'at most': '≤ ', 'more than': '> '})[how_f]}{tf:.2f} | "
                 f"{({'interpolated': '', 'at most': '≥ ', 'more than': '< '})[how_f]}{wall / tf:.2f} |")
        res["same_flip"].append(row)
        print(line, flush=True)


if __name__ == "__main__":
    main()
