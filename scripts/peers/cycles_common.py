"""Blender Cycles settings and the render loop shared by cycles_bunny.py and
cycles_spheres.py (run them with the venv of scripts/peers/setup_cycles.sh).

Coordinates: lumen (and Mitsuba) are Y-up, Blender is Z-up. Every point and
direction is mapped (x, y, z) -> (x, -z, y), a proper rotation (+90 degrees
about x), so triangle winding and handedness are kept.

Cycles settings (`configure`), chosen so that Cycles computes the same
expectation as lumen, in Cycles' own best unbiased way:

- CPU device, `threads` fixed worker threads (default 2), one tile.
- samples = spp; adaptive sampling off; denoising off; seed = --seed, not
  animated.
- pixel filter BOX of width 1 px (uniform over the pixel, as lumen).
- clamping off (sample_clamp_direct = sample_clamp_indirect = 0; Cycles
  clamps indirect light at 10 by default, a bias).
- filter glossy 0 and reflective/refractive caustics on: mirrors unbiased.
- bounces: lumen's max_depth D counts ray segments including the camera ray;
  Cycles max_bounces = diffuse = glossy = transmission = D - 1 by default
  (volume 0), or `bounces`. Transparent bounces are not used by these scenes.
  Measured since (cycles_cornell.py --check-depth; and cycles_bunny.py
  --max-depth 2 against lumen --depth 2 and 3 on the small bunny, 64 spp:
  Cycles 0.69750, lumen 0.66394 and 0.69753): Cycles' 0 bounces is direct
  light, i.e. 2 segments, so D - 2 matches lumen exactly and D - 1 renders
  one segment more. At the bunny's depth 8 and the spheres' 50 that last
  segment adds about 1e-6 to the image mean, far below the noise of the
  comparisons; cycles_cornell.py uses D - 2.
- Russian roulette: Cycles always terminates paths probabilistically after
  min_light_bounces (default 0) with probability 1 - min(sqrt(max throughput),
  1). `rr=False` sets min_light_bounces = max_bounces: no roulette (as lumen).
- light tree and MIS (world importance map) at their defaults.
- sampling pattern: `pattern` = None keeps the scene's value; the bpy startup
  scene stores TABULATED_SOBOL, a new scene's default is AUTOMATIC (blue-noise
  in final renders).
- view transform "Standard", look None, exposure 0, gamma 1; output OpenEXR
  32-bit float, which Blender writes in scene-linear RGB (no view transform):
  the PFM written here holds the render's linear radiance.
"""

import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402

import bpy  # noqa: E402
from mathutils import Matrix, Vector  # noqa: E402


def to_blender(p):
    """lumen's Y-up (x, y, z) -> Blender's Z-up (x, -z, y)."""
    x, y, z = (float(c) for c in p)
    return (x, -z, y)


def empty_scene():
    """The startup scene with every object, mesh, material and camera removed."""
    scene = bpy.context.scene
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.cameras, bpy.data.lights,
                 bpy.data.pointclouds):
        for d in list(coll):
            coll.remove(d)
    return scene


def configure(scene, width, height, spp, max_depth, seed=0, threads=2, rr=True, pattern=None,
              bounces=None):
    """`bounces` (if given) sets Cycles' max_bounces instead of max_depth - 1
    (cycles_cornell.py: max_depth - 2, see there)."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.use_animated_seed = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    b = max_depth - 1 if bounces is None else bounces
    c.max_bounces = b
    c.diffuse_bounces = b
    c.glossy_bounces = b
    c.transmission_bounces = b
    c.volume_bounces = 0
    c.min_light_bounces = b if not rr else 0
    if pattern:
        c.sampling_pattern = pattern
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = False
    scene.render.use_motion_blur = False
    scene.render.use_persistent_data = False
    vs = scene.view_settings
    vs.view_transform = "Standard"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.exr_codec = "ZIP"
    s.color_mode = "RGB"
    scene.render.use_compositing = False
    scene.render.use_sequencer = False


def settings_summary(scene):
    c = scene.cycles
    return {"device": c.device, "samples": c.samples, "seed": c.seed,
            "sampling_pattern": c.get("sampling_pattern", "default(AUTOMATIC)"),
            "sampling_pattern_name": c.sampling_pattern,
            "pixel_filter": [c.pixel_filter_type, c.filter_width],
            "clamp": [c.sample_clamp_direct, c.sample_clamp_indirect],
            "blur_glossy": c.blur_glossy, "max_bounces": c.max_bounces,
            "min_light_bounces": c.min_light_bounces, "light_tree": c.use_light_tree,
            "adaptive": c.use_adaptive_sampling, "denoise": c.use_denoising,
            "threads": scene.render.threads, "view_transform": scene.view_settings.view_transform}


def world_color(scene, color, strength=1.0):
    w = bpy.data.worlds.new("sky") if scene.world is None else scene.world
    scene.world = w
    w.use_nodes = True
    nt = w.node_tree
    nt.nodes.clear()
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (*peerlib.rgb(color), 1.0)
    bg.inputs["Strength"].default_value = strength
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])


def camera(scene, lookfrom, lookat, vup, vfov_deg):
    """A pinhole camera at lumen's lookfrom looking at lookat with up vup
    (lumen coordinates), vertical field of view vfov_deg."""
    eye = Vector(to_blender(lookfrom))
    at = Vector(to_blender(lookat))
    up = Vector(to_blender(vup))
    back = (eye - at).normalized()          # camera's local +Z (it looks down -Z)
    right = up.cross(back).normalized()     # local +X
    upv = back.cross(right)                 # local +Y
    m = Matrix.Identity(4)
    for i in range(3):
        m[i][0], m[i][1], m[i][2], m[i][3] = right[i], upv[i], back[i], eye[i]
    cam_data = bpy.data.cameras.new("cam")
    cam_data.type = "PERSP"
    cam_data.sensor_fit = "VERTICAL"
    cam_data.sensor_height = 24.0
    cam_data.lens = (cam_data.sensor_height / 2) / math.tan(math.radians(vfov_deg) / 2)
    cam_data.shift_x = cam_data.shift_y = 0.0
    cam_data.clip_start = 1e-3
    cam_data.clip_end = 1e5
    cam_data.dof.use_dof = False
    ob = bpy.data.objects.new("cam", cam_data)
    ob.matrix_world = m
    scene.collection.objects.link(ob)
    scene.camera = ob
    return ob


def diffuse_material(name, albedo=None, attribute=None):
    """Lambertian (Diffuse BSDF, roughness 0) of colour `albedo`, or of the
    geometry attribute `attribute` (a per-point colour)."""
    def bsdf(nt):
        node = nt.nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Roughness"].default_value = 0.0
        return node
    return _material(name, bsdf, albedo, attribute)


def mirror_material(name, albedo=None, attribute=None):
    """Perfect mirror reflecting exactly `albedo` at every angle: Glossy BSDF
    (GGX, roughness 0; Cycles applies no Fresnel term to it)."""
    def bsdf(nt):
        node = nt.nodes.new("ShaderNodeBsdfAnisotropic")  # "Glossy BSDF" since Blender 4.0
        node.distribution = "GGX"
        node.inputs["Roughness"].default_value = 0.0
        if "Anisotropy" in node.inputs:
            node.inputs["Anisotropy"].default_value = 0.0
        return node
    return _material(name, bsdf, albedo, attribute)


def _material(name, make_bsdf, albedo, attribute):
    """A Cycles material whose surface is the BSDF node `make_bsdf(node_tree)`
    makes, its Color input `albedo` or the geometry attribute `attribute`."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    bsdf = make_bsdf(nt)
    _colour_input(nt, bsdf.inputs["Color"], albedo, attribute)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def _colour_input(nt, socket, albedo, attribute):
    if attribute:
        a = nt.nodes.new("ShaderNodeAttribute")
        a.attribute_type = "GEOMETRY"
        a.attribute_name = attribute
        nt.links.new(a.outputs["Color"], socket)
    else:
        socket.default_value = (*peerlib.rgb(albedo), 1.0)


# ------------------------------------------------------------- rendering
def render_once():
    bpy.ops.render.render(write_still=False)


def render_pixels(scene):
    """The last render's linear RGB (H x W x 3 float32, top row first),
    through a 32-bit EXR written and read back by Blender."""
    with tempfile.TemporaryDirectory(prefix="lumen-cycles-") as d:
        path = os.path.join(d, "r.exr")
        bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
        img = bpy.data.images.load(path, check_existing=False)
        img.colorspace_settings.name = "Non-Color"  # keep the stored linear values
        w, h = img.size
        px = np.empty(w * h * img.channels, np.float32)
        img.pixels.foreach_get(px)
        bpy.data.images.remove(img)
    px = px.reshape(h, w, -1)[::-1, :, :3]  # Blender images start at the bottom row
    return np.ascontiguousarray(px)


def run(scene, args, extra):
    """Single render (--out) and/or timed mode (--seeds, --out-template);
    prints one JSON line."""
    result = {"renderer": "cycles", "blender": bpy.app.version_string, **extra}

    def render(seed):
        scene.cycles.seed = seed
        render_once()

    def save(seed, _img, path=None):
        path = Path(path or args.out_template.format(seed=seed))
        a = render_pixels(scene)
        if path.suffix.lower() == ".exr":
            path.parent.mkdir(parents=True, exist_ok=True)
            bpy.data.images["Render Result"].save_render(filepath=str(path), scene=scene)
        else:
            peerlib.write_pfm(path, a)
        return a

    if args.out:
        t0 = time.perf_counter()
        render(args.seed)
        t = time.perf_counter() - t0
        a = save(args.seed, None, args.out)
        print(f"wrote {args.out}: seed {args.seed}, {t:.2f} s, "
              f"mean {a.reshape(-1, 3).mean(0).round(5).tolist()}", file=sys.stderr)
        result.update(seed=args.seed, first_render_s=round(t, 3))
    if args.seeds:
        if not args.out_template or "{seed}" not in args.out_template:
            raise SystemExit("--seeds needs --out-template with {seed}")
        result.update(peerlib.timed_renders(render, args.seeds, save))
    result["settings"] = settings_summary(scene)
    peerlib.print_json(result)


def add_common_args(ap):
    ap.add_argument("--spp", type=int, help="samples per pixel")
    ap.add_argument("--seed", type=int, default=0, help="seed of the single render (--out)")
    ap.add_argument("--out", help="render once at --seed and write this .pfm (or .exr), linear RGB")
    ap.add_argument("--seeds", type=int, nargs="+", help="timed mode: warm up, then render each seed")
    ap.add_argument("--out-template", help="timed mode: image path with {seed}")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rr", choices=["on", "off"], default="on",
                    help="Russian roulette (Cycles' default: on; off = min_light_bounces = max_bounces)")
    ap.add_argument("--pattern", default="startup",
                    help="sampling pattern: 'startup' keeps the startup scene's (TABULATED_SOBOL), "
                         "or AUTOMATIC, TABULATED_SOBOL, SOBOL_BURLEY, ...")
    ap.add_argument("--max-depth", type=int, help="lumen max_depth (ray segments); Cycles bounces = D - 1")


def argv_after_dashdash():
    """Arguments for the script: all of sys.argv[1:] (run by python), or the
    ones after '--' (run by the blender executable)."""
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
