#!/usr/bin/env python3
"""lumen's bunny scene (scripts/peers/mitsuba_bunny.py, scripts/peers/bunny-scene.toml),
rendered with Blender Cycles.

    eval "$(scripts/peers/setup_cycles.sh --env)"
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_bunny.py [MESH.glb] --spp 64 --seed 1 --out bunny.pfm
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_bunny.py --spp 64 --seeds 1 2 --out-template /tmp/c-{seed}.pfm

The scene, in lumen's Y-up coordinates (each point and direction mapped to
Blender's Z-up by (x, y, z) -> (x, -z, y)):

- mesh: the Stanford bunny from a binary glTF file (default
  assets/bunny_235k.glb; assets/bunny.glb has 3,674 triangles), positions and
  indices only (read by mitsuba_bunny.read_glb), flat shaded; Diffuse BSDF
  0.7 (roughness 0: Lambertian).
- floor: 60 x 60 square at y = 0 centred at the origin, Diffuse BSDF 0.5
  (Cycles surfaces scatter on both sides).
- world: Background colour white, strength 1 (uniform white sky).
- camera: (0, 8, 22) looking at (0, 4.5, 0), up +y, vertical fov 40 degrees
  (sensor fit vertical), 400 x 400.
- max_depth 8 (ray segments) -> Cycles max_bounces 7.

Cycles settings: see cycles_common.py.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cycles_common as cc  # noqa: E402
from mitsuba_bunny import read_glb, BUNNY_ALBEDO, FLOOR_ALBEDO, FLOOR_HALF, MAX_DEPTH, WIDTH, HEIGHT  # noqa: E402

import bpy  # noqa: E402

REPO_ROOT = Path(__file__).resolve().parents[2]


def mesh_object(scene, name, verts_lumen, faces, material):
    v = np.asarray(verts_lumen, np.float64)
    vb = np.stack([v[:, 0], -v[:, 2], v[:, 1]], axis=1).astype(np.float32)  # (x, -z, y)
    f = np.asarray(faces, np.int32)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(vb))
    me.vertices.foreach_set("co", vb.ravel())
    me.loops.add(f.size)
    me.loops.foreach_set("vertex_index", f.ravel())
    me.polygons.add(len(f))
    me.polygons.foreach_set("loop_start", np.arange(0, f.size, 3, dtype=np.int32))
    me.update(calc_edges=True)
    assert not me.validate(verbose=False), f"{name}: invalid mesh"  # True = had to fix it
    me.shade_flat()
    me.materials.append(material)
    assert len(me.polygons) == len(f), (len(me.polygons), len(f))
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


def build(mesh_path, spp, seed, threads, rr, pattern, max_depth=MAX_DEPTH):
    scene = cc.empty_scene()
    cc.configure(scene, WIDTH, HEIGHT, spp, max_depth, seed, threads, rr, pattern)
    cc.world_color(scene, [1.0, 1.0, 1.0], 1.0)
    cc.camera(scene, [0, 8, 22], [0, 4.5, 0], [0, 1, 0], 40.0)
    pos, tri = read_glb(mesh_path)
    mesh_object(scene, "bunny", pos, tri, cc.diffuse_material("bunny", albedo=BUNNY_ALBEDO))
    h = FLOOR_HALF
    floor_v = [[-h, 0, -h], [h, 0, -h], [h, 0, h], [-h, 0, h]]
    mesh_object(scene, "floor", floor_v, [[0, 2, 1], [0, 3, 2]],
                cc.diffuse_material("floor", albedo=FLOOR_ALBEDO))
    return scene, len(tri)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", nargs="?", default=str(REPO_ROOT / "assets" / "bunny_235k.glb"))
    cc.add_common_args(ap)
    args = ap.parse_args(cc.argv_after_dashdash() if argv is None else argv)
    if not args.out and not args.seeds:
        ap.error("give --out (one render) or --seeds (timed renders)")
    spp = args.spp or 16
    depth = args.max_depth or MAX_DEPTH
    seed0 = args.seeds[0] if args.seeds else args.seed
    scene, ntri = build(args.mesh, spp, seed0, args.threads, args.rr == "on",
                        None if args.pattern == "startup" else args.pattern, depth)
    cc.run(scene, args, {"scene": "bunny", "mesh": Path(args.mesh).name, "triangles": ntri,
                         "width": WIDTH, "height": HEIGHT, "spp": spp, "max_depth": depth,
                         "rr": args.rr, "pattern": args.pattern})
    return 0


if __name__ == "__main__":
    sys.exit(main())
