#!/usr/bin/env python3
"""A lumen scene of quads, boxes and lights (the Cornell box), rendered with Blender Cycles.

    eval "$(scripts/peers/setup_cycles.sh --env)"
    lumen scenes export cornell-box -o /tmp/cornell.toml
    sed -i 's/two_sided = true/two_sided = false/; s/integrator = "bsdf"/integrator = "path"/' /tmp/cornell.toml
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_cornell.py /tmp/cornell.toml \\
        --width 200 --spp 1024 --seeds 0 1 2 3 --out-template /tmp/cc-{seed}.pfm
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_cornell.py /tmp/cornell.toml \\
        --width 300 --spp 64 --seeds 1 2 --timed --out-template /tmp/cc-{seed}.pfm

The scene is the one mitsuba_cornell.py reads (the same checks), translated
for Cycles in lumen's Y-up coordinates, every point mapped to Blender's Z-up
by (x, y, z) -> (x, -z, y) (cycles_common.py):

- quad (corner Q, edges u, v) -> a one-face mesh Q, Q + u, Q + u + v, Q + v:
  its front face (counter-clockwise corners) is the side u x v points to,
  lumen's front. Transform steps, if any, move its corners.
- box (min, max) -> a mesh of its 6 faces, outward fronts; the object's
  `transform` steps (rotate: right-handed about an axis through the origin,
  degrees; translate; scale; matrix: 3 x 4 row-major), in order, move its 8
  corners, as lumen applies them.
- diffuse (lambertian, attenuation "scale") -> Diffuse BSDF (roughness 0,
  Lambertian) of colour = albedo; Cycles surfaces scatter on both sides,
  as lumen's.
- emissive, one-sided -> Mix Shader of an Emission (colour = radiance,
  strength 1: on a mesh that is the radiance) on the front face and a black
  Emission on the back face, the mix factor being Geometry > Backfacing
  (a Cycles emission shader on a mesh emits from both faces); the material's
  emission sampling (how next-event estimation finds it) is FRONT (the
  --emission-sampling option; AUTO is Blender's default). A surface without
  a BSDF absorbs, as lumen's lights do. Two-sided lights (lumen's
  `two_sided = true`) -> the plain Emission shader, emission sampling
  FRONT_BACK; --one-sided makes them one-sided, as mitsuba_cornell.py.
- background: solid black only -> World Background black, strength 0.
- camera: lookfrom, lookat, vup and the vertical vfov of the file (sensor
  fit vertical); image --width wide (default the file's) with the file's
  aspect ratio.
- bounces: max_depth from the file (or --max-depth), lumen's count of ray
  segments (camera ray and shadow ray included: 1 = lights seen directly, 2 =
  direct light). Cycles' max_bounces (total, diffuse, glossy, transmission)
  = max_depth - 2: Cycles' 0 bounces is direct light (next-event estimation
  at the first hit, and the BSDF ray from it still collects the emission it
  meets, for MIS), i.e. lumen's max_depth 2; max_depth 1 has no Cycles
  equivalent and is refused. --check-depth renders both at max_depth 2, 3
  and 4 (lumen from --lumen) and prints their image means: with max_depth - 1
  instead, Cycles' image at every depth is lumen's at the next depth.

Cycles settings (cycles_common.configure): CPU, --threads worker threads,
path tracing, samples = spp, seed = the render's seed, pixel filter BOX of
width 1 px (uniform over the pixel, as lumen), no adaptive sampling, no
denoising, no clamping, view transform Standard (the image read back from a
32-bit float EXR: linear radiance), light tree on (--light-tree off to turn
it off) and MIS as Cycles' defaults (light threshold 0.01 at its default:
an unbiased roulette on shadow rays; --light-threshold to change it, 0 = no
roulette), Russian roulette --rr on (Cycles' default) or off. Sampling
pattern --pattern: `startup` keeps the bpy startup scene's TABULATED_SOBOL;
AUTOMATIC (a new scene's default: blue noise in final renders), BLUE_NOISE,
or SOBOL_BURLEY (Owen-scrambled Sobol computed
on the fly, one of Cycles' debug-only patterns; the Cycles debug preference
is turned on in this process to select it).

Images: without --timed, one render per --seeds seed, each written to
--out-template (.pfm linear RGB, or .exr); with --timed, a warm-up render
first (scene sync and caches, not counted), then one timed render per seed
and a JSON line last (as the other peer scripts: per-seed wall and CPU
seconds, load averages, the settings). Times are those of
bpy.ops.render.render(), which includes Cycles' scene sync and BVH build.
"""

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cycles_common as cc  # noqa: E402
import peerlib  # noqa: E402

import bpy  # noqa: E402

DEBUG_PATTERNS = {"SOBOL_BURLEY", "BLUE_NOISE_FIRST", "BLUE_NOISE_ROUND"}


# ------------------------------------------------------------------ scene
def read_scene(path, one_sided):
    """The lumen scene at `path` with its defaults filled in; what Cycles
    here cannot render is refused (as mitsuba_cornell.read_scene, except
    that two-sided lights are kept unless `one_sided`)."""
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
            if one_sided:
                m["two_sided"] = False
        else:
            raise ValueError(f"{path}: material {name}: type {m['type']} not supported")
    for i, o in enumerate(scene.get("objects", [])):
        if o["type"] not in ("quad", "box"):
            raise ValueError(f"{path}: objects[{i}]: only quads and boxes are supported")
    return scene


def rotation(axis, degrees):
    """Right-handed rotation by `degrees` about `axis` (Rodrigues)."""
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    a = math.radians(degrees)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.identity(3) + math.sin(a) * kx + (1 - math.cos(a)) * (kx @ kx)


def apply_steps(points, steps):
    """lumen's transform steps, the first applied first, to N x 3 points."""
    p = np.asarray(points, float)
    for step in steps or []:
        if "translate" in step:
            p = p + np.asarray(step["translate"], float)
        elif "rotate" in step:
            r = step["rotate"]
            p = p @ rotation(r["axis"], r["degrees"]).T
        elif "scale" in step:
            s = step["scale"]
            p = p * (np.full(3, float(s)) if isinstance(s, (int, float)) else np.asarray(s, float))
        elif "matrix" in step:
            m = np.asarray(step["matrix"], float).reshape(3, 4)
            p = p @ m[:, :3].T + m[:, 3]
        else:
            raise ValueError(f"transform step {step} not supported")
    return p


def quad_mesh(o):
    q, u, v = (np.asarray(o[k], float) for k in ("corner", "u", "v"))
    pts = apply_steps([q, q + u, q + u + v, q + v], o.get("transform"))
    return pts, [[0, 1, 2, 3]]


def box_mesh(o):
    lo, hi = np.asarray(o["min"], float), np.asarray(o["max"], float)
    # corner i: x from bit 0, y from bit 1, z from bit 2
    pts = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]]
                    for i in range(8)])
    # faces counter-clockwise seen from outside (fronts outward)
    faces = [[0, 4, 6, 2],   # -x
             [1, 3, 7, 5],   # +x
             [0, 1, 5, 4],   # -y
             [2, 6, 7, 3],   # +y
             [0, 2, 3, 1],   # -z
             [4, 5, 7, 6]]   # +z
    return apply_steps(pts, o.get("transform")), faces


def mesh_object(scene, name, pts_lumen, faces, material):
    v = np.asarray(pts_lumen, np.float64)
    vb = np.stack([v[:, 0], -v[:, 2], v[:, 1]], axis=1).astype(np.float32)  # (x, -z, y)
    me = bpy.data.meshes.new(name)
    me.from_pydata(vb.tolist(), [], [list(f) for f in faces])
    me.update(calc_edges=True)
    assert not me.validate(verbose=False), f"{name}: invalid mesh"
    me.shade_flat()
    me.materials.append(material)
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


def emission_material(name, radiance, two_sided, emission_sampling):
    """Emission of `radiance` from the front face only (or both faces)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (*peerlib.rgb(radiance), 1.0)
    em.inputs["Strength"].default_value = 1.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    if two_sided:
        nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
        mat.cycles.emission_sampling = "FRONT_BACK" if emission_sampling == "FRONT" else emission_sampling
        return mat
    black = nt.nodes.new("ShaderNodeEmission")
    black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    black.inputs["Strength"].default_value = 0.0
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geo.outputs["Backfacing"], mix.inputs[0])  # 0 = front: input 1; 1 = back: input 2
    nt.links.new(em.outputs["Emission"], mix.inputs[1])
    nt.links.new(black.outputs["Emission"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    mat.cycles.emission_sampling = emission_sampling
    return mat


def set_pattern(scene, pattern):
    """Cycles' sampling pattern; the debug-only ones need Cycles' debug
    preference (this process only: preferences are not saved)."""
    if not pattern or pattern == "startup":
        return
    if pattern in DEBUG_PATTERNS:
        prefs = bpy.context.preferences
        prefs.use_preferences_save = False
        prefs.experimental.use_cycles_debug = True
        prefs.view.show_developer_ui = True
    scene.cycles.sampling_pattern = pattern


def build(lscene, width, spp, seed, threads, rr, pattern, max_depth, light_tree, emission_sampling,
          light_threshold=None):
    r = lscene["render"]
    width = width or r["width"]
    height = max(1, r["height"] * width // r["width"])
    scene = cc.empty_scene()
    if max_depth < 2:
        raise ValueError("max_depth 1 (lights seen directly only) has no Cycles equivalent")
    cc.configure(scene, width, height, spp, max_depth, seed, threads, rr, None,
                 bounces=max_depth - 2)
    set_pattern(scene, pattern)
    scene.cycles.use_light_tree = light_tree
    if light_threshold is not None:
        scene.cycles.light_sampling_threshold = light_threshold
    cc.world_color(scene, [0.0, 0.0, 0.0], 0.0)
    cam = lscene["camera"]
    cc.camera(scene, cam["lookfrom"], cam["lookat"], cam["vup"], float(cam["vfov"]))
    mats = {}
    for name, m in lscene["materials"].items():
        if m["type"] == "diffuse":
            mats[name] = cc.diffuse_material(name, albedo=m["albedo"])
        else:
            mats[name] = emission_material(name, m["radiance"], m.get("two_sided", False),
                                           emission_sampling)
    for i, o in enumerate(lscene["objects"]):
        pts, faces = quad_mesh(o) if o["type"] == "quad" else box_mesh(o)
        mesh_object(scene, f"object{i}", pts, faces, mats[o["material"]])
    return scene, width, height


# ------------------------------------------------------------ depth check
def check_depth(args, lscene):
    """Image means of lumen (--depth D) and Cycles (max_bounces D - 2) at
    D = 2, 3, 4: they must agree if the bounce counts match."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="lumen-cc-depth-") as d:
        for depth in (2, 3, 4):
            scene, _, _ = build(lscene, args.width or 100, args.spp or 256, 1, args.threads,
                                args.rr == "on", args.pattern, depth, args.light_tree == "on",
                                args.emission_sampling)
            cc.render_once()
            c = cc.render_pixels(scene).reshape(-1, 3).mean(0)
            out = Path(d) / f"l{depth}.pfm"
            subprocess.run([args.lumen, "render", args.scene, "-o", str(out), "--width",
                            str(args.width or 100), "--spp", str(args.spp or 256), "--depth",
                            str(depth), "--seed", "1", "--threads", str(args.threads)],
                           check=True, capture_output=True)
            from compare import read_image
            lm = read_image(str(out)).reshape(-1, 3).mean(0)
            rows.append({"max_depth": depth, "cycles_max_bounces": depth - 2,
                         "cycles_mean": c.round(6).tolist(), "lumen_mean": lm.round(6).tolist(),
                         "ratio": (c / lm).round(4).tolist()})
            print(json.dumps(rows[-1]), file=sys.stderr)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="a lumen TOML scene of quads, boxes, diffuse and emissive materials")
    cc.add_common_args(ap)
    ap.add_argument("--width", type=int, help="image width (the height in proportion; default the file's)")
    ap.add_argument("--timed", action="store_true", help="warm up, then time each seed's render")
    ap.add_argument("--one-sided", action="store_true", help="make two-sided lights one-sided")
    ap.add_argument("--light-tree", choices=["on", "off"], default="on",
                    help="Cycles' light tree (its default: on)")
    ap.add_argument("--emission-sampling", default="FRONT",
                    choices=["AUTO", "FRONT", "BACK", "FRONT_BACK", "NONE"],
                    help="the one-sided lights' emission sampling (default FRONT; Blender's: AUTO)")
    ap.add_argument("--light-threshold", type=float,
                    help="Cycles' light sampling threshold (its default 0.01; 0: no roulette on shadow rays)")
    ap.add_argument("--check-depth", action="store_true",
                    help="compare image means with lumen at max_depth 2, 3, 4 (bounce counting)")
    ap.add_argument("--lumen", default=str(Path(__file__).resolve().parents[2] / "target/dist/lumen"),
                    help="lumen binary for --check-depth")
    args = ap.parse_args(cc.argv_after_dashdash() if argv is None else argv)
    lscene = read_scene(args.scene, args.one_sided)
    if args.check_depth:
        peerlib.print_json({"renderer": "cycles", "check": "depth", "rows": check_depth(args, lscene)})
        return 0
    if args.out and not args.seeds:  # one render at --seed
        args.seeds, args.out_template = [args.seed], args.out.replace("{", "{{").replace("}", "}}")
    if not args.spp or not args.seeds or not args.out_template or \
            (len(args.seeds) > 1 and "{seed}" not in args.out_template):
        ap.error("give --spp and --seeds with --out-template (with {seed}), or --out")
    depth = args.max_depth or lscene["render"]["max_depth"]
    scene, width, height = build(lscene, args.width, args.spp, args.seeds[0], args.threads,
                                 args.rr == "on", args.pattern, depth, args.light_tree == "on",
                                 args.emission_sampling, args.light_threshold)

    def render(seed):
        scene.cycles.seed = seed
        cc.render_once()

    def save(seed, _img):
        path = Path(args.out_template.format(seed=seed))
        a = cc.render_pixels(scene)
        if path.suffix.lower() == ".exr":
            path.parent.mkdir(parents=True, exist_ok=True)
            bpy.data.images["Render Result"].save_render(filepath=str(path), scene=scene)
        else:
            peerlib.write_pfm(path, a)
        print(f"wrote {path}: seed {seed}, mean {a.reshape(-1, 3).mean(0).round(6).tolist()}",
              file=sys.stderr)
        return a

    result = {"renderer": "cycles", "blender": bpy.app.version_string,
              "scene": Path(args.scene).name, "width": width, "height": height, "spp": args.spp,
              "max_depth": depth, "rr": args.rr, "pattern": args.pattern,
              "light_tree": args.light_tree, "emission_sampling": args.emission_sampling,
              "light_threshold": scene.cycles.light_sampling_threshold}
    result.update(peerlib.timed_renders(render, args.seeds, save, warmup=args.timed))
    result["settings"] = cc.settings_summary(scene)
    peerlib.print_json(result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
