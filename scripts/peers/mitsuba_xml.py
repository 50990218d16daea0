"""lumen against Mitsuba 3 on any Mitsuba scene file, each reading the XML
itself: image means, their ratio per half and quarter, and the relative
RMS difference beside each renderer's seed-to-seed noise.

Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/mitsuba_xml.py SCENE.xml SPP [NAME=VALUE ...]
(the NAME=VALUE pairs are the scene's defaults to set, for both, as
Mitsuba's and lumen's -D). Example: the material preview,
assets/mitsuba-data/scenes/matpreview/matpreview.xml 1024 width=342 height=256.
"""

import sys
import tempfile
from pathlib import Path

import mitsuba as mi
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peerlib import compare_images, render_xml_with_lumen, xml_arguments  # noqa: E402

SCENE, SPP, DEFINES = xml_arguments(sys.argv)

mi.set_variant("scalar_rgb")


def lumen(seed, d):
    out = Path(d) / f"lumen{seed}.exr"
    render_xml_with_lumen(SCENE, seed, DEFINES, out)
    return np.array(mi.Bitmap(str(out)))[..., :3]


def mitsuba(seed):
    scene = mi.load_file(str(SCENE), **DEFINES)
    return np.array(mi.render(scene, spp=SPP, seed=seed))[..., :3]


with tempfile.TemporaryDirectory() as d:
    a, a1 = lumen(0, d), lumen(1, d)
b, c = mitsuba(0), mitsuba(1)
print(f"{SCENE.name}, {SPP} spp")
compare_images(a, a1, b, c, "Mitsuba")
