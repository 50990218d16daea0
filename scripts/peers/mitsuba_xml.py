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
print(f"{SCENE.name}, {SPP} spp; lumen mean {a.mean(axis=(0, 1))}, Mitsuba {b.mean(axis=(0, 1))}")
h, w = b.shape[:2]
for name, part in [("image", np.s_[:]), ("left", np.s_[:, : w // 2]), ("right", np.s_[:, w // 2:]),
                   ("top", np.s_[: h // 2]), ("bottom", np.s_[h // 2:])]:
    print(f"{name:>6}: lumen / Mitsuba = {a[part].mean(axis=(0, 1)) / b[part].mean(axis=(0, 1))}")
rms = lambda x, y: np.sqrt(((x - y) ** 2).mean()) / y.mean()
lm, ll, mm = rms(a, b), rms(a1, a), rms(c, b)
print(f"relative RMS lumen - Mitsuba {lm:.4f}; seed 0 - seed 1: lumen {ll:.4f}, Mitsuba {mm:.4f}")
# Were the images equal but for noise, the difference's mean square would
# be the sum of the two renderers' noises (each half its seed-to-seed value).
excess = lm ** 2 - (ll ** 2 + mm ** 2) / 2
print(f"relative RMS beyond noise: {np.sign(excess) * np.sqrt(abs(excess)):.4f}")
