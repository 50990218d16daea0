"""lumen against Mitsuba 3 on any Mitsuba scene file, each reading the XML
itself: image means, their ratio per half and quarter, and the relative
RMS difference beside each renderer's seed-to-seed noise.

Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/mitsuba_xml.py SCENE.xml SPP [NAME=VALUE ...]
(the NAME=VALUE pairs are the scene's defaults to set, for both, as
Mitsuba's and lumen's -D). Example: the material preview,
assets/mitsuba-data/scenes/matpreview/matpreview.xml 1024 width=342 height=256.
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import mitsuba as mi
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peerlib import compare_images  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCENE = Path(sys.argv[1]).resolve()
SPP = int(sys.argv[2])
DEFINES = dict(a.split("=", 1) for a in sys.argv[3:])
DEFINES["spp"] = str(SPP)

mi.set_variant("scalar_rgb")


def lumen(seed, d):
    out = Path(d) / f"lumen{seed}.exr"
    args = [str(ROOT / "target/release/lumen"), "render", str(SCENE), "--seed", str(seed),
            "-o", str(out)]
    for k, v in DEFINES.items():
        args += ["-D", f"{k}={v}"]
    subprocess.run(args, check=True, capture_output=True)
    return np.array(mi.Bitmap(str(out)))[..., :3]


def mitsuba(seed):
    scene = mi.load_file(str(SCENE), **DEFINES)
    return np.array(mi.render(scene, spp=SPP, seed=seed))[..., :3]


with tempfile.TemporaryDirectory() as d:
    a, a1 = lumen(0, d), lumen(1, d)
b, c = mitsuba(0), mitsuba(1)
print(f"{SCENE.name}, {SPP} spp")
compare_images(a, a1, b, c, "Mitsuba")
