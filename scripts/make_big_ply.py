#!/usr/bin/env python3
"""Writes a large PLY mesh for measuring how fast lumen loads one: a grid
of N x N quads (2 N^2 triangles) bent into a wave, positions only, each
quad written as two triangles. N = 2237 gives 10,008,338 triangles.

    python3 scripts/make_big_ply.py OUT.ply [N] [binary|ascii]

Binary files are little endian, with faces as `list uchar int`, as most
tools write them. Needs numpy."""
import sys

import numpy as np


def main():
    out = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 2237
    encoding = sys.argv[3] if len(sys.argv) > 3 else "binary"
    side = n + 1
    u, v = np.meshgrid(np.linspace(-1, 1, side), np.linspace(-1, 1, side))
    y = 0.1 * np.sin(6 * u) * np.cos(4 * v)
    positions = np.stack([u, y, v], axis=-1).reshape(-1, 3).astype("<f4")
    i = np.arange(n)
    a = (i[None, :] + side * i[:, None]).reshape(-1)
    b, c, d = a + 1, a + side + 1, a + side
    triangles = np.stack([np.stack([a, b, c], 1), np.stack([a, c, d], 1)], 1)
    triangles = triangles.reshape(-1, 3).astype("<i4")
    fmt = "binary_little_endian" if encoding == "binary" else "ascii"
    header = (
        f"ply\nformat {fmt} 1.0\ncomment a wave of {len(triangles)} triangles\n"
        f"element vertex {len(positions)}\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {len(triangles)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    with open(out, "wb") as f:
        f.write(header.encode())
        if encoding == "binary":
            f.write(positions.tobytes())
            faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<i4", 3)])
            faces["n"] = 3
            faces["i"] = triangles
            f.write(faces.tobytes())
        else:
            np.savetxt(f, positions, fmt="%.7g")
            np.savetxt(f, np.hstack([np.full((len(triangles), 1), 3), triangles]), fmt="%d")
    print(f"{out}: {len(positions)} vertices, {len(triangles)} triangles")


if __name__ == "__main__":
    main()
