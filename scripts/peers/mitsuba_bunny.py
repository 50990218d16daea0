#!/usr/bin/env python3
"""lumen's `lumen bench` mesh workload, rendered with Mitsuba 3.

Run with the venv made by scripts/peers/setup.sh:

    eval "$(scripts/peers/setup.sh)"
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_bunny.py --spp 64 --out bunny.exr
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_bunny.py --spp 64 --time --runs 3

The scene (must match lumen's bench scene exactly):

- mesh: the Stanford bunny from a binary glTF file (default
  assets/bunny_235k.glb, 235,136 triangles; assets/bunny.glb has 3,674),
  positions and indices only, flat shaded (face normals); diffuse 0.7.
- floor: a 60 x 60 square at y = 0 centred at the origin, diffuse 0.5,
  scattering on both sides (`twosided`).
- light: a `constant` environment of radiance 1 (uniform white sky), only.
- camera: perspective from (0, 8, 22) to (0, 4.5, 0), up +y, vertical field of
  view 40 degrees, 400 x 400, box pixel filter (lumen averages samples
  uniformly over the pixel's area).
- integrator: `path`, max_depth 8, no Russian roulette (default; `--rr-depth 5`
  is Mitsuba's own default).

Depth convention. Mitsuba's documentation of `max_depth` (path integrator,
and `Integrator::m_max_depth` in mitsuba/render/integrator.h): "A value of 1
will only render directly visible light sources. 2 will lead to single-bounce
(direct-only) illumination, and so on." So Mitsuba's max_depth counts the
ray segments of a light path, camera ray included: max_depth 1 is the camera
ray alone (it sees the sky or black), max_depth 2 adds one segment from the
first hit to the sky (whether found by emitter sampling or by BSDF sampling,
which Mitsuba combines with MIS). That is lumen's convention: max_depth 8 = at
most 8 ray segments, so the same number (8) is used here.
`--check-depth` verifies the max_depth 1 end of it on the rendered scene.

Russian roulette starts at `rr_depth`; setting it above max_depth turns it off.
Samplers: independent, stratified, multijitter (both jittered), ldsampler.

`--seeds A B --out-template DIR/x-{seed}.pfm` (used by efficiency.sh): build
the scene, render once at A to warm up, then time one render per seed and
write each image; one JSON line with the times and load averages.

Output: `--out FILE.exr` writes the linear RGB float32 image (no tonemapping);
`.pfm` is accepted too. `--time` builds the scene once, renders once to warm up
(kernel compilation not counted), then times `--runs` renders and prints one
JSON line (the last line) with the median seconds and samples per second.
"""

import argparse
import json
import os
import statistics
import struct
import sys
import time
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parents[2]

WIDTH = HEIGHT = 400
MAX_DEPTH = 8
BUNNY_ALBEDO = 0.7
FLOOR_ALBEDO = 0.5
FLOOR_HALF = 30.0  # 60 x 60

# glTF componentType -> numpy dtype; type -> component count
_GLTF_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
                5125: np.uint32, 5126: np.float32}
_GLTF_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def read_glb(path):
    """Positions (N x 3 float32) and triangles (M x 3 uint32) of a GLB file.

    Binary glTF: a 12-byte header (magic 'glTF', version 2, total length),
    then chunks of (length, type, data): first JSON, then BIN. All primitives
    of all meshes of the default scene's nodes are concatenated; node
    transforms (matrix, or translation/rotation/scale) are applied.
    """
    data = Path(path).read_bytes()
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67 or version != 2:
        raise ValueError(f"{path}: not a binary glTF 2.0 file")
    if length > len(data):
        raise ValueError(f"{path}: truncated ({len(data)} of {length} bytes)")
    off, gltf, binchunk = 12, None, None
    while off + 8 <= length:
        clen, ctype = struct.unpack_from("<II", data, off)
        chunk = data[off + 8: off + 8 + clen]
        if ctype == 0x4E4F534A:  # 'JSON'
            gltf = json.loads(chunk)
        elif ctype == 0x004E4942 and binchunk is None:  # 'BIN\0'
            binchunk = chunk
        off += 8 + clen
    if gltf is None or binchunk is None:
        raise ValueError(f"{path}: missing JSON or BIN chunk")

    def accessor(i):
        acc = gltf["accessors"][i]
        view = gltf["bufferViews"][acc["bufferView"]]
        if view.get("buffer", 0) != 0:
            raise ValueError("only the GLB's own buffer is supported")
        dtype = np.dtype(_GLTF_DTYPES[acc["componentType"]]).newbyteorder("<")
        ncomp = _GLTF_NCOMP[acc["type"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride", 0) or dtype.itemsize * ncomp
        count = acc["count"]
        if stride == dtype.itemsize * ncomp:
            a = np.frombuffer(binchunk, dtype, count * ncomp, start)
        else:
            rows = np.frombuffer(binchunk, np.uint8, (count - 1) * stride + dtype.itemsize * ncomp, start)
            a = np.lib.stride_tricks.as_strided(rows, (count, dtype.itemsize * ncomp), (stride, 1))
            a = np.ascontiguousarray(a).view(dtype)
        return a.reshape(count, ncomp) if ncomp > 1 else a

    def node_matrix(node):
        if "matrix" in node:
            return np.array(node["matrix"], np.float64).reshape(4, 4).T  # column-major
        m = np.eye(4)
        if "scale" in node:
            m = np.diag(list(node["scale"]) + [1.0]) @ m
        if "rotation" in node:
            x, y, z, w = node["rotation"]
            r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            rm = np.eye(4)
            rm[:3, :3] = r
            m = rm @ m
        if "translation" in node:
            t = np.eye(4)
            t[:3, 3] = node["translation"]
            m = t @ m
        return m

    positions, faces, nverts = [], [], 0

    def visit(ni, parent):
        nonlocal nverts
        node = gltf["nodes"][ni]
        m = parent @ node_matrix(node)
        if "mesh" in node:
            for prim in gltf["meshes"][node["mesh"]]["primitives"]:
                if prim.get("mode", 4) != 4:
                    raise ValueError("only triangle primitives (mode 4) are supported")
                p = accessor(prim["attributes"]["POSITION"]).astype(np.float64)
                if not np.allclose(m, np.eye(4)):
                    p = p @ m[:3, :3].T + m[:3, 3]
                if "indices" in prim:
                    idx = accessor(prim["indices"]).astype(np.uint32)
                else:
                    idx = np.arange(len(p), dtype=np.uint32)
                positions.append(p.astype(np.float32))
                faces.append(idx.reshape(-1, 3) + np.uint32(nverts))
                nverts += len(p)
        for c in node.get("children", []):
            visit(c, m)

    scene = gltf.get("scenes", [{}])[gltf.get("scene", 0)] if "scenes" in gltf else None
    roots = scene["nodes"] if scene else range(len(gltf["nodes"]))
    for ni in roots:
        visit(ni, np.eye(4))
    if not faces:
        raise ValueError(f"{path}: no triangles")
    return np.concatenate(positions), np.concatenate(faces)


def build_scene(mi, mesh_path, sampler="independent", spp=16, seed=0,
                floor_albedo=FLOOR_ALBEDO, max_depth=MAX_DEPTH, samples_per_pass=None,
                verbose=True, rr_depth=None):
    ScalarTransform4f = mi.ScalarTransform4f
    pos, tri = read_glb(mesh_path)
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    if verbose:
        print(f"mesh {mesh_path}: {len(tri)} triangles, {len(pos)} vertices, "
              f"bounds x {lo[0]:.3f}..{hi[0]:.3f} y {lo[1]:.3f}..{hi[1]:.3f} "
              f"z {lo[2]:.3f}..{hi[2]:.3f}", file=sys.stderr)
    # The bunny assets all share these bounds (the subdivided one is split
    # at midpoints, so its hull does not move).
    expect_lo, expect_hi = np.array([-4.96, -0.003, -3.73]), np.array([4.95, 9.65, 3.81])
    if not (np.all(np.abs(lo - expect_lo) < 0.01) and np.all(np.abs(hi - expect_hi) < 0.01)):
        print(f"warning: bounds differ from the Stanford bunny's", file=sys.stderr)

    props = mi.Properties()
    props["bsdf"] = mi.load_dict({"type": "diffuse", "reflectance": {"type": "rgb", "value": BUNNY_ALBEDO}})
    # No vertex normals: Mitsuba shades with the face normal (flat shading).
    mesh = mi.Mesh("bunny", len(pos), len(tri), props=props,
                   has_vertex_normals=False, has_vertex_texcoords=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(pos.ravel())
    params["faces"] = mi.UInt32(tri.ravel())
    params.update()
    assert mesh.face_count() == len(tri) and mesh.vertex_count() == len(pos)

    # rr_depth None: Russian roulette off (it starts above max_depth), as in lumen.
    integrator = {"type": "path", "max_depth": max_depth,
                  "rr_depth": max_depth + 100 if rr_depth is None else rr_depth}
    if samples_per_pass:
        integrator["samples_per_pass"] = samples_per_pass
    if sampler == "stratified" or sampler == "multijitter":
        sampler_dict = {"type": sampler, "sample_count": spp, "seed": seed, "jitter": True}
    else:
        sampler_dict = {"type": sampler, "sample_count": spp, "seed": seed}

    scene = mi.load_dict({
        "type": "scene",
        "integrator": integrator,
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "near_clip": 1e-3,
            "far_clip": 1e5,
            "to_world": ScalarTransform4f().look_at(origin=[0, 8, 22], target=[0, 4.5, 0], up=[0, 1, 0]),
            "sampler": sampler_dict,
            "film": {
                "type": "hdrfilm",
                "width": WIDTH,
                "height": HEIGHT,
                "pixel_format": "rgb",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
        "bunny": mesh,
        # `rectangle` spans [-1, 1]^2 in the xy plane, normal +z; scale it to
        # 60 x 60 and turn it about x by -90 degrees so that the normal is +y.
        "floor": {
            "type": "rectangle",
            "to_world": ScalarTransform4f().rotate(axis=[1, 0, 0], angle=-90).scale([FLOOR_HALF, FLOOR_HALF, 1]),
            "bsdf": {"type": "twosided",
                     "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": floor_albedo}}},
        },
    })
    return scene, len(tri)


def write_image(mi, img, out):
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    bmp = mi.Bitmap(img)  # float32 RGB, linear
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp{out.suffix}")
    if out.suffix.lower() == ".pfm":
        a = np.asarray(bmp, dtype=np.float32)[:, :, :3]
        with open(tmp, "wb") as f:
            f.write(f"PF\n{a.shape[1]} {a.shape[0]}\n-1.0\n".encode())
            f.write(np.ascontiguousarray(a[::-1]).astype("<f4").tobytes())
    else:
        bmp.write(str(tmp))
    os.replace(tmp, out)


def efficiency_mode(mi, dr, args, rr_depth, spp_pass):
    """--seeds: build once, warm up at the first seed, time one render per
    seed, write each image to --out-template; print one JSON line."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import peerlib
    if not args.out_template or "{seed}" not in args.out_template:
        print("mitsuba_bunny.py: --seeds needs --out-template with {seed}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    scene, ntri = build_scene(mi, args.mesh, args.sampler, args.spp, args.seeds[0],
                              args.floor_albedo, args.max_depth, spp_pass, rr_depth=rr_depth)
    t_build = time.perf_counter() - t0

    def render(seed):
        img = mi.render(scene, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return img

    result = {"renderer": "mitsuba", "version": mi.__version__, "variant": mi.variant(),
              "scene": "bunny", "mesh": Path(args.mesh).name, "triangles": ntri,
              "width": WIDTH, "height": HEIGHT,
              "spp": scene.sensors()[0].sampler().sample_count(), "max_depth": args.max_depth,
              "sampler": args.sampler, "rr_depth": args.rr_depth, "threads": dr.thread_count(),
              "build_s": round(t_build, 3)}
    result.update(peerlib.timed_renders(
        render, args.seeds, lambda seed, img: write_image(mi, img, args.out_template.format(seed=seed))))
    print(json.dumps(result))
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", nargs="?", default=str(REPO_ROOT / "assets" / "bunny_235k.glb"),
                    help="binary glTF mesh (default: assets/bunny_235k.glb of the repo)")
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel (default 16)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sampler", choices=["independent", "stratified", "multijitter", "ldsampler"],
                    default="independent")
    ap.add_argument("--rr-depth", default="off",
                    help="Russian roulette from this depth (Mitsuba's default: 5); 'off' (default)")
    ap.add_argument("--seeds", type=int, nargs="+",
                    help="efficiency mode: warm up, then time one render per seed, writing "
                         "--out-template (see efficiency.sh)")
    ap.add_argument("--out-template", help="with --seeds: image path with {seed}, e.g. /tmp/m-{seed}.pfm")
    ap.add_argument("--threads", type=int, default=0, help="Mitsuba worker threads (default: all cores)")
    ap.add_argument("--out", help="output image, .exr (linear float RGB) or .pfm")
    ap.add_argument("--time", action="store_true", help="warm up, then time --runs renders")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--floor-albedo", type=float, default=FLOOR_ALBEDO,
                    help="floor reflectance (0.5; other values only to test compare.py)")
    ap.add_argument("--max-depth", type=int, default=MAX_DEPTH)
    ap.add_argument("--samples-per-pass", type=int, default=0,
                    help="split the render into passes of this many spp to bound memory "
                         "(deprecated in Mitsuba 3.6+; default: Mitsuba chooses)")
    ap.add_argument("--check-depth", action="store_true",
                    help="render with max_depth 1 and check that only the sky is seen")
    args = ap.parse_args(argv)

    if not Path(args.mesh).is_file():
        print(f"mitsuba_bunny.py: no mesh file {args.mesh} (pass the .glb path)", file=sys.stderr)
        return 2

    if args.variant.startswith("llvm") and not os.environ.get("DRJIT_LIBLLVM_PATH"):
        print("note: DRJIT_LIBLLVM_PATH is not set (eval \"$(scripts/peers/setup.sh)\")", file=sys.stderr)

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    if args.threads > 0:
        dr.set_thread_count(args.threads)

    spp_pass = args.samples_per_pass or None

    if args.check_depth:
        scene, _ = build_scene(mi, args.mesh, args.sampler, 4, args.seed, args.floor_albedo, 1)
        img = np.asarray(mi.render(scene, spp=4, seed=args.seed))
        # Pixels whose camera ray escapes see radiance 1; every other pixel is black.
        vals = np.unique(np.round(img, 6))
        sky = float((img[..., 0] > 0.5).mean())
        print(f"max_depth 1: pixel values {vals.tolist()[:6]}, sky fraction {sky:.3f}", file=sys.stderr)
        ok = set(vals.tolist()) <= {0.0, 0.25, 0.5, 0.75, 1.0}  # box filter, 4 spp: k/4
        print(json.dumps({"check_depth": "ok" if ok else "fail", "values": vals.tolist()[:10]}))
        return 0 if ok else 1

    rr_depth = None if args.rr_depth == "off" else int(args.rr_depth)
    if args.seeds:
        return efficiency_mode(mi, dr, args, rr_depth, spp_pass)

    t0 = time.perf_counter()
    scene, ntri = build_scene(mi, args.mesh, args.sampler, args.spp, args.seed,
                              args.floor_albedo, args.max_depth, spp_pass, rr_depth=rr_depth)
    t_build = time.perf_counter() - t0
    spp_used = scene.sensors()[0].sampler().sample_count()
    if spp_used != args.spp:  # `stratified` rounds up to a square
        print(f"note: the {args.sampler} sampler takes {spp_used} spp, not {args.spp}", file=sys.stderr)
        args.spp = spp_used

    def render(seed):
        img = mi.render(scene, seed=seed)  # spp: the sampler's
        dr.eval(img)
        dr.sync_thread()
        return img

    t0 = time.perf_counter()
    img = render(args.seed)
    t_first = time.perf_counter() - t0
    if args.out:
        write_image(mi, img, args.out)
        print(f"wrote {args.out}: {WIDTH}x{HEIGHT}, {args.spp} spp, seed {args.seed}, "
              f"{t_first:.2f} s (first render, includes kernel compilation)", file=sys.stderr)

    result = {
        "renderer": "mitsuba", "mitsuba": mi.__version__, "drjit": dr.__version__,
        "variant": mi.variant(), "mesh": Path(args.mesh).name, "triangles": ntri,
        "width": WIDTH, "height": HEIGHT, "spp": args.spp, "max_depth": args.max_depth,
        "sampler": args.sampler, "rr_depth": args.rr_depth, "samples_per_pass": spp_pass, "seed": args.seed,
        "threads": dr.thread_count(), "machine_threads": os.cpu_count(),
        "build_s": round(t_build, 3), "first_render_s": round(t_first, 3),
    }
    if args.time:
        # Wall-clock time, and the CPU time of this process (all its threads),
        # which depends less on what else runs on a shared machine.
        times, cpus = [], []
        for i in range(args.runs):
            c0, t0 = time.process_time(), time.perf_counter()
            render(args.seed)  # same seed: the compiled kernel is reused
            times.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
            print(f"run {i + 1}/{args.runs}: {times[-1]:.3f} s, {cpus[-1]:.3f} CPU-s", file=sys.stderr)
        med, med_cpu = statistics.median(times), statistics.median(cpus)
        nsamples = WIDTH * HEIGHT * args.spp
        result.update({
            "runs": args.runs, "times_s": [round(t, 3) for t in times], "median_s": round(med, 3),
            "samples_per_s": round(nsamples / med),
            "cpu_s": [round(t, 3) for t in cpus], "median_cpu_s": round(med_cpu, 3),
            "samples_per_cpu_s": round(nsamples / med_cpu),
            "loadavg_1m": round(os.getloadavg()[0], 2),
        })
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
