"""lumen against Mitsuba 3 on `blendbsdf`: one Mitsuba scene, rendered by
each (lumen reads the XML itself).

Two spheres of blends (matte grey and rough gold at weight 0.3; a
two-sided blend of rough copper and rough red plastic at 0.6) over a floor
(an OBJ quad) whose blend of white matte and rough aluminium has a
checkerboard of weights 0.8 and 0.1, lit by a point light and a dim
constant sky. Prints each renderer's image mean, their ratio per half and
quarter, and the relative RMS difference beside Mitsuba's own
seed-to-seed noise.

With `delta`, the plastic is smooth and the floor's metal a mirror: blends
of a specular lobe with a spread one. Mitsuba's blendbsdf weighs a
specular sample by a pdf that adds the spread lobe's density to the
specular lobe's probability, which is biased there (docs/mitsuba.md gives
the figures); lumen's mix is not.
Run with the peers' Python: eval "$(scripts/peers/setup.sh --env)";
$LUMEN_PEERS_PYTHON scripts/peers/mitsuba_blend.py [SPP] [delta].
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
SPP = int(sys.argv[1]) if len(sys.argv) > 1 else 512
DELTA = len(sys.argv) > 2 and sys.argv[2] == "delta"

mi.set_variant("scalar_rgb")

SCENE = """<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 2.2, 6" target="0, 0.4, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="160"/><integer name="height" value="120"/>
      <rfilter type="box"/></film>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
  </sensor>
  <emitter type="point"><point name="position" x="2" y="4" z="3"/>
    <rgb name="intensity" value="30"/></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.15"/></emitter>
  <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.5"/></bsdf>
  <bsdf type="roughconductor" id="gold"><string name="material" value="Au"/>
    <float name="alpha" value="0.2"/></bsdf>
  <shape type="sphere"><point name="center" x="-1.1" y="0.8" z="0"/><float name="radius" value="0.8"/>
    <bsdf type="blendbsdf"><float name="weight" value="0.3"/><ref id="grey"/><ref id="gold"/></bsdf>
  </shape>
  <shape type="sphere"><point name="center" x="1.1" y="0.8" z="0"/><float name="radius" value="0.8"/>
    <bsdf type="twosided"><bsdf type="blendbsdf"><float name="weight" value="0.6"/>
      <bsdf type="roughconductor"><string name="material" value="Cu"/>
        <float name="alpha" value="0.05"/></bsdf>
      <bsdf type="$plastic"><rgb name="diffuse_reflectance" value="0.7, 0.1, 0.1"/>
        <float name="alpha" value="0.1"/></bsdf>
    </bsdf></bsdf>
  </shape>
  <shape type="obj"><string name="filename" value="floor.obj"/>
    <bsdf type="blendbsdf">
      <texture type="checkerboard" name="weight">
        <float name="color0" value="0.8"/><float name="color1" value="0.1"/>
        <transform name="to_uv"><scale x="4" y="4"/></transform></texture>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>
      <bsdf type="$metal"><string name="material" value="Al"/>
        <float name="alpha" value="0.06"/></bsdf>
    </bsdf>
  </shape>
</scene>
"""

FLOOR = """v -4 0 -4
v 4 0 -4
v 4 0 4
v -4 0 4
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
f 1/1/1 4/4/1 3/3/1 2/2/1
"""


def main():
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        (d / "floor.obj").write_text(FLOOR)
        smooth = {"plastic": "plastic", "metal": "conductor"}
        rough = {"plastic": "roughplastic", "metal": "roughconductor"}
        text = SCENE
        for name, plugin in (smooth if DELTA else rough).items():
            text = text.replace(f"${name}", plugin)
        if DELTA:
            text = text.replace('<float name="alpha" value="0.1"/>', "")
            text = text.replace('\n        <float name="alpha" value="0.06"/></bsdf>', "</bsdf>")
        (d / "blend.xml").write_text(text)
        def lumen(seed):
            out = d / f"lumen{seed}.exr"
            subprocess.run(
                [str(ROOT / "target/release/lumen"), "render", str(d / "blend.xml"),
                 "-D", f"spp={SPP}", "--seed", str(seed), "-o", str(out)],
                check=True, capture_output=True)
            return np.array(mi.Bitmap(str(out)))[..., :3]

        a, a1 = lumen(0), lumen(1)
        scene = mi.load_file(str(d / "blend.xml"), spp=SPP)
        b, c = (np.array(mi.render(scene, spp=SPP, seed=s)) for s in (0, 1))
        if DELTA:
            # The right sphere's two BSDFs alone (weights 0 and 1 make
            # Mitsuba's blend exact), and the blend they make.
            alone = []
            for w in ("0", "1"):
                (d / "alone.xml").write_text(
                    text.replace('<float name="weight" value="0.6"/>',
                                 f'<float name="weight" value="{w}"/>'))
                one = mi.load_file(str(d / "alone.xml"), spp=SPP)
                alone.append(np.array(mi.render(one, spp=SPP, seed=0)))
            blend = 0.4 * alone[0] + 0.6 * alone[1]
    print(f"{SPP} spp")
    compare_images(a, a1, b, c, "Mitsuba")
    if DELTA:
        h, w = b.shape[:2]
        sphere = np.s_[int(h * .3):int(h * .6), int(w * .6):int(w * .8)]
        mean = lambda x: x[sphere].mean(axis=(0, 1))
        print(f"right sphere, against 0.4 copper + 0.6 plastic rendered apart by Mitsuba: "
              f"lumen {mean(a) / mean(blend)}, Mitsuba {mean(b) / mean(blend)}")

main()
