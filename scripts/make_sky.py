#!/usr/bin/env python3
"""Writes assets/sky.hdr: a small procedural HDR sky for the examples.

An equirectangular Radiance RGBE image (256 x 128, no run-length encoding)
laid out as lumen reads it: the centre column looks along -z, the top row
straight up. A blue sky that pales towards the horizon, a dim brown ground
below it, and a sun of angular radius 2.5 degrees, 35 degrees above the
horizon and 50 degrees to the right of the default view, about 1,000 times
as bright as the sky around it. No inputs, no randomness: the file is the
same on every run.

    python3 scripts/make_sky.py [OUT]
"""
import math
import struct
import sys

W, H = 256, 128
SUN_ELEVATION = math.radians(35.0)
SUN_AZIMUTH = math.radians(50.0)  # from -z towards +x
SUN_RADIUS = math.radians(2.5)
SUN = (800.0, 720.0, 610.0)


def direction(u, v):
    theta, phi = math.pi * v, 2.0 * math.pi * (u - 0.5)
    return (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))


def radiance(d):
    sun = (
        math.cos(SUN_ELEVATION) * math.sin(SUN_AZIMUTH),
        math.sin(SUN_ELEVATION),
        -math.cos(SUN_ELEVATION) * math.cos(SUN_AZIMUTH),
    )
    cos_to_sun = sum(a * b for a, b in zip(d, sun))
    if cos_to_sun >= math.cos(SUN_RADIUS):
        return SUN
    y = d[1]
    if y < 0.0:
        return (0.25, 0.2, 0.15)
    # Pale at the horizon, deep blue straight up, brighter near the sun.
    t = y ** 0.5
    glow = 1.0 + 2.0 * max(cos_to_sun, 0.0) ** 32
    horizon, zenith = (0.9, 0.95, 1.0), (0.25, 0.45, 0.9)
    return tuple(glow * ((1 - t) * h + t * z) for h, z in zip(horizon, zenith))


def rgbe(rgb):
    m = max(rgb)
    if m < 1e-32:
        return bytes(4)
    mantissa, exponent = math.frexp(m)
    scale = mantissa * 256.0 / m
    return bytes([int(c * scale) for c in rgb] + [exponent + 128])


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "assets/sky.hdr"
    body = bytearray()
    for y in range(H):
        for x in range(W):
            # Average 4 x 4 points per texel so the sun's edge is smooth.
            acc = [0.0, 0.0, 0.0]
            for j in range(4):
                for i in range(4):
                    r = radiance(direction((x + (i + 0.5) / 4) / W, (y + (j + 0.5) / 4) / H))
                    acc = [a + c / 16 for a, c in zip(acc, r)]
            body += rgbe(acc)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {H} +X {W}\n".encode()
    with open(out, "wb") as f:
        f.write(header + bytes(body))


if __name__ == "__main__":
    main()
