"""Helpers shared by the peer-renderer scripts (Mitsuba 3 and Cycles).

Pure Python + numpy, so it imports in either venv (scripts/peers/setup.sh,
scripts/peers/setup_cycles.sh) and in a plain Python with numpy.

- read_lumen_scene(path): a lumen TOML scene (docs/scene-format.md) as a dict,
  with the defaults the peer scripts rely on filled in and checked.
- write_pfm(path, rgb): linear float RGB image, top row first in `rgb`.
- timed_renders(render, seeds, ...): the timing protocol of the efficiency
  measurements (one warm-up render, then one timed render per seed).
- compare_images(lumen, lumen_again, peer, peer_again, name): two renderers'
  images of one scene (each rendered twice with other seeds) compared: means,
  their ratio per half and quarter, and the difference beyond the noise.
- xml_arguments(argv), render_xml_with_lumen(...): the command line of the
  scripts that give a Mitsuba scene file to both renderers, and lumen's
  render of such a file.
"""

import json
import math
import os
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np


# ------------------------------------------------------------------ scene
def fill_defaults(scene):
    """`scene` (a parsed lumen TOML scene) with lumen's defaults filled in for
    the render and camera fields the peer scripts read."""
    r = scene.setdefault("render", {})
    r.setdefault("width", 400)
    if "height" not in r:
        r["height"] = max(1, int(r["width"] / r.get("aspect_ratio", 16 / 9)))
    r.setdefault("samples_per_pixel", 100)
    r.setdefault("max_depth", 50)
    r.setdefault("seed", 0)
    c = scene.setdefault("camera", {})
    c.setdefault("vfov", 90.0)
    c.setdefault("lookfrom", [0.0, 0.0, 0.0])
    c.setdefault("lookat", [0.0, 0.0, -1.0])
    c.setdefault("vup", [0.0, 1.0, 0.0])
    return scene


def mitsuba_path_scene(mi, scene, spp, sampler="independent", seed=0, max_depth=None,
                       rr_depth=None, width=None, clip=(1e-3, 1e5)):
    """The start of a Mitsuba scene dict for a lumen scene: its `path`
    integrator (max_depth = lumen's, both counting ray segments; Russian
    roulette from `rr_depth`, None for none) and its camera (`perspective`,
    fov_axis "y", box pixel filter, `width` wide with the scene's aspect, the
    scene's size by default). The caller adds shapes and emitters."""
    r, cam = scene["render"], scene["camera"]
    width = width or r["width"]
    height = max(1, r["height"] * width // r["width"])
    max_depth = max_depth or r["max_depth"]
    rr = max_depth + 100 if rr_depth is None else rr_depth
    sampler_dict = {"type": sampler, "sample_count": spp, "seed": seed}
    if sampler in ("stratified", "multijitter"):
        sampler_dict["jitter"] = True
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth, "rr_depth": rr},
        "sensor": {
            "type": "perspective",
            "fov": float(cam["vfov"]),
            "fov_axis": "y",
            "near_clip": clip[0],
            "far_clip": clip[1],
            "to_world": mi.ScalarTransform4f().look_at(origin=cam["lookfrom"], target=cam["lookat"],
                                                      up=cam["vup"]),
            "sampler": sampler_dict,
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "pixel_format": "rgb", "component_format": "float32",
                     "rfilter": {"type": "box"}},
        },
    }


def read_lumen_scene(path):
    """The lumen scene at `path` (TOML), with camera/render defaults filled.

    Only what the peer scripts support is accepted: a solid background,
    diffuse (lambertian, scale) and metal materials, sphere objects.
    """
    scene = fill_defaults(tomllib.loads(Path(path).read_text()))
    if scene["camera"].get("defocus_angle", 0.0) != 0.0:
        raise ValueError(f"{path}: only a pinhole camera (defocus_angle 0) is supported")
    bg = scene.get("background", {})
    if bg.get("type") != "solid":
        raise ValueError(f"{path}: only a solid background is supported")
    for name, m in scene.get("materials", {}).items():
        if m["type"] == "diffuse":
            if m.get("bounce", "lambertian") != "lambertian" or m.get("attenuation", "scale") != "scale":
                raise ValueError(f"{path}: material {name}: only lambertian/scale diffuse")
        elif m["type"] == "metal":
            if m.get("fuzz", 0.0) != 0.0:
                raise ValueError(f"{path}: material {name}: only mirrors (fuzz 0)")
        else:
            raise ValueError(f"{path}: material {name}: type {m['type']} not supported")
    for i, o in enumerate(scene.get("objects", [])):
        if o["type"] != "sphere":
            raise ValueError(f"{path}: objects[{i}]: only spheres are supported")
    return scene


# ----------------------------------------------------------------- images
def write_pfm(path, rgb):
    """Write H x W x 3 linear float RGB (row 0 = top) as a PFM file, atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    a = np.asarray(rgb, dtype=np.float32)[:, :, :3]
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as f:
        f.write(f"PF\n{a.shape[1]} {a.shape[0]}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(a[::-1]).astype("<f4").tobytes())  # PFM: bottom row first
    os.replace(tmp, path)


def loadavg():
    """The 1-, 5- and 15-minute load averages (/proc/loadavg)."""
    return [round(x, 2) for x in os.getloadavg()]


# ----------------------------------------------------------------- timing
def timed_renders(render, seeds, save=None, warmup=True, log=sys.stderr):
    """Time one render per seed, after a warm-up render.

    `render(seed)` renders and returns the image (it must block until the
    image is finished); `save(seed, image)`, if given, writes it (not timed).
    The warm-up render (first seed) absorbs scene upload, kernel compilation
    and caches; it is not counted. Returns a dict with the per-seed wall and
    CPU seconds (this process, all threads) and the load averages at the
    start and end.
    """
    out = {"loadavg_start": loadavg()}
    if warmup:
        t0 = time.perf_counter()
        render(seeds[0])
        out["warmup_s"] = round(time.perf_counter() - t0, 3)
        print(f"warm-up render (seed {seeds[0]}): {out['warmup_s']:.3f} s", file=log)
    times, cpus = [], []
    for s in seeds:
        c0, t0 = time.process_time(), time.perf_counter()
        img = render(s)
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        print(f"seed {s}: {times[-1]:.3f} s, {cpus[-1]:.3f} CPU-s", file=log)
        if save:
            save(s, img)
    out.update(seeds=list(seeds), times_s=[round(t, 4) for t in times],
               cpu_s=[round(t, 3) for t in cpus],
               mean_s=round(sum(times) / len(times), 4), loadavg_end=loadavg())
    return out


def print_json(d):
    print(json.dumps(d), flush=True)


def camera_basis(cam):
    """lumen's camera frame: (eye, w, u, v) with w pointing backwards
    (eye - lookat), u right, v up; numpy float64 vectors."""
    eye = np.array(cam["lookfrom"], float)
    at = np.array(cam["lookat"], float)
    up = np.array(cam["vup"], float)
    w = eye - at
    w /= np.linalg.norm(w)
    u = np.cross(up, w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    return eye, w, u, v


def rgb(x):
    """A colour triple from a number or a list."""
    if isinstance(x, (int, float)):
        return [float(x)] * 3
    if len(x) != 3 or not all(math.isfinite(float(c)) for c in x):
        raise ValueError(f"bad colour {x!r}")
    return [float(c) for c in x]


# -------------------------------------------------------- mitsuba scene files
def xml_arguments(argv):
    """SCENE.xml SPP [NAME=VALUE ...]: the scene's path, the sample count
    and the scene's defaults to set (spp among them), for both renderers."""
    scene = Path(argv[1]).resolve()
    spp = int(argv[2])
    defines = dict(a.split("=", 1) for a in argv[3:])
    defines["spp"] = str(spp)
    return scene, spp, defines


def render_xml_with_lumen(scene, seed, defines, out):
    """lumen's release build renders Mitsuba scene file `scene` with `seed`
    and `defines` (as -D) to `out`; returns the seconds it took, reading
    the scene included."""
    root = Path(__file__).resolve().parents[2]
    args = [str(root / "target/release/lumen"), "render", str(scene), "--seed", str(seed),
            "-o", str(out)]
    for k, v in defines.items():
        args += ["-D", f"{k}={v}"]
    t0 = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    return time.perf_counter() - t0


# ------------------------------------------------------------------ compare
def compare_images(a, a1, b, b1, name="peer"):
    """Prints how lumen's image `a` (and `a1`, another seed) compares with a
    peer's `b` (and `b1`): image means, their ratio per half and quarter, the
    relative RMS difference beside each renderer's seed-to-seed noise, and
    what is left of it beyond that noise (about 0 when the images differ by
    noise alone)."""
    print(f"lumen mean {a.mean(axis=(0, 1))}, {name} {b.mean(axis=(0, 1))}")
    h, w = b.shape[:2]
    for part_name, part in [("image", np.s_[:]), ("left", np.s_[:, : w // 2]),
                            ("right", np.s_[:, w // 2:]), ("top", np.s_[: h // 2]),
                            ("bottom", np.s_[h // 2:])]:
        ratio = a[part].mean(axis=(0, 1)) / b[part].mean(axis=(0, 1))
        print(f"{part_name:>6}: lumen / {name} = {ratio}")
    rms = lambda x, y: np.sqrt(((x - y) ** 2).mean()) / y.mean()
    lm, ll, mm = rms(a, b), rms(a1, a), rms(b1, b)
    print(f"relative RMS lumen - {name} {lm:.4f}; seed 0 - seed 1: lumen {ll:.4f}, "
          f"{name} {mm:.4f}")
    # Were the images equal but for noise, the difference's mean square would
    # be the sum of the two renderers' noises (each half its seed-to-seed value).
    excess = lm ** 2 - (ll ** 2 + mm ** 2) / 2
    print(f"relative RMS beyond noise: {np.sign(excess) * np.sqrt(abs(excess)):.4f}")
