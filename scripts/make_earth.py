#!/usr/bin/env python3
"""Writes assets/earth.png: a made-up planet, the texture of the `earth` built-in.

An equirectangular 8-bit sRGB PNG (512 x 256) as lumen's sphere (u, v)
coordinates read it: u runs around the y axis, v from the south pole (bottom
row) to the north pole (top row). Continents come from fractal value noise
evaluated on the unit sphere (so the map has no seam), coloured by height:
deep and shallow sea, beaches, lowland green, highland brown, grey rock,
snow on the peaks and ice towards the poles. No inputs, no randomness beyond
a fixed hash: the file is the same on every run.

    python3 scripts/make_earth.py [OUT]
"""
import math
import struct
import sys
import zlib

W, H = 512, 256
OCTAVES = 6
SEA_LEVEL = 0.555


def lattice(x, y, z):
    """A fixed pseudo-random value in [0, 1) per integer lattice point."""
    h = (x * 73856093) ^ (y * 19349663) ^ (z * 83492791) ^ 0x5BD1E995
    h &= 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0x5BD1E995) & 0xFFFFFFFF
    h ^= h >> 15
    return h / 4294967296.0


def smooth(t):
    return t * t * (3.0 - 2.0 * t)


def value_noise(x, y, z):
    xi, yi, zi = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = smooth(x - xi), smooth(y - yi), smooth(z - zi)
    total = 0.0
    for dx in (0, 1):
        wx = fx if dx else 1.0 - fx
        for dy in (0, 1):
            wy = fy if dy else 1.0 - fy
            for dz in (0, 1):
                wz = fz if dz else 1.0 - fz
                total += wx * wy * wz * lattice(xi + dx, yi + dy, zi + dz)
    return total


def height(p):
    """Fractal noise in [0, 1] at the unit vector p."""
    total, amplitude, frequency, norm = 0.0, 1.0, 1.6, 0.0
    for _ in range(OCTAVES):
        total += amplitude * value_noise(p[0] * frequency + 17.0, p[1] * frequency, p[2] * frequency)
        norm += amplitude
        amplitude *= 0.5
        frequency *= 2.1
    return total / norm


def mix(a, b, t):
    t = min(max(t, 0.0), 1.0)
    return tuple(x + (y - x) * t for x, y in zip(a, b))


def colour(h, latitude):
    """Linear RGB of a point of height h at latitude (radians)."""
    if h < SEA_LEVEL:
        c = mix((0.005, 0.02, 0.09), (0.02, 0.12, 0.30), (h - 0.3) / (SEA_LEVEL - 0.3))
    else:
        land = (h - SEA_LEVEL) / (1.0 - SEA_LEVEL)
        if land < 0.03:
            c = (0.45, 0.40, 0.25)
        elif land < 0.25:
            c = mix((0.06, 0.20, 0.04), (0.20, 0.24, 0.07), (land - 0.03) / 0.22)
        elif land < 0.45:
            c = mix((0.20, 0.24, 0.07), (0.28, 0.18, 0.09), (land - 0.25) / 0.2)
        else:
            c = mix((0.28, 0.18, 0.09), (0.35, 0.35, 0.35), (land - 0.45) / 0.15)
        if land > 0.62:
            c = (0.85, 0.85, 0.88)
    ice = (abs(latitude) - math.radians(74.0)) / math.radians(4.0) + 2.0 * (h - 0.5)
    if ice > 0.0:
        c = mix(c, (0.80, 0.84, 0.90), ice * 2.0)
    return c


def srgb(x):
    x = min(max(x, 0.0), 1.0)
    s = 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1.0 / 2.4) - 0.055
    return int(round(255.0 * s))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "assets/earth.png"
    rows = bytearray()
    for row in range(H):
        # Top row: the north pole (+y); lumen's v = θ/π runs from −y.
        theta = math.pi * (row + 0.5) / H
        latitude = 0.5 * math.pi - theta
        rows.append(0)
        for col in range(W):
            # u = φ/2π with φ measured around y from −x (lumen's `Sphere::uv`).
            phi = 2.0 * math.pi * (col + 0.5) / W
            p = (-math.cos(phi) * math.sin(theta), math.cos(theta), math.sin(phi) * math.sin(theta))
            rows.extend(srgb(c) for c in colour(height(p), latitude))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(rows), 9))
    png += chunk(b"IEND", b"")
    with open(out, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
