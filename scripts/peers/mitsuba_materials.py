#!/usr/bin/env python3
"""A lumen scene of conductor, rough-dielectric and diffuse spheres
(scripts/peers/materials-scene.toml), rendered with Mitsuba 3.

    eval "$(scripts/peers/setup.sh --env)"
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_materials.py --spp 256 --seed 1 --out m.pfm
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_materials.py --spp 256 \\
        --seeds 0 1 2 3 --out-template /tmp/m-{seed}.pfm      # warm-up, then one render per seed
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_materials.py --smith correlated ...
    $LUMEN_PEERS_PYTHON scripts/peers/mitsuba_materials.py --print-materials   # the translation

Translation of the scene (read with tomllib, see docs/scene-format.md); only
these kinds are accepted, anything else is refused:

- sphere -> Mitsuba `sphere` (analytic).
- quad (corner Q, edges u, v) -> `rectangle` placed by the matrix of columns
  (u/2, v/2, unit u x v, Q + u/2 + v/2), its BSDF wrapped in `twosided`
  (lumen's quads scatter on both sides).
- diffuse (lambertian, attenuation "scale") -> `diffuse`, reflectance = albedo.
- conductor, `metal = NAME` -> Mitsuba's `material = NAME` (the same RGB
  eta/k: lumen's table is Mitsuba's reduction), or `eta`/`k` -> rgb eta/k.
  Smooth (no roughness, or alpha < 1e-3 as in lumen) -> `conductor`;
  rough -> `roughconductor`, distribution ggx|beckmann, alpha = roughness²
  (or `alpha` as given), sample_visible true. Isotropic only (a pair
  [u, v] is refused: the two renderers' tangent frames on a sphere need not
  agree).
- dielectric with a roughness (alpha >= 1e-3) -> `roughdielectric`,
  int_ior = ior, ext_ior = 1.0 (exactly; Mitsuba's default is air, 1.000277),
  alpha, distribution, sample_visible. With 0 < alpha < 1e-3 (lumen: the smooth
  exact-Fresnel interface) -> `dielectric` (int_ior, ext_ior 1.0). Roughness
  0 or absent is lumen's Schlick glass, which Mitsuba has no model of:
  refused.
- solid background colour C -> `constant` emitter of radiance C.
- camera, film, `path` integrator: peerlib.mitsuba_path_scene (max_depth =
  lumen's; both count ray segments). Russian roulette from --rr-depth,
  default 5 (Mitsuba's default; lumen's `path` integrator plays it from the
  fifth bounce too; both are unbiased, only the noise differs).

--smith correlated wraps every rough BSDF in `hcsmith`, a Python BSDF defined
here that multiplies the nested BSDF's value and sample weight by
G_corr / G_sep = 1 / (G1(wi) + G1(wo) - G1(wi) G1(wo)), with G1 Mitsuba's own
Smith term of the distribution (GGX: exactly 1/(1 + Lambda)). The sampling
(visible normals) and pdf are the nested BSDF's. This turns Mitsuba's
separable Smith shadowing G1(wi) G1(wo) into the height-correlated
1/(1 + Lambda(wi) + Lambda(wo)) that lumen (and pbrt-v4, glTF) use, so that a
remaining difference from lumen is not the shadowing model.
"""

import argparse
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peerlib  # noqa: E402

HERE = Path(__file__).resolve().parent
SMOOTH_ALPHA = 1e-3  # lumen: below this alpha the surface is a mirror (bsdf/microfacet.rs)


# ------------------------------------------------------------------ scene
def read_scene(path):
    """The lumen scene at `path`, checked to hold only what is translated."""
    scene = peerlib.fill_defaults(tomllib.loads(Path(path).read_text()))
    if scene["camera"].get("defocus_angle", 0.0) != 0.0:
        raise ValueError(f"{path}: only a pinhole camera (defocus_angle 0) is supported")
    if scene.get("background", {}).get("type") != "solid":
        raise ValueError(f"{path}: only a solid background is supported")
    if scene["render"].get("integrator", "path") != "path":
        print(f"note: {path}: integrator {scene['render']['integrator']!r}; Mitsuba renders `path` "
              "(same expected image)", file=sys.stderr)
    for i, o in enumerate(scene.get("objects", [])):
        if o["type"] not in ("sphere", "quad") or "transform" in o:
            raise ValueError(f"{path}: objects[{i}]: only spheres and quads without transforms "
                             "are supported")
    for name, m in scene.get("materials", {}).items():
        material_dict(name, m)  # raises on what is not supported
    return scene


def alpha_of(name, m):
    """The material's microfacet alpha (isotropic), 0 when none is given."""
    if "roughness" in m and "alpha" in m:
        raise ValueError(f"material {name}: give roughness or alpha, not both")
    for key, square in (("roughness", True), ("alpha", False)):
        if key in m:
            v = m[key]
            if not isinstance(v, (int, float)):
                raise ValueError(f"material {name}: {key} {v!r}: only one number (isotropic, "
                                 "no texture) is supported")
            v = float(v)
            if v < 0 or (square and v > 1):
                raise ValueError(f"material {name}: {key} {v} out of range")
            return v * v if square else v
    return 0.0


def distribution_of(name, m):
    d = m.get("distribution", "ggx")
    if d not in ("ggx", "beckmann"):
        raise ValueError(f"material {name}: distribution {d!r}")
    return d


def material_dict(name, m, smith="separable"):
    """The Mitsuba BSDF dict for lumen material `m` (named `name`)."""
    t = m["type"]
    common = {"type", "emission", "emission_strength", "two_sided"}
    if m.get("emission"):
        raise ValueError(f"material {name}: emission is not supported")
    if t == "diffuse":
        extra = set(m) - common - {"albedo", "bounce", "attenuation"}
        if extra or m.get("bounce", "lambertian") != "lambertian" \
                or m.get("attenuation", "scale") != "scale" or isinstance(m["albedo"], str):
            raise ValueError(f"material {name}: only lambertian/scale diffuse of a constant albedo")
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": peerlib.rgb(m["albedo"])}}
    if t == "conductor":
        extra = set(m) - common - {"metal", "eta", "k", "roughness", "alpha", "distribution"}
        if extra:
            raise ValueError(f"material {name}: fields {sorted(extra)} not supported")
        if "metal" in m:
            if "eta" in m or "k" in m:
                raise ValueError(f"material {name}: metal or eta/k, not both")
            d = {"material": str(m["metal"])}
        else:
            d = {"eta": {"type": "rgb", "value": peerlib.rgb(m["eta"])},
                 "k": {"type": "rgb", "value": peerlib.rgb(m["k"])}}
        alpha = alpha_of(name, m)
        if alpha < SMOOTH_ALPHA:
            return {"type": "conductor", **d}
        return wrap(smith, {"type": "roughconductor", "distribution": distribution_of(name, m),
                            "alpha": alpha, "sample_visible": True, **d})
    if t == "dielectric":
        extra = set(m) - common - {"ior", "roughness", "alpha", "distribution", "refract_only"}
        if extra or m.get("refract_only", False):
            raise ValueError(f"material {name}: fields {sorted(extra)} / refract_only not supported")
        ior = float(m["ior"])
        zero = all(float(m.get(k, 0.0)) == 0.0 for k in ("roughness", "alpha")
                   if isinstance(m.get(k, 0.0), (int, float)))
        if zero:
            raise ValueError(f"material {name}: a dielectric without roughness is lumen's Schlick "
                             "glass, which Mitsuba has no model of")
        alpha = alpha_of(name, m)
        if alpha < SMOOTH_ALPHA:
            return {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0}
        return wrap(smith, {"type": "roughdielectric", "distribution": distribution_of(name, m),
                            "alpha": alpha, "sample_visible": True,
                            "int_ior": ior, "ext_ior": 1.0})
    raise ValueError(f"material {name}: type {t!r} not supported")


def wrap(smith, d):
    if smith == "separable":
        return d
    return {"type": "hcsmith", "alpha": d["alpha"], "distribution": d["distribution"], "nested": d}


# ------------------------------------------- height-correlated Smith wrapper
def register_hcsmith(mi, dr):
    """Register the Python BSDF `hcsmith` (see the module docstring)."""

    class HeightCorrelatedSmith(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.nested = props["nested"]
            alpha = props.get("alpha", 0.1)
            kind = props.get("distribution", "ggx")
            mtype = mi.MicrofacetType.GGX if kind == "ggx" else mi.MicrofacetType.Beckmann
            self.distr = mi.MicrofacetDistribution(mtype, alpha, alpha, True)
            self.m_flags = self.nested.flags()
            self.m_components = [self.nested.flags(i) for i in range(self.nested.component_count())]

        def ratio(self, wi, wo):
            up = mi.Vector3f(0, 0, 1)
            g_i = self.distr.smith_g1(mi.Vector3f(wi.x, wi.y, dr.abs(wi.z)), up)
            g_o = self.distr.smith_g1(mi.Vector3f(wo.x, wo.y, dr.abs(wo.z)), up)
            den = g_i + g_o - g_i * g_o
            return dr.select(den > 0, dr.rcp(den), 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            bs, w = self.nested.sample(ctx, si, sample1, sample2, active)
            return bs, w * self.ratio(si.wi, bs.wo)

        def eval(self, ctx, si, wo, active=True):
            return self.nested.eval(ctx, si, wo, active) * self.ratio(si.wi, wo)

        def pdf(self, ctx, si, wo, active=True):
            return self.nested.pdf(ctx, si, wo, active)

        def eval_pdf(self, ctx, si, wo, active=True):
            v, p = self.nested.eval_pdf(ctx, si, wo, active)
            return v * self.ratio(si.wi, wo), p

        def traverse(self, callback):
            self.nested.traverse(callback)

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"HeightCorrelatedSmith[{self.nested}]"

    mi.register_bsdf("hcsmith", lambda props: HeightCorrelatedSmith(props))


def build_scene(mi, scene, spp, seed=0, rr_depth=5, max_depth=None, smith="separable"):
    d = peerlib.mitsuba_path_scene(mi, scene, spp, "independent", seed, max_depth, rr_depth)
    d["sky"] = {"type": "constant",
                "radiance": {"type": "rgb", "value": peerlib.rgb(scene["background"]["color"])}}
    bsdfs = {name: material_dict(name, m, smith) for name, m in scene["materials"].items()}
    for i, o in enumerate(scene["objects"]):
        if o["type"] == "sphere":
            d[f"sphere{i}"] = {"type": "sphere", "center": [float(x) for x in o["center"]],
                               "radius": float(o["radius"]), "bsdf": bsdfs[o["material"]]}
        else:
            d[f"quad{i}"] = {"type": "rectangle", "to_world": quad_transform(mi, o),
                             "bsdf": {"type": "twosided", "bsdf": bsdfs[o["material"]]}}
    return mi.load_dict(d)


def quad_transform(mi, o):
    """Mitsuba's rectangle ([-1, 1]^2 at z = 0, normal +z) onto lumen's quad
    Q, Q + u, Q + u + v, Q + v (normal along u x v)."""
    q, u, v = (np.array(o[k], float) for k in ("corner", "u", "v"))
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, q + u / 2 + v / 2
    return mi.ScalarTransform4f(m.tolist())


def print_materials(mi, scene, smith):
    """Each material's Mitsuba dict and, for conductors, the eta/k Mitsuba uses."""
    for name, m in scene["materials"].items():
        d = material_dict(name, m, smith)
        line = f"{name}: {d}"
        inner = d.get("nested", d)
        if inner["type"] in ("conductor", "roughconductor"):
            p = mi.traverse(mi.load_dict(inner))
            eta = [round(float(x), 6) for x in np.ravel(np.asarray(p["eta.value"]))]
            k = [round(float(x), 6) for x in np.ravel(np.asarray(p["k.value"]))]
            line += f"\n    Mitsuba eta {eta}, k {k}"
        print(line)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?", default=str(HERE / "materials-scene.toml"))
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the single render (--out)")
    ap.add_argument("--out", help="render once at --seed and write this .pfm or .exr (linear RGB)")
    ap.add_argument("--seeds", type=int, nargs="+", help="render each seed (after a warm-up render)")
    ap.add_argument("--out-template", help="with --seeds: image path with {seed}, e.g. /tmp/m-{seed}.pfm")
    ap.add_argument("--rr-depth", default="5",
                    help="Russian roulette from this depth (default 5, Mitsuba's); 'off' for none")
    ap.add_argument("--max-depth", type=int, help="default: the scene's max_depth")
    ap.add_argument("--smith", choices=["separable", "correlated"], default="separable",
                    help="Mitsuba's own separable Smith G (default) or the height-correlated G "
                         "(the hcsmith wrapper)")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit worker threads (default: all cores)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--print-materials", action="store_true", help="print the translation and exit")
    args = ap.parse_args(argv)

    scene = read_scene(args.scene)
    spp = args.spp or scene["render"]["samples_per_pixel"]
    rr_depth = None if args.rr_depth == "off" else int(args.rr_depth)

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    if args.threads > 0:
        dr.set_thread_count(args.threads)
    if args.smith == "correlated":
        register_hcsmith(mi, dr)
    if args.print_materials:
        print_materials(mi, scene, args.smith)
        return 0
    if not args.out and not args.seeds:
        ap.error("give --out (one render) or --seeds with --out-template")

    t0 = time.perf_counter()
    seed0 = args.seeds[0] if args.seeds else args.seed
    ms = build_scene(mi, scene, spp, seed0, rr_depth, args.max_depth, args.smith)
    t_build = time.perf_counter() - t0

    def render(seed):
        img = mi.render(ms, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return img

    def save(seed, img, path=None):
        path = Path(path or args.out_template.format(seed=seed))
        if path.suffix.lower() == ".pfm":
            peerlib.write_pfm(path, np.asarray(img))
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            mi.Bitmap(img).write(str(path))

    result = {"renderer": "mitsuba", "version": mi.__version__, "variant": mi.variant(),
              "scene": Path(args.scene).name, "width": scene["render"]["width"],
              "height": scene["render"]["height"], "spp": spp,
              "max_depth": args.max_depth or scene["render"]["max_depth"],
              "rr_depth": args.rr_depth, "smith": args.smith, "threads": dr.thread_count(),
              "build_s": round(t_build, 3)}
    if args.out:
        t0 = time.perf_counter()
        img = render(args.seed)
        t = time.perf_counter() - t0
        save(args.seed, img, args.out)
        a = np.asarray(img)
        print(f"wrote {args.out}: seed {args.seed}, {t:.2f} s (includes JIT), "
              f"mean {a[..., :3].reshape(-1, 3).mean(0).round(5).tolist()}", file=sys.stderr)
        result.update(seed=args.seed, first_render_s=round(t, 3))
    if args.seeds:
        if not args.out_template or "{seed}" not in args.out_template:
            ap.error("--seeds needs --out-template with {seed}")
        result.update(peerlib.timed_renders(render, args.seeds, save))
    peerlib.print_json(result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
