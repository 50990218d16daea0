"""lumen against Mitsuba 3 for speed on any Mitsuba scene file, each reading
the XML itself, in one run: seconds per render at the same sample count and
efficiency, 1 / (mean per-pixel variance x seconds), which compares them at
equal noise (docs/peers.md, "Efficiency").

Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/mitsuba_xml_speed.py SCENE.xml SPP [NAME=VALUE ...]

Mitsuba runs in its fastest CPU variant, llvm_ad_rgb (vectorised, compiled
on the fly: one render first, untimed, compiles its kernels), on every
thread; lumen runs its release build from the command line (reading the
scene included) on every thread. Each renders seeds 1 and 2; the variance
is half the mean squared difference of the two (pixels with a difference
beyond 100 times the median are left out of it for both, so that one rare
firefly does not decide the figure; how many is printed).
"""

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import drjit as dr
import mitsuba as mi
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peerlib import render_xml_with_lumen, xml_arguments  # noqa: E402

SCENE, SPP, DEFINES = xml_arguments(sys.argv)

mi.set_variant("llvm_ad_rgb")


def lumen(seed, d):
    out = Path(d) / f"lumen{seed}.exr"
    seconds = render_xml_with_lumen(SCENE, seed, DEFINES, out)
    return np.array(mi.Bitmap(str(out)))[..., :3].astype(np.float64), seconds


scene = mi.load_file(str(SCENE), **DEFINES)


def mitsuba(seed):
    t0 = time.perf_counter()
    img = mi.render(scene, spp=SPP, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    seconds = time.perf_counter() - t0
    return np.array(img)[..., :3].astype(np.float64), seconds


def variance(a, b, keep):
    return float(((a - b) ** 2)[keep].mean() / 2)


mitsuba(0)  # compiles the kernels
with tempfile.TemporaryDirectory() as d:
    (l1, tl1), (l2, tl2) = lumen(1, d), lumen(2, d)
(m1, tm1), (m2, tm2) = mitsuba(1), mitsuba(2)
# The same pixels left out of both: where either renderer's two seeds
# differ by more than 100 times its median difference.
dl, dm = np.abs(l1 - l2).sum(-1), np.abs(m1 - m2).sum(-1)
keep = (dl <= 100 * max(np.median(dl), 1e-6)) & (dm <= 100 * max(np.median(dm), 1e-6))
vl, vm = variance(l1, l2, keep), variance(m1, m2, keep)
tl, tm = (tl1 + tl2) / 2, (tm1 + tm2) / 2
cpu = "?"
try:
    cpu = re.search(r"Model name:\s*(.*)", subprocess.run(
        ["lscpu"], capture_output=True, text=True).stdout).group(1)
except (AttributeError, OSError):
    pass
print(f"{SCENE.name}, {SPP} spp, {cpu}, {dr.thread_count()} threads")
print(f"  lumen   {tl:8.2f} s  mean {l1.mean():.5f}  variance {vl:.4e}")
print(f"  Mitsuba {tm:8.2f} s  mean {m1.mean():.5f}  variance {vm:.4e}  (llvm_ad_rgb)")
print(f"  pixels left out: {int((~keep).sum())} of {keep.size}")
print(f"  time Mitsuba / lumen: {tm / tl:.2f}; efficiency lumen / Mitsuba: "
      f"{(vm * tm) / (vl * tl):.2f}")
