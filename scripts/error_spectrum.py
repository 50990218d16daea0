#!/usr/bin/env python3
"""How the error of renders is spread over spatial frequencies.

For each image, the error against a reference (both linear .pfm files, as
`lumen render ... -o X.pfm` writes them) is taken on the luminance, its
largest centred square is cut out, and its 2-D power spectrum is averaged
over rings of equal radius, normalised by the error's variance: white
noise is 1 in every ring, blue noise is below 1 at low frequencies and
above at high ones.

usage: scripts/error_spectrum.py REFERENCE.pfm IMAGE.pfm [IMAGE.pfm ...]
       (needs numpy: scripts/peers/setup.sh installs it into its venv,
        "$LUMEN_PEERS_PYTHON" scripts/error_spectrum.py ...)
"""
import sys

import numpy as np

RINGS = 8


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            sys.exit(f"{path}: not a colour PFM")
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.frombuffer(f.read(width * height * 12), dtype=dtype)
    # PFM rows go bottom to top.
    return data.reshape(height, width, 3)[::-1]


def luminance(image):
    return image @ np.array([0.2126, 0.7152, 0.0722])


def spectrum(error):
    n = min(error.shape)
    top, left = (error.shape[0] - n) // 2, (error.shape[1] - n) // 2
    e = error[top : top + n, left : left + n]
    e = e - e.mean()
    power = np.abs(np.fft.fft2(e)) ** 2 / e.size
    f = np.fft.fftfreq(n) * n
    radius = np.hypot(*np.meshgrid(f, f))
    rings = []
    for i in range(RINGS):
        lo, hi = i * n / 2 / RINGS, (i + 1) * n / 2 / RINGS
        ring = (radius >= max(lo, 1e-9)) & (radius < hi)
        rings.append(power[ring].mean() / e.var())
    return n, e.var(), rings


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    reference = luminance(read_pfm(sys.argv[1]))
    header = " | ".join(f"ring {i + 1}" for i in range(RINGS))
    print(f"| image | square | error variance | {header} |")
    print("| --- | ---: | ---: |" + " ---: |" * RINGS)
    for path in sys.argv[2:]:
        n, variance, rings = spectrum(luminance(read_pfm(path)) - reference)
        cells = " | ".join(f"{r:.2f}" for r in rings)
        print(f"| {path} | {n} | {variance:.3e} | {cells} |")


if __name__ == "__main__":
    main()
