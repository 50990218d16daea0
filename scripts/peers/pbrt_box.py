"""lumen reading assets/pbrt/box.pbrt against Mitsuba 3 rendering the same
scene written by hand (assets/pbrt/box.mitsuba.xml).

Prints each renderer's image mean, their ratio per half and quarter, and
the relative RMS difference beside Mitsuba's own seed-to-seed noise.
Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/pbrt_box.py [SPP].
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import mitsuba as mi
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SPP = int(sys.argv[1]) if len(sys.argv) > 1 else 1024

mi.set_variant("scalar_rgb")


def mitsuba(seed):
    scene = mi.load_file(str(ROOT / "assets/pbrt/box.mitsuba.xml"), spp=SPP)
    return np.array(mi.render(scene, spp=SPP, seed=seed))


def lumen():
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "box.exr"
        subprocess.run(
            [str(ROOT / "target/release/lumen"), "render", str(ROOT / "assets/pbrt/box.pbrt"),
             "--spp", str(SPP), "-o", str(out)],
            check=True, capture_output=True)
        return np.array(mi.Bitmap(str(out)))[..., :3]


a, b, c = lumen(), mitsuba(0), mitsuba(1)
print(f"{SPP} spp; lumen mean {a.mean(axis=(0, 1))}, Mitsuba {b.mean(axis=(0, 1))}")
h, w = b.shape[:2]
for name, part in [("image", np.s_[:]), ("left", np.s_[:, : w // 2]), ("right", np.s_[:, w // 2:]),
                   ("top", np.s_[: h // 2]), ("bottom", np.s_[h // 2:])]:
    print(f"{name:>6}: lumen / Mitsuba = {a[part].mean(axis=(0, 1)) / b[part].mean(axis=(0, 1))}")
rms = lambda x, y: np.sqrt(((x - y) ** 2).mean()) / y.mean()
print(f"relative RMS lumen - Mitsuba {rms(a, b):.4f}; Mitsuba seed 0 - seed 1 {rms(c, b):.4f}")
