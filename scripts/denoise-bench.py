#!/usr/bin/env python3
"""The denoiser measured as a user feels it: noisy and denoised images at a
few sample counts against a reference of many more, with their times.

For each scene, renders a reference at --reference-spp (kept in --cache and
reused), then at each of --spp renders with `--denoise` (which writes the
noisy image beside the denoised one) and reports, for both:
  - relMSE: mean over pixels and channels of (x - r)^2 / (r^2 + eps),
    eps = 0.01 (so that black pixels do not dominate);
  - PSNR (dB) of the display images (gamma 2.2, clamped to [0, 1]);
  - HDR-FLIP (PyPI `flip-evaluator`, its defaults: 67 pixels a degree);
  - each channel's image mean against the reference's;
  - the render's and the denoiser's seconds, from lumen's own report.

usage: scripts/denoise-bench.py LUMEN [--scenes cornell-box,...] [--width W]
       [--denoiser oidn|atrous]
       [--spp 16,64,256] [--reference-spp 16384] [--cache DIR]
Needs, for OIDN (the default), a lumen built with the `oidn` feature and OIDN_DIR set
(docs/denoising.md), and numpy, mitsuba (to read EXR) and flip-evaluator:
scripts/peers/setup.sh makes such a Python ($LUMEN_PEERS_PYTHON).
"""
import argparse
import os
import re
import subprocess
import sys

import flip_evaluator
import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

EPS = 0.01
SCENES = {
    # name: (scene argument, extra render arguments)
    # With next-event estimation and lumen's best sampler: the book's
    # scene finds its light by chance (`integrator = "bsdf"`), and noise
    # that heavy-tailed comes out of OIDN up to 5 % too bright
    # (docs/denoising.md, "Means").
    "cornell-box": ("cornell-box", ["--integrator", "path", "--sampler", "zsobol"]),
    "bunny-sky": ("examples/bunny-sky.toml", []),
    "materials": ("examples/materials.toml", []),
    # Textured, normal-mapped glTF models under a sky (not in the default
    # set: its reference takes longest).
    "gltf-models": ("examples/gltf-models.toml", []),
}


def rgb(path):
    """The R, G, B channels of an EXR file as an HxWx3 array."""
    bitmap = mi.Bitmap(path)
    names = [f.name for f in bitmap.struct_()]
    values = np.array(bitmap)
    return np.stack([values[..., names.index(c)] for c in "RGB"], axis=-1).astype(np.float64)


def render(lumen, scene, extra, width, spp, out):
    """Renders; returns (render seconds, denoise seconds or None)."""
    return run_render([lumen, "render", scene, "--width", str(width), "--spp", str(spp),
                       "-o", out, "--checkpoint-interval", "1h"] + extra)


def run_render(command):
    """Runs a `lumen render` command line; returns (render seconds, denoise
    seconds or None) from its report, or exits with its error."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{done.stderr}")
    seconds = float(re.search(r"^time ([0-9.]+) s", done.stderr, re.M).group(1))
    denoise = re.search(r"^denoised in ([0-9.]+) s", done.stderr, re.M)
    return seconds, float(denoise.group(1)) if denoise else None


def metrics(image, reference):
    rel = np.mean((image - reference) ** 2 / (reference ** 2 + EPS))
    display = lambda x: np.clip(x, 0, 1) ** (1 / 2.2)
    mse = np.mean((display(image) - display(reference)) ** 2)
    psnr = 10 * np.log10(1 / mse) if mse > 0 else float("inf")
    flip = flip_evaluator.evaluate(reference.astype(np.float32), np.maximum(image, 0).astype(np.float32),
                                   "HDR", applyMagma=False)[1]
    means = image.mean(axis=(0, 1)) / reference.mean(axis=(0, 1))
    return rel, psnr, flip, means


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("lumen")
    p.add_argument("--scenes", default="cornell-box,bunny-sky,materials")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--spp", default="16,64,256")
    p.add_argument("--reference-spp", type=int, default=16384)
    p.add_argument("--cache", default="denoise-bench")
    p.add_argument("--denoiser", default="oidn", help="oidn or atrous (lumen's own filter)")
    a = p.parse_args()
    os.makedirs(a.cache, exist_ok=True)
    print(f"relMSE eps = {EPS}; PSNR of gamma-2.2 images clamped to [0, 1]; HDR-FLIP; "
          f"means as fractions of the reference's")
    print("| scene | spp | image | relMSE | PSNR dB | FLIP | mean R, G, B | render s | denoise s |")
    print("| --- | ---: | --- | ---: | ---: | ---: | --- | ---: | ---: |")
    for name in a.scenes.split(","):
        scene, extra = SCENES[name]
        ref_path = os.path.join(a.cache, f"{name}-{a.width}-{a.reference_spp}.exr")
        if not os.path.exists(ref_path):
            t, _ = render(a.lumen, scene, extra, a.width, a.reference_spp, ref_path)
            print(f"reference {ref_path}: {t:.1f} s", file=sys.stderr)
        reference = rgb(ref_path)
        for spp in [int(s) for s in a.spp.split(",")]:
            out = os.path.join(a.cache, f"{name}-{a.width}-{spp}.exr")
            t, td = render(a.lumen, scene, extra + ["--denoise", "--denoiser", a.denoiser], a.width, spp, out)
            noisy = out[:-4] + ".noisy.exr"
            for label, path, seconds in [("noisy", noisy, None), ("denoised", out, td)]:
                rel, psnr, flip, means = metrics(rgb(path), reference)
                m = ", ".join(f"{v:.4f}" for v in means)
                den = f"{seconds:.2f}" if seconds is not None else ""
                print(f"| {name} | {spp} | {label} | {rel:.5f} | {psnr:.2f} | {flip:.4f} | {m} | {t:.2f} | {den} |",
                      flush=True)


if __name__ == "__main__":
    main()
