"""lumen reading pbrt-v4's killeroo-simple.pbrt against Mitsuba 3 rendering
the same scene written by hand (assets/pbrt/killeroos/killeroo-simple.mitsuba.xml).

Mitsuba has no subdivision surfaces: the killeroo's loopsubdiv limit mesh is
taken from lumen's export of the pbrt scene and written as killeroo.ply
beside a copy of the Mitsuba scene (the rest of that scene, camera, light,
floor, wall, placements and materials, is written by hand from the pbrt
file). Prints image means, their ratio per half and quarter, and the
relative RMS difference beside each renderer's seed-to-seed noise.

Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/pbrt_killeroo.py [SPP] [WIDTH].
"""

import shutil
import struct
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import mitsuba as mi
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peerlib import compare_images  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
LUMEN = str(ROOT / "target/release/lumen")
SCENE = ROOT / "assets/pbrt/killeroos/killeroo-simple.pbrt"
XML = ROOT / "assets/pbrt/killeroos/killeroo-simple.mitsuba.xml"
SPP = int(sys.argv[1]) if len(sys.argv) > 1 else 256
WIDTH = int(sys.argv[2]) if len(sys.argv) > 2 else 350

mi.set_variant("scalar_rgb")


def write_ply(path, positions, indices, normals):
    """A binary little-endian PLY of the mesh (with vertex normals)."""
    with open(path, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.write(f"element vertex {len(positions)}\n".encode())
        for p in ["x", "y", "z", "nx", "ny", "nz"]:
            f.write(f"property float {p}\n".encode())
        f.write(f"element face {len(indices)}\n".encode())
        f.write(b"property list uchar int vertex_indices\nend_header\n")
        for p, n in zip(positions, normals):
            f.write(struct.pack("<6f", *p, *n))
        for t in indices:
            f.write(struct.pack("<B3i", 3, *t))


def lumen(seed, d):
    out = Path(d) / f"lumen{seed}.exr"
    subprocess.run([LUMEN, "render", str(SCENE), "--spp", str(SPP), "--width", str(WIDTH),
                    "--sampler", "independent", "--seed", str(seed), "-o", str(out)],
                   check=True, capture_output=True)
    return np.array(mi.Bitmap(str(out)))[..., :3]


def mitsuba(seed, xml):
    scene = mi.load_file(str(xml), spp=SPP, width=WIDTH)
    return np.array(mi.render(scene, spp=SPP, seed=seed))


with tempfile.TemporaryDirectory() as d:
    exported = Path(d) / "k.toml"
    subprocess.run([LUMEN, "scenes", "export", str(SCENE), "-o", str(exported)],
                   check=True, capture_output=True)
    objects = tomllib.loads(exported.read_text())["objects"]
    meshes = [o for o in objects if o["type"] == "triangles" and len(o["positions"]) > 4]
    # Both killeroos are the one mesh, placed twice.
    assert len(meshes) == 2 and meshes[0]["positions"] == meshes[1]["positions"]
    k = meshes[0]
    write_ply(Path(d) / "killeroo.ply", k["positions"], k["indices"], k["normals"])
    xml = Path(d) / XML.name
    shutil.copy(XML, xml)
    print(f"{SCENE.name}, {WIDTH} x {WIDTH}, {SPP} spp, "
          f"{len(k['indices'])} triangles a killeroo")
    a, a1, b, b1 = lumen(0, d), lumen(1, d), mitsuba(0, xml), mitsuba(1, xml)
    compare_images(a, a1, b, b1, "Mitsuba")
    # The light, a sphere of radiance 2000 a few pixels wide, dominates the
    # whole image's error: where a sample lands about its pixel (lumen
    # draws it from the filter, Mitsuba splats it) moves thousands.
    below = np.s_[len(a) * 2 // 7:]
    print("\nbelow the light (the rows from 2/7 of the height down):")
    compare_images(a[below], a1[below], b[below], b1[below], "Mitsuba")
