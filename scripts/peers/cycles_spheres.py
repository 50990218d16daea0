#!/usr/bin/env python3
"""A lumen sphere scene (scripts/peers/spheres-scene.toml), rendered with Blender Cycles.

    eval "$(scripts/peers/setup_cycles.sh --env)"
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_spheres.py --spp 64 --seed 1 --out spheres.pfm
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_spheres.py --spp 64 --seeds 1 2 --out-template /tmp/c-{seed}.pfm

Cycles settings: see cycles_common.py (CPU, 2 threads, box filter 1 px, no
denoising, no adaptive sampling, no clamping, filter glossy 0, bounces =
max_depth - 1, Russian roulette on by default, `--rr off` to disable).

Translation of the scene (lumen Y-up -> Blender Z-up: (x, y, z) -> (x, -z, y)):

- spheres: by default a Cycles *point cloud* (`--geometry points`): Cycles
  intersects each point as an exact sphere (centre, radius) and shades it
  with the exact sphere normal, so there is no tessellation error. The
  spheres are two point clouds, one for the diffuse and one for the mirror
  materials, with the albedo as a per-point colour attribute "albedo".
  `--geometry uv` uses UV spheres instead (`--segments` 64 x 32 rings by
  default, smooth shaded; vertices on the true sphere, so the faceted surface
  lies inside it by up to r (1 - cos(pi/segments)) -- 0.12% of r at 64 -- and
  the interpolated normals deviate slightly from the true ones). The ground
  (radius 1000) as a UV sphere is far off (1.2 units at 64 segments), so
  `--geometry uv` is for the documentation of that error only.
- diffuse (lambertian, scale) -> Diffuse BSDF (roughness 0 = Lambertian),
  colour = albedo.
- metal, fuzz 0 -> Glossy BSDF, GGX, roughness 0: a perfect mirror whose
  reflectance is the colour at every angle (no Fresnel term; checked by
  `--check-mirror`, which renders one mirror sphere at max_depth 2 under the
  white sky: every pixel must be exactly the albedo or the sky).
- solid background C -> world Background node, colour C, strength 1.
- camera: pinhole at lookfrom looking at lookat, up vup, vertical field of
  view vfov (sensor fit vertical).
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402
import cycles_common as cc  # noqa: E402

import bpy  # noqa: E402

HERE = Path(__file__).resolve().parent


def add_point_cloud(scene, name, centers, radii, albedos, material):
    """Spheres as one Cycles point cloud (exact ray-sphere intersection).
    Made as a vertex-only mesh with 'radius' and 'albedo' vertex attributes,
    then converted to a point cloud (the attributes carry over)."""
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(centers))
    me.vertices.foreach_set("co", np.asarray([cc.to_blender(c) for c in centers], np.float32).ravel())
    r = me.attributes.new("radius", "FLOAT", "POINT")
    r.data.foreach_set("value", np.asarray(radii, np.float32))
    a = me.attributes.new("albedo", "FLOAT_COLOR", "POINT")
    rgba = np.ones((len(centers), 4), np.float32)
    rgba[:, :3] = albedos
    a.data.foreach_set("color", rgba.ravel())
    me.update()
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    for o in scene.objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    bpy.ops.object.convert(target="POINTCLOUD")
    ob = bpy.context.view_layer.objects.active
    pc = ob.data
    assert isinstance(pc, bpy.types.PointCloud), type(pc)
    assert len(pc.points) == len(centers), (len(pc.points), len(centers))
    got = np.empty(len(centers), np.float32)
    pc.attributes["radius"].data.foreach_get("value", got)
    assert np.allclose(got, radii, rtol=1e-6), "radius attribute lost in the conversion"
    assert "albedo" in pc.attributes, "albedo attribute lost in the conversion"
    pc.materials.append(material)
    return ob


def add_uv_sphere(scene, name, center, radius, material, segments, rings):
    import bmesh
    me = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bm.to_mesh(me)
    bm.free()
    me.shade_smooth()
    me.materials.append(material)
    ob = bpy.data.objects.new(name, me)
    ob.location = cc.to_blender(center)
    scene.collection.objects.link(ob)
    return ob


def build(lscene, spp, seed, threads, rr, pattern, geometry="points", segments=64, max_depth=None):
    r, cam = lscene["render"], lscene["camera"]
    scene = cc.empty_scene()
    cc.configure(scene, r["width"], r["height"], spp, max_depth or r["max_depth"], seed, threads, rr, pattern)
    cc.world_color(scene, lscene["background"]["color"])
    cc.camera(scene, cam["lookfrom"], cam["lookat"], cam["vup"], cam["vfov"])
    mats = lscene["materials"]
    groups = {"diffuse": [], "metal": []}
    for o in lscene["objects"]:
        groups[mats[o["material"]]["type"]].append(o)
    if geometry == "points":
        for kind, objs in groups.items():
            if not objs:
                continue
            m = (cc.diffuse_material if kind == "diffuse" else cc.mirror_material)(kind, attribute="albedo")
            add_point_cloud(scene, f"{kind}-spheres", [o["center"] for o in objs],
                            [o["radius"] for o in objs],
                            np.array([peerlib.rgb(mats[o["material"]]["albedo"]) for o in objs], np.float32), m)
    else:
        cache = {}
        for i, o in enumerate(lscene["objects"]):
            name = o["material"]
            if name not in cache:
                m = mats[name]
                f = cc.diffuse_material if m["type"] == "diffuse" else cc.mirror_material
                cache[name] = f(name, albedo=m["albedo"])
            add_uv_sphere(scene, f"sphere{i}", o["center"], o["radius"], cache[name],
                          segments, max(3, segments // 2))
    return scene


def check_mirror(args):
    """One mirror sphere (albedo 0.8, 0.5, 0.2) under the white sky, max_depth
    2 (one bounce): each pixel is a mix of the albedo (sphere) and 1 (sky)."""
    albedo = [0.8, 0.5, 0.2]
    ls = {"render": {"width": 64, "height": 64, "max_depth": 2},
          "camera": {"lookfrom": [0, 0, 4], "lookat": [0, 0, 0], "vup": [0, 1, 0], "vfov": 40},
          "background": {"type": "solid", "color": [1, 1, 1]},
          "materials": {"m": {"type": "metal", "albedo": albedo, "fuzz": 0.0}},
          "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "m"}]}
    build(ls, 16, 0, args.threads, True, None if args.pattern == "startup" else args.pattern)
    cc.render_once()
    a = cc.render_pixels(bpy.context.scene).reshape(-1, 3)
    inside = np.all(np.abs(a - albedo) < 1e-5, axis=1)
    sky = np.all(np.abs(a - 1) < 1e-5, axis=1)
    # edge pixels: a fraction f of sphere samples: a = f * albedo + (1 - f) * 1
    f = (1 - a) / (1 - np.array(albedo))
    edge = ~inside & ~sky & (np.ptp(f, axis=1) < 1e-4)
    ok = inside.sum() > 1000 and np.all(inside | sky | edge)
    print(f"check-mirror: {inside.sum()} pixels = albedo {albedo}, {sky.sum()} sky, {edge.sum()} edge, "
          f"{(~(inside | sky | edge)).sum()} other: {'ok' if ok else 'FAIL'}", file=sys.stderr)
    return 0 if ok else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?", default=str(HERE / "spheres-scene.toml"))
    cc.add_common_args(ap)
    ap.add_argument("--geometry", choices=["points", "uv"], default="points")
    ap.add_argument("--segments", type=int, default=64, help="UV sphere segments (rings = half)")
    ap.add_argument("--check-mirror", action="store_true")
    args = ap.parse_args(cc.argv_after_dashdash() if argv is None else argv)
    if args.check_mirror:
        return check_mirror(args)
    if not args.out and not args.seeds:
        ap.error("give --out (one render) or --seeds (timed renders)")
    ls = peerlib.read_lumen_scene(args.scene)
    spp = args.spp or ls["render"]["samples_per_pixel"]
    seed0 = args.seeds[0] if args.seeds else args.seed
    scene = build(ls, spp, seed0, args.threads, args.rr == "on",
                  None if args.pattern == "startup" else args.pattern, args.geometry, args.segments,
                  args.max_depth)
    cc.run(scene, args, {"scene": Path(args.scene).name, "width": ls["render"]["width"],
                         "height": ls["render"]["height"], "spp": spp,
                         "max_depth": args.max_depth or ls["render"]["max_depth"],
                         "geometry": args.geometry, "rr": args.rr, "pattern": args.pattern})
    return 0


if __name__ == "__main__":
    sys.exit(main())
